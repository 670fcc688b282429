"""renderer.detmath: within one ulp of mpmath, and the same bits as its JavaScript twin."""

from __future__ import annotations

import subprocess

import mpmath
import numpy as np
import pytest

from renderer import detmath

from .jsnode import DRIVERS, require_tool, write_modules


def _ulps(got, ref):
    return np.abs(got - ref) / np.spacing(np.abs(ref))


@pytest.fixture(scope="module")
def args():
    rng = np.random.default_rng(20261121)
    a = np.concatenate([rng.uniform(-80.0, 80.0, 6000), rng.uniform(-detmath.REDUCTION_LIMIT,
                        detmath.REDUCTION_LIMIT, 1000), rng.uniform(-1.0, 1.0, 1000),
                        np.pi / 2 * np.arange(-40, 41), [0.0, -0.0, 1e-300, -1e-300, 5e-324]])
    b = np.concatenate([rng.normal(size=a.size - 86), np.zeros(81),
                        [1.0, -1.0, 0.0, -0.0, 3.0]])
    return a, b


def test_sin_within_one_ulp_of_mpmath(args):
    a, _ = args
    mpmath.mp.prec = 120
    ref = np.array([float(mpmath.sin(mpmath.mpf(float(x)))) for x in a])
    got = detmath.sin(a)
    nonzero = ref != 0.0
    assert _ulps(got[nonzero], ref[nonzero]).max() <= 1.0
    assert np.array_equal(got[~nonzero], ref[~nonzero])


def test_atan2_within_one_ulp_of_mpmath(args):
    a, b = args
    mpmath.mp.prec = 120
    ref = np.array([float(mpmath.atan2(mpmath.mpf(float(y)), mpmath.mpf(float(x)))) for y, x in zip(a, b)])
    got = detmath.atan2(a, b)
    # mpmath has no signed zero (atan2(-0, -1) is +pi there); C's signed-zero
    # results are checked against numpy below.
    nonzero = (ref != 0.0) & (a != 0.0)
    assert _ulps(got[nonzero], ref[nonzero]).max() <= 1.0


@pytest.mark.parametrize("y, x", [(0.0, 1.0), (-0.0, 1.0), (0.0, -1.0), (-0.0, -1.0), (1.0, 0.0),
                                  (-1.0, -0.0), (0.0, 0.0), (-0.0, -0.0), (0.0, -0.0), (1e-300, -1.0),
                                  (1.0, 1e-300), (np.inf, 1.0), (1.0, -np.inf)])
def test_atan2_signed_zeros_and_limits_match_c(y, x):
    got, want = detmath.atan2(y, x), np.arctan2(y, x)
    assert got == want and np.signbit(got) == np.signbit(want)


def test_atan2_fast_path_gives_the_general_paths_bits(args):
    """Finite ratios off the axes take a shorter path; one NaN in the array
    forces the general path on the same arguments, which must give the same bits.
    The general path with the quotient formed as y * (1 / x) instead of y / x
    (one more rounding, a different result for some arguments in any IEEE
    arithmetic) does not, so the check can fail."""
    a, b = args
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        keep = (b != 0.0) & np.isfinite(np.abs(a / b))
    y, x = a[keep], b[keep]
    fast = detmath.atan2(y, x)
    general = detmath.atan2(np.append(y, np.nan), np.append(x, 1.0))[:-1]
    assert np.array_equal(fast.view(np.int64), general.view(np.int64))
    with np.errstate(divide="ignore"):
        regrouped = detmath.atan2(np.append(y * (1.0 / x), np.nan), np.append(np.ones_like(x), 1.0))[:-1]
    assert not np.array_equal(regrouped.view(np.int64), general.view(np.int64))


def test_nan_propagates():
    assert np.isnan(detmath.sin(np.nan)) and np.isnan(detmath.sin(np.inf))
    assert np.isnan(detmath.atan2(np.nan, 1.0)) and np.isnan(detmath.atan2(1.0, np.nan))


def test_the_one_ulp_check_rejects_a_coarser_sine(args):
    a, _ = args
    ref = np.array([float(mpmath.sin(mpmath.mpf(float(x)))) for x in a[:2000]])
    coarse = np.float32(np.sin(a[:2000])).astype(np.float64)
    assert _ulps(coarse, ref).max() > 1.0


def test_javascript_twin_gives_the_same_bits(args, tmp_path):
    node = require_tool("node", "the detmath twin is checked under node")
    a, b = args
    modules = write_modules(tmp_path / "js")
    np.stack([a, b], axis=-1).astype("<f8").tofile(tmp_path / "args.f64")
    subprocess.run([node, str(DRIVERS / "detmath_driver.mjs"), str(modules), str(tmp_path / "args.f64"),
                    str(tmp_path / "out.f64")], check=True, timeout=120)
    out = np.fromfile(tmp_path / "out.f64", dtype="<f8").reshape(-1, 4)
    js_sin, js_atan2 = out.T[:2]         # columns 3-4: V8's own Math.sin, Math.atan2
    py_sin, py_atan2 = detmath.sin(a), detmath.atan2(a, b)
    assert np.array_equal(js_sin.view(np.int64), py_sin.view(np.int64))
    assert np.array_equal(js_atan2.view(np.int64), py_atan2.view(np.int64))
    # A twin that rounds its arguments differently (here: the sine one ulp
    # away) fails the comparison.  Whether V8's own Math.sin differs from
    # numpy's is the libraries' accident on this CPU: not asserted.
    off_by_an_ulp = detmath.sin(np.nextafter(a, np.inf))
    assert not np.array_equal(js_sin.view(np.int64), off_by_an_ulp.view(np.int64))


