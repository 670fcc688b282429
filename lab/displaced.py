"""Sphere A truly displaced: the surface r = R + beta h(u, v), rendered by root finding.

The bump modes of `renderer` tilt the normal of the undisplaced sphere; the
"surface" mode's normal is that of exactly this displaced surface, but the
silhouette, the cast shadows and the bumps' shadows on one another stay those
of the sphere.  `render_displaced` renders the displaced surface itself with
the renderer's camera, lights and materials, and counts what changes.

Per pixel the ray's first root of F(P) = |P| - R - beta h(chart(P / |P|)) is
bracketed between the spheres of radius R +- beta max|h| (`H_MAX`): ``samples``
evenly spaced points of the ray inside the outer sphere, up to where it enters
the inner one, find the first sign change, and safeguarded Newton steps
(bisection when a step leaves the bracket) converge to it.  F and its gradient
are sympy's, lambdified from the field's expression and `renderer.formulas.CHART`; the
normal is grad F / |grad F|.  A shadow ray is blocked by sphere A where one of
``samples`` points of its segment inside the outer sphere has F < 0, and by
sphere B as in the renderer.  The shading is the kernel's own
(`renderer.kernel.shade`), called with the displaced geometry.

Sampling can miss a sliver of the surface thinner than the spacing between
samples (a ray grazing a bump's crest); ``samples`` sets the spacing.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass

import numpy as np
import sympy as sp
from numba import njit

from renderer import GBuffer, formulas, gbuffer, kernel, pointwise, render
from renderer.render import Frame, check_args, image_plane
from renderer.intervals import search_chart
from renderer.validate import InvalidValue, positive_int

__all__ = ["Displaced", "render_displaced", "surface_function", "H_MAX", "MAX_SAMPLES"]

#: The bound on |h| the bracketing assumes (the built-in fields are sines, their products and |.| of
#: one); `render_displaced` refuses a field that exceeds it on the chart (`_check_bounded`).
H_MAX = 1.0
#: Points per side of the chart grid on which a field is held to `H_MAX`.
BOUND_CHECK_POINTS = 257
#: Most samples per ray (the root-bracketing march and the shadow segments).
MAX_SAMPLES = 4096
#: Newton-bisection stops when the step is below this fraction of t, or after `MAX_NEWTON` steps.
REL_TOL, MAX_NEWTON = 1e-14, 60
#: A shadow-ray point is inside sphere A where F < -SHADOW_TOL R: F's rounding (a few ulps of R) at
#: points next to the surface point the ray leaves must not shadow it.
SHADOW_TOL = 1e-12
#: Shadow-segment points evaluated at once (memory: 24 bytes each, several arrays).
CHUNK = 1 << 20

_X, _Y, _Z = sp.symbols("X Y Z", real=True)


def surface_function(field):
    """F and grad F of the displaced sphere for one height field, as numpy functions.

    F(P) = |P| - R - beta h(u, v), (u, v) the chart (`renderer.formulas.CHART`) of P / |P|,
    h the field's expression; its gradient by sympy.  F < 0 inside the surface.

    Parameters
    ----------
    field : height field
        As `renderer.formulas.field` takes it.

    Returns
    -------
    (F, grad) : callables of (X, Y, Z, R, beta, k_u, k_v), arrays that broadcast (scene units);
        F returns one float64 array, grad a list of three (dF/dX, dF/dY, dF/dZ), dimensionless.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``field`` is refused (`renderer.formulas.field`, naming "field").
    """
    return _surface_function(formulas.field(field, "field"))


@functools.lru_cache(maxsize=None)
def _surface_function(record):
    h = record.expr
    r = sp.sqrt(_X**2 + _Y**2 + _Z**2)
    uv = {formulas.N_x: _X / r, formulas.N_y: _Y / r, formulas.N_z: _Z / r}
    chart = {formulas.u: formulas.CHART[0].xreplace(uv), formulas.v: formulas.CHART[1].xreplace(uv)}
    F = r - formulas.R - formulas.beta * h.xreplace(chart)
    args = (_X, _Y, _Z, formulas.R, formulas.beta, formulas.k_u, formulas.k_v)
    return (sp.lambdify(args, F, "numpy", cse=True),
            sp.lambdify(args, [sp.diff(F, s) for s in (_X, _Y, _Z)], "numpy", cse=True))


def _sphere_span(O, D, radius):
    """(t_near, t_far) of the rays O + t D (O, D (n, 3)) on the sphere |P| = radius; NaN where
    they miss it.  Stable roots q = -(b + sign(b) sqrt(disc)), t = q / a, c / q (pbrt-v4)."""
    a = np.einsum("ij,ij->i", D, D)
    b = np.einsum("ij,ij->i", O, D)
    c = np.einsum("ij,ij->i", O, O) - radius**2
    disc = b * b - a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        q = -(b + np.copysign(np.sqrt(disc), b))
        t0, t1 = q / a, c / q
    miss = ~(disc >= 0)
    return np.where(miss, np.nan, np.minimum(t0, t1)), np.where(miss, np.nan, np.maximum(t0, t1))


@dataclass(frozen=True)
class Displaced:
    """A frame of the displaced sphere beside the bumped render of the same scene.

    Attributes
    ----------
    image : (H, W, 3) float64
        Linear RGB in [0, 1], the displaced sphere A shaded by `renderer.kernel.shade`.
    chamber : (H, W) uint8
        0 background, 1 sphere A (displaced), 2 sphere B, 3 floor.
    covered : (H, W) bool
        The coverage mask of the displaced sphere A (chamber == 1).
    shadow : (H, W) bool
        Cast shadow: a light the surface faces (geometric normal) does not reach the point.
    P, normal : (H, W, 3) float64
        Hit point (scene units) and unit geometric normal (0 on the background).
    bumped : renderer.Frame
        ``render(scene, W, H, gradient="exact")``, the bump-mapped frame compared with.
    bumped_shadow : (H, W) bool
        `shadow` of the bumped frame, by the kernel's own reach (`renderer.pointwise.reach`).
    silhouette_changed : int
        Pixels covered by sphere A in one frame and not the other.
    shadow_changed : int
        Pixels in `shadow` in one frame and not the other.
    self_shadowed : int
        Pixels on sphere A in both frames where a light is blocked by the displaced sphere
        A itself and lights the pixel in the bumped frame (reaches it with Ns . w > 0).
    blocked : (n_lights, H, W) bool
        The displaced sphere A cuts the segment from the hit point to light k (asked where the
        surface faces the light and is not the background; False elsewhere).
    samples : int
        Points per ray and per shadow segment of the bracketing march.
    newton_max, newton_mean : int, float
        Newton-bisection steps after the march, most and mean over sphere A's pixels.
    seconds, render_seconds : float
        Wall time of this frame (geometry, shadows, shading) and of the bumped `render`
        (compiled, second call), in seconds.
    """

    image: np.ndarray
    chamber: np.ndarray
    covered: np.ndarray
    shadow: np.ndarray
    P: np.ndarray
    normal: np.ndarray
    bumped: Frame
    bumped_shadow: np.ndarray
    silhouette_changed: int
    shadow_changed: int
    self_shadowed: int
    blocked: np.ndarray
    samples: int
    newton_max: int
    newton_mean: float
    seconds: float
    render_seconds: float


def _first_root(scene, O, D, samples):
    """Hit t (NaN: miss), point, unit normal and Newton steps of rays O + t D on the displaced sphere."""
    F, grad = _surface_function(scene.field)
    R, beta = scene.radius_a, scene.beta
    const = (R, beta, scene.k_u, scene.k_v)
    t0, t1 = _sphere_span(O, D, R + beta * H_MAX)
    ti, _ = _sphere_span(O, D, R - beta * H_MAX)
    inner = np.isfinite(ti)
    end = np.where(inner, ti, t1)
    n = O.shape[0]
    lo, hi = np.full(n, np.nan), np.full(n, np.nan)
    k = np.arange(1, samples + 1) / samples
    for rows in np.array_split(np.flatnonzero(np.isfinite(t0)), max(1, n * samples // CHUNK)):
        ts = t0[rows, None] + (end[rows] - t0[rows])[:, None] * k            # (rows, samples)
        pts = O[rows, None, :] + ts[..., None] * D[rows, None, :]
        inside = F(pts[..., 0], pts[..., 1], pts[..., 2], *const) <= 0.0
        # The first sample inside; on a ray into the inner sphere, its entry at the latest.
        first = np.where(inside.any(axis=1), inside.argmax(axis=1), np.where(inner[rows], samples - 1, -1))
        hit = first >= 0
        lo[rows[hit]] = np.where(first[hit] > 0, ts[hit, first[hit] - 1], t0[rows[hit]])
        hi[rows[hit]] = ts[hit, first[hit]]
    hit = np.isfinite(lo)
    t, steps = (lo + hi) / 2, np.zeros(n, np.int64)
    active = hit.copy()
    for _ in range(MAX_NEWTON):
        if not active.any():
            break
        a = np.flatnonzero(active)
        p = O[a] + t[a, None] * D[a]
        f = F(p[:, 0], p[:, 1], p[:, 2], *const)
        df = np.einsum("ij,ij->i", np.stack(np.broadcast_arrays(*grad(p[:, 0], p[:, 1], p[:, 2], *const)), -1),
                       D[a])
        lo[a] = np.where(f > 0, t[a], lo[a])
        hi[a] = np.where(f > 0, hi[a], t[a])
        with np.errstate(invalid="ignore", divide="ignore"):
            new = t[a] - f / df
        done = np.abs(new - t[a]) <= REL_TOL * np.abs(t[a])
        new = np.where(done | ((new > lo[a]) & (new < hi[a])), new, (lo[a] + hi[a]) / 2)
        t[a], steps[a] = new, steps[a] + 1
        active[a[done]] = False
    t[~hit] = np.nan
    P = O + t[:, None] * D
    g = np.stack(np.broadcast_arrays(*grad(P[:, 0], P[:, 1], P[:, 2], *const)), -1)
    normal = g / np.linalg.norm(g, axis=1, keepdims=True)
    # The pole (P on the z axis): the chart's u is undefined there; the radial direction stands in.
    radial = P / np.linalg.norm(P, axis=1, keepdims=True)
    normal = np.where(np.isfinite(normal).all(axis=1, keepdims=True), normal, radial)
    return t, P, normal, steps


def _blocked_by_a(scene, P, L, samples):
    """(n,) bool: does the segment from P (n, 3) to the light L (3,) pass inside the displaced sphere A?"""
    F, _ = _surface_function(scene.field)
    const = (scene.radius_a, scene.beta, scene.k_u, scene.k_v)
    W = L[None, :] - P
    t0, t1 = _sphere_span(P, W, scene.radius_a + scene.beta * H_MAX)
    a, b = np.maximum(t0, 0.0), np.minimum(t1, 1.0)
    out = np.zeros(P.shape[0], bool)
    k = np.arange(1, samples + 1) / samples       # from P itself excluded: F(P) = 0 on sphere A
    for rows in np.array_split(np.flatnonzero(a < b), max(1, P.shape[0] * samples // CHUNK)):
        ts = a[rows, None] + (b[rows] - a[rows])[:, None] * k
        pts = P[rows, None, :] + ts[..., None] * W[rows, None, :]
        out[rows] = (F(pts[..., 0], pts[..., 1], pts[..., 2], *const) < -SHADOW_TOL * const[0]).any(axis=1)
    return out


@njit(error_model="numpy")
def _surfaces(prm, xs, ys, tA, PA, NA, chamber, P, N, albedo):
    """Nearest hit per pixel among the displaced A (t, point, normal given), B and the floor (ties
    as `renderer.kernel.nearest_hit`), with the kernel's `surface` for B and the floor."""
    s = prm[0]
    for j in range(ys.shape[0]):
        for i in range(xs.shape[0]):
            x, y = xs[i], ys[j]
            t, code = tA[j, i], kernel.SPHERE_A
            if not t < math.inf:
                t, code = math.inf, kernel.BACKGROUND
            if s.sphere_b:
                tb = kernel.sphere_hit(x, y, s.camera_z, s.center_b[0], s.center_b[1], s.center_b[2], s.radius_b)
                if tb < t:
                    t, code = tb, kernel.SPHERE_B
            if s.floor and 1.0 < t:
                t, code = 1.0, kernel.FLOOR
            chamber[j, i] = code
            if code == kernel.SPHERE_A:
                for c in range(3):
                    P[j, i, c], N[j, i, c], albedo[j, i, c] = PA[j, i, c], NA[j, i, c], s.albedo_a[c]
            elif code != kernel.BACKGROUND:
                p, n, al = kernel.surface(s, x, y, t, code, math.sin(math.pi * x) * math.sin(math.pi * y))
                for c in range(3):
                    P[j, i, c], N[j, i, c], albedo[j, i, c] = p[c], n[c], al[c]


