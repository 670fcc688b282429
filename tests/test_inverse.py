"""lab.inverse: β recovered from a normal map, with the exact Jacobian."""

from __future__ import annotations

import re

import numpy as np
import pytest

from renderer import Scene, gbuffer
from renderer.validate import InvalidValue
from lab.inverse import fit_beta, geometry, normal_and_jacobian

SIZE, BETA = 40, 0.35
RNG = np.random.default_rng(20261125)


@pytest.mark.parametrize("mode", ["chart", "surface"])
@pytest.mark.parametrize("field", ["sine", "rings"])
@pytest.mark.parametrize("beta0", [0.0, 0.1, 0.8])
def test_fit_recovers_beta(mode, field, beta0):
    scene = Scene(height_field=field, bump=mode, beta=BETA)
    target = gbuffer(scene, SIZE, SIZE).Ns
    fit = fit_beta(target, scene.replace(beta=0.05), beta0=beta0)
    # Gauss-Newton with the exact Jacobian: measured 6-11 iterates; the residual's floor is rounding.
    assert fit.converged and len(fit.iterates) <= 12
    assert abs(fit.beta - BETA) <= 1e-9
    assert fit.iterates[-1][1] <= 1e-9 < fit.iterates[0][1]
    assert fit.iterates[0][0] == beta0 and fit.pixels > 500


@pytest.mark.parametrize("mode", ["chart", "surface"])
def test_jacobian_is_the_beta_derivative_of_the_renderers_normal(mode):
    # Independent route: central differences of the kernel's own Ns in beta (step 1e-5:
    # truncation ~1e-10 x |N'''|, rounding ~1e-16 / 1e-5).
    scene, d = Scene(height_field="sine", bump=mode, beta=BETA), 1e-5
    on_a, inputs = geometry(scene, SIZE, SIZE)
    _, jac = normal_and_jacobian(mode, inputs, BETA)
    fd = (gbuffer(scene.replace(beta=BETA + d), SIZE, SIZE).Ns - gbuffer(scene.replace(beta=BETA - d), SIZE, SIZE).Ns)
    fd = fd[on_a] / (2 * d)
    assert np.abs(jac - fd).max() <= 1e-7 * np.abs(fd).max()
    assert np.abs(fd).max() > 0.1


@pytest.mark.parametrize("mode", ["chart", "surface"])
def test_a_gauss_newton_step_from_the_public_geometry_is_the_fits_step(mode):
    """`geometry` is what the fit reads: beta_1 = beta_0 - J.r / J.J from its inputs is the fit's
    second iterate (the book's exercise takes this step by hand)."""
    scene = Scene(height_field="sine", bump=mode, beta=BETA)
    target = gbuffer(scene, SIZE, SIZE).Ns
    fit = fit_beta(target, scene, beta0=0.1, steps=1)
    on_a, inputs = geometry(scene, SIZE, SIZE)
    normal, jac = normal_and_jacobian(mode, inputs, 0.1)
    r, J = (normal - target[on_a]).ravel(), jac.ravel()
    assert on_a.sum() == fit.pixels and np.isclose(np.linalg.norm(r), fit.iterates[0][1], rtol=1e-12, atol=0)
    assert np.isclose(0.1 - (J @ r) / (J @ J), fit.iterates[1][0], rtol=1e-12, atol=0)


def test_chart_jacobian_is_the_closed_form():
    # (I - N'N'^T) g / |M|, M = N + beta g, written here in numpy; at random unit N, orthonormal
    # frames and gradients (verified numerically: sympy's simplify takes ~25 s on it).
    rng = np.random.default_rng(7)
    n = 1000
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    et = np.cross(N, rng.normal(size=(n, 3)))
    et /= np.linalg.norm(et, axis=1, keepdims=True)
    ep = np.cross(et, N)
    hu, hv, beta = rng.uniform(-3, 3, n), rng.uniform(-3, 3, n), rng.uniform(0, 2, n)
    zero = np.zeros(n)
    normal, jac = normal_and_jacobian("chart", (*N.T, *et.T, *ep.T, hu, hv, zero, zero + 1, zero + 1), beta)
    g = hu[:, None] * et + hv[:, None] * ep
    M = N + beta[:, None] * g
    Np = M / np.linalg.norm(M, axis=1, keepdims=True)
    closed = (g - Np * np.einsum("ij,ij->i", Np, g)[:, None]) / np.linalg.norm(M, axis=1, keepdims=True)
    assert np.abs(normal - Np).max() <= 1e-14
    assert np.abs(jac - closed).max() <= 1e-12 * np.abs(closed).max()


