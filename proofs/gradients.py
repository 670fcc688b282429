"""The exact gradient of each height field (seed §3) and the renderer's generated code for it.

One theorem per registered field (`renderer.formulas.FIELDS`, ``gradient-<name>``), about its
record's gradient (`HeightField.gradient`, sympy's derivatives of its expression) and its
compiled evaluation (`renderer.pointwise.exact_gradient`, the kernel's generated function).
Everything a theorem says is derived from the field's expression: how it is shown
(`named_factors`, `shown`), the closed form its proof reaches, written as seed §3 prints the
gradients (`printed`), the argument's sentences, and its wrong variants (a factor dropped,
k_u and k_v swapped, the kernel's outputs swapped or rounded to float32).
"""

import random
from functools import lru_cache, partial

import mpmath
import numpy as np
import sympy as sp

from renderer import formulas as F

from .core import DIGITS, POINTS, Theorem, Verdict, calc, loose, written

u, v, k_u, k_v = F.u, F.v, F.k_u, F.k_v
#: The factors as the proofs name them: s_1 a field's factor in u, s_2 its factor in v (seed §3's
#: s_1 = sin(pi k_u u), s_2 = sin(pi k_v v)).
S1, S2 = sp.symbols("s_1 s_2", real=True)
DOMAIN = {u: (0.0, 1.0), v: (0.0, 1.0), k_u: (0.5, 12.0), k_v: (0.5, 12.0)}
PREFIX = "gradient-"


def named_factors(field):
    """{s_1: its factor in u alone, s_2: its factor in v alone} of a field whose h is a product of
    one of each (powers of them included), or the absolute value of one; {} for any other field.

    Parameters
    ----------
    field : renderer.formulas.HeightField

    Returns
    -------
    dict
        sympy Symbol -> sympy expression (`S1`, `S2`), or empty.
    """
    inner = field.expr.args[0] if isinstance(field.expr, sp.Abs) else field.expr
    bases = [b for b, _ in (f.as_base_exp() for f in sp.Mul.make_args(inner)) if b.free_symbols & {u, v}]
    by = {x: [b for b in bases if b.free_symbols & {u, v} == {x}] for x in (u, v)}
    return {S1: by[u][0], S2: by[v][0]} if len(bases) == 2 and len(by[u]) == len(by[v]) == 1 else {}


def shown(field):
    """The field's h as the statement shows it: its expression with the `named_factors` named."""
    return field.expr.xreplace({e: s for s, e in named_factors(field).items()})


def _group(factor, names):
    """Where a factor of a printed component goes: 0 if it varies with u alone, 1 with v alone, 2 with both."""
    free = factor.xreplace(names).free_symbols & {u, v}
    return 0 if free == {u} else 1 if free == {v} else 2


def printed_factors(field):
    """Each component (h_u, h_v) of the field's gradient as the list of its factors, in the order seed §3
    prints them: the constant ones (pi k_u), then those varying with u, with v, with both (the sign of
    an Abs), the `named_factors` named; [] for a component that is 0."""
    names = named_factors(field)
    out = []
    for d in field.gradient:
        d = d.xreplace({e: s for s, e in names.items()})
        if d == 0:
            out.append([])
            continue
        constant, varying = d.as_independent(u, v, *names, as_Add=False)
        out.append([f for f in sp.Mul.make_args(constant) if f != 1]
                   + sorted(sp.Mul.make_args(varying), key=lambda f: (_group(f, names), sp.default_sort_key(f))))
    return out


def _as_written(factors):
    return written(sp.Mul(*factors, evaluate=False)) if factors else sp.Integer(0)


def printed(field):
    """(h_u, h_v) as seed §3 prints a field's gradient (`printed_factors`), kept as written:
    sine's h_u = pi k_u cos(pi k_u u) s_2."""
    return tuple(_as_written(f) for f in printed_factors(field))


