"""The §4 ledger (`renderer.compare`) against a direct whole-image computation.

`compare` sums sphere A's pixels in one compiled pass, in raster order.  The
reference below forms |dI| over the whole frame and masks it, as the seed's
Cell 3 does, and sums with `math.fsum` (the correctly rounded sum).  The
maximum and the counts must agree exactly; a mean or the rms within the
error bound of a sum of n non-negative terms added one at a time, n u of it
(u = 2^-53; Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed.,
eq. 4.4), plus a rounding each for the division, the squares and the square
root.  The check must notice a ledger on the wrong pixels or missing one.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from renderer import Scene, compare, render, sweep
from renderer.render import SPHERE_A

U = 2.0**-53


def whole_image_ledger(numeric, symbolic, kink=None):
    """(max_abs, rms, flips, pixels_a, mean_abs_kink, mean_abs_off_kink, n) with exact sums;
    n, the most terms any of the sums adds, sets the allowance."""
    on_a = (numeric.chamber == SPHERE_A) & (symbolic.chamber == SPHERE_A)
    d = np.abs(numeric.image - symbolic.image)
    kink = symbolic.kink if kink is None else kink
    da = d[on_a].ravel()

    def mean(m):
        values = d[m].ravel()
        return math.fsum(values) / values.size if values.size else math.nan

    rms = math.sqrt(math.fsum(da * da) / da.size) if da.size else 0.0
    return (float(da.max()) if da.size else 0.0, rms, int(np.count_nonzero(numeric.chamber != symbolic.chamber)),
            int(on_a.sum()), mean(kink & on_a), mean(on_a & ~kink), da.size)


def ledger_differences(led, want):
    """Names of the ledger's fields outside their allowance (see the module docstring)."""
    *values, n = want
    bad = []
    for field, got, exact in zip(("max_abs", "rms", "flips", "pixels_a", "mean_abs_kink", "mean_abs_off_kink"),
                                 dataclasses.astuple(led), values):
        if field in ("max_abs", "flips", "pixels_a"):
            ok = got == exact
        elif math.isnan(exact):
            ok = math.isnan(got)
        else:
            ok = abs(got - exact) <= (n + 3) * U * exact
        if not ok:
            bad.append(field)
    return bad


SCENES = {"default": Scene(), "sine-1e-9": Scene(height_field="sine", eps=1e-9),
          "beta1.5": Scene(beta=1.5, eps=1e-1, bump="chart"), "rings-alone": Scene(height_field="rings", sphere_b=False, floor=False)}


@pytest.mark.parametrize("gradient", ["central", "footprint"])
@pytest.mark.parametrize("name", sorted(SCENES))
def test_ledger_equals_the_whole_image_computation(name, gradient):
    scene = SCENES[name]
    numeric, symbolic = render(scene, 61, 47, gradient=gradient), render(scene, 61, 47)
    assert ledger_differences(compare(numeric, symbolic), whole_image_ledger(numeric, symbolic)) == []


def test_the_check_rejects_a_ledger_on_the_wrong_band_or_missing_a_pixel():
    scene = Scene(eps=1e-1)
    numeric, symbolic = render(scene, 61, 47, gradient="central"), render(scene, 61, 47)
    led = compare(numeric, symbolic)
    assert not math.isnan(led.mean_abs_kink) and not math.isnan(led.mean_abs_off_kink)
    shifted = whole_image_ledger(numeric, symbolic, kink=np.roll(symbolic.kink, 1, axis=1))
    assert {"mean_abs_kink", "mean_abs_off_kink"} <= set(ledger_differences(led, shifted))
    # One sphere-A pixel fewer (made a floor pixel in the numeric frame).
    j, i = np.argwhere((numeric.chamber == SPHERE_A) & ~symbolic.kink)[0]
    chamber = numeric.chamber.copy()
    chamber[j, i] = 3
    missing = whole_image_ledger(dataclasses.replace(numeric, chamber=chamber), symbolic)
    assert {"flips", "pixels_a", "mean_abs_off_kink", "rms"} <= set(ledger_differences(led, missing))


