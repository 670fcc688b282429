"""The render kernel as one branch-free array program over a namespace ``xp``.

The steps, names and formulas of `renderer.kernel` (the numba kernel), each
applied to a whole block of pixels at once: `nearest_hit` (chamber masks) ->
`surface` -> on sphere A the generated formulas of renderer/generated_array.py
(chart, tangent frame, gradient, shading normal: `renderer.codegen` prints
them from `renderer.formulas`) -> `shade` (per light: `reach`, then
`light_term`).  A per-pixel branch becomes ``xp.select``: both sides are
computed and one is kept, so a pixel gets the value the numba kernel's branch
gives it.  What is a constant of the render (the scene, the field, the
gradient method, the outputs wanted) is branched on in Python, once.

``xp`` is a namespace of `renderer.backends`: numpy (any machine; the tests
check this program's logic with it) or Dr.Jit's LLVM backend, which traces
the program and compiles the block into one vectorized kernel (its sin, cos
and atan2 are Dr.Jit's own, a few ulp from libm's: the images agree with the
numba kernel's to the parity tolerance, not bit for bit).
"""

from __future__ import annotations

import math

import numpy as np

from . import generated_array as G
from .kernel import FLOOR_DARK, FLOOR_LIGHT, NORMAL_MIN, SUBNORMAL_MIN, TINY

__all__ = ["render_block"]


def sphere_hit(xp, x, y, e, cx, cy, cz, r):
    """`renderer.kernel.sphere_hit` over arrays x, y (the other arguments are Python floats)."""
    ox, oy, oz = -cx, -cy, e - cz
    a = x * x + y * y + e * e
    b = x * ox + y * oy - e * oz
    c = ox * ox + oy * oy + oz * oz - r * r
    f = b / a
    lx, ly, lz = ox - f * x, oy - f * y, oz + f * e
    disc = a * (r * r - (lx * lx + ly * ly + lz * lz))
    q = -(b + xp.copysign(xp.sqrt(disc), b))
    t0, t1 = q / a, c / q
    near, far = xp.minimum(t0, t1), xp.maximum(t0, t1)
    t = xp.select(near > 0.0, near, xp.select(far > 0.0, far, math.inf))
    return xp.select(disc >= 0.0, t, math.inf)


def nearest_hit(xp, s, x, y):
    """(t, on_a, on_b, on_floor): the nearest positive hit and one mask per chamber
    (None for an object that is off); ties go to A, then B, then the floor."""
    t = sphere_hit(xp, x, y, s.camera_z, 0.0, 0.0, 0.0, s.radius_a)
    on_a, on_b, on_floor = t < math.inf, None, None
    if s.sphere_b:
        t_b = sphere_hit(xp, x, y, s.camera_z, *s.center_b, s.radius_b)
        on_b = t_b < t
        t = xp.select(on_b, t_b, t)
        on_a = on_a & ~on_b
    if s.floor:                     # the floor z = 0 is the image plane: t = 1
        on_floor = 1.0 < t
        t = xp.select(on_floor, 1.0, t)
        on_a = on_a & ~on_floor
        on_b = None if on_b is None else on_b & ~on_floor
    return t, on_a, on_b, on_floor


def sphere_a_point(xp, x, y, e, r):
    """`renderer.kernel.sphere_a_point`: sphere A's hit point, free of cancellation."""
    rho2 = x * x + y * y
    root = xp.sqrt(xp.maximum((rho2 + e * e) * r * r - e * e * rho2, 0.0))
    q = e * e + root
    t = (e - r) * (e + r) / q
    return t * x, t * y, e * ((r * r + root) / q)


def _pick(xp, mask, a, b):
    """a where mask, else b, per component of two triples (mask None: b)."""
    return b if mask is None else tuple(xp.select(mask, p, q) for p, q in zip(a, b))


def surface(xp, s, x, y, t, on_a, on_b, checker):
    """(P, N, albedo, N_a): hit point, unit geometric normal and albedo of every
    pixel's chamber (garbage on the background), and sphere A's normal P / R."""
    r, e = s.radius_a, s.camera_z
    P_a = sphere_a_point(xp, x, y, e, r)
    N_a = (P_a[0] / r, P_a[1] / r, P_a[2] / r)
    P = (t * x, t * y, e * (1.0 - t))
    # The floor, unless B or A replaces it: checker light where sin(pi x) sin(pi y) >= 0.
    base = xp.select(checker >= 0.0, FLOOR_LIGHT, FLOOR_DARK)
    rg = base * (1.0 - s.floor_tint)
    N, albedo = (0.0, 0.0, 1.0), (rg, rg, base)
    if on_b is not None:
        c = s.center_b
        nx, ny, nz = P[0] - c[0], P[1] - c[1], P[2] - c[2]
        inv = 1.0 / xp.sqrt(nx * nx + ny * ny + nz * nz)
        N = _pick(xp, on_b, (nx * inv, ny * inv, nz * inv), N)
        albedo = _pick(xp, on_b, s.albedo_b, albedo)
    return (_pick(xp, on_a, P_a, P), _pick(xp, on_a, N_a, N), _pick(xp, on_a, s.albedo_a, albedo), N_a)


