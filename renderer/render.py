"""The two pipelines (and a third): `render` and `gbuffer`, checked arguments
around one compiled per-pixel kernel (`renderer.kernel`).

The pipelines differ only in the gradient of h on sphere A: "exact" (the
symbolic pipeline, sympy's derivative), "central" (the numeric pipeline,
central differences with step ``scene.eps``) and "footprint" (central
differences whose step is the pixel's footprint in the chart, pbrt-v4's rule).
"""

from __future__ import annotations

import concurrent.futures
import math
import os
import threading
from dataclasses import dataclass

import numba
import numpy as np

from . import backends, fieldcode, kernel, validate
from .kernel import BACKGROUND, FLOOR, SPHERE_A, SPHERE_B
from .scene import Scene

__all__ = [
    "Frame", "render", "GBuffer", "gbuffer", "image_plane", "window_width", "GRADIENTS", "MAX_SIDE", "MAX_PIXELS", "MAX_ZOOM",
    "CHAMBER_NAMES", "BACKGROUND", "SPHERE_A", "SPHERE_B", "FLOOR", "WINDOW_MARGIN", "WINDOW_OFFSET",
]

#: Accepted values of ``render(..., gradient=...)`` (their index is the kernel's code).
GRADIENTS = ("exact", "central", "footprint")
#: Largest accepted image side, in pixels.
MAX_SIDE = 8192
#: Most pixels (W * H) of one frame: a frame with kink and grad holds 42 bytes a pixel (0.7 GB at
#: the most), a G-buffer 138.
MAX_PIXELS = 4096 * 4096
#: Largest accepted magnification of the image window (`render`'s ``zoom``).  The pole's shading
#: normal is right to a few ulps at every zoom: the hit's N_x, N_y = t (x, y) / R keep their relative
#: precision however near the axis, and so do theta and sin phi (tests/test_pole.py, to 1e6).
MAX_ZOOM = 1e6
#: Chamber codes of `Frame.chamber`.
CHAMBER_NAMES = {BACKGROUND: "background", SPHERE_A: "sphere A", SPHERE_B: "sphere B", FLOOR: "floor"}
#: The window's half-width is this multiple of sphere A's silhouette radius,
#: and it is shifted down by this fraction of its half-width (seed Cell 1).
WINDOW_MARGIN, WINDOW_OFFSET = 1.25, 0.15


def image_plane(radius_a, camera_z, width, height, zoom=1.0):
    """Pixel centres on the image plane z = 0 (seed Cell 1's window).

    The half-width is 1.25 e R / sqrt(e^2 - R^2) (1.25 times sphere A's
    silhouette radius on z = 0) and the window is shifted down by 0.15 of it;
    column i and row j map to x_i = half (2 (i + 1/2) / width - 1) and
    y_j = half (1 - 2 (j + 1/2) / height) - 0.15 half, both divided by
    ``zoom`` (the window magnified about the optical axis, where sphere A's
    pole is seen).

    Returns
    -------
    x : (width,) float64, y : (height,) float64   scene units; row 0 is the top.
    """
    half = window_width(radius_a, camera_z, 1.0) / 2.0
    x = half * (2.0 * (np.arange(width) + 0.5) / width - 1.0) / zoom
    y = (half * (1.0 - 2.0 * (np.arange(height) + 0.5) / height) - WINDOW_OFFSET * half) / zoom
    return x, y


def window_width(radius_a, camera_z, zoom=1.0):
    """Width (and height) of the image window in scene units: twice 1.25 times
    sphere A's silhouette radius e R / sqrt(e^2 - R^2) on z = 0, over ``zoom``."""
    return 2.0 * WINDOW_MARGIN * camera_z * radius_a / math.sqrt(camera_z**2 - radius_a**2) / zoom


@dataclass(frozen=True)
class Frame:
    """One rendered frame.

    Attributes
    ----------
    image : (H, W, 3) float64     linear RGB, clipped to [0, 1]
    chamber : (H, W) uint8        0 background, 1 sphere A, 2 sphere B, 3 floor
    kink : (H, W) bool or None    the seed's crease band on sphere A (fields with creases only)
    grad : (H, W, 2) float64 or None   (h_u, h_v) used on sphere A; 0 elsewhere
    scene : Scene
    gradient : {"exact", "central", "footprint"}
    """

    image: np.ndarray
    chamber: np.ndarray
    kink: np.ndarray
    grad: np.ndarray
    scene: Scene
    gradient: str


