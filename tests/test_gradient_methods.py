"""The gradient methods of lab/gradient_methods.py: their orders against sympy's derivative
evaluated by mpmath, the complex step's analyticity premise, the work per pixel counted from the
formulas, AD against the exact gradient and through one compiler, and any field a reader types
through every method.  Their measurement is tests/test_gradient_benchmark.py's.  Each check is
shown to reject a wrong variant.
"""

from __future__ import annotations

import inspect
import re
import time

import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from lab import gradient_benchmark as gb
from lab import gradient_methods as gm
from renderer import DRAFT_SCENE, pointwise
from renderer import formulas as F
from renderer import generated as G
from renderer.validate import InputError, InvalidValue

from .expressions import expressions, fields_at_points

KU, KV = DRAFT_SCENE.k_u, DRAFT_SCENE.k_v
#: float64 spacing at the gradient's scale (`formulas.gradient_scale`: 8 pi here, as in lab/accuracy.py).
SPACING = float(np.spacing(F.gradient_scale(KU, KV)))
#: Over many pixels a float64 evaluation of the gradient is off by up to ~40 spacings: the
#: phase pi k u (up to 8 pi) is rounded, and the rounding is multiplied by the slope, up to
#: 8 pi.  verify/test_accuracy.py allows 64 spacings for the exact gradient; so do we.
FLOAT64_EVAL = 64 * SPACING


#: The sine field's (h_u, h_v), its record's gradient, as an mpmath function.
_SINE_GRADIENT_MP = sp.lambdify((F.u, F.v, F.k_u, F.k_v), F.FIELDS["sine"].gradient, "mpmath")


def sine_gradient_mp(u, v, ku=KU, kv=KV):
    """(h_u, h_v) of the sine field: sympy's derivative (`HeightField.gradient`,
    checked against seed §3's closed form in tests/test_codegen.py) evaluated
    by mpmath at 40 digits at the float64 point: no float64 rounding of any
    method under test."""
    with mpmath.workdps(40):
        return tuple(+x for x in _SINE_GRADIENT_MP(*(mpmath.mpf(float(a)) for a in (u, v, ku, kv))))


def abs_errors(grad, ref):
    """|float64 - reference| of both components, computed at 40 digits."""
    with mpmath.workdps(40):
        return np.array([float(abs(mpmath.mpf(float(np.ravel(g)[0])) - r)) for g, r in zip(grad, ref)])


U0, V0 = np.array([0.31]), np.array([0.47])          # the draft's smooth point (Cell 2)
REF0 = sine_gradient_mp(U0[0], V0[0])


def fitted_order(method, steps):
    """Slope of log(error) against log(eps), per component."""
    errs = np.array([abs_errors(method(e), REF0) for e in steps])
    return np.polyfit(np.log(steps), np.log(errs), 1)[0]


CENTRAL = lambda e: pointwise.central_gradient("sine", U0, V0, KU, KV, e)          # noqa: E731
FORWARD = lambda e: gm.forward_gradient("sine", U0, V0, KU, KV, e)        # noqa: E731
COMPLEX = lambda e: gm.complex_step_gradient("sine", U0, V0, KU, KV, e)   # noqa: E731
STEPS = (1e-2, 1e-3, 1e-4)            # truncation-dominated for all three at this point


def second_order(slopes):
    return bool(np.all(np.abs(slopes - 2.0) < 0.1))


def first_order(slopes):
    return bool(np.all(np.abs(slopes - 1.0) < 0.1))


# --- orders against mpmath ---------------------------------------------------------------

def test_central_difference_is_second_order():
    assert second_order(fitted_order(CENTRAL, STEPS))


def test_forward_difference_is_first_order_and_fails_the_second_order_check():
    slopes = fitted_order(FORWARD, STEPS)
    assert first_order(slopes)
    assert not second_order(slopes)       # the criterion above rejects a one-sided quotient


