"""The per-pixel render kernel, compiled with numba.

One pixel at a time, in the order of the data flow (seed Cell 1,
``render_numeric_bump``; the §4 simulator's renderer/js/render.js and the
scalar reference of tests/ take the same steps):

camera ray -> `nearest_hit` (chamber) -> `surface` (hit point, normal,
albedo) -> on sphere A: `chart`, `tangent_frame`, `gradient`,
`shading_normal` -> `shade`: ambient + per light, `reach` (the normal faces
the light, the floor plane does not separate them, no blocker sphere on the
segment) then Lambert and Blinn/Phong with the shading normal.

Everything up to the gradient depends on geometry alone (theorem "bump moves
no boundary"), which licenses `sweep_rows`: geometry and shadow rays once per
pixel, sphere A re-shaded per step.  The formulas of sphere A are the
generated block below (`renderer.codegen` prints `renderer.formulas`); they
live in this file because numba's cache is keyed on the file of a compiled
function.  Compiled on first use and cached beside this file (``__pycache__``,
or numba's user cache directory when that is not writable).

``skip``: True does only the work the outputs need (an object that is off is
not intersected; a shadow ray is traced only where the light could add light;
at beta = 0 no gradient unless it is an output; the crease flag only when it
is an output).  False does all of it and discards what is unused: the
reference path of tests/test_skips.py, which shows both give the same bits.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit, prange

from .generated import (FIELD_CODES, central_gradient, chart, exact_gradient, footprint, height,
                        kink_band, perturbed_normal_chart, perturbed_normal_surface, tangent_frame)

BACKGROUND, SPHERE_A, SPHERE_B, FLOOR = 0, 1, 2, 3
#: Codes of the gradient methods (`renderer.render.GRADIENTS`, in order).
EXACT, CENTRAL, FOOTPRINT = 0, 1, 2
#: Checker albedo levels of the floor's two colours (seed Cell 1).
FLOOR_LIGHT, FLOOR_DARK = 0.85, 0.15
#: Floor under |h| in Blinn's half-vector quotient (|h| = 0 only where w = -v).
TINY = 1e-300

#: The scene as the kernel reads it (`params`): floats, bools, int codes and
#: the lights as an (n, 6) float64 array of position and colour.
Params = namedtuple("Params", "camera_z radius_a center_b radius_b sphere_b floor lights ambient "
                              "albedo_a albedo_b ka kd ks shininess phong floor_tint field k_u k_v "
                              "beta surface")

FORMULAS_DIGEST = "e8a03aa67b22655643b57341607433b2ab38e335efd147aa2ba29fae3d88ebf2"  # of generated.py, written by renderer/codegen.py


# ---- the kernel's own steps: intersection, shadows, shading ---------------------

@njit(cache=True, error_model="numpy")
def sphere_hit(x, y, e, cx, cy, cz, r):
    """Nearest t > 0 of the ray E + t (x, y, -e), E = (0, 0, e), on a sphere, or inf.

    Stable roots q = -(b + sign(b) sqrt(disc)), t = q / a, c / q (pbrt-v4); the
    discriminant from the centre's distance to the ray's line (Haines et al.,
    Ray Tracing Gems, ch. 7), free of the cancellation of b^2 - a c.
    """
    ox, oy, oz = -cx, -cy, e - cz
    a = x * x + y * y + e * e
    b = x * ox + y * oy - e * oz
    c = ox * ox + oy * oy + oz * oz - r * r
    f = b / a
    lx, ly, lz = ox - f * x, oy - f * y, oz + f * e
    disc = a * (r * r - (lx * lx + ly * ly + lz * lz))
    if not disc >= 0.0:
        return math.inf
    q = -(b + math.copysign(math.sqrt(disc), b))
    t0, t1 = q / a, c / q
    near, far = min(t0, t1), max(t0, t1)
    return near if near > 0.0 else (far if far > 0.0 else math.inf)


@njit(cache=True, error_model="numpy")
def segment_blocked(wx, wy, wz, w2, L, cx, cy, cz, r):
    """Does the segment from P to the light L meet the sphere (C, r)?  w = L - P.

    With d = C - L and g = -(w . d): a root of |L + tau (P - L) - C| = r lies in
    (0, 1) exactly when g^2 >= |w|^2 (|d|^2 - r^2) and 0 < g < |w|^2 (light
    outside the sphere); a light inside is blocked from every outside point;
    a light on it where the chord tau = 2 g / |w|^2 ends before P.
    """
    dx, dy, dz = L[0] - cx, L[1] - cy, L[2] - cz
    k = dx * dx + dy * dy + dz * dz - r * r
    if k < 0.0:
        return True
    g = wx * dx + wy * dy + wz * dz
    if k == 0.0:
        return g > 0.0 and 2.0 * g < w2
    return g > 0.0 and g < w2 and g * g >= w2 * k


@njit(cache=True, error_model="numpy")
def nearest_hit(s, x, y, skip):
    """(t, chamber) of the nearest positive hit; ties go to A, then B, then the floor."""
    t, code = sphere_hit(x, y, s.camera_z, 0.0, 0.0, 0.0, s.radius_a), BACKGROUND
    if t < math.inf:
        code = SPHERE_A
    if s.sphere_b or not skip:
        tb = sphere_hit(x, y, s.camera_z, s.center_b[0], s.center_b[1], s.center_b[2], s.radius_b)
        if s.sphere_b and tb < t:
            t, code = tb, SPHERE_B
    if s.floor and 1.0 < t:        # the floor z = 0 is the image plane: t = 1
        t, code = 1.0, FLOOR
    return t, code


@njit(cache=True, error_model="numpy")
def surface(s, x, y, t, code):
    """Hit point P, geometric normal N and albedo of a hit (geometry only)."""
    P = (t * x, t * y, s.camera_z * (1.0 - t))
    if code == SPHERE_A:
        r = s.radius_a
        return P, (P[0] / r, P[1] / r, P[2] / r), (s.albedo_a[0], s.albedo_a[1], s.albedo_a[2])
    if code == SPHERE_B:
        c, r = s.center_b, s.radius_b
        return P, ((P[0] - c[0]) / r, (P[1] - c[1]) / r, (P[2] - c[2]) / r), (s.albedo_b[0], s.albedo_b[1],
                                                                             s.albedo_b[2])
    # Checker: light squares where sin(pi x) sin(pi y) >= 0 (seed Cell 1).
    base = FLOOR_LIGHT if math.sin(math.pi * P[0]) * math.sin(math.pi * P[1]) >= 0.0 else FLOOR_DARK
    rg = base * (1.0 - s.floor_tint)
    return P, (0.0, 0.0, 1.0), (rg, rg, base)


@njit(cache=True, error_model="numpy")
def attached(s, L, P, N, code):
    """The geometric normal faces the light and the floor plane does not
    separate P from it (floor on, P not on the floor)."""
    facing = N[0] * (L[0] - P[0]) + N[1] * (L[1] - P[1]) + N[2] * (L[2] - P[2]) > 0.0
    if s.floor and code != FLOOR:
        if (L[2] < 0.0 and P[2] > 0.0) or (L[2] > 0.0 and P[2] < 0.0):
            return False
    return facing


@njit(cache=True, error_model="numpy")
def occluded(s, L, P, code, skip):
    """A blocker sphere (B for A, A for B, both for the floor) cuts the segment P-L."""
    wx, wy, wz = L[0] - P[0], L[1] - P[1], L[2] - P[2]
    w2 = wx * wx + wy * wy + wz * wz
    hit = False
    if code != SPHERE_A:
        hit = segment_blocked(wx, wy, wz, w2, L, 0.0, 0.0, 0.0, s.radius_a)
    if code != SPHERE_B and (s.sphere_b or not skip):
        c = s.center_b
        hit_b = segment_blocked(wx, wy, wz, w2, L, c[0], c[1], c[2], s.radius_b)
        hit = hit or (s.sphere_b and hit_b)
    return hit


@njit(cache=True, error_model="numpy")
def light_term(s, k, P, Ns, albedo, rgb):
    """Add light k's Lambert and Blinn/Phong terms at P with shading normal Ns to rgb."""
    L, col = s.lights[k, :3], s.lights[k, 3:]
    wx, wy, wz = L[0] - P[0], L[1] - P[1], L[2] - P[2]
    inv = 1.0 / math.sqrt(wx * wx + wy * wy + wz * wz)
    wx, wy, wz = wx * inv, wy * inv, wz * inv
    mu = Ns[0] * wx + Ns[1] * wy + Ns[2] * wz
    if not mu > 0.0:
        return
    vx, vy, vz = -P[0], -P[1], s.camera_z - P[2]
    inv = 1.0 / math.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx * inv, vy * inv, vz * inv
    if s.phong:
        m2 = 2.0 * mu
        spec_cos = (m2 * Ns[0] - wx) * vx + (m2 * Ns[1] - wy) * vy + (m2 * Ns[2] - wz) * vz
    else:
        hx, hy, hz = wx + vx, wy + vy, wz + vz
        hn = max(math.sqrt(hx * hx + hy * hy + hz * hz), TINY)
        spec_cos = (Ns[0] * hx + Ns[1] * hy + Ns[2] * hz) / hn
    # Clamped before the power: rounding can put the cosine an ulp above 1.
    spec = min(max(spec_cos, 0.0), 1.0) ** s.shininess * s.ks
    diffuse = mu * s.kd
    for c in range(3):
        rgb[c] += col[c] * (diffuse * albedo[c] + spec)


