"""The exact gradients of the three height fields (seed §3) and the renderer's
generated code for them.

The theorems are about `renderer.formulas.GRADIENT` (sympy's derivatives of
`renderer.formulas.HEIGHT`) and its compiled evaluation
(`renderer.pointwise.exact_gradient`, the kernel's generated function); the
closed forms they are checked against are typed here from seed §3.
"""

import random
from functools import partial

import mpmath
import numpy as np
import sympy as sp

from renderer import formulas as F
from renderer import pointwise

from .core import DIGITS, POINTS, Identity, Theorem, Verdict, check_identities

u, v, k_u, k_v = F.u, F.v, F.k_u, F.k_v
s1, s2 = sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_v * v)
c1, c2 = sp.cos(sp.pi * k_u * u), sp.cos(sp.pi * k_v * v)
sigma = sp.sign(s1 * s2)
DOMAIN = {u: (0.0, 1.0), v: (0.0, 1.0), k_u: (0.5, 12.0), k_v: (0.5, 12.0)}

#: The closed forms as printed in seed §3.
PRINTED = {
    "sine": (sp.pi * k_u * c1 * s2, sp.pi * k_v * s1 * c2),
    "ridges": (sp.pi * k_u * c1 * s2 * sigma, sp.pi * k_v * s1 * c2 * sigma),
    "rings": (sp.Integer(0), 2 * sp.pi * k_v * sp.cos(2 * sp.pi * k_v * v)),
}

#: Wrong variants: a dropped factor, a flipped sign, a wrong frequency.
WRONG = {
    "sine": ("h_u without its factor sin(pi k_v v)", (sp.pi * k_u * c1, PRINTED["sine"][1])),
    "ridges": ("h_v with the sign factor dropped", (PRINTED["ridges"][0], sp.pi * k_v * s1 * c2)),
    "rings": ("h_v with the factor 2 lost", (sp.Integer(0), sp.pi * k_v * sp.cos(2 * sp.pi * k_v * v))),
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
    fn = sp.lambdify((u, v, k_u, k_v), list(closed_form), modules="mpmath")
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


def _gradient_check(name, closed_form, corrupt=None, compiled=None):
    """The check of theorem gradient-<name> against `closed_form` (h_u, h_v); `corrupt` alters the
    renderer's gradients, `compiled` the kernel's pointwise ones, first (wrong variants).  Theorems bind it with functools.partial, so that it
    runs when checked, not when the module is imported."""
    identities = [Identity(f"h_u ({name})", F.GRADIENT[name][0], closed_form[0], DOMAIN),
                  Identity(f"h_v ({name})", F.GRADIENT[name][1], closed_form[1], DOMAIN)]
    symbolic = check_identities(identities)
    if not symbolic.holds:
        return symbolic
    worst = generated_code_residual(name, closed_form, compiled=compiled)
    if worst > GENERATED_TOLERANCE:
        return Verdict("refuted", f"generated (compiled) gradient differs from the closed form by "
                       f"{worst:.2e} (relative to pi max(k_u, 2 k_v))", worst, DIGITS, POINTS)
    # The renderer's own gradients (GBuffer.grad) at its own (u, v) (proofs/pixels.py).
    from .pixels import gradient_error
    rendered = {method: gradient_error(name, method, corrupt) for method in ("exact", "central", "footprint")}
    if max(r for r, _ in rendered.values()) > 1:
        return Verdict("refuted", "the renderer's gradient leaves its tolerance by "
                       + ", ".join(f"{m} {r:.2g}x" for m, (r, _) in rendered.items()))
    return Verdict(symbolic.status, f"renderer.formulas.GRADIENT: {symbolic.evidence}; "
                   f"the kernel's generated code within "
                   f"{worst:.1e} of mpmath ({DIGITS} digits, {POINTS} points); the renderer's exact, central and "
                   f"footprint gradients (GBuffer.grad) at {rendered['exact'][1]} seeded sphere-A pixels within "
                   f"{rendered['exact'][0]:.2f}, {rendered['central'][0]:.2f} and {rendered['footprint'][0]:.2f} "
                   "of their tolerances against GRADIENT, CENTRAL (stencil included) and CENTRAL with "
                   "FOOTPRINT's steps at its (u, v)", worst, DIGITS, POINTS, rendered["exact"][1])


def _theorem(name):
    hu, hv = PRINTED[name]
    description, wrong = WRONG[name]
    return Theorem(
        id=f"gradient-{name}", title=f"The gradient of the {name} field",
        statement=(rf"For $h = {sp.latex(F.HEIGHT[name])}$: "
                   rf"$h_u = {sp.latex(hu)}$ and $h_v = {sp.latex(hv)}$, and the renderer's "
                   r"generated code evaluates them to float64 accuracy."),
        steps=((r"h_u", sp.Derivative(F.HEIGHT[name], u), F.GRADIENT[name][0]),
               (r"h_v", sp.Derivative(F.HEIGHT[name], v), F.GRADIENT[name][1])),
        check=partial(_gradient_check, name, PRINTED[name]),
        wrong_variants=((description, partial(_gradient_check, name, wrong)),
                        ("the kernel's h_u and h_v swapped",
                         partial(_gradient_check, name, PRINTED[name], corrupt=lambda g: g[:, ::-1])),
                        ("the kernel's gradient evaluated in float32",
                         partial(_gradient_check, name, PRINTED[name],
                                 compiled=lambda g: [np.float32(x) for x in g]))),
        pages=("s3", "s5"),
    )


THEOREMS = tuple(_theorem(name) for name in ("sine", "ridges", "rings"))