@njit(error_model="numpy")
def _shade(prm, prm_no_b, lights, chamber, P, N, albedo, blocked, image):
    """`renderer.kernel.shade` per pixel, sphere A's blocking (``blocked``, (n_lights, H, W)) given:
    a light blocked by the displaced A is passed with colour 0; the kernel tests the rest (the
    normal faces the light, the floor plane, sphere B).  Called as for a point of sphere A, so
    that the kernel does not test its undisplaced sphere A; on sphere B with sphere B off."""
    s, s_no_b = prm[0], prm_no_b[0]
    masked, geo = lights.copy(), np.empty((lights.shape[0], kernel.LIGHT_COLUMNS))
    for j in range(chamber.shape[0]):
        for i in range(chamber.shape[1]):
            if chamber[j, i] == kernel.BACKGROUND:
                continue
            for k in range(lights.shape[0]):
                for c in range(3):
                    masked[k].color[c] = 0.0 if blocked[k, j, i] else lights[k].color[c]
            p, n = (P[j, i, 0], P[j, i, 1], P[j, i, 2]), (N[j, i, 0], N[j, i, 1], N[j, i, 2])
            a = (albedo[j, i, 0], albedo[j, i, 1], albedo[j, i, 2])
            rgb = kernel.shade(s_no_b if chamber[j, i] == kernel.SPHERE_B else s, masked, geo, p, n, n, a,
                               kernel.SPHERE_A, True)
            image[j, i, 0], image[j, i, 1], image[j, i, 2] = rgb