@njit(cache=True, error_model="numpy")
def shade(s, P, N, Ns, albedo, code, skip, rgb):
    """Ambient plus every light that reaches P (seed Cell 1, ``shade1``), clipped to [0, 1]."""
    for c in range(3):
        rgb[c] = s.ka * s.ambient[c]
    for k in range(s.lights.shape[0]):
        L = s.lights[k, :3]
        if not attached(s, L, P, N, code):
            continue
        if skip:
            # No shadow ray where the light adds nothing: Ns . w <= 0.
            wx, wy, wz = L[0] - P[0], L[1] - P[1], L[2] - P[2]
            if not Ns[0] * wx + Ns[1] * wy + Ns[2] * wz > 0.0:
                continue
        if not occluded(s, L, P, code, skip):
            light_term(s, k, P, Ns, albedo, rgb)
    for c in range(3):
        rgb[c] = min(max(rgb[c], 0.0), 1.0)


@njit(cache=True, error_model="numpy")
def gradient(s, method, eps, u, v, x, y, dx, dy, P, N, frame, sin_phi):
    """(h_u, h_v) by ``method``: exact, central with step eps, or central with
    the pixel's footprint as step (pixel spacing dx, dy on the image plane)."""
    if method == EXACT:
        return exact_gradient(s.field, u, v, s.k_u, s.k_v)
    if method == CENTRAL:
        return central_gradient(s.field, u, v, s.k_u, s.k_v, eps, eps)
    eu, ev = footprint(x, y, dx, dy, s.camera_z, P[0], P[1], P[2], N[0], N[1], N[2],
                       frame[0], frame[1], frame[2], frame[3], frame[4], frame[5], s.radius_a, sin_phi)
    return central_gradient(s.field, u, v, s.k_u, s.k_v, eu, ev)