def generated_code_residual(field, closed_form, *, seed=0, points=POINTS, compiled=None):
    """Worst relative error of the renderer's float64 gradient against mpmath.

    The closed form (in the `named_factors` of ``field``, a `renderer.formulas.HeightField`) is
    evaluated at ``DIGITS`` digits at seeded random points (float64-representable, so both sides
    see the same input).  Points within 1e-9 of a crease (a zero of one of the field's
    `HeightField.crease_factors`) are skipped: there the sign factor depends on the last bit of the
    float64 factor.  ``compiled`` alters the kernel's (h_u, h_v) first (a wrong variant).
    """
    from renderer import pointwise
    rng = random.Random(seed)
    names = named_factors(field)
    fn = sp.lambdify((u, v, k_u, k_v), [sp.sympify(e).xreplace(names).doit() for e in closed_form], modules="mpmath")
    creases = sp.lambdify((u, v, k_u, k_v), list(field.crease_factors), modules="mpmath")
    worst = 0.0
    taken = 0
    with mpmath.workdps(DIGITS):
        while taken < points:
            uu, vv = rng.random(), rng.random()
            ku, kv = rng.uniform(0.5, 12.0), rng.uniform(0.5, 12.0)
            at = (mpmath.mpf(uu), mpmath.mpf(vv), mpmath.mpf(ku), mpmath.mpf(kv))
            if any(abs(c) < 1e-9 for c in creases(*at)):
                continue
            got = pointwise.exact_gradient(field, uu, vv, ku, kv)        # 0-d arrays
            got = compiled(got) if compiled else got
            ref = fn(*at)
            scale = F.gradient_scale(ku, kv, field)
            for g, r in zip(got, ref):
                worst = max(worst, float(abs(mpmath.mpf(float(g)) - r) / scale))
            taken += 1
    return worst


#: float64 evaluation of a handful of trigonometric calls: relative error budget.
GENERATED_TOLERANCE = 1e-13


def _gradient_evidence(field, closed_form, corrupt=None, compiled=None):
    """The kernel's generated gradient against ``closed_form`` (h_u, h_v) in mpmath, and the renderer's
    gradients (GBuffer.grad, exact, central and footprint) against theirs; ``corrupt`` alters the
    renderer's gradients, ``compiled`` the kernel's pointwise ones, first (wrong variants)."""
    worst = generated_code_residual(field, closed_form, compiled=compiled)
    if worst > GENERATED_TOLERANCE:
        return Verdict("refuted", f"generated (compiled) gradient differs from the closed form by "
                       f"{worst:.2e} (relative to {F.gradient_scale_text(field)})", worst, DIGITS, POINTS)
    from .pixels import gradient_error
    rendered = {method: gradient_error(field.name, method, corrupt) for method in ("exact", "central", "footprint")}
    if max(r for r, _ in rendered.values()) > 1:
        return Verdict("refuted", "the renderer's gradient leaves its tolerance by "
                       + ", ".join(f"{m} {r:.2g}x" for m, (r, _) in rendered.items()))
    for method, (r, _) in rendered.items():                    # rule 11 on each tolerance, in its own units
        why = loose(1.0, r)
        if why:
            return Verdict("refuted", f"the renderer's {method} gradient's tolerance: {why}")
    return Verdict("proved", f"the kernel's generated code within {worst:.1e} of mpmath, relative to "
                   f"{F.gradient_scale_text(field)} ({DIGITS} digits, {POINTS} points); the renderer's exact, "
                   "central and "
                   f"footprint gradients at {rendered['exact'][1]:,} seeded sphere-A pixels at "
                   f"{rendered['exact'][0]:.2f}, {rendered['central'][0]:.2f} and {rendered['footprint'][0]:.2f} "
                   "times their rounding tolerances against the exact gradient and the central difference "
                   "(stencil included) at the kernel's and the footprint's steps",
                   worst, DIGITS, POINTS, rendered=rendered["exact"][1], bound=GENERATED_TOLERANCE)


