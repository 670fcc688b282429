"""Deterministic sine and atan2: the same IEEE operations in numpy and in JavaScript.

Why.  The central-difference quotient (h(u + eps) - h(u - eps)) / (2 eps)
amplifies the last bit of each value of h by 1/eps.  Two correct libraries
disagree in that bit often: on this project's machines V8's ``Math.sin``
differs from glibc's ``sin`` (which numpy calls) for about 3 % of arguments,
``Math.atan2`` for 13 % and ``Math.hypot`` for 39 %.  At eps = 1e-10 that is a
1e-7 difference in the image, and the §4 simulator could not be checked
against this renderer.  So the values that the quotient amplifies, the chart
(u, v) and h itself, are computed by the functions below, which use only
+, -, *, / , sqrt and floor: operations IEEE 754 rounds exactly, so numpy and
``renderer/js/detmath.js`` (the same algorithm, operation for operation) give
the same bits on every platform.

How.  The algorithms are those of Sun's fdlibm as kept in FreeBSD's msun
(``e_rem_pio2.c`` medium path, ``k_sin.c``, ``k_cos.c``, ``s_atan.c``,
``e_atan2.c``), vectorised: every branch is computed and the right one
selected.  Error below one ulp (checked against mpmath in tests/test_detmath.py)
for |x| < 2^20 pi/2, about 1.6e6; beyond that the argument reduction loses
accuracy gradually but stays deterministic.
"""

from __future__ import annotations

import numpy as np

__all__ = ["sin", "atan2", "REDUCTION_LIMIT"]

#: |x| below which `sin` is accurate to within one ulp (2^20 pi / 2).
REDUCTION_LIMIT = 2.0**20 * np.pi / 2

# pi/2 split for Cody-Waite reduction (e_rem_pio2.c): pio2_1 has 33 bits, so
# n * pio2_1 is exact for |n| < 2^20.
_INVPIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21

# k_sin.c and k_cos.c minimax coefficients on [-pi/4, pi/4].
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11

# s_atan.c: atan of the interval anchors 0.5, 1, 1.5, inf (hi + lo) and the
# odd polynomial's coefficients.
_ATANHI = np.array([4.63647609000806093515e-01, 7.85398163397448278999e-01,
                    9.82793723247329054082e-01, 1.57079632679489655800e+00])
_ATANLO = np.array([2.26987774529616870924e-17, 3.06161699786838301793e-17,
                    1.39033110312309984516e-17, 6.12323399573676603587e-17])
_AT = (3.33333333333329318027e-01, -1.99999999998764832476e-01, 1.42857142725034663711e-01,
       -1.11111104054623557880e-01, 9.09088713343650656196e-02, -7.69187620504482999495e-02,
       6.66107313738753120669e-02, -5.83357013379057348645e-02, 4.97687799461593236017e-02,
       -3.65315727442169155270e-02, 1.62858201153657823623e-02)
_PI = 3.1415926535897931160e+00
_PI_LO = 1.2246467991473531772e-16
_PI_O_2 = 1.5707963267948965580e+00


