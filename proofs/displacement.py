"""Bump versus displacement (beyond the seed).

Displace sphere A along its normal, P = (R + beta H(theta, phi)) N.  Then,
exactly,

    P_phi x P_theta = (R + beta H)^2 sin(phi) [N - beta / (R + beta H) (H_theta / sin(phi) e_theta + H_phi e_phi)],

so the unit normal of the displaced surface is the normalisation of the
bracket.  In chart terms (H_theta = h_u / 2 pi, H_phi = h_v / pi) its tangential
part is -beta / (R + beta h) (h_u / (2 pi sin phi) e_theta + h_v / pi e_phi):
opposite in sign to the seed's +beta (h_u e_theta + h_v e_phi) and carrying the
metric factors 1 / (2 pi R sin phi) and 1 / (pi R).

Is the seed's N' the (first-order) normal of *some* displaced sphere
P = (R + beta G) N?  Matching tangential parts needs G_theta = -2 pi R sin(phi) h_theta
and G_phi = -pi R h_phi, which is integrable only if
2 cos(phi) h_theta + (2 sin(phi) - 1) h_theta_phi = 0 everywhere.  For the rings
field (h_theta = 0) it holds: the seed's rings bump is the first-order normal
of the sphere displaced by G = -pi R h.  For sine and ridges it fails, so the
seed's bump is the normal of no displaced sphere.

The renderer's bump="surface" is checked twice: its coefficients
(`renderer.formulas.BUMP["surface"]`, off the pole cut-off) equal the
bracket's in chart terms, with the chart's rates du/dtheta and dv/dphi taken
from `renderer.formulas.CHART` (theorem `chart`); and its rendered normals
equal the displaced surface's, evaluated by mpmath.
"""

import mpmath
import numpy as np
import sympy as sp

from renderer import formulas as F

from .core import Identity, Theorem, Verdict, check_identities
from .frame import CHART_RATES, PHI_OF_V, THETA_OF_U, U_OF_THETA, V_OF_PHI

theta, phi = sp.symbols("theta phi", real=True)
R, beta = sp.symbols("R beta", positive=True)
H = sp.Function("H")
N = sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
e_theta = sp.diff(N, theta) / sp.sin(phi)
e_phi = sp.diff(N, phi)
P = (R + beta * H(theta, phi)) * N
CROSS = sp.diff(P, phi).cross(sp.diff(P, theta))
H_t, H_p = sp.diff(H(theta, phi), theta), sp.diff(H(theta, phi), phi)
#: The tangential coefficients of the displaced normal: BRACKET = N + c_theta e_theta + c_phi e_phi.
COEFFS = (-beta / (R + beta * H(theta, phi)) * H_t / sp.sin(phi), -beta / (R + beta * H(theta, phi)) * H_p)
BRACKET = N + COEFFS[0] * e_theta + COEFFS[1] * e_phi
CLAIM = (R + beta * H(theta, phi)) ** 2 * sp.sin(phi) * BRACKET

#: The same coefficients in chart terms: H(theta, phi) = h(u, v) with the chart's rates
#: (theorem `chart`), H_theta = h_u du/dtheta and H_phi = h_v dv/dphi; in the renderer's symbols.
CHART_COEFFS = tuple(c.subs({H_t: F.h_u * CHART_RATES[0], H_p: F.h_v * CHART_RATES[1]})
                     .subs({H(theta, phi): F.h, sp.sin(phi): F.sin_phi, beta: F.beta, R: F.R})
                     for c in COEFFS)
#: The renderer's coefficients of bump="surface" (`renderer.formulas.BUMP`) away from
#: the pole cut-off, where its floor max(sin phi, POLE_SIN_PHI) is sin phi.
_FLOOR = sp.Max(F.sin_phi, F.POLE_SIN_PHI)