@njit(cache=True, error_model="numpy")
def shading_normal(s, N, frame, hu, hv, u, v, sin_phi):
    """N' of sphere A (`formulas.PERTURBED_NORMAL`); N itself at beta = 0."""
    if s.beta == 0.0:
        return N
    et0, et1, et2, ep0, ep1, ep2 = frame
    if s.surface:
        h = height(s.field, u, v, s.k_u, s.k_v)
        return perturbed_normal_surface(N[0], N[1], N[2], et0, et1, et2, ep0, ep1, ep2, hu, hv, s.beta,
                                        h, s.radius_a, sin_phi)
    return perturbed_normal_chart(N[0], N[1], N[2], et0, et1, et2, ep0, ep1, ep2, hu, hv, s.beta)


@njit(cache=True, error_model="numpy", parallel=True)
def render_rows(s, xs, ys, dx, dy, method, eps, skip, want_kink, want_grad, want_geo,
                image, chamber, kink, grad, t_out, P_out, N_out, Ns_out, uv_out):
    """Render every pixel (rows in parallel) into the preallocated outputs.

    xs (W,), ys (H,): pixel centres on the image plane; image (H, W, 3),
    chamber (H, W) uint8; kink (H, W) bool and grad (H, W, 2) when wanted;
    t (H, W), P, N, Ns (H, W, 3), uv (H, W, 2) when ``want_geo`` (the GBuffer).
    """
    for j in prange(ys.shape[0]):
        rgb = np.zeros(3)
        for i in range(xs.shape[0]):
            x, y = xs[i], ys[j]
            t, code = nearest_hit(s, x, y, skip)
            chamber[j, i] = code
            if code == BACKGROUND:
                if want_geo:
                    t_out[j, i] = t
                continue
            P, N, albedo = surface(s, x, y, t, code)
            Ns = N
            if code == SPHERE_A:
                u, v, sin_phi = chart(N[0], N[1], N[2])
                frame = tangent_frame(N[0], N[1], N[2], sin_phi)
                if want_grad or want_geo or s.beta != 0.0 or not skip:
                    hu, hv = gradient(s, method, eps, u, v, x, y, dx, dy, P, N, frame, sin_phi)
                    Ns = shading_normal(s, N, frame, hu, hv, u, v, sin_phi)
                    if want_grad:
                        grad[j, i, 0], grad[j, i, 1] = hu, hv
                    if want_geo:
                        uv_out[j, i, 0], uv_out[j, i, 1] = u, v
                if want_kink or not skip:
                    flag = kink_band(s.field, u, v, s.k_u, s.k_v)
                    if want_kink:
                        kink[j, i] = flag
            shade(s, P, N, Ns, albedo, code, skip, rgb)
            image[j, i, 0], image[j, i, 1], image[j, i, 2] = rgb[0], rgb[1], rgb[2]
            if want_geo:
                t_out[j, i] = t
                for c in range(3):
                    P_out[j, i, c], N_out[j, i, c], Ns_out[j, i, c] = P[c], N[c], Ns[c]