def _kernels(x, y):
    """k_sin.c and k_cos.c on the reduced argument x + y, sharing z = x^2 and z^2.

    Computed in place on a few temporaries (a quarter faster than one new
    array per operation); each line's comment is the expression of the C
    source it evaluates, in the same order.  ``x``, ``y``: float64 arrays of
    one shape (at least 1-d), not written to.
    """
    mul = np.multiply
    z = x * x
    w = z * z
    # r = S2 + z*(S3 + z*S4) + (z*w)*(S5 + z*S6)
    r = z * _S4
    r += _S3
    r *= z
    r += _S2
    a = z * _S6
    a += _S5
    b = z * w
    a *= b
    r += a
    # s = x - ((z*(0.5*y - v*r) - y) - v*S1), v = z*x
    v = mul(z, x, out=b)
    r *= v
    s = mul(y, 0.5, out=a)
    s -= r
    s *= z
    s -= y
    v *= _S1
    s -= v
    np.subtract(x, s, out=s)
    # r = z*(C1 + z*(C2 + z*C3)) + (w*w)*(C4 + z*(C5 + z*C6))
    mul(z, _C3, out=r)
    r += _C2
    r *= z
    r += _C1
    r *= z
    b = mul(z, _C6, out=v)
    b += _C5
    b *= z
    b += _C4
    w *= w
    b *= w
    r += b
    # c = (1 - hz) + (((1 - (1 - hz)) - hz) + (z*r - x*y)), hz = 0.5*z
    hz = mul(z, 0.5, out=w)
    one_hz = np.subtract(1.0, hz)
    r *= z
    r -= mul(x, y, out=b)
    c = np.subtract(1.0, one_hz, out=z)
    c -= hz
    c += r
    c += one_hz                                   # IEEE addition commutes exactly
    return s, c


def sin(x):
    """Deterministic sine of float64 ``x`` (array or scalar), in radians.

    Returns float64 of the shape of ``x``.  Bit-identical to
    ``det_sin`` of renderer/js/detmath.js.  NaN for inf or NaN.
    """
    x = np.asarray(x, dtype=np.float64)
    scalar = x.ndim == 0
    x = x.reshape(1) if scalar else x
    with np.errstate(invalid="ignore"):           # inf and NaN give NaN, quietly
        # Cody-Waite reduction, x = fn pi/2 + (y0 + y1) (e_rem_pio2.c, medium path),
        # in place; the comments are the C expressions.
        fn = x * _INVPIO2                         # fn = floor(x * invpio2 + 0.5)
        fn += 0.5
        np.floor(fn, out=fn)
        t = fn * _PIO2_1                          # t = x - fn * pio2_1
        np.subtract(x, t, out=t)
        w = fn * _PIO2_2                          # w = fn * pio2_2
        r = t - w                                 # r = t - w
        a = t - r                                 # w = fn * pio2_2t - ((t - r) - w)
        a -= w
        w2 = fn * _PIO2_2T
        w2 -= a
        y0 = np.subtract(r, w2, out=t)            # y0 = r - w
        y1 = np.subtract(r, y0, out=r)            # y1 = (r - y0) - w
        y1 -= w2
        # Quadrant q = fn mod 4, exactly (fn is an integer): sin, cos, -sin, -cos.
        q = np.multiply(fn, 0.25, out=a)
        np.floor(q, out=q)
        q *= 4.0
        np.subtract(fn, q, out=q)
        s, c = _kernels(y0, y1)
        out = np.where((q == 1.0) | (q == 3.0), c, s)
        out = np.where(q >= 2.0, -out, out)
    return float(out[0]) if scalar else out


# The interval reduction of s_atan.c, t -> (a t + b) / (c t + d), one row per
# interval: [0, 7/16) none, [7/16, 11/16) (2t - 1)/(2 + t), [11/16, 19/16)
# (t - 1)/(t + 1), [19/16, 39/16) (t - 1.5)/(1 + 1.5 t), beyond -1/t.  With
# these coefficients each row performs exactly the operations of the C source
# (multiplying by 1, adding 0), so the result is the same bits.
_ATAN_BREAKS = np.array([0.4375, 0.6875, 1.1875, 2.4375])
_ATAN_MOBIUS = tuple(np.array(col) for col in zip(
    (1.0, 0.0, 0.0, 1.0), (2.0, -1.0, 1.0, 2.0), (1.0, -1.0, 1.0, 1.0), (1.0, -1.5, 1.5, 1.0),
    (0.0, -1.0, 1.0, 0.0)))
_ATANHI_ROW = np.concatenate([[0.0], _ATANHI])
_ATANLO_ROW = np.concatenate([[0.0], _ATANLO])


