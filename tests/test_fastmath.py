"""lab.fastmath: the ulp count against an independent mpmath count, its reference, planted
wrong functions, the tables' structure, and the U-curve floor's quotient against the kernel's.

Nothing here asserts how accurate a library's sin or pow is on this CPU (numpy's SIMD
paths differ per CPU): the backends are checked for shape and for a sine good to far
fewer digits than any libm has, and the counts on functions the test builds itself.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from lab import fastmath as fm
from renderer import backends, pointwise
from renderer.ucurve import DEFAULT_STEPS, SEED_FREQUENCIES, SEED_POINT
from tests.jsnode import in_ci

RNG = np.random.default_rng(12)
#: The functions as mpmath defines them (the library's references call mpmath.libmp's directly).
MP = {"sin": mpmath.sin, "cos": mpmath.cos, "atan2": mpmath.atan2, "acos": mpmath.acos, "pow": mpmath.power}
ARGUMENTS = fm.arguments        # the real one, for `few` while a test plants another


def mp_ulps(y, function, *args):
    """|y - t| / ulp(t) computed in mpmath at 60 digits, the definition written out."""
    with mpmath.workdps(60):
        t = MP[function](*(mpmath.mpf(float(a)) for a in args))
        e = -1074 if t == 0 else max(int(mpmath.floor(mpmath.log(abs(t), 2))), -1022) - 52
        return float(abs(mpmath.mpf(float(y)) - t) / mpmath.mpf(2) ** e)


def few(function, count=40, hard=40):
    """A few sampled points and a spread of the hard points of ``function``."""
    args, n_hard = ARGUMENTS(function, count)
    pick = np.concatenate([np.arange(count), count + np.linspace(0, n_hard - 1, hard).astype(int)])
    return tuple(a[pick] for a in args)


@pytest.mark.parametrize("function", fm.FUNCTIONS)
def test_the_reference_agrees_with_one_at_twice_the_digits(function, monkeypatch):
    args = few(function)
    hi, e, rest = fm.reference(function, *args)
    monkeypatch.setattr(fm, "DIGITS", 2 * fm.DIGITS)
    hi2, e2, rest2 = fm.reference(function, *args)
    np.testing.assert_array_equal(hi, hi2)
    np.testing.assert_array_equal(e, e2)
    assert np.max(np.abs(rest - rest2)) < 1e-15       # rest is rounded once, to 2^-54 ulp
    assert np.all(np.abs(rest) <= 0.5)


def test_the_reference_rounds_sin_pi_correctly():
    # sin(fl(pi)) = pi - fl(pi) (1 - ...): its correctly rounded value is 1.2246467991473532e-16
    # (Muller, Handbook of Floating-Point Arithmetic, the classic range-reduction example).
    hi, e, rest = fm.reference("sin", np.array([math.pi]))
    assert hi[0] == 1.2246467991473532e-16
    assert e[0] == math.frexp(hi[0])[1] - 1 - 52


@pytest.mark.parametrize("seed, count", [(fm.SEED, 2000), (12345, 501)])
def test_the_arguments_are_the_sets_their_docstring_names(seed, count):
    """`fm.arguments`, read against its docstring: the random part in each function's range and the
    hard points exactly the sets it lists (at the book's seed and at another)."""
    (x,), hard = fm.arguments("sin", count, seed)
    quarter = math.pi / 2
    assert 0 <= x[:count].min() and x[:count].max() <= fm.max_angle() and x.size == count + hard
    m = np.round(x[count:] / quarter)
    assert np.all(np.abs(x[count:] - m * quarter) <= np.spacing(x[count:]))      # m pi/2 and its neighbours
    assert np.unique(m, return_counts=True)[1].tolist() == [3] * int(fm.max_angle() / quarter)
    (y, x), hard = fm.arguments("atan2", count, seed)
    half = count // 2
    assert np.all(np.hypot(y[:half], x[:half]) <= 1 + 1e-15)                     # (N_y, N_x) of unit N
    assert np.all(y[half:count] >= 0) and np.allclose(np.hypot(y[half:count], x[half:count]), 1, rtol=0, atol=1e-15)
    tiny = [2.0**-j for j in range(1, 61)]
    assert set(zip(y[count:], x[count:])) == ({(t, -1.0) for t in tiny} | {(-t, -1.0) for t in tiny}
                                              | {(t, 1.0) for t in tiny})
    (x,), hard = fm.arguments("acos", count, seed)
    assert np.all(np.abs(x[:count]) <= 1)
    assert set(x[count:]) == {s * (1 - j * 2.0**-53) for j in range(1000) for s in (1, -1)}
    (base, exponent), hard = fm.arguments("pow", count, seed)
    assert np.all((exponent >= 1) & (exponent <= 1e4) & (base >= 0) & (base <= 1))
    assert np.all(exponent * np.log2(base) > fm.MIN_POWER_LOG2)                  # a normal power
    assert set(base[count:]) == {1 - 2.0**-j for j in range(1, 54)} | {0.999}
    assert np.allclose(np.unique(exponent[count:]), np.geomspace(1, 1e4, 41), rtol=1e-12, atol=0)


def test_the_reference_counts_in_the_subnormal_ulp_below_the_normal_range():
    """ulp(t) is 2^-1074 for every t below 2^-1021 (subnormals and the smallest binade of normals alike),
    2^(floor(log2 |t|) - 52) above; sin x rounds to x there (sin x = x - x^3/6 ...)."""
    tiny = np.array([5e-324, 1e-310, 2.0**-1022, 2.0**-1021, -1e-310])
    hi, e, rest = fm.reference("sin", tiny)
    np.testing.assert_array_equal(hi, tiny)
    assert e.tolist() == [-1074, -1074, -1074, -1073, -1074] and np.all(np.abs(rest) < 1e-300)


@pytest.mark.parametrize("function", fm.FUNCTIONS)
@pytest.mark.parametrize("wrong", ["+1 ulp", "+2 ulps", "1e-10 relative"])
def test_planted_wrong_functions_are_counted_as_mpmath_counts_them(function, wrong):
    args = few(function, 30, 30)
    with mpmath.workdps(60):
        true = [MP[function](*(mpmath.mpf(float(a)) for a in p)) for p in zip(*args)]
        rounded = np.array([float(t) for t in true])
    if wrong == "1e-10 relative":
        y = rounded * (1 + 1e-10)
    else:
        y = np.nextafter(rounded, np.inf)
        if wrong == "+2 ulps":
            y = np.nextafter(y, np.inf)
    got = fm.ulps(y, *fm.reference(function, *args))
    expected = np.array([mp_ulps(a, function, *p) for a, p in zip(y, zip(*args))])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)
    nonzero = rounded != 0
    # One step of y's spacing is 1 ulp of t, or 1/2 or 2 of them at a power of 2, and t is
    # within 1/2 ulp of its rounding.
    if wrong == "+1 ulp":
        assert 1.0 <= got.max() <= 2.5
    elif wrong == "+2 ulps":
        assert got.min() >= 0.5 and got.max() >= 2.0
    else:   # 1e-10 |t| over a spacing between 2^-53 |t| and 2^-52 |t|: 4.5e5 to 9e5 ulps
        assert np.all((got[nonzero] > 4.5e5) & (got[nonzero] < 9.1e5))


