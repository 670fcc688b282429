"""The exact gradients of the three height fields (seed §3) and the renderer's
generated code for them.

The theorems are about `renderer.formulas.GRADIENT` (sympy's derivatives of
`renderer.formulas.HEIGHT`) and its compiled evaluation
(`renderer.pointwise.exact_gradient`, the kernel's generated function); the
closed forms the proofs reach are typed here from seed §3.
"""

import random
from functools import partial

import mpmath
import numpy as np
import sympy as sp

from renderer import formulas as F
from renderer import pointwise

from .core import DIGITS, POINTS, Theorem, Verdict, calc, written

u, v, k_u, k_v = F.u, F.v, F.k_u, F.k_v
s1, s2 = F.RIDGE_FACTORS
c1, c2 = sp.cos(sp.pi * k_u * u), sp.cos(sp.pi * k_v * v)
#: The factors as the proofs name them: s_1 = sin(pi k_u u), s_2 = sin(pi k_v v).
S1, S2 = sp.symbols("s_1 s_2", real=True)
FACTORS = {S1: s1, S2: s2}
sigma = sp.sign(S1 * S2)
DOMAIN = {u: (0.0, 1.0), v: (0.0, 1.0), k_u: (0.5, 12.0), k_v: (0.5, 12.0)}
#: The fields as the proofs write them (`formulas.HEIGHT` with s_1, s_2 named).
SHOWN = {"sine": S1 * S2, "ridges": sp.Abs(S1 * S2), "rings": F.HEIGHT["rings"]}


def _as_written(*factors):
    return written(sp.Mul(*factors, evaluate=False))


#: The closed forms as printed in seed §3 (and in that order), with s_1 and s_2 named.
PRINTED = {
    "sine": (_as_written(sp.pi, k_u, c1, S2), _as_written(sp.pi, k_v, S1, c2)),
    "ridges": (_as_written(sp.pi, k_u, c1, S2, sigma), _as_written(sp.pi, k_v, S1, c2, sigma)),
    "rings": (sp.Integer(0), _as_written(2, sp.pi, k_v, sp.cos(2 * sp.pi * k_v * v))),
}

#: Wrong variants: a dropped factor, a flipped sign, a wrong frequency.
WRONG = {
    "sine": ("h_u without its factor sin(pi k_v v)", (_as_written(sp.pi, k_u, c1), PRINTED["sine"][1])),
    "ridges": ("h_v with the sign factor dropped", (PRINTED["ridges"][0], _as_written(sp.pi, k_v, S1, c2))),
    "rings": ("h_v with the factor 2 lost", (sp.Integer(0), _as_written(sp.pi, k_v, sp.cos(2 * sp.pi * k_v * v)))),
}


def generated_code_residual(name, closed_form, *, seed=0, points=POINTS, compiled=None):
    """Worst relative error of the renderer's float64 gradient against mpmath.

    The closed form is evaluated at ``DIGITS`` digits at seeded random points
    (float64-representable, so both sides see the same input).  Points within
    1e-9 of a crease of the ridges field are skipped: there the sign factor
    depends on the last bit of the float64 sine.  ``compiled`` alters the
    kernel's (h_u, h_v) first (a wrong variant).
    """
    rng = random.Random(seed)
    fn = sp.lambdify((u, v, k_u, k_v), [sp.sympify(e).subs(FACTORS) for e in closed_form], modules="mpmath")
    worst = 0.0
    taken = 0
    with mpmath.workdps(DIGITS):
        while taken < points:
            uu, vv = rng.random(), rng.random()
            ku, kv = rng.uniform(0.5, 12.0), rng.uniform(0.5, 12.0)
            if name == "ridges" and min(abs(mpmath.sin(mpmath.pi * ku * uu)),
                                        abs(mpmath.sin(mpmath.pi * kv * vv))) < 1e-9:
                continue
            got = pointwise.exact_gradient(name, uu, vv, ku, kv)        # 0-d arrays
            got = compiled(got) if compiled else got
            ref = fn(mpmath.mpf(uu), mpmath.mpf(vv), mpmath.mpf(ku), mpmath.mpf(kv))
            scale = mpmath.pi * max(ku, 2 * kv)
            for g, r in zip(got, ref):
                worst = max(worst, float(abs(mpmath.mpf(float(g)) - r) / scale))
            taken += 1
    return worst


