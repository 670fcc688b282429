"""Scalar per-pixel oracle for the vectorized renderer: `math` only, slow on purpose.

Written from the seed's equations (Cell 1 ``render_numeric_bump`` and
``shade1``, Cell 3 ``grad_exact``, and the formulas of §3) with the project's
corrections:

* sphere B's ray quadratic uses the constant term c = |E - C|^2 - r^2 (the
  seed's Cell 1 writes |C|^2 - r^2, which places the hit points off the sphere);
* the nearest *positive* root is taken for every sphere;
* the chart's polar angle is atan2(hypot(N_x, N_y), N_z) rather than acos(N_z);
* a light reaches a point only if the geometric normal faces it, no blocker
  sphere meets the segment, and (for sphere points, floor on) the floor plane
  does not separate the point from the light.

It also covers the project's ``Scene.bump = "surface"`` option (the normal of
the displaced sphere), derived by hand in `perturb_surface`, and the third
pipeline ``gradient="footprint"`` (central differences whose steps are the
pixel's footprint in the chart), written in `footprint_steps` from pbrt-v4's
rule (``SurfaceInteraction::ComputeDifferentials`` and ``BumpMap``) with
pbrt's least-squares solve, not the renderer's projections.

The height fields are the one thing read from the renderer: each field's record
(`renderer.formulas.HeightField`, sympy objects only) gives its expression, sympy's
derivative and its crease factors, printed here by ``sympy.lambdify`` for the
``math`` module, not by renderer/codegen.py nor compiled by numba; so a field
registered later, or a reader's expression, renders here too.  The seed's three
fields are also written by hand (`seed_height`, `seed_gradient`), only to
cross-check the records.  Otherwise the only contact with the renderer is
reading attribute values off a ``renderer.Scene``.  The structure is
deliberately different from ``renderer/`` (one pixel at a time, plain tuples,
textbook quadratic formula) so that a shared mistake is unlikely.

Each stage is a module-level function so that a test can swap one stage for a
wrong variant (``monkeypatch.setattr``) and check that parity notices.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import sympy as sp

from renderer import formulas as F

__all__ = [
    "BACKGROUND", "SPHERE_A", "SPHERE_B", "FLOOR",
    "pixel_point", "ray_point", "nearest_positive_root", "sphere_a_t", "sphere_b_t",
    "nearest_hit", "chart_a", "tangent_frame_a", "chart_tangents", "height_value", "grad_exact",
    "seed_height", "seed_gradient", "SEED_FIELDS",
    "stencil_u", "stencil_v", "grad_central", "in_kink_band", "chart_bump_vector", "perturb",
    "perturb_surface", "segment_blocked", "shade", "tangent_plane_offset", "footprint_steps",
    "footprint_neighbours", "sphere_a_colour", "render_pixel", "render_reference",
]

BACKGROUND, SPHERE_A, SPHERE_B, FLOOR = 0, 1, 2, 3
TWO_PI = 2.0 * math.pi
POLE_SIN_PHI = 2.0**-1022   # float64's smallest normal: at or below it (sin phi 0 or subnormal) the fixed basis
#                            (the seed's Cell 1 took it below 1e-4)
KINK_HALF_WIDTH = 0.03   # seed Cell 1, height1: the crease band
FOOTPRINT_FALLBACK = 0.0005   # pbrt-v4, BumpMap: the step where the footprint is 0
FOOTPRINT_LIMIT = 1e8         # pbrt-v4 clamps |du/dx| to this; beyond it, the fallback
FOOTPRINT_MAX = 0.25          # the project's cap (u +- eps stays a quarter period apart)
GRADIENTS = ("exact", "central", "footprint")


# --- small 3-vector helpers on tuples ----------------------------------------------

def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def scale(s, a):
    return (s * a[0], s * a[1], s * a[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def normalize(a):
    n = math.sqrt(dot(a, a))
    return (a[0] / n, a[1] / n, a[2] / n)


# --- camera ---------------------------------------------------------------------------

def pixel_point(scene, i, j, width, height):
    """Image-plane point (x, y) of pixel centre (i, j) (seed Cell 1's window)."""
    e, R = scene.camera_z, scene.radius_a
    half = 1.25 * e * R / math.sqrt(e * e - R * R)
    x = half * (2.0 * (i + 0.5) / width - 1.0)
    y = half * (1.0 - 2.0 * (j + 0.5) / height) - 0.15 * half
    return x, y


def ray_point(t, x, y, e):
    """P(t) = (t x, t y, e (1 - t)): t = 0 is the eye, t = 1 the floor z = 0."""
    return (t * x, t * y, e * (1.0 - t))


# --- intersections ----------------------------------------------------------------------

def nearest_positive_root(a, b, c):
    """Smallest root t > 0 of a t^2 + b t + c = 0 (a > 0), or inf."""
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return math.inf
    root = math.sqrt(disc)
    for t in ((-b - root) / (2.0 * a), (-b + root) / (2.0 * a)):   # ascending
        if t > 0.0:
            return t
    return math.inf


def ray_sphere_t(x, y, e, C, r):
    """Nearest positive t with |P(t) - C| = r.

    P(t) = E + t d, d = (x, y, -e), E = (0, 0, e):
    a = |d|^2, b = 2 d . (E - C), c = |E - C|^2 - r^2.
    """
    d = (x, y, -e)
    oc = sub((0.0, 0.0, e), C)
    return nearest_positive_root(dot(d, d), 2.0 * dot(d, oc), dot(oc, oc) - r * r)


def sphere_a_t(x, y, scene):
    return ray_sphere_t(x, y, scene.camera_z, (0.0, 0.0, 0.0), scene.radius_a)


def sphere_b_t(x, y, scene):
    return ray_sphere_t(x, y, scene.camera_z, scene.center_b, scene.radius_b)


def nearest_hit(x, y, scene):
    """(t, chamber code) of the nearest positive hit; ties go A, then B, then floor."""
    best_t, best_code = math.inf, BACKGROUND
    candidates = [(sphere_a_t(x, y, scene), SPHERE_A)]
    if scene.sphere_b:
        candidates.append((sphere_b_t(x, y, scene), SPHERE_B))
    if scene.floor:
        candidates.append((1.0, FLOOR))
    for t, code in candidates:        # strict '<' keeps the earlier object on a tie
        if t < best_t:
            best_t, best_code = t, code
    return best_t, best_code


# --- sphere A: chart and tangent frame ------------------------------------------------

def chart_a(N):
    """(u, v, sin phi) of a unit normal: u from the azimuth, v from the polar angle."""
    sin_phi = math.hypot(N[0], N[1])
    u = (math.atan2(N[1], N[0]) + math.pi) / TWO_PI
    v = math.atan2(sin_phi, N[2]) / math.pi
    return u, v, sin_phi


def tangent_frame_a(N, sin_phi):
    """(e_theta, e_phi) of seed §3, with the seed's fixed basis at the poles (sin phi 0 or subnormal)."""
    if sin_phi > POLE_SIN_PHI:
        e_th = (-N[1] / sin_phi, N[0] / sin_phi, 0.0)
        e_ph = (N[2] * N[0] / sin_phi, N[2] * N[1] / sin_phi, -sin_phi)
    else:
        e_th, e_ph = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    return e_th, e_ph


def chart_tangents(R, sin_phi, e_th, e_ph):
    """(dP/du, dP/dv) of sphere A: with theta = 2 pi u - pi and phi = pi v,
    P = R N gives dP/dtheta = R sin(phi) e_theta and dP/dphi = R e_phi."""
    return scale(TWO_PI * R * sin_phi, e_th), scale(math.pi * R, e_ph)


# --- height fields and their gradients ------------------------------------------------

@functools.lru_cache(maxsize=None)
def _field_functions(record):
    """(h, (h_u, h_v), crease factors) of a `renderer.formulas.HeightField` record as functions
    of (u, v, k_u, k_v), printed by ``sympy.lambdify`` for the ``math`` module."""
    args = F.FIELD_SYMBOLS
    return (sp.lambdify(args, record.expr, "math"), sp.lambdify(args, list(record.gradient), "math"),
            sp.lambdify(args, list(record.crease_factors), "math"))


def height_value(field, u, v, ku, kv):
    """h(u, v) of the height field ``field`` (a Scene's ``height_field``): its record's expression."""
    return _field_functions(F.field(field))[0](u, v, ku, kv)


def grad_exact(field, u, v, ku, kv):
    """(h_u, h_v): the record's sympy derivatives (where h = |f|, sign(f) f', 0 on a zero of f)."""
    return tuple(_field_functions(F.field(field))[1](u, v, ku, kv))


def in_kink_band(field, u, v, ku, kv):
    """The seed's crease flag: a crease factor of the record within the band about its zero."""
    return any(abs(f) < KINK_HALF_WIDTH for f in _field_functions(F.field(field))[2](u, v, ku, kv))


# The seed's three fields as it writes them (seed §2 and §3), by hand: only a cross-check of
# the records at random points (tests/test_codegen.py), never what the reference renders with.

def sign(x):
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


#: h(s1, s2, v, kv) of seed §2 per field, s1 = sin(pi ku u), s2 = sin(pi kv v): the seed's fields.
_SEED_HEIGHTS = {"sine": lambda s1, s2, v, kv: s1 * s2, "ridges": lambda s1, s2, v, kv: abs(s1 * s2),
                 "rings": lambda s1, s2, v, kv: math.sin(TWO_PI * kv * v)}
#: The fields `seed_height` and `seed_gradient` know.
SEED_FIELDS = tuple(_SEED_HEIGHTS)


def seed_height(field, u, v, ku, kv):
    """h(u, v) of seed §2."""
    return _SEED_HEIGHTS[field](math.sin(math.pi * ku * u), math.sin(math.pi * kv * v), v, kv)


def seed_gradient(field, u, v, ku, kv):
    """Closed-form (h_u, h_v) of seed §3 (ridges: the sign factor 0 on the zero lines, as the
    seed's grad_exact)."""
    s1, c1 = math.sin(math.pi * ku * u), math.cos(math.pi * ku * u)
    s2, c2 = math.sin(math.pi * kv * v), math.cos(math.pi * kv * v)
    sigma = {"sine": 1.0, "ridges": sign(s1 * s2)}.get(field)
    if sigma is not None:
        return math.pi * ku * c1 * s2 * sigma, math.pi * kv * s1 * c2 * sigma
    return {"rings": (0.0, TWO_PI * kv * math.cos(TWO_PI * kv * v))}[field]



def stencil_u(u, eps):
    """(u + eps, u - eps), each wrapped modulo 1 (the chart is periodic in u)."""
    return (u + eps) % 1.0, (u - eps) % 1.0


def stencil_v(v, eps_v):
    """(v_plus, v_minus, divisor): v +- eps_v clamped to [0, 1]; where either
    clamps, the divisor is the clamped distance (a one-sided quotient), else 2 eps_v."""
    v_plus, v_minus = min(1.0, v + eps_v), max(0.0, v - eps_v)
    clamped = v + eps_v > 1.0 or v - eps_v < 0.0
    return v_plus, v_minus, (v_plus - v_minus) if clamped else 2.0 * eps_v


def grad_central(field, u, v, ku, kv, eps, eps_v=None):
    """Central differences of h with steps eps (in u) and eps_v (in v, default
    eps): u wraps modulo 1, v clamps to [0, 1] (one-sided there)."""
    eps_v = eps if eps_v is None else eps_v
    h = lambda uu, vv: height_value(field, uu, vv, ku, kv)  # noqa: E731
    u_plus, u_minus = stencil_u(u, eps)
    hu = (h(u_plus, v) - h(u_minus, v)) / (2.0 * eps)
    v_plus, v_minus, step = stencil_v(v, eps_v)
    hv = (h(u, v_plus) - h(u, v_minus)) / step
    return hu, hv


def chart_bump_vector(N, e_th, e_ph, hu, hv, beta):
    """Seed §3's M = N + beta (h_u e_theta + h_v e_phi), before normalisation."""
    g = add(scale(hu, e_th), scale(hv, e_ph))
    return add(N, scale(beta, g))


def perturb(N, e_th, e_ph, hu, hv, beta):
    """Seed §3: N' = M / |M| (`chart_bump_vector`); N itself at beta = 0."""
    if beta == 0.0:
        return N
    return normalize(chart_bump_vector(N, e_th, e_ph, hu, hv, beta))


def perturb_surface(N, e_th, e_ph, hu, hv, h, beta, R, sin_phi):
    """Normal of the displaced sphere r = rho N, rho = R + beta h (Scene.bump = "surface").

    Derived by hand: with theta = 2 pi u - pi and phi = pi v, r_theta = rho_theta N
    + rho sin(phi) e_theta and r_phi = rho_phi N + rho e_phi, and e_phi x e_theta = N,
    so r_phi x r_theta is parallel to N - (rho_theta / (rho sin phi)) e_theta
    - (rho_phi / rho) e_phi, with rho_theta = beta h_u / (2 pi), rho_phi = beta h_v / pi.
    At the pole cut-off and below (sin phi 0 or subnormal), where the frame falls back to
    the fixed basis, the e_theta term is dropped (renderer's documented choice).
    """
    if beta == 0.0:
        return N
    rho = R + beta * h
    a_th = beta * hu / (TWO_PI * sin_phi * rho) if sin_phi > POLE_SIN_PHI else 0.0
    a_ph = beta * hv / (math.pi * rho)
    return normalize(sub(N, add(scale(a_th, e_th), scale(a_ph, e_ph))))


# --- the pixel footprint (pbrt-v4) -------------------------------------------------------

def tangent_plane_offset(scene, P, N, x, y):
    """Where the eye ray through the image-plane point (x, y) meets the tangent
    plane at P, minus P (pbrt-v4, ComputeDifferentials: d = -N . P,
    t = (-N . o - d) / (N . dir), p = o + t dir)."""
    o, direction = (0.0, 0.0, scene.camera_z), (x, y, -scene.camera_z)
    t = (-dot(N, o) + dot(N, P)) / dot(N, direction)
    return sub(add(o, scale(t, direction)), P)


def footprint_steps(scene, P, N, e_th, e_ph, sin_phi, right, up):
    """(eps_u, eps_v) of pbrt-v4's bump mapping at a pixel of sphere A.

    ``right``, ``up``: image-plane centres of the neighbouring pixels one
    column right and one row up (the renderer's ray differentials,
    `renderer.formulas.FOOTPRINT`; pbrt's own y differential goes one raster
    row down, the same to first order).  dp/dx and dp/dy are where the
    neighbours' rays meet the tangent plane at P, minus P; (du/dx, dv/dx)
    solve the normal equations of dp/dx = du/dx dP/du + dv/dx dP/dv with
    dP/du = 2 pi R sin(phi) e_theta and dP/dv = pi R e_phi (pbrt's 2 x 2
    least squares); then du = (|du/dx| + |du/dy|) / 2, the fallback 0.0005
    where that is 0 (pbrt-v4, BumpMap) or not below 1e8 (pbrt clamps a
    derivative to 1e8 and zeroes a non-finite one), at most 0.25 (the
    project's cap).  Where dP/du = 0 (sin phi = 0 exactly) u's footprint is
    unbounded, so the fallback, and v's solve is one-dimensional.
    """
    dpdu, dpdv = chart_tangents(scene.radius_a, sin_phi, e_th, e_ph)
    a00, a01, a11 = dot(dpdu, dpdu), dot(dpdu, dpdv), dot(dpdv, dpdv)
    det = a00 * a11 - a01 * a01
    derivatives = []
    for neighbour in (right, up):
        dp = tangent_plane_offset(scene, P, N, *neighbour)
        b0, b1 = dot(dpdu, dp), dot(dpdv, dp)
        if det:
            derivatives.append(((a11 * b0 - a01 * b1) / det, (a00 * b1 - a01 * b0) / det))
        else:
            derivatives.append((math.inf, b1 / a11))
    (dudx, dvdx), (dudy, dvdy) = derivatives
    steps = []
    for half in (0.5 * (abs(dudx) + abs(dudy)), 0.5 * (abs(dvdx) + abs(dvdy))):
        steps.append(min(half, FOOTPRINT_MAX) if 0.0 < half < FOOTPRINT_LIMIT else FOOTPRINT_FALLBACK)
    return tuple(steps)


# --- shading ---------------------------------------------------------------------------

def segment_blocked(P, L, C, r):
    """Seed Cell 1's sign logic: does P + s (L - P) meet the sphere for some s in (0, 1)?"""
    w = sub(L, P)
    pc = sub(P, C)
    a = dot(w, w)
    if a == 0.0:
        return False
    b = dot(pc, w)                     # half the linear coefficient
    c = dot(pc, pc) - r * r
    disc = b * b - a * c
    if disc < 0.0:
        return False
    root = math.sqrt(disc)
    s1, s2 = (-b - root) / a, (-b + root) / a
    return 0.0 < s1 < 1.0 or 0.0 < s2 < 1.0


def floor_separates(P, L):
    """The plane z = 0 lies strictly between P and L."""
    return (P[2] > 0.0 and L[2] < 0.0) or (P[2] < 0.0 and L[2] > 0.0)


def shade(scene, P, N, N_shade, albedo, blockers, floor_blocks):
    """Ambient plus, per visible light, Lambert and Blinn or Phong; clipped to [0, 1]."""
    E = (0.0, 0.0, scene.camera_z)
    v_hat = normalize(sub(E, P))
    col = [scene.ka * a for a in scene.ambient]
    for light in scene.lights:
        L, color = light.position, light.color
        if color[0] == 0.0 and color[1] == 0.0 and color[2] == 0.0:
            continue
        w = sub(L, P)
        # Visibility: attached shadow on the true normal, then the cast shadows.
        if not dot(N, w) > 0.0:
            continue
        if any(segment_blocked(P, L, C, r) for C, r in blockers):
            continue
        if floor_blocks and floor_separates(P, L):
            continue
        # Reflectance with the shading normal.
        w_hat = normalize(w)
        mu = dot(N_shade, w_hat)
        if mu <= 0.0:
            continue                    # neither diffuse nor specular
        if scene.model == "blinn":
            spec = max(0.0, dot(N_shade, normalize(add(w_hat, v_hat)))) ** scene.shininess
        else:
            reflected = sub(scale(2.0 * mu, N_shade), w_hat)
            spec = max(0.0, dot(reflected, v_hat)) ** scene.shininess
        for k in range(3):
            col[k] += color[k] * (scene.kd * albedo[k] * mu + scene.ks * spec)
    return tuple(min(1.0, max(0.0, c)) for c in col)


# --- one pixel, one frame ---------------------------------------------------------------

def footprint_neighbours(scene, i, j, width, height):
    """Image-plane centres of the pixels one column right and one row up of (i, j)."""
    return pixel_point(scene, i + 1, j, width, height), pixel_point(scene, i, j - 1, width, height)


def sphere_a_colour(scene, P, N, e_th, e_ph, sin_phi, u, v, hu, hv):
    """Shade a point of sphere A with gradient (h_u, h_v): perturbed normal, then lights."""
    if scene.bump == "chart":
        N_shade = perturb(N, e_th, e_ph, hu, hv, scene.beta)
    elif scene.bump == "surface":
        h = height_value(scene.height_field, u, v, scene.k_u, scene.k_v)
        N_shade = perturb_surface(N, e_th, e_ph, hu, hv, h, scene.beta, scene.radius_a, sin_phi)
    else:
        raise ValueError(f"unknown bump {scene.bump!r}")
    blockers = [(scene.center_b, scene.radius_b)] if scene.sphere_b else []
    return shade(scene, P, N, N_shade, scene.albedo_a, blockers, scene.floor)


def render_pixel(scene, i, j, width, height, gradient):
    """(rgb, chamber, kink, (h_u, h_v)) of pixel (i, j)."""
    e = scene.camera_z
    x, y = pixel_point(scene, i, j, width, height)
    t, code = nearest_hit(x, y, scene)
    if code == BACKGROUND:
        return (0.0, 0.0, 0.0), code, False, (0.0, 0.0)
    P = ray_point(t, x, y, e)
    sphere_a = ((0.0, 0.0, 0.0), scene.radius_a)
    sphere_b = (scene.center_b, scene.radius_b)
    if code == SPHERE_A:
        # Chart, frame, gradient, perturbed normal.
        N = scale(1.0 / scene.radius_a, P)
        u, v, sin_phi = chart_a(N)
        args = (scene.height_field, u, v, scene.k_u, scene.k_v)
        e_th, e_ph = tangent_frame_a(N, sin_phi)
        if gradient == "exact":
            hu, hv = grad_exact(*args)
        elif gradient == "central":
            hu, hv = grad_central(*args, scene.eps)
        else:
            neighbours = footprint_neighbours(scene, i, j, width, height)
            hu, hv = grad_central(*args, *footprint_steps(scene, P, N, e_th, e_ph, sin_phi, *neighbours))
        rgb = sphere_a_colour(scene, P, N, e_th, e_ph, sin_phi, u, v, hu, hv)
        return rgb, code, in_kink_band(*args), (hu, hv)
    if code == SPHERE_B:
        N = scale(1.0 / scene.radius_b, sub(P, scene.center_b))
        rgb = shade(scene, P, N, N, scene.albedo_b, [sphere_a], scene.floor)
        return rgb, code, False, (0.0, 0.0)
    # Floor: checker albedo, blocked by both spheres, never by itself.
    base = 0.85 if math.sin(math.pi * P[0]) * math.sin(math.pi * P[1]) >= 0.0 else 0.15
    rg = base * (1.0 - scene.floor_tint)
    blockers = [sphere_a] + ([sphere_b] if scene.sphere_b else [])
    rgb = shade(scene, P, (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), (rg, rg, base), blockers, False)
    return rgb, code, False, (0.0, 0.0)


def render_reference(scene, width, height, *, gradient="exact"):
    """Render pixel by pixel.

    Returns
    -------
    image : (H, W, 3) float64, chamber : (H, W) uint8, kink : (H, W) bool,
    grad : (H, W, 2) float64 -- numpy containers filled one pixel at a time.
    """
    if gradient not in GRADIENTS:
        raise ValueError(f"unknown gradient {gradient!r}")
    image = np.zeros((height, width, 3))
    chamber = np.zeros((height, width), dtype=np.uint8)
    kink = np.zeros((height, width), dtype=bool)
    grad = np.zeros((height, width, 2))
    for j in range(height):
        for i in range(width):
            rgb, code, flag, g = render_pixel(scene, i, j, width, height, gradient)
            image[j, i] = rgb
            chamber[j, i] = code
            kink[j, i] = flag
            grad[j, i] = g
    return image, chamber, kink, grad
