"""The per-pixel render kernel, compiled with numba.

One pixel at a time, in the order of the data flow (seed Cell 1,
``render_numeric_bump``; the §4 simulator's renderer/js/render.js and the
scalar reference of tests/ take the same steps): camera ray -> `nearest_hit`
(chamber) -> `surface` (hit point, normal, albedo) -> per light `facing`
(the normal faces the light, the floor plane does not separate them) -> on
sphere A: `chart`, `tangent_frame`, `gradient`, `shading_normal` ->
`shade_lit`: ambient + per light not `shadowed` (no blocker sphere on the
segment) Lambert and Blinn/Phong with the shading normal.

Everything up to the gradient depends on geometry alone (theorem "bump moves
no boundary"), which licenses the frames of `render_rows`: geometry and shadow
rays once per pixel, sphere A shaded per frame (an eps sweep's steps).  Sphere
A's formulas come from renderer/generated.py (`renderer.codegen` prints `renderer.formulas`).
Compiled on first use, cached in ``__pycache__`` (or numba's user cache);
as that cache checks only the file of the function it compiled, this file
holds generated.py's SHA-256 (`FORMULAS_DIGEST`) and refuses any other.
No numba threading layer: `render_rows` releases the GIL (``nogil``), and
`renderer.render.run_bands` runs its bands on Python threads.

``skip``: True does only the work the outputs need (an object that is off is
not intersected; a shadow ray only where the light could add light; at
beta = 0 no gradient unless it is an output, as beta times any gradient is
0).  False does all of it and discards what is unused: the reference path
of tests/test_skips.py, which shows both give the same bits.
"""

from __future__ import annotations

import hashlib
import math
from collections import namedtuple
from pathlib import Path

import numpy as np
from numba import njit

from . import _numba_cache

_numba_cache()          # where numba caches what it compiles, decided before its first function is decorated
from .generated import chart, footprint, perturbed_normal_chart, perturbed_normal_surface, tangent_frame  # noqa: E402

BACKGROUND, SPHERE_A, SPHERE_B, FLOOR = 0, 1, 2, 3
#: Codes of the gradient methods (`renderer.render.GRADIENTS`, in order).
EXACT, CENTRAL, FOOTPRINT = 0, 1, 2
#: Checker albedo levels of the floor's two colours (seed Cell 1).
FLOOR_LIGHT, FLOOR_DARK = 0.85, 0.15
#: Floor under |h| in Blinn's half-vector quotient (|h| = 0 only where w = -v).
TINY = 1e-300
#: The smallest positive float64 (a subnormal) and the smallest normal one.
SUBNORMAL_MIN, NORMAL_MIN = 2.0**-1074, 2.0**-1022

#: The scene as the pixel code reads it, by name (a numba Record: ``s.camera_z``,
#: ``s.center_b[0]``): floats, bools, triples (the height field is its code,
#: `renderer.fieldcode.FieldCode`, an argument of its own).  `params`
#: fills each field from the `renderer.Scene` attribute of its name, or from
#: `DERIVED` (the lights are a separate array of `LIGHT`).
SCENE = np.dtype([("camera_z", "f8"), ("radius_a", "f8"), ("center_b", "f8", (3,)), ("radius_b", "f8"),
                  ("sphere_b", "?"), ("floor", "?"), ("ambient", "f8", (3,)), ("albedo_a", "f8", (3,)),
                  ("albedo_b", "f8", (3,)), ("ka", "f8"), ("kd", "f8"), ("ks", "f8"), ("shininess", "f8"),
                  ("phong", "?"), ("floor_tint", "f8"), ("k_u", "f8"), ("k_v", "f8"),
                  ("beta", "f8"), ("surface", "?")], align=True)
#: The fields of `SCENE` that are not a Scene attribute of their name, as functions of the Scene.
DERIVED = {"phong": lambda scene: scene.model == "phong",
           "surface": lambda scene: scene.bump == "surface"}
