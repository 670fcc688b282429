"""The arguments of `renderer.ucurve.measure` and `renderer.ucurve.measure_function`: each is wired
to its validator (`renderer.validate`, whose kinds tests/test_validate.py tests once each), and
refused by name.

One refusal per parameter, matched on the parameter's name and the essential phrase only (the
reader's function: each of its own refusals whole); the accepted values at each limit are measured
(a step each).
"""

import re
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from renderer.pointwise import MIN_STEP
from renderer.ucurve import DEFAULT_STEPS, MAX_FUNCTION_STEP, measure, measure_function
from renderer.validate import InputError

from .expressions import CHART, fields_at_points, functions_at_points, singular_cases


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
    (("exp(x)", 800.0), {}, ValueError, "function exp(x) must be defined and differentiable at x = 800.0"),
    (("exp(x)/exp(x - 1)", 710.0), {}, ValueError,
     "x must be a point where function exp(x)*exp(1 - x) is a finite float64"),
    (("log(x)", 0.5), dict(eps=[1e-3, 0.6]), ValueError,
     "eps must keep log(x) finite and real at the abscissae of its quotient; at the step 0.6 (step 1) it is not, "
     "at -0.09999999999999998 or 1.1"),
])
def test_measure_functions_arguments_are_refused_by_name(args, kwargs, error, message):
    with pytest.raises(InputError) as info:
        measure_function(*args, **kwargs)
    assert isinstance(info.value, error) and str(info.value).startswith(message), str(info.value)


@pytest.mark.parametrize("call, said", [
    (lambda: measure_function("1/(x - 2)", 2.0), "function 1/(x - 2) must be defined and differentiable at x = 2.0: there "
                                                  "f is infinite"),
    (lambda: measure_function("sqrt(x - 3)", 1.0), "there f is not real ((0.0 + 1.41j): a root or logarithm of a "
                                                   "negative number, say)"),
    (lambda: measure_function("exp(x)", 710.0), "there f is 2.23e+308, beyond float64's largest number"),
    (lambda: measure_function("sqrt(x)", 0.0), "there f' is infinite"),                  # f = 0, f' infinite
    (lambda: measure_function("x**2.5", 0.0), "there f''' is infinite"),
    (lambda: measure("log(u - 0.2)", 0.2), "field log(u - 0.2) must be defined and differentiable at (u, v) = (0.2, "
                                           "0.47): there h is infinite"),
    (lambda: measure("u*sqrt(v - 0.47)", 0.3, 0.47, component="v"), "there h_v is infinite"),
    (lambda: measure("tan(pi*u)", 0.5, component="v"), "there it has no value on the line u = 0.5"),
])
def test_a_point_without_a_value_is_refused_saying_which_of_f_and_its_derivatives_fails_and_how(call, said):
    """A pole, a complex value, a value beyond float64 and an infinite derivative: each named, with the
    function or derivative that fails, h's derivative by its component."""
    with pytest.raises(InputError) as info:
        call()
    assert said in str(info.value) and "\n" not in str(info.value), str(info.value)


def test_measure_function_takes_its_steps_or_the_default_ones():
    assert measure_function("sin(x)", 0.5, eps=[MAX_FUNCTION_STEP, 1e-3]).eps.tolist() == [MAX_FUNCTION_STEP, 1e-3]
    assert np.array_equal(measure_function("sin(x)", 0.5).eps, DEFAULT_STEPS)


#: Steps from wide (past a nearby singularity) to below the rounding of x.
STEPS = (0.5, 1e-4, 1e-9, 1e-14)


