"""Central differences: the truncation series and the optimal step (seed §3).

The series is proved for any h, by Taylor's theorem.  That it is the renderer's
quotient is part of the theorem: away from the chart's seam and poles, each
component of each registered field's central difference (`HeightField.central`: the
kernel's stencil, with the interior branch of `renderer.formulas.STENCIL_POINTS` and of
its denominator) equals the quotient (h(x + eps) - h(x - eps)) / (2 eps) written here,
for every field (a step of the proof); the evidence checks that the kernel's formulas take those interior
branches at seeded interior points, wrap and clamp at the borders, and take
pbrt-v4's footprint steps.
"""

import random
from functools import partial

import numpy as np
import sympy as sp

from renderer import formulas as F

from .core import Step, Theorem, Verdict, calc, catalogue, written

x = sp.Symbol("x", real=True)
eps = F.eps
f = sp.Function("h")
ORDER = 6


def _d(n):
    """h^(n)(x)."""
    return sp.Derivative(f(x), (x, n)) if n else f(x)


#: Taylor's theorem for h(x + eps), written out to fifth order.
TAYLOR = written(sp.Add(*[eps**n / sp.factorial(n) * _d(n) for n in range(ORDER)], sp.O(eps**ORDER), evaluate=False))
#: The central quotient, as written.
QUOTIENT = written(sp.Add(f(sp.Add(x, eps, evaluate=False)), -f(sp.Add(x, -eps, evaluate=False)), evaluate=False)
                   / (2 * eps))
#: The claimed series' terms, in the order written: h' + eps^2 h''' / 6 + eps^4 h^(5) / 120.
CLAIMED = (sp.diff(f(x), x), eps**2 / 6 * sp.diff(f(x), x, 3), eps**4 / 120 * sp.diff(f(x), x, 5))



def richardson(coarse, fine):
    """Richardson's extrapolation of two central differences, ``fine`` at half the step of ``coarse``:
    (4 fine - coarse) / 3, which cancels their eps^2 term (verify/test_ucurve.py expands it by sympy);
    numbers, numpy arrays or sympy expressions alike.  Its only statement of the weights."""
    return (4 * fine - coarse) / 3


a, b = sp.symbols("a b", real=True)
#: A concrete analytic h for numerical sampling only (the proof is for any h).
INSTANCE = {f: sp.Lambda(x, sp.sin(a * x) + sp.exp(b * x))}
SERIES_DOMAIN = {x: (-1.0, 1.0), eps: (0.01, 0.3), a: (0.5, 3.0), b: (-1.0, 1.0)}


def interior(expr):
    """``expr`` with every Piecewise replaced by its last (default) branch and
    every Min(1, a) or Max(0, a) by a: the branch that `HeightField.central` and
    `formulas.STENCIL_POINTS` take where u +- eps stays in [0, 1) and v +- eps
    in [0, 1] (no wrap, no clamp)."""
    expr = expr.replace(lambda e: isinstance(e, sp.Piecewise), lambda e: e.args[-1].expr)
    return expr.replace(lambda e: isinstance(e, (sp.Min, sp.Max)) and len(e.args) == 2 and e.args[0].is_number,
                        lambda e: e.args[1])


def interior_points(stencil=F.STENCIL_POINTS):
    """{point symbol: its interior branch} of ``stencil``'s (symbol, expression) pairs: the kernel's
    stencil points at an interior point."""
    return {p: interior(e) for p, e in stencil}


STEP = {F.u: F.eps_u, F.v: F.eps_v}
KERNEL_DOMAIN = {F.u: (0.0, 1.0), F.v: (0.0, 1.0), F.k_u: (0.5, 12.0), F.k_v: (0.5, 12.0),
                 F.eps_u: (1e-4, 0.1), F.eps_v: (1e-4, 0.1)}


def quotient(h, var, denominator):
    """(h(var + eps) - h(var - eps)) / (denominator eps) of the expression ``h``, eps the step of ``var``,
    as written (unevaluated: var + eps, not eps + var)."""
    e = STEP[var]
    at = (lambda sign: h.subs(var, sp.Add(var, sign * e, evaluate=False)))
    return written(sp.Add(at(1), -at(-1), evaluate=False) / (denominator * e))


def kernel_quotient(field, k):
    """Component ``k`` (0: h_u, 1: h_v) of the central difference of ``field`` (a `HeightField`) at an
    interior point."""
    return interior(field.central[k]).subs(interior_points())


