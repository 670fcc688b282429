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

from functools import lru_cache

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
    """Image-plane angles alpha_m (radians, float64 array of ceil(k_u)) of the rays
    u = m / k_u, m = 0 .. ceil(k_u) - 1, from `ALPHA_M`."""
    return np.asarray(_ALPHA_M(np.arange(int(np.ceil(k_u))), k_u), dtype=float)


def circle_angles(k_v):
    """Polar angles phi_m = pi m / k_v (radians, float64 array) of the circles v = m / k_v,
    m = 0 .. floor(k_v); m = 0 is the north pole, the circle of radius 0."""
    return np.pi * np.arange(int(np.floor(k_v)) + 1) / k_v


@lru_cache(maxsize=None)
def _numeric(expr):
    """``expr`` in (phi, R, e) as a numpy function, made once per expression."""
    return sp.lambdify((phi, R, e), expr, modules="numpy")


def rho_of_phi(phi_, radius_a, camera_z, rho=RHO, drho=DRHO):
    """(rho, visible): the image radius of sphere A's circle of polar angle ``phi_``
    (float64 arrays of phi_'s shape), from the expression `RHO` the theorem checks, and
    whether it faces the camera: `DRHO` > 0, i.e. e cos(phi) > R.  ``rho``, ``drho``:
    other expressions in (phi, R, e), for wrong variants."""
    at = (np.asarray(phi_, dtype=float), radius_a, camera_z)
    return np.asarray(_numeric(rho)(*at), dtype=float), np.asarray(_numeric(drho)(*at) > 0)


def circle_radii(radius_a, camera_z, k_v):
    """(phi_m, rho_m, visible), float64, float64 and bool arrays, of the circles
    v = m / k_v (`circle_angles`, `rho_of_phi`)."""
    phi_m = circle_angles(k_v)
    return (phi_m, *rho_of_phi(phi_m, radius_a, camera_z))


def _half_width(k):
    """The crease band's half-width about a zero of sin(pi k t) (`formulas.RIDGE_FACTORS`):
    |sin(pi k (t - m/k))| < KINK_BAND_HALF_WIDTH, i.e. |t - m/k| < asin(w) / (pi k)."""
    return float(np.arcsin(float(F.KINK_BAND_HALF_WIDTH)) / (np.pi * k))


#: The frame the loci are compared on (pixels per side).
SIZE = 256
KINDS = ("rays", "circles")


