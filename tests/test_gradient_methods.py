"""The gradient methods of lab/gradient_methods.py: their orders against
sympy's derivative evaluated by mpmath, the complex step's analyticity
premise, the work per pixel counted from the formulas, and the Pareto front.
Each check is shown to reject a wrong variant.
"""

from __future__ import annotations

import inspect
import re
import time

import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from lab import gradient_methods as gm
from renderer import formulas as F
from renderer import generated as G
from renderer import pointwise

KU, KV = 8.0, 4.0
#: float64 spacing at the gradient's scale pi max(k_u, 2 k_v) = 8 pi (as lab/accuracy.py).
SPACING = float(np.spacing(np.pi * max(KU, 2 * KV)))
#: Over many pixels a float64 evaluation of the gradient is off by up to ~40 spacings: the
#: phase pi k u (up to 8 pi) is rounded, and the rounding is multiplied by the slope, up to
#: 8 pi.  verify/test_accuracy.py allows 64 spacings for the exact gradient; so do we.
FLOAT64_EVAL = 64 * SPACING


#: The sine field's (h_u, h_v), `formulas.GRADIENT["sine"]`, as an mpmath function.
_SINE_GRADIENT_MP = sp.lambdify((F.u, F.v, F.k_u, F.k_v), F.GRADIENT["sine"], "mpmath")