def interior_branch_mismatches(stencil=F.STENCIL_POINTS, samples=2000, seed=11):
    """(mismatches, points compared): of ``samples`` seeded points (u, v, eps), those
    with eps > 0, u +- eps in [0, 1) and v +- eps in [0, 1] in float64 (with seed 11,
    every one) are compared, and counted where ``stencil`` (`formulas.STENCIL_POINTS`),
    evaluated in float64, differs from its interior branches (`interior_points`)."""
    args = (F.u, F.v, F.eps_u, F.eps_v)
    full = sp.lambdify(args, [e for _, e in stencil], modules="math")
    inner = sp.lambdify(args, list(interior_points(stencil).values()), modules="math")
    rng = random.Random(seed)
    bad = compared = 0
    for _ in range(samples):
        step = 10.0 ** rng.uniform(-9, -1)
        u_, v_ = rng.uniform(step, 1.0 - step), rng.uniform(step, 1.0 - step)
        if 0.0 <= u_ - step < u_ + step < 1.0 and 0.0 <= v_ - step < v_ + step <= 1.0:
            compared += 1
            bad += full(u_, v_, step, step) != inner(u_, v_, step, step)
    return bad, compared


def _border_rule(u, v, eps, top=1.0):
    """The stencil at the chart's borders, written from the rule (seed Cell 1,
    ``grad_numeric``): u wraps (the chart is periodic in u), v clamps to [0, 1]
    and the v-quotient is then one-sided, over the clamped distance.  (``top``:
    v_p's clamp, 1 but in a wrong variant.)"""
    u_p = u + eps - 1 if u + eps >= 1 else u + eps
    u_m = u - eps + 1 if u - eps < 0 else u - eps
    v_p, v_m = min(top, v + eps), max(0.0, v - eps)
    return u_p, u_m, v_p, v_m, (v_p - v_m) if (v + eps > 1 or v - eps < 0) else 2 * eps


def border_points(samples=2000, seed=12):
    """``samples`` seeded (u, v, step) triples, step log-uniform in [1e-6, 1e-1]: u within a step of 0,
    within a step of 1, or anywhere in [0, 1), a third each (and v alike, within a step of 0 or 1 or in
    [0, 1]), so that each border's wrap or clamp is taken at about a third of them."""
    rng = random.Random(seed)
    for _ in range(samples):
        step = 10.0 ** rng.uniform(-6, -1)
        u_ = rng.choice((rng.uniform(0.0, step), rng.uniform(1.0 - step, 1.0 - 1e-12), rng.uniform(0, 1)))
        v_ = rng.choice((rng.uniform(0.0, step), rng.uniform(1.0 - step, 1.0), rng.uniform(0, 1)))
        yield u_, v_, step


def border_mismatches(samples=2000, seed=12, rule=_border_rule, stencil=F.STENCIL_POINTS):
    """The `border_points` at which ``stencil`` (`formulas.STENCIL_POINTS`), the v-quotient of a
    registered field's central difference (`HeightField.central` at ``stencil``, k_u = 3, k_v = 2), or
    the compiled kernel's central differences (`renderer.pointwise.central_gradient`, both components)
    differ from ``rule``; evaluated in float64 (the quotients within 1e-9 relative)."""
    args = (F.u, F.v, F.eps_u, F.eps_v)
    points = sp.lambdify(args, [e for _, e in stencil], modules="math")
    ks = {F.k_u: 3, F.k_v: 2}
    fields = [(sp.lambdify((F.u, F.v), f.expr.subs(ks), modules="math"),
               sp.lambdify(args, f.central[1].subs(ks).subs(dict(stencil)), modules="math")) for f in F.FIELDS.values()]
    at = list(border_points(samples, seed))
    wrong = np.zeros(len(at), dtype=bool)
    rules = [rule(u_, v_, step) for u_, v_, step in at]
    for i, ((u_, v_, step), want) in enumerate(zip(at, rules)):
        wrong[i] = list(points(u_, v_, step, step)) != list(want[:4])
        for h_of, central_v in fields:
            quotient = (h_of(u_, want[2]) - h_of(u_, want[3])) / want[4]
            wrong[i] |= abs(central_v(u_, v_, step, step) - quotient) > 1e-9 * (1 + abs(quotient))
    # The compiled kernel's central differences (`renderer.pointwise.central_gradient`) by the rule, too.
    from renderer import pointwise
    u_, v_, step = (np.array(c) for c in zip(*at))
    for (h_of, _), name in zip(fields, F.FIELDS):
        rule_u = np.array([(h_of(w[0], v) - h_of(w[1], v)) / (2 * s) for w, v, s in zip(rules, v_, step)])
        rule_v = np.array([(h_of(u, w[2]) - h_of(u, w[3])) / w[4] for w, u in zip(rules, u_)])
        for compiled, quotient in zip(pointwise.central_gradient(name, u_, v_, ks[F.k_u], ks[F.k_v], step),
                                      (rule_u, rule_v)):
            wrong |= ~(np.abs(compiled - quotient) <= 1e-9 * (1 + np.abs(quotient)))
    return int(np.count_nonzero(wrong))


