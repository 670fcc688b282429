"""The U-curve reference (renderer/ucurve.py): the split is exact, each part
behaves as its theory says, and the checks reject wrong variants."""

import numpy as np
import sympy as sp
import pytest

from proofs.finite_difference import CLAIMED, eps, f, x
from renderer.ucurve import SEED_FREQUENCIES, UNIT_ROUNDOFF, measure

#: The central quotient's truncation coefficient (h''' eps^2 times it), as the theorem
#: central-difference-truncation proves it: 1/6.
TRUNCATION = float(CLAIMED[1] / (eps**2 * sp.diff(f(x), x, 3)))

def test_split_is_exact(curve):
    # error = |truncation + roundoff| up to the float64 rounding of each part.
    total = np.abs(curve.truncation + curve.roundoff)
    assert np.allclose(total, curve.error, rtol=1e-12, atol=0)


def test_truncation_follows_eps_squared_h3_over_6_at_large_steps(curve):
    big = (curve.eps > 1e-4) & (curve.eps < 1e-2)
    predicted = curve.eps[big] ** 2 * curve.third_derivative * TRUNCATION
    assert np.allclose(curve.truncation[big], predicted, rtol=2e-2, atol=0)
    # A wrong coefficient (1/3) is rejected by the same comparison.
    assert not np.allclose(curve.truncation[big], 2 * predicted, rtol=2e-2, atol=0)


def test_the_plotted_model_is_the_truncation_where_it_dominates_and_least_at_the_model_optimal_step(curve):
    """`UCurve.model` (the error model E, which ``symrender ucurve --plot`` draws): its truncation part is the
    measured truncation at large steps (a wrong 1/6 fails), and its minimum lies at the model-optimal step
    (a wrong roundoff coefficient moves it by the cube root of the error)."""
    big = (curve.eps > 1e-4) & (curve.eps < 1e-2)
    assert np.allclose(curve.model[big], np.abs(curve.truncation[big]), rtol=2e-2, atol=0)
    around = measure(eps=curve.eps_model * np.array([0.75, 0.9, 1.0, 1.1, 1.3]))
    assert np.argmin(around.model) == 2, around.model


def test_roundoff_is_bounded_by_a_few_ulps_over_eps(curve):
    # |roundoff| <= c u |h'| ... bounded by (2 ulp(h) + ulp of the quotient) / (2 eps).
    bound = 4 * UNIT_ROUNDOFF * (1 + abs(curve.derivative)) / curve.eps
    assert np.all(np.abs(curve.roundoff) <= bound)
    assert np.any(np.abs(curve.roundoff) > 1e-3 * bound)   # and it is not identically tiny


def test_at_the_v_border_the_split_divides_by_the_kernels_own_denominator():
    """Near v = 1 the stencil clamps and the kernel divides by v_p - v_m, not 2 eps: the exact
    quotient must use that denominator, or its error is counted as roundoff (half of h_v here)."""
    c = measure(v=0.9995, component="v")
    assert c.reason is None and np.count_nonzero(c.eps > 5e-4) > 10    # steps that clamp
    assert np.all(np.abs(c.roundoff) <= 4 * UNIT_ROUNDOFF * (1 + abs(c.derivative)) / c.eps)


def test_measured_minimum_near_the_model_optimal_step(curve):
    ratio = curve.eps_measured_min / curve.eps_model
    assert 0.05 < ratio < 20
    assert curve.error_at_measured_min < 1e-9
    assert curve.error[curve.eps < 1e-13].min() > 100 * curve.error_at_measured_min


def test_crease_does_not_converge():
    crease = measure("ridges", u=0.125)                   # u = 1/k_u
    assert np.all(crease.error > 9.0)                     # no step gets within 9 of a one-sided slope
    smooth = measure("ridges", u=0.1)
    assert smooth.error_at_measured_min < 1e-8