def sine_gradient_mp(u, v, ku=KU, kv=KV):
    """(h_u, h_v) of the sine field: sympy's derivative (`formulas.GRADIENT`,
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


@pytest.mark.parametrize("eps", [0.0, -1e-3, np.inf, np.nan])
def test_steps_are_validated(eps):
    with pytest.raises(ValueError, match="eps must be a positive finite number"):
        gm.forward_gradient("sine", U0, V0, KU, KV, eps)
    with pytest.raises(ValueError, match="eps must be a positive finite number"):
        gm.complex_step_gradient("sine", U0, V0, KU, KV, eps)


def test_unknown_field_is_rejected():
    for fn in (lambda: gm.complex_step_gradient("bumps", U0, V0, KU, KV, 1e-20),
               lambda: gm.richardson_gradient("bumps", U0, V0, KU, KV),
               lambda: gm.reference_gradient("bumps", U0, V0, KU, KV)):
        with pytest.raises(ValueError, match="height_field must be one of"):
            fn()


# --- the complex step's premise ------------------------------------------------------------

def test_analyticity_flag_is_read_from_the_expressions():
    assert gm.ANALYTIC == {"sine": True, "ridges": False, "rings": True}
    x = sp.Symbol("x", real=True)
    assert gm.is_analytic(sp.sin(x) * sp.exp(x))
    assert not gm.is_analytic(sp.Abs(sp.sin(x)))
    assert not gm.is_analytic(sp.sign(x) * x)


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
    # Had the flag called ridges analytic, this result would be trusted as exact; it is
    # flagged instead.
    def complex_step_valid(field):
        return {(m, e): ok for m, e, ok, _, _ in gm.methods(field, gm.FAST, KU, KV)}[("complex step", 1e-20)]
    assert complex_step_valid("ridges") is False and complex_step_valid("sine") is True
    # With |z| continued as z sign(Re z) the complex step is right off the crease.
    hu_cont, _ = gm.complex_step_gradient("ridges", u, v, KU, KV, 1e-20, continued=True)
    assert abs((hu_cont[0] - hi[0, 0]) - lo[0, 0]) <= 4 * SPACING


# --- the work per pixel ------------------------------------------------------------------

def generated_trig_calls(function, field):
    """math.sin and math.cos calls in the branch of ``field`` of a function of
    renderer/generated.py: the code numba compiles, read as text."""
    source = inspect.getsource(function.py_func)
    branch = source.split(f"if field == {F.FIELD_CODES[field]}:")[1].split("if field ==")[0]
    return len(re.findall(r"math\.(?:sin|cos)\(", branch))


@pytest.mark.parametrize("field", gm.FIELDS)
def test_trig_count_is_the_generated_codes(field):
    # Two routes: sympy's cse over the formulas, and the text numba compiles.
    assert gm.trig_calls(F.CENTRAL[field]) == generated_trig_calls(G.central_gradient, field)
    assert gm.trig_calls(F.GRADIENT[field]) == generated_trig_calls(G.exact_gradient, field)
    assert gm.trig_calls((F.HEIGHT[field],)) == generated_trig_calls(G.height, field)


def test_trig_count_rejects_counting_without_the_shared_factors():
    # Counting the stencil's four values of h as written (no cse) gives 8 sines for the
    # sine field; the generated code shares sin(pi k_v v) and sin(pi k_u u) and calls 6.
    as_written = sum(isinstance(n, sp.sin) for c in F.CENTRAL["sine"] for n in sp.preorder_traversal(c))
    assert as_written == 8 != generated_trig_calls(G.central_gradient, "sine") == 6


def test_work_per_pixel_of_each_method():
    expected = {
        ("sine", "central"): gm.Evaluations(h=4, trig=6),
        ("ridges", "central"): gm.Evaluations(h=4, trig=6),
        ("rings", "central"): gm.Evaluations(h=2, trig=2),      # the u-difference of rings is 0
        ("sine", "exact"): gm.Evaluations(gradient=1, trig=4),
        ("rings", "exact"): gm.Evaluations(gradient=1, trig=1),
        ("sine", "forward"): gm.Evaluations(h=3, trig=6),
        ("sine", "complex step"): gm.Evaluations(h_complex=2),
        ("ridges", "h"): gm.Evaluations(h=1, trig=2),
    }
    for (field, method), want in expected.items():
        assert gm.evaluations(field, method) == want, (field, method)
    assert gm.evaluations("sine", "richardson", h_per_pixel=22.5) == gm.Evaluations(h=22.5, trig=45)
    with pytest.raises(ValueError, match="pass h_per_pixel"):
        gm.evaluations("sine", "richardson")
    with pytest.raises(ValueError, match="unknown method"):
        gm.evaluations("sine", "backward")


def test_stencil_values_are_the_points_the_stencil_reads():
    assert [gm.stencil_values(f) for f in gm.FIELDS] == [4, 4, 2]
    # A stencil that read h only at u +- eps would be counted as 2, not 4.
    assert sum(p in F.CENTRAL["sine"][0].free_symbols for p, _ in F.STENCIL_POINTS) == 2


def test_scipy_counts_richardsons_evaluations():
    u, v = gm.chart_points()
    u, v = u[:300], v[:300]
    info = {}
    gm.richardson_gradient("ridges", u, v, KU, KV, info=info)
    assert info["nfev"] > 4 * 2 * u.size     # more than a central difference's four, per component


# --- the Pareto front ----------------------------------------------------------------------

def result(label, t, err):
    return gm.MethodResult("sine", label, None, True, (t,), 0.0, 0.0, 0.0, err, err)


def test_pareto_front_rejects_a_dominated_point():
    fast_exact = result("a", 1.0, 1e-14)
    slow_coarse = result("b", 2.0, 1e-9)          # slower and less accurate than a
    fastest = result("c", 0.5, 1e-3)
    tie_time = result("d", 1.0, 1e-12)            # same time as a, worse error: dominated
    twin = result("e", 1.0, 1e-14)                # equal to a: neither dominates the other
    front = gm.pareto_front([fast_exact, slow_coarse, fastest, tie_time, twin])
    assert [r.method for r in front] == ["c", "a", "e"]
    assert slow_coarse not in front and tie_time not in front


def test_pareto_front_validates_its_input():
    with pytest.raises(ValueError, match="error must be 'max' or 'rms'"):
        gm.pareto_front([result("a", 1.0, 1.0)], error="mean")
    with pytest.raises(ValueError, match="must be finite"):
        gm.pareto_front([result("a", 1.0, np.nan), result("b", 2.0, 1.0)])


# --- the whole measurement, small ----------------------------------------------------------

TINY = gm.Config("tiny", central_steps=(1e-3, 1e-6), forward_steps=(1e-8,), complex_steps=(1e-20,),
                 repeats=2, richardson_repeats=1, reference_pixels=30)


def test_chart_points_do_not_depend_on_the_field():
    # This licenses measure(uv=...) sharing one set of chart points across fields.
    a, b = gm.chart_points("sine"), gm.chart_points("rings")
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert a[0].size > 20000


def test_measure_small_run_and_its_presentations():
    u, v = gm.chart_points()
    step = max(1, u.size // 2000)
    m = gm.measure(TINY, uv=(u[::step].copy(), v[::step].copy()))
    assert m.reference_pixels == {"sine": 30, "ridges": 30, "rings": 30}
    assert m.excluded_pixels["sine"] == 0 and m.excluded_pixels["ridges"] > 0
    exact = m.get("sine", "exact")
    assert exact.max_error <= FLOAT64_EVAL and len(exact.times) == 2
    assert m.get("sine", "central 1e-03").h_evals == 4.0
    assert m.get("sine", "central 1e-03").trig_evals == 6.0 and m.get("rings", "exact").trig_evals == 1.0
    assert m.get("sine", "richardson").h_evals > 4.0
    assert len(m.get("sine", "richardson").times) == 1
    plain = m.get("ridges", "complex step 1e-20")
    assert not plain.valid and plain.max_error > 1.0
    assert m.get("ridges", "complex step, |z| continued 1e-20").max_error <= FLOAT64_EVAL
    assert m.get("sine", "central 1e-06").max_error > 1e4 * FLOAT64_EVAL
    for f in gm.FIELDS:                   # AD: exact to rounding, compile time kept apart from the runs
        ad = m.get(f, gm.AD)
        assert ad.max_error <= FLOAT64_EVAL and len(ad.times) == 2 and ad.compile_seconds > 0
        assert ad.h_tangent_evals == 2.0 and ad.trig_evals == gm.ad_trig_calls(f)
    from chapter.benchmark import markdown_table, pareto_figure
    table = markdown_table(m, rows="best", include=("central 1e-03",))
    rows = [[c.strip() for c in line.strip("|").split(" | ")] for line in table.splitlines()[2:]]
    # "best": per field one row per method (6 on sine and rings, 7 on ridges) + central 1e-03.
    assert [r[0] for r in rows] == ["sine"] * 7 + ["ridges"] * 8 + ["rings"] * 7
    assert all(len(r) == len(rows[0]) == 8 for r in rows)
    assert {"exact", "central 1e-03"} <= {r[1] for r in rows if r[0] == "ridges"}
    shown = {(r[0], r[1]): r for r in rows}
    for f in gm.FIELDS:                                        # the numbers are the measurement's
        exact = m.get(f, "exact")
        assert float(shown[f, "exact"][4]) == pytest.approx(exact.max_error, rel=1e-2, abs=1e-300)
        assert float(shown[f, "exact"][5]) == pytest.approx(exact.rms_error, rel=1e-2, abs=1e-300)
    assert [r[1] for r in rows if r[0] == "ridges" and "not valid" in r[7]] == ["complex step 1e-20"]
    with pytest.raises(ValueError, match="rows must be 'all', 'front' or 'best', got 'some'"):
        markdown_table(m, rows="some")
    fig = pareto_figure(m)
    assert_drawn_for_a_phone(fig, panels=3)
    with pytest.raises(ValueError, match="error must be 'max' or 'rms', got 'mean'"):
        pareto_figure(m, error="mean")
    assert '"label": "exact"' in gm.to_json(m)


def assert_drawn_for_a_phone(fig, panels):
    """One panel per field, in at most two columns read row by row, at most 5 in wide, every drawn
    text at least 9 pt, and no two texts overlapping (`chapter.figures.text_overlaps`)."""
    from chapter.figures import _drawn_texts, text_overlaps
    axes = [ax for ax in fig.axes if ax.get_title()]
    assert len(axes) == panels and fig.get_figwidth() <= 5.0, (len(axes), fig.get_figwidth())
    boxes = [ax.get_position() for ax in axes]
    columns = len({round(b.x0, 6) for b in boxes})
    assert columns <= 2 and all(a.y0 > b.y1 for a, b in zip(boxes, boxes[columns:])), boxes
    assert min(t.get_fontsize() for t in _drawn_texts(fig)) >= 9.0
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
            assert_drawn_for_a_phone(fig, panels=3)


# --- forward-mode automatic differentiation ------------------------------------------------

def ad_agrees_with_exact(name, u, v, height=None):
    """|AD - exact gradient| within float64 evaluation error (`FLOAT64_EVAL`) in both components."""
    uu, vv = np.array([u]), np.array([v])
    ad = np.ravel(gm.ad_gradient(name, uu, vv, KU, KV, height=height))
    ex = np.ravel(pointwise.exact_gradient(name, uu, vv, KU, KV))
    return bool(np.all(np.abs(ad - ex) <= FLOAT64_EVAL))


CHART = st.floats(0.0, 1.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(field=st.sampled_from(gm.FIELDS), u=CHART, v=CHART)
def test_ad_is_the_exact_gradient_to_rounding_at_random_points(field, u, v):
    # Off the ridges' crease band: on a crease the two take different sides (next test).
    if pointwise.kink_band(field, np.array([u]), np.array([v]), KU, KV)[0]:
        return
    assert ad_agrees_with_exact(field, u, v)


#: Wrong programs AD could be handed: a frequency off by a part in 1e9, and the ridges' |f|
#: written as sqrt(f^2), the same function, whose program's derivative on the crease is 0/0.
_f = F.RIDGE_FACTORS[0] * F.RIDGE_FACTORS[1]
WRONG_PROGRAMS = {
    "sine": F.HEIGHT["sine"].subs(F.k_u, F.k_u * (1 + sp.Rational(1, 10**9))),
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
    assert at_zero["ad"] == pytest.approx(gm.abs_slope_at_zero()[1] * f_u, rel=1e-12)
    assert at_zero["ad"] in (pytest.approx(-slope, rel=1e-12), pytest.approx(slope, rel=1e-12))
    # Where the factor is a rounding residue, both take the side its sign picks: the same one.
    assert at_residue["exact"] == pytest.approx(at_residue["ad"], rel=1e-12)
    assert abs(at_residue["exact"]) == pytest.approx(slope, rel=1e-12)
    # The central difference averages the two sides: ~0.
    for c in (at_zero, at_residue):
        assert abs(c["central"]) < 1e-9 * slope


def test_jax_slope_of_abs_at_zero_is_measured_and_x64_stays_local():
    import jax
    slopes = gm.abs_slope_at_zero()
    assert all(s in (-1.0, 0.0, 1.0) for s in slopes)
    assert gm.ad_gradient("sine", np.array([0.31]), np.array([0.47]), KU, KV)[0].dtype == np.float64
    assert not jax.config.jax_enable_x64          # the float64 switch was a context, not global


def test_crease_values_rejects_a_bad_step():
    with pytest.raises(ValueError, match="eps must be a positive finite number, got -1"):
        gm.crease_values(eps=-1.0)
    with pytest.raises(ValueError, match="height_field must be one of"):
        gm.ad_gradient("bumps", np.array([0.1]), np.array([0.1]), KU, KV)


# --- AD and the exact gradient through one compiler ---------------------------------------------

@pytest.mark.parametrize("field", gm.FIELDS)
def test_the_xla_exact_gradient_is_the_exact_gradient(field):
    """What `same_compiler_times` times as "exact" computes the exact gradient (the numba one)."""
    rng = np.random.default_rng(7)
    u, v = rng.random(257), rng.random(257)
    got = gm.xla_exact_gradient(field, u, v, KU, KV)
    want = pointwise.exact_gradient(field, u, v, KU, KV)
    for g, w in zip(got, want):
        assert np.allclose(g, w, rtol=1e-13, atol=1e-13)


def test_same_compiler_times_report_each_side_and_their_ratio(monkeypatch):
    u = v = np.linspace(0.1, 0.9, 64)
    fast = gm.same_compiler_times(u, v, rounds=3, fields_=("rings",))["rings"]
    assert fast["exact"] > 0 and fast["ad"] > 0 and fast["numba"] > 0
    assert fast["ratio"] == fast["ad"] / fast["exact"] and fast["compiler"] == fast["exact"] / fast["numba"]
    # A planted slow AD (5 ms a call, the exact gradient of 64 points takes microseconds) shows.
    real = gm.ad_gradient

    def slow(*args, **kwargs):
        time.sleep(0.005)
        return real(*args, **kwargs)
    monkeypatch.setattr(gm, "ad_gradient", slow)
    assert gm.same_compiler_times(u, v, rounds=3, fields_=("rings",))["rings"]["ratio"] > 5


@pytest.mark.parametrize("kwargs, match", [({"rounds": 0}, "^rounds"), ({"rounds": 2.0}, "^rounds"),
                                           ({"rounds": True}, "^rounds"), ({"fields_": ("waves",)}, "waves")])
def test_same_compiler_times_refuses_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        gm.same_compiler_times(np.zeros(4), np.zeros(4), **kwargs)
