"""The two pipelines: one render function, differing only in the gradient.

Data flow for a tile of pixels:

camera -> intersections -> chamber code -> hit points and geometric normals
-> sphere A only: chart (u, v), tangent frame, gradient, perturbed normal
-> shading (ambient + per light: geometric shadow predicate, Lambert, Blinn or
Phong).  Everything before the gradient depends on geometry alone.
"""

from __future__ import annotations

import functools
import numbers
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from . import fields
from . import workers as _workers
from .geometry import (POLE_SIN_PHI, chart, image_plane, projected_bounds, segment_hits_sphere,
                       sphere_hit, tangent_frame)
from .heap import keep_heap
from .scene import Scene

__all__ = [
    "Frame", "render", "GBuffer", "gbuffer", "central_gradient", "GRADIENTS", "MAX_SIDE", "MAX_ZOOM", "CHAMBER_NAMES",
    "BACKGROUND", "SPHERE_A", "SPHERE_B", "FLOOR",
]

#: Accepted values of ``render(..., gradient=...)``.
GRADIENTS = ("exact", "central")
#: Largest accepted image side, in pixels.
MAX_SIDE = 8192
#: Largest accepted magnification of the image window (`render`'s ``zoom``).
MAX_ZOOM = 1e6
#: Pixels per tile: bounds the working memory of a render at any resolution
#: (about 0.4 KiB of temporaries per pixel of a tile, per thread).
TILE_PIXELS = 1 << 16
#: Default number of workers rendering tiles side by side: the machine's cores,
#: at most 4.  The calling thread is one; the others are worker processes
#: (`renderer.workers`) once they have started, threads until then.  numpy
#: releases the GIL inside its loops, but each of the few thousand array
#: operations of a tile takes it back, so threads contend for it; processes
#: do not (benchmarks/results/render.md, "Steady state").
#: Tiles write disjoint slices: the image is the same bits for any number.
WORKERS = max(1, min(4, os.cpu_count() or 1))
#: Frames smaller than this many pixels are rendered on one thread: below it
#: the threads' contention for the GIL costs more than they gain (measured
#: here when this was set: two threads took 6.0 ms for a 128^2 frame against
#: 4.3 ms on one, and were about even at 224^2).
MIN_SPLIT_PIXELS = 1 << 16
_POOLS = {}


