"""The size limits of `render`, `gbuffer` and `sweep`, each at the limit and one past it.

renderer/render.py: a side of at most `MAX_SIDE` pixels, at most `MAX_PIXELS`
in a frame; renderer/sweep.py: at most `MAX_STEPS` steps and
`MAX_SWEEP_PIXELS` pixels in all its (steps + 1) frames.  An accepted call
at a pixel limit would allocate gigabytes, so numpy's allocator is replaced
by one that refuses any array of more than a million elements, saying what
was asked: the accepted call must reach the allocation of its first frame
(of the shape asked for), a refused call must raise its ValueError before
allocating anything large.  The smallest requests past each limit are
searched for over all sides, so that an off-by-one in the arithmetic (the
sweep's frames counted without the exact one) fails.  With the sweep's bound
scaled down to a few pixels the same arithmetic runs end to end.
"""

from __future__ import annotations

import numpy as np
import pytest

from renderer import Scene, gbuffer, render, sweep
import importlib
from renderer.render import MAX_PIXELS, MAX_SIDE
from renderer.sweep import MAX_STEPS, MAX_SWEEP_PIXELS

#: Arrays of more elements than this are refused by `allocations`.
LARGE = 1 << 20


class Allocated(Exception):
    """Raised by the guarded allocator in place of allocating a large array."""


@pytest.fixture
def allocations(monkeypatch):
    """numpy.zeros refusing arrays of more than LARGE elements (raises `Allocated`
    with the shape); returns the list of shapes asked for."""
    asked, zeros = [], np.zeros

    def guarded(shape, *args, **kwargs):
        asked.append(tuple(np.atleast_1d(shape)))
        if np.prod(shape, dtype=np.int64) > LARGE:
            raise Allocated(tuple(np.atleast_1d(shape)))
        return zeros(shape, *args, **kwargs)

    monkeypatch.setattr(np, "zeros", guarded)
    return asked


CALLS = {"render": lambda w, h: render(Scene(), w, h),
         "gbuffer": lambda w, h: gbuffer(Scene(), w, h),
         "sweep": lambda w, h: sweep(Scene(), (1e-3,), w, h)}


def smallest_past(limit, frames=1):
    """(width, height), sides in [1, MAX_SIDE], whose frames x width x height is the
    least above ``limit``; for a sweep (frames > 1) a frame of at most MAX_PIXELS."""
    width = np.arange(1, MAX_SIDE + 1, dtype=np.int64)
    height = limit // (frames * width) + 1                     # the least with frames w h > limit
    ok = (height <= MAX_SIDE) & ((frames == 1) | (width * height <= MAX_PIXELS))
    total = np.where(ok, frames * width * height, np.iinfo(np.int64).max)
    k = int(np.argmin(total))
    assert ok[k] and frames * width[k] * (height[k] - 1) <= limit < total[k]
    return int(width[k]), int(height[k])


# --- the side -------------------------------------------------------------------------------------

@pytest.mark.parametrize("call", sorted(CALLS))
def test_a_side_of_max_side_is_rendered(call):
    for width, height in ((MAX_SIDE, 1), (1, MAX_SIDE)):
        result = CALLS[call](width, height)
        chamber = result.symbolic.chamber if call == "sweep" else result.chamber
        assert chamber.shape == (height, width)


@pytest.mark.parametrize("call", sorted(CALLS))
def test_a_side_one_past_max_side_is_refused_before_allocating(call, allocations):
    for name, (width, height) in (("width", (MAX_SIDE + 1, 1)), ("height", (1, MAX_SIDE + 1))):
        with pytest.raises(ValueError, match=rf"^{name} must be an integer in \[1, {MAX_SIDE}\], "
                                             rf"got {MAX_SIDE + 1}$"):
            CALLS[call](width, height)
    assert not any(np.prod(shape) > LARGE for shape in allocations)


# --- the pixels of a frame ------------------------------------------------------------------------

