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

from functools import lru_cache, partial

import numpy as np
import sympy as sp

from renderer import formulas as F
from renderer.scene import Scene

from .core import Dot, Step, Theorem, Verdict, catalogue, written
from .frame import PHI_OF_V, U_OF_THETA, V_OF_PHI

theta, phi = sp.symbols("theta phi", real=True)
R, e = sp.symbols("R e", positive=True)
P = R * sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
#: Projection from the eye (0, 0, e) onto the image plane z = 0.
x_img = P[0] * e / (e - P[2])
y_img = P[1] * e / (e - P[2])
#: rho(phi), the image radius of sphere A's circle of polar angle phi, and rho'(phi), as written (the
#: theorems print them so): e R sin(phi) / (e - R cos(phi)) and e R (e cos phi - R) / (e - R cos phi)^2;
#: `RHO` and `DRHO` are the same objects unwrapped, which the evidence evaluates.
RHO_SHOWN = written(sp.Mul(e, R, sp.sin(phi), sp.Pow(sp.Add(e, -R * sp.cos(phi), evaluate=False), -1), evaluate=False))
DRHO_SHOWN = written(sp.Mul(e, R, sp.Add(e * sp.cos(phi), -R, evaluate=False),
                            sp.Pow(sp.Add(e, -R * sp.cos(phi), evaluate=False), -2), evaluate=False))
RHO, DRHO = RHO_SHOWN.args[0], DRHO_SHOWN.args[0]
DOMAIN = {theta: (-3.1, 3.1), phi: (0.01, 1.2), R: (0.5, 1.0), e: (2.0, 6.0)}
m_sym = sp.Symbol("m", integer=True)
#: The zero lines u = m / k_u and v = m / k_v, and the circle's polar angle phi_m (v = m / k_v by the chart).
LINE_U, LINE_V = m_sym / F.k_u, m_sym / F.k_v
PHI_M = PHI_OF_V.subs(F.v, LINE_V)


@lru_cache(maxsize=None)
def ray_angle():
    """The crease u = m / k_u solved for theta (the chart of theorem `chart`), which is alpha, and
    it as a numpy function of (m, k_u)."""
    alpha = sp.solve(sp.Eq(U_OF_THETA, m_sym / F.k_u), theta)[0]      # frame's theta is this module's
    return alpha, sp.lambdify((m_sym, F.k_u), alpha, modules="numpy")


def ray_angles(k_u):
    """Image-plane angles alpha_m (radians, float64 array of ceil(k_u)) of the rays
    u = m / k_u, m = 0 .. ceil(k_u) - 1, from `ray_angle`."""
    return np.asarray(ray_angle()[1](np.arange(int(np.ceil(k_u))), k_u), dtype=float)


@lru_cache(maxsize=None)
def _circle_angle():
    """`PHI_M` (the chart's phi at v = m / k_v) as a numpy function of (m, k_v)."""
    return sp.lambdify((m_sym, F.k_v), PHI_M, modules="numpy")


