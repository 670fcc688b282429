"""The §4 simulator's JavaScript renderer against Python's `render`, under node.

Acceptance grid: every field, both models, every gradient method, both bump
modes, beta = 0, sphere B on and off, eps from 1e-1 down to 1e-10, the pole
magnified.  Per frame: chamber codes identical; crease flags identical except
at band-edge pixels (below); the chart (u, v), the gradient and the image
within the tolerances of the error model below.  Each check is shown
rejecting a wrong variant of the JavaScript at the end of the file.

Error model
-----------
Both sides take the same steps with the same operations in the same order:
kernel.py's steps are written out alike in render.js, and sphere A's formulas
are printed from the same sympy objects (renderer/codegen.py).  IEEE 754
rounds +, -, *, / and sqrt correctly, so whatever uses only those is the same
bits on both sides: the hits and their chamber (checked exactly), P, N, the
shadow tests, the footprint's steps given the same sin(phi).  What differs:

(a) the libraries.  numba calls glibc's sin, cos, atan2, hypot and pow; V8 its
    port of fdlibm's (and its own Math.hypot).  Each returns a value within 1
    ulp of the exact result, so two results for one argument are at most 1 ulp
    apart.  (An integral shininess n is raised by repeated squaring on both
    sides, in numba's order: the same bits for the same base.);
(b) the printers.  formulas.js normalises with Math.pow(s, -1/2) and squares
    with Math.pow(x, 2) where generated.py has 1/math.sqrt(s) and x**2.

With u = 2^-53 the unit roundoff and L = formulas.gradient_scale (pi max(k_u, 2 k_v)), which bounds
the slope pi k of every sine argument and |h_u|, |h_v| (L^2 bounds h's
second derivatives), the differences propagate as follows (each step a
worst-case sum, rounded up):

1. Chart: |du|, |dv| <= CHART_TOL = 6u.  u = (atan2 + pi) / 2 pi: atan2's ulp
   is <= 4u on [-pi, pi], the sum rounds afresh (2u 2 pi over both sides),
   / 2 pi and one more rounding (2u): 4.7u.  v = atan2(sin phi, N_z) / pi:
   4u, plus 3u for sin phi = hypot(N_x, N_y) (a), / pi, plus 2u: 4.3u.
2. A sine's argument a = (pi k) w, w = u, v or a stencil point (u +- eps
   wrapped, v +- eps clamped: two roundings of values <= 1.25 per side, 5u,
   and 2u for a footprint step that moved by (b)): |da| <= pi k (6u + 7u) +
   2u |a| <= ARG = 16 L u.
3. A sine or cosine: <= ARG + u (1-Lipschitz, plus (a)).
4. h, a product of <= 2 of them (|.| for ridges): |dh| <= DH = 2 ARG + 4u.
5. Exact gradient, pi k times <= 2 of them and a sign: |dg| <= L (2 ARG + 8u),
   except where the ridges' sign factor sign(sin a_u sin a_v) can flip: a
   multiple of pi within ARG of a, and the two sides' (u, v) not the same
   bits (the same bits give the same a, and a faithful sine keeps the sign of
   the exact one) ("crease-sign" pixels, exempt).
6. Central gradient with steps (eps_u, eps_v): (S+ - S-) / 2 eps moves by
   (DH + 2u) / eps, plus 10u |g| for the quotient's roundings and a
   footprint step's (b); where v clamps the quotient is divided by
   v+ - v- >= eps_v, itself moved by <= 28u: (2 DH + 4u + 28u |g_v|) / eps_v.
   Except where a stencil branch (u wraps, v clamps) can go the other way:
   u + eps_u - 1, eps_u - u, eps_v - v or v + eps_v - 1 within 32u of 0
   ("stencil-branch" pixels, exempt).
7. Shading normal Ns = M / |M|.  |M| >= 1/2 (N is orthogonal to the frame,
   and nearly so under the pole fallback) and |a/|a| - b/|b|| <= 2|a - b|/|a|,
   so |dNs| <= 4 |dM| + 8u (8u: the normalisation, (b)).  Chart bump:
   |dM| <= beta (|dg_u| + |dg_v|) + 12u (1 + beta (|g_u| + |g_v|)).  Surface
   bump, M = N - t_u e_theta - t_v e_phi with t_u = q h_u / (2 sin phi) (0 at
   the pole, sin phi <= POLE_SIN_PHI), t_v = q h_v, q = beta / (pi (R + beta h)): the same with
   q / (2 s) and q for beta, plus (|t_u| + |t_v|)(beta DH / (R + beta h) + 12u).
   (The coefficients and their slopes in h_u, h_v and h are formulas.BUMP's,
   evaluated, not retyped.)  At beta = 0, M = N and only the roundings
   remain: both sides normalise N, by different printers (b).
8. Image, per light of colour c, at Python's mu = Ns . w and specular cosine
   (Blinn Ns . h / |h|, Phong 2 mu (Ns . v) - w . v): mu moves by dmu = dNs +
   6u, the cosine by dcos = m dNs + 24u (m = 1 Blinn, 4 Phong).  The lobe x^n
   moves by its largest slope on the cosine's interval, n b^(n-1) with
   b = clip(cos + dcos, 0, 1), times dcos, plus its own rounding on both
   sides, 2 n u b^n (any chain of n - 1 products is within (n - 1) u; a
   non-integral n's pow within 1 ulp).  So a light on for both sides (mu >
   dmu + 8u, 8u for mu's own rounding here) adds c (kd dmu + ks (n b^(n-1)
   dcos + 2 n u b^n)), one off for both (mu < -(dmu + 8u)) nothing, and one
   whose mu is within dmu + 8u of 0 (a "terminator" pixel: on for one side
   only) its whole contribution, c (kd (|mu| + dmu) + ks b^n).  Plus 4u
   (lights + 1)(ka ambient + sum_l c (kd + ks)) for the sums' roundings and a
   non-integral pow, everywhere (off sphere A only this: Ns = N there).
   Clipping is 1-Lipschitz.
9. Crease flag |sin a| < 0.03: can differ only where ||sin a| - 0.03| <=
   ARG + 2 ulp(0.03) for a ridge factor and (u, v) differ ("band-edge"
   pixels, exempt from the flag check).

The margins of 5 and 9 are computed with mpmath at the float arguments the
Python side used; those of 6 and 8 in float64 with their rounding inside the
stated slack.  At most MAX_EXEMPT pixels per frame may be exempt of each
kind, so an exemption cannot swallow a frame.  The measured
worst |d|/tolerance and the smallest margin/threshold of every case are
written to test-artifacts/js_parity.md.

At eps = 1e-10 the central tolerance is large (a last-bit difference of h
divided by eps): that is the U-curve of §7, not a defect of the twin.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from mpmath import mp, mpf

from renderer import GRADIENTS, PointLight, Scene, gbuffer, pointwise, render
from renderer import formulas as F
from renderer.render import WINDOW_MARGIN

from .jsnode import ARTIFACTS, read_frame, run_render_cases, write_modules

U = 2.0**-53                    # unit roundoff of float64
CHART_TOL = 6 * U               # step 1
MAX_EXEMPT = 2                  # exempt pixels of one kind per frame
SPHERE_A = 1
POLE_SIN_PHI = float(F.POLE_SIN_PHI)
KINK_BAND_HALF_WIDTH = float(F.KINK_BAND_HALF_WIDTH)


def _bump_functions():
    """Per bump mode, numpy functions of (beta, R, h, h_u, h_v, sin phi) giving
    the coefficients (t_u, t_v) of M = N + t_u e_theta + t_v e_phi
    (`formulas.BUMP`) and their derivatives in h_u, h_v and h (sympy's), for
    the error model of step 7."""
    args = (F.beta, F.R, F.h, F.h_u, F.h_v, F.sin_phi)
    out = {}
    for mode, coefficients in F.BUMP.items():
        exprs = [sp.sympify(b) for b in coefficients]
        parts = {"b": exprs, **{str(x): [sp.diff(b, x) for b in exprs] for x in (F.h_u, F.h_v, F.h)}}
        out[mode] = {key: sp.lambdify(args, tuple(e), "numpy") for key, e in parts.items()}
    return out


BUMP = _bump_functions()

#: (id, scene, width, height, gradient, zoom); non-square sizes catch a transposed
#: image, odd widths put a pixel column exactly on x = 0 (the seam's meridian).
CASES = [
    ("default-central", Scene(), 96, 80, "central", 1.0),
    ("default-exact", Scene(), 96, 80, "exact", 1.0),
    ("default-footprint", Scene(), 96, 80, "footprint", 1.0),
    ("sine-phong-eps1e-1", Scene(height_field="sine", model="phong", eps=1e-1), 96, 80, "central", 1.0),
    ("sine-exact-beta1.5", Scene(height_field="sine", beta=1.5, bump="chart"), 96, 80, "exact", 1.0),
    ("rings-eps1e-10-noB", Scene(height_field="rings", eps=1e-10, sphere_b=False), 96, 80, "central", 1.0),
    ("rings-phong-exact-nofloor", Scene(height_field="rings", model="phong", floor=False), 96, 80, "exact", 1.0),
    ("ridges-eps1e-6-beta0", Scene(eps=1e-6, beta=0.0), 96, 80, "central", 1.0),
    ("ridges-exact-beta0-noB", Scene(beta=0.0, sphere_b=False), 96, 80, "exact", 1.0),
    ("sine-eps1e-8-surface", Scene(height_field="sine", eps=1e-8, bump="surface", beta=0.5), 96, 80,
     "central", 1.0),
    ("rings-eps1e-4-pole-x8", Scene(height_field="rings", eps=1e-4), 96, 80, "central", 8.0),
    ("rings-footprint-pole-x8", Scene(height_field="rings"), 96, 80, "footprint", 8.0),
    ("sine-phong-footprint-surface", Scene(height_field="sine", model="phong", bump="surface", beta=0.5),
     99, 61, "footprint", 1.0),
    ("ridges-phong-eps1e-10-k5x3", Scene(model="phong", eps=1e-10, k_u=5.0, k_v=3.0), 99, 61,
     "central", 1.0),
    ("ridges-exact-odd", Scene(), 99, 61, "exact", 1.0),
    ("sine-eps1e-2-lights", Scene(height_field="sine", eps=1e-2, lights=(
        PointLight((5.0, 5.0, 10.0), (1.0, 1.0, 1.0)), PointLight((0.0, 3.0, -2.0), (0.5, 0.5, 0.5)),
        PointLight((-6.0, 2.0, 8.0), (0.0, 0.0, 0.0)))), 96, 80, "central", 1.0),
    ("default-central-256", Scene(), 256, 256, "central", 1.0),
    # A shininess that is not an integer: pow on both sides, not repeated squaring.
    ("sine-phong-shininess7.5", Scene(height_field="sine", model="phong", shininess=7.5), 64, 48,
     "central", 1.0),
]


def field_cases(cases, fields):
    """Cases for each of ``fields`` that no case of ``cases`` renders (a field newly registered in
    renderer/formulas.py): central and exact, at the book's other defaults."""
    named = {c[1].height_field for c in cases}
    return [(f"{name}-{g}", Scene(height_field=name), 64, 48, g, 1.0)
            for name in fields if name not in named for g in ("central", "exact")]


CASES += field_cases(CASES, F.BUILTIN)


# ---- the error model -----------------------------------------------------------------

def slope(scene):
    """L = `formulas.gradient_scale` (pi max(k_u, 2 k_v) for the built-in fields): the largest rate of a sine's
    argument, and a bound of |grad h|."""
    return F.gradient_scale(scene.k_u, scene.k_v)


def arg_tol(scene):
    """Step 2: how far a sine's argument may move between the two sides."""
    return 16.0 * slope(scene) * U


def height_tol(scene):
    """Step 4: |dh|."""
    return 2.0 * arg_tol(scene) + 4.0 * U


def grad_tolerance(scene, gradient, g, uv, steps):
    """Step 5 (exact) or 6 (central, footprint): allowed |dg|, (..., 2), at
    Python's gradient ``g``, chart ``uv`` and steps ``steps`` (..., 2)."""
    if gradient == "exact":
        return np.full(g.shape, slope(scene) * (2.0 * arg_tol(scene) + 8.0 * U))
    dh, ag = height_tol(scene), np.abs(g)
    eu, ev, v = steps[..., 0], steps[..., 1], uv[..., 1]
    clamped = (ev - v > 0.0) | (ev + v > 1.0)
    tu = (dh + 2.0 * U) / eu + 10.0 * U * ag[..., 0]
    tv = np.where(clamped, (2.0 * dh + 4.0 * U + 28.0 * U * ag[..., 1]) / ev, (dh + 2.0 * U) / ev) \
        + 10.0 * U * ag[..., 1]
    return np.stack([tu, tv], axis=-1)


def normal_tolerance(scene, g, dg, h, sin_phi):
    """Step 7: allowed |dNs| given Python's gradient ``g``, its bound ``dg``,
    h and sin(phi) per pixel.  The coefficients (t_u, t_v) of M and their
    slopes in h_u, h_v and h are `formulas.BUMP` of the scene's mode, evaluated."""
    f = BUMP[scene.bump]
    at = (scene.beta, scene.radius_a, h, g[..., 0], g[..., 1], sin_phi)
    size = lambda values: sum(np.abs(np.broadcast_to(c, h.shape)) for c in values)  # noqa: E731
    b = size(f["b"](*at))
    dM = (size(f["h_u"](*at)) * dg[..., 0] + size(f["h_v"](*at)) * dg[..., 1] + size(f["h"](*at)) * height_tol(scene)
          + 12.0 * U * (1.0 + b))
    if scene.bump == "surface":
        dM = dM + 12.0 * U * b              # the roundings of b's own factors
    return 4.0 * dM + 8.0 * U


def _lights(scene):
    return [l for l in scene.lights if any(l.color)]


def mu_tolerance(d_ns):
    """Step 8: how far mu = Ns . w may move."""
    return d_ns + 6.0 * U * (d_ns > 0)


def image_tolerance(scene, on_a, P, Ns, d_ns):
    """Step 8: allowed |dI| (H, W, 3), and per pixel of sphere A the smallest
    |mu| / (dmu + 8u) over the lights (<= 1: a terminator pixel).  ``P``,
    ``Ns``: Python's hit points and shading normals on sphere A (n, 3);
    ``d_ns``: the bound of |dNs| there (n,)."""
    lights = _lights(scene)
    n = scene.shininess
    rounding = scene.ka * np.array(scene.ambient)
    for light in lights:
        rounding = rounding + np.array(light.color) * (scene.kd + scene.ks)
    tol = np.broadcast_to(4.0 * U * (len(lights) + 1) * rounding, on_a.shape + (3,)).copy()
    ratio = np.full(len(P), np.inf)
    varies = d_ns > 0
    if not varies.any():                    # Ns = N on both sides: the same bits but for pow
        return tol, ratio
    unit = lambda a: a / np.maximum(np.linalg.norm(a, axis=-1, keepdims=True), 1e-300)  # noqa: E731
    view = unit(np.array([0.0, 0.0, scene.camera_z]) - P)
    d_mu = mu_tolerance(d_ns)
    d_cos = (4.0 if scene.model == "phong" else 1.0) * d_ns + 24.0 * U
    extra = np.zeros((len(P), 3))
    for light in lights:
        c = np.array(light.color)
        w = unit(np.array(light.position) - P)
        mu = np.sum(Ns * w, axis=-1)
        if scene.model == "phong":
            cos = 2.0 * mu * np.sum(Ns * view, axis=-1) - np.sum(w * view, axis=-1)
        else:
            cos = np.sum(Ns * unit(w + view), axis=-1)
        b = np.clip(cos + d_cos, 0.0, 1.0)
        edge = d_mu + 8.0 * U
        on = varies & (mu > edge)
        near = varies & (np.abs(mu) <= edge)
        smooth = scene.kd * d_mu + scene.ks * (n * b ** (n - 1.0) * d_cos + 2.0 * n * U * b**n)
        whole = scene.kd * (np.abs(mu) + d_mu) + scene.ks * b**n
        extra += c * (np.where(on, smooth, 0.0) + np.where(near, whole, 0.0))[:, None]
        ratio = np.minimum(ratio, np.where(varies, np.abs(mu) / edge, np.inf))
    tol[on_a] += extra
    return tol, ratio


# ---- margins: where the model allows a discrete difference ---------------------------------

#: How close to a multiple of pi or to the band's edge an argument's float64 margin must be for
#: `crease_margins` to compute it again in mpmath: a million times the float's error.
NEAR = 1e-6


def crease_arguments(scene, uv):
    """[(a, c)] per crease factor sin(a) of the scene's field (its record's ``crease_factors``;
    the ridges': a_u = (pi k_u) u, a_v = (pi k_v) v): the float arguments a, rounded as
    formulas.js and generated.py round them (pi k first), and the chart coordinate c (0: u,
    1: v) a depends on."""
    out = []
    for factor in scene.field.crease_factors:
        assert isinstance(factor, sp.sin), f"the error model knows crease factors sin(a), not {factor}"
        (c,) = [i for i, x in enumerate((F.u, F.v)) if x in factor.free_symbols]
        a = sp.lambdify(F.FIELD_SYMBOLS, factor.args[0], "numpy")
        out.append((a(uv[..., 0], uv[..., 1], scene.k_u, scene.k_v), c))
    return out


def crease_margins(args):
    """(distance of a to the nearest multiple of pi, | |sin a| - 0.03 |) per argument, exactly
    enough where it decides anything.  In float64 first: for |a| <= pi k <= 3.2e3 both are
    within 1e-12 of the truth (pi's rounding times k, and sin's), so a margin above `NEAR` is
    far above the thresholds (~1e-14 to 1e-11) and its float suffices; the arguments within
    `NEAR` of either edge get mpmath at 40 digits (known to ~1e-36 absolute)."""
    a = np.asarray(args, float)
    to_pi = np.abs(a - np.pi * np.rint(a / np.pi))
    to_edge = np.abs(np.abs(np.sin(a)) - KINK_BAND_HALF_WIDTH)
    with mp.workdps(40):
        edge = mpf(KINK_BAND_HALF_WIDTH)          # the float 0.03 the code compares with, exactly
        for k in np.flatnonzero((to_pi < NEAR) | (to_edge < NEAR)):
            x = mpf(float(a[k]))
            to_pi[k] = float(abs(x - mp.pi * mp.nint(x / mp.pi)))
            to_edge[k] = float(abs(abs(mp.sin(x)) - edge))
    return to_pi, to_edge


def stencil_margin(uv, steps):
    """Step 6: distance of the stencil's branch conditions to their edges (float64)."""
    u, v, eu, ev = uv[..., 0], uv[..., 1], steps[..., 0], steps[..., 1]
    return np.minimum.reduce([np.abs(u + eu - 1.0), np.abs(eu - u), np.abs(ev - v), np.abs(v + ev - 1.0)])


# ---- one case ---------------------------------------------------------------------------

def python_side(scene, width, height, gradient, zoom):
    """Python's frame and the per-pixel values the model needs."""
    frame = render(scene, width, height, gradient=gradient, zoom=zoom)
    gb = gbuffer(scene, width, height, gradient=gradient, zoom=zoom)
    on_a = gb.chamber == SPHERE_A
    N = gb.N[on_a]
    u, v = gb.uv[on_a, 0], gb.uv[on_a, 1]
    _, _, sin_phi = pointwise.chart(N[:, 0], N[:, 1], N[:, 2])
    if gradient == "footprint":
        e_theta, e_phi = pointwise.tangent_frame(N[:, 0], N[:, 1], N[:, 2], sin_phi)
        x, y = gb.x, gb.y
        window = 2.0 * WINDOW_MARGIN * scene.camera_z * scene.radius_a / math.sqrt(
            scene.camera_z**2 - scene.radius_a**2) / zoom
        dx = x[1] - x[0] if width > 1 else window
        dy = y[0] - y[1] if height > 1 else window
        X, Y = np.broadcast_to(x, on_a.shape)[on_a], np.broadcast_to(y[:, None], on_a.shape)[on_a]
        P = gb.P[on_a]
        steps = np.stack(pointwise.footprint(X, Y, dx, dy, scene.camera_z, P.T, N.T, e_theta, e_phi,
                                             scene.radius_a, sin_phi), axis=-1)
    else:
        steps = np.full((len(u), 2), scene.eps)
    h = pointwise.height(scene.height_field, u, v, scene.k_u, scene.k_v)
    return frame, gb, on_a, dict(sin_phi=sin_phi, steps=steps, h=h)


def error_model(scene, gradient, py, moved):
    """The model at Python's side ``py`` (`python_side`), per pixel of sphere A:
    gradient tolerance g_tol (n, 2); image tolerance i_tol (H, W, 3) (the
    terminator allowance included); which pixels are exempt from the gradient
    and image checks; and the margin ratios of steps 5, 6, 8 and 9 (<= 1:
    inside the threshold).  ``moved`` (n, 2) bool: where the other side's u, v
    are not Python's bits (all True when it is not known)."""
    frame, gb, on_a, extra = py
    uv_py, g_py = gb.uv[on_a], frame.grad[on_a]
    n = len(uv_py)
    sign_ratio, edge_ratio = np.full(n, np.inf), np.full(n, np.inf)
    # Where u (v) is the same bits on both sides, so is a_u (a_v).
    for a, c in crease_arguments(scene, uv_py):
        moves = moved[:, c]
        to_pi, to_edge = crease_margins(a[moves])
        if gradient == "exact":
            sign_ratio[moves] = np.minimum(sign_ratio[moves], to_pi / arg_tol(scene))
        edge_ratio[moves] = np.minimum(edge_ratio[moves],
                                       to_edge / (arg_tol(scene) + 2.0 * math.ulp(KINK_BAND_HALF_WIDTH)))
    branch_ratio = (stencil_margin(uv_py, extra["steps"]) / (32.0 * U) if gradient != "exact"
                    else np.full(n, np.inf))
    g_tol = grad_tolerance(scene, gradient, g_py, uv_py, extra["steps"])
    d_ns = normal_tolerance(scene, g_py, g_tol, extra["h"], extra["sin_phi"])
    i_tol, term_ratio = image_tolerance(scene, on_a, gb.P[on_a], gb.Ns[on_a], d_ns)
    grad_exempt = (sign_ratio <= 1.0) | (branch_ratio <= 1.0)
    image_exempt = np.zeros(on_a.shape, bool)
    image_exempt[on_a] = grad_exempt
    return dict(g_tol=g_tol, i_tol=i_tol, grad_exempt=grad_exempt, image_exempt=image_exempt,
                sign_ratio=sign_ratio, edge_ratio=edge_ratio, branch_ratio=branch_ratio, term_ratio=term_ratio)


def image_bound(scene, width, height, gradient, zoom=1.0):
    """(H, W, 3): how far the JavaScript image may lie from Python's, by the
    model alone (no JavaScript frame: every chart point counts as moved, and
    an exempt pixel is bounded by 1, the range of a clipped channel)."""
    py = python_side(scene, width, height, gradient, zoom)
    on_a = py[2]
    m = error_model(scene, gradient, py, np.ones((int(on_a.sum()), 2), bool))
    return np.where(m["image_exempt"][..., None], 1.0, m["i_tol"])


def compare_case(case, js, py):
    """One row of measurements: mismatches, exemptions, worst |d| / tolerance, margins."""
    case_id, scene, width, height, gradient, zoom = case
    image, grad, chamber, kink, uv = js
    frame, gb, on_a, extra = py
    row = dict(id=case_id, gradient=gradient, size=f"{width}x{height}", pixels_a=int(on_a.sum()))
    row["chamber_mismatches"] = int(np.count_nonzero(chamber != frame.chamber))
    if row["chamber_mismatches"]:
        return row                  # the rest compares sphere A pixel by pixel
    uv_py, g_py = gb.uv[on_a], frame.grad[on_a]
    m = error_model(scene, gradient, py, uv[on_a] != uv_py)
    ratios = [m[k] for k in ("sign_ratio", "edge_ratio", "branch_ratio", "term_ratio")]
    row.update(crease_sign_exempt=int(np.count_nonzero(m["sign_ratio"] <= 1.0)),
               band_edge_exempt=int(np.count_nonzero(m["edge_ratio"] <= 1.0)),
               stencil_exempt=int(np.count_nonzero(m["branch_ratio"] <= 1.0)),
               terminator=int(np.count_nonzero(m["term_ratio"] <= 1.0)),
               min_margin=float(min(r.min(initial=np.inf) for r in ratios)))
    # Crease flags: identical except at band-edge pixels; off A both are false.
    row["kink_mismatches"] = int(np.count_nonzero((kink != frame.kink)[on_a] & (m["edge_ratio"] > 1.0))
                                 + np.count_nonzero((kink != frame.kink)[~on_a]))
    # Chart, gradient, image: |d| / tolerance (<= 1 passes; NaN fails).
    row["chart_ratio"] = float(np.abs(uv[on_a] - uv_py).max(initial=0.0) / CHART_TOL)
    d_grad = np.abs(grad[on_a] - g_py) / m["g_tol"]
    off_a_grad = float(np.abs(grad[~on_a]).max(initial=0.0))          # 0 on both sides
    row["grad_ratio"] = float(max(d_grad[~m["grad_exempt"]].max(initial=0.0), np.inf if off_a_grad else 0.0))
    d_image = np.abs(image - frame.image) / m["i_tol"]
    row["image_ratio"] = float(d_image[~m["image_exempt"]].max(initial=0.0))
    row["max_abs_dI"] = float(np.abs(image - frame.image).max())
    row["max_abs_dgrad"] = float(np.abs(grad[on_a] - g_py).max(initial=0.0))
    return row


def parity_rows(module_dir, out_dir, cases=CASES):
    """Render ``cases`` in node and in Python; one row of measurements per case."""
    ms = run_render_cases(module_dir, [dict(id=i, scene=s, width=w, height=h, gradient=g, zoom=z)
                                       for i, s, w, h, g, z in cases], out_dir)
    rows = []
    for case in cases:
        case_id, scene, width, height, gradient, zoom = case
        row = compare_case(case, read_frame(out_dir, case_id, width, height),
                           python_side(scene, width, height, gradient, zoom))
        rows.append(dict(row, node_ms=ms[case_id]))
    return rows


def violations(row):
    """What a row breaks, each entry starting with the check's name."""
    if row["chamber_mismatches"]:
        return [f"chamber: {row['chamber_mismatches']} mismatches"]
    bad = []
    if row["kink_mismatches"]:
        bad.append(f"kink: {row['kink_mismatches']} mismatches beyond the band-edge margin")
    for name in ("chart", "grad", "image"):
        if not row[f"{name}_ratio"] <= 1.0:                       # also catches NaN
            bad.append(f"{name}: |d| / tolerance = {row[name + '_ratio']:.3g}")
    for kind in ("crease_sign", "band_edge", "stencil"):
        if row[f"{kind}_exempt"] > MAX_EXEMPT:
            bad.append(f"exempt: {row[kind + '_exempt']} {kind} pixels > {MAX_EXEMPT}")
    return bad


# ---- the tests ----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    return write_modules(tmp_path_factory.mktemp("js"))


@pytest.fixture(scope="module")
def rows(modules, tmp_path_factory):
    return parity_rows(modules, tmp_path_factory.mktemp("out"))


def test_parity_cover_the_acceptance_grid():
    scenes = [c[1] for c in CASES]
    assert {bool(s.field.crease_factors) for s in scenes} == {True, False}
    assert {s.model for s in scenes} == {"blinn", "phong"}
    assert {s.bump for s in scenes} == {"chart", "surface"}
    assert {c[4] for c in CASES} == set(GRADIENTS)
    assert any(s.beta == 0.0 for s in scenes)
    assert {s.sphere_b for s in scenes} == {True, False}
    central_eps = {c[1].eps for c in CASES if c[4] == "central"}
    assert min(central_eps) <= 1e-10 and max(central_eps) >= 1e-1
    assert any(c[5] > 1.0 for c in CASES if c[4] == "footprint")
    assert {s.shininess == int(s.shininess) for s in scenes} == {True, False}
    assert {s.height_field for s in scenes} == set(F.BUILTIN)
    new = "sin(pi*k_u*u)**2"                               # a field no case renders
    assert [c[0] for c in field_cases(CASES, [*F.BUILTIN, new])] == [f"{new}-central", f"{new}-exact"]


def test_js_renderer_matches_python_within_the_error_model(rows):
    lines = ["| case | pipeline | size | chamber mismatches | kink mismatches | chart d/tol | grad d/tol "
             "| image d/tol | max abs dI | exempt (sign, edge, stencil) / terminator | min margin/threshold "
             "| node ms |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['id']} | {r['gradient']} | {r['size']} | {r['chamber_mismatches']} | "
                     f"{r.get('kink_mismatches', '-')} | {r.get('chart_ratio', math.nan):.3f} | "
                     f"{r.get('grad_ratio', math.nan):.2e} | {r.get('image_ratio', math.nan):.2e} | "
                     f"{r.get('max_abs_dI', math.nan):.1e} | {r.get('crease_sign_exempt', '-')}, "
                     f"{r.get('band_edge_exempt', '-')}, {r.get('stencil_exempt', '-')} / "
                     f"{r.get('terminator', '-')} | {r.get('min_margin', math.nan):.3g} | "
                     f"{r['node_ms']:.0f} |")
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / "js_parity.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    failures = {r["id"]: violations(r) for r in rows if violations(r)}
    assert not failures, failures
    assert all(r["pixels_a"] > 0 for r in rows)


def test_render_pair_is_render_bit_for_bit(modules, tmp_path):
    """The simulator's one-pass pair equals two separate renders, bit for bit (JavaScript on both sides)."""
    cases = [("pair-default", Scene(), 64, 48, "central"),
             ("pair-sine-phong", Scene(height_field="sine", model="phong", eps=1e-7), 64, 48, "central"),
             ("pair-rings-noB", Scene(height_field="rings", sphere_b=False), 64, 48, "central"),
             ("pair-footprint-surface", Scene(height_field="sine", bump="surface", beta=0.5), 64, 48,
              "footprint")]
    spec = []
    for cid, scene, w, h, numeric in cases:
        spec += [dict(id=cid, scene=scene, width=w, height=h, gradient="pair", numeric=numeric, zoom=1.0),
                 dict(id=cid + "-n", scene=scene, width=w, height=h, gradient=numeric, zoom=1.0),
                 dict(id=cid + "-e", scene=scene, width=w, height=h, gradient="exact", zoom=1.0)]
    run_render_cases(modules, spec, tmp_path)
    for cid, _, w, h, numeric in cases:
        for pipe, suffix in ((numeric, "-n"), ("exact", "-e")):
            pair = read_frame(tmp_path, f"{cid}.{pipe}", w, h)
            single = read_frame(tmp_path, cid + suffix, w, h)
            for a, b in zip(pair, single):
                assert np.array_equal(a, b), (cid, pipe)


# ---- the checks reject wrong variants of the JavaScript ------------------------------

#: name: (module, old text, new text, the check that must fail, cases to run it on)
WRONG_VARIANTS = {
    "ties go to sphere B": ("render", "if (tb < t)", "if (tb <= t)", "chamber",
                            [("tie", Scene(center_b=(0.0, 0.0, 0.0), radius_b=1.0), 33, 33, "exact", 1.0)]),
    "shadow ray ignores the floor plane": ("render", "if (s.floor && code !== FLOOR && (", "if (false && (",
                                           "image", ["sine-eps1e-2-lights"]),
    "shading with the geometric normal": ("render", "light_term(s, s.lights[k].color, px.w, px.axis, 0, wv, px.Ns,",
                                          "light_term(s, s.lights[k].color, px.w, px.axis, 0, wv, px.N,", "image",
                                          ["default-exact"]),
    "footprint with the column spacing for rows": (
        "render", "const dy = height > 1 ? y[0] - y[1] : window;",
        "const dy = width > 1 ? x[1] - x[0] : window;", "grad", ["default-footprint"]),
    "central step 0.1 % off": ("render", "px.steps[0] = eps; px.steps[1] = eps;",
                               "px.steps[0] = 1.001 * eps; px.steps[1] = 1.001 * eps;", "grad",
                               ["sine-phong-eps1e-1"]),
    "the seed's acos(N_z) in the chart": ("formulas", "Math.atan2(x1, N_z)", "Math.acos(N_z)", "chart",
                                          ["rings-eps1e-4-pole-x8"]),
    "a wider crease band": ("formulas", "< 0.03", "< 0.031", "kink", ["default-exact", "default-central-256"]),
}


@pytest.mark.parametrize("variant", sorted(WRONG_VARIANTS))
def test_parity_check_rejects_wrong_variant(variant, tmp_path):
    module, old, new, check, cases = WRONG_VARIANTS[variant]

    def transform(name, text):
        if name != module:
            return text
        assert old in text, f"variant {variant!r} no longer applies to {module}.js"
        return text.replace(old, new)

    modules = write_modules(tmp_path / "js", transform)
    by_id = {c[0]: c for c in CASES}
    cases = [by_id[c] if isinstance(c, str) else c for c in cases]
    rows = parity_rows(modules, tmp_path / "out", cases)
    failed = [v for r in rows for v in violations(r)]
    assert any(v.startswith(check) for v in failed), \
        f"wrong variant {variant!r} passed the {check} check: {failed}"
