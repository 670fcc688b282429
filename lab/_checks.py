"""The lab's argument checks beyond `renderer.validate`'s kinds, with the same errors.

Each public function of lab/ checks its arguments once, at its entry, with these or with
`renderer.validate`'s (`real`, `real_array`, `positive_int`, `choice`, `flag`, `steps`):
one `renderer.validate.InvalidType` (a TypeError) or `renderer.validate.InvalidValue` (a
ValueError) naming the parameter, the value (cut at 80 characters) and what is accepted.
Internal calls between lab functions go to their unchecked forms (no check twice).
"""

from __future__ import annotations

import numbers
import sys

import numpy as np

from renderer.pointwise import MIN_STEP
from renderer.render import MAX_PIXELS
from renderer.scene import FREQUENCY, UNIT
from renderer.validate import InvalidType, InvalidValue, real, real_array

#: Largest seed accepted (a 64-bit unsigned integer, as numpy's generators take it).
MAX_SEED = 2**64 - 1
#: Largest count of samples, pixels, trials or repeats accepted: 2^24.
MAX_COUNT = 2**24
#: Largest side of a square frame accepted: `renderer.render.MAX_PIXELS` holds 4096 x 4096.
MAX_SQUARE = int(MAX_PIXELS**0.5)
#: The mpmath working precision accepted, decimal digits: a double-double reference (hi, lo)
#: needs 32; above 1000 a reference is slower than any measurement here needs.
DIGITS = (32, 1000)
#: A step of a difference quotient (chart units): [`renderer.pointwise.MIN_STEP`, 1).
STEP = dict(low=MIN_STEP, high=1.0, high_open=True)


def shown(value, limit=80):
    """``value`` for a message: its type and repr, cut to ``limit`` characters."""
    if isinstance(value, int) and value.bit_length() > 3 * sys.get_int_max_str_digits():
        return f"an integer of {value.bit_length():,} bits"
    text = " ".join(repr(value).split())
    return f"{type(value).__name__} {text if len(text) <= limit else text[:limit] + '...'}"


def integer(name, value, low, high):
    """``value`` as an int in [low, high]: a Python or numpy integer, not a bool or a float."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    # A bound of 2**k - 1 past 32 bits reads as such (MAX_SEED: 2**64 - 1); any other, as digits.
    mersenne = high.bit_length() > 32 and high & (high + 1) == 0
    accepted = f"an integer in [{low}, {f'2**{high.bit_length()} - 1' if mersenne else high}]"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise InvalidType(f"{name} must be {accepted}, got {shown(value)}")
    n = int(value)
    if not low <= n <= high:
        raise InvalidValue(f"{name} must be {accepted}, got {shown(n) if n.bit_length() > 64 else n}")
    return n


def seed(name, value):
    """``value`` as a seed of `numpy.random.default_rng`: an integer in [0, `MAX_SEED`]."""
    return integer(name, value, 0, MAX_SEED)


def digits(name, value):
    """``value`` as an mpmath working precision: an integer in `DIGITS`."""
    return integer(name, value, *DIGITS)


def optional(check, name, value, *args, **kwargs):
    """None, or ``check(name, value, *args, **kwargs)``."""
    return None if value is None else check(name, value, *args, **kwargs)


def instance(name, value, kind, what):
    """``value`` if it is a ``kind`` (a class or tuple of classes), else InvalidType saying ``what``."""
    if not isinstance(value, kind):
        raise InvalidType(f"{name} must be {what}, got {shown(value)}")
    return value


def sequence(name, value, what):
    """``value`` as a non-empty tuple: a list or a tuple (not a string, a set or a dict), of ``what``."""
    if not isinstance(value, (list, tuple)):
        raise InvalidType(f"{name} must be a list or tuple of {what}, got {shown(value)}")
    if not value:
        raise InvalidValue(f"{name} must hold at least one ({what}), got {value!r}")
    return tuple(value)


def _array(value):
    """``np.asarray(value)``, or an object array where numpy cannot make one (a ragged list)."""
    try:
        return np.asarray(value)
    except (TypeError, ValueError):
        return np.asarray(None)


def numbers_array(name, value):
    """``value`` as a float64 array of real numbers, inf and NaN allowed (a value judged, not an input
    of a formula): any integer or floating dtype; not bool, complex, strings, objects or ragged lists."""
    a = _array(value)
    if a.dtype.kind not in "iuf":
        raise InvalidType(f"{name} must be real numbers (a scalar or an array), got {shown(value, 60)}")
    return a.astype(np.float64, copy=False)


def integers(name, value, low, high):
    """``value`` as an int64 array of integers in [low, high]: any integer dtype; not bool or float."""
    a = _array(value)
    if a.dtype.kind not in "iu":
        raise InvalidType(f"{name} must be integers in [{low}, {high}], got {shown(value, 60)}")
    bad = np.flatnonzero((a < low) | (a > high))
    if bad.size:
        raise InvalidValue(f"{name} must be integers in [{low}, {high}], got {a.flat[bad[0]]} at flat index {bad[0]}")
    return a.astype(np.int64)


def broadcast(names, *arrays):
    """``arrays`` broadcast to one shape, or InvalidValue naming their shapes."""
    try:
        return np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = ", ".join(f"{n} {np.shape(a)}" for n, a in zip(names, arrays))
        raise InvalidValue(f"{', '.join(names)} must broadcast to one shape, got {shapes}") from None


def chart_points(uu, vv, ku, kv, names=("uu", "vv", "ku", "kv")):
    """(uu, vv, ku, kv) checked: chart coordinates uu, vv, real arrays in [0, 1] that broadcast
    together (float64 arrays of the broadcast shape), and frequencies ku, kv, real numbers in
    (0, 1e3] (floats), as `renderer.Scene` accepts them."""
    uu, vv = broadcast(names[:2], real_array(names[0], uu, **UNIT), real_array(names[1], vv, **UNIT))
    return uu, vv, real(names[2], ku, **FREQUENCY), real(names[3], kv, **FREQUENCY)


def height_fields(name, fields_):
    """The height-field records of ``fields_`` (None: every registered field), a non-empty list or
    tuple of what `renderer.formulas.field` takes, each refused as ``name[i]``."""
    from renderer import formulas as F
    if fields_ is None:
        return tuple(F.FIELDS.values())
    return tuple(F.field(f, f"{name}[{i}]") for i, f in enumerate(sequence(name, fields_, "height fields")))