@dataclass(frozen=True)
class GBuffer:
    """Per-pixel geometry of a frame, for checks and figures.

    chamber (H, W) uint8; t (H, W) float64, the ray parameter of the nearest
    hit (inf: none), which decides the chamber; P, N, Ns (H, W, 3) float64:
    hit point, geometric and shading normal, unit (0 where chamber is 0); on
    sphere A, P is computed apart from t, within a few ulps of the radius of
    the exact hit (`renderer.kernel.sphere_a_point`); uv, grad (H, W, 2)
    float64: sphere A's chart and gradient (0 elsewhere); x (W,), y (H,):
    pixel centres.
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


def check_args(scene, width, height, gradient, zoom):
    """Validated (scene, width, height, gradient, zoom) by `renderer.validate`; raises as `render` says."""
    if not isinstance(scene, Scene):
        raise validate.InvalidType(f"scene must be a renderer.Scene, got {type(scene).__name__}")
    width = validate.positive_int("width", width, high=MAX_SIDE)
    height = validate.positive_int("height", height, high=MAX_SIDE)
    if width * height > MAX_PIXELS:
        raise validate.InvalidValue(f"width * height must be at most {MAX_PIXELS:,} pixels (4096 x 4096), "
                                    f"got {width} x {height} = {width * height:,}")
    gradient = validate.choice("gradient", gradient, GRADIENTS)
    zoom = validate.real("zoom", zoom, low=1.0, high=MAX_ZOOM)
    return scene, width, height, gradient, zoom


def check_workers(workers):
    """``workers``: None or an integer in [1, 64] (`renderer.validate.positive_int`)."""
    return None if workers is None else validate.positive_int("workers", workers, high=64)


#: Pixels per call of the compiled kernel: a frame is rendered in bands of rows, so that a Ctrl-C
#: (a KeyboardInterrupt, raised between two calls) stops a large render within one band.
BAND_PIXELS = 1 << 16


def bands(height, width):
    """(first, last) row ranges of about `BAND_PIXELS` pixels each (at least one row), in order."""
    rows = max(1, BAND_PIXELS // width)
    return [(j, min(j + rows, height)) for j in range(0, height, rows)]


#: Pixels per thread at least: handing rows to a second thread costs some 0.3 ms (the GIL, the
#: kernel's dispatch), so it gains from about 128 x 128 (measured, 2 threads against one:
#: 64 x 64 0.80 ms against 0.71, 128 x 128 1.96 against 2.39; medians of 300 renders).
THREAD_PIXELS = 1 << 13
#: The process's rendering threads, made on first use (`_pool`); a forked child, which has none of
#: its parent's threads, makes its own (`_forget_pool`).
_POOL, _POOL_LOCK = None, threading.Lock()


def _pool():
    global _POOL
    with _POOL_LOCK:
        if _POOL is None:
            _POOL = concurrent.futures.ThreadPoolExecutor(validate.MAX_THREADS, thread_name_prefix="render")
        return _POOL


def _forget_pool():
    global _POOL, _POOL_LOCK
    _POOL, _POOL_LOCK = None, threading.Lock()


os.register_at_fork(after_in_child=_forget_pool)


def run_bands(rows, height, width, workers):
    """Call ``rows(first, last, stride)`` on every band of `bands`, on ``workers`` threads
    (None: ``NUMBA_NUM_THREADS``, numba's count, by default the machine's cores; at most
    that count, and at most one per `THREAD_PIXELS` pixels): thread t of n computes rows
    first + t, first + t + n, ... of each band (the kernel releases the GIL); thread 0 is
    the caller, the others come from a pool kept for the process (a pool made per call cost
    about 1 ms, more than a 64 x 64 render).  A KeyboardInterrupt stops every thread after
    its band, and returns when they have.  The count must be in [1,
    `renderer.validate.MAX_THREADS`] (InvalidValue: numba's own pool, 100000 threads,
    segfaulted at that count)."""
    most = validate.thread_count("NUMBA_NUM_THREADS", numba.config.NUMBA_NUM_THREADS)
    n = min(int(workers or most), most, max(1, height * width // THREAD_PIXELS))
    work, stop = bands(height, width), threading.Event()

    def thread(t):
        for first, last in work:
            if stop.is_set():
                return
            rows(first + t, last, n)
    others = [_pool().submit(thread, t) for t in range(1, n)]
    try:
        thread(0)
        for other in others:
            other.result()
    except BaseException:
        stop.set()
        concurrent.futures.wait(others)
        raise


def _run(scene, width, height, gradient, zoom, skip, want_kink, want_grad, want_geo, workers):
    x, y = image_plane(scene.radius_a, scene.camera_z, width, height, zoom)
    out = dict(image=np.zeros((1, height, width, 3)), chamber=np.zeros((height, width), np.uint8),
               kink=np.zeros((height, width) if want_kink else (1, 1), bool),
               grad=np.zeros((1, height, width, 2) if want_grad else (1, 1, 1, 2)))
    geo_shape = (height, width) if want_geo else (1, 1)
    geo = dict(t=np.full(geo_shape, np.inf), P=np.zeros(geo_shape + (3,)), N=np.zeros(geo_shape + (3,)),
               Ns=np.zeros(geo_shape + (3,)), uv=np.zeros(geo_shape + (2,)))
    # Pixel spacing on the image plane (the footprint's ray differentials);
    # a frame one pixel wide or high spans the whole window.
    window = window_width(scene.radius_a, scene.camera_z, zoom)
    dx = float(x[1] - x[0]) if width > 1 else window
    dy = float(y[0] - y[1]) if height > 1 else window
    prm, lights = kernel.params(scene, skip)
    job = kernel.Job(methods=np.array([GRADIENTS.index(gradient)]), steps=np.array([float(scene.eps)]), skip=skip,
                     want_kink=want_kink, want_grad=want_grad, want_geo=want_geo, dx=dx, dy=dy)
    outputs = kernel.Outputs(**out, **geo)
    code = fieldcode.compiled(scene.field)
    run_bands(lambda first, last, stride: kernel.render_rows(prm, lights, x, y, first, last, stride, job, outputs,
                                                             code), height, width, workers)
    out["image"], out["grad"] = out["image"][0], out["grad"][0]          # the one frame
    return x, y, out, geo


#: Pixels per launch of the array kernel, per backend (bounds its working memory: numpy holds
#: some forty temporaries per pixel, Dr.Jit fuses them and holds the outputs).
ARRAY_BLOCK_PIXELS = {"numpy": 1 << 16, "drjit": 1 << 22}


def _render_array(scene, width, height, gradient, zoom, want_kink, want_grad, backend):
    """The outputs of `render` from the array kernel (`renderer.arraykernel`) on ``backend``."""
    from . import arraykernel
    xp = backends.namespace(backend)
    x, y = image_plane(scene.radius_a, scene.camera_z, width, height, zoom)
    window = window_width(scene.radius_a, scene.camera_z, zoom)
    dx = float(x[1] - x[0]) if width > 1 else window
    dy = float(y[0] - y[1]) if height > 1 else window
    rows = max(1, ARRAY_BLOCK_PIXELS[backend] // width)
    with xp.scope():
        blocks = [arraykernel.render_block(xp, scene, x, y[j:j + rows], method=gradient, eps=float(scene.eps),
                                           dx=dx, dy=dy, kink=want_kink, grad=want_grad)
                  for j in range(0, height, rows)]
    out = {k: blocks[0][k] if len(blocks) == 1 else np.concatenate([b[k] for b in blocks]) for k in blocks[0]}
    return {k: a.reshape((height, width) + a.shape[1:]) for k, a in out.items()}


def render(scene, width, height, *, gradient="exact", zoom=1.0, kink=True, grad=True, skip=True,
           workers=None, backend="numba"):
    """Render the Chapter-9 scene.

    Parameters
    ----------
    scene : Scene
    width, height : int in [1, 8192]
        Image size in pixels.
    gradient : {"exact", "central", "footprint"}, keyword-only
        "exact": sympy's derivative of h (the symbolic pipeline).  "central":
        central differences of h with step ``scene.eps`` (u wraps, v clamps;
        the numeric pipeline).  "footprint": central differences whose steps
        in u and v are the pixel's footprint in the chart, half the sum of
        |du/dx| and |du/dy| (pbrt-v4's bump rule; `renderer.formulas.FOOTPRINT`).
    zoom : float in [1, 1e6], keyword-only
        Magnification of the window about the optical axis (sphere A's pole).
    kink, grad : bool, keyword-only
        Whether to compute ``Frame.kink`` and ``Frame.grad`` (else None).
    skip : bool, keyword-only
        True: only the work the outputs need (see `renderer.kernel`).  False:
        the reference path that skips nothing; both give the same bits.
    workers : int in [1, 64] or None, keyword-only
        Threads rendering rows side by side (None: numba's count,
        ``NUMBA_NUM_THREADS`` or the machine's cores; never more than that
        count, nor more than one per `THREAD_PIXELS` pixels).  The image is the same bits for any number.  The numba
        backend's; Dr.Jit runs on its own thread pool, and one render at a
        time uses it (`renderer.backends.DRJIT_LOCK`: other threads wait).
    backend : {"numba", "drjit", "auto", "numpy"}, keyword-only
        "numba": the per-pixel kernel (`renderer.kernel`), the book's.
        "drjit": the branch-free array kernel (`renderer.arraykernel`, the
        same steps and generated formulas) compiled by Dr.Jit's LLVM backend,
        which evaluates sin, cos and atan2 for several pixels per instruction;
        it needs the system's libLLVM (`renderer.backends`).  Its own sin,
        cos and atan2 are a few ulp from libm's: the frame agrees with
        numba's to the parity tests' tolerance, not bit for bit (1e-12 per
        channel with the exact gradient; with ``gradient="central"`` the
        quotient divides those ulps by 2 eps, up to about 4e-17 / eps:
        measured at 256 x 256 on sine, ridges and rings, 1e-13 at eps = 1e-3,
        4e-8 at 1e-9, 0.4 at 1e-16).  The scene's
        numbers are inputs of the compiled kernel: scenes that differ only in
        them replay one kernel; a new `renderer.arraykernel.structure`
        (field, bump, model, which objects are on, where each light is
        against the spheres and the floor, an integer shininess) compiles one
        (tens of ms).  "auto":
        "drjit" where available, else "numba".  "numpy": the array kernel on
        numpy (slow; it checks the array kernel on any machine).  The array
        kernel ignores ``skip`` (it computes what a render of the outputs
        needs, the same values either way).

    Returns
    -------
    Frame

    Raises
    ------
    TypeError
        ``scene`` is not a Scene; a size, ``gradient``, ``zoom``,
        ``workers`` or ``backend`` of the wrong type; a flag not a bool.
    ValueError
        A size outside [1, 8192], an unknown ``gradient`` or ``backend``,
        ``zoom`` outside [1, 1e6], ``workers`` outside [1, 64];
        ``NUMBA_NUM_THREADS`` outside [1, `renderer.validate.MAX_THREADS`]
        (numba backend); ``backend="drjit"`` where Dr.Jit's LLVM backend is
        unavailable (the message says what is missing and how to install it).

    Notes
    -----
    Working memory beyond the outputs is a few hundred bytes per thread.
    Source: seed Cells 1 and 3 (``render_numeric_bump``, ``render_symbolic_bump``)
    with the corrections listed in the book's errata.
    """
    scene, width, height, gradient, zoom = check_args(scene, width, height, gradient, zoom)
    kink, grad, skip = (validate.flag(n, f) for n, f in (("kink", kink), ("grad", grad), ("skip", skip)))
    check_workers(workers)
    backend = backends.resolve(validate.choice("backend", backend, backends.BACKENDS))
    if backend == "numba":
        _, _, out, _ = _run(scene, width, height, gradient, zoom, skip, kink, grad, False, workers)
    else:
        out = _render_array(scene, width, height, gradient, zoom, kink, grad, backend)
    return Frame(out["image"], out["chamber"], out["kink"] if kink else None, out["grad"] if grad else None,
                 scene, gradient)


def gbuffer(scene, width, height, *, gradient="exact", zoom=1.0):
    """Per-pixel hit points, normals and chart of a frame.

    Same arguments, validation and errors (TypeError, ValueError) as
    `render`, and the same kernel pass: the geometry is that of the rendered
    frame, not recomputed.

    Returns
    -------
    GBuffer
        chamber (H, W) uint8; t (H, W) float64; P, N, Ns (H, W, 3) float64
        (scene units; unit normals); uv, grad (H, W, 2) float64; x (W,), y (H,).
    """
    scene, width, height, gradient, zoom = check_args(scene, width, height, gradient, zoom)
    x, y, out, geo = _run(scene, width, height, gradient, zoom, True, False, True, True, None)
    return GBuffer(out["chamber"], geo["t"], geo["P"], geo["N"], geo["Ns"], geo["uv"], out["grad"], x, y)
