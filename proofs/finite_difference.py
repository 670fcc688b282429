"""Central differences: the truncation series and the optimal step (seed §3).

The series is proved for any h.  That it is the renderer's quotient is part
of the theorem: away from the chart's seam and poles, each component of
`renderer.formulas.CENTRAL` (the kernel's stencil, with the interior branch
of `renderer.formulas.STENCIL_POINTS` and of its denominator) equals the
quotient (h(x + eps) - h(x - eps)) / (2 eps) written here, for every field;
and the branches the kernel's formulas take at seeded interior points are
checked to be those interior branches.
"""

import random

import sympy as sp

from renderer import formulas as F

from .core import Identity, Theorem, Verdict, check_identities

x = sp.Symbol("x", real=True)
eps = sp.Symbol("varepsilon", positive=True)
f = sp.Function("h")
ORDER = 6


def central_series(order=ORDER):
    """Series of (h(x + eps) - h(x - eps)) / (2 eps) in eps, up to O(eps**order)."""
    q = (f(x + eps) - f(x - eps)) / (2 * eps)
    return sp.series(q, eps, 0, order).removeO().doit()


CLAIMED = (sp.diff(f(x), x) + eps**2 / 6 * sp.diff(f(x), x, 3)
           + eps**4 / 120 * sp.diff(f(x), x, 5))

a, b = sp.symbols("a b", real=True)
#: A concrete analytic h for numerical sampling only (the proof is for any h).
INSTANCE = {f: sp.Lambda(x, sp.sin(a * x) + sp.exp(b * x))}
SERIES_DOMAIN = {x: (-1.0, 1.0), eps: (0.01, 0.3), a: (0.5, 3.0), b: (-1.0, 1.0)}


def _series_identity(rhs):
    return Identity("series", central_series(), rhs, SERIES_DOMAIN, INSTANCE)


def interior(expr):
    """``expr`` with every Piecewise replaced by its last (default) branch and
    every Min(1, a) or Max(0, a) by a: the branch that `formulas.CENTRAL` and
    `formulas.STENCIL_POINTS` take where u +- eps stays in [0, 1) and v +- eps
    in [0, 1] (no wrap, no clamp)."""
    expr = expr.replace(lambda e: isinstance(e, sp.Piecewise), lambda e: e.args[-1].expr)
    return expr.replace(lambda e: isinstance(e, (sp.Min, sp.Max)) and len(e.args) == 2 and e.args[0].is_number,
                        lambda e: e.args[1])


def interior_points(stencil=F.STENCIL_POINTS):
    """{point symbol: its interior branch} of ``stencil``'s (symbol, expression) pairs: the kernel's
    stencil points at an interior point (computed in the check, so that `interior` runs there)."""
    return {p: interior(e) for p, e in stencil}


STEP = {F.u: F.eps_u, F.v: F.eps_v}
KERNEL_DOMAIN = {F.u: (0.0, 1.0), F.v: (0.0, 1.0), F.k_u: (0.5, 12.0), F.k_v: (0.5, 12.0),
                 F.eps_u: (1e-4, 0.1), F.eps_v: (1e-4, 0.1)}


def quotient(h, var, denominator):
    """(h(var + eps) - h(var - eps)) / (denominator eps) of the expression ``h``, eps the step of ``var``."""
    e = STEP[var]
    return (h.subs(var, var + e) - h.subs(var, var - e)) / (denominator * e)


def kernel_quotient(name, k):
    """Component ``k`` (0: h_u, 1: h_v) of `formulas.CENTRAL` for field ``name`` at an interior point."""
    return interior(F.CENTRAL[name][k]).subs(interior_points())


def _kernel_identities(denominator):
    return [Identity(rf"\text{{CENTRAL[{name}]}}_{var}", kernel_quotient(name, k), quotient(h, var, denominator),
                     KERNEL_DOMAIN)
            for name, h in F.HEIGHT.items() for k, var in enumerate((F.u, F.v))]


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