def circle_angles(k_v):
    """Polar angles phi_m (radians, float64 array) of the circles v = m / k_v, m = 0 .. floor(k_v),
    from `PHI_M`: pi m / k_v; m = 0 is the north pole, the circle of radius 0."""
    return np.asarray(_circle_angle()(np.arange(int(np.floor(k_v)) + 1), k_v), dtype=float)


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
    """The crease band's half-width about a zero of sin(pi k t) (the ridges field's crease factors):
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
    from renderer import gbuffer
    from renderer.render import SPHERE_A
    g = gbuffer(scene, width, height)
    X, Y = np.meshgrid(g.x, g.y)
    on_a = g.chamber == SPHERE_A
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
    from renderer import render
    rendered = render(scene, size, size).kink
    where = on_a & ~other
    return (int(np.count_nonzero((rendered != mine.any(axis=0)) & where)),
            np.count_nonzero(mine & (rendered & where)[None], axis=(1, 2)), int(np.count_nonzero(where)))


def _loci(kind, shift=0.0, rho=RHO, drho=DRHO, scene=None, all_visible=False, band_scale=1.0):
    """Proved if the rendered crease flag is the bands about ``kind``'s loci (`part_mismatch`) and
    exactly the loci claimed visible have crease pixels; else refuted.  ``shift``, ``rho``,
    ``drho``, ``band_scale`` (`locus_bands`) and ``all_visible`` (claim every circle visible):
    wrong variants.  ``scene``: the book's, `Scene()`, by default."""
    scene = Scene() if scene is None else scene
    mismatched, per_locus, compared = part_mismatch(kind, scene, SIZE, shift, rho, drho, band_scale)
    if kind == "rays":
        seen = np.ones(len(per_locus), dtype=bool)             # every ray crosses the visible cap
        what = f"{len(per_locus)} rays at psi = " + ", ".join(f"{a:+.4f}" for a in ray_angles(scene.k_u))
    else:
        phis, rhos, seen = circle_radii(scene.radius_a, scene.camera_z, scene.k_v)
        seen = seen | all_visible
        what = "circles " + "; ".join(f"phi={p:.4f}: r={r:.4f} ({'visible' if s else 'hidden'})"
                                      for p, r, s in zip(phis, rhos, seen))
    family = "u-creases (rays)" if kind == "rays" else "v-creases (circles)"
    if mismatched > 0:
        return Verdict("refuted", f"{mismatched:,} of {compared:,} sphere-A pixels: the rendered crease flag differs "
                       f"from the {family} predicted from the loci")
    if not np.array_equal(per_locus > 0, seen):
        return Verdict("refuted", f"rendered crease pixels per locus {per_locus.tolist()}, but the loci "
                       f"claimed visible are {seen.tolist()}")
    return Verdict("proved", f"{what}; the bands about these loci (closed form alone) equal the rendered crease "
                   f"flag on all {compared:,} sphere-A pixels off the other family, and exactly the visible loci have "
                   f"crease pixels ({', '.join(map(str, per_locus))}) ({SIZE} × {SIZE})",
                   rendered=compared)


#: The quantities the proofs name: the image point (x, y), its radius rho(phi), the ray's angle alpha_m,
#: the eye O and the normal N.
X, Y = sp.symbols("x y", real=True)
ALPHA = sp.Symbol("psi", real=True)
rho = sp.Function("r")
alpha_m = sp.Symbol("psi_m")
O_S, N_S, P_S = (sp.MatrixSymbol(name, 3, 1) for name in "ONP")
NAMES = {alpha_m: r"\psi_m"}
#: The ray's angle as written: 2 pi m / k_u - pi.
ALPHA_SHOWN = written(sp.Add(2 * sp.pi * m_sym / F.k_u, -sp.pi, evaluate=False))


def _where(rho_, alpha=ALPHA_SHOWN):
    return {X: x_img, Y: y_img, rho(phi): rho_, alpha_m: alpha, O_S: sp.ImmutableMatrix([0, 0, e]),
            N_S: P / R, P_S: P}


def _rays(rho_=RHO_SHOWN, alpha=ALPHA_SHOWN, **evidence):
    """Theorem kink-loci-rays for the radius ``rho_``, the ray's angle ``alpha`` and the evidence's options
    (wrong variants)."""
    polar = sp.Tuple(rho(phi) * sp.cos(theta), rho(phi) * sp.sin(theta))
    ray = U_OF_THETA.subs(theta, alpha_m)
    return Theorem(
        id="kink-loci-rays", title=TITLES["kink-loci-rays"],
        statement=r"Seen from the eye $(0, 0, e)$, in image-plane polar coordinates $(r, \psi)$ about the projection of the $z$ axis, "
                  r"$⟦polar⟧$ with $⟦r⟧$: $⟦alpha⟧$, so $⟦u⟧$ depends on the angle "
                  r"alone, and the crease $⟦line_u⟧$ is the ray $⟦psi_m⟧$: $⟦ray⟧$.",
        steps=(
            Step(r"Project $P = R\,N(\theta, \varphi)$ from the eye $(0, 0, e)$ onto the image plane $z = 0$: its "
                 r"$x$ and $y$ scale by $e/(e - P_z)$, and $P_z = R\cos\varphi$", sp.Tuple(X, Y), polar,
                 defines=(rho(phi),)),
            Step(r"So the image point's polar angle $\psi$ is $\theta$, and $u = (\theta + \pi)/2\pi$, by ⟪chart⟫, "
                 r"is a function of $\psi$ alone; $u = m/k_u$ on the ray", ray, LINE_U,
                 defines=(alpha_m,)),
        ),
        claims={"polar": (sp.Tuple(X, Y), polar), "ray": (ray, LINE_U)},
        shown={"alpha": sp.Eq(ALPHA, theta), "u": sp.Eq(F.u, U_OF_THETA.subs(theta, ALPHA)), "line_u": sp.Eq(F.u, LINE_U)},
        where=_where(rho_, alpha), names=NAMES, domain={**DOMAIN, m_sym: (0.0, 8.0), F.k_u: (0.5, 12.0)},
        evidence=partial(_loci, "rays", **evidence),
        wrong_variants=(("projection with a flipped sign: e + R cos(phi) in the denominator",
                         lambda: _rays(e * R * sp.sin(phi) / (e + R * sp.cos(phi))).check()),
                        ("the rays turned by half a period (alpha + pi/k_u)",
                         lambda: _rays(shift=np.pi / Scene().k_u).check()),
                        ("the ray's angle with + pi (its last term), not - pi",
                         lambda: _rays(alpha=written(sp.Add(2 * sp.pi * m_sym / F.k_u, sp.pi, evaluate=False))).check())),
    )