def _stencil_with(point, change):
    """`formulas.STENCIL_POINTS` with ``change`` (expression -> expression) applied to ``point``'s
    expression: the stencil of a wrong kernel."""
    return tuple((p, change(e) if p == point else e) for p, e in F.STENCIL_POINTS)


#: The largest relative difference of the kernel's footprint steps from pbrt-v4's rule the evidence accepts:
#: rule 11 of proofs.core holds it within TIGHT of the worst found (1.2e-13 where it was set).
FOOTPRINT_TOLERANCE = 3e-12


def _stencil_evidence(rule=_border_rule, half=0.5, stencil=F.STENCIL_POINTS):
    """The kernel's stencil (`stencil`) takes its interior branch inside the chart and wraps u, clamps v
    at the borders as `rule` says; its footprint steps are pbrt-v4's with the factor ``half``."""
    bad, compared = interior_branch_mismatches(stencil)
    if bad or compared < 2000:
        return Verdict("refuted", f"the kernel's stencil is not its interior branch at {bad} of the {compared:,} "
                       "seeded interior points compared (of 2,000 drawn)")
    border = border_mismatches(rule=rule, stencil=stencil)
    if border:
        return Verdict("refuted", f"at {border} of 2,000 points near the borders the stencil does not wrap u, "
                       "clamp v and divide by the clamped distance")
    from .pixels import footprint_error
    fp, pixels = footprint_error(half=half)
    if fp > FOOTPRINT_TOLERANCE:
        return Verdict("refuted", f"the kernel's footprint steps differ from pbrt-v4's rule by {fp:.2g} (relative)")
    return Verdict("proved", "the stencil takes its interior branch at 2,000 seeded interior points, and at "
                   "2,000 points near the borders wraps u, clamps v and divides by the clamped distance; the "
                   f"footprint steps, compiled, equal pbrt-v4's least-squares rule within {fp:.1e} "
                   f"(relative) at {pixels:,} sphere-A pixels", fp, rendered=pixels, bound=FOOTPRINT_TOLERANCE)


#: The renderer's stencil as functions of (u, v), one pair per height field (the steps' cases).
CENTRAL_U, CENTRAL_V = sp.Function("CENTRAL_u"), sp.Function("CENTRAL_v")
h_uv = sp.Function("h")


def _kernel_cases():
    return tuple((name, {h_uv: sp.Lambda((F.u, F.v), field.expr),
                         CENTRAL_U: sp.Lambda((F.u, F.v), kernel_quotient(field, 0)),
                         CENTRAL_V: sp.Lambda((F.u, F.v), kernel_quotient(field, 1))})
                 for name, field in F.FIELDS.items())


#: The renderer's footprint rule (`formulas.FOOTPRINT_RULE`) at the differentials of u, named as the statement
#: shows them (an inline fraction within a fraction is set at half size).
DU_DX, DU_DY = sp.symbols("du/dx du/dy", real=True)
with sp.evaluate(False):
    FOOTPRINT_SHOWN = F.FOOTPRINT_RULE.expr.xreplace(dict(zip(F.FOOTPRINT_RULE.variables, (DU_DX, DU_DY))))