#: A point light: position and colour (linear RGB intensities).
LIGHT = np.dtype([("position", "f8", (3,)), ("color", "f8", (3,))], align=True)
#: What `render_row` keeps of each light at one pixel, a row of an (n, `LIGHT_COLUMNS`) float64
#: array: the unit vector to the light (columns `W` to W + 2), its `specular_axis` (`AXIS` to
#: AXIS + 2, and `WV`) and its `STATE`: `UNTRACED` (the normal faces it, its shadow ray not yet
#: traced), `LIT` (it reaches the pixel) or `DARK` (it does not).  A plain array: with a record
#: array's nested fields instead, renders measured about 10 % slower.
W, AXIS, WV, STATE, LIGHT_COLUMNS = 0, 3, 6, 7, 8
UNTRACED, LIT, DARK = 0.0, 1.0, 2.0
#: What `render_rows` computes, and how (see its docstring).
Job = namedtuple("Job", "methods steps skip want_kink want_grad want_geo dx dy")
#: The arrays `render_rows` writes (see its docstring).
Outputs = namedtuple("Outputs", "image chamber kink grad t P N Ns uv")


FORMULAS_DIGEST = "9c6e1e198171ab8cb9ea0ff1480cb81b72b3f5b021ec671fb6123e0cece6b7b6"  # of generated.py, written by renderer/codegen.py
if hashlib.sha256(Path(__file__).with_name("generated.py").read_bytes()).hexdigest() != FORMULAS_DIGEST:
    raise ImportError("renderer/generated.py does not match the digest kernel.py holds: it was edited by "
                      "hand or not regenerated; run python -m renderer.codegen")


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


@njit(cache=True, error_model="numpy", inline="always")
def nearest_hit(s, x, y, skip):
    """(t, chamber) of the nearest positive hit; ties go to A, then B, then the floor."""
    t = sphere_hit(x, y, s.camera_z, 0.0, 0.0, 0.0, s.radius_a)
    code = SPHERE_A if t < math.inf else BACKGROUND
    if s.sphere_b or not skip:
        tb = sphere_hit(x, y, s.camera_z, s.center_b[0], s.center_b[1], s.center_b[2], s.radius_b)
        if s.sphere_b and tb < t:
            t, code = tb, SPHERE_B
    if s.floor and 1.0 < t:        # the floor z = 0 is the image plane: t = 1
        t, code = 1.0, FLOOR
    return t, code


@njit(cache=True, error_model="numpy")
def sphere_a_point(x, y, e, r):
    """Hit point P of the ray E + t (x, y, -e) on sphere A (centre 0, radius r);
    the ray must hit it (`sphere_hit` finite).

    Not (t x, t y, e (1 - t)) from `sphere_hit`'s t: where the sphere is small
    against its distance t is near 1, and e (1 - t) cancels to an error of u e
    (u the unit roundoff), u e / r in N = P / r, and an accepted scene has e / r
    up to MAX_LENGTH / MIN_RADIUS.  With the centre on the axis t and 1 - t
    both have forms free of cancellation.  With rho^2 = x^2 + y^2, a = rho^2 +
    e^2, disc = b^2 - a c = a r^2 - e^2 rho^2 (the e^4 terms cancelled by hand)
    and q = e^2 + sqrt(disc): t = c / q (pbrt-v4's stable root) with c =
    (e - r)(e + r) (e - r exact for e <= 2 r), and 1 - t = (q - c) / q =
    (r^2 + sqrt(disc)) / q.  Each is a quotient of sums of non-negative terms,
    so each component of P is within a few u of the exact hit's, but for the
    rounding of disc itself (the ill-condition of a grazing ray, `sphere_hit`'s
    too): that moves P along the ray and leaves |P|^2 = r^2 (1 + O(u)), so
    N = P / r is unit to a few u at every accepted e and r.
    """
    rho2 = x * x + y * y
    root = math.sqrt(max((rho2 + e * e) * r * r - e * e * rho2, 0.0))
    q = e * e + root
    t = (e - r) * (e + r) / q
    return t * x, t * y, e * ((r * r + root) / q)


