"""The §4 ledger (`renderer.compare`) against a direct whole-image computation.

`compare` gathers sphere A's pixels first and works on those only; the
reference below forms |dI| over the whole frame and masks it, as the seed's
Cell 3 does.  The two must agree exactly (same values, same order, so the
same sums), and the check must notice a ledger that masks the wrong pixels.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from renderer import Scene, compare, render, sweep
from renderer.render import SPHERE_A


def whole_image_ledger(numeric, symbolic, kink=None):
    on_a = (numeric.chamber == SPHERE_A) & (symbolic.chamber == SPHERE_A)
    d = np.abs(numeric.image - symbolic.image)
    kink = symbolic.kink if kink is None else kink
    da = d[on_a]

    def mean(m):
        return float(d[m].mean()) if m.any() else float("nan")

    return (float(da.max()) if da.size else 0.0,
            float(np.sqrt(np.mean(da ** 2))) if da.size else 0.0,
            int(np.count_nonzero(numeric.chamber != symbolic.chamber)),
            int(on_a.sum()), mean(kink & on_a), mean(on_a & ~kink))


def as_tuple(led):
    return (led.max_abs, led.rms, led.flips, led.pixels_a, led.mean_abs_kink, led.mean_abs_off_kink)


def same(a, b):
    return all((x == y) or (isinstance(x, float) and math.isnan(x) and math.isnan(y))
               for x, y in zip(a, b))


@pytest.mark.parametrize("scene", [
    Scene(), Scene(height_field="sine", eps=1e-9), Scene(beta=1.5, eps=1e-1),
    Scene(height_field="rings", sphere_b=False, floor=False),
], ids=["default", "sine-1e-9", "beta1.5", "rings-alone"])
def test_ledger_equals_the_whole_image_computation(scene):
    numeric = render(scene, 61, 47, gradient="central")
    symbolic = render(scene, 61, 47)
    assert same(as_tuple(compare(numeric, symbolic)), whole_image_ledger(numeric, symbolic))


def test_the_check_rejects_a_ledger_on_the_wrong_band():
    scene = Scene(eps=1e-1)
    numeric, symbolic = render(scene, 61, 47, gradient="central"), render(scene, 61, 47)
    led = as_tuple(compare(numeric, symbolic))
    assert led[4] == led[4] and led[5] == led[5]      # ridges: both sets non-empty
    wrong = whole_image_ledger(numeric, symbolic, kink=np.roll(symbolic.kink, 1, axis=1))
    assert not same(led, wrong)


def test_sweep_census_is_the_ledger_of_its_frames():
    scene = Scene()
    sw = sweep(scene, (1e-1, 1e-4, 1e-10), 61, 47)
    for frame, led in zip(sw.numeric, sw.census):
        assert same(as_tuple(led), whole_image_ledger(frame, sw.symbolic))


def test_frames_of_different_sizes_are_refused():
    with pytest.raises(ValueError, match="same shape"):
        compare(render(Scene(), 8, 8), render(Scene(), 9, 8))
