"""`renderer.ucurve.fit_model`: the model A eps^2 + B / eps fitted to a U-curve.

Random synthetic curves (A, B and the steps drawn so that the optimum lies among them) are recovered;
two nonzero errors are enough and zero errors are left out; steps that see one side of the optimum only
are refused with the module's ValueError, not a None, a NaN or a warning; arguments are refused by name.
"""

import warnings

import numpy as np
import pytest

from renderer.ucurve import fit_model
from renderer.validate import InputError, InvalidType, InvalidValue

STEPS = np.logspace(-1, -12, 23)


def _curves(count=20, seed=11):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        A, B = 10.0 ** rng.uniform(-3, 6), 10.0 ** rng.uniform(-20, -12)
        star = (B / (2 * A)) ** (1 / 3)
        eps = np.sort(star * 10.0 ** rng.uniform(-3, 3, int(rng.integers(2, 30))))
        if eps.min() <= star <= eps.max():
            yield A, B, eps


@pytest.mark.parametrize("A, B, eps", list(_curves()), ids=lambda x: f"{x:.1e}" if isinstance(x, float) else "")
def test_a_synthetic_curve_is_recovered(A, B, eps):
    got = fit_model(eps, A * eps**2 + B / eps, start=(1.0, 1e-16))
    assert got == pytest.approx((A, B), rel=1e-9, abs=0)


def test_two_nonzero_errors_fit_and_zero_errors_are_left_out():
    eps = np.array([1e-3, 1e-6])
    assert fit_model(eps, 3.0 * eps**2 + 2e-16 / eps) == pytest.approx((3.0, 2e-16), rel=1e-12, abs=0)
    with_zeros = np.array([1e-2, 1e-3, 1e-5, 1e-6])
    error = 3.0 * with_zeros**2 + 2e-16 / with_zeros
    error[[0, 2]] = 0.0                                    # an exact quotient at two of the steps
    assert fit_model(with_zeros, error) == pytest.approx((3.0, 2e-16), rel=1e-12, abs=0)
    with pytest.raises(ValueError, match="^error must have at least 2 nonzero entries to fit a two-term model$"):
        fit_model(with_zeros, np.where(with_zeros == 1e-3, 1e-9, 0.0))


ONE_SIDED = {                      # (steps, error, start): each ends the fit by another of its branches
    "rounding only": (STEPS, 1e-17 / STEPS, (1.0, 1e-16)),                 # an optimum outside the steps
    "truncation only": (STEPS, 61.0 * STEPS**2, (1.0, 1e-16)),
    "optimum below the steps": (STEPS, 61.0 * STEPS**2 + 1e-40 / STEPS, (1.0, 1e-16)),   # no convergence
    "errors far below the start": (STEPS, 1e-300 * STEPS**2, (1.0, 1e-16)),  # log A or log B past 700
    "errors far above the start": (STEPS, 1e290 / STEPS, (1.0, 1e-16)),
    "a term that overflows at once": (np.array([1e5, 1e10]), np.array([1.0, 2.0]), (1e300, 1e-16)),  # A eps^2 = inf
}


@pytest.mark.parametrize("case", ONE_SIDED)
def test_steps_on_one_side_of_the_optimum_are_refused_without_a_warning(case):
    eps, error, start = ONE_SIDED[case]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"^the U-curve model did not fit \(steps on one side of the optimum "
                                             r"only, or no convergence in 100 Gauss-Newton steps\)$"):
            fit_model(eps, error, start=start)


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(eps=[1e-3, 0.0]), InvalidValue, "eps must be > 0, got 0.0 at flat index 1"),
    (dict(error=[1e-3, -1.0]), InvalidValue, "error must be >= 0, got -1.0 at flat index 1"),
    (dict(error=[1e-3, np.nan]), InvalidValue, "error must be "),
    (dict(eps=["a", "b"]), InvalidType, "eps must be real numbers"),
    (dict(error=[1e-3]), InvalidValue, "eps and error must be 1-D arrays of one length, got shapes (2,) and (1,)"),
    (dict(eps=[[1e-3, 1e-6]], error=[[1e-3, 1e-6]]), InvalidValue, "eps and error must be 1-D"),
    (dict(start=(1.0,)), InvalidValue, "start must be two numbers (A, B), got shape (1,)"),
    (dict(start=(1.0, 0.0)), InvalidValue, "start must be > 0, got 0.0 at flat index 1"),
])
def test_arguments_are_refused_by_name(kwargs, error, message):
    args = {"eps": [1e-3, 1e-6], "error": [1e-6, 1e-10], **kwargs}
    with pytest.raises(InputError) as info:
        fit_model(**args)
    assert isinstance(info.value, error) and str(info.value).startswith(message), str(info.value)
