"""An eps sweep that computes everything but sphere A's shading once.

Everything above the gradient depends on geometry alone (the theorem "bump
moves no boundary", proved in proofs/no_boundary.py and checked by verify/
with independent full renders).  So for a sweep over the step eps of the
numeric pipeline the kernel (`renderer.kernel.render_rows`, one frame per step) computes, per
pixel, the ray, the chamber, the hit point, the shadow rays and the colour of
every object but sphere A once, and re-shades sphere A per step; the exact
frame is rendered in the same pass.  tests/test_skips.py shows every frame
equal, bit for bit, to a separate `render` call.
"""

from __future__ import annotations

import collections.abc
import itertools
from dataclasses import dataclass

import numpy as np

from . import fieldcode, kernel, validate
from .ledger import compare
from .render import Frame, check_args, check_workers, image_plane, run_bands
from .scene import MAX_EPS, MIN_EPS

__all__ = ["Sweep", "sweep", "MAX_STEPS", "MAX_SWEEP_PIXELS"]

#: Most steps one sweep accepts (each holds a frame in memory).
MAX_STEPS = 64
#: Most pixels one sweep holds in all its frames, (steps + 1) x width x
#: height: two 4096^2 frames' worth (each pixel 42 bytes: image, grad,
#: chamber, kink), bounding its memory.
MAX_SWEEP_PIXELS = 2 * 4096 * 4096


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
    if (isinstance(eps_values, (str, bytes)) or not hasattr(eps_values, "__iter__")
            or np.ndim(eps_values) == 0 and isinstance(eps_values, np.ndarray)):    # 0-d: not iterable
        raise validate.InvalidType(f"eps_values must be a sequence of positive numbers, got "
                                   f"{validate._shown(eps_values)}")
    if isinstance(eps_values, (collections.abc.Set, collections.abc.Mapping,
                               collections.abc.KeysView, collections.abc.ValuesView)):
        raise validate.InvalidType(f"eps_values must be ordered (a list, tuple, array or iterator), got a "
                                   f"{type(eps_values).__name__}: the census follows the order of the steps")
    steps = []
    for i, e in enumerate(itertools.islice(eps_values, MAX_STEPS + 1)):
        steps.append(validate.real(f"eps_values[{i}]", e, low=MIN_EPS, high=MAX_EPS))
    if not steps:
        raise validate.InvalidValue(f"eps_values must hold 1 to {MAX_STEPS} steps, got none")
    if len(steps) > MAX_STEPS:
        raise validate.InvalidValue(f"eps_values must hold 1 to {MAX_STEPS} steps, got more than {MAX_STEPS}")
    return tuple(steps)


def sweep(scene, eps_values, width, height, *, zoom=1.0, workers=None):
    """Render the symbolic frame and one numeric frame per step, sharing the geometry.

    Parameters
    ----------
    scene : Scene
        ``scene.eps`` is ignored; the steps come from ``eps_values``.
    eps_values : ordered iterable of float in [1e-16, 0.25] (1 to 64 of them), chart units
    width, height : int in [1, 8192]
    zoom : float in [1, 1e6], keyword-only (see `render`)
    workers : int in [1, 64] or None, keyword-only (see `render`)

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
        or a step outside [1e-16, 0.25] (the message names its index); or
        more than `MAX_SWEEP_PIXELS` pixels in all frames (ValueError).

    Notes
    -----
    Memory: one frame per step plus one (its image, grad, chamber and kink);
    at most `MAX_SWEEP_PIXELS` pixels in all.  Source: seed §4 (the
    simulator's ε slider) and Cell 2.
    """
    scene, width, height, _, zoom = check_args(scene, width, height, "exact", zoom)
    steps = _check_steps(eps_values)
    check_workers(workers)
    n = len(steps) + 1
    if n * width * height > MAX_SWEEP_PIXELS:
        raise validate.InvalidValue(f"a sweep holds (steps + 1) x width x height <= {MAX_SWEEP_PIXELS:,} pixels "
                                    f"in memory, got {n} x {width} x {height} = {n * width * height:,}")
    images, grads = np.zeros((n, height, width, 3)), np.zeros((n, height, width, 2))
    chamber, kink = np.zeros((height, width), np.uint8), np.zeros((height, width), bool)
    x, y = image_plane(scene.radius_a, scene.camera_z, width, height, zoom)
    prm, lights = kernel.params(scene)
    code = fieldcode.compiled(scene.field)
    job = kernel.Job(methods=np.array([kernel.EXACT] + [kernel.CENTRAL] * len(steps)), steps=np.array((0.0,) + steps),
                     skip=True, want_kink=True, want_grad=True, want_geo=False, dx=0.0, dy=0.0)
    none = np.zeros((1, 1, 3))
    outputs = kernel.Outputs(images, chamber, kink, grads, np.zeros((1, 1)), none, none, none, np.zeros((1, 1, 2)))
    run_bands(lambda first, last, stride: kernel.render_rows(prm, lights, x, y, first, last, stride, job, outputs,
                                                             code), height, width, workers)
    frames = [Frame(images[f], chamber.copy(), kink.copy(), grads[f], scene.replace(eps=e) if f else scene,
                    "central" if f else "exact") for f, e in enumerate((scene.eps,) + steps)]
    census = tuple(compare(frame, frames[0]) for frame in frames[1:])
    return Sweep(eps=steps, numeric=tuple(frames[1:]), symbolic=frames[0], census=census)
