"""The kink loci of the ridges field, seen by the camera: rays and circles.

The camera sits on the z-axis, so the z-axis projects to the image-plane
origin.  A point R N(theta, phi) of sphere A projects to

    (x, y) = rho(phi) (cos theta, sin theta),  rho(phi) = e R sin(phi) / (e - R cos(phi)),

so in polar coordinates (rho, alpha) about the origin, alpha = theta: the chart
u = (theta + pi) / 2 pi depends only on the angle, and v = phi / pi only on the
radius (rho is increasing on the visible cap cos(phi) > R / e).  The zero line
u = m / k_u is the ray alpha_m = 2 pi m / k_u - pi; the zero line v = m / k_v
is the circle rho_m = rho(pi m / k_v), visible when cos(pi m / k_v) > R / e.
"""

import numpy as np
import sympy as sp

from renderer import Scene, gbuffer, render
from renderer import formulas as F

from .core import Identity, Theorem, Verdict, check_identities
from .frame import ANGLE_NAMES, U_OF_THETA

theta, phi = sp.symbols("theta phi", real=True)
R, e = sp.symbols("R e", positive=True)
P = R * sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
#: Projection from the eye (0, 0, e) onto the image plane z = 0.
x_img = P[0] * e / (e - P[2])
y_img = P[1] * e / (e - P[2])
RHO = e * R * sp.sin(phi) / (e - R * sp.cos(phi))
DRHO = e * R * (e * sp.cos(phi) - R) / (e - R * sp.cos(phi)) ** 2
DOMAIN = {theta: (-3.1, 3.1), phi: (0.01, 1.2), R: (0.5, 1.0), e: (2.0, 6.0)}
#: The crease u = m / k_u solved for theta (the chart of theorem `chart`), which is alpha.
m_sym = sp.Symbol("m", integer=True)
ALPHA_M = sp.solve(sp.Eq(U_OF_THETA, m_sym / F.k_u), theta)[0]      # frame's theta is this module's
_ALPHA_M = sp.lambdify((m_sym, F.k_u), ALPHA_M, modules="numpy")


def _tex(expr):
    return sp.latex(expr, order="rev-lex", symbol_names=ANGLE_NAMES)


def ray_angles(k_u):
    """Image-plane angles alpha_m (radians, float64 array) of the rays u = m / k_u,
    m = 0 .. ceil(k_u) - 1 (`ALPHA_M`)."""
    return np.asarray(_ALPHA_M(np.arange(int(np.ceil(k_u))), k_u), dtype=float)


def circle_radii(radius_a, camera_z, k_v):
    """(phi_m, rho_m, visible) for the circles v = m / k_v with 0 < phi_m < pi."""
    m = np.arange(1, int(np.ceil(k_v)))
    phi_m = np.pi * m / k_v
    rho = camera_z * radius_a * np.sin(phi_m) / (camera_z - radius_a * np.cos(phi_m))
    return phi_m, rho, np.cos(phi_m) > radius_a / camera_z


def phi_of_rho(rho, radius_a, camera_z):
    """Invert rho(phi) on the visible cap: phi = asin(rho e / (R sqrt(e^2 + rho^2))) - atan2(rho, e)."""
    s = np.clip(rho * camera_z / (radius_a * np.hypot(camera_z, rho)), -1.0, 1.0)
    return np.arcsin(s) - np.arctan2(rho, camera_z)


#: The crease flag's two parts (`formulas.KINK_BAND`: a factor of `RIDGE_FACTORS`
#: below `KINK_BAND_HALF_WIDTH`), as functions of (u, k_u) and (v, k_v).
_PART = [sp.lambdify((var, k), sp.Abs(f) < F.KINK_BAND_HALF_WIDTH, modules="numpy")
         for var, k, f in ((F.u, F.k_u, F.RIDGE_FACTORS[0]), (F.v, F.k_v, F.RIDGE_FACTORS[1]))]


def predicted_parts(scene, width, height, shift=(0.0, 0.0)):
    """The two parts of the crease band predicted from the closed forms alone,
    on sphere A's pixels: the rays (u from the image angle) and the circles (v
    from the image radius); ``shift`` (in u, v) moves them, for wrong variants.
    Returns (u part, v part, on A), (H, W) bool arrays."""
    g = gbuffer(scene, width, height)
    X, Y = np.meshgrid(g.x, g.y)
    u = (np.arctan2(Y, X) + np.pi) / (2 * np.pi) + shift[0]
    v = phi_of_rho(np.hypot(X, Y), scene.radius_a, scene.camera_z) / np.pi + shift[1]
    on_a = g.chamber == 1
    return _PART[0](u, scene.k_u) & on_a, _PART[1](v, scene.k_v) & on_a, on_a