@pytest.mark.parametrize("kwargs, where", [
    (dict(field="ridges", u=0.125), "sin(pi*k_u*u) changes sign"),
    (dict(field="ridges", u=0.125 + 2**-55), "sin(pi*k_u*u) changes sign"),      # one ulp away: the same
    (dict(field="ridges", u=0.3, v=0.25, component="v"), "sin(pi*k_v*v) changes sign"),
    (dict(field="sine", v=0.0), "pole"), (dict(field="rings", v=1.0, component="v"), "pole"),
])
def test_no_true_derivative_and_no_optimum_where_h_is_not_differentiable(kwargs, where):
    c = measure(eps=[1e-3, 1e-6], **kwargs)
    assert where in c.reason and "not differentiable" in c.reason
    assert np.isnan([c.derivative, c.eps_measured_min, c.eps_model, c.error_at_measured_min]).all()


@pytest.mark.parametrize("component", ["u", "v"])
def test_at_the_charts_edge_1_the_reference_is_the_slope_from_inside(component):
    """u = 1 and v = 1 are creases of the ridges field (k = 8, 4): the one-sided reference the split is
    measured against (the float64 quotient less its roundoff and truncation) is the slope from below, the
    chart's side, as the kernel's own h shows it a step of 1e-7 inside; from beyond 1 it has the other sign."""
    from renderer import pointwise
    at = dict(u=1.0) if component == "u" else dict(v=1.0)
    c = measure("ridges", component=component, eps=[1e-3], **at)
    k = 0 if component == "u" else 1
    fd = float(pointwise.central_gradient("ridges", c.u, c.v, *SEED_FREQUENCIES, 1e-3)[k])
    reference = fd - c.roundoff[0] - c.truncation[0]
    d = 1e-7
    below = dict(u=c.u - d * (k == 0), v=c.v - d * (k == 1))
    inside = (float(pointwise.height("ridges", c.u, c.v, *SEED_FREQUENCIES))
              - float(pointwise.height("ridges", below["u"], below["v"], *SEED_FREQUENCIES))) / d
    assert c.reason is not None and abs(inside) > 1.0
    assert reference == pytest.approx(inside, rel=1e-5, abs=0)


@pytest.mark.parametrize("kwargs", [
    dict(field="ridges", u=0.1), dict(field="ridges", u=0.125, v=0.25),    # both factors vanish
    dict(field="ridges", u=0.125, component="v"), dict(field="sine", u=0.125),
    dict(field="ridges", u=0.125 + 2**-50),                               # 32 ulps off the crease
])
def test_differentiable_points_are_not_flagged(kwargs):
    c = measure(eps=[1e-3], **kwargs)
    assert c.reason is None and np.isfinite(c.derivative)


def test_the_fitted_model_recovers_a_synthetic_curve_and_the_truncation_coefficient(curve):
    from renderer.ucurve import fit_model
    eps = np.logspace(-1, -15, 200)
    A, B = fit_model(eps, 61.0 * eps**2 + 1e-17 / eps)
    assert A == pytest.approx(61.0, rel=1e-9, abs=0) and B == pytest.approx(1e-17, rel=1e-9, abs=0)
    # On the measured curve, A is |h'''| / 6 (the truncation term), not twice or half of it.
    assert curve.fitted_truncation == pytest.approx(abs(curve.third_derivative) * TRUNCATION, rel=0.1, abs=0)
    assert curve.fitted_truncation != pytest.approx(abs(curve.third_derivative) * 2 * TRUNCATION, rel=0.1, abs=0)


def test_the_fitted_optimum_does_not_depend_on_the_grid(curve):
    """Four grids of steps: the fitted optimum moves by less than 20 % between them."""
    grids = [np.logspace(-1, -15, 200), np.logspace(-1, -12, 60), np.logspace(-1, -14, 120),
             np.logspace(-1, -13, 37)]
    curves = [measure(eps=g) for g in grids]
    fitted = [c.eps_fitted for c in curves]
    assert max(fitted) / min(fitted) < 1.2
    # and it sits on the measured curve: within a factor 3 of the model-optimal step
    assert 1 / 3 < curve.eps_fitted / curve.eps_model < 3