def away_from_pole(bump):
    """A bump's coefficients away from the pole cut-off.

    Parameters
    ----------
    bump : sequence of two sympy expressions
        (b_u, b_v), the coefficients of dpdu and dpdv in N' for one bump mode
        (`renderer.formulas.BUMP`), in the symbols of `renderer.formulas`.

    Returns
    -------
    tuple of two sympy expressions
        The same with the kernel's floor max(sin_phi, POLE_SIN_PHI) replaced by
        sin_phi: equal to the input wherever sin_phi > POLE_SIN_PHI (1e-4), the
        only region the symbolic identities below compare.  An expression
        without the floor comes back unchanged.  Source: the renderer's pole
        guard (seed §3, the 1/sin phi of the chart's v-derivative).
    """
    return tuple(b.subs(_FLOOR, F.sin_phi) for b in bump)


KERNEL_COEFFS = away_from_pole(F.BUMP["surface"])
KERNEL_DOMAIN = {F.beta: (0.0, 2.0), F.R: (0.5, 2.0), F.h: (-1.0, 1.0), F.h_u: (-30.0, 30.0),
                 F.h_v: (-30.0, 30.0), F.sin_phi: (0.001, 1.0)}


def _kernel_identities(coeffs):
    return [Identity(r"b_u\ (\text{surface})", coeffs[0], CHART_COEFFS[0], KERNEL_DOMAIN),
            Identity(r"b_v\ (\text{surface})", coeffs[1], CHART_COEFFS[1], KERNEL_DOMAIN)]

a, b = sp.symbols("a b", real=True)
INSTANCE = {H: sp.Lambda((theta, phi), sp.sin(a * theta) * sp.cos(b * phi) + sp.sin(phi))}
DOMAIN = {theta: (-3.0, 3.0), phi: (0.1, 3.0), R: (0.5, 2.0), beta: (0.0, 0.3),
          a: (1.0, 4.0), b: (1.0, 4.0)}


#: Which sphere P = (R + beta G) N has the seed's bump (`renderer.formulas.BUMP["chart"]`) as
#: its normal to first order in beta?  Its gradient (G_theta, G_phi), solved from COEFFS's first
#: order (H -> G) against the chart bump's coefficients in angular terms (h_u = H_theta / (du/dtheta),
#: h_v = H_phi / (dv/dphi), the chart's rates of theorem `chart`).
_G_t, _G_p = sp.symbols("G_theta G_phi")
_SEED_ANGULAR = tuple(b.subs(F.beta, 1).subs({F.h_u: H_t / CHART_RATES[0], F.h_v: H_p / CHART_RATES[1]})
                      for b in F.BUMP["chart"])
SEED_DISPLACEMENT = tuple(sp.solve([sp.diff(c, beta).subs(beta, 0).subs({H_t: _G_t, H_p: _G_p}) - s_
                                    for c, s_ in zip(COEFFS, _SEED_ANGULAR)], [_G_t, _G_p], dict=True)[0][g]
                          for g in (_G_t, _G_p))
#: G exists only where its gradient is curl-free: d/dphi G_theta - d/dtheta G_phi = 0.
CURL = sp.diff(SEED_DISPLACEMENT[0], phi) - sp.diff(SEED_DISPLACEMENT[1], theta)
#: The statement's obstruction, for a general H; CURL is -pi R times it (an identity of the check).
OBSTRUCTION = 2 * sp.cos(phi) * H_t + (2 * sp.sin(phi) - 1) * sp.diff(H_t, phi)
INTEGRABLE = ("rings",)


def _angular(field):
    """The field's height h(u, v) at the chart's (u, v) of (theta, phi), k_u and k_v symbolic."""
    return F.HEIGHT[field].subs({F.u: U_OF_THETA, F.v: V_OF_PHI})


def integrability_obstruction(field):
    """`OBSTRUCTION`, 2 cos(phi) h_theta + (2 sin(phi) - 1) h_theta_phi, for a field of
    `renderer.formulas.HEIGHT` (sympy expression in theta, phi, k_u, k_v): zero exactly
    when the seed's bump on that field is the first-order normal of a displaced sphere."""
    return sp.simplify(OBSTRUCTION.subs(H, sp.Lambda((theta, phi), _angular(field))).doit())