def part_mismatch(kind, scene=None, size=256, shift=(0.0, 0.0)):
    """(mismatched, in the part, compared): where the other part's closed form is off, the
    rendered kink flag against this part's closed form (rays: u; circles: v)."""
    scene = scene or Scene()
    u_part, v_part, on_a = predicted_parts(scene, size, size, shift)
    mine, other = (u_part, v_part) if kind == "rays" else (v_part, u_part)
    rendered = render(scene, size, size).kink
    where = on_a & ~other
    return (int(np.count_nonzero((rendered != mine) & where)), int(np.count_nonzero(mine & where)),
            int(np.count_nonzero(where)))


def _projection_identities(rho, drho):
    return [Identity("x", x_img, rho * sp.cos(theta), DOMAIN),
            Identity("y", y_img, rho * sp.sin(theta), DOMAIN),
            Identity(r"d\rho/d\varphi", sp.diff(RHO, phi), drho, DOMAIN)]


def _check(kind, rho=RHO, drho=DRHO, scene=None, shift=(0.0, 0.0)):
    symbolic = check_identities(_projection_identities(rho, drho))
    if not symbolic.holds:
        return symbolic
    scene = scene or Scene()
    mismatched, band, on_a = part_mismatch(kind, scene, shift=shift)
    if kind == "rays":
        loci = ", ".join(f"{a:+.4f}" for a in ray_angles(scene.k_u))
        what = f"{len(ray_angles(scene.k_u))} rays at alpha = {loci} (all visible)"
    else:
        phis, rhos, vis = circle_radii(scene.radius_a, scene.camera_z, scene.k_v)
        what = "; ".join(f"phi={p:.4f}: rho={r:.4f} ({'visible' if s else 'hidden'})"
                         for p, r, s in zip(phis, rhos, vis))
    part = "u-creases from the image angle" if kind == "rays" else "v-creases from the image radius"
    if mismatched > 0:
        return Verdict("refuted", f"{mismatched} of {on_a} sphere-A pixels: the rendered crease flag differs "
                       f"from the {part}")
    return Verdict(symbolic.status, f"{symbolic.evidence}; {what}; the {part} (closed form alone) equal the "
                   f"rendered crease flag on all {on_a} sphere-A pixels off the other family ({band} on a "
                   "crease) at 256x256")


KINK_LOCI_RAYS = Theorem(
    id="kink-loci-rays", title="The u-creases are rays",
    statement=r"In image-plane polar coordinates $(\rho, \alpha)$ about the projection of the "
              rf"$z$-axis, $\alpha = \theta$, so $u = {_tex(U_OF_THETA.subs(theta, sp.Symbol('alpha')))}$ "
              r"depends on the angle alone and the crease $u = m/k_u$ is the ray "
              rf"$\alpha_m = {_tex(ALPHA_M)}$.",
    steps=(("projection", r"(x, y)", sp.Matrix([x_img, y_img]).applyfunc(sp.simplify)),
           ("polar form", r"(x, y)", sp.Matrix([RHO * sp.cos(theta), RHO * sp.sin(theta)]))),
    check=lambda: _check("rays"),
    wrong_variants=(("projection with a flipped sign: e + R cos(phi) in the denominator",
                     lambda: _check("rays", rho=e * R * sp.sin(phi) / (e + R * sp.cos(phi)))),
                    ("the rays turned by half a period (u + 1/2k_u)",
                     lambda: _check("rays", shift=(0.5 / Scene().k_u, 0.0)))),
    pages=("s3", "s4"),
    seed_says="§3: the zero lines u = m/k_u are rays 'by Chapter 5's longitude theorem'.",
)

KINK_LOCI_CIRCLES = Theorem(
    id="kink-loci-circles", title="The v-creases are circles",
    statement=rf"$v = \varphi/\pi$ depends on the radius alone: $\rho(\varphi) = {_tex(RHO)}$ "
              rf"with $\rho'(\varphi) = {_tex(DRHO)} > 0$ on the visible cap "
              r"$\cos\varphi > R/e$. The crease $v = m/k_v$ is the circle of radius "
              r"$\rho(\pi m/k_v)$, visible when $\cos(\pi m/k_v) > R/e$.",
    steps=(("radius", r"\rho(\varphi)", RHO), ("monotone", r"\rho'(\varphi)", DRHO)),
    check=lambda: _check("circles"),
    wrong_variants=(("derivative with the factor e cos(phi) - R replaced by e - R cos(phi)",
                     lambda: _check("circles", drho=e * R / (e - R * sp.cos(phi)))),
                    ("the circles moved by half a period (v + 1/2k_v)",
                     lambda: _check("circles", shift=(0.0, 0.5 / Scene().k_v)))),
    pages=("s3", "s4"),
    seed_says="§3: the zero lines v = m/k_v are circles 'by its corollary'.",
)

THEOREMS = (KINK_LOCI_RAYS, KINK_LOCI_CIRCLES)