def _truncation(claimed=CLAIMED, denominator=2, order=ORDER, **stencil):
    """Theorem central-difference-truncation with the series of the terms ``claimed`` + O(eps^``order``)
    (written as they stand: a term the O-term contains is refused, not absorbed), the stencil's quotients
    over ``denominator`` eps, and the evidence's ``stencil`` options (`_stencil_evidence`): wrong variants."""
    kernel = sp.Tuple(CENTRAL_U(F.u, F.v), CENTRAL_V(F.u, F.v))
    quotients = sp.Tuple(*(quotient(h_uv(F.u, F.v), var, denominator) for var in (F.u, F.v)))
    series = written(sp.Add(*claimed, sp.O(eps**order), evaluate=False))
    return Theorem(
        id="central-difference-truncation", title=TITLES["central-difference-truncation"],
        statement=(r"For a smooth $h$, $$⟦series⟧$$ Away from the seam (the meridian where $u$ wraps from 1 to "
                   r"0) and the poles this quotient is the renderer's "
                   r"central-difference stencil $D_u$, $D_v$, in $u$ and in $v$, for every height field: $$⟦stencil⟧$$ At "
                   r"the borders $u$ wraps and $v$ clamps to $[0, 1]$, the quotient in $v$ then one-sided over the "
                   r"clamped distance.  Here $\varepsilon_u$, $\varepsilon_v$ are the steps in $u$ and $v$: one fixed "
                   r"step $\varepsilon$ by default, or each pixel's footprint, the mean size of $u$'s change to the "
                   r"next pixel in $x$ and in $y$, $⟦footprint⟧$ (pbrt-v4's rule; likewise $\varepsilon_v$)."),
        steps=(
            Step(r"Taylor's theorem: $h$ is smooth, so $h(x + \varepsilon)$ is its Taylor polynomial of degree 5 "
                 r"about $x$, up to a remainder of order $\varepsilon^6$", written(f(sp.Add(x, eps, evaluate=False))),
                 TAYLOR),
            Step(r"Write the same series for $h(x - \varepsilon)$: in the difference the even powers of "
                 r"$\varepsilon$ cancel and the odd ones double; divide by $2\varepsilon$", QUOTIENT, series),
            Step(r"Away from the seam and the poles the kernel's stencil points are $u \pm \varepsilon_u$ and "
                 r"$v \pm \varepsilon_v$ (its branch away from the borders) and its $v$-denominator is "
                 r"$2\varepsilon_v$, so for each height field $h$ the stencil is the central quotient", kernel,
                 quotients, cases=_kernel_cases()),
        ),
        claims={"series": (QUOTIENT, series), "stencil": (kernel, quotients)},
        shown={"footprint": sp.Eq(F.eps_u, FOOTPRINT_SHOWN, evaluate=False)},
        names={CENTRAL_U: "D_u", CENTRAL_V: "D_v", DU_DX: r"\partial u/\partial x", DU_DY: r"\partial u/\partial y"},
        domain={**SERIES_DOMAIN, **KERNEL_DOMAIN}, functions=INSTANCE,
        evidence=partial(_stencil_evidence, **stencil),
        wrong_variants=(("coefficient 1/3 instead of 1/6",
                         lambda: _truncation((CLAIMED[0], eps**2 / 3 * sp.diff(f(x), x, 3), CLAIMED[2])).check()),
                        ("eps^3 instead of eps^2",
                         lambda: _truncation((CLAIMED[0], eps**3 / 6 * sp.diff(f(x), x, 3), CLAIMED[2])).check()),
                        ("the highest written term with 1/60 instead of 1/120",
                         lambda: _truncation(CLAIMED[:2] + (eps**4 / 60 * sp.diff(f(x), x, 5),)).check()),
                        ("the highest written term at eps^5 instead of eps^4",
                         lambda: _truncation(CLAIMED[:2] + (eps**5 / 120 * sp.diff(f(x), x, 5),)).check()),
                        ("the remainder claimed O(eps^7): the eps^6 term is not zero",
                         lambda: _truncation(order=ORDER + 1).check()),
                        ("the stencil read as a quotient over eps, not 2 eps",
                         lambda: _truncation(denominator=1).check()),
                        ("the footprint without pbrt's factor 1/2", lambda: _truncation(half=1.0).check()),
                        ("a v border divided by 2 eps",
                         lambda: _truncation(rule=lambda u_, v_, e_: _border_rule(u_, v_, e_)[:4] + (2 * e_,)).check()),
                        ("v_p clamped to 1/2, in the kernel and the border rule alike: a clamp inside the chart",
                         lambda: _truncation(rule=lambda u_, v_, e_: _border_rule(u_, v_, e_, top=0.5),
                                             stencil=_stencil_with(F.v_p, lambda e: e.xreplace({1: sp.S.Half}))
                                             ).check()),
                        *((f"{p} without its {'wrap' if p.name[0] == 'u' else 'clamp'} (its interior branch "
                           "everywhere)", lambda p=p: _truncation(stencil=_stencil_with(p, interior)).check())
                          for p in (F.u_p, F.u_m, F.v_p, F.v_m))),
    )

# ----------------------------------------------------------------------------- the optimal step
H3, H, HX, u_round = F.H3, F.H, F.HX, F.u_round
E = sp.Function("E")
eps_star = sp.Symbol("eps_star", positive=True)
#: The renderer's error model and optimal step (`renderer.formulas.ERROR_MODEL` and `EPS_STAR`, what
#: the U-curves draw), kept as written.
ROUNDOFF = sp.Add(H, HX, evaluate=False)
ERROR_MODEL, EPS_STAR = written(F.ERROR_MODEL), written(F.EPS_STAR)
NAMES = {H: r"\lvert h\rvert", HX: r"\lvert u\,h'\rvert", H3: r"\lvert h'''\rvert", u_round: r"u_{\mathrm{round}}",
         eps_star: r"\varepsilon^\ast"}