def test_an_exact_quotient_has_no_fitted_optimum():
    flat = measure("rings", u=0.3, v=0.31)          # h_u = 0 for rings: every quotient is exact
    assert np.all(flat.error == 0) and np.isnan(flat.eps_fitted)


def test_the_argument_rounding_coefficient_is_the_rounded_abscissae_measured(curve):
    """fl(u +- eps) is off by up to half an ulp of u +- eps; the exact quotient at the rounded
    abscissae less the one at the exact ones (mpmath, 50 digits) is at most |h'| u_round |u| / eps,
    the model's argument term, and comes within a factor 2 of it (half an ulp of 0.31 is 0.81 of
    u_round |0.31|): a coefficient twice or half as large fails one side."""
    import mpmath
    import sympy as sp

    from renderer.formulas import FIELDS, k_u, k_v, u, v
    h = sp.lambdify(u, FIELDS[curve.field].expr.subs({k_u: 8, k_v: 4, v: sp.Rational(47, 100)}), modules="mpmath")
    steps = curve.eps[(curve.eps < 1e-4) & (curve.eps > 1e-14)]
    ratios = []
    with mpmath.workdps(50):
        U = mpmath.mpf(curve.u)
        for e in steps:
            E = mpmath.mpf(float(e))
            rounded = (h(mpmath.mpf(curve.u + float(e))) - h(mpmath.mpf(curve.u - float(e)))) / (2 * E)
            exact = (h(U + E) - h(U - E)) / (2 * E)
            ratios.append(float(abs(rounded - exact) * E) / curve.model_argument)
    assert 0.5 < max(ratios) <= 1.0, max(ratios)


def test_the_model_optimal_step_from_an_independent_derivative(curve):
    """eps* = (3 u_round (|h| + |u h'|) / |h'''|)^(1/3), with h, h' and h''' of the sine field
    (8, 4) at (0.31, 0.47) from mpmath's numerical differentiation of its closed form
    sin(8 pi u) sin(4 pi v); without the argument term (|u h'|) it is 13 % smaller and fails."""
    import mpmath
    with mpmath.workdps(40):
        h = lambda x: mpmath.sin(8 * mpmath.pi * x) * mpmath.sin(4 * mpmath.pi * mpmath.mpf("0.47"))  # noqa: E731
        x = mpmath.mpf(0.31)
        h0, h1, h3 = (float(abs(mpmath.diff(h, x, n))) for n in (0, 1, 3))
    star = (3 * UNIT_ROUNDOFF * (h0 + 0.31 * h1) / h3) ** (1 / 3)
    assert curve.eps_model == pytest.approx(star, rel=1e-9, abs=0)
    assert curve.error_model == pytest.approx(h3 / 6 * star**2 + UNIT_ROUNDOFF * (h0 + 0.31 * h1) / star, rel=1e-9, abs=0)
    assert curve.model == pytest.approx(h3 / 6 * curve.eps**2 + UNIT_ROUNDOFF * (h0 + 0.31 * h1) / curve.eps,
                                        rel=1e-9, abs=0)


def _series_after(extrapolate):
    """The error of ``extrapolate(D_eps, D_eps/2)`` of the central quotient (any h), sympy's series in eps."""
    from proofs.finite_difference import ORDER, QUOTIENT, eps as e, f, x
    central = QUOTIENT.doit()
    return sp.expand(extrapolate(central, central.subs(e, e / 2)).series(e, 0, ORDER).removeO().doit()
                     - f(x).diff(x)), e


def test_richardsons_extrapolation_cancels_the_square_term_and_keeps_the_fourth():
    """`proofs.finite_difference.richardson`, the weights §3 prints and `lab.accuracy.image_beta_order`'s
    reference uses: its error has no eps^2 term and an eps^4 term; the weights (2, -1) of a first-order
    method's extrapolation leave the eps^2 term."""
    from proofs.finite_difference import richardson
    rest, e = _series_after(richardson)
    assert rest.coeff(e, 2) == 0 and rest.coeff(e, 4) != 0, rest
    wrong, e = _series_after(lambda coarse, fine: 2 * fine - coarse)
    assert wrong.coeff(e, 2) != 0