def unit_vector(xp, wx, wy, wz, w2):
    """`renderer.kernel.unit_vector`: where w2 is below the smallest normal float64, w is
    first divided by its largest component (elsewhere by 1.0, which is exact)."""
    small = w2 < NORMAL_MIN
    m = xp.select(small, xp.maximum(xp.maximum(xp.abs(wx), xp.abs(wy)), xp.abs(wz)), 1.0)
    wx, wy, wz = wx / m, wy / m, wz / m
    w2 = xp.select(small, wx * wx + wy * wy + wz * wz, w2)
    inv = 1.0 / xp.sqrt(w2)
    return wx * inv, wy * inv, wz * inv


def segment_blocked(xp, wx, wy, wz, w2, L, c, r):
    """`renderer.kernel.segment_blocked`; the light L and the sphere (c, r) are constants,
    so the case of the light (inside, on, outside the sphere) is a Python branch."""
    dx, dy, dz = L[0] - c[0], L[1] - c[1], L[2] - c[2]
    k = dx * dx + dy * dy + dz * dz - r * r
    if k < 0.0:
        return True
    g = wx * dx + wy * dy + wz * dz
    if k == 0.0:
        return (g > 0.0) & (2.0 * g < w2)
    return (g > 0.0) & (g < w2) & (g * g >= w2 * k)


def reach(xp, s, L, P, N, Ns, on_a, on_b, on_floor):
    """(w, mu, lit): unit vector to the light L, Ns . w and whether the light adds
    light (`renderer.kernel.reach` with its gate: N and Ns face it, the floor
    plane does not separate them, no blocker sphere cuts the segment)."""
    wx, wy, wz = L[0] - P[0], L[1] - P[1], L[2] - P[2]
    lit = N[0] * wx + N[1] * wy + N[2] * wz > 0.0
    if on_floor is not None and L[2] != 0.0:
        separated = (P[2] > 0.0) if L[2] < 0.0 else (P[2] < 0.0)
        lit = lit & (on_floor | ~separated)
    w2 = wx * wx + wy * wy + wz * wz
    w = unit_vector(xp, wx, wy, wz, w2)
    mu = Ns[0] * w[0] + Ns[1] * w[1] + Ns[2] * w[2]
    lit = lit & (mu > 0.0)
    blockers = [((0.0, 0.0, 0.0), s.radius_a, on_a)] + ([(s.center_b, s.radius_b, on_b)] if s.sphere_b else [])
    for centre, radius, on_it in blockers:          # a sphere does not block its own points
        blocked = segment_blocked(xp, wx, wy, wz, w2, L, centre, radius)
        lit = lit & on_it if blocked is True else lit & (on_it | ~blocked)
    return w, mu, lit


def view_vector(xp, s, P):
    """Unit vector from P to the eye (0, 0, camera_z)."""
    vx, vy, vz = -P[0], -P[1], s.camera_z - P[2]
    inv = 1.0 / xp.sqrt(vx * vx + vy * vy + vz * vz)
    return vx * inv, vy * inv, vz * inv


def specular_axis(xp, s, w, view):
    """`renderer.kernel.specular_axis`: (a, w . v)."""
    if s.model == "phong":
        return view, w[0] * view[0] + w[1] * view[1] + w[2] * view[2]
    hx, hy, hz = w[0] + view[0], w[1] + view[1], w[2] + view[2]
    inv = 1.0 / xp.maximum(xp.sqrt(hx * hx + hy * hy + hz * hz), TINY)   # |h| = 0 only where w = -v
    return (hx * inv, hy * inv, hz * inv), 0.0


def int_power(base, n):
    """base ** n for a Python int n >= 0: `renderer.kernel.int_power`'s multiplications."""
    r = None
    while n != 0:
        if n & 1:
            r = base if r is None else r * base     # 1.0 * base is base
        n >>= 1
        if n:
            base = base * base
    return 1.0 if r is None else r


def light_term(xp, s, color, mu, axis, wv, Ns, albedo):
    """`renderer.kernel.light_term` where the light reaches (mu = Ns . w > 0)."""
    spec_cos = Ns[0] * axis[0] + Ns[1] * axis[1] + Ns[2] * axis[2]
    if s.model == "phong":
        spec_cos = 2.0 * mu * spec_cos - wv
    base = xp.minimum(xp.maximum(spec_cos, 0.0), 1.0)
    n = int(s.shininess)
    spec = (int_power(base, n) if n == s.shininess else xp.power(base, s.shininess)) * s.ks
    diffuse = mu * s.kd
    return tuple(color[c] * (diffuse * albedo[c] + spec) for c in range(3))