@njit(cache=True, error_model="numpy")
def surface(s, x, y, t, code, checker):
    """Hit point P, geometric normal N (unit) and albedo of a hit (geometry only).

    ``checker`` = sin(pi x) sin(pi y): a floor hit is the pixel centre (x, y, 0)
    itself (t = 1), so the caller takes the sines once per column and row."""
    if code == SPHERE_A:
        r = s.radius_a
        P = sphere_a_point(x, y, s.camera_z, r)
        return P, (P[0] / r, P[1] / r, P[2] / r), (s.albedo_a[0], s.albedo_a[1], s.albedo_a[2])
    P = (t * x, t * y, s.camera_z * (1.0 - t))
    if code == SPHERE_B:
        # P - C carries the rounding of E - C, u |E - C|, against a radius
        # that may be far smaller: N is P - C over its own length (pbrt-v4
        # reprojects its sphere hits onto the surface by the same ratio).
        c = s.center_b
        nx, ny, nz = P[0] - c[0], P[1] - c[1], P[2] - c[2]
        inv = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
        return P, (nx * inv, ny * inv, nz * inv), (s.albedo_b[0], s.albedo_b[1], s.albedo_b[2])
    # Checker: light squares where sin(pi x) sin(pi y) >= 0 (seed Cell 1).
    base = FLOOR_LIGHT if checker >= 0.0 else FLOOR_DARK
    rg = base * (1.0 - s.floor_tint)
    return P, (0.0, 0.0, 1.0), (rg, rg, base)


@njit(cache=True, error_model="numpy", inline="always")
def unit_vector(wx, wy, wz, w2):
    """(wx, wy, wz) / |w| for w != 0, given w2 = |w|^2 as computed.  Below the
    smallest normal float64 (a light within its square root of the point it
    lights) w2 has lost its digits or underflowed to 0 (1 / 0: inf, then NaN
    in the shading, compiled; ZeroDivisionError, interpreted), so w is first
    divided by its largest component."""
    if w2 < NORMAL_MIN:
        m = max(abs(wx), abs(wy), abs(wz))
        wx, wy, wz = wx / m, wy / m, wz / m
        w2 = wx * wx + wy * wy + wz * wz
    inv = 1.0 / math.sqrt(w2)
    return wx * inv, wy * inv, wz * inv


@njit(cache=True, error_model="numpy", inline="always")
def chart_of(N):
    """`chart` of sphere A's normal N: (u, v, sin phi), sin phi at least the
    smallest positive float64.  At the pole itself (N_x = N_y = 0, a pixel
    centre on the optical axis) sin phi is 0, and `tangent_frame` and
    `footprint` divide by it in the branch they then discard (the pole
    fallbacks).  Compiled, 1 / 0 is inf and so is 1 / SUBNORMAL_MIN (it
    overflows), so the outputs are the same bits; interpreted
    (NUMBA_DISABLE_JIT=1), Python's float division by 0 raises
    ZeroDivisionError."""
    u, v, sin_phi = chart(N[0], N[1], N[2])
    return u, v, max(sin_phi, SUBNORMAL_MIN)


@njit(cache=True, error_model="numpy", inline="always")
def facing(s, L, P, N, code):
    """Unit vector w from P to the light L, and whether the light can reach P on
    the cheap tests: the geometric normal faces it (attached shadow) and the floor
    plane does not separate them (floor on, P off the floor); else (0, 0, 0), False."""
    wx, wy, wz = L[0] - P[0], L[1] - P[1], L[2] - P[2]
    if not N[0] * wx + N[1] * wy + N[2] * wz > 0.0:
        return (0.0, 0.0, 0.0), False
    if s.floor and code != FLOOR and ((L[2] < 0.0 and P[2] > 0.0) or (L[2] > 0.0 and P[2] < 0.0)):
        return (0.0, 0.0, 0.0), False
    return unit_vector(wx, wy, wz, wx * wx + wy * wy + wz * wz), True