def _compile(prm, lights):
    """Compile `_surfaces` and `_shade` (on empty frames) before the frame is timed."""
    e1, e2, e3 = np.zeros(0), np.zeros((0, 0)), np.zeros((0, 0, 3))
    _surfaces(prm, e1, e1, e2, e3, e3, np.zeros((0, 0), np.uint8), e3, e3, e3)
    _shade(prm, prm, lights, np.zeros((0, 0), np.uint8), e3, e3, e3, np.zeros((lights.shape[0], 0, 0), bool), e3)


def _cast_shadow(lights, chamber, P, N, reach):
    """(H, W) bool: some light the geometric normal N faces does not reach P (``reach`` (n, H, W))."""
    facing = np.einsum("hwc,khwc->khw", N, lights.position[:, None, None, :] - P[None]) > 0.0
    return (facing & ~reach).any(axis=0) & (chamber != kernel.BACKGROUND)


def _check_bounded(scene):
    """InvalidValue unless |h| <= `H_MAX` at every point of a `BOUND_CHECK_POINTS`-square grid of the
    chart and between its points (`renderer.intervals.search_chart`): the bracketing shells lie at
    R +- beta `H_MAX`."""
    h_of = sp.lambdify(formulas.FIELD_SYMBOLS, scene.field.expr, modules="numpy")   # not numba's: no compilation

    def height(u, v):
        return np.broadcast_to(h_of(u, v, scene.k_u, scene.k_v), np.shape(u))
    t = np.linspace(0.0, 1.0, BOUND_CHECK_POINTS)
    uu, vv = np.meshgrid(t, t)
    h = np.abs(height(uu, vv))
    ij = np.unravel_index(np.argmax(h), h.shape)
    def holds(hs):
        return hs is not None and max(abs(hs[0].a), abs(hs[0].b)) <= H_MAX
    at = (float(uu[ij]), float(vv[ij])) if not h[ij] <= H_MAX else search_chart(
        [scene.field.expr], scene.k_u, scene.k_v, holds, broken=lambda u, v: not abs(height(u, v)) <= H_MAX)
    if at is not None:
        raise InvalidValue(f"Scene.height_field {scene.height_field!r} reaches |h| = {abs(float(height(*at)))!r} at "
                           f"(u, v) = ({at[0]:.6g}, {at[1]:.6g}) of the chart; a displaced sphere brackets its surface "
                           f"for |h| <= {H_MAX:g}")