def _tile_rows(width, height, workers):
    """Rows per tile: at most `TILE_PIXELS` pixels, and at least ``workers`` tiles
    when the frame has `MIN_SPLIT_PIXELS` pixels or more."""
    rows = max(1, TILE_PIXELS // width)
    if workers > 1 and width * height >= MIN_SPLIT_PIXELS:
        rows = min(rows, -(-height // workers))
    return rows


def _run_tiles(jobs, workers):
    """Run the tile jobs (callables), on ``workers`` threads when there are several.

    An exception raised in a job is raised again here, in the caller; then,
    as on KeyboardInterrupt while waiting, the jobs not yet started are
    cancelled.
    """
    if workers <= 1 or len(jobs) <= 1:
        for job in jobs:
            job()
        return
    pool = _POOLS.get(workers)
    if pool is None:
        pool = _POOLS.setdefault(workers, ThreadPoolExecutor(max_workers=workers,
                                                             thread_name_prefix="symrender-tile"))
    futures = [pool.submit(job) for job in jobs]
    try:
        for future in futures:
            future.result()
    except BaseException:                   # an error or Ctrl-C: drop the tiles not yet started
        for future in futures:
            future.cancel()
        raise


BACKGROUND, SPHERE_A, SPHERE_B, FLOOR = 0, 1, 2, 3
#: Chamber codes of `Frame.chamber`.
CHAMBER_NAMES = {BACKGROUND: "background", SPHERE_A: "sphere A", SPHERE_B: "sphere B",
                 FLOOR: "floor"}

#: Relative cost of a pixel by the object it shows, for balancing the tiles of
#: a frame between workers (`_tile_bounds`), with sphere A's cost per pipeline.
#: Measured here on one thread at 256^2 (default scene), in ns per pixel: the
#: camera ray and its intersections about 30 for every pixel; then the floor
#: about 110, sphere B 150, sphere A 290 (exact) or 485 (central); the
#: background next to nothing.  In units of a floor pixel:
RAY_COST = 0.3
PIXEL_COST = {BACKGROUND: 0.05, FLOOR: 1.0, SPHERE_B: 1.4}
SPHERE_A_COST = {"exact": 2.7, "central": 4.4}
#: Rows and columns of the coarse grid of rays that estimates the cost.
COST_SAMPLES = 64


#: Cache of `_row_costs`, by the scene's geometry and the frame (at most
#: `ROW_COST_CACHE` entries; cleared when full).
_ROW_COSTS = {}
ROW_COST_CACHE = 64


def _row_costs(scene, width, height, zoom, a_cost):
    """Cumulative estimated cost of a frame's rows: float64 (height,), read-only.

    Estimated from the objects that a coarse grid of at most `COST_SAMPLES`^2
    rays meets (`PIXEL_COST`; sphere A weighs ``a_cost``) plus `RAY_COST` per
    ray.  Cached by what the estimate reads: the spheres, the floor and the
    camera of ``scene`` (not its lights, field or eps), ``width``, ``height``
    (int), ``zoom`` (float) and ``a_cost``.  A scene rendered again with the
    same geometry, size and pipeline costs nothing here.
    """
    key = (scene.radius_a, scene.camera_z, scene.center_b, scene.radius_b, scene.sphere_b,
           scene.floor, width, height, zoom, a_cost)
    cum = _ROW_COSTS.get(key)
    if cum is not None:
        return cum
    x, y = image_plane(scene.radius_a, scene.camera_z, width, height, zoom)
    sr, sc = max(1, height // COST_SAMPLES), max(1, width // COST_SAMPLES)
    ys, xs = y[sr // 2::sr], x[sc // 2::sc]
    _, code = _nearest_hit(scene, np.tile(xs, ys.shape[0]), np.repeat(ys, xs.shape[0]), grid=(xs, ys))
    table = np.zeros(256)
    for kind, cost in PIXEL_COST.items():
        table[kind] = cost
    table[SPHERE_A] = a_cost
    sample = table[code].reshape(ys.shape[0], xs.shape[0]).sum(axis=1) + RAY_COST * xs.shape[0]
    cum = np.cumsum(sample[np.minimum(np.arange(height) // sr, ys.shape[0] - 1)])
    cum.flags.writeable = False
    cum = cum.view()                        # a view of a read-only array cannot be made writeable
    if len(_ROW_COSTS) >= ROW_COST_CACHE:
        _ROW_COSTS.clear()
    _ROW_COSTS[key] = cum
    return cum


def _tile_bounds(scene, width, height, zoom, workers, a_cost):
    """Row ranges ``[(j0, j1), ...]`` of a frame's tiles, in order, covering it.

    ``width``, ``height``: int pixels; ``zoom``: float (as validated by
    `render`); ``workers``: int >= 1; ``a_cost``: sphere A's weight
    (`SPHERE_A_COST`).  Equal bands of `_tile_rows` rows, except where the
    frame splits into just one tile per worker (``workers`` >= 2, at least
    `MIN_SPLIT_PIXELS` pixels, at most ``workers`` * `TILE_PIXELS`): then the
    tiles are cut at estimated cost (`_row_costs`), so that the workers finish
    together.  In the default scene sphere B is in the top half, whose rows
    cost about 1.3 times as much as the bottom half's: an even split leaves
    one worker waiting.  With more tiles than workers the pool hands them out
    as workers free up.  Each pixel is computed the same way in any tile, so
    the bounds change no bit.
    """
    rows = _tile_rows(width, height, workers)
    bands = [(j0, min(height, j0 + rows)) for j0 in range(0, height, rows)]
    if workers <= 1 or len(bands) != min(workers, height):
        return bands
    cum = _row_costs(scene, width, height, zoom, a_cost)
    n = len(bands)
    cuts = [0]
    for k in range(1, n):
        # The first row boundary with at least k/n of the cost above it, and
        # at least one row per tile.
        j = int(np.searchsorted(cum, cum[-1] * k / n)) + 1
        cuts.append(min(max(j, cuts[-1] + 1), height - (n - k)))
    cuts.append(height)
    if max(j1 - j0 for j0, j1 in zip(cuts, cuts[1:])) * width > TILE_PIXELS:
        return bands                        # the memory bound comes first
    return list(zip(cuts, cuts[1:]))


def quiet_underflow(fn):
    """Run ``fn`` with numpy's underflow flag ignored (and every other
    floating-point error left as the caller set it).

    A product or power that underflows (a vanishing highlight pow(0.01, 1e4),
    a tiny beta times a gradient) rounds to a subnormal or to 0, which is the
    correctly rounded result and invisible in any image; invalid operations,
    division by zero and overflow stay errors or warnings, as the caller
    chose.  Worker threads start with numpy's defaults, which already ignore
    underflow.
    """
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with np.errstate(under="ignore"):
            return fn(*args, **kwargs)
    return wrapper


#: Floor under |h| in Blinn's half-vector quotient (|h| = 0 only off the lit side).
_TINY = 1e-300

#: Checker albedo levels of the floor's two colours (seed Cell 1).
FLOOR_LIGHT, FLOOR_DARK = 0.85, 0.15


@dataclass(frozen=True)
class Frame:
    """One rendered frame.

    Attributes
    ----------
    image : (H, W, 3) float64
        Linear RGB, clipped to [0, 1].
    chamber : (H, W) uint8
        0 background, 1 sphere A, 2 sphere B, 3 floor: the object of the
        nearest positive hit.
    kink : (H, W) bool, or None if not requested
        The seed's crease band on sphere A (ridges only; all False otherwise).
    grad : (H, W, 2) float64, or None if not requested
        (h_u, h_v) used on sphere A by this frame's pipeline; 0 elsewhere.
    scene : Scene
    gradient : {"exact", "central"}
    """

    image: np.ndarray
    chamber: np.ndarray
    kink: np.ndarray
    grad: np.ndarray
    scene: Scene
    gradient: str


def _check_size(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer number of pixels, got {value!r}")
    if not 1 <= value <= MAX_SIDE:
        raise ValueError(f"{name} must be between 1 and {MAX_SIDE} pixels, got {value!r}")
    return int(value)


def central_gradient(name, uu, vv, ku, kv, eps, base=None):
    """Central-difference chart gradient, the numeric pipeline's one difference.

    h_u = (h(u + eps, v) - h(u - eps, v)) / (2 eps) with u wrapped modulo 1
    (the chart is periodic in u).  v is clamped to [0, 1]; where a clamp
    happens the quotient is one-sided, divided by the clamped distance
    v_+ - v_-; elsewhere by 2 eps (seed Cell 1, ``grad_numeric``).  Four
    values of h per point, from `renderer.fields.central_stencil` (the same
    bits as four calls of `fields.height`, with the factors that do not move
    shared).

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    uu, vv : (n,) float64 chart coordinates in [0, 1]
    ku, kv : float
    eps : float > 0, the step in chart units
    base : list of arrays, optional
        ``central_stencil(name).base(uu, vv, ku, kv)``, computed once by a
        caller that differentiates the same points with several steps.

    Returns
    -------
    (h_u, h_v) : two (n,) float64 arrays.
    """
    up, um = uu + eps, uu - eps
    if eps < 1.0:
        # u in [0, 1]: u + eps in [0, 2) and u - eps in (-1, 1), where the
        # wrap is one exact subtraction or addition, the bits of np.mod
        # (x - 1 is exact on [1, 2]; np.mod adds 1 to a negative fmod, which is x).
        up = np.where(up >= 1.0, up - 1.0, up)
        um = np.where(um < 0.0, um + 1.0, um)
    else:
        up, um = np.mod(up, 1.0), np.mod(um, 1.0)
    vp = np.minimum(1.0, vv + eps)
    vm = np.maximum(0.0, vv - eps)
    h_up, h_um, h_vp, h_vm = fields.central_stencil(name).values(up, um, vp, vm, uu, vv, ku, kv, base)
    hu = (h_up - h_um) / (2.0 * eps)
    clamped = (vv + eps > 1.0) | (vv - eps < 0.0)
    den = np.where(clamped, vp - vm, 2.0 * eps)
    hv = (h_vp - h_vm) / den
    return hu, hv


def _dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@dataclass
class _Light:
    """One light as seen from the points of a surface (geometry only).

    ``w`` is the unit vector to the light, ``attached`` says where the geometric
    normal faces it and no floor plane separates it, and ``lit`` (once shadow
    rays have been traced) where it also reaches the point.
    """

    color: tuple
    position: tuple
    w: tuple
    w_raw: tuple
    w2: np.ndarray
    attached: np.ndarray
    lit: np.ndarray = None


def _lights(scene, P, N, floor_blocks, skip, flat=False):
    """The lights that can contribute (zero colour is skipped), seen from P.

    ``flat`` says N is exactly (0, 0, 1) (the floor): then N . w is w_z, the
    same number the dot product gives (0 w_x + 0 w_y + w_z), in one operation.
    """
    Px, Py, Pz = P
    out = []
    for light in scene.lights:
        if skip and not any(light.color):
            continue
        Lx, Ly, Lz = light.position
        wx, wy, wz = Lx - Px, Ly - Py, Lz - Pz
        attached = (wz > 0.0) if flat else (_dot(*N, wx, wy, wz) > 0.0)
        if floor_blocks:
            # The floor plane z = 0 separates P from a light on the other side.
            if Lz < 0.0:
                attached &= ~(Pz > 0.0)
            elif Lz > 0.0:
                attached &= ~(Pz < 0.0)
        w2 = _dot(wx, wy, wz, wx, wy, wz)
        inv = 1.0 / np.sqrt(w2)
        out.append(_Light(light.color, light.position, (wx * inv, wy * inv, wz * inv), (wx, wy, wz),
                          w2, attached))
    return out


def _trace_shadows(light, spheres, test, floor_points=None):
    """Set ``light.lit``: attached and no blocker sphere on the segment to the light.

    Shadow rays are traced only where ``test`` is True, and a ray is not traced
    again once a blocker has stopped it; elsewhere the pixel keeps
    ``attached``, which the caller guarantees cannot change its colour.
    ``floor_points = (x, y)``: the points are (x, y, 0) on the floor, and
    against each sphere only those inside the box of its shadow on z = 0
    (`projected_bounds` from the light) are traced; the others' segments miss
    it.  ``test=None`` is the reference path: every pixel against every blocker.
    """
    lit = light.attached.copy()
    wx, wy, wz = light.w_raw
    if test is None:
        # Reference path: every pixel against every blocker.
        for center, radius in spheres:
            lit &= ~segment_hits_sphere(wx, wy, wz, light.w2, light.position, center, radius)
        light.lit = lit
        return
    for center, radius in spheres:
        trace = test & lit
        if floor_points is not None:
            box = projected_bounds(light.position, center, radius)
            if box is not None:
                px, py = floor_points
                trace &= (px >= box[0]) & (px <= box[1]) & (py >= box[2]) & (py <= box[3])
        idx = np.flatnonzero(trace)
        if idx.size == 0:
            continue
        blocked = segment_hits_sphere(wx[idx], wy[idx], wz[idx], light.w2[idx], light.position,
                                      center, radius)
        lit[idx[blocked]] = False
    light.lit = lit


def _view(scene, P, lights):
    """The shading terms that depend on geometry alone, not on the normal.

    Returns ``(halves, v)``: v is the unit vector from P to the eye and
    ``halves[k]``, for Blinn, the half vector h = w_k + v of light k with
    max(|h|, tiny); None for Phong.  Computed once per surface: an eps sweep
    shades sphere A with a new normal per step on the same view
    (`renderer.sweep`).
    """
    Px, Py, Pz = P
    vx, vy, vz = -Px, -Py, scene.camera_z - Pz
    inv = 1.0 / np.sqrt(_dot(vx, vy, vz, vx, vy, vz))
    v = (vx * inv, vy * inv, vz * inv)
    halves = []
    for light in lights:
        if scene.model == "blinn":
            wx, wy, wz = light.w
            hx, hy, hz = wx + v[0], wy + v[1], wz + v[2]
            # |h| = 0 only where w = -v, which no front pixel has; the floor
            # keeps that quotient finite (it is masked below).
            hn = np.maximum(np.sqrt(_dot(hx, hy, hz, hx, hy, hz)), _TINY)
            halves.append(((hx, hy, hz), hn))
        else:
            halves.append(None)
    return halves, v


def _power(base, exponent):
    """``base ** exponent`` for a float64 array ``base`` (any values) and a
    float ``exponent`` > 0 (`Scene.shininess`, validated there), with the
    power computed only where ``base`` is not +0.

    The specular base is exactly +0 wherever the light is masked off or the
    cosine is negative (half of sphere A's pixels in the default scene), and
    numpy's float64 power loop (Intel SVML on AVX-512 machines, libm
    elsewhere) is about four times as slow at 0 as at other bases, measured
    here: skipping those makes the specular power about twice as fast.  The
    skipped entries hold +0, which is pow(+0, p) for every p > 0; -0, NaN,
    inf and the rest go through the same loop as ``**`` with a scalar
    exponent.  The same bits as ``base ** exponent`` (tests/test_skips.py
    checks it, with the bases that could differ).  Returns a new float64
    array of the shape of ``base``.
    """
    mask = base != 0.0
    mask |= np.signbit(base)
    out = np.zeros_like(base)
    np.power(base, exponent, out=out, where=mask)
    return out


def _shade(scene, P, Ns, albedo, lights, flat=False, mus=None, view=None):
    """Ambient plus, per light, Lambert and Blinn/Phong (seed Cell 1, ``shade1``).

    ``lights`` come from `_lights` with ``lit`` set: a light reaches P only if
    the geometric normal faces it (attached shadow) and no blocker sphere, nor
    the floor plane, cuts the segment to it (cast shadow), both predicates of
    geometry alone.  The shading normal Ns (perturbed on sphere A) enters only
    the Lambert and specular factors, and both are gated by Ns . w > 0.
    Returns a triple of (n,) arrays (clipping is the caller's).  ``flat``:
    Ns is exactly (0, 0, 1), and its dot products are read off the z
    components (the same numbers, as in `_lights`).  ``mus``: Ns . w per
    light, when the caller has computed them already; ``view``: `_view` of
    (P, lights), likewise.
    """
    Sx, Sy, Sz = Ns
    halves, (vx, vy, vz) = _view(scene, P, lights) if view is None else view
    out = [None, None, None]
    for k, light in enumerate(lights):
        wx, wy, wz = light.w
        mu = wz if flat else mus[k] if mus is not None else _dot(Sx, Sy, Sz, wx, wy, wz)
        front = light.lit & (mu > 0.0)
        if not front.any():
            continue
        if scene.model == "blinn":
            (hx, hy, hz), hn = halves[k]
            spec_cos = (hz if flat else _dot(Sx, Sy, Sz, hx, hy, hz)) / hn
        else:
            two_mu = 2.0 * mu
            spec_cos = _dot(two_mu * Sx - wx, two_mu * Sy - wy, two_mu * Sz - wz, vx, vy, vz)
        # The cosine clamped to [0, 1] before the power: rounding can put it a
        # few ulps above 1, and at a large exponent 1 + 2^-52 would grow.
        # Masks by multiplication (x * False = 0): the same sums as np.where, faster.
        spec = _power(np.clip(spec_cos, 0.0, 1.0) * front, scene.shininess)
        diffuse = (mu * front) * scene.kd
        spec *= scene.ks
        term = None
        for c in range(3):
            # The floor passes one array as its red and green albedo (rg, rg, b):
            # the same object gives the same term, computed once.
            if c == 0 or albedo[c] is not albedo[c - 1]:
                term = diffuse * albedo[c] + spec
            # A colour of exactly 1 multiplies by 1: the product is the term itself.
            add = term if light.color[c] == 1.0 else light.color[c] * term
            out[c] = add + out[c] if out[c] is not None else add + scene.ka * scene.ambient[c]
    n = P[0].shape[0]
    return [np.full(n, scene.ka * a) if o is None else o for o, a in zip(out, scene.ambient)]


def _grid_block(grid, bounds):
    """The block of a tile's pixels whose image-plane point lies in ``bounds``.

    ``grid = (x, y)``: the tile's rays are ``X = tile(x, len(y))``, ``Y =
    repeat(y, len(x))`` (row-major; x increases along a row, y decreases down
    the rows).  Returns ``(rows, cols)`` slices of the (len(y), len(x)) grid,
    or None when no pixel is in the box.
    """
    x, y = grid
    x_min, x_max, y_min, y_max = bounds
    c0, c1 = np.searchsorted(x, x_min, side="left"), np.searchsorted(x, x_max, side="right")
    # y decreases down the rows: search its negation.
    r0, r1 = np.searchsorted(-y, -y_max, side="left"), np.searchsorted(-y, -y_min, side="right")
    if c0 >= c1 or r0 >= r1:
        return None
    return slice(r0, r1), slice(c0, c1)


def _nearest_hit(scene, X, Y, skip=True, grid=None):
    """Ray parameter and chamber code of the nearest positive hit of each ray.

    With ``skip`` an object that is off is not intersected, and when the
    tile's ``grid`` is given (see `_grid_block`) a sphere is intersected only
    by the rays inside the box of its projection (`projected_bounds`): the rays
    outside miss it.  Without ``skip`` every ray meets every object and the
    hits of objects that are off are discarded (the reference path for the
    tests).
    """
    e = scene.camera_z
    t = np.full(X.shape, np.inf)
    code = np.zeros(X.shape, dtype=np.uint8)
    eye = (0.0, 0.0, e)
    # Ties go to A, then B, then the floor (the seed's order of tests).
    spheres = [(SPHERE_A, (0.0, 0.0, 0.0), scene.radius_a, True)]
    if scene.sphere_b or not skip:
        spheres.append((SPHERE_B, scene.center_b, scene.radius_b, scene.sphere_b))
    for kind, center, radius, on in spheres:
        bounds = projected_bounds(eye, center, radius) if skip and grid is not None else None
        if bounds is None:
            ts = sphere_hit(X, Y, e, center, radius)
            tv, cv = t, code
        else:
            block = _grid_block(grid, bounds)
            if block is None:
                continue                              # no ray of this tile can meet it
            rows, cols = block
            x, y = grid
            ts = sphere_hit(x[cols], y[rows, None], e, center, radius)
            tv = t.reshape(y.shape[0], x.shape[0])[rows, cols]
            cv = code.reshape(y.shape[0], x.shape[0])[rows, cols]
        if not on:
            continue
        closer = ts < tv
        tv[closer], cv[closer] = ts[closer], kind
    if scene.floor or not skip:
        # The floor z = 0 is the image plane: every ray meets it at t = 1.
        closer = (1.0 < t) & scene.floor
        t[closer], code[closer] = 1.0, FLOOR
    return t, code


@dataclass
class _Surface:
    """Geometry of the pixels of one object (triples are x, y, z arrays).

    On sphere A also the chart (u, v), sin(phi) and, once computed, the tangent
    frame, the gradient and the kink flag.
    """

    kind: int
    idx: np.ndarray
    P: tuple
    N: tuple
    albedo: tuple
    spheres: list
    floor_blocks: bool
    uv: tuple = None
    sin_phi: np.ndarray = None
    frame: tuple = None
    grad: tuple = None
    kink: np.ndarray = None


def _surfaces(scene, X, Y, t, code, skip=True, grid=None):
    """A `_Surface` per object hit by at least one ray (geometry only, no gradient).

    With ``skip`` and the tile's ``grid`` (see `_grid_block`) the floor's
    checker factors sin(pi x) and sin(pi y) are computed once per column and
    per row: a floor point is exactly its pixel centre (x, y, 0), as t = 1.
    """
    e = scene.camera_z
    sphere_a = ((0.0, 0.0, 0.0), scene.radius_a)
    sphere_b = (scene.center_b, scene.radius_b)
    out = []
    for kind in (SPHERE_A, SPHERE_B, FLOOR):
        idx = np.flatnonzero(code == kind)
        if idx.size == 0:
            continue
        ti = t[idx]
        P = (ti * X[idx], ti * Y[idx], e * (1.0 - ti))
        floor_blocks = scene.floor and kind != FLOOR
        if kind == SPHERE_A:
            N = tuple(c / scene.radius_a for c in P)
            uu, vv, sin_phi = chart(*N)
            out.append(_Surface(kind, idx, P, N, scene.albedo_a, [sphere_b] if scene.sphere_b else [],
                                floor_blocks, uv=(uu, vv), sin_phi=sin_phi))
        elif kind == SPHERE_B:
            N = tuple((p - c) / scene.radius_b for p, c in zip(P, scene.center_b))
            out.append(_Surface(kind, idx, P, N, scene.albedo_b, [sphere_a], floor_blocks))
        else:
            zero = np.zeros_like(ti)
            N = (zero, zero, zero + 1.0)
            # Checker: light squares where sin(pi x) sin(pi y) >= 0 (seed Cell 1).
            if skip and grid is not None:
                gx, gy = grid
                light_square = (np.sin(np.pi * gx) * np.sin(np.pi * gy)[:, None] >= 0.0).reshape(-1)[idx]
            else:
                light_square = np.sin(np.pi * P[0]) * np.sin(np.pi * P[1]) >= 0.0
            base = np.where(light_square, FLOOR_LIGHT, FLOOR_DARK)
            rg = base * (1.0 - scene.floor_tint)
            out.append(_Surface(kind, idx, P, N, (rg, rg, base),
                                [sphere_a] + ([sphere_b] if scene.sphere_b else []), floor_blocks))
    if not skip:
        # Reference path: the chart everywhere, kept on sphere A only.
        for surf in out:
            if surf.kind != SPHERE_A:
                chart(*tuple(c / scene.radius_a for c in surf.P))
    return out


def _gradient(scene, surf, gradient, eps, base=None):
    """(h_u, h_v) on sphere A by the pipeline ``gradient`` with step ``eps``."""
    uu, vv = surf.uv
    if gradient == "exact":
        return fields.exact_gradient(scene.height_field, uu, vv, scene.k_u, scene.k_v)
    return central_gradient(scene.height_field, uu, vv, scene.k_u, scene.k_v, eps, base)


def _shading_normal(scene, surf, grad):
    """N' on sphere A from the gradient (seed §3; `Scene.bump`)."""
    if scene.beta == 0.0:
        return surf.N                       # beta = 0 is the un-bumped scene, exactly
    hu, hv = grad
    N = surf.N
    if surf.frame is None:
        surf.frame = tangent_frame(*N, surf.sin_phi)
    e_theta, e_phi = surf.frame
    if scene.bump == "chart":
        bu, bv = scene.beta * hu, scene.beta * hv
    else:
        # Normal of P = (R + beta h) N: h_theta = h_u / 2 pi, h_phi = h_v / pi.
        uu, vv = surf.uv
        h = fields.height(scene.height_field, uu, vv, scene.k_u, scene.k_v)
        w = -scene.beta / (scene.radius_a + scene.beta * h)
        s_phi = np.maximum(surf.sin_phi, POLE_SIN_PHI)
        bu, bv = w * hu / (2.0 * np.pi * s_phi), w * hv / np.pi
    M = tuple(n_ + bu * a + bv * b for n_, a, b in zip(N, e_theta, e_phi))
    inv = 1.0 / np.sqrt(_dot(*M, *M))
    return tuple(m * inv for m in M)


def _prepare_a(scene, surf, gradient, want_grad, want_kink, skip, base=None):
    """Gradient, kink flag and shading normal of sphere A's pixels.

    With ``skip`` the gradient is computed only if beta != 0 or the caller wants
    it, and the kink flag only if the caller wants it.  ``base``: the central
    stencil's eps-free values at the chart points (`fields.CentralStencil.base`),
    if the caller has them; the central pipeline computes them here.  With
    ``skip`` the kink flag is then read off the two sines among them, the
    deterministic sines `fields.kink_band` would compute again.
    """
    need_grad = want_grad or scene.beta != 0.0 or not skip
    if base is None and gradient == "central" and need_grad:
        base = fields.central_stencil(scene.height_field).base(*surf.uv, scene.k_u, scene.k_v)
    if need_grad:
        surf.grad = _gradient(scene, surf, gradient, scene.eps, base)
    if want_kink or not skip:
        factors = (fields.central_stencil(scene.height_field).ridge_factors(base)
                   if skip and base is not None else None)
        surf.kink = fields.kink_band(scene.height_field, *surf.uv, scene.k_u, scene.k_v, factors)
    if not skip and surf.frame is None:
        surf.frame = tangent_frame(*surf.N, surf.sin_phi)
    return _shading_normal(scene, surf, surf.grad)


def _shade_surface(scene, surf, Ns, skip):
    """Colour of one surface's pixels (not clipped): lights, shadow rays, shading."""
    flat = skip and surf.kind == FLOOR
    lights = _lights(scene, surf.P, surf.N, surf.floor_blocks, skip, flat)
    mus = None
    if skip and surf.kind == SPHERE_A:
        # Ns . w, for the shadow-ray test here and for the shading.
        mus = [_dot(*Ns, *light.w) for light in lights]
    for k, light in enumerate(lights):
        if skip:
            # Shadow rays only where the light could add something: attached and
            # in front of the shading normal (Ns . w > 0 gates both terms).  Off
            # sphere A, Ns = N and attached already implies it.
            test = light.attached & (mus[k] > 0.0) if mus is not None else light.attached
            _trace_shadows(light, surf.spheres, test, surf.P[:2] if surf.kind == FLOOR else None)
        else:
            _trace_shadows(light, surf.spheres, None)
        if not skip and not scene.sphere_b and surf.kind != SPHERE_B:
            # Reference path: trace the switched-off sphere B too, and ignore it.
            segment_hits_sphere(*light.w_raw, light.w2, light.position, scene.center_b,
                                scene.radius_b)
    return _shade(scene, surf.P, Ns, surf.albedo, lights, flat, mus)


def _put_rows(dest, idx, rows):
    """``dest[idx] = rows`` for a C-contiguous (n, k) ``dest`` and (m, k) ``rows``.

    Done as one `np.put` of k-float records on a void view: the same bytes
    as the 2-D fancy assignment, three to four times as fast.
    """
    record = np.dtype((np.void, dest.dtype.itemsize * dest.shape[1]))
    rows = np.ascontiguousarray(rows, dtype=dest.dtype)
    np.put(dest.view(record).reshape(-1), idx, rows.view(record).reshape(-1))


def _take_rows(src, idx):
    """``src[idx]`` for a C-contiguous (n, k) ``src``: one `np.take` of k-float
    records on a void view (the same bytes as 2-D fancy indexing, faster)."""
    record = np.dtype((np.void, src.dtype.itemsize * src.shape[1]))
    rows = np.take(src.view(record).reshape(-1), idx)
    return rows.view(src.dtype).reshape(idx.shape[0], src.shape[1])


def _store_rgb(image, idx, col):
    """Clip the colour triple ``col`` to [0, 1] and write it to rows ``idx`` of
    the (n, 3) ``image`` view (one row scatter, not three strided ones)."""
    rgb = np.empty((idx.shape[0], 3))
    for c in range(3):
        np.clip(col[c], 0.0, 1.0, out=rgb[:, c])
    _put_rows(image, idx, rgb)


def _render_tile(scene, gradient, X, Y, image, chamber, kink, grad, skip, grid=None):
    """Render the rays (X, Y) into the flat output views (one entry per ray).

    ``grid``: the tile's pixel-centre columns and rows (see `_grid_block`).
    """
    t, code = _nearest_hit(scene, X, Y, skip, grid)
    chamber[:] = code
    for surf in _surfaces(scene, X, Y, t, code, skip, grid):
        if surf.kind == SPHERE_A:
            Ns = _prepare_a(scene, surf, gradient, grad is not None, kink is not None, skip)
            if grad is not None:
                _put_rows(grad, surf.idx, np.stack(surf.grad, axis=-1))
            if kink is not None:
                kink[surf.idx] = surf.kink
        else:
            Ns = surf.N
        _store_rgb(image, surf.idx, _shade_surface(scene, surf, Ns, skip))


@dataclass(frozen=True)
class GBuffer:
    """Per-pixel geometry of a frame, for checks and figures (not shaded).

    Attributes
    ----------
    chamber : (H, W) uint8        as `Frame.chamber`
    t : (H, W) float64            ray parameter of the nearest hit (inf: none)
    P : (H, W, 3) float64         hit point (0 where chamber is 0)
    N : (H, W, 3) float64         geometric unit normal (0 where chamber is 0)
    Ns : (H, W, 3) float64        shading normal (perturbed on sphere A)
    uv : (H, W, 2) float64        sphere-A chart (u, v); 0 elsewhere
    grad : (H, W, 2) float64      (h_u, h_v) on sphere A; 0 elsewhere
    x, y : (W,), (H,) float64     image-plane coordinates of the pixel centres
    """

    chamber: np.ndarray
    t: np.ndarray
    P: np.ndarray
    N: np.ndarray
    Ns: np.ndarray
    uv: np.ndarray
    grad: np.ndarray
    x: np.ndarray
    y: np.ndarray


@quiet_underflow
def gbuffer(scene, width, height, *, gradient="exact", zoom=1.0):
    """Per-pixel hit points, normals and chart of a frame (see `GBuffer`).

    Same arguments, validation and errors as `render`; computed by the same
    code path as `render` up to (not including) shading.  Unlike `render` it
    is not tiled: its arrays (about 150 bytes per pixel) are built whole, so
    it is meant for checks and figures, not for very large frames.
    """
    scene, width, height, gradient, zoom = _check_args(scene, width, height, gradient, zoom)
    keep_heap()
    x, y = image_plane(scene.radius_a, scene.camera_z, width, height, zoom)
    X = np.tile(x, height)
    Y = np.repeat(y, width)
    t, code = _nearest_hit(scene, X, Y, grid=(x, y))
    n = width * height
    P, N, Ns = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    uv, grad = np.zeros((n, 2)), np.zeros((n, 2))
    for surf in _surfaces(scene, X, Y, t, code, grid=(x, y)):
        P[surf.idx] = np.stack(surf.P, axis=-1)
        N[surf.idx] = np.stack(surf.N, axis=-1)
        if surf.kind == SPHERE_A:
            Ns[surf.idx] = np.stack(_prepare_a(scene, surf, gradient, True, False, True), axis=-1)
            uv[surf.idx] = np.stack(surf.uv, axis=-1)
            grad[surf.idx] = np.stack(surf.grad, axis=-1)
        else:
            Ns[surf.idx] = N[surf.idx]
    shape = (height, width)
    return GBuffer(code.reshape(shape), t.reshape(shape), P.reshape(shape + (3,)),
                   N.reshape(shape + (3,)), Ns.reshape(shape + (3,)), uv.reshape(shape + (2,)),
                   grad.reshape(shape + (2,)), x, y)


def _check_workers(workers):
    if workers is None:
        return WORKERS
    if isinstance(workers, bool) or not isinstance(workers, numbers.Integral) or not 1 <= workers <= 64:
        raise ValueError(f"workers must be an integer from 1 to 64, got {workers!r}")
    return int(workers)


def check_flag(name, value):
    """Return ``value`` as a bool if it is one (Python's or numpy's), else
    raise TypeError naming the keyword ``name`` (as `_check_size` does for
    sizes): ``kink="no"`` or ``grad=0`` would otherwise be read by truth value."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {type(value).__name__} {value!r}")
    return bool(value)


def _check_args(scene, width, height, gradient, zoom):
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a renderer.Scene, got {type(scene).__name__}")
    width = _check_size("width", width)
    height = _check_size("height", height)
    if not isinstance(gradient, str) or gradient not in GRADIENTS:
        raise ValueError(f"gradient must be one of {GRADIENTS}, got {gradient!r}")
    if isinstance(zoom, bool) or not isinstance(zoom, numbers.Real):
        raise TypeError(f"zoom must be a real number, got {type(zoom).__name__} {zoom!r}")
    if not 1.0 <= zoom <= MAX_ZOOM:
        raise ValueError(f"zoom must be between 1 and {MAX_ZOOM:g}, got {zoom!r}")
    return scene, width, height, gradient, float(zoom)


@quiet_underflow
def render(scene, width, height, *, gradient="exact", zoom=1.0, kink=True, grad=True, skip=True,
           workers=None):
    """Render the Chapter-9 scene.

    Parameters
    ----------
    scene : Scene
        A validated scene (see `Scene`).
    width, height : int
        Image size in pixels, each in [1, 8192].
    gradient : {"exact", "central"}, keyword-only
        "exact": the symbolic pipeline, the gradient of h generated from its
        sympy expression.  "central": the numeric pipeline, central differences
        of the same h with step ``scene.eps`` (u wraps, v clamps).
    zoom : float in [1, 1e6], keyword-only
        Magnification of the image window about the optical axis, where sphere
        A's pole is seen (see `renderer.geometry.image_plane`); 1 is the seed's view.
    kink, grad : bool, keyword-only
        Whether to compute ``Frame.kink`` and ``Frame.grad``; when False the
        field is None and its work is skipped (the image does not need them).
    skip : bool, keyword-only
        True (default): do only the work the outputs need: objects that are off
        are neither intersected nor shadow blockers, zero-colour lights are
        skipped, shadow rays are traced only where the light could add
        something, and at beta = 0 no gradient is computed unless ``grad``.
        False runs the reference path that skips none of it; the tests show the
        two give the same bits.
    workers : int in [1, 64], keyword-only
        Workers rendering tiles side by side (default `WORKERS`: the
        machine's cores, at most 4): the calling thread, and ``workers - 1``
        worker processes, at most one per further core (`renderer.workers`:
        started in the background by the second render of a frame of at
        least `MIN_SPLIT_PIXELS` pixels), or threads until they are ready or
        when ``SYMRENDER_WORKER_PROCESSES=0``.  A frame of one tile per
        worker is split so that the tiles cost about the same
        (`_tile_bounds`).  The image is the same bits for any number.

    Returns
    -------
    Frame
        ``image`` (H, W, 3) float64 linear RGB in [0, 1]; ``chamber`` (H, W)
        uint8; ``kink`` (H, W) bool; ``grad`` (H, W, 2) float64 (each of the last
        two None when not requested).

    Raises
    ------
    TypeError
        ``scene`` is not a Scene, ``width``/``height`` is not an integer, or
        ``kink``, ``grad`` or ``skip`` is not a bool.
    ValueError
        ``width``/``height`` outside [1, 8192], an unknown ``gradient``, or
        ``zoom`` outside [1, 1e6] (TypeError if it is not a real number).

    Notes
    -----
    The image is computed in tiles of at most 65,536 pixels, so the working
    memory beyond the outputs is bounded at any resolution (about 26 MiB per
    worker, and 5.25 MiB of tile slots shared with each worker process).  The
    first call keeps freed memory in the process heap (`renderer.heap`;
    ``SYMRENDER_KEEP_HEAP=0`` opts out).  Source: seed
    Cells 1 and 3 (``render_numeric_bump``, ``render_symbolic_bump``), with the
    corrections listed in the book's errata.
    """
    scene, width, height, gradient, zoom = _check_args(scene, width, height, gradient, zoom)
    kink, grad, skip = (check_flag(n, f) for n, f in (("kink", kink), ("grad", grad), ("skip", skip)))
    keep_heap()
    workers = _check_workers(workers)
    image = np.zeros((height, width, 3))
    chamber = np.zeros((height, width), dtype=np.uint8)
    kink_out = np.zeros((height, width), dtype=bool) if kink else None
    grad_out = np.zeros((height, width, 2)) if grad else None
    x, y = image_plane(scene.radius_a, scene.camera_z, width, height, zoom)
    flat_image = image.reshape(-1, 3)
    flat_chamber = chamber.reshape(-1)
    flat_kink = kink_out.reshape(-1) if kink else None
    flat_grad = grad_out.reshape(-1, 2) if grad else None

    def tile(j0, j1):
        X = np.tile(x, j1 - j0)
        Y = np.repeat(y[j0:j1], width)
        sl = slice(j0 * width, j1 * width)
        _render_tile(scene, gradient, X, Y, flat_image[sl], flat_chamber[sl],
                     flat_kink[sl] if kink else None, flat_grad[sl] if grad else None, skip,
                     (x, y[j0:j1]))

    bounds = _tile_bounds(scene, width, height, zoom, workers, SPHERE_A_COST[gradient])
    if not (workers > 1 and len(bounds) > 1 and _workers.run_tiles(
            bounds, tile, (scene, gradient, width, height, zoom, kink, grad, skip),
            (flat_image, flat_chamber, flat_kink, flat_grad), width, workers - 1, TILE_PIXELS)):
        _run_tiles([lambda b=b: tile(*b) for b in bounds], workers)
    return Frame(image=image, chamber=chamber, kink=kink_out, grad=grad_out, scene=scene,
                 gradient=gradient)