@njit(cache=True, error_model="numpy", inline="always")
def shadowed(s, L, P, code, skip):
    """Does a blocker sphere (B for A, A for B, both for the floor) cut the segment from
    P to the light L (cast shadow)?  With ``skip`` sphere B is tested only if it is on."""
    wx, wy, wz = L[0] - P[0], L[1] - P[1], L[2] - P[2]
    w2 = wx * wx + wy * wy + wz * wz
    if code != SPHERE_A and segment_blocked(wx, wy, wz, w2, L, 0.0, 0.0, 0.0, s.radius_a):
        return True
    if code != SPHERE_B and (s.sphere_b or not skip):
        c = s.center_b
        return segment_blocked(wx, wy, wz, w2, L, c[0], c[1], c[2], s.radius_b) and s.sphere_b
    return False


@njit(cache=True, error_model="numpy", inline="always")
def reach(s, L, P, N, code, skip, gate, Ns):
    """(w, whether the light L reaches P): `facing` and not `shadowed`; geometry
    only.  With ``gate`` the shadow ray is not traced where Ns . w <= 0, where
    `light_term` adds nothing (then False is returned)."""
    w, ok = facing(s, L, P, N, code)
    if not ok or (gate and not Ns[0] * w[0] + Ns[1] * w[1] + Ns[2] * w[2] > 0.0):
        return w, False
    return w, not shadowed(s, L, P, code, skip)


@njit(cache=True, error_model="numpy")
def view_vector(s, P):
    """Unit vector from P to the eye (0, 0, camera_z)."""
    vx, vy, vz = -P[0], -P[1], s.camera_z - P[2]
    inv = 1.0 / math.sqrt(vx * vx + vy * vy + vz * vz)
    return vx * inv, vy * inv, vz * inv


@njit(cache=True, error_model="numpy")
def specular_axis(s, w, view):
    """The geometry of the highlight, independent of the shading normal Ns:
    (a, w . v) with the specular cosine Ns . a (Blinn: a = the unit half
    vector (w + v) / |w + v|) or 2 (Ns . w)(Ns . a) - w . v (Phong: a = v,
    the reflected light (2 (Ns . w) Ns - w) . v)."""
    if s.phong:
        return view, w[0] * view[0] + w[1] * view[1] + w[2] * view[2]
    hx, hy, hz = w[0] + view[0], w[1] + view[1], w[2] + view[2]
    inv = 1.0 / max(math.sqrt(hx * hx + hy * hy + hz * hz), TINY)   # |h| = 0 only where w = -v
    return (hx * inv, hy * inv, hz * inv), 0.0


@njit(cache=True, error_model="numpy", inline="always")
def int_power(base, n):
    """base ** n for an integer n >= 0 by repeated squaring: numba's own
    float ** int, the same multiplications in the same order, written out so
    that the kernel run interpreted (NUMBA_DISABLE_JIT=1, where Python's **
    calls libm's pow) gives the compiled bits, as renderer/js/render.js does."""
    r = 1.0
    while n != 0:
        if n & 1:
            r *= base
        n >>= 1
        base *= base
    return r


@njit(cache=True, error_model="numpy")
def light_term(s, color, w, axis, wv, Ns, albedo):
    """A light's Lambert and Blinn/Phong terms (r, g, b) at a point it reaches:
    ``w`` the unit vector to the light, (``axis``, ``wv``) its `specular_axis`
    (the formula: theorem ``shading``, proofs/shading.py)."""
    mu = Ns[0] * w[0] + Ns[1] * w[1] + Ns[2] * w[2]
    if not mu > 0.0:
        return 0.0, 0.0, 0.0
    spec_cos = Ns[0] * axis[0] + Ns[1] * axis[1] + Ns[2] * axis[2]
    if s.phong:
        spec_cos = 2.0 * mu * spec_cos - wv
    # Clamped before the power: rounding can put the cosine an ulp above 1.
    base = min(max(spec_cos, 0.0), 1.0)
    # An integral exponent (the seed's 32) by repeated squaring, faster than libm's pow.
    n = int(s.shininess)
    spec = (int_power(base, n) if n == s.shininess else base ** s.shininess) * s.ks
    diffuse = mu * s.kd
    return (color[0] * (diffuse * albedo[0] + spec), color[1] * (diffuse * albedo[1] + spec),
            color[2] * (diffuse * albedo[2] + spec))


