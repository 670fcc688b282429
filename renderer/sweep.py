"""An eps sweep that computes everything but sphere A's shading once.

Everything above the gradient in the pipeline depends on geometry alone (the
theorem "bump moves no boundary", proved in proofs/no_boundary.py and checked
by verify/ with independent full renders).  So for a sweep over the step eps
of the numeric pipeline, the rays, the chamber codes, the hit points, the
shadow rays and the shading of every object other than sphere A are computed
once per tile; per eps only sphere A's central-difference gradient, perturbed
normal and colour are recomputed.  The symbolic frame is rendered alongside in
the same pass.  tests/test_skips.py shows every frame equal, bit for bit, to a
separate `render` call.
"""

from __future__ import annotations

import collections.abc
import itertools
import math
import numbers
import threading
from dataclasses import dataclass

import numpy as np

from . import fields
from .geometry import image_plane
from .heap import keep_heap
from .ledger import compare
from .render import (FLOOR, SPHERE_A, Frame, _check_args, _check_workers, _gradient, quiet_underflow,
                     _lights, _nearest_hit, _prepare_a, _run_tiles, _shade, _shading_normal, _view,
                     _put_rows, _store_rgb, _surfaces, _tile_rows, _trace_shadows)
from .scene import MAX_EPS, MIN_EPS

__all__ = ["Sweep", "sweep", "MAX_STEPS"]

#: Most steps one sweep accepts (each holds a frame in memory).
MAX_STEPS = 64


@dataclass(frozen=True)
class Sweep:
    """Frames and census of an eps sweep.

    Attributes
    ----------
    eps : tuple of float            the steps, in the order given
    numeric : tuple of Frame        central-difference frames, one per step
    symbolic : Frame                the exact-gradient frame
    census : tuple of Ledger        ``compare(numeric[i], symbolic)`` per step
    """

    eps: tuple
    numeric: tuple
    symbolic: Frame
    census: tuple


def _check_steps(eps_values):
    """The steps as a tuple of floats, read one at a time: at most
    `MAX_STEPS` + 1 items are taken from an iterator, so an endless or
    over-long one is refused without being consumed whole.

    Raises TypeError for a non-iterable, a string, or an unordered collection
    (a set or a mapping: the census is reported in the order of the steps);
    ValueError for no steps, more than `MAX_STEPS`, or a step outside
    [`MIN_EPS`, `MAX_EPS`] (naming its index)."""
    if isinstance(eps_values, (str, bytes)) or not hasattr(eps_values, "__iter__"):
        raise TypeError(f"eps_values must be a sequence of positive numbers, got {eps_values!r}")
    if isinstance(eps_values, (collections.abc.Set, collections.abc.Mapping,
                               collections.abc.KeysView, collections.abc.ValuesView)):
        raise TypeError(f"eps_values must be ordered (a list, tuple, array or iterator), got a "
                        f"{type(eps_values).__name__}: the census follows the order of the steps")
    steps = []
    for i, e in enumerate(itertools.islice(eps_values, MAX_STEPS + 1)):
        if isinstance(e, (bool, np.bool_)) or not isinstance(e, numbers.Real) or not math.isfinite(e) \
                or not MIN_EPS <= e <= MAX_EPS:
            raise ValueError(f"eps_values[{i}] must be a number in [{MIN_EPS:g}, {MAX_EPS:g}], got {e!r}")
        steps.append(float(e))
    if not steps:
        raise ValueError(f"eps_values must hold 1 to {MAX_STEPS} steps, got none")
    if len(steps) > MAX_STEPS:
        raise ValueError(f"eps_values must hold 1 to {MAX_STEPS} steps, got more than {MAX_STEPS}")
    return tuple(steps)


