"""The arguments of `renderer.ucurve.measure` and `renderer.ucurve.measure_function`: each is wired
to its validator (`renderer.validate`, whose kinds tests/test_validate.py tests once each), and
refused by name.

One refusal per parameter, matched on the parameter's name and the essential phrase only (the
reader's function: each of its own refusals whole); the accepted values at each limit are measured
(a step each).
"""

from fractions import Fraction

import numpy as np
import pytest

from renderer.pointwise import MIN_STEP
from renderer.ucurve import DEFAULT_STEPS, MAX_FUNCTION_STEP, measure, measure_function
from renderer.validate import InputError


@pytest.mark.parametrize("kwargs, error, name, phrase", [
    (dict(field="u + w"), ValueError, "field", "'w' is not one of its names"),
    (dict(component="w"), ValueError, "component", "must be one of"),
    (dict(u=1.5), ValueError, "u", "must be in [0, 1]"),
    (dict(v=True), TypeError, "v", "must be a real number"),
    (dict(k_u=0.0), ValueError, "k_u", "must be in (0, 1000]"),
    (dict(k_v=np.True_), TypeError, "k_v", "must be a real number"),
    (dict(eps=[1e-3, 1.0]), ValueError, "eps", "must be in [1e-300, 1)"),
    (dict(eps={1e-3}), TypeError, "eps", "must be ordered steps"),
])
def test_each_argument_is_refused_by_name(kwargs, error, name, phrase):
    with pytest.raises(InputError) as info:
        measure(**{"eps": [1e-3], **kwargs})
    assert isinstance(info.value, error)
    assert str(info.value).startswith(f"{name} ") and phrase in str(info.value)
    if name in ("u", "v", "k_u", "k_v"):           # refused by measure itself, as a scalar, not by a callee
        assert "flat index" not in str(info.value), str(info.value)


def test_values_at_the_limits_and_numpy_scalars_are_measured():
    for kwargs in (dict(u=0.0), dict(u=1.0), dict(v=0), dict(v=np.float32(0.5)), dict(u=np.array(0.25)),
                   dict(u=Fraction(1, 3)), dict(k_u=1e3), dict(k_v=5e-324), dict(k_u=np.int64(3)),
                   dict(eps=[MIN_STEP, np.nextafter(1.0, 0.0)]), dict(eps=np.float32(1e-3))):
        uc = measure(**{"eps": [1e-3], **kwargs})
        assert np.all(np.isfinite(uc.error)) and uc.eps.dtype == np.float64, kwargs
        for name in ("u", "v"):
            if name in kwargs:
                assert getattr(uc, name) == float(kwargs[name]) and type(getattr(uc, name)) is float
    uc = measure("rings", 0.2, 0.3, "v", eps=[1e-3])
    assert (uc.field, uc.u, uc.v, uc.component) == ("rings", 0.2, 0.3, "v")


@pytest.mark.parametrize("args, kwargs, error, message", [
    (("x + y", 0.5), {}, ValueError, "function must be an expression in x (with pi"),
    (("sin(x)", True), {}, TypeError, "x must be a real number"),
    (("sin(x)", float("inf")), {}, ValueError, "x must be finite, got inf"),
    (("sin(x)", 0.5), dict(eps=[1e-3, 2e3]), ValueError, "eps must be in [1e-300, 1000]"),
    (("sin(x)", 0.5), dict(eps=[1e-301]), ValueError, "eps must be in [1e-300, 1000]"),
    (("sqrt(x)", -1.0), {}, ValueError, "function sqrt(x) must be defined and differentiable at x = -1.0"),
    (("1/x", 0.0), {}, ValueError, "function 1/x must be defined and differentiable at x = 0.0"),   # mpmath raises
    (("abs(x)", 0.0), {}, ValueError, "function Abs(x) is not differentiable at x = 0.0: it has a crease"),
    (("exp(x)", 800.0), {}, ValueError, "x must be a point where function exp(x) is a finite float64"),
    (("log(x)", 0.5), dict(eps=[1e-3, 0.6]), ValueError, "eps must keep f finite at x +- eps; f(0.5 +- 0.6) is not (step 1)"),
])
def test_measure_functions_arguments_are_refused_by_name(args, kwargs, error, message):
    with pytest.raises(InputError) as info:
        measure_function(*args, **kwargs)
    assert isinstance(info.value, error) and str(info.value).startswith(message), str(info.value)


def test_measure_function_takes_its_steps_or_the_default_ones():
    assert measure_function("sin(x)", 0.5, eps=[MAX_FUNCTION_STEP, 1e-3]).eps.tolist() == [MAX_FUNCTION_STEP, 1e-3]
    assert np.array_equal(measure_function("sin(x)", 0.5).eps, DEFAULT_STEPS)
