"""The generated height fields and gradients against hand closed forms."""

import numpy as np
import pytest

from renderer import fields
from renderer.render import central_gradient
from tests.reference_renderer import h_gradient_exact

rng = np.random.default_rng(2026)
U, V = rng.uniform(0, 1, 500), rng.uniform(0, 1, 500)


@pytest.mark.parametrize("name", ["sine", "ridges", "rings"])
@pytest.mark.parametrize("ku, kv", [(8.0, 4.0), (3.0, 7.5)])
def test_generated_gradient_equals_closed_form(name, ku, kv):
    hu, hv = fields.exact_gradient(name, U, V, ku, kv)
    expected = np.array([h_gradient_exact(name, u, v, ku, kv) for u, v in zip(U, V)])
    scale = np.pi * max(ku, 2 * kv)
    assert np.abs(hu - expected[:, 0]).max() <= 1e-13 * scale
    assert np.abs(hv - expected[:, 1]).max() <= 1e-13 * scale


def test_closed_form_check_rejects_a_wrong_gradient():
    hu, _ = fields.exact_gradient("sine", U, V, 8.0, 4.0)
    wrong = np.pi * 8.0 * np.cos(np.pi * 8.0 * U)                  # dropped sin(pi k_v v)
    assert np.abs(hu - wrong).max() > 1.0


def test_central_difference_is_second_order_for_sine():
    u, v = np.array([0.31]), np.array([0.47])
    exact = fields.exact_gradient("sine", u, v, 8.0, 4.0)
    steps = np.logspace(-2, -4, 9)
    err = [[abs(central_gradient("sine", u, v, 8.0, 4.0, e)[k][0] - exact[k][0]) for e in steps]
           for k in (0, 1)]
    for k in (0, 1):
        slope = np.polyfit(np.log(steps), np.log(err[k]), 1)[0]
        assert 1.8 <= slope <= 2.2, slope
    # A first-order (forward) quotient is rejected by the same slope check.
    fwd = [abs((fields.height("sine", u + e, v, 8.0, 4.0)[0] - fields.height("sine", u, v, 8.0, 4.0)[0]) / e
               - exact[0][0]) for e in steps]
    assert not 1.8 <= np.polyfit(np.log(steps), np.log(fwd), 1)[0] <= 2.2


def test_rings_has_no_u_derivative_in_either_pipeline():
    assert np.all(fields.exact_gradient("rings", U, V, 8.0, 4.0)[0] == 0.0)
    assert np.all(central_gradient("rings", U, V, 8.0, 4.0, 1e-3)[0] == 0.0)


def test_kink_band_only_for_ridges():
    assert not fields.kink_band("sine", U, V, 8.0, 4.0).any()
    assert not fields.kink_band("rings", U, V, 8.0, 4.0).any()
    band = fields.kink_band("ridges", np.array([0.125, 0.3]), np.array([0.3, 0.3]), 8.0, 4.0)
    assert band.tolist() == [True, False]


def test_v_clamp_is_one_sided_at_the_poles():
    ku, kv, eps = 8.0, 4.0, 1e-3
    u = np.array([0.31, 0.31])
    v = np.array([0.0, 1.0])
    _, hv = central_gradient("sine", u, v, ku, kv, eps)
    h = lambda vv: fields.height("sine", u[:1], np.array([vv]), ku, kv)[0]  # noqa: E731
    # One-sided, divided by the clamped distance actually spanned (v_+ - v_-).
    assert hv[0] == (h(eps) - h(0.0)) / (eps - 0.0)
    assert hv[1] == (h(1.0) - h(1.0 - eps)) / (1.0 - (1.0 - eps))
    # A central quotient over 2 eps would be off by a factor of about 2.
    assert abs(hv[1] - (h(1.0) - h(1.0 - eps)) / (2 * eps)) > 1.0


def test_interior_v_difference_divides_by_two_eps():
    """Not the seed's rounding-dependent branch (errata: v-border-branch)."""
    u, v, eps = np.array([0.31]), np.array([0.47]), 1e-9
    _, hv = central_gradient("sine", u, v, 8.0, 4.0, eps)
    h = lambda vv: fields.height("sine", u, np.array([vv]), 8.0, 4.0)[0]  # noqa: E731
    assert (v[0] + eps) - (v[0] - eps) != 2 * eps         # the seed's test would fire here
    assert hv[0] == (h(v[0] + eps) - h(v[0] - eps)) / (2 * eps)


@pytest.mark.parametrize("eps", [5e-324, 1e-300, 1e-17, 0.5, 0.75, 3.0, 1e300])
def test_central_difference_finite_for_extreme_steps(eps):
    for name in ("sine", "ridges", "rings"):
        hu, hv = central_gradient(name, U, V, 8.0, 4.0, eps)
        assert np.isfinite(hu).all() and np.isfinite(hv).all(), (name, eps)