def test_a_correctly_rounded_value_is_within_half_an_ulp_and_subnormals_count_in_their_spacing():
    args = few("sin")
    hi, e, rest = fm.reference("sin", *args)
    assert fm.ulps(hi, hi, e, rest).max() <= 0.5
    # t = 0.3 * 2^-1074 (below the smallest subnormal): 0 is off by 0.3 ulp, 2^-1074 by 0.7.
    with mpmath.workdps(60):
        t = mpmath.mpf(0.3) * mpmath.mpf(2) ** -1074
        r = float(mpmath.ldexp(t, 1074))
    got = fm.ulps(np.array([0.0, 2.0**-1074]), np.zeros(2), np.full(2, -1074), np.full(2, r))
    np.testing.assert_allclose(got, [0.3, 0.7], rtol=1e-15)


def plant(monkeypatch, functions):
    """Add a backend "planted" holding ``functions``."""
    real = fm._functions
    monkeypatch.setattr(fm, "BACKENDS", fm.BACKENDS + ("planted",))
    monkeypatch.setattr(fm, "_functions", lambda name: functions if name == "planted" else real(name))


def rounded(function):
    """``function`` correctly rounded, from mpmath (a backend with every count <= 0.5)."""
    def run(*args):
        with mpmath.workdps(60):
            return np.array([float(MP[function](*(mpmath.mpf(float(a)) for a in p))) for p in zip(*args)])
    return run