@njit(cache=True, error_model="numpy", inline="always")
def face(s, lights, P, N, code, geo):
    """Fill ``geo`` ((n, `LIGHT_COLUMNS`) float64) with each light's `facing` at P: its unit
    vector w, and its state `UNTRACED` (its shadow ray traced when a frame first needs it) or `DARK`."""
    for k in range(lights.shape[0]):
        w, ok = facing(s, lights[k].position, P, N, code)
        geo[k, W], geo[k, W + 1], geo[k, W + 2] = w
        geo[k, STATE] = UNTRACED if ok else DARK


@njit(cache=True, error_model="numpy", inline="always")
def shade_lit(s, lights, geo, P, view, Ns, albedo, code, skip):
    """Ambient plus every light that reaches P (seed Cell 1, ``shade1``), with shading normal
    Ns and ``view`` the `view_vector`, for the lights `face` described in ``geo``: (r, g, b)
    clipped to [0, 1].  A light's
    shadow ray is traced the first time a frame needs it (with ``skip``, not where Ns . w <=
    0, where `light_term` adds nothing), and its verdict and `specular_axis` kept in ``geo``
    for the pixel's other frames."""
    r, g, b = s.ka * s.ambient[0], s.ka * s.ambient[1], s.ka * s.ambient[2]
    for k in range(lights.shape[0]):
        state = geo[k, STATE]
        if state == DARK:
            continue
        w = (geo[k, W], geo[k, W + 1], geo[k, W + 2])
        if skip and not Ns[0] * w[0] + Ns[1] * w[1] + Ns[2] * w[2] > 0.0:
            continue
        if state == UNTRACED:
            if shadowed(s, lights[k].position, P, code, skip):
                geo[k, STATE] = DARK
                continue
            axis, wv = specular_axis(s, w, view)
            geo[k, AXIS], geo[k, AXIS + 1], geo[k, AXIS + 2] = axis
            geo[k, WV], geo[k, STATE] = wv, LIT
        axis = (geo[k, AXIS], geo[k, AXIS + 1], geo[k, AXIS + 2])
        dr, dg, db = light_term(s, lights[k].color, w, axis, geo[k, WV], Ns, albedo)
        r, g, b = r + dr, g + dg, b + db
    # + 0.0: a -0.0 (a -0.0 albedo times a light) leaves as 0.0, not as a negative zero pixel.
    return min(max(r, 0.0), 1.0) + 0.0, min(max(g, 0.0), 1.0) + 0.0, min(max(b, 0.0), 1.0) + 0.0


@njit(cache=True, error_model="numpy")
def shade(s, lights, geo, P, N, Ns, albedo, code, skip):
    """One frame's (r, g, b) at P: `face` then `shade_lit` (``geo`` scratch, as `face`'s)."""
    face(s, lights, P, N, code, geo)
    return shade_lit(s, lights, geo, P, view_vector(s, P), Ns, albedo, code, skip)


@njit(cache=True, error_model="numpy", inline="always")
def gradient(s, field, method, eps, u, v, x, y, dx, dy, P, N, frame, sin_phi):
    """(h, h_u, h_v, crease flag) of the field whose functions are ``field``
    (`renderer.fieldcode.FieldCode`) by ``method``: exact, central with step
    eps, or central with the pixel's footprint as steps (pixel spacing dx, dy).
    One call of the field's code, which shares the sines of all four."""
    if method == EXACT:
        return field.exact(u, v, s.k_u, s.k_v)
    eu = ev = eps
    if method == FOOTPRINT:
        eu, ev = footprint(x, y, dx, dy, s.camera_z, P[0], P[1], P[2], N[0], N[1], N[2],
                           frame[0], frame[1], frame[2], frame[3], frame[4], frame[5], s.radius_a, sin_phi)
    return field.central(u, v, s.k_u, s.k_v, eu, ev)