def _circles(drho=DRHO_SHOWN, radius_term=-R, **evidence):
    """Theorem kink-loci-circles claiming rho' = ``drho`` and N . (O - P) = e cos(phi) + ``radius_term``, with
    the evidence's options (wrong variants)."""
    radius, slope, facing = X**2 + Y**2, sp.Derivative(rho(phi), phi), Dot(N_S, O_S - P_S)
    cap = written(sp.Add(e * sp.cos(phi), radius_term, evaluate=False))
    return Theorem(
        id="kink-loci-circles", title=TITLES["kink-loci-circles"],
        statement=r"$⟦v⟧$ depends on the image radius alone: $⟦radius⟧$, and $$⟦slope⟧$$ so "
                  r"$⟦rising⟧$ on the visible cap, where $⟦facing⟧$ is positive. The crease $⟦line_v⟧$ is the circle of "
                  r"radius $⟦rho_m⟧$, visible when $⟦visible⟧$.",
        steps=(
            Step(r"By ⟪kink-loci-rays⟫, $x^2 + y^2 = r(\varphi)^2 (\cos^2\theta + \sin^2\theta)$", radius,
                 rho(phi)**2),
            Step(r"Differentiate $r(\varphi) = eR\sin\varphi/(e - R\cos\varphi)$ with the quotient rule", slope,
                 drho),
            Step(r"The point $P = R N$ faces the eye $O = (0, 0, e)$ where $N \cdot (O - P) > 0$, that is "
                 r"$e\cos\varphi > R$: there $r' > 0$, so $r$ increases with $\varphi$ and each circle "
                 r"$\varphi = \pi m/k_v$ has one radius", facing, cap),
        ),
        claims={"radius": (radius, rho(phi)**2), "slope": (slope, drho), "facing": (facing, cap)},
        shown={"v": sp.Eq(F.v, V_OF_PHI), "rising": sp.Gt(slope, 0), "line_v": sp.Eq(F.v, LINE_V),
               "rho_m": rho(PHI_M), "visible": sp.Gt(sp.cos(PHI_M), R / e)},
        where=_where(RHO_SHOWN), names=NAMES, domain=DOMAIN, evidence=partial(_loci, "circles", **evidence),
        wrong_variants=(("derivative with the factor e cos(phi) - R replaced by e - R cos(phi)",
                         lambda: _circles(e * R / (e - R * sp.cos(phi))).check()),
                        ("the facing condition's last term -2R, not -R",
                         lambda: _circles(radius_term=-2 * R).check()),
                        ("the circles moved by half a period (phi + pi/2k_v)",
                         lambda: _circles(shift=np.pi / (2 * Scene().k_v)).check()),
                        ("the circles' bands twice as wide as the renderer's (the loci right, their bands not)",
                         lambda: _circles(band_scale=2.0).check()),
                        ("every circle claimed visible (the visibility condition dropped)",
                         lambda: _circles(all_visible=True).check()),
                        ("the radii with e + R cos(phi) in the projection's denominator",
                         lambda: _circles(rho=e * R * sp.sin(phi) / (e + R * sp.cos(phi))).check())),
    )


#: This module's theorems: id -> title.
TITLES = {"kink-loci-rays": "The u-creases are rays", "kink-loci-circles": "The v-creases are circles"}

titles, build = catalogue(TITLES, {"kink-loci-rays": _rays, "kink-loci-circles": _circles})
