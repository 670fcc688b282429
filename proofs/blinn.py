"""Blinn's perturbed normal, set for sphere A (seed §8; beyond the seed's code).

Blinn (1978, "Simulation of Wrinkled Surfaces", SIGGRAPH) displaces a
parametric surface P(u, v) by a bump function F along its unit normal,
P' = P + F N / |N| with N = P_u x P_v, drops the terms of P'_u x P'_v that
carry F itself (those with F d(N/|N|)/du or /dv), and keeps

    N' = N + (F_u (N x P_v) - F_v (N x P_u)) / |N|.

Here P(u, v) = R N(theta(u), phi(v)) in the renderer's chart (theorem `chart`:
u = (theta + pi) / 2 pi, v = phi / pi).  With that chart P_u x P_v points
*inward* (the frame is left-handed, theorem `frame-orientation`), so the
outward displacement P = (R + beta h) N of the renderer is F = -beta h; the
sign is computed, not assumed.

Each normal is compared through its slopes: its components along e_theta and
e_phi (`formulas.TANGENT_FRAME`, regular branch) divided by its component
along N.  They fix the unit normal and do not depend on its length or
orientation.  Blinn's slopes are -beta (h_u / (2 pi R sin phi), h_v / (pi R)),
exactly linear in beta; the displaced sphere's (`PERTURBED_NORMAL["surface"]`)
are the same with R replaced by R + beta h, so the two agree to first order and
differ at the second.  The draft's (`PERTURBED_NORMAL["chart"]`) are
+beta (h_u, h_v): to first order Blinn's times -2 pi R sin phi and -pi R.

The check also redoes Blinn's derivation for a general bump h(u, v): what his
formula drops from P'_u x P'_v is, to first order in beta, a multiple of N (on
the sphere 2 h / R times his N), so it changes the length of the normal and
not its direction; and the slopes of P'_u x P'_v are the renderer's surface
slopes at every beta.
"""

import sympy as sp

from renderer import formulas as F

from .core import Identity, Theorem, Verdict, check_identities
from .frame import (ANGLE_NAMES, CHART_RATES, N, ON_SPHERE, PHI_OF_V, THETA_OF_U, U_OF_THETA, V_OF_PHI, e_phi,
                    e_theta, phi, theta)

# ----------------------------------------------------------- Blinn's surface, his notation
_TO_ANGLES = {F.u: U_OF_THETA, F.v: V_OF_PHI}
#: Sphere A as a parametric surface P(u, v) of the renderer's chart.
P_UV = F.R * N.subs({theta: THETA_OF_U, phi: PHI_OF_V}, simultaneous=True)


def _at_angles(expr):
    return expr.subs(_TO_ANGLES, simultaneous=True).applyfunc(sp.simplify)


P_u, P_v = _at_angles(P_UV.diff(F.u)), _at_angles(P_UV.diff(F.v))
#: Blinn's unnormalised normal N = P_u x P_v.
N_BLINN = P_u.cross(P_v)
#: On 0 < phi < pi (the chart's range, theorem `chart`) |sin phi| = sin phi.
_OPEN = {sp.Abs(sp.sin(phi)): sp.sin(phi)}
NORM_N = sp.sqrt(sp.simplify(N_BLINN.dot(N_BLINN))).subs(_OPEN)
#: N / |N| = ORIENTATION * N(theta, phi): -1, P_u x P_v points into the sphere.
ORIENTATION = sp.simplify(N_BLINN.dot(N) / NORM_N)
#: The bump function that displaces P to (R + beta h) N:  F N / |N| = beta h N.
F_u, F_v = ORIENTATION * F.beta * F.h_u, ORIENTATION * F.beta * F.h_v


def blinn_normal(f_u=F_u, f_v=F_v, sign_v=-1):
    """Blinn's N' = N + (F_u (N x P_v) + sign_v F_v (N x P_u)) / |N| (his formula: sign_v = -1)."""
    return N_BLINN + (f_u * N_BLINN.cross(P_v) + sign_v * f_v * N_BLINN.cross(P_u)) / NORM_N


# ------------------------------------------------------------- Blinn's derivation, redone
_H = sp.Function("H")
#: The displaced surface P' = P + F N / |N| with F = ORIENTATION beta H(u, v), i.e. (R + beta H) N.
_P_DISPLACED = P_UV + ORIENTATION * F.beta * _H(F.u, F.v) * P_UV.diff(F.u).cross(P_UV.diff(F.v)) \
    / NORM_N.subs({theta: THETA_OF_U, phi: PHI_OF_V}, simultaneous=True)
_SYMBOLS = {sp.Derivative(_H(F.u, F.v), F.u): F.h_u, sp.Derivative(_H(F.u, F.v), F.v): F.h_v,
            _H(F.u, F.v): F.h}