@pytest.mark.parametrize("call", sorted(CALLS))
def test_a_frame_of_max_pixels_is_allocated(call, allocations):
    for width in (MAX_PIXELS // MAX_SIDE, 4096, MAX_SIDE):
        height = MAX_PIXELS // width
        assert width * height == MAX_PIXELS
        frames = (2,) if call == "sweep" else (1,)          # the image: (frames, H, W, 3)
        with pytest.raises(Allocated) as asked:
            CALLS[call](width, height)
        assert asked.value.args[0][:-1] == frames + (height, width)


@pytest.mark.parametrize("call", sorted(CALLS))
def test_a_frame_one_past_max_pixels_is_refused_before_allocating(call, allocations):
    width, height = smallest_past(MAX_PIXELS)
    with pytest.raises(ValueError, match=rf"^width \* height must be at most {MAX_PIXELS:,} pixels .*, "
                                         rf"got {width} x {height} = {width * height:,}$"):
        CALLS[call](width, height)
    assert allocations == []


# --- the steps and the pixels of a sweep ----------------------------------------------------------

def test_max_steps_are_swept_and_one_more_refused(allocations):
    sw = sweep(Scene(), np.geomspace(1e-1, 1e-8, MAX_STEPS), 2, 2)
    assert len(sw.numeric) == len(sw.census) == MAX_STEPS
    allocations.clear()
    with pytest.raises(ValueError, match=rf"^eps_values must hold 1 to {MAX_STEPS} steps, got more than {MAX_STEPS}$"):
        sweep(Scene(), np.geomspace(1e-1, 1e-8, MAX_STEPS + 1), 2, 2)
    assert allocations == []


@pytest.mark.parametrize("steps", [1, 3, MAX_STEPS - 1])
def test_a_sweep_of_max_sweep_pixels_is_allocated(steps, allocations):
    """(steps + 1) frames of MAX_SWEEP_PIXELS / (steps + 1) pixels each: the bound itself."""
    pixels = MAX_SWEEP_PIXELS // (steps + 1)
    width = min(MAX_SIDE, pixels)
    height = pixels // width
    assert (steps + 1) * width * height == MAX_SWEEP_PIXELS
    with pytest.raises(Allocated) as asked:
        sweep(Scene(), [1e-3] * steps, width, height)
    assert asked.value.args[0] == (steps + 1, height, width, 3)


@pytest.mark.parametrize("steps", [2, MAX_STEPS])
def test_a_sweep_one_pixel_or_one_frame_past_max_sweep_pixels_is_refused_before_allocating(steps, allocations):
    """The least (steps + 1) x width x height above the bound, and one frame more than
    the bound holds at the largest frame that fits it with one step fewer."""
    frames = steps + 1
    cases = [smallest_past(MAX_SWEEP_PIXELS, frames)]
    width = min(MAX_SIDE, MAX_SWEEP_PIXELS // steps)
    cases.append((width, MAX_SWEEP_PIXELS // steps // width))      # steps x w x h = the bound
    for width, height in cases:
        assert frames * width * height > MAX_SWEEP_PIXELS >= steps * width * height
        with pytest.raises(ValueError, match=rf"^a sweep holds \(steps \+ 1\) x width x height <= "
                                             rf"{MAX_SWEEP_PIXELS:,} pixels in memory, got {frames} x {width} x "
                                             rf"{height} = {frames * width * height:,}$"):
            sweep(Scene(), [1e-3] * steps, width, height)
    assert not any(np.prod(shape) > LARGE for shape in allocations)


def test_the_sweeps_bound_end_to_end_at_a_few_pixels(monkeypatch):
    """The bound scaled down to two 4 x 4 frames: sweeps at it run whole, one frame or
    one pixel past it are refused."""
    monkeypatch.setattr(importlib.import_module("renderer.sweep"), "MAX_SWEEP_PIXELS", 2 * 4 * 4)
    assert len(sweep(Scene(), (1e-3,), 4, 4).numeric) == 1                     # 2 x 16
    assert len(sweep(Scene(), (1e-1, 1e-2, 1e-3), 4, 2).numeric) == 3          # 4 x 8
    for steps, width, height in (((1e-3, 1e-4), 4, 4), ((1e-3,), 3, 6), ((1e-3,) * 3, 3, 3)):
        with pytest.raises(ValueError, match=r"^a sweep holds .* <= 32 pixels in memory, got "):
            sweep(Scene(), steps, width, height)