def test_complex_step_is_second_order_then_at_machine_precision():
    assert second_order(fitted_order(COMPLEX, STEPS))
    # No subtraction: at eps = 1e-20 the truncation term (~1e-40 relative) is gone and
    # what is left is the rounding of a few products, within 4 spacings of 8 pi.
    assert np.all(abs_errors(COMPLEX(1e-20), REF0) <= 4 * SPACING)
    # A difference quotient at the same step sees u + eps == u: it returns 0, wrong by
    # the whole derivative (|h_u| = 0.58, |h_v| = 11.7 here).
    assert np.all(abs_errors(CENTRAL(1e-20), REF0) > 0.5)


def test_exact_and_richardson_against_mpmath():
    assert np.all(abs_errors(pointwise.exact_gradient("sine", U0, V0, KU, KV), REF0) <= 4 * SPACING)
    err = abs_errors(gm.richardson_gradient("sine", U0, V0, KU, KV), REF0)
    # Order-8 stencils, stopped at rtol ~ 1.5e-8.  How much smaller than 1e-11
    # the error comes out is the last bits of the library's sine and of
    # SciPy's extrapolation on this CPU, so no lower bound is asserted.
    assert np.all(err < 1e-11)


def _richardson_table(f, x, step, rounds):
    """Richardson's extrapolation, in mpmath at 40 digits, of the central differences of ``f`` at
    ``step``, ``step``/2, ..., ``step``/2^rounds: ``rounds`` times (4^k D(s/2) - D(s)) / (4^k - 1)."""
    with mpmath.workdps(40):
        x = mpmath.mpf(x)
        table = [(f(x + s) - f(x - s)) / (2 * s) for s in (mpmath.mpf(step) / 2**k for k in range(rounds + 1))]
        for k in range(1, rounds + 1):
            table = [(4**k * b - a) / (4**k - 1) for a, b in zip(table, table[1:])]
        return table[0]


@settings(max_examples=40, deadline=None)
@given(a=st.floats(1.5, 4.0), b=st.floats(-1.0, 1.0), x=st.floats(-1.0, 1.0), step=st.floats(0.4, 0.8))
def test_scipys_first_estimate_is_richardsons_extrapolation_over_halved_steps(a, b, x, step):
    """§3: SciPy's differentiator, at the settings `RICHARDSON` gives it, starts from
    `RICHARDSON_ROUNDS` rounds of Richardson's extrapolation of central differences at the step
    halved each time.  At
    steps this large the truncation error dwarfs float64's rounding, so one round fewer or more
    gives another number: the count of rounds is checked, not only the method."""
    from scipy.differentiate import derivative

    def f(t):
        return np.sin(a * t) * np.exp(b * t)

    def f_mp(t):
        return mpmath.sin(a * t) * mpmath.exp(b * t)

    settings_ = {**gm.RICHARDSON, "initial_step": step, "maxiter": 1, "tolerances": dict(atol=0.0, rtol=0.0)}
    rounds = gm.RICHARDSON_ROUNDS
    first = float(derivative(f, x, **settings_).df)
    assert first == pytest.approx(float(_richardson_table(f_mp, x, step, rounds)), rel=0, abs=1e-13)
    # exp(a t), whose derivatives never vanish, at steps 2.5 times as long: one round fewer or
    # more gives another number (by 6e-9 or more here).
    first = float(derivative(lambda t: np.exp(a * t), x, **{**settings_, "initial_step": 2.5 * step}).df)
    for wrong in (rounds - 1, rounds + 1):
        assert abs(first - float(_richardson_table(lambda t: mpmath.exp(a * t), x, 2.5 * step, wrong))) > 1e-10


def test_reference_gradient_is_the_mpmath_value_as_a_double_double():
    hi, lo = gm.reference_gradient("sine", U0, V0, KU, KV)
    with mpmath.workdps(40):
        for c in range(2):
            assert hi[c, 0] == float(REF0[c])                      # rounded to nearest
            residual = mpmath.mpf(hi[c, 0]) + mpmath.mpf(lo[c, 0]) - REF0[c]
            assert abs(residual) < mpmath.mpf(10) ** -30           # hi + lo carries ~32 digits
    # A wrong reference (the generated float64 gradient in place of mpmath) has lo = 0.
    assert np.any(lo != 0.0)


