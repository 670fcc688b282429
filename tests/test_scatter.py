"""renderer.render._put_rows: one np.put of records writes what 2-D fancy assignment writes."""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

render_module = importlib.import_module("renderer.render")


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 400), k=st.sampled_from([1, 2, 3]), seed=st.integers(0, 2**32 - 1),
       frac=st.floats(0.0, 1.0))
def test_put_rows_writes_the_fancy_assignment_bytes(n, k, seed, frac):
    rng = np.random.default_rng(seed)
    idx = np.flatnonzero(rng.random(n) < frac)
    rows = rng.standard_normal((idx.size, k))
    rows[rng.random(rows.shape) < 0.1] = -0.0                     # signed zeros survive
    want = rng.standard_normal((n, k))
    got = want.copy()
    want[idx] = rows
    render_module._put_rows(got, idx, rows)
    assert got.tobytes() == want.tobytes()


def test_put_rows_check_can_fail():
    """The byte comparison above catches rows written to the wrong places."""
    idx = np.array([0, 2, 3])
    rows = np.arange(9.0).reshape(3, 3)
    want = np.zeros((5, 3))
    want[idx] = rows
    got = np.zeros((5, 3))
    render_module._put_rows(got, idx[::-1].copy(), rows)
    assert got.tobytes() != want.tobytes()


def test_put_rows_writes_into_a_tile_view():
    """Tiles pass contiguous row slices of the frame: the writes land in the frame."""
    frame = np.zeros((10, 3))
    render_module._put_rows(frame[4:8], np.array([1, 3]), np.ones((2, 3)))
    assert frame[5].tolist() == [1.0, 1.0, 1.0] and frame[7].tolist() == [1.0, 1.0, 1.0]
    assert frame.sum() == 6.0


def test_put_rows_refuses_an_index_out_of_range():
    with pytest.raises(IndexError):
        render_module._put_rows(np.zeros((3, 3)), np.array([3]), np.ones((1, 3)))