def _plain_sin(x, reassociate=False):
    """fdlibm's sine written as plain expressions, one new array per operation
    (the form of the C source and of renderer/js/detmath.js).  ``reassociate``
    is a wrong variant: one subtraction grouped differently."""
    s1, s2, s3, s4, s5, s6 = (detmath._S1, detmath._S2, detmath._S3, detmath._S4, detmath._S5,
                              detmath._S6)
    c1, c2, c3, c4, c5, c6 = (detmath._C1, detmath._C2, detmath._C3, detmath._C4, detmath._C5,
                              detmath._C6)
    fn = np.floor(x * detmath._INVPIO2 + 0.5)
    t = x - fn * detmath._PIO2_1
    w = fn * detmath._PIO2_2
    r = t - w
    w = fn * detmath._PIO2_2T - (t - (r + w) if reassociate else (t - r) - w)
    y0 = r - w
    y = (r - y0) - w
    q = fn - 4.0 * np.floor(fn * 0.25)
    z = y0 * y0
    w = z * z
    r = s2 + z * (s3 + z * s4) + z * w * (s5 + z * s6)
    v = z * y0
    s = y0 - ((z * (0.5 * y - v * r) - y) - v * s1)
    r = z * (c1 + z * (c2 + z * c3)) + w * w * (c4 + z * (c5 + z * c6))
    hz = 0.5 * z
    w = 1.0 - hz
    c = w + (((1.0 - w) - hz) + (z * r - y0 * y))
    out = np.where((q == 1.0) | (q == 3.0), c, s)
    return np.where(q >= 2.0, -out, out)


def test_in_place_sine_gives_the_plain_expressions_bits():
    """`detmath.sin` computes in place; it must be the same bits as the plain
    expressions, on 400,000 arguments over 300 decades; the check rejects a
    variant that groups one subtraction differently."""
    rng = np.random.default_rng(8)
    x = np.concatenate([rng.uniform(-100.0, 100.0, 200000),
                        rng.uniform(-1.0, 1.0, 200000) * 10.0 ** rng.integers(-300, 7, 200000),
                        [0.0, -0.0, 5e-324, -5e-324, np.inf, -np.inf, np.nan]])
    with np.errstate(invalid="ignore"):
        want = _plain_sin(x)
        wrong = _plain_sin(x, reassociate=True)
    got = detmath.sin(x)
    assert got.tobytes() == want.tobytes()
    assert wrong.tobytes() != want.tobytes()
    # Shapes and strides: 2-d, strided and broadcast inputs, and a scalar, unchanged.
    grid = rng.uniform(-20.0, 20.0, (30, 40))
    for a in (grid, grid[:, ::3], np.broadcast_to(grid[0], (5, 40))):
        before = a.copy()
        assert detmath.sin(a).tobytes() == _plain_sin(a).tobytes() and np.array_equal(a, before)
    assert isinstance(detmath.sin(2.5), float) and detmath.sin(2.5) == float(_plain_sin(np.array(2.5)))


def _plain_atan_nonneg(t, distribute=False):
    """s_atan.c on t >= 0 as plain expressions (one new array per operation),
    the interval found by searchsorted.  ``distribute`` is a wrong variant:
    tr (s1 + s2) computed as tr s1 + tr s2."""
    row = np.searchsorted(detmath._ATAN_BREAKS, t, side="right")
    a, b, c, d = (np.take(col, row) for col in detmath._ATAN_MOBIUS)
    with np.errstate(divide="ignore", invalid="ignore"):
        tr = (a * t + b) / (c * t + d)
    tr = np.where(t == np.inf, -0.0, tr)
    z = tr * tr
    w = z * z
    at = detmath._AT
    s1 = z * (at[0] + w * (at[2] + w * (at[4] + w * (at[6] + w * (at[8] + w * at[10])))))
    s2 = w * (at[1] + w * (at[3] + w * (at[5] + w * (at[7] + w * at[9]))))
    p = tr * s1 + tr * s2 if distribute else tr * (s1 + s2)
    reduced = np.take(detmath._ATANHI_ROW, row) - ((p - np.take(detmath._ATANLO_ROW, row)) - tr)
    return np.where(row == 0, tr - p, reduced)


def test_in_place_atan_gives_the_plain_expressions_bits():
    """`detmath._atan_nonneg` finds the interval by comparisons and works in
    place: the same bits as the plain expressions, break points included; the
    check rejects a variant that distributes one product over a sum."""
    rng = np.random.default_rng(9)
    breaks = detmath._ATAN_BREAKS
    t = np.concatenate([np.abs(rng.normal(size=200000)),
                        rng.uniform(0.0, 1.0, 200000) * 10.0 ** rng.integers(-300, 300, 200000),
                        breaks, np.nextafter(breaks, 0.0), np.nextafter(breaks, 9.0),
                        [0.0, 5e-324, 1e308, np.inf]])
    want = _plain_atan_nonneg(t)
    assert detmath._atan_nonneg(t).tobytes() == want.tobytes()
    finite = t[np.isfinite(t)]
    assert detmath._atan_nonneg(finite, finite=True).tobytes() == _plain_atan_nonneg(finite).tobytes()
    assert _plain_atan_nonneg(t, distribute=True).tobytes() != want.tobytes()