def gradient(xp, s, method, eps, u, v, x, y, dx, dy, P, N, frame, sin_phi):
    """(h_u, h_v) on sphere A by ``method`` ("exact", "central", "footprint")."""
    field = G.FIELD_CODES[s.height_field]
    if method == "exact":
        return G.exact_gradient(xp, field, u, v, s.k_u, s.k_v)
    eu = ev = eps
    if method == "footprint":
        eu, ev = G.footprint(xp, x, y, dx, dy, s.camera_z, *P, *N, *frame, s.radius_a, sin_phi)
    return G.central_gradient(xp, field, u, v, s.k_u, s.k_v, eu, ev)


def render_block(xp, s, xs, ys, *, method, eps, dx, dy, kink, grad):
    """Render the pixels (xs[i], ys[j]) of a block of rows, row-major.

    Parameters
    ----------
    xp : a namespace of `renderer.backends`
    s : renderer.Scene, validated
    xs : (W,) float64, ys (B,) float64
        Pixel centres on the image plane (`renderer.render.image_plane`).
    method : {"exact", "central", "footprint"}
    eps : float
        The central step (scene units of the chart).
    dx, dy : float
        Pixel spacing (the footprint's ray differentials).
    kink, grad : bool
        Whether to return the crease flags and the gradient.

    Returns
    -------
    dict of numpy arrays of W * B pixels
        ``image`` (n, 3) float64 in [0, 1], ``chamber`` (n,) uint8, and when
        asked ``kink`` (n,) bool and ``grad`` (n, 2) float64 (0 off sphere A).
    """
    return xp.run(program, s, (xs, ys, np.sin(np.pi * xs), np.sin(np.pi * ys)), OUTPUTS,
                  method=method, eps=eps, dx=dx, dy=dy, kink=kink, grad=grad)


#: Each output of `program`: (values per pixel, numpy dtype).
OUTPUTS = {"image": (3, np.float64), "chamber": (1, np.uint8), "kink": (1, np.bool_), "grad": (2, np.float64)}


def program(xp, s, xs, ys, sin_xs, sin_ys, *, method, eps, dx, dy, kink, grad):
    """The frame's array program: `render_block`'s outputs as a dict name -> list of
    arrays of the namespace (k arrays for k values per pixel, `OUTPUTS`), unevaluated
    on Dr.Jit; xs, ys and their sines sin(pi xs), sin(pi ys) as arrays of ``xp``."""
    x, y = xp.grid(xs, ys)
    sin_x, sin_y = xp.grid(sin_xs, sin_ys)
    t, on_a, on_b, on_floor = nearest_hit(xp, s, x, y)
    P, N, albedo, N_a = surface(xp, s, x, y, t, on_a, on_b, sin_x * sin_y)

    # Sphere A: chart, frame, gradient, shading normal (the generated formulas).
    field = G.FIELD_CODES[s.height_field]
    u, v, sin_phi = G.chart(xp, *N_a)
    sin_phi = xp.maximum(sin_phi, SUBNORMAL_MIN)
    frame = G.tangent_frame(xp, *N_a, sin_phi)
    hu = hv = 0.0
    if grad or s.beta != 0.0:           # beta = 0: the gradient moves nothing
        hu, hv = gradient(xp, s, method, eps, u, v, x, y, dx, dy, P, N_a, frame, sin_phi)
    if s.bump == "surface":
        h = G.height(xp, field, u, v, s.k_u, s.k_v)
        Ns_a = G.perturbed_normal_surface(xp, *N_a, *frame, hu, hv, s.beta, h, s.radius_a, sin_phi)
    else:
        Ns_a = G.perturbed_normal_chart(xp, *N_a, *frame, hu, hv, s.beta)
    Ns = _pick(xp, on_a, Ns_a, N)

    # Ambient plus every light that reaches the point.
    rgb = tuple(s.ka * a for a in s.ambient)
    view = view_vector(xp, s, P)
    for light in s.lights:
        if not any(light.color):        # a black light adds exactly 0
            continue
        w, mu, lit = reach(xp, s, tuple(light.position), P, N, Ns, on_a, on_b, on_floor)
        axis, wv = specular_axis(xp, s, w, view)
        term = light_term(xp, s, light.color, mu, axis, wv, Ns, albedo)
        rgb = tuple(xp.select(lit, c + d, c) for c, d in zip(rgb, term))
    hit = t < math.inf
    # + 0.0: a -0.0 leaves as 0.0, as in the numba kernel.
    rgb = [xp.select(hit, xp.minimum(xp.maximum(c, 0.0), 1.0) + 0.0, 0.0) for c in rgb]
    chamber = xp.select(on_a, 1.0, 0.0)
    for mask, code in ((on_b, 2.0), (on_floor, 3.0)):
        chamber = chamber if mask is None else xp.select(mask, code, chamber)
    out = {"image": rgb, "chamber": [chamber]}
    if kink:
        out["kink"] = [on_a & G.kink_band(xp, field, u, v, s.k_u, s.k_v)]
    if grad:
        out["grad"] = [xp.select(on_a, hu, 0.0), xp.select(on_a, hv, 0.0)]
    return out