def test_the_table_reports_a_planted_backend(monkeypatch):
    exact = {f: rounded(f) for f in fm.FUNCTIONS}
    wrong = dict(exact, sin=lambda x: np.nextafter(np.nextafter(exact["sin"](x), np.inf), np.inf))
    plant(monkeypatch, wrong)
    monkeypatch.setattr(fm, "arguments", lambda f, count, seed: (few(f, count, 20), 20))
    table = fm._ulp_table(30, fm.SEED, {"planted": "0"})
    assert table["backends"] == ["planted"] and table["missing"] == list(fm.BACKENDS[:-1])
    errors = table["errors"]["planted"]
    assert list(errors) == list(fm.FUNCTIONS)
    assert errors["sin"]["max"] >= 1.5 and errors["sin"]["hard_max"] >= 1.5
    for f in fm.FUNCTIONS[1:]:
        assert errors[f]["quantile"] <= errors[f]["max"] <= 0.5 and errors[f]["hard_max"] <= 0.5
        assert (errors[f]["points"], errors[f]["hard_points"]) == (30, 20)
    assert table["flushes"] == {"planted": False}


def test_the_build_table_has_every_available_backend_and_function():
    table = fm.ulp_table(count=64)
    assert table["backends"] == list(fm.available()) and {"numba", "numpy", "jax"} <= set(table["backends"])
    assert sorted(table["backends"] + table["missing"]) == sorted(fm.BACKENDS)
    assert table["backends"] == [b for b in fm.BACKENDS if b in table["backends"]]
    for name in table["backends"]:
        for f in fm.FUNCTIONS:
            e = table["errors"][name][f]
            assert 0.0 <= e["quantile"] <= e["max"] < math.inf and e["points"] == 64


def test_with_the_kernels_sine_the_quotient_is_the_kernels():
    (u, v), (k_u, k_v) = SEED_POINT, SEED_FREQUENCIES
    steps = np.concatenate([DEFAULT_STEPS, [0.25, 0.7, 0.69]])       # 0.7, 0.69: u + eps wraps
    ours = fm.central_differences("numba", steps, u, v, k_u, k_v)
    kernel = np.array([pointwise.central_gradient("sine", u, v, k_u, k_v, e)[0] for e in steps])
    np.testing.assert_array_equal(ours, kernel)