#: P'_u x P'_v, the displaced surface's normal, in the renderer's h, h_u, h_v at N(theta, phi).
#: Not simplified here (slow, and nothing needs it): `slopes` and `dropped_terms` simplify what they take.
EXACT_NORMAL = _P_DISPLACED.diff(F.u).cross(_P_DISPLACED.diff(F.v)).subs(_SYMBOLS) \
    .subs(_TO_ANGLES, simultaneous=True)


def dropped_terms(normal):
    """d/dbeta at beta = 0 of P'_u x P'_v minus that of ``normal``: what Blinn's formula leaves out."""
    return (EXACT_NORMAL - normal).diff(F.beta).subs(F.beta, 0).applyfunc(sp.simplify)


# ------------------------------------------------------------------------------ slopes
def slopes(normal):
    """(n . e_theta / n . N, n . e_phi / n . N) of a normal n at N(theta, phi)."""
    along = normal.dot(N)
    return sp.Matrix([sp.simplify(sp.cancel(sp.together(normal.dot(e) / along))) for e in (e_theta, e_phi)])


#: The renderer's symbols at N(theta, phi), with the frame's regular branch.
_RENDERER_AT = {**ON_SPHERE, **dict(zip(F.e_theta, e_theta)), **dict(zip(F.e_phi, e_phi))}
#: bump="surface" floors sin phi at the pole cut-off; away from it the floor is sin phi.
_FLOOR = sp.Max(F.sin_phi, F.POLE_SIN_PHI)


def renderer_slopes(mode):
    """Slopes of `renderer.formulas.PERTURBED_NORMAL[mode]` at N(theta, phi), off the pole cut-off."""
    return slopes(sp.Matrix(F.PERTURBED_NORMAL[mode]).subs(_FLOOR, F.sin_phi).subs(_RENDERER_AT))


def first_order(s):
    """The coefficient of beta in the Taylor series of s at beta = 0."""
    return s.diff(F.beta).subs(F.beta, 0).applyfunc(sp.simplify)


BLINN = slopes(blinn_normal())
SURFACE, CHART = renderer_slopes("surface"), renderer_slopes("chart")
#: Blinn's dropped terms, d/dbeta at 0: a multiple of N (of his N = P_u x P_v, by 2 h / R).
DROPPED = dropped_terms(blinn_normal())
#: The draft's first-order slopes over Blinn's, claimed: -R sin(phi) / (du/dtheta) and
#: -R / (dv/dphi), with the chart's rates (theorem `chart`), i.e. -|P_u| and -|P_v|.
FACTORS = sp.Matrix([-F.R * sp.sin(phi) / CHART_RATES[0], -F.R / CHART_RATES[1]])

DOMAIN = {theta: (-3.1, 3.1), phi: (0.01, 3.13), F.R: (0.5, 2.0), F.beta: (0.0, 2.0),
          F.h: (-1.0, 1.0), F.h_u: (-30.0, 30.0), F.h_v: (-30.0, 30.0)}


def _identities(normal, factors, *, exact):
    blinn = slopes(normal)
    ids = [
        Identity(r"P_u\times P_v", N_BLINN, ORIENTATION * NORM_N * N, DOMAIN),
        Identity(r"\text{dropped terms}\times N", dropped_terms(normal).cross(N), sp.zeros(3, 1), DOMAIN),
        Identity(r"\text{slopes of }P'_u\times P'_v", slopes(EXACT_NORMAL), SURFACE, DOMAIN),
        Identity(r"\text{slopes at }\beta = 0", sp.Matrix([blinn, SURFACE, CHART]).subs(F.beta, 0),
                 sp.zeros(6, 1), DOMAIN),
        Identity(r"\text{first order: surface vs Blinn}", first_order(SURFACE), first_order(blinn), DOMAIN),
        Identity(r"\text{first order: draft vs Blinn}", first_order(CHART),
                 sp.matrix_multiply_elementwise(factors, first_order(blinn)), DOMAIN),
    ]
    if exact:   # the claim that Blinn's slopes are the displaced sphere's at every beta
        ids.append(Identity(r"\text{all orders: surface vs Blinn}", SURFACE, blinn, DOMAIN))
    else:       # what holds instead: R + beta h in the surface's, R in Blinn's
        ids.append(Identity(r"(R + \beta h)\,\text{surface} = R\,\text{Blinn}", (F.R + F.beta * F.h) * SURFACE,
                            F.R * blinn, DOMAIN))
    return ids


