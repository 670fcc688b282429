"""The measurement of the gradient methods, lab/gradient_benchmark.py: the Pareto front, a small
run of the whole measurement and the figures drawn from it, a method added as one record, and a
reader's function of one variable through the methods against mpmath and the papers.  Each check
is shown to reject a wrong variant.
"""

from __future__ import annotations

import dataclasses
import math
import re

import mpmath
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from lab import gradient_benchmark as gb
from lab import gradient_methods as gm
from renderer import DRAFT_SCENE, pointwise, ucurve
from renderer import formulas as F
from renderer.validate import InputError, InvalidType, InvalidValue

from .expressions import functions_at_points
from .test_gradient_methods import FLOAT64_EVAL, applying, generated_trig_calls

KU, KV = DRAFT_SCENE.k_u, DRAFT_SCENE.k_v

# --- the Pareto front ----------------------------------------------------------------------

def result(label, t, err):
    return gb.MethodResult("sine", label, None, (t,), 0.0, 0.0, 0.0, err, err)


def test_pareto_front_rejects_a_dominated_point():
    fast_exact = result("a", 1.0, 1e-14)
    slow_coarse = result("b", 2.0, 1e-9)          # slower and less accurate than a
    fastest = result("c", 0.5, 1e-3)
    tie_time = result("d", 1.0, 1e-12)            # same time as a, worse error: dominated
    twin = result("e", 1.0, 1e-14)                # equal to a: neither dominates the other
    front = gb.pareto_front([fast_exact, slow_coarse, fastest, tie_time, twin])
    assert [r.method for r in front] == ["c", "a", "e"]
    assert slow_coarse not in front and tie_time not in front


def test_pareto_front_minimises_the_error_it_is_asked_for():
    """max and rms rank a spiky method and a uniformly coarse one oppositely: each front keeps its own."""
    def both(label, t, max_error, rms_error):
        return gb.MethodResult("sine", label, None, (t,), 0.0, 0.0, 0.0, max_error, rms_error)
    fast = both("fast", 1.0, 1e-6, 1e-8)                  # a few bad pixels: large max, small rms
    slow = both("slow", 2.0, 1e-7, 1e-7)                  # uniform: smaller max, larger rms
    assert [r.method for r in gb.pareto_front([fast, slow], error="max")] == ["fast", "slow"]
    assert [r.method for r in gb.pareto_front([fast, slow], error="rms")] == ["fast"]
    assert [r.method for r in gb.pareto_front([fast, slow])] == ["fast", "slow"]      # "max" by default


def test_pareto_front_validates_its_input():
    with pytest.raises(ValueError, match="error must be 'max' or 'rms'"):
        gb.pareto_front([result("a", 1.0, 1.0)], error="mean")
    with pytest.raises(ValueError, match="must be finite"):
        gb.pareto_front([result("a", 1.0, np.nan), result("b", 2.0, 1.0)])


# --- the whole measurement, small ----------------------------------------------------------

TINY = gb.Config("tiny", central_steps=(1e-3, 1e-6), forward_steps=(1e-8,), complex_steps=(1e-20,),
                 repeats=2, richardson_repeats=1, reference_pixels=30)


def test_chart_points_do_not_depend_on_the_field():
    # This licenses measure(uv=...) sharing one set of chart points across fields.
    a, b = gb.chart_points("sine"), gb.chart_points("rings")
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert a[0].size > 20000


