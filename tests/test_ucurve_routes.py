"""`renderer.ucurve`'s U-curves against routes of their own.

A reader's function (`renderer.ucurve.measure_function`) against mpmath at random functions, points and
steps; and where a field has a crease (`renderer.ucurve.measure` with a ``reason``), the reference the
split is measured against: the derivative at the float64 point itself by ``mpmath.diff`` (the crease in
exact arithmetic lies an ulp or so to one side), at frequencies that do not divide a power of ten.

The route here is written without the module's helpers: f as an mpmath lambda of its own, the abscissae
fl(x + eps) and fl(x - eps) rounded by Python, f', f''' by ``mpmath.diff``.  The truncation is the
exact-arithmetic quotient at those abscissae less f'(x); the error is |truncation + roundoff|; the
roundoff is the float64 quotient (Python's math library here, the numba-compiled f there) less the exact
one, so the two agree to the rounding of f's few evaluations over eps.
"""

import math

import mpmath
import numpy as np
import pytest

import sympy as sp

from renderer import formulas as F
from renderer import univariate as U
from renderer import pointwise
from renderer.ucurve import UNIT_ROUNDOFF, measure, measure_function, non_differentiable

#: (text the reader types, the same function for mpmath, for float64 Python) with parameters a, b.
FAMILIES = [
    ("{a}*sin({b}*x)", lambda a, b: lambda x: a * mpmath.sin(b * x), lambda a, b: lambda x: a * math.sin(b * x)),
    ("exp({a}*x)/({b} + x**2)", lambda a, b: lambda x: mpmath.exp(a * x) / (b + x**2),
     lambda a, b: lambda x: math.exp(a * x) / (b + x**2)),
    ("log({b} + x**2)*cos({a}*x)", lambda a, b: lambda x: mpmath.log(b + x**2) * mpmath.cos(a * x),
     lambda a, b: lambda x: math.log(b + x**2) * math.cos(a * x)),
]


def _cases(count=6, seed=2027):
    rng = np.random.default_rng(seed)
    for i in range(count):
        text, mp, py = FAMILIES[i % len(FAMILIES)]
        a, b = (round(float(y), 3) for y in rng.uniform([0.5, 0.5], [3.0, 2.0]))
        # The text's decimals are the reader's numbers: mpmath reads them as decimals, Python as floats.
        with mpmath.workdps(50):
            a_mp, b_mp = mpmath.mpf(repr(a)), mpmath.mpf(repr(b))
        yield text.format(a=a, b=b), mp(a_mp, b_mp), py(a, b), \
            round(float(rng.uniform(-2.0, 2.0)), 4)


@pytest.mark.parametrize("text, f_mp, f_py, x", list(_cases()), ids=lambda c: c if isinstance(c, str) else "")
def test_the_u_curve_of_a_readers_function_is_mpmaths(text, f_mp, f_py, x):
    steps = [1e-1, 1e-3, 1e-5, 1e-8, 1e-11]
    uc = measure_function(text, x, eps=steps)
    with mpmath.workdps(40):
        X = mpmath.mpf(x)
        true = mpmath.diff(f_mp, X)
        assert uc.derivative == pytest.approx(float(true), rel=1e-14, abs=0)
        assert uc.height == pytest.approx(float(f_mp(X)), rel=1e-14, abs=0)
        assert uc.third_derivative == pytest.approx(float(mpmath.diff(f_mp, X, 3)), rel=1e-12, abs=0)
        for i, e in enumerate(steps):
            plus, minus = x + e, x - e
            exact = (f_mp(mpmath.mpf(plus)) - f_mp(mpmath.mpf(minus))) / (2 * mpmath.mpf(e))
            # The module's mpmath reads f's constants as sympy prints them (17 digits), 1e-17 from both
            # the decimal and the float: the truncation agrees to 1e-9 or to 1e-15 of f'.
            assert uc.truncation[i] == pytest.approx(float(exact - true), rel=1e-9, abs=1e-15 * abs(float(true)))
            assert uc.error[i] == pytest.approx(abs(uc.truncation[i] + uc.roundoff[i]), rel=1e-9, abs=1e-300)
            python = (f_py(plus) - f_py(minus)) / (2 * e)
            slack = 8 * UNIT_ROUNDOFF * max(abs(f_py(plus)), abs(f_py(minus))) / e
            assert abs(uc.roundoff[i] - float(mpmath.mpf(python) - exact)) <= slack, (text, e)
    assert uc.u == x and uc.component == "x" and np.isnan(uc.v) and uc.field == U.univariate(text, "function").name
    # The error model E(eps) = T eps^2 + (C + G) / eps, its minimiser and least value, from mpmath's values.
    T, C, G = abs(uc.third_derivative) / 6, UNIT_ROUNDOFF * abs(uc.height), UNIT_ROUNDOFF * abs(x * uc.derivative)
    star = ((C + G) / (2 * T)) ** (1 / 3)
    assert uc.eps_model == pytest.approx(star, rel=1e-12, abs=0)
    assert uc.error_model == pytest.approx(T * star**2 + (C + G) / star, rel=1e-12, abs=0)
    assert uc.model == pytest.approx(T * uc.eps**2 + (C + G) / uc.eps, rel=1e-12, abs=0)
    assert (uc.model_truncation, uc.model_cancellation, uc.model_argument) == pytest.approx((T, C, G), rel=1e-12, abs=0)
    best = int(np.argmin(uc.error))
    assert (uc.eps_measured_min, uc.error_at_measured_min) == (steps[best], uc.error[best])
    A, B, fitted = uc.fitted_truncation, uc.fitted_roundoff, uc.eps_fitted
    assert fitted == pytest.approx((B / (2 * A)) ** (1 / 3), rel=1e-12, abs=0, nan_ok=True)     # NaN: no U to fit
    assert uc.error_at_fitted == pytest.approx(A * fitted**2 + B / fitted, rel=1e-12, abs=0, nan_ok=True)