def border_mismatches(samples=2000, seed=12, rule=_border_rule, stencil=F.STENCIL_POINTS):
    """Seeded points within a step of the borders (u near 0 or 1, v near 0 or 1) at
    which ``stencil`` (`formulas.STENCIL_POINTS`), or the v-denominator of `formulas.CENTRAL`
    (read off its sine field, at ``stencil``), differ from ``rule``; evaluated in float64."""
    args = (F.u, F.v, F.eps_u, F.eps_v)
    points = sp.lambdify(args, [e for _, e in stencil], modules="math")
    h = F.HEIGHT["sine"].subs({F.k_u: 3, F.k_v: 2})
    central_v = sp.lambdify(args, F.CENTRAL["sine"][1].subs({F.k_u: 3, F.k_v: 2}).subs(dict(stencil)),
                            modules="math")
    h_of = sp.lambdify((F.u, F.v), h, modules="math")
    rng = random.Random(seed)
    bad = 0
    for _ in range(samples):
        step = 10.0 ** rng.uniform(-6, -1)
        u_ = rng.choice((rng.uniform(0.0, step), rng.uniform(1.0 - step, 1.0 - 1e-12), rng.uniform(0, 1)))
        v_ = rng.choice((rng.uniform(0.0, step), rng.uniform(1.0 - step, 1.0), rng.uniform(0, 1)))
        want = rule(u_, v_, step)
        got = points(u_, v_, step, step)
        quotient = (h_of(u_, want[2]) - h_of(u_, want[3])) / want[4]
        bad += list(got) != list(want[:4]) or abs(central_v(u_, v_, step, step) - quotient) > 1e-9 * (1 + abs(quotient))
    return bad


def _stencil_with(point, change):
    """`formulas.STENCIL_POINTS` with ``change`` (expression -> expression) applied to ``point``'s
    expression: the stencil of a wrong kernel."""
    return tuple((p, change(e) if p == point else e) for p, e in F.STENCIL_POINTS)


def _check_truncation(claimed, denominator=2, rule=_border_rule, half=0.5, stencil=F.STENCIL_POINTS):
    verdict = check_identities([_series_identity(claimed)] + _kernel_identities(denominator))
    if not verdict.holds:
        return verdict
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
    if fp > 1e-9:
        return Verdict("refuted", f"the kernel's footprint steps differ from pbrt-v4's rule by {fp:.2g} (relative)")
    return Verdict(verdict.status, f"{verdict.evidence} (the series, and the 6 components of "
                   f"renderer.formulas.CENTRAL at interior points); the stencil takes its interior "
                   f"branch at 2,000 seeded interior points, and at 2,000 points near the borders wraps u, "
                   f"clamps v and divides by the clamped distance; the footprint steps (FOOTPRINT, compiled) "
                   f"equal pbrt-v4's least-squares rule within {fp:.1e} (relative) at {pixels} sphere-A pixels",
                   verdict.residual, verdict.digits, verdict.points, pixels)


CENTRAL_DIFFERENCE_TRUNCATION = Theorem(
    id="central-difference-truncation", title="Truncation error of the central difference",
    statement=(r"$\dfrac{h(x+\varepsilon) - h(x-\varepsilon)}{2\varepsilon} = h' + \dfrac{\varepsilon^2}{6}h''' + "
               r"\dfrac{\varepsilon^4}{120}h^{(5)} + O(\varepsilon^6)$. Away from the seam and the poles "
               r"this quotient is the renderer's stencil (`renderer.formulas.CENTRAL`), in $u$ and in $v$, "
               r"for every height field; at the borders $u$ wraps and $v$ clamps to $[0, 1]$, the quotient "
               r"in $v$ then one-sided over the clamped distance.  The footprint steps are pbrt-v4's "
               r"$\tfrac12(\lvert\partial u/\partial x\rvert + \lvert\partial u/\partial y\rvert)$ (likewise $v$)."),
    steps=(("series", r"\frac{h(x+\varepsilon) - h(x-\varepsilon)}{2\varepsilon}", CLAIMED),
           ("stencil", r"\text{CENTRAL[sine]}_u", kernel_quotient("sine", 0).subs(F.eps_u, eps))),
    check=lambda: _check_truncation(CLAIMED),
    wrong_variants=(("coefficient 1/3 instead of 1/6",
                     lambda: _check_truncation(CLAIMED + eps**2 / 6 * sp.diff(f(x), x, 3))),
                    ("eps^3 instead of eps^2",
                     lambda: _check_truncation(CLAIMED - eps**2 / 6 * sp.diff(f(x), x, 3)
                                               + eps**3 / 6 * sp.diff(f(x), x, 3))),
                    ("the stencil read as a quotient over eps, not 2 eps",
                     lambda: _check_truncation(CLAIMED, denominator=1)),
                    ("the footprint without pbrt's factor 1/2", lambda: _check_truncation(CLAIMED, half=1.0)),
                    ("a v border divided by 2 eps",
                     lambda: _check_truncation(CLAIMED, rule=lambda u_, v_, e_: _border_rule(u_, v_, e_)[:4] + (2 * e_,))),
                    ("v_p clamped to 1/2, in the kernel and the border rule alike: a clamp inside the chart",
                     lambda: _check_truncation(CLAIMED, rule=lambda u_, v_, e_: _border_rule(u_, v_, e_, top=0.5),
                                               stencil=_stencil_with(F.v_p, lambda e: e.xreplace({1: sp.S.Half})))),
                    *((f"{p} without its {'wrap' if p.name[0] == 'u' else 'clamp'} (its interior branch everywhere)",
                       lambda p=p: _check_truncation(CLAIMED, stencil=_stencil_with(p, interior)))
                      for p in (F.u_p, F.u_m, F.v_p, F.v_m))),
    pages=("s3",),
)