def test_forward_difference_steps_backwards_at_the_top_of_the_chart():
    u, v = np.array([0.31]), np.array([1.0 - 1e-5])
    hu, hv = gm.forward_gradient("sine", u, v, KU, KV, 1e-3)
    ref = sine_gradient_mp(u[0], v[0])
    # A step past v = 1 would still be O(eps) here (h is defined beyond the chart);
    # check the rule itself: the quotient equals the backward one.
    h0 = pointwise.height("sine", u, v, KU, KV)
    back = (pointwise.height("sine", u, v - 1e-3, KU, KV) - h0) / -1e-3
    assert hv[0] == back[0]
    assert abs(hv[0] - float(ref[1])) < 10 * 1e-3 * (np.pi * KV) ** 2       # |h_vv| eps / 2 bound


# --- the complex step's premise ------------------------------------------------------------

def applying(field):
    return [m.name for m in gm.METHODS if m.applies(F.field(field))]


def test_the_complex_step_applies_where_the_field_is_analytic_and_its_continuation_where_it_has_an_abs():
    for name, field in F.FIELDS.items():
        cs = applying(name)
        assert ("complex step" in cs) == field.analytic and ("complex step, |z| continued" in cs) != field.analytic
    assert applying("sin(pi*k_u*u) + Abs(u - 1/2)") == [m.name for m in gm.METHODS if m.name != "complex step"]


def test_complex_step_on_ridges_is_wrong_near_a_crease_so_the_flag_matters():
    # Just off the crease u = 1/k_u (float64 1/8 exactly), where the derivative exists.
    u, v = np.array([1.0 / KU + 1e-6]), np.array([0.47])
    hi, lo = gm.reference_gradient("ridges", u, v, KU, KV)
    true_hu = hi[0, 0]
    assert abs(true_hu) > 1.0                          # a steep slope, not a flat spot
    hu_plain, _ = gm.complex_step_gradient("ridges", u, v, KU, KV, 1e-20)
    # Im |f(u + i eps)| = 0: the plain complex step returns 0, wrong by the whole slope.
    assert hu_plain[0] == 0.0
    assert abs(hu_plain[0] - true_hu) > 1.0
    # Had the record called ridges analytic, this result would be measured as a method's; it is not.
    assert "complex step" not in applying("ridges") and "complex step" in applying("sine")
    # With |z| continued as z sign(Re z) the complex step is right off the crease.
    hu_cont, _ = gm.complex_step_gradient("ridges", u, v, KU, KV, 1e-20, continued=True)
    assert abs((hu_cont[0] - hi[0, 0]) - lo[0, 0]) <= 4 * SPACING


# --- the work per pixel ------------------------------------------------------------------

def generated_trig_calls(kind, field):
    """math.sin and math.cos calls in the function ``kind`` (height, exact, central) of ``field`` in
    renderer/generated.py: the code numba compiles, read as text."""
    source = inspect.getsource(G.FIELDS[field][list(F.FIELD_FUNCTIONS).index(kind)])
    return len(re.findall(r"math\.(?:sin|cos)\(", source))


@pytest.mark.parametrize("field", F.BUILTIN)
def test_trig_count_is_the_generated_codes(field):
    # Two routes: sympy's cse over the formulas, and the text numba compiles.
    record = F.FIELDS[field]
    assert gm.evaluations(field, "central").trig == generated_trig_calls("central", field)
    assert gm.evaluations(field, "exact").trig == generated_trig_calls("exact", field)
    assert gm.height_work(field).trig == generated_trig_calls("height", field)
    assert gm.evaluations(field, "forward").trig == 3 * gm.trig_calls((record.expr,))


def test_trig_count_rejects_counting_without_the_shared_factors():
    # Counting the stencil's four values of h as written (no cse) gives 8 sines for the
    # sine field; the generated code shares sin(pi k_v v) and sin(pi k_u u) and calls 6.
    as_written = sum(isinstance(n, sp.sin) for c in F.FIELDS["sine"].central for n in sp.preorder_traversal(c))
    assert as_written == 8 != generated_trig_calls("central", "sine") == 6