#: float64 evaluation of a handful of trigonometric calls: relative error budget.
GENERATED_TOLERANCE = 1e-13


def _gradient_evidence(name, closed_form, corrupt=None, compiled=None):
    """The kernel's generated gradient against ``closed_form`` (h_u, h_v) in mpmath, and the renderer's
    gradients (GBuffer.grad, exact, central and footprint) against theirs; ``corrupt`` alters the
    renderer's gradients, ``compiled`` the kernel's pointwise ones, first (wrong variants)."""
    worst = generated_code_residual(name, closed_form, compiled=compiled)
    if worst > GENERATED_TOLERANCE:
        return Verdict("refuted", f"generated (compiled) gradient differs from the closed form by "
                       f"{worst:.2e} (relative to pi max(k_u, 2 k_v))", worst, DIGITS, POINTS)
    from .pixels import gradient_error
    rendered = {method: gradient_error(name, method, corrupt) for method in ("exact", "central", "footprint")}
    if max(r for r, _ in rendered.values()) > 1:
        return Verdict("refuted", "the renderer's gradient leaves its tolerance by "
                       + ", ".join(f"{m} {r:.2g}x" for m, (r, _) in rendered.items()))
    return Verdict("proved", f"the kernel's generated code within {worst:.1e} of mpmath ({DIGITS} digits, {POINTS} "
                   f"points); the renderer's exact, central and footprint gradients at "
                   f"{rendered['exact'][1]} seeded sphere-A pixels within {rendered['exact'][0]:.2f}, "
                   f"{rendered['central'][0]:.2f} and {rendered['footprint'][0]:.2f} of their tolerances against "
                   "the exact gradient, the central difference (stencil included) and the central difference with "
                   "the footprint's steps at its (u, v)",
                   rendered=rendered["exact"][1])


#: The argument after its first step (the renderer's gradient is sympy's derivative of the field): how
#: each field's derivative is taken, as (sentence, the pair it gives) links of a calc chain.
def _argument(name, closed_form):
    if name == "ridges":
        f = S1 * S2
        return ((r"Away from the zero lines of $s_1 s_2$, $d\lvert x\rvert/dx = \operatorname{sign} x$ (the chain rule)",
                 sp.Tuple(sigma * sp.Derivative(f, u), sigma * sp.Derivative(f, v))),
                ("Then the product rule, as for the sine field", sp.Tuple(*closed_form)))
    if name == "rings":
        return (("The field does not depend on $u$, and in $v$ the chain rule gives", sp.Tuple(*closed_form)),)
    return (("Each factor depends on one variable: differentiate it and keep the other", sp.Tuple(*closed_form)),)


def _theorem(name, closed_form=None, **evidence):
    """Theorem gradient-<name> claiming ``closed_form`` (default: the printed one), with the evidence's options."""
    closed_form = PRINTED[name] if closed_form is None else closed_form
    description, wrong = WRONG[name]
    gradient = sp.Tuple(F.h_u, F.h_v)
    return Theorem(
        id=f"gradient-{name}", title=f"The gradient of the {name} field",
        statement=(r"For $h = ⟦h⟧$" + (", $⟦s_1⟧$, $⟦s_2⟧$" if name != "rings" else "")
                   + f" (the renderer's {name} field): $⟦gradient⟧$."),
        steps=calc(gradient,
                   (f"The renderer's gradient of the {name} field (the formula compiled into its kernel) is "
                    "sympy's derivative of its $h$",
                    sp.Tuple(sp.Derivative(SHOWN[name], u), sp.Derivative(SHOWN[name], v))),
                   *_argument(name, closed_form)),
        claims={"gradient": (gradient, sp.Tuple(*closed_form))}, shown={"h": SHOWN[name]},
        where={F.h_u: F.GRADIENT[name][0], F.h_v: F.GRADIENT[name][1], **FACTORS}, domain=DOMAIN,
        evidence=partial(_gradient_evidence, name, closed_form, **evidence),
        wrong_variants=((description, lambda: _theorem(name, wrong).check()),
                        ("the kernel's h_u and h_v swapped",
                         lambda: _theorem(name, corrupt=lambda g: g[:, ::-1]).check()),
                        ("the kernel's gradient evaluated in float32",
                         lambda: _theorem(name, compiled=lambda g: [np.float32(x) for x in g]).check())),
        pages=("s3", "s5"),
    )


THEOREMS = tuple(_theorem(name) for name in ("sine", "ridges", "rings"))
