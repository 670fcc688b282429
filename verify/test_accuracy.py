"""Image-wide accuracy against mpmath (lab/accuracy.py); that the measurement catches a wrong pipeline is tested in tests/test_accuracy_teeth.py."""

import pytest

from lab.accuracy import gradient_accuracy, image_beta_order, normal_beta_derivative_residual


@pytest.mark.parametrize("field", ["sine", "ridges", "rings"])
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
