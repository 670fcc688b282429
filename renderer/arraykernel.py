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
The scene's numbers enter as values (`scene_values`), not as constants of
the program: Dr.Jit compiles one kernel per `structure` of a scene (its
Python-level branches), and scenes that differ only in numbers share it.

``xp`` is a namespace of `renderer.backends`: numpy (any machine; the tests
check this program's logic with it) or Dr.Jit's LLVM backend, which traces
the program and compiles the block into one vectorized kernel (its sin, cos
and atan2 are Dr.Jit's own, a few ulp from libm's: the images agree with the
numba kernel's to the parity tolerance, not bit for bit).
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from . import fieldcode
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


def nearest_hit(xp, s, v, x, y):
    """(t, on_a, on_b, on_floor): the nearest positive hit and one mask per chamber
    (None for an object that is off); ties go to A, then B, then the floor."""
    t = sphere_hit(xp, x, y, v.camera_z, 0.0, 0.0, 0.0, v.radius_a)
    on_a, on_b, on_floor = t < math.inf, None, None
    if s.sphere_b:
        t_b = sphere_hit(xp, x, y, v.camera_z, *v.center_b, v.radius_b)
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


def surface(xp, v, x, y, t, on_a, on_b, checker):
    """(P, N, albedo, N_a): hit point, unit geometric normal and albedo of every
    pixel's chamber (garbage on the background), and sphere A's normal P / R."""
    r, e = v.radius_a, v.camera_z
    P_a = sphere_a_point(xp, x, y, e, r)
    N_a = (P_a[0] / r, P_a[1] / r, P_a[2] / r)
    P = (t * x, t * y, e * (1.0 - t))
    # The floor, unless B or A replaces it: checker light where sin(pi x) sin(pi y) >= 0.
    base = xp.select(checker >= 0.0, FLOOR_LIGHT, FLOOR_DARK)
    rg = base * (1.0 - v.floor_tint)
    N, albedo = (0.0, 0.0, 1.0), (rg, rg, base)
    if on_b is not None:
        c = v.center_b
        nx, ny, nz = P[0] - c[0], P[1] - c[1], P[2] - c[2]
        inv = 1.0 / xp.sqrt(nx * nx + ny * ny + nz * nz)
        N = _pick(xp, on_b, (nx * inv, ny * inv, nz * inv), N)
        albedo = _pick(xp, on_b, v.albedo_b, albedo)
    return (_pick(xp, on_a, P_a, P), _pick(xp, on_a, N_a, N), _pick(xp, on_a, v.albedo_a, albedo), N_a)


def unit_vector(xp, wx, wy, wz, w2):
    """`renderer.kernel.unit_vector`: where w2 is below the smallest normal float64, w is
    first divided by its largest component (elsewhere by 1.0, which is exact)."""
    small = w2 < NORMAL_MIN
    m = xp.select(small, xp.maximum(xp.maximum(xp.abs(wx), xp.abs(wy)), xp.abs(wz)), 1.0)
    wx, wy, wz = wx / m, wy / m, wz / m
    w2 = xp.select(small, wx * wx + wy * wy + wz * wz, w2)
    inv = 1.0 / xp.sqrt(w2)
    return wx * inv, wy * inv, wz * inv


def _light_offset(L, c, r):
    """(d, k): the light L less the sphere's centre c, and |d|^2 - r^2 (k < 0: L inside)."""
    d = (L[0] - c[0], L[1] - c[1], L[2] - c[2])
    return d, d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - r * r


def light_case(L, c, r):
    """Where the light L is against the sphere (c, r), Python floats: -1 inside, 0 on it,
    1 outside (the sign of `segment_blocked`'s k)."""
    k = _light_offset(L, c, r)[1]
    return (k > 0.0) - (k < 0.0)


def segment_blocked(xp, wx, wy, wz, w2, case, L, c, r):
    """`renderer.kernel.segment_blocked` for the light L and the sphere (c, r), values of
    the render; the case of the light (`light_case`) is a Python branch."""
    if case < 0:
        return True
    (dx, dy, dz), k = _light_offset(L, c, r)
    g = wx * dx + wy * dy + wz * dz
    if case == 0:
        return (g > 0.0) & (2.0 * g < w2)
    return (g > 0.0) & (g < w2) & (g * g >= w2 * k)


def reach(xp, s, v, i, P, N, Ns, on_a, on_b, on_floor):
    """(w, mu, lit): unit vector to light i, Ns . w and whether the light adds
    light (`renderer.kernel.reach` with its gate: N and Ns face it, the floor
    plane does not separate them, no blocker sphere cuts the segment)."""
    L, Lz = v.lights[i].position, s.lights[i].position[2]     # values; the side of z = 0 decides
    wx, wy, wz = L[0] - P[0], L[1] - P[1], L[2] - P[2]
    lit = N[0] * wx + N[1] * wy + N[2] * wz > 0.0
    if on_floor is not None and Lz != 0.0:
        separated = (P[2] > 0.0) if Lz < 0.0 else (P[2] < 0.0)
        lit = lit & (on_floor | ~separated)
    w2 = wx * wx + wy * wy + wz * wz
    w = unit_vector(xp, wx, wy, wz, w2)
    mu = Ns[0] * w[0] + Ns[1] * w[1] + Ns[2] * w[2]
    lit = lit & (mu > 0.0)
    blockers = [((0.0, 0.0, 0.0), v.radius_a, on_a)] + ([(v.center_b, v.radius_b, on_b)] if s.sphere_b else [])
    for case, (centre, radius, on_it) in zip(_light_cases(s, i), blockers):   # not its own points
        blocked = segment_blocked(xp, wx, wy, wz, w2, case, L, centre, radius)
        lit = lit & on_it if blocked is True else lit & (on_it | ~blocked)
    return w, mu, lit


def view_vector(xp, v, P):
    """Unit vector from P to the eye (0, 0, camera_z)."""
    vx, vy, vz = -P[0], -P[1], v.camera_z - P[2]
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


def light_term(xp, s, v, color, mu, axis, wv, Ns, albedo):
    """`renderer.kernel.light_term` where the light reaches (mu = Ns . w > 0)."""
    spec_cos = Ns[0] * axis[0] + Ns[1] * axis[1] + Ns[2] * axis[2]
    if s.model == "phong":
        spec_cos = 2.0 * mu * spec_cos - wv
    base = xp.minimum(xp.maximum(spec_cos, 0.0), 1.0)
    n = int(s.shininess)
    spec = (int_power(base, n) if n == s.shininess else xp.power(base, v.shininess)) * v.ks
    diffuse = mu * v.kd
    return tuple(color[c] * (diffuse * albedo[c] + spec) for c in range(3))


def gradient(xp, code, q, method, u, v, x, y, P, N, frame, sin_phi):
    """(h, h_u, h_v, crease flag) on sphere A of the field whose array functions are ``code``
    (`renderer.fieldcode.array_code`) by ``method`` ("exact", "central", "footprint"); ``q``
    the render's values (`scene_values`)."""
    if method == "exact":
        return code.exact(xp, u, v, q.k_u, q.k_v)
    eu = ev = q.eps
    if method == "footprint":
        eu, ev = G.footprint(xp, x, y, q.dx, q.dy, q.camera_z, *P, *N, *frame, q.radius_a, sin_phi)
    return code.central(xp, u, v, q.k_u, q.k_v, eu, ev)


#: The numbers of a scene the program computes with (a tuple attribute: its components),
#: then each light's position and colour, then the render's eps, dx, dy: `scene_values`.
NUMBERS = ("camera_z", "radius_a", "radius_b", "center_b", "albedo_a", "albedo_b", "floor_tint", "ka", "kd",
           "ks", "ambient", "shininess", "k_u", "k_v", "beta")


def scene_values(s, eps, dx, dy):
    """The render's numbers as one flat tuple of Python floats: `NUMBERS` of the scene,
    each light's position and colour, eps, dx, dy (`values` reads it back)."""
    flat = []
    for name in NUMBERS:
        value = getattr(s, name)
        flat.extend(map(float, value) if isinstance(value, tuple) else [float(value)])
    for light in s.lights:
        flat.extend(map(float, (*light.position, *light.color)))
    return tuple(flat) + (float(eps), float(dx), float(dy))


def values(s, flat):
    """`scene_values`' tuple read back as a namespace with the scene's attribute names
    (``lights`` a list of namespaces with ``position``, ``color``; ``eps``, ``dx``,
    ``dy``), its entries whatever ``flat`` holds: Python floats, or Dr.Jit values."""
    it = iter(flat)
    out = {}
    for name in NUMBERS:
        n = len(getattr(s, name)) if isinstance(getattr(s, name), tuple) else 0
        out[name] = tuple(next(it) for _ in range(n)) if n else next(it)
    out["lights"] = [SimpleNamespace(position=tuple(next(it) for _ in range(3)), color=tuple(next(it) for _ in range(3)))
                     for _ in s.lights]
    out["eps"], out["dx"], out["dy"] = next(it), next(it), next(it)
    return SimpleNamespace(**out)


def _light_cases(s, i):
    """Light i against each blocker sphere (A, then B when on): `light_case`."""
    L = s.lights[i].position
    spheres = [((0.0, 0.0, 0.0), s.radius_a)] + ([(s.center_b, s.radius_b)] if s.sphere_b else [])
    return tuple(light_case(L, c, r) for c, r in spheres)


def structure(s):
    """Every property of scene ``s`` that `program` branches on in Python: two scenes with
    the same structure run the same program on different values (`scene_values`), so
    Dr.Jit replays one compiled kernel for both."""
    n = int(s.shininess)
    return (s.height_field, s.bump, s.model, s.sphere_b, s.floor, s.beta == 0.0,
            n if n == s.shininess else None,
            tuple((any(light.color), (light.position[2] > 0.0) - (light.position[2] < 0.0), _light_cases(s, i))
                  for i, light in enumerate(s.lights)))


def render_block(xp, s, xs, ys, *, method, eps, dx, dy, kink, grad, normal=False):
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
    kink, grad, normal : bool
        Whether to return the crease flags, the gradient and the shading normal.

    Returns
    -------
    dict of numpy arrays of W * B pixels
        ``image`` (n, 3) float64 in [0, 1], ``chamber`` (n,) uint8, and when
        asked ``kink`` (n,) bool, ``grad`` (n, 2) float64 (0 off sphere A) and ``normal``
        (n, 3) float64, the unit shading normal (the bumped one on sphere A, the geometric
        one elsewhere; garbage on the background), as `renderer.GBuffer.Ns`.
    """
    return xp.run(program, s, structure(s), scene_values(s, eps, dx, dy),
                  (xs, ys, np.sin(np.pi * xs), np.sin(np.pi * ys)), OUTPUTS, method=method, kink=kink, grad=grad,
                  normal=normal)


#: Each output of `program`: (values per pixel, numpy dtype).
OUTPUTS = {"image": (3, np.float64), "chamber": (1, np.uint8), "kink": (1, np.bool_), "grad": (2, np.float64),
           "normal": (3, np.float64)}


def program(xp, s, flat, xs, ys, sin_xs, sin_ys, *, method, kink, grad, normal=False):
    """The frame's array program: `render_block`'s outputs as a dict name -> list of
    arrays of the namespace (k arrays for k values per pixel, `OUTPUTS`), unevaluated
    on Dr.Jit.  ``s`` decides the branches (only through `structure`), ``flat`` (its
    `scene_values`, as floats or values of ``xp``) gives the numbers; xs, ys and their
    sines sin(pi xs), sin(pi ys) as arrays of ``xp``."""
    q = values(s, flat)
    x, y = xp.grid(xs, ys)
    sin_x, sin_y = xp.grid(sin_xs, sin_ys)
    t, on_a, on_b, on_floor = nearest_hit(xp, s, q, x, y)
    P, N, albedo, N_a = surface(xp, q, x, y, t, on_a, on_b, sin_x * sin_y)

    # Sphere A: chart, frame, gradient, shading normal (the generated formulas).
    code = fieldcode.array_code(s.field)
    u, v, sin_phi = G.chart(xp, *N_a)
    sin_phi = xp.maximum(sin_phi, SUBNORMAL_MIN)
    frame = G.tangent_frame(xp, *N_a, sin_phi)
    h = hu = hv = 0.0
    flag = None
    if grad or s.beta != 0.0:           # beta = 0: the gradient moves nothing
        h, hu, hv, flag = gradient(xp, code, q, method, u, v, x, y, P, N_a, frame, sin_phi)
    if s.bump == "surface":
        Ns_a = G.perturbed_normal_surface(xp, *N_a, *frame, hu, hv, q.beta, h, q.radius_a, sin_phi)
    else:
        Ns_a = G.perturbed_normal_chart(xp, *N_a, *frame, hu, hv, q.beta)
    Ns = _pick(xp, on_a, Ns_a, N)

    # Ambient plus every light that reaches the point.
    rgb = tuple(q.ka * a for a in q.ambient)
    view = view_vector(xp, q, P)
    for i, light in enumerate(s.lights):
        if not any(light.color):        # a black light adds exactly 0
            continue
        w, mu, lit = reach(xp, s, q, i, P, N, Ns, on_a, on_b, on_floor)
        axis, wv = specular_axis(xp, s, w, view)
        term = light_term(xp, s, q, q.lights[i].color, mu, axis, wv, Ns, albedo)
        rgb = tuple(xp.select(lit, c + d, c) for c, d in zip(rgb, term))
    hit = t < math.inf
    # + 0.0: a -0.0 leaves as 0.0, as in the numba kernel.
    rgb = [xp.select(hit, xp.minimum(xp.maximum(c, 0.0), 1.0) + 0.0, 0.0) for c in rgb]
    chamber = xp.select(on_a, 1.0, 0.0)
    for mask, number in ((on_b, 2.0), (on_floor, 3.0)):
        chamber = chamber if mask is None else xp.select(mask, number, chamber)
    out = {"image": rgb, "chamber": [chamber]}
    if kink:
        out["kink"] = [on_a & (code.kink(xp, u, v, q.k_u, q.k_v) if flag is None else flag)]
    if grad:
        out["grad"] = [xp.select(on_a, hu, 0.0), xp.select(on_a, hv, 0.0)]
    if normal:
        out["normal"] = list(Ns)
    return out