@njit(cache=True, error_model="numpy")
def shading_normal(s, N, frame, h, hu, hv, sin_phi):
    """N' of sphere A (`formulas.PERTURBED_NORMAL`) for the height h and gradient (hu, hv)."""
    et0, et1, et2, ep0, ep1, ep2 = frame
    if s.surface:
        return perturbed_normal_surface(N[0], N[1], N[2], et0, et1, et2, ep0, ep1, ep2, hu, hv, s.beta,
                                        h, s.radius_a, sin_phi)
    return perturbed_normal_chart(N[0], N[1], N[2], et0, et1, et2, ep0, ep1, ep2, hu, hv, s.beta)


@njit(cache=True, error_model="numpy", nogil=True)
def render_rows(scene, lights, xs, ys, first, last, stride, job, out, field):
    """Render the pixels of rows ``first``, ``first + stride``, ... below ``last`` into the preallocated
    outputs: F frames of one geometry, which differ only in sphere A's gradient method and step.

    Per pixel the geometry (hit, normal, chart, tangent frame) is computed once, and each
    light's shadow ray at most once (theorem "bump moves no boundary": none depends on the
    gradient); sphere A is shaded per frame.  A render is one frame; an eps sweep
    (`renderer.sweep`) is the exact frame and one central frame per step.

    Parameters
    ----------
    scene : (1,) `SCENE` record array
        From `params`.
    lights : (n,) `LIGHT` record array
        From `params`.
    xs, ys : (W,), (H,) float64
        Pixel centres on the image plane (scene units).
    first, last, stride : int
        The rows to render, ``range(first, last, stride)``: 0 <= first, last <= H, stride >= 1.
    job : Job
        ``methods`` ((F,) int64: `EXACT`, `CENTRAL` or `FOOTPRINT` per frame), ``steps`` ((F,)
        float64, the central step per frame), ``skip`` (bool, see the module), ``want_kink``,
        ``want_grad``, ``want_geo`` (bool: which optional outputs to write), ``dx``, ``dy``
        (float, the pixel spacing).
    field : FieldCode
        The height field's compiled functions (`renderer.fieldcode.compiled`).
    out : Outputs
        image (F, H, W, 3) float64, chamber (H, W) uint8; kink (H, W) bool (frame 0's crease
        flag) and grad (F, H, W, 2) float64 when wanted; t (H, W), P, N, Ns (H, W, 3), uv
        (H, W, 2) float64 of frame 0 when ``want_geo`` (the GBuffer).  Written in place.

    Notes
    -----
    Nothing is checked here: the caller allocates the outputs with these shapes and dtypes
    (a wrong one is read or written out of bounds, or compiles another specialization).
    """
    sin_x = np.sin(np.pi * xs)
    geo = np.empty((lights.shape[0], LIGHT_COLUMNS))
    for j in range(first, last, stride):
        render_row(j, scene, lights, xs, ys, sin_x, geo, job, out, field)