@pytest.mark.parametrize("args, kwargs, words", [
    ((np.zeros((8, 8)),), {}, "target"), ((np.zeros((8, 8, 4)),), {}, "target"), (("x",), {}, "target"),
    ((np.full((8, 8, 3), np.nan),), {}, "finite"),
    ((np.zeros((8, 8, 3)),), dict(beta0=-0.1), "beta0"),
    ((np.zeros((8, 8, 3)), Scene(bump="surface")), dict(beta0=1.0), "beta0"),
    ((np.zeros((8, 8, 3)),), dict(steps=0), "steps"), ((np.zeros((8, 8, 3)),), dict(tol=0.0), "tol"),
    ((np.zeros((8, 8, 3)), "scene"), {}, "scene")])
def test_bad_input_is_refused(args, kwargs, words):
    args = args + (Scene(),) if len(args) == 1 else args
    with pytest.raises((TypeError, ValueError), match=words):
        fit_beta(*args, **kwargs)


def test_importing_takes_no_derivative_and_an_unknown_mode_is_named():
    # The Jacobian is sympy's work on first use, not at import (it cost 75 ms of every import).
    import subprocess
    import sys
    code = "import lab.inverse as m; print(m._jacobian.cache_info().currsize)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "0"
    from lab.inverse import jacobian
    with pytest.raises(InvalidValue, match=r"^mode must be one of \('chart', 'surface'\), got 'bump'"):
        jacobian("bump")


def test_a_geometry_of_another_length_is_refused_with_the_length_geometry_returns():
    """The refusal names the count of arrays `geometry` hands over (14: N, e_θ, e_φ by components,
    h_u, h_v, h, R, sin φ), whether one is missing or one too many."""
    from renderer.validate import InvalidType
    _, inputs = geometry(Scene(), 8, 8)
    for wrong in (inputs[:-1], (*inputs, inputs[0]), list(inputs[:3])):
        with pytest.raises(InvalidType, match=rf"^geometry must be a tuple of {len(inputs)} arrays \(N, e_θ"):
            normal_and_jacobian("chart", wrong, 0.1)
    normal, _ = normal_and_jacobian("chart", list(inputs), 0.1)
    assert normal.shape == (inputs[0].shape[0], 3)


def test_beta_is_taken_on_its_whole_interval_and_refused_past_either_end():
    from lab.inverse import MAX_BETA
    _, inputs = geometry(Scene(), 8, 8)
    n = inputs[0].shape[0]
    for beta in (0.0, MAX_BETA, np.linspace(0.0, MAX_BETA, n)):
        assert np.isfinite(normal_and_jacobian("surface", inputs, beta)[1]).all()
    for beta in (-1e-300, -0.5, np.nextafter(MAX_BETA, np.inf), 2 * MAX_BETA, np.full(n, -0.1)):
        with pytest.raises(InvalidValue, match=r"^beta must be .*\[0(\.0)?, "):
            normal_and_jacobian("surface", inputs, beta)


def test_a_normal_map_one_pixel_thin_or_at_the_largest_side_is_fitted():
    """Every (H, W) with H, W in [1, MAX_SIDE] is a normal map: one row, one column and a row
    MAX_SIDE pixels long are each fitted; a side of 0 or MAX_SIDE + 1 is refused."""
    from lab.inverse import MAX_SIDE
    scene = Scene(beta=BETA)
    for height, width in ((1, 64), (64, 1), (1, MAX_SIDE), (MAX_SIDE, 1)):
        fit = fit_beta(gbuffer(scene, width, height).Ns, scene.replace(beta=0.05))
        assert fit.converged and abs(fit.beta - BETA) <= 1e-9 and fit.pixels > 0, (height, width)
    for shape in ((0, 8, 3), (1, MAX_SIDE + 1, 3), (MAX_SIDE + 1, 1, 3)):
        with pytest.raises(InvalidValue, match=r"^target must be an \(H, W, 3\) normal map .*got shape " + re.escape(str(shape))):
            fit_beta(np.zeros(shape), scene)