def surface_normal_residual(bump, gradient, fields=("sine", "ridges", "rings")):
    """(worst |N'_renderer - N'_exact|, pixels compared, pixels left out) for the renderer's
    `bump` ('surface' is the one claimed to be the displaced normal) and `gradient`
    ('exact'; 'central' differs by its truncation error).

    The pixels are `proofs.pixels.pixels` (seeded: full frame, pole ring at zoom 300 and
    3e4, crease neighbours) of each field.  N'_exact normalises P_v x P_u of
    P(u, v) = (R + beta h(u, v)) N(theta(u), phi(v)) at the pixel's (u, v), in mpmath at
    `pixels.DIGITS` digits (P_v x P_u = (dtheta/du)(dphi/dv) P_phi x P_theta, an outward
    normal); N'_renderer is the G-buffer's Ns.  Pixels with sin phi <= `formulas.POLE_SIN_PHI`,
    where the renderer floors sin phi by design, are left out (and counted).
    """
    from .pixels import DIGITS, pixels
    worst, compared, left_out = 0.0, 0, 0
    for field in fields:
        scene, px = pixels(field, gradient, bump)
        P = (scene.radius_a + scene.beta * F.HEIGHT[field].subs({F.k_u: scene.k_u, F.k_v: scene.k_v})) \
            * N.subs({theta: THETA_OF_U, phi: PHI_OF_V}, simultaneous=True)
        fn = sp.lambdify((F.u, F.v), list(sp.diff(P, F.v).cross(sp.diff(P, F.u))), modules="mpmath")
        keep = np.sin(np.pi * px["uv"][:, 1]) > float(F.POLE_SIN_PHI)
        compared, left_out = compared + int(np.count_nonzero(keep)), left_out + int(np.count_nonzero(~keep))
        for (uu, vv), got in zip(px["uv"][keep], px["Ns"][keep]):
            with mpmath.workdps(DIGITS):
                c = fn(mpmath.mpf(float(uu)), mpmath.mpf(float(vv)))
                n = mpmath.sqrt(sum(x * x for x in c))
                worst = max(worst, max(float(abs(mpmath.mpf(float(gk)) - ck / n)) for gk, ck in zip(got, c)))
    return worst, compared, left_out


def _check(claim, kernel=KERNEL_COEFFS, integrable=INTEGRABLE, bump="surface", gradient="exact"):
    """The theorem's check: the cross product `claim`, the renderer's surface-bump coefficients
    `kernel` (pole floor read away), which fields' seed bump is a displacement's normal
    (`integrable`), and the rendered normals of `bump` and `gradient` against the displaced
    surface's."""
    if any(b.has(sp.Max) for b in kernel):
        return Verdict("refuted", f"a floor other than max(sin_phi, POLE_SIN_PHI) in the surface bump: {kernel}")
    rings = _angular("rings")
    symbolic = check_identities(
        [Identity("P_phi x P_theta", CROSS, claim, DOMAIN, INSTANCE)] + _kernel_identities(kernel)
        + [Identity("curl of the seed's G", CURL, -sp.pi * R * OBSTRUCTION, DOMAIN, INSTANCE),
           Identity("G_theta (rings)", SEED_DISPLACEMENT[0].subs(H, sp.Lambda((theta, phi), rings)).doit(),
                    sp.diff(-sp.pi * R * rings, theta), DOMAIN),
           Identity("G_phi (rings)", SEED_DISPLACEMENT[1].subs(H, sp.Lambda((theta, phi), rings)).doit(),
                    sp.diff(-sp.pi * R * rings, phi), DOMAIN)])
    if not symbolic.holds:
        return symbolic
    obstruction = {f: integrability_obstruction(f) for f in ("sine", "ridges", "rings")}
    found = tuple(f for f, o in obstruction.items() if o == 0)
    if set(found) != set(integrable):
        return Verdict("refuted", f"the seed's bump is a displaced sphere's normal for {found or 'no field'}, "
                       f"not {integrable}: integrability obstructions {obstruction}")
    worst, compared, left_out = surface_normal_residual(bump, gradient)
    if worst > 1e-12:
        return Verdict("refuted", f"renderer's bump={bump!r}, gradient={gradient!r} normal differs from the displaced "
                       f"surface's by {worst:.2e}", worst, rendered=compared)
    return Verdict(symbolic.status,
                   f"{symbolic.evidence} (the cross product, renderer.formulas.BUMP['surface'] "
                   f"against its chart form, and the curl of the G whose sphere has the seed's bump as "
                   f"normal, G = -pi R h for rings); obstruction is 0 for {', '.join(found)} only (the "
                   f"seed's bump is the normal of no displaced sphere for the others); "
                   f"renderer's bump='surface' Ns within {worst:.1e} of the displaced normal (mpmath, "
                   f"{compared} seeded sphere-A pixels of the three fields, pole ring and crease neighbours "
                   f"included; {left_out} inside the pole floor sin phi <= {float(F.POLE_SIN_PHI):g} left out)",
                   rendered=compared)