@quiet_underflow
def sweep(scene, eps_values, width, height, *, zoom=1.0, workers=None, progress=None):
    """Render the symbolic frame and one numeric frame per step, sharing the geometry.

    Parameters
    ----------
    scene : Scene
        ``scene.eps`` is ignored; the steps come from ``eps_values``.
    eps_values : ordered iterable of float in [1e-16, 0.25] (1 to 64 of them), chart units
    width, height : int in [1, 8192]
    zoom : float in [1, 1e6], keyword-only (see `render`)
    workers : int >= 1, keyword-only (see `render`)
    progress : callable(done, total), keyword-only, optional
        Called after each tile with the pixels done so far and the total
        (for a progress bar); it must not raise.

    Returns
    -------
    Sweep
        Each ``numeric[i]`` equals ``render(scene.replace(eps=eps_values[i]),
        width, height, gradient="central", zoom=zoom)`` bit for bit, and
        ``symbolic`` equals the exact render; ``census[i]`` is their `Ledger`.

    Raises
    ------
    TypeError, ValueError
        As `render`; for an empty or over-long ``eps_values`` (an iterator is
        read no further than step 65), an unordered one (a set or a mapping),
        or a step outside [1e-16, 0.25] (the message names its index).

    Notes
    -----
    Memory: one frame (about 57 bytes per pixel) per step plus one.  Source:
    seed §4 (the simulator's ε slider) and Cell 2; the licence is the theorem
    "bump moves no boundary" (seed §3).
    """
    scene, width, height, _, zoom = _check_args(scene, width, height, "exact", zoom)
    keep_heap()
    workers = _check_workers(workers)
    steps = _check_steps(eps_values)
    scenes = [scene.replace(eps=e) for e in steps]

    def blank(gradient, s):
        return Frame(image=np.zeros((height, width, 3)), chamber=np.zeros((height, width), np.uint8),
                     kink=np.zeros((height, width), bool), grad=np.zeros((height, width, 2)),
                     scene=s, gradient=gradient)

    symbolic = blank("exact", scene)
    numeric = [blank("central", s) for s in scenes]
    frames = [symbolic] + numeric
    flat = [(f.image.reshape(-1, 3), f.chamber.reshape(-1), f.kink.reshape(-1), f.grad.reshape(-1, 2))
            for f in frames]
    x, y = image_plane(scene.radius_a, scene.camera_z, width, height, zoom)
    rows = _tile_rows(width, height, workers)
    def tile(j0):
        j1 = min(height, j0 + rows)
        X = np.tile(x, j1 - j0)
        Y = np.repeat(y[j0:j1], width)
        sl = slice(j0 * width, j1 * width)
        t, code = _nearest_hit(scene, X, Y, grid=(x, y[j0:j1]))
        for image, chamber, _, _ in flat:
            chamber[sl] = code
        for surf in _surfaces(scene, X, Y, t, code, grid=(x, y[j0:j1])):
            flat_kind = surf.kind == FLOOR
            lights = _lights(scene, surf.P, surf.N, surf.floor_blocks, True, flat_kind)
            for light in lights:
                # Every attached pixel, once: the shading normal varies with eps.
                _trace_shadows(light, surf.spheres, light.attached, surf.P[:2] if flat_kind else None)
            rows_idx = surf.idx + j0 * width
            if surf.kind != SPHERE_A:
                col = _shade(scene, surf.P, surf.N, surf.albedo, lights, flat_kind)
                for image, _, _, _ in flat:
                    _store_rgb(image, rows_idx, col)
                continue
            # Sphere A: the stencil's eps-free factors, once for all steps (and
            # the kink flag read off them), the exact frame, then one re-shade
            # per step.
            base = fields.central_stencil(scene.height_field).base(*surf.uv, scene.k_u, scene.k_v)
            Ns = _prepare_a(scene, surf, "exact", True, True, True, base)
            kink = surf.kink
            view = _view(scene, surf.P, lights)
            for k, (s, (image, _, kink_out, grad_out)) in enumerate(zip([scene] + scenes, flat)):
                if k > 0:
                    surf.grad = _gradient(s, surf, "central", s.eps, base)
                    Ns = _shading_normal(s, surf, surf.grad)
                _store_rgb(image, rows_idx, _shade(s, surf.P, Ns, surf.albedo, lights, view=view))
                _put_rows(grad_out, rows_idx, np.stack(surf.grad, axis=-1))
                kink_out[rows_idx] = kink
    done = {"pixels": 0}
    lock = threading.Lock()

    def tile_and_report(j0):
        tile(j0)
        if progress is not None:
            with lock:
                done["pixels"] += (min(height, j0 + rows) - j0) * width
                progress(done["pixels"], width * height)

    _run_tiles([lambda j0=j0: tile_and_report(j0) for j0 in range(0, height, rows)], workers)
    # The ledgers, side by side on the same threads.
    census = [None] * len(numeric)

    def ledger(i):
        census[i] = compare(numeric[i], symbolic)

    _run_tiles([lambda i=i: ledger(i) for i in range(len(numeric))], workers)
    census = tuple(census)
    return Sweep(eps=steps, numeric=tuple(numeric), symbolic=symbolic, census=census)