def test_work_per_pixel_of_the_methods_without_a_formula_to_count():
    assert gm.evaluations("sine", "complex step") == gm.Evaluations(h_complex=2)
    assert gm.evaluations("sine", "forward").h == 3 and gm.evaluations("sine", "exact").gradient == 1
    assert gm.evaluations("sine", "richardson", {"h_per_pixel": 22.5}) == gm.Evaluations(h=22.5, trig=45)
    for info in (None, {}, {"iterations": 3.0}):
        with pytest.raises(InvalidValue, match="^info must hold 'h_per_pixel' for richardson"):
            gm.evaluations("sine", "richardson", info)
    with pytest.raises(ValueError, match="^method must be one of .*'sideways'"):
        gm.evaluations("sine", "sideways")


def test_stencil_values_are_the_points_the_stencil_reads():
    # Two values of h per chart variable the field depends on: sine and ridges 4, rings (v alone) 2.
    for name, record in F.FIELDS.items():
        assert gm.stencil_values(name) == sum(2 for x in (F.u, F.v) if x in record.expr.free_symbols), name
    assert gm.evaluations("rings", "central").h == 2                  # the u-difference of rings is 0
    # A stencil that read h only at u +- eps would be counted as 2, not 4.
    assert sum(p in F.FIELDS["sine"].central[0].free_symbols for p, _ in F.STENCIL_POINTS) == 2


def test_scipy_counts_richardsons_evaluations():
    u, v = gb.chart_points()
    u, v = u[:300], v[:300]
    info = {}
    gm.richardson_gradient("ridges", u, v, KU, KV, info=info)
    assert info["h_per_pixel"] > 4 * 2       # more than a central difference's four, per component


# --- forward-mode automatic differentiation ------------------------------------------------

def ad_agrees_with_exact(name, u, v, height=None):
    """|AD - exact gradient| within float64 evaluation error (`FLOAT64_EVAL`) in both components."""
    uu, vv = np.array([u]), np.array([v])
    ad = np.ravel(gm.ad_gradient(name, uu, vv, KU, KV, height=height))
    ex = np.ravel(pointwise.exact_gradient(name, uu, vv, KU, KV))
    return bool(np.all(np.abs(ad - ex) <= FLOAT64_EVAL))