def test_the_model_without_truncation_or_without_rounding_has_its_optimum_at_an_end():
    """h_u of rings is 0 (no truncation: E falls as eps grows, eps* infinite, least E 0); sin at 0 has
    h = x h' = 0 (no rounding: eps* = 0, least E 0)."""
    flat = measure("rings", component="u", eps=[1e-3, 1e-6])
    assert flat.reason is None and (flat.model_truncation, flat.eps_model, flat.error_model) == (0.0, np.inf, 0.0)
    exact = measure_function("sin(x)", 0.0, eps=[1e-3, 1e-6])
    assert (exact.model_cancellation + exact.model_argument, exact.eps_model, exact.error_model) == (0.0, 0.0, 0.0)


def test_abscissae_taken_on_one_side_are_caught(monkeypatch):
    """The wrong variant: the exact quotient taken at fl(x + eps) twice (it is 0, and the truncation
    -f'(x))."""
    import renderer.ucurve as ucurve
    real = ucurve._curve
    monkeypatch.setattr(ucurve, "_curve", lambda label, x, steps, quotient, *rest: real(
        label, x, steps, lambda e: (lambda fd, p, m, d: (fd, p, p, d))(*quotient(e)), *rest))
    with pytest.raises(AssertionError):
        test_the_u_curve_of_a_readers_function_is_mpmaths(*next(_cases()))


@pytest.mark.parametrize("k, x, component", [(1 / 0.3, 0.3, "u"), (2.6, 1 / 2.6, "u"), (10 / 3, 0.6, "u"),
                                             (2.6, 1 / 2.6, "v"), (8.0, 0.125, "u"), (4.0, 0.25, "v")])
def test_at_a_crease_the_reference_is_the_derivative_at_the_float_point(k, x, component):
    at = dict(u=x, v=0.47, k_u=k) if component == "u" else dict(u=0.31, v=x, k_v=k)
    c = measure("ridges", component=component, eps=[1e-3], **at)
    assert c.reason is not None and "crease" in c.reason
    assert (c.field, c.component, c.u, c.v) == ("ridges", component, at["u"], at["v"])
    # No true derivative, no model and no optimum: every one of them NaN (a float), the model a NaN per step.
    nan = ("derivative", "third_derivative", "model_truncation", "model_cancellation", "model_argument",
           "eps_model", "error_model", "eps_measured_min", "error_at_measured_min")
    assert all(type(getattr(c, name)) is float and np.isnan(getattr(c, name)) for name in nan)
    assert c.model.shape == c.eps.shape and np.isnan(c.model).all()
    k_u, k_v = at.get("k_u", 8.0), at.get("k_v", 4.0)
    h = sp.lambdify((F.u, F.v), F.FIELDS["ridges"].expr.subs({F.k_u: sp.Rational(k_u), F.k_v: sp.Rational(k_v)}),
                    modules="mpmath")
    with mpmath.workdps(60):
        U, V = mpmath.mpf(at["u"]), mpmath.mpf(at["v"])
        # On the crease exactly (8 * 0.125 = 1), the slope from above, as the class says.
        side = mpmath.mpf(10) ** -45 if k * x == 1.0 and float(mpmath.mpf(k) * mpmath.mpf(x)) == 1.0 else 0
        if component == "u":
            slope = mpmath.diff(lambda t: h(t, V), U + side)
        else:
            slope = mpmath.diff(lambda t: h(U, t), V + side)
    fd = float(pointwise.central_gradient("ridges", at["u"], at["v"], k_u, k_v, 1e-3)[component == "v"])
    assert fd - c.roundoff[0] - c.truncation[0] == pytest.approx(float(slope), rel=1e-9, abs=0)