def render_displaced(scene, width, height, *, samples=64):
    """Render the scene with sphere A displaced, r = R + beta h(u, v), and compare with the bumped render.

    Parameters
    ----------
    scene : renderer.Scene
        Its ``beta`` displaces sphere A along the radius; ``bump`` is the mode of the bumped
        frame compared with ("surface" is the normal of this very surface).
    width, height : int in [1, 8192]
        Image size in pixels (at most 4096 x 4096 in all), as `renderer.render`.
    samples : int in [1, 4096], keyword-only
        Points per primary ray and per shadow segment inside the bracketing shell.

    Returns
    -------
    Displaced

    Raises
    ------
    renderer.validate.InvalidType
        ``scene`` is not a Scene; a size or ``samples`` not an integer (a bool, a float).
    renderer.validate.InvalidValue
        A size out of range; ``samples`` outside [1, 4096]; ``beta * max|h|`` not below
        ``radius_a`` (the displaced radius must stay positive); the camera not outside the
        displaced sphere (``camera_z > radius_a + beta``); a height field whose |h| exceeds
        `H_MAX` somewhere on the chart.
    """
    scene, width, height, _, _ = check_args(scene, width, height, "exact", 1.0)
    samples = positive_int("samples", samples, high=MAX_SAMPLES)
    _check_bounded(scene)
    reach_a = scene.beta * H_MAX
    if not reach_a < scene.radius_a:
        raise InvalidValue(f"Scene.beta = {scene.beta!r} times max|h| = {H_MAX:g} must be < radius_a = "
                           f"{scene.radius_a!r} for a displaced sphere (its radius R + beta h must stay positive)")
    if not scene.camera_z > scene.radius_a + reach_a:
        raise InvalidValue(f"Scene.camera_z = {scene.camera_z!r} must be > radius_a + beta max|h| = "
                           f"{scene.radius_a + reach_a!r}: the camera must be outside the displaced sphere")
    bumped = render(scene, width, height, gradient="exact")
    start = time.perf_counter()
    bumped = render(scene, width, height, gradient="exact")          # compiled: the second call is timed
    render_seconds = time.perf_counter() - start

    prm, lights = kernel.params(scene, skip=False)
    prm_no_b = kernel.params(scene.replace(sphere_b=False), skip=False)[0]
    _compile(prm, lights)
    _surface_function(scene.field)                # sympy's lambdify, once per field, before the clock starts
    start = time.perf_counter()
    xs, ys = image_plane(scene.radius_a, scene.camera_z, width, height)
    X, Y = np.meshgrid(xs, ys)
    D = np.stack([X.ravel(), Y.ravel(), np.full(X.size, -scene.camera_z)], -1)
    O = np.broadcast_to(np.array([0.0, 0.0, scene.camera_z]), D.shape)
    t, PA, NA, steps = _first_root(scene, O, D, samples)
    shape = (height, width)
    chamber = np.zeros(shape, np.uint8)
    P, N, albedo = (np.zeros(shape + (3,)) for _ in range(3))
    _surfaces(prm, xs, ys, np.where(np.isfinite(t), t, np.inf).reshape(shape), PA.reshape(shape + (3,)),
              NA.reshape(shape + (3,)), chamber, P, N, albedo)
    # Sphere A's blocking of every light, at every lit-facing point that is not the background.
    blocked = np.zeros((lights.shape[0],) + shape, bool)
    for k, L in enumerate(lights.position):
        facing = (np.einsum("hwc,hwc->hw", N, L - P) > 0.0) & (chamber != kernel.BACKGROUND)
        blocked[k][facing] = _blocked_by_a(scene, P[facing], L, samples)
    image = np.zeros(shape + (3,))
    _shade(prm, prm_no_b, lights, chamber, P, N, albedo,
           blocked, image)
    seconds = time.perf_counter() - start

    # Shadows: the kernel's reach (B, floor plane), as for a point of A (no undisplaced-A test),
    # on sphere B with B off; then the displaced A's blocking.
    as_a = np.where(chamber == kernel.BACKGROUND, kernel.BACKGROUND, kernel.SPHERE_A).astype(np.uint8)
    on_b = chamber == kernel.SPHERE_B
    reach = np.zeros_like(blocked)
    for sc, where in ((scene, ~on_b), (scene.replace(sphere_b=False), on_b)):
        reach |= pointwise.reach(sc, GBuffer(as_a, None, P, N, N, None, None, xs, ys)) & where
    reach &= ~blocked
    shadow = _cast_shadow(lights, chamber, P, N, reach)
    geo = gbuffer(scene, width, height, gradient="exact")
    bumped_shadow = _cast_shadow(lights, geo.chamber, geo.P, geo.N, pointwise.reach(scene, geo))
    lit_bumped = pointwise.reach(scene, geo, gate=True)
    covered, covered_bumped = chamber == kernel.SPHERE_A, bumped.chamber == kernel.SPHERE_A
    self_shadowed = int(((blocked & lit_bumped).any(axis=0) & covered & covered_bumped).sum())
    on_a = steps.reshape(shape)[covered]
    return Displaced(image, chamber, covered, shadow, P, N, bumped, bumped_shadow,
                     int((covered != covered_bumped).sum()), int((shadow != bumped_shadow).sum()), self_shadowed,
                     blocked, samples, int(on_a.max(initial=0)), float(on_a.mean()) if on_a.size else 0.0,
                     seconds, render_seconds)