def _u_curve_or_refusal(call, names):
    """``call()``'s U-curve, of finite numbers, or one `InputError` whose message starts with one of
    ``names`` (the parameter it refuses)."""
    try:
        uc = call()
    except InputError as exc:
        assert re.match(rf"^({'|'.join(names)})\b", str(exc)) and "\n" not in str(exc), str(exc)
        return None
    assert all(np.isfinite(a).all() for a in (uc.error, uc.truncation, uc.roundoff)) and np.isfinite(uc.height)
    assert uc.reason is not None or np.isfinite(uc.derivative), uc
    return uc


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=functions_at_points())
def test_any_function_at_any_point_is_a_u_curve_or_one_input_error(case):
    """Whatever f a reader types and wherever: a U-curve of finite numbers, or one refusal naming
    ``function``, ``x`` or ``eps``; never an exception from inside mpmath or sympy (a pole, an
    overflow, a complex value, a derivative sympy leaves unevaluated)."""
    text, x = case
    _u_curve_or_refusal(lambda: measure_function(text, x, eps=STEPS), ("function", "x", "eps"))


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=fields_at_points())
def test_any_field_at_any_chart_point_is_a_u_curve_or_one_input_error(case):
    """The same for a reader's height field at a chart point, refusals naming ``field`` or ``eps``:
    at a pole of the field, on a line where it has no value (tan(pi u) at u = 1/2), past a branch
    point."""
    text, u, v, component = case
    _u_curve_or_refusal(lambda: measure(text, u, v, component, eps=STEPS), ("field", "eps"))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=singular_cases("x", -10.0, 10.0))
def test_a_function_on_its_singularity_is_refused_never_measured(case):
    """f at a pole, a branch point, an essential singularity or out of its domain: refused, naming
    ``function``, also where float64 and a 50-digit pi both give a finite value (1/sin(pi x) at 1)."""
    text, x = case
    with pytest.raises(InputError, match=r"^(function|x)\b"):
        measure_function(text, x, eps=STEPS)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=singular_cases("u", 0.0, 1.0), v=st.sampled_from(CHART))
def test_a_field_on_its_singularity_is_refused_never_measured(case, v):
    """The same for a field of u at a chart point on its singularity (tan(pi u) at u = 1/2): refused,
    naming ``field`` or ``eps`` (a step past a branch point), or measured with the reason it has no
    derivative there (on the seam, where u**1.5 meets 1)."""
    text, u = case
    uc = _u_curve_or_refusal(lambda: measure(text, u, v, "u", eps=STEPS), ("field", "eps"))
    assert uc is None or uc.reason is not None, uc


@pytest.mark.parametrize("call, name", [
    (lambda: measure_function("exp(exp(x))", 1e300), "function"),      # mpmath overflows
    (lambda: measure_function("tanh(x)", 1.0, eps=[1e-3, 100.0]), None),  # measured
    (lambda: measure_function("x**2.5", 0.0), "function"),              # f, f' are 0; the model's f''' infinite
    (lambda: measure("1/(u - 0.31)"), "field"),                          # a pole at the seed's point
    (lambda: measure("abs(log(u + 1))"), None),          # measured: sympy's h''' holds d/du sign(log(u + 1))
    (lambda: measure("tan(pi*u)", 0.5, component="v"), "field"),         # no value on the line u = 1/2
    (lambda: measure("log(v)", 0.5, 0.0, component="v"), "field"),      # log 0 at the pole
    (lambda: measure("sqrt(u - 0.3)", 0.31, eps=[1e-3, 0.02]), "eps"),  # u - eps past the branch point
    (lambda: measure("u*(3*k_u + 1/k_u)**(3**k_u)"), "field"),          # 9,077 digits at k_u = 8
    (lambda: measure("(3*k_u)**(k_u**k_u)"), "field"),                   # 23 million: refused before computing
    (lambda: measure_function("9**9**9*x", 0.5), "function"),            # hours to parse: refused unevaluated
    (lambda: measure_function("sin(" * 30 + "x" + ")" * 30, 0.5), "function"),  # f'' of 15,781 nodes: refused
    (lambda: measure("sin(" * 99 + "u" + ")" * 99), "field"),            # h' of 5,050 nodes: refused before h''
    (lambda: measure_function("1/sin(pi*x)", 1.0), "function"),          # a pole only exactly: 1e102 at 50 digits
    (lambda: measure("abs(log(u - 0.31))"), "field"),                   # the crease check meets the pole
    # float64 rounds u_m**2 up to the constant (h(u_m) = 0); exactly it is below it (h imaginary).
    (lambda: measure("sqrt(u**2 - 0.1417678433433451)", 0.3774972702218265, eps=[2.0**-10]), "eps"),
])
def test_a_singular_point_is_one_input_error_naming_what_is_wrong(call, name):
    """One case of each kind the random tests above draw, fixed: the refusal names the argument."""
    if name is None:
        assert _u_curve_or_refusal(call, ()) is not None
    else:
        with pytest.raises(InputError, match=rf"^{name}\b"):
            call()