STEP_DOMAIN = {eps: (0.05, 2.0), H: (0.1, 10.0), HX: (0.1, 10.0), H3: (0.1, 10.0), u_round: (1e-3, 0.1)}


def _optimal(model=ERROR_MODEL, star=EPS_STAR):
    """Theorem optimal-step for the error model ``model`` and the claimed optimum ``star`` (wrong variants)."""
    slope, curvature = sp.Derivative(E(eps), eps), sp.Derivative(E(eps), (eps, 2))
    stationary, minimum = sp.Subs(slope, eps, eps_star), sp.Subs(curvature, eps, eps_star)
    return Theorem(
        id="optimal-step", title=TITLES["optimal-step"],
        statement=r"Where $⟦curved⟧$, the error model $⟦E⟧$ ($u_{\mathrm{round}}$ the unit roundoff, $u$ the point) has "
                  r"one stationary point on $⟦steps⟧$, $⟦eps_star⟧$, and it is the minimum: $⟦stationary⟧$ and $⟦minimum⟧$.",
        steps=(
            *calc(slope,
                  ("Differentiate the model term by term",
                   written(sp.Add(sp.Mul(sp.Rational(1, 3), eps, H3, evaluate=False),
                                  sp.Mul(-1, u_round, ROUNDOFF, eps**-2, evaluate=False), evaluate=False))),
                  (r"Put it over the common denominator $3\varepsilon^2$ and write $3u_{\mathrm{round}}(\lvert h\rvert + "
                   r"\lvert u\,h'\rvert)/\lvert h'''\rvert$ as $\varepsilon^{\ast 3}$",
                   written(sp.Mul(sp.Rational(1, 3), H3, sp.Add(eps**3, -eps_star**3, evaluate=False), eps**-2,
                                  evaluate=False)))),
            Step(r"For $\varepsilon > 0$ the factor $\varepsilon^3 - \varepsilon^{\ast 3}$ vanishes only at "
                 r"$\varepsilon = \varepsilon^\ast$, negative below it and positive above", stationary, sp.Integer(0)),
            Step(r"Differentiate again: $E'' = \lvert h'''\rvert/3 + 2u_{\mathrm{round}}(\lvert h\rvert + \lvert u\,h'\rvert)/"
                 r"\varepsilon^3$, which at "
                 r"$\varepsilon^\ast$ is $\lvert h'''\rvert/3 + 2\lvert h'''\rvert/3 > 0$: $\varepsilon^\ast$ is the "
                 r"minimum", minimum, H3),
        ),
        claims={"stationary": (stationary, sp.Integer(0)), "minimum": (minimum, H3)},
        shown={"steps": sp.Gt(eps, 0, evaluate=False), "curved": sp.Gt(H3, 0, evaluate=False)},
        where={E(eps): model, eps_star: star}, names=NAMES, domain=STEP_DOMAIN,
        wrong_variants=(("exponent 1/2 instead of 1/3",
                         lambda: _optimal(star=(3 * u_round * (H + HX) / H3) ** sp.Rational(1, 2)).check()),
                        ("the optimum without the argument-rounding term, (3 u |h| / |h'''|)^(1/3)",
                         lambda: _optimal(star=(3 * u_round * H / H3) ** sp.Rational(1, 3)).check()),
                        ("the roundoff term added with the wrong sign (no stationary point)",
                         lambda: _optimal(eps**2 * H3 / 6 - u_round * (H + HX) / eps).check()),
                        ("both terms negated (the stationary point is a maximum)",
                         lambda: _optimal(-ERROR_MODEL).check()),
                        ("a model with stationary points 1, 3/2 and 2: a minimum at 1, but not the only one",
                         lambda: _optimal((eps - 1)**2 * (eps - 2)**2, sp.Integer(1)).check()),
                        ("the model's truncation term (its highest power) over 3, not 6",
                         lambda: _optimal(eps**2 * H3 / 3 + u_round * (H + HX) / eps).check()),
                        ("the model's truncation term at eps^3, not eps^2",
                         lambda: _optimal(eps**3 * H3 / 6 + u_round * (H + HX) / eps).check())),
    )


#: This module's theorems: id -> title.
TITLES = {"central-difference-truncation": "Truncation error of the central difference",
          "optimal-step": "The optimal central-difference step"}

#: The stencil's step has a case per registered field: built again when they change.
titles, build = catalogue(TITLES, {"central-difference-truncation": _truncation, "optimal-step": _optimal},
                          key=lambda: tuple(F.FIELDS.values()))