def test_a_crease_is_a_sign_change_within_one_ulp_of_any_abs_of_the_field():
    """One ulp from the crease counts as on it, two do not; a field with two Abs is read at either
    one's crease; a crease of tiny slope is still a crease."""
    at = dict(v=0.47, k_u=8.0, k_v=4.0)
    assert non_differentiable("ridges", 0.125 + 2**-55, component="u", **at) is not None
    assert non_differentiable("ridges", 0.125 + 2**-54, component="u", **at) is None
    two = sp.Abs(sp.sin(sp.pi * F.k_u * F.u)) + sp.Abs(sp.sin(sp.pi * F.k_v * F.v))
    assert "where sin(pi*k_u*u) changes sign" in non_differentiable(two, 0.125, 0.3, "u", 8.0, 4.0)
    assert "where sin(pi*k_v*v) changes sign" in non_differentiable(two, 0.3, 0.25, "v", 8.0, 4.0)
    assert non_differentiable(two, 0.3, 0.3, "v", 8.0, 4.0) is None
    tiny = sp.Abs((F.u - sp.Rational(1, 2)) / 10**20, evaluate=False) + F.v
    assert "changes sign" in non_differentiable(tiny, 0.5, 0.3, "u", 8.0, 4.0)



def test_the_curves_draw_the_model_the_optimal_step_theorem_proves(monkeypatch):
    """One error model: the optimal-step theorem is about `renderer.formulas.ERROR_MODEL` and `EPS_STAR`
    (the same objects), and a U-curve's model, its coefficients and its optimum are read from them.
    Planted in the records one at a time: the truncation over 2, not 6, plus a term eps (the curve's
    truncation coefficient triples, its model follows term for term, its optimum stays EPS_STAR's), and
    the optimum's 3 dropped (the optimum shrinks by 3^(1/3), nothing else moves).  The same plants in
    renderer/formulas.py leave the theorem refuted (the mutation audit's model-coefficient)."""
    import renderer.ucurve as ucurve
    from proofs import finite_difference as fd
    assert fd.ERROR_MODEL.args[0] is F.ERROR_MODEL and fd.EPS_STAR.args[0] is F.EPS_STAR

    def curve(**planted):
        with monkeypatch.context() as m:
            for name, value in planted.items():
                m.setattr(F, name, value)
            ucurve._error_model.cache_clear()
            try:
                return measure_function("exp(x)*sin(3*x)", 0.4, eps=[1e-3, 1e-6])
            finally:
                ucurve._error_model.cache_clear()
    right = curve()
    model = curve(ERROR_MODEL=F.ERROR_MODEL.xreplace({sp.Rational(1, 6): sp.Rational(1, 2)}) + F.eps)
    assert model.model_truncation == pytest.approx(3 * right.model_truncation, rel=1e-15, abs=0)
    assert (model.model_cancellation, model.model_argument, model.eps_model) == \
        (right.model_cancellation, right.model_argument, right.eps_model)
    assert model.model == pytest.approx(right.model + 2 * right.model_truncation * right.eps**2 + right.eps, rel=1e-14, abs=0)
    star = curve(EPS_STAR=F.EPS_STAR.xreplace({3: 1}))
    assert star.eps_model == pytest.approx(right.eps_model / 3 ** (1 / 3), rel=1e-14, abs=0)
    assert (star.model_truncation, star.model.tolist()) == (right.model_truncation, right.model.tolist())