def _argument(field, closed_form):
    """The argument after its first step (the renderer's gradient is sympy's derivative of the field): how
    its derivative is taken, as (sentence, the pair it gives) links of a calc chain, by the form of h."""
    h = shown(field)
    if isinstance(h, sp.Abs):
        inner, sign = h.args[0], sp.sign(h.args[0])
        like = [name for name, f in F.FIELDS.items() if f.expr == inner.xreplace(named_factors(field))]
        written_ = sp.latex(inner, symbol_names={x: x.name for x in inner.free_symbols})
        return ((rf"Away from the zero lines of ${written_}$, $d\lvert x\rvert/dx = \operatorname{{sign}} x$ "
                 "(the chain rule)", sp.Tuple(sign * sp.Derivative(inner, u), sign * sp.Derivative(inner, v))),
                ("Then the product rule" + (f", as for the {like[0]} field" if like else ""), sp.Tuple(*closed_form)))
    constant = [x for x in (u, v) if x not in h.free_symbols]
    if len(constant) == 1:
        other = ({u, v} - set(constant)).pop()
        return ((f"The field does not depend on ${constant[0]}$, and in ${other}$ the chain rule gives",
                 sp.Tuple(*closed_form)),)
    if named_factors(field):
        return (("Each factor depends on one variable: differentiate it and keep the other", sp.Tuple(*closed_form)),)
    return (("Differentiate $h$ in $u$ and in $v$", sp.Tuple(*closed_form)),)


def _wrong_closed_forms(field):
    """(description, closed form) of the wrong variants of the field's printed gradient: in its first
    nonzero component, each factor dropped in turn, and k_u and k_v swapped (where that changes it)."""
    factors = printed_factors(field)
    k = next((i for i, f in enumerate(factors) if f), None)
    if k is None:
        return ()
    component = f"h_{'uv'[k]}"
    out = []
    for j, factor in enumerate(factors[k]):
        wrong = list(printed(field))
        wrong[k] = _as_written(factors[k][:j] + factors[k][j + 1:])
        out.append((f"{component} without its factor {factor}", tuple(wrong)))
    swapped = [f.xreplace({k_u: k_v, k_v: k_u}) for f in factors[k]]
    if swapped != factors[k]:
        wrong = list(printed(field))
        wrong[k] = _as_written(swapped)
        out.append((f"{component} with k_u and k_v swapped", tuple(wrong)))
    return tuple(out)


def _theorem(field, closed_form=None, **evidence):
    """Theorem gradient-<name> of ``field`` claiming ``closed_form`` (default: the printed one), with the
    evidence's options (wrong variants)."""
    closed_form = printed(field) if closed_form is None else closed_form
    name, h, names = field.name, shown(field), named_factors(field)
    gradient = sp.Tuple(F.h_u, F.h_v)
    return Theorem(
        id=PREFIX + name, title=_title(name),
        statement=(r"For $⟦h⟧$" + (", $⟦s_1⟧$, $⟦s_2⟧$" if names else "")
                   + f" (the renderer's {name} field): $⟦gradient⟧$."),
        steps=calc(gradient,
                   (f"The renderer's gradient of the {name} field (the formula compiled into its kernel) is "
                    "sympy's derivative of its $h$", sp.Tuple(sp.Derivative(h, u), sp.Derivative(h, v))),
                   *_argument(field, closed_form)),
        claims={"gradient": (gradient, sp.Tuple(*closed_form))}, shown={"h": sp.Eq(F.h, h, evaluate=False)},
        where={F.h_u: field.gradient[0], F.h_v: field.gradient[1], **names}, domain=DOMAIN,
        evidence=partial(_gradient_evidence, field, closed_form, **evidence),
        wrong_variants=(*((description, lambda wrong=wrong: _theorem(field, wrong).check())
                          for description, wrong in _wrong_closed_forms(field)),
                        ("the kernel's h_u and h_v swapped",
                         lambda: _theorem(field, corrupt=lambda g: g[:, ::-1]).check()),
                        ("the kernel's gradient evaluated in float32",
                         lambda: _theorem(field, compiled=lambda g: [np.float32(x) for x in g]).check())),
    )


def _title(name):
    return f"The gradient of the {name} field"


def titles():
    """{id: title} of this module's theorems, one per registered field, in `formulas.FIELDS`' order."""
    return {PREFIX + name: _title(name) for name in F.FIELDS}


def build(theorem_id):
    """Theorem gradient-<name> of the registered field <name>, built once per field record."""
    return _built(F.FIELDS[theorem_id.removeprefix(PREFIX)])


@lru_cache(maxsize=None)
def _built(field):
    return _theorem(field)


build.cache_clear = _built.cache_clear