@njit(cache=True, error_model="numpy")
def render_row(j, scene, lights, xs, ys, sin_x, geo, job, out, field):
    """Row j of `render_rows` (``geo``: scratch for `face`)."""
    s, y, sin_y = scene[0], ys[j], math.sin(math.pi * ys[j])
    methods, steps, skip, dx, dy = job.methods, job.steps, job.skip, job.dx, job.dy
    want_kink, want_grad, want_geo = job.want_kink, job.want_grad, job.want_geo
    image, chamber, kink, grad = out.image, out.chamber, out.kink, out.grad
    for i in range(xs.shape[0]):
        x = xs[i]
        t, code = nearest_hit(s, x, y, skip)
        chamber[j, i] = code
        if want_geo:
            out.t[j, i] = t
        if code == BACKGROUND:
            continue
        P, N, albedo = surface(s, x, y, t, code, sin_x[i] * sin_y)
        face(s, lights, P, N, code, geo)
        view, Ns = view_vector(s, P), N
        if code != SPHERE_A:
            rgb = shade_lit(s, lights, geo, P, view, N, albedo, code, skip)
            for f in range(image.shape[0]):
                image[f, j, i, 0], image[f, j, i, 1], image[f, j, i, 2] = rgb
        else:
            u, v, sin_phi = chart_of(N)
            frame = tangent_frame(N[0], N[1], N[2], sin_phi)
            for f in range(image.shape[0]):
                h, hu, hv, flag = 0.0, 0.0, 0.0, False
                if want_grad or want_geo or s.beta != 0.0 or not skip:
                    h, hu, hv, flag = gradient(s, field, methods[f], steps[f], u, v, x, y, dx, dy, P, N, frame,
                                               sin_phi)
                elif want_kink and f == 0:
                    flag = field.kink(u, v, s.k_u, s.k_v)
                ns = shading_normal(s, N, frame, h, hu, hv, sin_phi)
                image[f, j, i, 0], image[f, j, i, 1], image[f, j, i, 2] = shade_lit(s, lights, geo, P, view, ns,
                                                                                    albedo, code, skip)
                if want_grad:
                    grad[f, j, i, 0], grad[f, j, i, 1] = hu, hv
                if f == 0:
                    Ns = ns
                    if want_kink:
                        kink[j, i] = flag
            if want_geo:
                out.uv[j, i, 0], out.uv[j, i, 1] = u, v
        for c in range(3 if want_geo else 0):
            out.P[j, i, c], out.N[j, i, c], out.Ns[j, i, c] = P[c], N[c], Ns[c]


@njit(cache=True, error_model="numpy")
def reach_rows(scene, lights, chamber, P, N, Ns, gate, out):
    """`reach` at every pixel of a G-buffer (`renderer.pointwise.reach`): out[k, j, i] for light
    k, (H, W) uint8 chamber, (H, W, 3) float64 P, N, Ns; ``out`` (n, H, W) bool, written in place."""
    s = scene[0]
    for j in range(chamber.shape[0]):
        for i in range(chamber.shape[1]):
            code = chamber[j, i]
            if code == BACKGROUND:
                continue
            p, n, ns = (P[j, i, 0], P[j, i, 1], P[j, i, 2]), (N[j, i, 0], N[j, i, 1], N[j, i, 2]), \
                (Ns[j, i, 0], Ns[j, i, 1], Ns[j, i, 2])
            for k in range(lights.shape[0]):
                out[k, j, i] = reach(s, lights[k].position, p, n, code, True, gate, ns)[1]


def params(scene, skip=True):
    """The kernel's scene and lights, by name, for a validated `renderer.Scene`.

    Parameters
    ----------
    scene : renderer.Scene
    skip : bool
        Leave out the lights of zero colour (they add exactly 0).

    Returns
    -------
    scene : (1,) `SCENE` record array (``np.recarray``)
        Each field the Scene attribute of its name, or its `DERIVED` value.
    lights : (n,) `LIGHT` record array (``np.recarray``)
        The lights in order.

    Raises
    ------
    AttributeError
        A field of `SCENE` that is neither a Scene attribute nor in `DERIVED` (its name).
    """
    prm = np.zeros(1, SCENE).view(np.recarray)
    for name in SCENE.names:
        if name in DERIVED:
            prm[name] = DERIVED[name](scene)
        elif hasattr(scene, name):
            prm[name] = getattr(scene, name)
        else:
            raise AttributeError(f"kernel.SCENE field {name!r} is neither a Scene attribute nor in kernel.DERIVED")
    lights = [(l.position, l.color) for l in scene.lights if any(l.color) or not skip]
    return prm, np.array(lights, dtype=LIGHT).view(np.recarray)
