"""β fitted to a normal map: Gauss–Newton on the perturbed normals of sphere A.

A render's G-buffer holds, per pixel of sphere A, the perturbed normal N'(β)
(`renderer.gbuffer`'s ``Ns``).  Given such a map made with an unknown β and
otherwise the same scene, `fit_beta` recovers β: the residual is
N'(β) - target over sphere A's pixels, and its Jacobian ∂N'/∂β is sympy's
derivative of `renderer.formulas.PERTURBED_NORMAL` for the scene's bump mode
(`jacobian`).  Everything else N' depends on (N, the tangent frame, h and its
exact gradient) is geometry and does not depend on β (the bump moves no
boundary), so it is read once from a G-buffer of the scene.

In the chart mode M = N + β g (g = h_u e_θ + h_v e_φ) is linear in β, and the
Jacobian is the closed form (I − N'N'ᵀ) g / |M|: the derivative of a unit
vector lies in its tangent plane.  In the surface mode the coefficients of M
depend on β through 1 / (R + β h), and only sympy's derivative holds.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import sympy as sp

from renderer import formulas, gbuffer, pointwise
from renderer.pointwise import UNIT_NORMAL
from renderer.render import MAX_SIDE, SPHERE_A, check_args
from renderer.scene import MAX_BETA
from renderer.validate import InvalidType, InvalidValue, choice, positive_int, real, real_array

from ._checks import numbers_array

__all__ = ["Fit", "fit_beta", "geometry", "jacobian", "normal_and_jacobian", "MAX_STEPS", "MODES"]

#: Most Gauss–Newton steps `fit_beta` accepts.
MAX_STEPS = 100
#: The arguments of both modes' normals and Jacobians (the chart mode ignores h, R, sin φ).
_ARGS = ((formulas.N_x, formulas.N_y, formulas.N_z) + formulas.e_theta + formulas.e_phi
         + (formulas.h_u, formulas.h_v, formulas.beta, formulas.h, formulas.R, formulas.sin_phi))


#: The bump modes, as `formulas.PERTURBED_NORMAL` names them.
MODES = tuple(sorted(formulas.PERTURBED_NORMAL))


def jacobian(mode):
    """∂N'/∂β for one bump mode: sympy's derivative of each component of
    `formulas.PERTURBED_NORMAL[mode]`, taken on first use (not at import).

    Parameters
    ----------
    mode : {"chart", "surface"}

    Returns
    -------
    tuple of 3 sympy expressions
        In the symbols of `renderer.formulas` (dimensionless, per unit β).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``mode`` is not a string, or not a bump mode of `formulas.PERTURBED_NORMAL` (`MODES`).
    """
    return _jacobian(choice("mode", mode, MODES))


@functools.lru_cache(maxsize=None)
def _jacobian(mode):
    return tuple(sp.diff(c, formulas.beta) for c in formulas.PERTURBED_NORMAL[mode])


@functools.lru_cache(maxsize=None)
def _lambdified(mode):
    return sp.lambdify(_ARGS, [list(formulas.PERTURBED_NORMAL[mode]), list(_jacobian(mode))], "numpy", cse=True)


def normal_and_jacobian(mode, geometry, beta):
    """N'(β) and ∂N'/∂β at sphere-A points.

    Parameters
    ----------
    mode : {"chart", "surface"}
    geometry : tuple of 14 float64 arrays of one shape (n,)
        N (3), e_θ (3), e_φ (3), h_u, h_v, h, R, sin φ, as `_ARGS` orders them without β
        (`geometry` returns them); finite real numbers.
    beta : float, or (n,) array of floats, in [0, 100]

    Returns
    -------
    (normal, jacobian) : two (n, 3) float64 arrays (dimensionless; the Jacobian per unit β).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: ``mode`` not one of `MODES`; ``geometry`` not a list or tuple of
        14 arrays, an entry (``geometry[i]``) not finite real numbers or not 1-D of one length;
        ``beta`` not real numbers in [0, 100], or an array of another shape than (n,).
    """
    mode = choice("mode", mode, MODES)
    if not (isinstance(geometry, (tuple, list)) and len(geometry) == len(_ARGS) - 1):
        raise InvalidType(f"geometry must be a tuple of {len(_ARGS) - 1} arrays (N, e_θ, e_φ, h_u, h_v, h, R, "
                          f"sin φ), got {type(geometry).__name__} {geometry!r:.80}")
    geometry = tuple(real_array(f"geometry[{i}]", g) for i, g in enumerate(geometry))
    if any(g.ndim != 1 or g.shape != geometry[0].shape for g in geometry):
        raise InvalidValue(f"geometry must be 1-D arrays of one length, got shapes {[g.shape for g in geometry]}")
    beta = real_array("beta", beta, low=0.0, high=MAX_BETA)
    if beta.ndim and beta.shape != geometry[0].shape:
        raise InvalidValue(f"beta must be a number or an array of the geometry's shape {geometry[0].shape}, "
                           f"got shape {beta.shape}")
    return _normal_and_jacobian(mode, geometry, beta[()])


def _normal_and_jacobian(mode, geometry, beta):
    N, et, ep, hu, hv, h, R, sin_phi = geometry[:3], geometry[3:6], geometry[6:9], *geometry[9:]
    normal, jac = _lambdified(mode)(*N, *et, *ep, hu, hv, beta, h, R, sin_phi)
    n = hu.shape[0]
    return (np.stack([np.broadcast_to(c, (n,)) for c in normal], -1),
            np.stack([np.broadcast_to(c, (n,)) for c in jac], -1))


@dataclass(frozen=True)
class Fit:
    """The result of `fit_beta`.

    Attributes
    ----------
    beta : float
        The last iterate.
    iterates : tuple of (float, float)
        (β_k, |r(β_k)|) for k = 0 (the start), 1, ..., the residual's 2-norm over all
        components of sphere A's pixels (dimensionless).
    pixels : int
        Sphere-A pixels fitted.
    converged : bool
        The last step moved β by at most ``tol``.
    """

    beta: float
    iterates: tuple
    pixels: int
    converged: bool


def geometry(scene, width, height):
    """The β-independent inputs of N' on sphere A's pixels, as `normal_and_jacobian` takes them.

    Parameters
    ----------
    scene : renderer.Scene
    width, height : int in [1, 8192]

    Returns
    -------
    (on_a, inputs) : a (height, width) bool array (the sphere-A pixels) and a tuple of 14
        float64 arrays of shape (n,), n = on_a.sum(): N (3), e_θ (3), e_φ (3), h_u, h_v, h, R, sin φ.

    Raises
    ------
    TypeError, ValueError
        As `renderer.gbuffer` for a bad scene or size.
    """
    g = gbuffer(scene, width, height, gradient="exact")
    on_a = g.chamber == SPHERE_A
    N = g.N[on_a]
    _, _, sin_phi = pointwise.chart(*N.T)
    et, ep = pointwise.tangent_frame(*N.T, sin_phi)
    uv, grad = g.uv[on_a], g.grad[on_a]
    h = pointwise.height(scene.field, uv[:, 0], uv[:, 1], scene.k_u, scene.k_v)
    return on_a, (*N.T, *et, *ep, grad[:, 0], grad[:, 1], h, np.full(h.shape, scene.radius_a), sin_phi)


def fit_beta(target, scene, *, beta0=0.1, steps=20, tol=1e-12):
    """Recover β from a normal map by Gauss–Newton.

    Parameters
    ----------
    target : (H, W, 3) array_like of float
        Perturbed unit normals (``renderer.gbuffer(scene', W, H).Ns``) of a render of
        ``scene`` with an unknown β; read on sphere A's pixels only, whose components must be
        finite and within [-1.5, 1.5] (a unit vector's, with room for rounding).
    scene : renderer.Scene
        The scene (its ``beta`` is ignored; its ``bump`` mode decides the formula).
    beta0 : float in [0, 100], keyword-only
        The starting β (below ``radius_a`` for ``bump="surface"``).
    steps : int in [1, 100], keyword-only
        Most Gauss–Newton steps.
    tol : float in (0, 1], keyword-only
        Stop when a step moves β by at most ``tol``.

    Returns
    -------
    Fit

    Raises
    ------
    renderer.validate.InvalidType
        ``scene`` not a Scene; ``target`` not real numbers (bools, strings); ``steps`` not an
        integer; ``beta0`` or ``tol`` not real.
    renderer.validate.InvalidValue
        ``target`` not of shape (H, W, 3) with H, W in [1, 8192], or on sphere A not finite or
        outside [-1.5, 1.5]; ``beta0``, ``steps`` or ``tol`` out of range; ``scene`` whose normals
        on sphere A do not move with β (dN'/dβ = 0 on every pixel: a field of gradient 0, such as
        a constant, or no pixel on sphere A), where β cannot be recovered.
    """
    target = numbers_array("target", target)
    if target.ndim != 3 or target.shape[2] != 3 or not 1 <= min(target.shape[:2]) <= max(target.shape[:2]) <= MAX_SIDE:
        raise InvalidValue(f"target must be an (H, W, 3) normal map with H, W in [1, {MAX_SIDE}], "
                           f"got shape {target.shape}")
    scene, width, height, _, _ = check_args(scene, target.shape[1], target.shape[0], "exact", 1.0)
    high = scene.radius_a if scene.bump == "surface" else MAX_BETA
    beta = real("beta0", beta0, low=0.0, high=high, high_open=scene.bump == "surface")
    steps = positive_int("steps", steps, high=MAX_STEPS)
    tol = real("tol", tol, low=0.0, low_open=True, high=1.0)
    on_a, inputs = geometry(scene, width, height)
    want = target[on_a]
    bad = ~((want >= UNIT_NORMAL["low"]) & (want <= UNIT_NORMAL["high"])).all(axis=1)     # NaN too
    if bad.any():
        row, col = np.argwhere(on_a)[np.argmax(bad)]
        raise InvalidValue(f"target must be finite and in [{UNIT_NORMAL['low']}, {UNIT_NORMAL['high']}] on sphere A's "
                           f"{on_a.sum():,} pixels, got {np.count_nonzero(bad):,} pixels outside, the first "
                           f"{tuple(want[np.argmax(bad)].tolist())} at (row, column) ({row}, {col})")
    iterates, converged = [], False
    for _ in range(steps + 1):
        normal, jac = _normal_and_jacobian(scene.bump, inputs, beta)
        r = (normal - want).ravel()
        iterates.append((beta, float(np.linalg.norm(r))))
        if converged or len(iterates) > steps:
            break
        J = jac.ravel()
        if not J @ J > 0.0:
            raise InvalidValue(f"scene must show normals that move with beta on sphere A to fit beta; at beta = "
                               f"{beta:g} dN'/dbeta is 0 on all {on_a.sum():,} of its pixels (height_field "
                               f"{scene.height_field!r}: a gradient 0 everywhere, or no pixel on sphere A)")
        step = -float(J @ r) / float(J @ J)
        # Keep β in the scene's range (surface: R + β h > 0).
        new = min(max(beta + step, 0.0), np.nextafter(high, 0.0) if scene.bump == "surface" else high)
        converged, beta = abs(new - beta) <= tol, new
    return Fit(beta, tuple(iterates), int(on_a.sum()), converged)