@njit(cache=True, error_model="numpy", parallel=True)
def sweep_rows(s, xs, ys, steps, images, chamber, kink, grads):
    """The exact frame (index 0) and one central frame per step (1, 2, ...).

    Per pixel the geometry, the crease flag and the shadow rays are computed
    once (they do not depend on the gradient); sphere A is re-shaded per step.
    images (S+1, H, W, 3), grads (S+1, H, W, 2); chamber, kink (H, W).
    """
    n = s.lights.shape[0]
    for j in prange(ys.shape[0]):
        rgb = np.zeros(3)
        reach = np.zeros(n, dtype=np.bool_)
        for i in range(xs.shape[0]):
            x, y = xs[i], ys[j]
            t, code = nearest_hit(s, x, y, True)
            chamber[j, i] = code
            if code == BACKGROUND:
                continue
            P, N, albedo = surface(s, x, y, t, code)
            if code != SPHERE_A:
                shade(s, P, N, N, albedo, code, True, rgb)
                for f in range(images.shape[0]):
                    for c in range(3):
                        images[f, j, i, c] = rgb[c]
                continue
            u, v, sin_phi = chart(N[0], N[1], N[2])
            frame = tangent_frame(N[0], N[1], N[2], sin_phi)
            kink[j, i] = kink_band(s.field, u, v, s.k_u, s.k_v)
            for k in range(n):
                L = s.lights[k, :3]
                reach[k] = attached(s, L, P, N, code) and not occluded(s, L, P, code, True)
            for f in range(images.shape[0]):
                if f == 0:
                    hu, hv = exact_gradient(s.field, u, v, s.k_u, s.k_v)
                else:
                    hu, hv = central_gradient(s.field, u, v, s.k_u, s.k_v, steps[f - 1], steps[f - 1])
                Ns = shading_normal(s, N, frame, hu, hv, u, v, sin_phi)
                for c in range(3):
                    rgb[c] = s.ka * s.ambient[c]
                for k in range(n):
                    if reach[k]:
                        light_term(s, k, P, Ns, albedo, rgb)
                for c in range(3):
                    images[f, j, i, c] = min(max(rgb[c], 0.0), 1.0)
                grads[f, j, i, 0], grads[f, j, i, 1] = hu, hv


def params(scene, skip=True):
    """The kernel's `Params` of a validated `renderer.Scene`.  With ``skip``
    the lights of zero colour are left out (they add exactly 0)."""
    lights = [tuple(l.position) + tuple(l.color) for l in scene.lights if any(l.color) or not skip]
    vec = lambda a: np.array(a, dtype=np.float64)  # noqa: E731
    return Params(float(scene.camera_z), float(scene.radius_a), vec(scene.center_b),
                  float(scene.radius_b), bool(scene.sphere_b), bool(scene.floor),
                  vec(lights).reshape(-1, 6), vec(scene.ambient), vec(scene.albedo_a), vec(scene.albedo_b),
                  float(scene.ka), float(scene.kd), float(scene.ks), float(scene.shininess),
                  scene.model == "phong", float(scene.floor_tint), FIELD_CODES[scene.height_field],
                  float(scene.k_u), float(scene.k_v), float(scene.beta), scene.bump == "surface")