def small_chart():
    u, v = gb.chart_points()
    step = max(1, u.size // 2000)
    return u[::step].copy(), v[::step].copy()


def test_measure_small_run_and_its_presentations():
    m = gb.measure(TINY, uv=small_chart())
    assert m.reference_pixels == dict.fromkeys(F.FIELDS, 30)
    assert m.excluded_pixels["sine"] == 0 and m.excluded_pixels["ridges"] > 0
    exact = m.get("sine", "exact")
    assert exact.max_error <= FLOAT64_EVAL and len(exact.times) == 2
    assert m.get("sine", "central 1e-03").h_evals == 4.0
    assert m.get("sine", "central 1e-03").trig_evals == 6.0
    assert m.get("rings", "exact").trig_evals == generated_trig_calls("exact", "rings")
    assert m.get("sine", "richardson").h_evals > 4.0
    assert len(m.get("sine", "richardson").times) == 1
    with pytest.raises(KeyError, match=r"'complex step 1e-20' for 'ridges'; its labels: \[.*'exact'"):
        m.get("ridges", "complex step 1e-20")                   # not measured where it does not apply
    with pytest.raises(KeyError, match=re.escape(f"field 'Sine' was not measured; measured: {sorted(F.FIELDS)}")):
        m.of("Sine")                                            # a typo is not an empty list
    assert m.get("ridges", "complex step, |z| continued 1e-20").max_error <= FLOAT64_EVAL
    assert m.get("sine", "central 1e-06").max_error > 1e4 * FLOAT64_EVAL
    for f in F.FIELDS:                   # AD: exact to rounding, compile time kept apart from the runs
        ad = m.get(f, gm.AD)
        assert ad.max_error <= FLOAT64_EVAL and len(ad.times) == 2 and ad.compile_seconds > 0
        assert ad.h_tangent_evals == 2.0 and ad.trig_evals == gm.ad_trig_calls(F.FIELDS[f])
    from chapter.benchmark import markdown_table, pareto_figure
    table = markdown_table(m, rows="best", include=("central 1e-03",))
    rows = [[c.strip() for c in line.strip("|").split(" | ")] for line in table.splitlines()[2:]]
    # "best": per field one row per method that applies + central 1e-03.
    assert [r[0] for r in rows] == [f for f in F.FIELDS for _ in range(len(applying(f)) + 1)]
    assert all(len(r) == len(rows[0]) == 8 for r in rows)
    assert {"exact", "central 1e-03"} <= {r[1] for r in rows if r[0] == "ridges"}
    shown = {(r[0], r[1]): r for r in rows}
    for f in F.FIELDS:                                         # the numbers are the measurement's
        exact = m.get(f, "exact")
        assert float(shown[f, "exact"][4]) == pytest.approx(exact.max_error, rel=1e-2, abs=1e-300)
        assert float(shown[f, "exact"][5]) == pytest.approx(exact.rms_error, rel=1e-2, abs=1e-300)
    with pytest.raises(ValueError, match="rows must be 'all', 'front' or 'best', got 'some'"):
        markdown_table(m, rows="some")
    fig = pareto_figure(m)
    assert_drawn_for_a_phone(fig, panels=len(F.FIELDS))
    with pytest.raises(ValueError, match="error must be 'max' or 'rms', got 'mean'"):
        pareto_figure(m, error="mean")
    assert '"label": "exact"' in gb.to_json(m)


def assert_drawn_for_a_phone(fig, panels):
    """One panel per field, in at most two columns read row by row, at most 5 in wide, every drawn
    text at least 9 pt, and no two texts overlapping (`chapter.layout.text_overlaps`)."""
    from chapter.layout import drawn_texts, text_overlaps
    axes = [ax for ax in fig.axes if ax.get_title()]
    assert len(axes) == panels and fig.get_figwidth() <= 5.0, (len(axes), fig.get_figwidth())
    boxes = [ax.get_position() for ax in axes]
    columns = len({round(b.x0, 6) for b in boxes})
    assert columns <= 2 and all(a.y0 > b.y1 for a, b in zip(boxes, boxes[columns:])), boxes
    assert min(t.get_fontsize() for t in drawn_texts(fig)) >= 9.0
    assert text_overlaps(fig) == []


def test_a_figure_not_drawn_for_a_phone_is_caught():
    """Wrong variants of the Pareto figure's layout: side by side (too wide, or three columns), too
    wide, 8-pt text."""
    from matplotlib.figure import Figure
    for width, rows, size in ((9.0, 1, 10), (5.0, 1, 10), (5.5, 3, 10), (5.0, 3, 8)):
        fig = Figure(figsize=(width, 6), layout="constrained")
        axes = fig.subplots(rows, 3 // rows, squeeze=False).ravel()
        for i, ax in enumerate(axes):
            ax.set_title(f"panel {i}", fontsize=10)
            ax.tick_params(labelsize=size)
        with pytest.raises(AssertionError):
            assert_drawn_for_a_phone(fig, panels=len(F.FIELDS))


# --- a method added as one record ------------------------------------------------------------

def backward_gradient(field, u, v, ku, kv, eps, info):
    """A toy method: the backward difference (h(x) - h(x - eps)) / eps in u and v, u wrapped."""
    h0 = pointwise.height(field, u, v, ku, kv)
    return ((h0 - pointwise.height(field, np.mod(u - eps, 1.0), v, ku, kv)) / eps,
            (h0 - pointwise.height(field, u, v - eps, ku, kv)) / eps)


#: Named as no real method would be, so that a real backward difference added to METHODS meets no clash.
BACKWARD = gm.Method("toy backward", backward_gradient, lambda f, info: gm.Evaluations(h=3.0),
                     "toy backward difference", gm.Style("#444444", "v", 6, "--"), steps="forward_steps")


def test_a_method_with_steps_of_its_own_runs_at_them_in_every_configuration(monkeypatch):
    """A record may give its own steps instead of naming a `Config` list: `measure` runs it at exactly
    those, whatever the configuration.  Steps out of range and a name that is no step list are refused,
    naming ``Method.steps``."""
    own = dataclasses.replace(BACKWARD, name="toy backward, own", steps=[3e-5, 1e-4])
    assert own.steps == (3e-5, 1e-4)
    monkeypatch.setattr(gm, "METHODS", [*gm.METHODS, own])
    for config in (TINY, dataclasses.replace(TINY, forward_steps=(1e-2,))):
        m = gb.measure(config, uv=small_chart(), fields_=("sine",))
        assert sorted(r.eps for r in m.results if r.method == own.name) == [3e-5, 1e-4]
    for bad, error in ((0.0, InvalidValue), ((1e-3, 2.0), InvalidValue), ((1e-3, "x"), InvalidType), ([1e-3] * 65, InvalidValue)):
        with pytest.raises(error, match=r"^Method\.steps"):
            dataclasses.replace(BACKWARD, steps=bad)
    lists = tuple(f.name for f in dataclasses.fields(gb.Config) if f.name.endswith("_steps"))
    with pytest.raises(InvalidValue, match=re.escape(f"Method.steps must be one of {lists}, got 'backward_steps'")):
        dataclasses.replace(BACKWARD, steps="backward_steps").steps_in(TINY)


def test_a_new_method_is_one_record_measured_and_drawn(monkeypatch):
    """Appending a record to METHODS is the whole change: `measure` runs it on every field, at the
    steps it names, against the reference; the table shows it and the figure draws it with its style
    and label.  Its error is first order, as a backward difference's is."""
    from chapter.benchmark import markdown_table, pareto_figure
    monkeypatch.setattr(gm, "METHODS", [*gm.METHODS, BACKWARD])
    m = gb.measure(TINY, uv=small_chart(), fields_=("sine",))
    back = m.get("sine", "toy backward 1e-08")
    assert back.h_evals == 3.0 and 1e-7 < back.max_error < 1e-4 and len(back.times) == TINY.repeats
    assert "toy backward 1e-08" in markdown_table(m)
    fig = pareto_figure(m)
    style = (BACKWARD.style.colour, BACKWARD.style.marker)
    assert [ln for ax in fig.axes for ln in ax.get_lines() if (ln.get_color(), ln.get_marker()) == style]
    legend = {t.get_text(): h for lg in fig.legends for t, h in zip(lg.get_texts(), lg.legend_handles)}
    assert (legend[BACKWARD.label].get_color(), legend[BACKWARD.label].get_marker()) == style


def test_a_second_record_of_one_name_is_refused_where_the_methods_are_read(monkeypatch):
    """Two records of one name (a method added under a name already used): the benchmark, the table's
    lookup and the figure's legend would find the first for both.  Every reader of the list refuses it,
    naming the name; a record renamed is measured beside the original."""
    from chapter.benchmark import methods_sentence
    twin = dataclasses.replace(BACKWARD, name="forward")
    monkeypatch.setattr(gm, "METHODS", [*gm.METHODS, twin])
    refused = "^lab.gradient_methods.METHODS holds more than one record named 'forward'"
    for read in (lambda: gb.measure(TINY, uv=small_chart(), fields_=("sine",)), lambda: gm.method("exact"),
                 lambda: gb.univariate_errors("exp(x)", 0.5), lambda: methods_sentence(TINY)):
        with pytest.raises(ValueError, match=refused):
            read()
    monkeypatch.setattr(gm, "METHODS", [*gm.METHODS[:-1], BACKWARD])
    assert gm.method(BACKWARD.name) is BACKWARD


# --- a reader's function of one variable -------------------------------------------------------

@pytest.fixture(scope="module")
def classic():
    """The classic complex-step test function at its point, through the methods."""
    return gb.univariate_errors(gb.TEST_FUNCTION.function, gb.TEST_FUNCTION.x)


def test_the_reference_of_the_classic_function_is_mpmaths_own_derivative(classic):
    """An independent route to f'(1.5): mpmath's numerical differentiation of f at 50 digits."""
    with mpmath.workdps(50):
        f = lambda x: mpmath.exp(x) / mpmath.sqrt(mpmath.sin(x) ** 3 + mpmath.cos(x) ** 3)  # noqa: E731
        assert classic.derivative == float(mpmath.diff(f, mpmath.mpf(1.5)))
    assert classic.derivative == classic.curve.derivative               # measure_function's reference


def test_the_classic_function_reproduces_the_papers_behaviour(classic):
    """What `gb.PUBLISHED` reports, measured: the complex step at the precision of f's evaluation for
    every step up to 1e-8 (a few units of roundoff), the differences first and second order on the
    truncation side and ruined by cancellation below their best step, AD at the same precision as the
    complex step; the central difference's rows are measure_function's U-curve."""
    u = ucurve.UNIT_ROUNDOFF
    cs = classic.of("complex step")
    assert max(r.relative_error for r in cs if r.eps <= 1e-8) <= 8 * u
    assert classic.best(gm.AD).relative_error <= 8 * u and classic.best("exact").relative_error <= 8 * u
    for name, order in (("forward", 1.0), ("central", 2.0), ("complex step", 2.0)):
        rows = [r for r in classic.of(name) if 1e-3 <= r.eps <= 1e-1]
        slope = np.polyfit(np.log([r.eps for r in rows]), np.log([r.error for r in rows]), 1)[0]
        assert abs(slope - order) < 0.15, (name, slope)
        best = classic.best(name)
        if name != "complex step":
            assert classic.of(name)[-1].relative_error > 1e3 * best.relative_error   # the cliff below
    assert [r.error for r in classic.of("central")] == list(classic.curve.error)
    with pytest.raises(KeyError, match=r"method 'centrall' was not measured; measured: \[.*'central'"):
        classic.best("centrall")
    assert 0.1 < classic.best("central").eps / classic.curve.eps_fitted < 10
    assert {p.method for p in gb.PUBLISHED} - {None} <= {m.name for m in gm.METHODS}


def test_each_method_has_a_row_per_step_or_one_without(classic):
    """A method that takes a step is measured at every step of the curve; one that takes none (AD,
    Richardson, exact) once, its step None; every method with a one-variable form that applies is there."""
    steps = [float(e) for e in classic.curve.eps]
    measured = {r.method for r in classic.rows}
    for m in gm.METHODS:
        if m.name in measured:
            assert [r.eps for r in classic.of(m.name)] == ([None] if m.steps is None else steps), m.name
    assert {m.name for m in gm.METHODS if m.steps is None} & measured and len(measured) >= 5, measured


def test_an_abs_function_takes_the_continued_complex_step_and_not_the_plain_one():
    e = gb.univariate_errors("x*abs(x - 1)", 2.0, steps=(1e-3, 1e-20))
    names = {r.method for r in e.rows}
    assert "complex step" not in names and "complex step, |z| continued" in names
    assert e.best("complex step, |z| continued").relative_error <= 8 * ucurve.UNIT_ROUNDOFF


@pytest.mark.parametrize("function, x, match", [
    ("exp(y)", 1.0, "^function .*'y'"),                     # an unknown symbol
    ("exp(x)", 1j, "^x must be a real number"),             # not real
    ("abs(x - 1)", 1.0, "^function .*not differentiable at x = 1.0"),
    ("sqrt(x)", -1.0, "^function .*x = -1.0"),              # not defined there
    ("exp(x)", 800.0, r"^function exp\(x\) must be defined .*: there f is 2.73e\+347, beyond float64's largest number"),
    ("sinh(x)**2/cosh(x)", 400.0, "^x must be a point where .* at x = 400.0 it overflows"),  # f finite, f64 not
    ("log(x**2)", 0.0, r"^function log\(x\*\*2\) must be defined"),  # f is infinite: not "too large"
    ("1/x", 0.0, "^function 1/x must be defined"),
    ("abs(atan(x)**atan(x))", 1.0, r"^function 'abs\(atan\(x\)\*\*atan\(x\)\)' must have a real derivative in x in "
                                   "closed form; sympy's holds arg, im, re"),
    ("cos(3)**x", 1.0, r"^function 'cos\(3\)\*\*x' must have .* sympy's holds the imaginary unit"),
])
def test_a_bad_function_or_point_is_one_input_error(function, x, match):
    with pytest.raises(InputError, match=match):
        gb.univariate_errors(function, x)


@pytest.mark.filterwarnings("error::RuntimeWarning")
def test_a_method_reaching_past_the_domain_is_refused_without_a_numpy_warning():
    with pytest.raises(InputError, match=r"^function log\(x\): its richardson derivative at x = 0.02"):
        gb.univariate_errors("log(x)", 0.02, steps=(1e-2,))


def test_a_derivative_below_float64s_range_is_measured_and_one_whose_program_overflows_refused():
    """exp at -778.8: f' = 1e-338 is 0 in float64, the relative errors finite all the same (taken in
    mpmath).  tanh(sinh(x)) at -951.8: the float64 program of sympy's derivative overflows (cosh x),
    so the exact method has no value there: one refusal naming the function."""
    found = gb.univariate_errors("exp(x)", -778.8, steps=(1e-2, 1e-6))
    assert found.derivative == 0.0 and all(math.isfinite(r.relative_error) for r in found.rows)
    with pytest.raises(InputError, match=r"^function tanh\(sinh\(x\)\): its exact derivative at x = -951.8"):
        gb.univariate_errors("tanh(sinh(x))", -951.8, steps=(1e-2,))


def test_a_step_past_where_f_is_defined_is_refused_by_this_functions_name_for_it():
    with pytest.raises(InputError, match=r"^steps must keep log\(x\) finite and real .* at the step 0.6 \(step 1\)"):
        gb.univariate_errors("log(x)", 0.5, steps=(1e-3, 0.6))


@pytest.mark.filterwarnings("error::RuntimeWarning")
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=functions_at_points())
def test_any_function_at_any_point_is_measured_or_one_input_error(case):
    """Whatever f a reader types and wherever: every method's row a finite value and error, or one
    refusal naming ``function``, ``x`` or ``steps`` (never an exception from inside mpmath, math,
    SciPy or JAX: a pole, an overflow of a derivative, a derivative below float64's range), and no
    numpy warning on the way (Richardson's steps reaching past log's domain, log(x) at 0.02)."""
    text, x = case
    try:
        found = gb.univariate_errors(text, x, steps=(1e-2, 1e-6, 1e-20))
    except InputError as exc:
        assert re.match(r"^(function|x|steps)\b", str(exc)) and "\n" not in str(exc), str(exc)
        return
    assert found.rows and all(math.isfinite(r.value) and math.isfinite(r.error) and not math.isnan(r.relative_error)
                              for r in found.rows), found.rows