def locus_bands(kind, scene, width, height, shift=0.0, rho=RHO, drho=DRHO, band_scale=1.0):
    """The crease band about each locus, predicted from the loci alone: for the rays, the
    pixels whose image angle is within 2 pi `_half_width`(k_u) of a ray's `ray_angles`
    (u = (alpha + pi) / 2 pi); for the circles, those whose image radius lies between the
    radii `rho_of_phi` gives at phi_m -+ pi `_half_width`(k_v) (v = phi / pi; to the limb
    when the outer edge is hidden, nothing when the inner one is).  ``shift`` moves every
    locus (radians of alpha or phi) and ``band_scale`` widens the bands, for wrong variants.
    Returns ((n, H, W) bool, one per locus, sphere A's pixels only; (H, W) bool, sphere A's
    pixels).  Source: seed §3 (the zero lines are rays and circles); the projection in this
    module's docstring.

    Raises
    ------
    ValueError
        ``kind`` is not "rays" or "circles".
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    g = gbuffer(scene, width, height)
    X, Y = np.meshgrid(g.x, g.y)
    on_a = g.chamber == 1
    if kind == "rays":
        off = np.angle(np.exp(1j * (np.arctan2(Y, X)[None] - ray_angles(scene.k_u)[:, None, None] - shift)))
        return (np.abs(off) < 2 * np.pi * band_scale * _half_width(scene.k_u)) & on_a, on_a
    r = np.hypot(X, Y)[None]
    phi_m = circle_angles(scene.k_v)[:, None, None] + shift
    half = np.pi * band_scale * _half_width(scene.k_v)
    (lo, lo_seen), (hi, hi_seen) = (rho_of_phi(phi_m + s * half, scene.radius_a,
                                               scene.camera_z, rho, drho) for s in (-1, 1))
    return lo_seen & (r > lo) & (~hi_seen | (r < hi)) & on_a, on_a


def part_mismatch(kind, scene, size, shift, rho, drho, band_scale):
    """(mismatched, pixels per locus, compared) at size x size: the rendered crease flag
    against the union of ``kind``'s `locus_bands`, on the sphere-A pixels off the other
    family's bands.  Pixels per locus: the rendered crease pixels in each locus's band
    there (int array)."""
    mine, on_a = locus_bands(kind, scene, size, size, shift, rho, drho, band_scale)
    other = locus_bands("circles" if kind == "rays" else "rays", scene, size, size)[0].any(axis=0)
    rendered = render(scene, size, size).kink
    where = on_a & ~other
    return (int(np.count_nonzero((rendered != mine.any(axis=0)) & where)),
            np.count_nonzero(mine & (rendered & where)[None], axis=(1, 2)), int(np.count_nonzero(where)))


def _projection_identities(rho, drho):
    return [Identity("x", x_img, rho * sp.cos(theta), DOMAIN),
            Identity("y", y_img, rho * sp.sin(theta), DOMAIN),
            Identity(r"d\rho/d\varphi", sp.diff(RHO, phi), drho, DOMAIN)]


#: What the loci's check is handed in a wrong variant that skips the identities.
PROVED = Verdict("proved", "(identities skipped)")


def _check(kind, rho=RHO, drho=DRHO):
    symbolic = check_identities(_projection_identities(rho, drho))
    return _loci(kind, symbolic) if symbolic.holds else symbolic


def _loci(kind, symbolic, shift=0.0, rho=RHO, drho=DRHO, scene=Scene(), all_visible=False, band_scale=1.0):
    """The identities' verdict ``symbolic``, kept if the rendered crease flag is the bands
    about ``kind``'s loci (`part_mismatch`) and exactly the loci claimed visible have
    crease pixels; else refuted.  ``all_visible`` (claim every circle visible) and
    ``band_scale`` (`locus_bands`): wrong variants."""
    from .book import frame_label
    mismatched, per_locus, compared = part_mismatch(kind, scene, SIZE, shift, rho, drho, band_scale)
    if kind == "rays":
        seen = np.ones(len(per_locus), dtype=bool)             # every ray crosses the visible cap
        what = f"{len(per_locus)} rays at alpha = " + ", ".join(f"{a:+.4f}" for a in ray_angles(scene.k_u))
    else:
        phis, rhos, seen = circle_radii(scene.radius_a, scene.camera_z, scene.k_v)
        seen = seen | all_visible
        what = "circles " + "; ".join(f"phi={p:.4f}: rho={r:.4f} ({'visible' if s else 'hidden'})"
                                      for p, r, s in zip(phis, rhos, seen))
    family = "u-creases (rays)" if kind == "rays" else "v-creases (circles)"
    if mismatched > 0:
        return Verdict("refuted", f"{mismatched} of {compared} sphere-A pixels: the rendered crease flag differs "
                       f"from the {family} predicted from the loci")
    if not np.array_equal(per_locus > 0, seen):
        return Verdict("refuted", f"rendered crease pixels per locus {per_locus.tolist()}, but the loci "
                       f"claimed visible are {seen.tolist()}")
    return Verdict(symbolic.status, f"{symbolic.evidence}; {what}; the bands about these loci (closed form "
                   f"alone) equal the rendered crease flag on all {compared} sphere-A pixels off the other "
                   f"family, and exactly the visible loci have crease pixels ({', '.join(map(str, per_locus))}) "
                   f"({frame_label(scene, SIZE, SIZE)})", rendered=compared)


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
                    ("the rays turned by half a period (alpha + pi/k_u)",
                     lambda: _loci("rays", PROVED, shift=np.pi / Scene().k_u))),
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
                    ("the circles moved by half a period (phi + pi/2k_v)",
                     lambda: _loci("circles", PROVED, shift=np.pi / (2 * Scene().k_v))),
                    ("the circles' bands twice as wide as the renderer's (the loci right, their bands not)",
                     lambda: _loci("circles", PROVED, band_scale=2.0)),
                    ("every circle claimed visible (the visibility condition dropped)",
                     lambda: _loci("circles", PROVED, all_visible=True)),
                    ("the radii with e + R cos(phi) in the projection's denominator",
                     lambda: _loci("circles", PROVED, rho=e * R * sp.sin(phi) / (e + R * sp.cos(phi))))),
    pages=("s3", "s4"),
    seed_says="§3: the zero lines v = m/k_v are circles 'by its corollary'.",
)

THEOREMS = (KINK_LOCI_RAYS, KINK_LOCI_CIRCLES)
