"""lab/_checks.py, the lab's argument checks, at the edges of what they accept and of what their
messages show: values of every length about the cut of `shown`, integers about the size Python
refuses to print, integer arrays reaching each end of their interval."""

from __future__ import annotations

import re
import sys

import numpy as np
import pytest

from lab import _checks
from renderer.validate import InvalidType, InvalidValue

RNG = np.random.default_rng(20261125)


@pytest.mark.parametrize("limit", [60, 80, int(RNG.integers(5, 200))])
def test_a_value_is_shown_whole_up_to_the_limit_and_cut_there_beyond(limit):
    for length in (limit - 1, limit, limit + 1, limit + 2, int(RNG.integers(limit + 3, 4 * limit))):
        value = "".join(RNG.choice(list("abcdefghij"), length - 2))       # repr adds two quotes
        expect = repr(value)
        assert len(expect) == length
        got = _checks.shown(value, limit)
        if len(expect) <= limit:
            assert got == f"str {expect}", (limit, length, got)
        else:
            assert got == f"str {expect[:limit]}...", (limit, length, got)
    assert _checks.shown("x" * 200).endswith("x" * 78 + "...")                 # the default cut: 80


def test_an_integer_too_long_to_print_is_shown_by_its_size():
    """Python refuses str() of an int over `sys.get_int_max_str_digits()` digits (about 3.32 bits a
    digit): such an int, and any of more than 3 bits a digit, is shown by its bit count."""
    limit = sys.get_int_max_str_digits()
    for bits in (int(3.5 * limit), 4 * limit, 10 * limit, 3 * limit + 1):
        assert _checks.shown(1 << (bits - 1)) == f"an integer of {bits:,} bits"
    assert _checks.shown(12345) == "int 12345"
    assert _checks.shown((1 << (3 * limit - 1)) + 1) == f"int {(1 << (3 * limit - 1)) + 1}"[:84] + "..."


def test_integer_arrays_take_both_ends_and_refuse_one_past_either():
    for _ in range(20):
        low, high = sorted(int(x) for x in RNG.integers(-10**6, 10**6, size=2))
        inside = np.array([low, high, (low + high) // 2], dtype=RNG.choice([np.int32, np.int64]))
        np.testing.assert_array_equal(_checks.integers("n", inside, low, high), inside)
        for wrong in (low - 1, high + 1):
            with pytest.raises(InvalidValue, match=rf"got {wrong} at flat index 1"):
                _checks.integers("n", np.array([low, wrong]), low, high)


@pytest.mark.parametrize("check, value", [(lambda v: _checks.integers("n", v, 0, 9), [0.5] * 100),
                                          (lambda v: _checks.numbers_array("n", v), ["x"] * 100)])
def test_a_wrong_kind_of_array_is_shown_cut_at_60_characters(check, value):
    with pytest.raises(InvalidType) as info:
        check(value)
    shown = str(info.value).split("got ", 1)[1]
    assert shown.startswith(f"list [{value[0]!r}, ") and shown.endswith("...") and len(shown) == len("list ") + 60 + 3


def test_chart_points_refuse_either_coordinate_off_the_chart_and_name_only_the_two_that_broadcast():
    for _ in range(10):
        inside = RNG.uniform(0.0, 1.0, size=4)
        outside = float(RNG.choice([-1e-9, 1 + 1e-9, RNG.uniform(1.0, 5.0), -RNG.uniform(0.0, 5.0)]))
        for name, args in (("uu", (np.append(inside, outside), inside[:1])), ("vv", (inside[:1], np.append(inside, outside)))):
            with pytest.raises(InvalidValue, match=rf"^{name} must be"):
                _checks.chart_points(*args, 1.0, 2.0)
    with pytest.raises(InvalidValue, match=r"^uu, vv must broadcast to one shape, got uu \(2,\), vv \(3,\)$"):
        _checks.chart_points(np.zeros(2), np.zeros(3), 1.0, 2.0)


def test_an_integer_is_taken_as_python_numpy_or_0_d_array_and_a_seed_from_0():
    for value in (7, np.int16(7), np.uint64(7), np.array(7), np.array(7, dtype=np.int8)):
        assert _checks.integer("n", value, 0, 9) == 7 and type(_checks.integer("n", value, 0, 9)) is int
    assert _checks.seed("seed", 0) == 0 and _checks.seed("seed", _checks.MAX_SEED) == _checks.MAX_SEED
    for value in (np.array([7]), True, 7.0, "7"):
        with pytest.raises(InvalidType, match=r"^n must be an integer in \[0, 9\]"):
            _checks.integer("n", value, 0, 9)
    for value in (-1, _checks.MAX_SEED + 1):
        with pytest.raises(InvalidValue, match=r"^seed must be an integer in \[0, 2\*\*64 - 1\]"):
            _checks.seed("seed", value)


@pytest.mark.parametrize("high, reads", [(9, "9"), (2**24, "16777216"), (2**32 - 1, "4294967295"),
                                         (2**32, "4294967296"), (2**40, "1099511627776"), (2**40 - 1, "2**40 - 1"), (2**33 - 1, "2**33 - 1"),
                                         (2**64 - 1, "2**64 - 1"), (2**64, "18446744073709551616")])
def test_the_accepted_interval_reads_as_written(high, reads):
    with pytest.raises(InvalidValue, match=rf"^n must be an integer in \[0, {re.escape(reads)}\], got -1$"):
        _checks.integer("n", -1, 0, high)


def test_an_out_of_range_integer_is_printed_whole_up_to_64_bits():
    for value, reads in ((2**63, "9223372036854775808"), (2**64 - 1, "18446744073709551615"),
                         (2**64, "int 18446744073709551616"), (-(2**64), "int -18446744073709551616")):
        with pytest.raises(InvalidValue, match=rf", got {reads}$"):
            _checks.integer("n", value, 0, 9)