BUMP_VS_DISPLACEMENT = Theorem(
    id="bump-vs-displacement", title="Bump versus displacement",
    statement=r"For $P = (R + \beta H)N$: $P_\varphi \times P_\theta = (R+\beta H)^2\sin\varphi\,"
              r"\bigl[N - \tfrac{\beta}{R + \beta H}\bigl(\tfrac{H_\theta}{\sin\varphi}e_\theta + "
              r"H_\varphi e_\varphi\bigr)\bigr]$. In chart terms the displaced normal's tangential "
              r"part is $-\tfrac{\beta}{R+\beta h}\bigl(\tfrac{h_u}{2\pi\sin\varphi}e_\theta + "
              r"\tfrac{h_v}{\pi}e_\varphi\bigr)$, against the seed's $+\beta(h_u e_\theta + h_v e_\varphi)$: "
              r"opposite sign, and the chart's metric factors missing; the renderer's "
              r"`bump='surface'` (`renderer.formulas.BUMP['surface']`) is the displaced normal's. "
              r"The seed's bump is, to first "
              r"order, the normal of the sphere displaced by $G = -\pi R h$ for the rings field, and "
              r"of no displaced sphere for the sine and ridges fields.",
    steps=(("cross product", r"P_\varphi \times P_\theta", CLAIM),
           ("obstruction (sine)", r"2\cos\varphi\,h_\theta + (2\sin\varphi - 1)h_{\theta\varphi}",
            integrability_obstruction("sine")),
           ("obstruction (rings)", r"2\cos\varphi\,h_\theta + (2\sin\varphi - 1)h_{\theta\varphi}",
            integrability_obstruction("rings")),
           ("the renderer's surface bump", r"(b_u, b_v)", sp.Tuple(*KERNEL_COEFFS))),
    check=lambda: _check(CLAIM),
    wrong_variants=(("the renderer's chart bump (the seed's) as the displaced normal's coefficients",
                     lambda: _check(CLAIM, kernel=F.BUMP["chart"])),
                    ("a surface bump floored at sin phi = 1e-3, not POLE_SIN_PHI",
                     lambda: _check(CLAIM, kernel=away_from_pole(
                         tuple(b.subs(F.POLE_SIN_PHI, sp.Float(1e-3)) for b in F.BUMP["surface"])))),
                    ("the seed's bump the normal of a displaced sphere for every field",
                     lambda: _check(CLAIM, integrable=("sine", "ridges", "rings"))),
                    ("the renderer's bump='chart' normals as the displaced surface's",
                     lambda: _check(CLAIM, bump="chart")),
                    ("the numeric pipeline's bump='surface' normals (central differences) as exactly the "
                     "displaced surface's", lambda: _check(CLAIM, gradient="central")),
                    ("the seed's reading: the bump is the displaced normal (+ sign, no metric)",
                     lambda: _check((R + beta * H(theta, phi)) ** 2 * sp.sin(phi)
                                    * (N + beta * (2 * sp.pi * H_t * e_theta + sp.pi * H_p * e_phi)))),),
    pages=("s3", "s7"),
    seed_says="§3 and Cell 8 present the bump as the shading-side stand-in for displacement.",
)

THEOREMS = (BUMP_VS_DISPLACEMENT,)