def test_the_floor_follows_the_sine(monkeypatch):
    libm = fm._functions("numba")
    # Off by up to 1e-10 relative, differently at neighbouring arguments (a uniform factor
    # would scale the quotient and cancel out of the difference).
    off = dict(libm, sin=lambda x: libm["sin"](x) * (1 + 1e-10 * np.cos(x * 2.0**30)))
    plant(monkeypatch, off)
    out = fm._floors({"numba": "0", "planted": "0"})
    good, bad = out["floors"]["numba"], out["floors"]["planted"]
    assert out["backends"] == ["numba", "planted"] and bad["differ"] > 0 and good["differ"] == 0
    # Rounding coefficient ~1e-10 |h| instead of ~u_round |h|.
    assert bad["error"] > 1e3 * good["error"] and bad["fitted_roundoff"] > 1e3 * good["fitted_roundoff"]
    assert bad["fitted_step"] > good["fitted_step"]
    assert good["step"] in DEFAULT_STEPS and bad["step"] in DEFAULT_STEPS
    # The fitted step minimises the fitted model E = A eps^2 + B/eps: there 2 A eps^3 = B, so E eps = 3B/2.
    for f in (good, bad):
        assert f["fitted_error"] * f["fitted_step"] == pytest.approx(1.5 * f["fitted_roundoff"], rel=1e-9, abs=0)
    assert 0.5 < good["fitted_step"] / out["model"]["step"] < 2          # near the error model's optimum


@pytest.mark.parametrize("call, match", [
    (lambda: fm.backend("cuda"), "backend"), (lambda: fm.arguments("tan"), "function"),
    (lambda: fm.arguments("sin", 0), "count"), (lambda: fm.reference("sin", np.zeros(2), np.zeros(3)), "shapes"),
])
def test_bad_input_names_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_a_missing_drjit_is_refused_by_name(monkeypatch):
    monkeypatch.setattr(fm, "_functions", lambda name: None if name == "drjit" else {})
    assert "drjit" not in fm.available()
    with pytest.raises(ValueError, match=r"^backend 'drjit' is not available on this machine \(\S.*\); available"):
        fm.backend("drjit")


@pytest.fixture
def drjit_backend():
    if "drjit" not in fm.available():
        message = backends.missing("drjit") or "Dr.Jit's LLVM backend is not available"
        if in_ci():
            pytest.fail(message + " (CI=true: this test may not skip)")
        pytest.skip(message)
    return fm.backend("drjit")


def test_drjit_computes_float64_and_its_quotient_is_near_libms(drjit_backend):
    x = RNG.uniform(0.0, 10.0, 100)
    for f in fm.FUNCTIONS:
        args = (x / 10.0, x) if f == "pow" else (x, x + 1.0) if f == "atan2" else (x / 10.0,) if f == "acos" else (x,)
        y = drjit_backend[f](*args)
        assert y.dtype == np.float64 and y.shape == x.shape
        # float32 would be off by ~1e-7: far above any double library's few ulps.
        np.testing.assert_allclose(y, fm.backend("numba")[f](*args), rtol=1e-12, atol=1e-300)
    (u, v), (k_u, k_v) = SEED_POINT, SEED_FREQUENCIES
    steps = DEFAULT_STEPS[DEFAULT_STEPS > 1e-6]
    np.testing.assert_allclose(fm.central_differences("drjit", steps, u, v, k_u, k_v),
                               fm.central_differences("numba", steps, u, v, k_u, k_v), rtol=1e-8)


def test_the_sampled_angles_follow_the_registered_fields():
    """`max_angle` is the largest phase of the fields' sines and cosines: the built-in fields' 2 pi k
    (rings), and 3 pi k for a field sin(3 pi k_u u) registered for this test; the sample reaches it."""
    import sympy as sp

    from renderer import formulas as F
    from renderer.scene import MAX_FREQUENCY
    assert fm.max_angle() == pytest.approx(2 * math.pi * MAX_FREQUENCY, rel=1e-15, abs=0)
    F.register(F.HeightField("triple", sp.sin(3 * sp.pi * F.k_u * F.u)))
    try:
        assert fm.max_angle() == pytest.approx(3 * math.pi * MAX_FREQUENCY, rel=1e-15, abs=0)
        (x,), hard = fm.arguments("sin", count=1000, seed=1)
        assert 2 * math.pi * MAX_FREQUENCY < x.max() <= fm.max_angle() * (1 + 1e-15)
    finally:
        F.FIELDS.pop("triple", None)