def test_the_start_and_the_tolerance_are_taken_on_their_whole_intervals():
    """beta0 in [0, MAX_BETA] for bump="chart" (a chart-mode β may exceed R: it moves no surface),
    in [0, R) for "surface"; tol in (0, 1]."""
    from lab.inverse import MAX_BETA
    target = gbuffer(Scene(beta=BETA), 24, 24).Ns
    radius = Scene().radius_a
    start = float(RNG.uniform(2 * radius, MAX_BETA))
    assert fit_beta(target, Scene(bump="chart"), beta0=start).iterates[0][0] == start
    assert fit_beta(target, Scene(bump="chart"), beta0=MAX_BETA).iterates[0][0] == MAX_BETA
    with pytest.raises(InvalidValue, match=r"^beta0 must be"):
        fit_beta(target, Scene(bump="surface"), beta0=radius)
    assert fit_beta(target, Scene(), tol=1.0).iterates[0][0] == 0.1
    for tol in (np.nextafter(1.0, 2.0), 1.5, 2.0, 10.0):
        with pytest.raises(InvalidValue, match=r"^tol must be"):
            fit_beta(target, Scene(), tol=tol)


def test_a_bad_normal_is_named_at_its_own_pixel():
    """A normal outside [-1.5, 1.5] (or NaN) at a random pixel of sphere A: the refusal names that
    pixel's (row, column) and components, and how many pixels are bad."""
    scene = Scene(beta=BETA)
    on_a, _ = geometry(scene, 32, 32)
    pixels = np.argwhere(on_a)
    for _ in range(5):
        target = gbuffer(scene, 32, 32).Ns.copy()
        row, col = pixels[RNG.integers(1, len(pixels))]
        target[row, col] = (0.0, float(RNG.choice([2.0, -7.5, np.nan])), 0.0)
        with pytest.raises(InvalidValue, match=rf"got 1 pixels outside, the first \(0\.0, .*\) at \(row, column\) "
                                               rf"\({row}, {col}\)$"):
            fit_beta(target, scene)


def test_normals_at_the_ends_of_the_accepted_range_are_read():
    """Components of exactly -1.5 and 1.5 on sphere A are within the accepted range (a fit is made)."""
    scene = Scene(beta=BETA)
    on_a, _ = geometry(scene, 32, 32)
    target = gbuffer(scene, 32, 32).Ns.copy()
    rows, cols = np.nonzero(on_a)
    target[rows[0], cols[0]] = (1.5, -1.5, 0.0)
    target[rows[-1], cols[-1]] = (-1.5, 1.5, 1.5)
    assert np.isfinite(fit_beta(target, scene).beta)


@pytest.mark.parametrize("mode, beta, push, start", [("surface", 0.99, 2.0, 0.9), ("chart", 100.0, 200.0, 99.0)])
def test_a_step_past_the_range_stops_at_its_edge(mode, beta, push, start):
    """A target whose best β lies past the range (the normal map at β pushed along ∂N'/∂β): the
    fit's step is cut at the edge: just below R under the displaced surface's normal (R + β h must
    stay positive), at MAX_BETA on the chart."""
    from lab.inverse import MAX_BETA
    scene = Scene(bump=mode)
    on_a, inputs = geometry(scene, 24, 24)
    normal, jac = normal_and_jacobian(mode, inputs, beta)
    target = np.zeros((24, 24, 3))
    target[on_a] = np.clip(normal + push * jac, -1.5, 1.5)
    fit = fit_beta(target, scene, beta0=start)
    edge = np.nextafter(scene.radius_a, 0.0) if mode == "surface" else MAX_BETA
    assert max(b for b, _ in fit.iterates) == edge == fit.beta, fit.iterates
    assert all(np.isfinite(r) for _, r in fit.iterates)
    if mode == "chart":             # from 99 to the edge is a step of exactly 1: within tol = 1, done
        assert [b for b, _ in fit_beta(target, scene, beta0=start, tol=1.0).iterates] == [start, MAX_BETA]


@pytest.mark.parametrize("mode", ["surface", "chart"])
@pytest.mark.parametrize("field", ["1", "0", "2*k_u"])
def test_a_field_whose_normals_do_not_move_with_beta_is_refused_not_divided_by_zero(mode, field):
    """A constant field has gradient 0: no β moves a normal, so none can be recovered.  The fit
    says so, naming the scene, where its Gauss-Newton step divided by |dN'/dβ|² = 0."""
    scene = Scene(height_field=field, bump=mode, beta=0.2)
    with pytest.raises(InvalidValue, match=r"^scene must show normals that move with beta .* on all [\d,]+ of its "
                                           rf"pixels \(height_field '{re.escape(field)}'"):
        fit_beta(gbuffer(scene, 8, 8).Ns, scene)