def test_sweep_census_is_the_ledger_of_its_frames():
    scene = Scene()
    sw = sweep(scene, (1e-1, 1e-4, 1e-10), 61, 47)
    for frame, led in zip(sw.numeric, sw.census):
        assert ledger_differences(led, whole_image_ledger(frame, sw.symbolic)) == []


# --- empty sets: a mean over no pixel is nan, and only then ---------------------------------------

#: name: (scene, render keywords, which means are over an empty set).  "sine" has no
#: crease; at zoom 1e3 the frame is sphere A's pole, inside the band of the factor
#: sin(pi k_v v); sphere B centred at (0, 0, 2) with radius 1.9 hides sphere A.
EMPTY_SETS = {
    "no crease band": (Scene(height_field="sine", eps=1e-1), {}, {"mean_abs_kink"}),
    "all in the band": (Scene(eps=1e-1), dict(zoom=1e3), {"mean_abs_off_kink"}),
    "no sphere A": (Scene(center_b=(0.0, 0.0, 2.0), radius_b=1.9), {}, {"mean_abs_kink", "mean_abs_off_kink"}),
}


@pytest.mark.parametrize("name", sorted(EMPTY_SETS))
def test_a_mean_over_no_pixel_is_nan_and_the_rest_is_the_whole_image_computation(name):
    scene, kw, empty = EMPTY_SETS[name]
    numeric, symbolic = render(scene, 31, 23, gradient="central", **kw), render(scene, 31, 23, **kw)
    on_a = (numeric.chamber == SPHERE_A) & (symbolic.chamber == SPHERE_A)
    sets = {"mean_abs_kink": symbolic.kink & on_a, "mean_abs_off_kink": ~symbolic.kink & on_a}
    assert {k for k, m in sets.items() if not m.any()} == empty      # the scene has the empty sets named
    led = compare(numeric, symbolic)
    assert {k for k in sets if math.isnan(getattr(led, k))} == empty
    assert ledger_differences(led, whole_image_ledger(numeric, symbolic)) == []
    if len(empty) == 2:
        assert (led.pixels_a, led.max_abs, led.rms) == (0, 0.0, 0.0)
    else:
        assert led.pixels_a > 100 and led.max_abs > 0.0


def test_the_empty_set_check_rejects_zero_for_nan_and_nan_for_a_mean():
    scene, kw, _ = EMPTY_SETS["no crease band"]
    numeric, symbolic = render(scene, 31, 23, gradient="central"), render(scene, 31, 23)
    led, want = compare(numeric, symbolic), whole_image_ledger(numeric, symbolic)
    for wrong in (dataclasses.replace(led, mean_abs_kink=0.0),
                  dataclasses.replace(led, mean_abs_off_kink=math.nan)):
        assert ledger_differences(wrong, want) != []


def test_frames_of_different_sizes_are_refused():
    with pytest.raises(ValueError, match="same shape"):
        compare(render(Scene(), 8, 8), render(Scene(), 9, 8))


#: Linear value -> encoded value of the sRGB curve, IEC 61966-2-1 (six decimals).  A gamma-2.2
#: curve (0.5 -> 0.729740), or the breakpoint taken on the encoded side (0.01 -> 0.1292), fails.
SRGB = {0.0: 0.0, 0.001: 0.01292, 0.0031308: 0.040450, 0.01: 0.099853, 0.18: 0.461356,
        0.5: 0.735357, 0.8: 0.906332, 1.0: 1.0, -0.25: 0.0}


def test_to_srgb_is_the_iec_curve():
    from renderer import to_srgb
    np.testing.assert_allclose(to_srgb(np.array(list(SRGB))), list(SRGB.values()), rtol=0, atol=1e-6)


def test_the_simulators_to_srgb_is_the_iec_curve(tmp_path):
    import json
    import subprocess

    from tests.jsnode import node_command, write_modules
    node = node_command("the simulator's sRGB curve runs under node")
    modules = write_modules(tmp_path)
    script = (f"import('{(modules / 'ledger.js').as_uri()}').then(m => "
              f"console.log(JSON.stringify({json.dumps(list(SRGB))}.map(m.to_srgb))))")
    out = subprocess.run([*node, "--input-type=module", "-e", script], capture_output=True, text=True, check=True)
    np.testing.assert_allclose(json.loads(out.stdout), list(SRGB.values()), rtol=0, atol=1e-6)