CHART = st.floats(0.0, 1.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(field=st.sampled_from(F.BUILTIN), u=CHART, v=CHART)
def test_ad_is_the_exact_gradient_to_rounding_at_random_points(field, u, v):
    # Off the ridges' crease band: on a crease the two take different sides (next test).
    if pointwise.kink_band(field, np.array([u]), np.array([v]), KU, KV)[0]:
        return
    assert ad_agrees_with_exact(field, u, v)


#: Wrong programs AD could be handed: a frequency off by a part in 1e9, and the ridges' |f|
#: written as sqrt(f^2), the same function, whose program's derivative on the crease is 0/0.
_f = sp.Mul(*F.FIELDS["ridges"].crease_factors)
WRONG_PROGRAMS = {
    "sine": F.FIELDS["sine"].expr.subs(F.k_u, F.k_u * (1 + sp.Rational(1, 10**9))),
    "ridges": sp.Pow(_f**2, sp.S.Half, evaluate=False),
}


def test_ad_of_a_wrong_program_is_caught():
    assert not ad_agrees_with_exact("sine", 0.31, 0.47, height=WRONG_PROGRAMS["sine"])
    # sqrt(f^2) equals |f| everywhere, and AD agrees off the crease ...
    assert ad_agrees_with_exact("ridges", 0.31, 0.47, height=WRONG_PROGRAMS["ridges"])
    # ... but on it AD differentiates the program, sqrt at 0: no number at all.
    h_u, _ = gm.ad_gradient("ridges", np.array([0.0]), np.array([0.47]), KU, KV, height=WRONG_PROGRAMS["ridges"])
    assert not np.isfinite(h_u[0])
    assert not ad_agrees_with_exact("ridges", 0.0, 0.47, height=WRONG_PROGRAMS["ridges"])


def test_ad_on_the_crease_beside_the_exact_gradient_and_the_central_difference():
    at_zero, at_residue = gm.crease_values()
    slope = at_zero["right"]
    assert at_zero["factor"] == 0.0 and at_residue["factor"] != 0.0
    assert at_zero["left"] == -slope and slope > 1.0
    # Where the factor is exactly 0: the exact gradient's sign(0) = 0; AD takes JAX's slope of |x| at
    # f = -0.0 (f = 0 times a negative factor here) times f_u, which is one of the one-sided slopes.
    assert at_zero["exact"] == 0.0
    f_u = -slope if np.sin(np.pi * KV * 0.47) < 0 else slope
    assert at_zero["ad"] == pytest.approx(gm.abs_slope_at_zero()[1] * f_u, rel=1e-12, abs=0)
    assert at_zero["ad"] in (pytest.approx(-slope, rel=1e-12, abs=0), pytest.approx(slope, rel=1e-12, abs=0))
    # Where the factor is a rounding residue, both take the side its sign picks: the same one.
    assert at_residue["exact"] == pytest.approx(at_residue["ad"], rel=1e-12, abs=0)
    assert abs(at_residue["exact"]) == pytest.approx(slope, rel=1e-12, abs=0)
    # The central difference averages the two sides: ~0.
    for c in (at_zero, at_residue):
        assert abs(c["central"]) < 1e-9 * slope


def test_jax_slope_of_abs_at_zero_is_measured_and_x64_stays_local():
    import jax
    slopes = gm.abs_slope_at_zero()
    assert all(s in (-1.0, 0.0, 1.0) for s in slopes)
    assert gm.ad_gradient("sine", np.array([0.31]), np.array([0.47]), KU, KV)[0].dtype == np.float64
    assert not jax.config.jax_enable_x64          # the float64 switch was a context, not global


# --- AD and the exact gradient through one compiler ---------------------------------------------

@pytest.mark.parametrize("field", F.BUILTIN)
def test_the_xla_exact_gradient_is_the_exact_gradient(field):
    """What `same_compiler_times` times as "exact" computes the exact gradient (the numba one)."""
    rng = np.random.default_rng(7)
    u, v = rng.random(257), rng.random(257)
    got = gm.xla_exact_gradient(field, u, v, KU, KV)
    want = pointwise.exact_gradient(field, u, v, KU, KV)
    assert len(got) == len(want) == 2
    for g, w in zip(got, want):
        assert np.shape(g) == np.shape(w) and np.allclose(g, w, rtol=1e-13, atol=1e-13)


def test_same_compiler_times_report_each_side_and_their_ratio(monkeypatch):
    u = v = np.linspace(0.1, 0.9, 64)
    fast = gm.same_compiler_times(u, v, rounds=3, fields_=("rings",))["rings"]
    assert fast["exact"] > 0 and fast["ad"] > 0 and fast["numba"] > 0
    assert fast["ratio"] == fast["ad"] / fast["exact"] and fast["compiler"] == fast["exact"] / fast["numba"]
    # A planted slow AD (5 ms a call, the exact gradient of 64 points takes microseconds) shows.
    real = gm._ad_gradient

    def slow(*args, **kwargs):
        time.sleep(0.005)
        return real(*args, **kwargs)
    monkeypatch.setattr(gm, "_ad_gradient", slow)
    assert gm.same_compiler_times(u, v, rounds=3, fields_=("rings",))["rings"]["ratio"] > 5


@pytest.mark.parametrize("text", ["0", "2*k_u", "u", "sin(pi*k_v*v)"])
def test_every_method_gives_one_value_per_point_of_any_field(text):
    """A field constant in u and v (0, 2 k_u), or in one of them: every method's gradient is two
    float64 arrays of the points' shape (AD's once were JAX's scalar tangent for 2 k_u, and JAX's
    float0 tangent of an integer for 0)."""
    record, uu, vv = F.field(text), np.array([0.31, 0.5, 0.9]), np.array([0.47, 0.2, 0.6])
    for m in gm.METHODS:
        if m.applies(record):
            grad = m.gradient(record, uu, vv, 8.0, 4.0, None if m.steps is None else 1e-6, {})
            assert [(np.asarray(g).dtype, np.shape(g)) for g in grad] == [(np.float64, (3,))] * 2, (m.name, text)


#: Frequencies at the ends of what a scene accepts, and the draft's.
FREQUENCIES = st.sampled_from([1e-3, 0.5, KV, KU, 1e3])


@pytest.mark.filterwarnings("ignore::RuntimeWarning")     # numpy's, where it gives NaN or inf
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=fields_at_points(), ku=FREQUENCIES, kv=FREQUENCIES, program=expressions(["u", "v", "k_u", "k_v"]))
@example(case=("cos(k_u**k_u)", 0.31, 0.47, "u"), ku=1e3, kv=1e3, program="log(log(1))")
def test_any_field_at_any_point_gives_every_method_one_float_per_point_or_one_input_error(case, ku, kv, program):
    """Whatever field a reader types, at any chart point and frequencies: every method that applies,
    the reference and AD of any program give float64 arrays of the points' shape (NaN or inf where
    the field has no value, as numpy gives), or the field or program is refused by name when parsed;
    never an exception from inside numpy, sympy's printers or JAX (k_u**k_u at k_u = 1e3 raised
    Python's OverflowError in the complex step; a program sympy reads as complex infinity, a KeyError)."""
    text, u, v, _ = case
    uu, vv = np.array([u, 0.31]), np.array([v, 0.47])
    try:
        record = F.field(text)
    except InputError as exc:
        assert str(exc).startswith("height_field") and "\n" not in str(exc), str(exc)
    else:
        for m in gm.METHODS:
            if m.applies(record):
                grad = m.gradient(record, uu, vv, ku, kv, None if m.steps is None else 1e-6, {})
                assert [(np.asarray(g).dtype, np.shape(g)) for g in grad] == [(np.float64, (2,))] * 2, m.name
        assert all(a.shape == (2, 2) for a in gm.reference_gradient(record, uu, vv, ku, kv, digits=32))
    height = sp.parse_expr(program, local_dict={s.name: s for s in F.FIELD_SYMBOLS})
    try:
        grad = gm.ad_gradient("sine", uu, vv, ku, kv, height=height)
    except InputError as exc:
        assert str(exc).startswith("height") and "\n" not in str(exc), str(exc)
    else:
        assert [(g.dtype, g.shape) for g in grad] == [(np.float64, (2,))] * 2