def _atan_nonneg(t, finite=False):
    """atan of t >= 0 (s_atan.c, with the interval reduction).

    ``finite``: the caller knows t has no inf (skips the -1/inf fix-up).
    """
    if t.ndim == 0:                               # in-place steps need an array
        return _atan_nonneg(t.reshape(1), finite).reshape(())
    # The interval of t: the number of breaks <= t (t is never NaN here).
    row = (t >= _ATAN_BREAKS[0]).view(np.uint8)
    for brk in _ATAN_BREAKS[1:]:
        row = row + (t >= brk).view(np.uint8)
    a, b, c, d = (np.take(col, row) for col in _ATAN_MOBIUS)
    with np.errstate(divide="ignore", invalid="ignore"):
        a *= t                                    # tr = (a t + b) / (c t + d)
        a += b
        c *= t
        c += d
        tr = np.divide(a, c, out=a)
    if not finite:
        tr = np.where(t == np.inf, -0.0, tr)      # -1/inf, where 0 * inf would give NaN
    z = tr * tr
    w = z * z
    at = _AT
    # s1 = z*(at0 + w*(at2 + w*(at4 + w*(at6 + w*(at8 + w*at10))))), Horner in place
    s1 = w * at[10]
    for coef in (at[8], at[6], at[4], at[2]):
        s1 += coef
        s1 *= w
    s1 += at[0]
    s1 *= z
    # s2 = w*(at1 + w*(at3 + w*(at5 + w*(at7 + w*at9))))
    s2 = np.multiply(w, at[9], out=b)
    for coef in (at[7], at[5], at[3], at[1]):
        s2 += coef
        s2 *= w
    s1 += s2                                      # p = tr * (s1 + s2)
    p = np.multiply(s1, tr, out=s1)
    # row 0: tr - p; else atanhi - ((p - atanlo) - tr)
    reduced = np.take(_ATANLO_ROW, row)
    np.subtract(p, reduced, out=reduced)
    reduced -= tr
    np.subtract(np.take(_ATANHI_ROW, row), reduced, out=reduced)
    return np.where(row == 0, np.subtract(tr, p, out=p), reduced)


def atan2(y, x):
    """Deterministic atan2(y, x) of float64 arrays or scalars, in (-pi, pi].

    The quadrant logic of e_atan2.c on atan(|y / x|); signed zeros as in C.
    Bit-identical to ``detmath.atan2`` of renderer/js/detmath.js.
    """
    y = np.asarray(y, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64)
    y, x = np.broadcast_arrays(y, x)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        ratio = np.abs(y / x)
    if np.isfinite(ratio).all() and (x != 0.0).all():
        # The common case, no NaN, no axis, no origin: e_atan2.c's quadrant
        # rule is the sign of y on z (x > 0) or on pi - (z - pi_lo) (x < 0).
        # z >= +0 is never -0, and (z - pi_lo) - pi = -(pi - (z - pi_lo))
        # exactly, so copysign gives the general path's bits (below).
        z = _atan_nonneg(ratio, finite=True)
        out = np.copysign(np.where(np.signbit(x), _PI - (z - _PI_LO), z), y)
        return out if out.ndim else float(out)
    z = _atan_nonneg(np.where(np.isnan(ratio), 0.0, ratio))
    ny = np.signbit(y)
    nx = np.signbit(x)
    # x > 0 (or +0 with y != 0 handled below): +-z; x < 0: +-(pi - (z - pi_lo)).
    out = np.where(nx, np.where(ny, (z - _PI_LO) - _PI, _PI - (z - _PI_LO)), np.where(ny, -z, z))
    on_axis = (x == 0.0) & (y != 0.0)
    out = np.where(on_axis, np.where(ny, -_PI_O_2, _PI_O_2), out)
    origin = (x == 0.0) & (y == 0.0)
    out = np.where(origin, np.where(nx, np.where(ny, -_PI, _PI), np.where(ny, -0.0, 0.0)), out)
    out = np.where(np.isnan(x) | np.isnan(y), np.nan, out)
    return out if out.ndim else float(out)