def _check(normal=None, factors=FACTORS, *, exact=False):
    if any(not c.has(_FLOOR) for c in F.PERTURBED_NORMAL["surface"]):
        return Verdict("refuted", "the surface bump's pole floor max(sin_phi, POLE_SIN_PHI) was not "
                       "found in renderer.formulas.PERTURBED_NORMAL['surface']")
    normal = blinn_normal() if normal is None else normal
    verdict = check_identities(_identities(normal, factors, exact=exact))
    if not verdict.holds:
        return verdict
    return Verdict(verdict.status,
                   f"{verdict.evidence} (P_u x P_v = {ORIENTATION} |N| N: inward, so F = -beta h; what Blinn's "
                   f"formula drops from P'_u x P'_v is along N to first order; the slopes of "
                   f"renderer.formulas.PERTURBED_NORMAL['surface'] are those of P'_u x P'_v, and its and "
                   f"['chart']'s against Blinn's to first order in beta)",
                   verdict.residual, verdict.digits, verdict.points)


def _tex(expr):
    return sp.latex(expr.subs(sp.sin(phi), F.sin_phi), symbol_names={**ANGLE_NAMES, F.sin_phi: r"\sin\varphi"})


def _slopes_tex(s):
    return rf"\bigl({_tex(s[0])},\ {_tex(s[1])}\bigr)"


BLINN_PERTURBATION = Theorem(
    id="blinn-perturbation", title="Blinn's perturbation on the sphere",
    statement=(
        r"Set Blinn's $N' = N + \bigl(F_u (N\times P_v) - F_v (N\times P_u)\bigr)/\lvert N\rvert$, "
        r"$N = P_u\times P_v$, for sphere A in the renderer's chart, "
        rf"$P(u, v) = R\,N(\theta, \varphi)$ with $\theta = {sp.latex(THETA_OF_U)}$, "
        rf"$\varphi = {sp.latex(PHI_OF_V)}$. Then $N = {_tex(ORIENTATION * NORM_N)}\,N(\theta, \varphi)$ "
        r"points inward, so the displacement $P \to (R + \beta h)N$ is $F = -\beta h$. "
        r"Measured as slopes (components along $e_\theta$, $e_\varphi$ over the component along $N$), "
        rf"Blinn's normal has ${_slopes_tex(BLINN)}$, the displaced sphere's "
        rf"(`PERTURBED_NORMAL['surface']`) ${_slopes_tex(SURFACE)}$ and the draft's "
        rf"(`PERTURBED_NORMAL['chart']`) ${_slopes_tex(CHART)}$. Blinn's equals the displaced "
        r"sphere's to first order in $\beta$ (not beyond: he drops the terms in $F$ itself); the "
        r"draft's first-order slopes are Blinn's times "
        rf"${_slopes_tex(FACTORS)}$: the opposite sign, and the chart's metric factors missing."),
    steps=(
        ("Blinn's normal", r"P_u\times P_v", rf"{_tex(ORIENTATION * NORM_N)}\,N(\theta, \varphi)"),
        ("what Blinn drops: along N to first order", r"\partial_\beta(P'_u\times P'_v - N'_{\mathrm{Blinn}})"
                                                      r"\big|_{\beta=0}",
         rf"{_tex(sp.simplify(DROPPED.dot(N)))}\,N(\theta, \varphi)"),
        ("Blinn's slopes", r"(t_\theta, t_\varphi)_{\mathrm{Blinn}}", _tex(sp.Tuple(*BLINN))),
        ("the displaced sphere's slopes", r"(t_\theta, t_\varphi)_{\mathrm{surface}}", _tex(sp.Tuple(*SURFACE))),
        ("the draft's slopes", r"(t_\theta, t_\varphi)_{\mathrm{chart}}", _tex(sp.Tuple(*CHART))),
        ("first order", r"\partial_\beta(t_\theta, t_\varphi)_{\mathrm{Blinn}}\big|_{\beta=0} = "
                        r"\partial_\beta(t_\theta, t_\varphi)_{\mathrm{surface}}\big|_{\beta=0}",
         _tex(sp.Tuple(*first_order(BLINN)))),
        ("the draft's factors", r"\partial_\beta t_{\mathrm{chart}} / \partial_\beta t_{\mathrm{Blinn}}",
         _tex(sp.Tuple(*FACTORS))),
    ),
    check=_check,
    wrong_variants=(
        ("Blinn's formula with the sign of the F_v term flipped", lambda: _check(blinn_normal(sign_v=+1))),
        ("the draft's chart bump equal to Blinn's to first order, without the factors",
         lambda: _check(factors=sp.ones(2, 1))),
        ("the draft's factors without the sign: +2 pi R sin(phi), +pi R", lambda: _check(factors=-FACTORS)),
        ("F = +beta h, ignoring that P_u x P_v points inward",
         lambda: _check(blinn_normal(-F_u, -F_v))),
        ("Blinn's normal equal to the displaced sphere's at every beta", lambda: _check(exact=True)),
    ),
    pages=("s8",),
    seed_says="§8: Blinn computed his perturbation exactly; finite differences are the folklore shortcut.",
)

THEOREMS = (BLINN_PERTURBATION,)