def test_the_reference_is_nan_where_the_gradient_has_no_value_and_mpmaths_elsewhere():
    """A pole in u at the first point (both components NaN: mpmath raises), a square root past its
    branch point in v at the last (h_v complex: NaN), the values elsewhere mpmath's own."""
    uu, vv = np.array([0.31, 0.5, 0.2]), np.array([0.47, 0.47, 0.3])
    hi, lo = gm.reference_gradient("1/(u - 0.31) + sqrt(v - 0.4)", uu, vv, 8.0, 4.0)
    with mpmath.workdps(50):
        h_u = [float(-1 / (mpmath.mpf(a) - mpmath.mpf("0.31")) ** 2) for a in uu[1:]]
        h_v = float(1 / (2 * mpmath.sqrt(mpmath.mpf(0.47) - mpmath.mpf("0.4"))))
    assert np.isnan(hi[:, 0]).all() and np.isnan(lo[:, 0]).all() and np.isnan(hi[1, 2]) and np.isnan(lo[1, 2])
    assert np.allclose(hi[0, 1:], h_u, rtol=1e-15, atol=0) and np.isclose(hi[1, 1], h_v, rtol=1e-15, atol=0)


def _style_clashes(methods):
    """Pairs of methods a reader could not tell apart in a figure: the same colour and marker."""
    seen, clashes = {}, []
    for m in methods:
        key = (m.style.colour, m.style.marker)
        if key in seen:
            clashes.append(f"{m.name!r} is drawn as {seen[key]!r} is: colour {key[0]}, marker {key[1]!r}")
        seen.setdefault(key, m.name)
    return clashes


def test_each_method_is_drawn_unlike_every_other():
    """Every record's colour and marker together are its own (a new method's style is checked here, with the
    method it copies named); a planted copy of the central difference's style is caught."""
    import dataclasses
    assert _style_clashes(gm.METHODS) == []
    copy = dataclasses.replace(gm.METHODS[-1], name="copy", style=gm.method("central").style)
    assert _style_clashes([*gm.METHODS, copy]) == ["'copy' is drawn as 'central' is: colour "
                                                    f"{gm.method('central').style.colour}, marker "
                                                    f"{gm.method('central').style.marker!r}"]
