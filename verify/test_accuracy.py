"""Image-wide accuracy against mpmath (lab/accuracy.py); that the measurement catches a wrong pipeline is tested in tests/test_accuracy_teeth.py."""

import pytest

from lab.accuracy import gradient_accuracy, image_beta_order, normal_beta_derivative_residual
from renderer.formulas import FIELDS
from renderer.ucurve import UNIT_ROUNDOFF


@pytest.mark.parametrize("field", list(FIELDS))
def test_exact_gradient_is_float64_accurate_and_central_is_not(field):
    results = gradient_accuracy(field, count=2000)
    exact, central = results[0], {r.method: r for r in results[1:]}
    assert exact.pixels >= 1990                       # >= 2000 sampled, minus crease pixels
    assert exact.max_ulps < 64                        # a handful of trig calls
    best = min(central.values(), key=lambda r: r.max_abs)
    assert best.max_abs > 100 * exact.max_abs         # no step comes near the exact gradient


def test_normal_beta_derivative_float64_against_50_digits():
    assert normal_beta_derivative_residual(trials=2000) < 1e-13


def test_image_beta_derivative_is_second_order_in_the_median():
    result = image_beta_order()
    assert 1.8 < result["median_slope"] < 2.3
    # The RMS is dominated by pixels where max(0, .) or the clip switches: not second order.
    assert result["rms_slope"] < 1.5


def test_each_fields_optimum_at_its_stated_point():
    """`optima`: every field's entry is its curve's (the same `measure` at the same point and
    steps), at the point and component its record names (`HeightField.optimum_at`: rings in v); a
    field with creases is measured farther from every crease the curve's stencil can reach (along its
    component's coordinate) than the curve's largest step; the fitted
    optimal step lies below the model-optimal one (measured rounding errors are below their bound) and
    its measured error within a factor 3 of the fitted model's."""
    from lab.accuracy import OPTIMUM_POINTS, crease_distance, optima
    from renderer.ucurve import DEFAULT_STEPS, measure
    opt = optima()
    assert set(opt) == set(OPTIMUM_POINTS) == set(FIELDS)
    for field, (u, v, component) in OPTIMUM_POINTS.items():
        o = opt[field]
        assert (o["u"], o["v"], o["component"]) == (u, v, component) == FIELDS[field].optimum_at, field
        if FIELDS[field].crease_factors:
            assert o["largest_step"] < o["crease_distance"], field
            assert o["crease_distance"] == pytest.approx(      # along the component's coordinate: its stencil's
                float(crease_distance(u, v, o["k_u"], o["k_v"], field, along=component))), field
        steps = DEFAULT_STEPS[DEFAULT_STEPS <= o["largest_step"]]
        c = measure(field, u, v, component, eps=steps)
        assert (o["steps"], o["eps_model"], o["eps_fitted"]) == (steps.size, c.eps_model, c.eps_fitted), field
        assert o["fitted_over_model"] == o["eps_fitted"] / o["eps_model"] < 1, field
        ratio = o["measured_at_fitted"] / o["error_at_fitted"]
        assert 1 / 3 < ratio < 3, (
            f"{field}: at its fitted step the measured error is {ratio:.3g} times the model's (accepted: within "
            f"a factor 3) at optimum=({u}, {v}, {component!r}); register the field with another optimum= point "
            f"(lab.accuracy.measure_optimum({field!r}, u, v, component) measures any point first)")
        assert o["h"] + o["x_h1"] == pytest.approx(c.model_argument / o["argument_share"] / UNIT_ROUNDOFF), field
        # The model's two coefficients from their parts (abs=0: approx's default absolute 1e-12 would pass any
        # rounding coefficient, about 1e-16).
        assert o["model_truncation"] == pytest.approx(o["h3"] / 6, rel=1e-12, abs=0), field
        assert o["model_roundoff"] == pytest.approx(UNIT_ROUNDOFF * (o["h"] + o["x_h1"]), rel=1e-12, abs=0), field


def test_the_crease_share_is_the_census_straddling_count():
    """Two routes to the pixels whose stencil straddles a crease: `crease_share` (share of
    sphere-A pixels) times its pixel count is the census's count at each step."""
    from lab.accuracy import crease_share
    from lab.claims import census
    share, c = crease_share(), census()
    assert share["steps"] == c["steps"]
    assert [round(s * share["pixels"]) for s in share["share"]] == c["straddling"]
    assert share["share"][-1] < share["share"][0]