H3, H, u_round = sp.symbols("H_3 H u", positive=True)
ERROR_MODEL = eps**2 * H3 / 6 + u_round * H / eps
EPS_STAR = (3 * u_round * H / H3) ** sp.Rational(1, 3)


def _optimum(claimed, model=ERROR_MODEL):
    """Proved when sympy finds exactly one stationary point, decided positive, of ``model`` in eps,
    equal to ``claimed``, with a positive second derivative there; else refuted."""
    roots = sp.solve(sp.diff(model, eps), eps)
    stationary = [r for r in roots if r.is_positive]
    if len(stationary) != 1 or any(r.is_positive is None for r in roots):
        return Verdict("refuted", f"{len(stationary)} stationary points sympy decides are positive, "
                       f"among the roots {roots}")
    if sp.simplify(stationary[0] - claimed) != 0:
        return Verdict("refuted", f"the stationary point is {stationary[0]}, not the claimed {claimed}")
    curvature = sp.simplify(sp.diff(model, eps, 2).subs(eps, claimed))
    if not curvature.is_positive:
        return Verdict("refuted", f"second derivative {curvature} at the stationary point: not a minimum")
    return Verdict("proved", f"sympy solves E'(eps) = 0: one positive root, {sp.latex(stationary[0])}; "
                   f"second derivative {sp.latex(curvature)} > 0 there")


OPTIMAL_STEP = Theorem(
    id="optimal-step", title="The optimal central-difference step",
    statement=r"The error model $E(\varepsilon) = \varepsilon^2\lvert h'''\rvert/6 + "
              r"\mathrm{u}\lvert h\rvert/\varepsilon$ ($\mathrm{u}$ the unit roundoff) has its "
              r"minimum at $\varepsilon^\ast = (3\mathrm{u}\lvert h\rvert/\lvert h'''\rvert)^{1/3}$.",
    steps=((r"derivative", r"E'(\varepsilon)", sp.diff(ERROR_MODEL, eps)),
           (r"\varepsilon^\ast", r"\varepsilon^\ast", EPS_STAR)),
    check=lambda: _optimum(EPS_STAR),
    wrong_variants=(("exponent 1/2 instead of 1/3",
                     lambda: _optimum((3 * u_round * H / H3) ** sp.Rational(1, 2))),
                    ("the roundoff term added with the wrong sign (no stationary point)",
                     lambda: _optimum(EPS_STAR, eps**2 * H3 / 6 - u_round * H / eps)),
                    ("both terms negated (the stationary point is a maximum)",
                     lambda: _optimum(EPS_STAR, -ERROR_MODEL)),
                    ("a model with stationary points 1, 3/2 and 2: a minimum at 1, but not the only one",
                     lambda: _optimum(sp.Integer(1), (eps - 1)**2 * (eps - 2)**2))),
    pages=("s3", "s5", "s7"),
    seed_says="§3: truncation dominates until eps ~ 1e-6; Cell 2 expects the minimum near 1e-6.",
)

THEOREMS = (CENTRAL_DIFFERENCE_TRUNCATION, OPTIMAL_STEP)
