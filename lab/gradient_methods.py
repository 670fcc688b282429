"""Run time against error for the ways of computing the chart gradient.

For each height field, over the sphere-A pixels of a 256 x 256 default-scene
frame, this module measures five ways of computing (h_u, h_v):

* ``exact``: the kernel's generated gradient (sympy's derivative,
  `renderer.formulas.GRADIENT`), `renderer.pointwise.exact_gradient`;
* ``central``: the kernel's central difference (`renderer.formulas.CENTRAL`),
  `renderer.pointwise.central_gradient`, at each step of a sweep;
* ``forward``: the one-sided difference (h(u + eps) - h(u)) / eps, at each
  step of a sweep (`forward_gradient`);
* ``complex step``: Im h(u + i eps) / eps (Squire and Trapp 1998), with h the
  sympy expression evaluated in complex numpy by ``sympy.lambdify``
  (`complex_step_gradient`).  It needs h to be analytic; `ANALYTIC` says for
  which fields it is, decided from the expression.  The ridges field is
  |f|, which is not: lambdify's ``abs`` of a complex number is its modulus,
  a real number, so the plain complex step returns 0.  The usual repair
  (Martins, Sturdza and Alonso 2003) continues |f| as f sign(Re f); that
  variant is measured too, as ``complex step, |z| continued``;
* ``forward-mode AD``: automatic differentiation in forward mode, ``jax.jvp``
  (Griewank and Walther 2008), of the program that evaluates h, printed from
  the sympy expression by ``sympy.lambdify(..., modules="jax")``
  (`ad_gradient`).  AD differentiates that program, operation by operation;
  sympy differentiates the expression.  Its one choice that is not a
  derivative is JAX's slope of |x| at x = 0 (`abs_slope_at_zero`, measured);
* ``richardson``: `scipy.differentiate.derivative`, an adaptive
  finite-difference differentiator that raises the order of accuracy by
  combining nested steps (Richardson's idea, as in numdifftools and
  DERIVEST), vectorised over pixels (`richardson_gradient`).

For each method and field it records the time per frame (median, minimum and
maximum over repeats, methods interleaved), the work per pixel (`evaluations`:
the values of h, or evaluations of the generated gradient, and the sines and
cosines they cost, counted from the sympy objects the kernel is generated
from, since compiled code cannot be instrumented; scipy counts its own
evaluations), and the largest and RMS error of the two components against an
mpmath reference of the exact gradient (`reference_gradient`).  On the ridges
field the derivative does not exist on the crease lines, so errors there are
measured off the seed's crease band (`renderer.pointwise.kink_band`); the
timings still cover every pixel.

The exact and central gradients and h itself are the kernel's compiled
functions; forward differences call the compiled h three times from numpy;
the complex step evaluates h in complex numpy (lambdify), Richardson
calls the compiled h from scipy's iteration, and AD runs JAX's jit-compiled
(XLA) program on the arrays.  Compiling is not in AD's times: the first call
at the frame's size traces and compiles, and is timed on its own
(`MethodResult.compile_seconds`).  So the times compare the
methods as they are available here, not as each could best be compiled.

`FAST` is the configuration the book runs when it is built; `FULL` the one the
benchmark runs for a release (every pixel in the reference, more steps, more
repeats).  `pareto_front` picks a `Measurement`'s non-dominated methods; the book
draws and tabulates it (book/chapter/benchmark.py).

References
----------
.. [1] W. Squire and G. Trapp, "Using complex variables to estimate
   derivatives of real functions", SIAM Review 40(1), 110-112, 1998.
.. [2] J. R. R. A. Martins, P. Sturdza and J. J. Alonso, "The complex-step
   derivative approximation", ACM Trans. Math. Softw. 29(3), 245-262, 2003.
.. [3] SciPy 1.17, ``scipy.differentiate.derivative``.
.. [4] A. Griewank and A. Walther, *Evaluating Derivatives*, 2nd ed., SIAM, 2008.
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time
from dataclasses import asdict, dataclass, field as dc_field
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp
from scipy.differentiate import derivative

from renderer import DRAFT_SCENE, gbuffer, pointwise
from renderer import formulas as F
from renderer.render import SPHERE_A

__all__ = [
    "FIELDS", "ANALYTIC", "Config", "FAST", "FULL", "Evaluations", "MethodResult", "Measurement",
    "is_analytic", "chart_points", "forward_gradient", "complex_step_gradient",
    "richardson_gradient", "reference_gradient", "trig_calls", "stencil_values", "evaluations",
    "methods", "measure", "pareto_front", "to_json", "AD", "ad_gradient", "ad_trig_calls",
    "abs_slope_at_zero", "crease_values",
]

FIELDS = ("sine", "ridges", "rings")
#: The name of forward-mode automatic differentiation in the results.
AD = "forward-mode AD"

#: sympy functions that are not holomorphic in their argument: an expression
#: containing one of them cannot be differentiated by the complex step.
_NON_ANALYTIC = (sp.Abs, sp.sign, sp.re, sp.im, sp.conjugate, sp.arg, sp.Heaviside,
                 sp.Piecewise, sp.Max, sp.Min, sp.floor, sp.ceiling)


def is_analytic(expr):
    """Whether the sympy expression ``expr`` is built from holomorphic functions only.

    True when ``expr`` contains none of Abs, sign, re, im, conjugate, arg,
    Heaviside, Piecewise, Max, Min, floor, ceiling: then its lambdified
    complex evaluation is the analytic continuation the complex step needs.
    This is a syntactic test (sufficient, not necessary): |x|^2 written with
    Abs would be reported as not analytic.
    """
    return not expr.has(*_NON_ANALYTIC)


#: For each field: may the complex step be used?  Computed from `renderer.formulas.HEIGHT`.
ANALYTIC = {name: is_analytic(expr) for name, expr in F.HEIGHT.items()}


@dataclass(frozen=True)
class Config:
    """What `measure` runs.

    Attributes
    ----------
    name : str
    central_steps, forward_steps, complex_steps : tuple of float
        The steps eps (chart units) of each sweep.
    repeats : int
        Timed runs of every method (each run: all pixels of the frame) ...
    richardson_repeats : int
        ... except ``richardson``, ten to twenty times slower than the rest,
        which is timed this many times.
    reference_pixels : int or None
        Pixels per field at which errors are measured against mpmath (a
        seeded sample of the pixels where the gradient exists); None for all.
    digits : int
        mpmath working precision of the reference, in decimal digits.
    size : int
        Frame side in pixels.
    seed : int
        Seed of the pixel sample and of the order in which methods run.
    """

    name: str
    central_steps: tuple
    forward_steps: tuple
    complex_steps: tuple
    repeats: int
    richardson_repeats: int
    reference_pixels: int | None
    digits: int = 34
    size: int = 256
    seed: int = 6


#: Book build (§5, Cell 4, which reports the time it took): a few hundred reference pixels
#: at 34 digits and one Richardson run per field keep it to about a second.
#: Steps: the renderer's default 1e-3, near each quotient's optimum (central
#: 1e-6, forward 1e-8), and one past the central optimum, where rounding rules.
FAST = Config("fast", central_steps=(1e-3, 1e-6, 1e-9), forward_steps=(1e-3, 1e-8),
              complex_steps=(1e-20,), repeats=3, richardson_repeats=1, reference_pixels=100)
#: Release: every pixel in the reference, twelve steps per sweep, more repeats.
FULL = Config("full", central_steps=tuple(10.0 ** -np.arange(1, 13)),
              forward_steps=tuple(10.0 ** -np.arange(1, 13)),
              complex_steps=(1e-2, 1e-4, 1e-6, 1e-8, 1e-20, 1e-100), repeats=15, richardson_repeats=15,
              reference_pixels=None, digits=40)


# --- chart points --------------------------------------------------------------------------

def chart_points(field="ridges", size=256):
    """Chart coordinates (u, v) of the sphere-A pixels of a default-scene frame.

    Parameters
    ----------
    field : {"sine", "ridges", "rings"}
        The scene's height field (the chart does not depend on it: it is
        computed from the geometry before any gradient).
    size : int
        Frame side in pixels.

    Returns
    -------
    (u, v) : two (n,) float64 arrays, contiguous, in row-major pixel order.
    """
    g = gbuffer(DRAFT_SCENE.replace(height_field=field), size, size)
    uv = g.uv[g.chamber == SPHERE_A]
    return np.ascontiguousarray(uv[:, 0]), np.ascontiguousarray(uv[:, 1])


# --- the methods ---------------------------------------------------------------------------

def forward_gradient(name, uu, vv, ku, kv, eps):
    """One-sided (forward) difference chart gradient.

    h_u = (h(u + eps, v) - h(u, v)) / eps with u + eps wrapped modulo 1 (the
    chart is periodic in u), and h_v the same in v, except where v + eps > 1,
    where the step is taken backwards, (h(u, v) - h(u, v - eps)) / eps.  The
    quotient is divided by the nominal step, as the kernel's central difference does.
    h(u, v) is shared by both components: three evaluations of h per point.
    Truncation error O(eps); h is the kernel's, `renderer.pointwise.height`.

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    uu, vv : (n,) float64 chart coordinates in [0, 1]
    ku, kv : float
    eps : float > 0, the step in chart units

    Returns
    -------
    (h_u, h_v) : two (n,) float64 arrays.

    Raises
    ------
    ValueError
        If ``eps`` is not a positive finite number or ``name`` is unknown.
    """
    if not (np.isfinite(eps) and eps > 0):
        raise ValueError(f"eps must be a positive finite number, got {eps!r}")
    h0 = pointwise.height(name, uu, vv, ku, kv)
    hu = (pointwise.height(name, np.mod(uu + eps, 1.0), vv, ku, kv) - h0) / eps
    back = vv + eps > 1.0
    step = np.where(back, -eps, eps)
    hv = (pointwise.height(name, uu, vv + step, ku, kv) - h0) / step
    return hu, hv


def _abs_continued(z):
    """|x| continued off the real axis as z sign(Re z) (Martins et al. 2003, sec. 3)."""
    return np.where(np.real(z) < 0, -z, z)


@lru_cache(maxsize=None)
def _complex_height_fn(name, continued):
    modules = [{"Abs": _abs_continued}, "numpy"] if continued else "numpy"
    # With "Abs" in a user namespace, lambdify prints Abs(...) and calls that function.
    return sp.lambdify((F.u, F.v, F.k_u, F.k_v), F.HEIGHT[name], modules=modules)


def _complex_height(name, uu, vv, ku, kv, continued):
    """h at complex chart points, from the sympy expression."""
    return _complex_height_fn(name, continued)(uu, vv, ku, kv)


def complex_step_gradient(name, uu, vv, ku, kv, eps, *, continued=False):
    """Complex-step chart gradient, h_u = Im h(u + i eps, v) / eps, h_v likewise.

    h is the sympy expression of `renderer.formulas.HEIGHT` evaluated in
    complex128 numpy by ``sympy.lambdify``.  No difference is taken, so there
    is no cancellation and eps may be tiny (1e-20 is usual); the truncation
    error is O(eps^2).  Two complex evaluations of h per point.  Valid only
    where h is analytic (`ANALYTIC`): for "ridges" numpy's abs of a complex
    number is its modulus, a real number, and the result is 0.  With
    ``continued=True`` the expression's Abs is evaluated as z sign(Re z)
    [Martins et al. 2003], which gives the one-sided derivative of |f|.

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    uu, vv : (n,) float64 chart coordinates
    ku, kv : float
    eps : float > 0, the imaginary step in chart units
    continued : bool, keyword-only

    Returns
    -------
    (h_u, h_v) : two (n,) float64 arrays.

    Raises
    ------
    ValueError
        If ``eps`` is not a positive finite number or ``name`` is unknown.
    """
    if not (np.isfinite(eps) and eps > 0):
        raise ValueError(f"eps must be a positive finite number, got {eps!r}")
    _check_name(name)
    shape = np.broadcast(uu, vv).shape
    hu = np.imag(_complex_height(name, uu + 1j * eps, vv, ku, kv, continued)) / eps
    hv = np.imag(_complex_height(name, uu, vv + 1j * eps, ku, kv, continued)) / eps
    return np.broadcast_to(hu, shape), np.broadcast_to(hv, shape)


#: scipy.differentiate.derivative's settings.  The first step is half a radian of
#: phase at the highest frequency of the default scene (pi k_u = 8 pi);
#: atol lets it stop where a component is exactly 0 (rings: h_u = 0), which its
#: default (the smallest normal float) never does.
RICHARDSON = dict(initial_step=0.02, order=8, step_factor=2.0, maxiter=10,
                  tolerances=dict(atol=1e-12))


def richardson_gradient(name, uu, vv, ku, kv, *, info=None):
    """Chart gradient by `scipy.differentiate.derivative` (settings `RICHARDSON`).

    Both components are computed in one vectorised call: the 2n abscissae are
    u (moving u) followed by v (moving v).  h is `renderer.pointwise.height`,
    evaluated at whatever steps scipy chooses (the chart formula is defined for
    every real u and v, so no wrapping or clamping).  Elements whose
    iteration did not converge (scipy status != 0) keep scipy's last estimate.

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    uu, vv : (n,) float64 chart coordinates
    ku, kv : float
    info : dict or None, keyword-only
        If given, receives ``"not_converged"`` (int, elements with status != 0),
        ``"iterations"`` (float, mean iterations per element) and ``"nfev"``
        (int, scipy's own count of points evaluated, summed over elements).

    Returns
    -------
    (h_u, h_v) : two (n,) float64 arrays.

    Raises
    ------
    ValueError
        If ``name`` is unknown.
    """
    _check_name(name)
    uu, vv = np.broadcast_arrays(np.asarray(uu, dtype=np.float64), np.asarray(vv, dtype=np.float64))
    n = uu.size
    x = np.concatenate([uu.ravel(), vv.ravel()])
    other = np.concatenate([vv.ravel(), uu.ravel()])
    moves_v = np.repeat(np.array([False, True]), n)

    def h(x, other, moves_v):
        return pointwise.height(name, np.where(moves_v, other, x), np.where(moves_v, x, other), ku, kv)

    res = derivative(h, x, args=(other, moves_v), **RICHARDSON)
    if info is not None:
        info["not_converged"] = int(np.count_nonzero(res.status != 0))
        info["iterations"] = float(np.mean(res.nit))
        info["nfev"] = int(np.sum(res.nfev))
    return res.df[:n].reshape(uu.shape), res.df[n:].reshape(uu.shape)


# --- automatic differentiation (JAX, forward mode) -----------------------------------------

@lru_cache(maxsize=None)
def _ad_program(height):
    """The jit-compiled forward-mode gradient of the program that evaluates ``height``.

    ``height`` (a sympy expression in u, v, k_u, k_v) is printed as a JAX
    function by ``sympy.lambdify``; ``jax.jvp`` pushes the tangent 1 through
    it once along u (v held) and once along v.  JAX is imported here, not
    with the module: only this method needs it.
    """
    import jax
    import jax.numpy as jnp
    h = sp.lambdify((F.u, F.v, F.k_u, F.k_v), height, modules="jax")

    def gradient(uu, vv, ku, kv):
        one = jnp.ones_like(uu)
        h_u = jax.jvp(lambda x: h(x, vv, ku, kv), (uu,), (one,))[1]
        h_v = jax.jvp(lambda y: h(uu, y, ku, kv), (vv,), (one,))[1]
        return h_u, h_v
    return jax.jit(gradient)


def ad_gradient(name, uu, vv, ku, kv, *, height=None):
    """Chart gradient by forward-mode automatic differentiation (``jax.jvp``).

    The program differentiated is h as `renderer.formulas.HEIGHT` writes it,
    printed for JAX by ``sympy.lambdify`` and jit-compiled by XLA, in float64
    (``jax.enable_x64`` around the call only; JAX's global setting is left
    as it is).  Two forward passes per point, one tangent each.  No step, no
    truncation: the result is the derivative of the program, rounded as the
    program's operations round.  Where the program takes |x| of x = 0 it
    uses JAX's slope of |x| there (`abs_slope_at_zero`).  The first call at a
    new array shape compiles (tens of milliseconds); later calls reuse it.

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    uu, vv : (n,) float64 chart coordinates
    ku, kv : float
    height : sympy expression or None, keyword-only
        The program to differentiate, in `renderer.formulas` u, v, k_u, k_v;
        None (the default) for the field's ``HEIGHT[name]``.  A test hands
        in a wrong one to see it caught.

    Returns
    -------
    (h_u, h_v) : two (n,) float64 numpy arrays.

    Raises
    ------
    ValueError
        If ``name`` is unknown.
    """
    import jax
    _check_name(name)
    fn = _ad_program(F.HEIGHT[name] if height is None else height)
    uu, vv = np.broadcast_arrays(np.asarray(uu, dtype=np.float64), np.asarray(vv, dtype=np.float64))
    with jax.enable_x64(True):
        h_u, h_v = fn(uu, vv, float(ku), float(kv))
        return np.asarray(h_u), np.asarray(h_v)


@lru_cache(maxsize=None)
def ad_trig_calls(name):
    """Sines and cosines per point in the program XLA compiled for `ad_gradient` of ``name``.

    Counted in the optimised HLO text, after XLA's common-subexpression
    elimination has merged what it could of the two passes, at a small
    array size (the program is the same at every size).

    Raises
    ------
    ValueError
        If ``name`` is unknown.
    """
    import re

    import jax
    _check_name(name)
    x = np.zeros(4)
    with jax.enable_x64(True):
        text = _ad_program(F.HEIGHT[name]).lower(x, x, 1.0, 1.0).compile().as_text()
    return len(re.findall(r"\b(?:sine|cosine)\(", text))


@lru_cache(maxsize=None)
def _xla_exact_program(name):
    """The exact gradient `renderer.formulas.GRADIENT` of field ``name`` printed for JAX by
    ``sympy.lambdify`` (common subexpressions shared) and jit-compiled by XLA, as
    `_ad_program` compiles the program AD differentiates."""
    import jax
    fn = sp.lambdify((F.u, F.v, F.k_u, F.k_v), list(F.GRADIENT[name]), modules="jax", cse=True)
    return jax.jit(lambda uu, vv, ku, kv: tuple(fn(uu, vv, ku, kv)))


def xla_exact_gradient(name, uu, vv, ku, kv):
    """The exact chart gradient compiled by XLA, AD's compiler: (h_u, h_v), two (n,) float64
    arrays for (n,) float64 ``uu``, ``vv``.  `same_compiler_times` times it beside
    `ad_gradient`.  Raises ValueError if ``name`` is unknown."""
    import jax
    _check_name(name)
    uu, vv = np.broadcast_arrays(np.asarray(uu, dtype=np.float64), np.asarray(vv, dtype=np.float64))
    with jax.enable_x64(True):
        h_u, h_v = _xla_exact_program(name)(uu, vv, float(ku), float(kv))
        return np.broadcast_to(np.asarray(h_u), uu.shape), np.broadcast_to(np.asarray(h_v), uu.shape)


def same_compiler_times(uu, vv, *, ku=None, kv=None, rounds=21, fields_=FIELDS):
    """AD and the exact gradient through one compiler (XLA), and the exact gradient
    compiled by numba, timed side by side.

    Per field, after one call of each (which compiles), ``rounds`` interleaved
    rounds of `xla_exact_gradient`, `ad_gradient` and
    `renderer.pointwise.exact_gradient` (numba) on the chart points ``uu``,
    ``vv`` ((n,) float64); ``ku``, ``kv`` default to the draft's scene's.
    Separates what the method costs from what the compiler costs: §5's
    benchmark sets AD (XLA) beside the exact gradient compiled by numba.

    Returns
    -------
    dict field -> {"exact": seconds, "ad": seconds, "numba": seconds, "ratio": ad / exact,
    "compiler": exact / numba}, medians.

    Raises
    ------
    ValueError
        If ``rounds`` is not a positive int or a field is unknown.
    """
    if not isinstance(rounds, int) or isinstance(rounds, bool) or rounds < 1:
        raise ValueError(f"rounds must be a positive int, got {rounds!r}")
    ku = float(DRAFT_SCENE.k_u if ku is None else ku)
    kv = float(DRAFT_SCENE.k_v if kv is None else kv)
    out = {}
    for name in fields_:
        _check_name(name)
        calls = {"exact": lambda: xla_exact_gradient(name, uu, vv, ku, kv),
                 "ad": lambda: ad_gradient(name, uu, vv, ku, kv),
                 "numba": lambda: pointwise.exact_gradient(name, uu, vv, ku, kv)}
        times = {k: [] for k in calls}
        for call in calls.values():                  # the first call compiles
            call()
        for _ in range(rounds):
            for k, call in calls.items():
                t0 = time.perf_counter()
                call()                               # returns numpy arrays: the work is done
                times[k].append(time.perf_counter() - t0)
        exact, ad, numba = (float(np.median(times[k])) for k in ("exact", "ad", "numba"))
        out[name] = {"exact": exact, "ad": ad, "numba": numba, "ratio": ad / exact, "compiler": exact / numba}
    return out


def abs_slope_at_zero():
    """JAX's forward-mode slope of |x| at x = +0.0 and x = -0.0, measured: (float, float).

    |x| has no derivative at 0; an AD tool must still return a number there,
    and which one is its convention.
    """
    import jax
    import jax.numpy as jnp
    with jax.enable_x64(True):
        return tuple(float(jax.jvp(jnp.abs, (jnp.float64(x),), (jnp.float64(1.0),))[1]) for x in (0.0, -0.0))


def crease_values(*, v=None, eps=None, ku=None, kv=None):
    """h_u of the ridges field on two of its creases in u, by three methods, beside the one-sided slopes.

    The creases are u = 0, where the factor sin(pi k_u u) is exactly 0 in
    float64, and u = 1/k_u as float64 holds it, where the float64 factor is
    a rounding residue, not 0, so the sign of f picks a side.

    Parameters
    ----------
    v : float or None, keyword-only
        The chart v of both points; None for the U-curve's point
        (`renderer.ucurve.SEED_POINT`), off the creases in v.
    eps : float > 0 or None, keyword-only
        The central difference's step in chart units; None for the draft
        scene's step.
    ku, kv : float or None, keyword-only
        The frequencies; None for the U-curve's (`renderer.ucurve.SEED_FREQUENCIES`).

    Returns
    -------
    list of two dicts of floats: ``u``; ``factor``, sin(pi k_u u) in float64;
    ``exact``, the generated gradient (sign(0) = 0); ``ad``, `ad_gradient`;
    ``central``, the kernel's central difference at ``eps``; ``left`` and
    ``right``, the one-sided slopes of |f| in u, -|f_u| and +|f_u| with f_u
    sympy's derivative of the product evaluated by mpmath.

    Raises
    ------
    ValueError
        If ``eps`` is not a positive finite number.
    """
    from renderer import ucurve
    v = ucurve.SEED_POINT[1] if v is None else float(v)
    ku0, kv0 = ucurve.SEED_FREQUENCIES
    ku, kv = float(ku0 if ku is None else ku), float(kv0 if kv is None else kv)
    eps = float(DRAFT_SCENE.eps) if eps is None else eps
    if not (np.isfinite(eps) and eps > 0):
        raise ValueError(f"eps must be a positive finite number, got {eps!r}")
    f_u = sp.lambdify((F.u, F.v, F.k_u, F.k_v), sp.diff(F.RIDGE_FACTORS[0] * F.RIDGE_FACTORS[1], F.u),
                      modules="mpmath")
    out = []
    for u0 in (0.0, 1.0 / ku):
        uu, vv = np.array([u0]), np.array([v])
        slope = abs(float(f_u(mpmath.mpf(u0), mpmath.mpf(v), mpmath.mpf(ku), mpmath.mpf(kv))))
        out.append(dict(u=u0, factor=float(np.sin(np.pi * ku * u0)),
                        exact=float(pointwise.exact_gradient("ridges", uu, vv, ku, kv)[0][0]),
                        ad=float(ad_gradient("ridges", uu, vv, ku, kv)[0][0]),
                        central=float(pointwise.central_gradient("ridges", uu, vv, ku, kv, eps)[0][0]),
                        left=-slope, right=slope))
    return out


# --- the reference -------------------------------------------------------------------------

@lru_cache(maxsize=None)
def _reference_fn(name, ku, kv):
    # Exact rational frequencies, so that mpmath does not inherit float64 rounding.
    # First derivatives of |f| carry sign(f), no DiracDelta: usable as they are.
    ks = {F.k_u: sp.nsimplify(ku), F.k_v: sp.nsimplify(kv)}
    exprs = [g.subs(ks) for g in F.GRADIENT[name]]
    return sp.lambdify((F.u, F.v), exprs, modules="mpmath", cse=True)


def reference_gradient(name, uu, vv, ku, kv, *, digits=34):
    """The exact gradient at float64 chart points, evaluated by mpmath.

    sympy's derivative of the field (`renderer.formulas.GRADIENT`) is
    evaluated with mpmath at ``digits`` decimal digits, at the chart points
    exactly as float64 represents them, and returned as a double-double: the
    value rounded to float64 (``hi``) and the rounding residual (``lo``).  An
    error |x - ref| of a float64 estimate x is then ``|(x - hi) - lo|``, exact
    up to one rounding of the error itself.  Working precision: 34 digits
    put the reference's own error (~1e-33 relative) sixteen orders below the
    float64 spacing it judges; ``lo`` needs only 32.

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    uu, vv : (n,) float64
    ku, kv : float (converted to exact rationals)
    digits : int, keyword-only

    Returns
    -------
    (hi, lo) : two (2, n) float64 arrays; row 0 is h_u, row 1 is h_v.
    """
    _check_name(name)
    fn = _reference_fn(name, float(ku), float(kv))
    uu, vv = np.broadcast_arrays(np.ravel(uu), np.ravel(vv))
    hi = np.empty((2, uu.size))
    lo = np.empty((2, uu.size))
    with mpmath.workdps(digits):
        for j, (a, b) in enumerate(zip(uu.tolist(), vv.tolist())):
            for c, val in enumerate(fn(mpmath.mpf(a), mpmath.mpf(b))):
                hi[c, j] = float(val)
                lo[c, j] = float(val - hi[c, j])
    return hi, lo


# --- the work per pixel -------------------------------------------------------------------

def _check_name(name):
    if name not in F.HEIGHT:
        raise ValueError(f"height_field must be one of {tuple(F.HEIGHT)}, got {name!r}")


def trig_calls(exprs):
    """Sines and cosines evaluated per point by the code generated from ``exprs``.

    ``renderer.codegen`` prints a function's outputs after one common-subexpression
    elimination over all of them (``sympy.cse``); a sine or cosine left in the
    eliminated code is computed once per point, so this counts the sin and cos
    nodes of the replacements and the reduced outputs.  The numba kernel calls
    exactly these (tests/test_gradient_methods.py compares the count with the
    text of renderer/generated.py).
    """
    subs, reduced = sp.cse(list(exprs), symbols=sp.numbered_symbols("x"))
    return sum(isinstance(node, (sp.sin, sp.cos))
               for e in [x for _, x in subs] + list(reduced) for node in sp.preorder_traversal(e))


def stencil_values(name):
    """Values of h per point in the kernel's central difference of field ``name``:
    the stencil points (`formulas.STENCIL_POINTS`) that `formulas.CENTRAL` reads.
    4 for sine and ridges; 2 for rings, whose u-difference sympy reduced to 0."""
    _check_name(name)
    used = set().union(*(c.free_symbols for c in F.CENTRAL[name]))
    return sum(p in used for p, _ in F.STENCIL_POINTS)


@dataclass(frozen=True)
class Evaluations:
    """Work per pixel: real values of h, complex values of h, evaluations of the
    generated gradient, forward-mode passes through h's program (a value and
    one tangent each), and the real sines and cosines all of them cost."""

    h: float = 0.0
    h_complex: float = 0.0
    gradient: float = 0.0
    trig: float = 0.0
    h_tangent: float = 0.0


def evaluations(name, method, *, h_per_pixel=None):
    """The work per pixel of ``method`` on field ``name``, from the sympy objects.

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    method : str
        "exact", "central", "forward", "complex step", "complex step, |z|
        continued", "richardson", `AD` (its sines and cosines counted in
        the compiled program, `ad_trig_calls`) or "h" (one evaluation of h
        alone).
    h_per_pixel : float, keyword-only
        For "richardson" only: the values of h per pixel scipy reported (its
        iteration adapts, so the count is measured, not derived).

    Returns
    -------
    Evaluations

    Raises
    ------
    ValueError
        An unknown field or method, or ``h_per_pixel`` missing for "richardson".
    """
    _check_name(name)
    per_h = trig_calls((F.HEIGHT[name],))
    if method == "exact":
        return Evaluations(gradient=1.0, trig=float(trig_calls(F.GRADIENT[name])))
    if method == "central":
        return Evaluations(h=float(stencil_values(name)), trig=float(trig_calls(F.CENTRAL[name])))
    if method == "forward":
        return Evaluations(h=3.0, trig=3.0 * per_h)
    if method in ("complex step", "complex step, |z| continued"):
        return Evaluations(h_complex=2.0)
    if method == "h":
        return Evaluations(h=1.0, trig=float(per_h))
    if method == AD:
        return Evaluations(h_tangent=2.0, trig=float(ad_trig_calls(name)))
    if method == "richardson":
        if h_per_pixel is None:
            raise ValueError("richardson's evaluations are measured: pass h_per_pixel")
        return Evaluations(h=float(h_per_pixel), trig=float(h_per_pixel) * per_h)
    raise ValueError(f"unknown method {method!r}")


# --- the measurement -----------------------------------------------------------------------

@dataclass(frozen=True)
class MethodResult:
    """One method on one field.

    Times are seconds per frame (all sphere-A pixels, both components);
    evaluations are per pixel; errors are absolute, in units of h per chart
    unit, over both components at the reference pixels.
    """

    field: str
    method: str                 # "exact", "central", "forward", "complex step", ...
    eps: float | None           # the step, or None
    valid: bool                 # False: the method's premise fails on this field
    times: tuple                # seconds, one per repeat
    h_evals: float              # real evaluations of h per pixel (`evaluations`)
    h_complex_evals: float      # complex evaluations of h per pixel
    gradient_evals: float       # evaluations of the generated gradient per pixel
    max_error: float
    rms_error: float
    note: str = ""
    trig_evals: float = 0.0     # real sines and cosines per pixel
    h_tangent_evals: float = 0.0        # forward-mode passes through h per pixel (AD)
    compile_seconds: float | None = None    # AD: its first call in the process at the frame's size (trace, compile, run)

    @property
    def label(self):
        """The method and its step, e.g. ``central 1e-06``."""
        return self.method if self.eps is None else f"{self.method} {self.eps:.0e}"

    @property
    def median(self):
        """Median time per frame, seconds."""
        return float(np.median(self.times))

    @property
    def t_min(self):
        """Fastest run, seconds."""
        return float(min(self.times))

    @property
    def t_max(self):
        """Slowest run, seconds."""
        return float(max(self.times))


@dataclass(frozen=True)
class Measurement:
    """All results of one `measure` run.

    ``pixels`` is the number of sphere-A pixels timed per frame;
    ``reference_pixels`` maps each field to the number of pixels whose error
    was measured, ``excluded_pixels`` to the number of the frame's pixels on
    the crease band, where no error is measured (0 for sine and rings);
    ``h_times`` to the times (seconds) of one evaluation of h at all pixels,
    timed among the methods as a unit of cost; ``seconds`` is the wall time
    of the run.
    """

    config: Config
    results: tuple
    pixels: int
    reference_pixels: dict
    excluded_pixels: dict
    h_times: dict
    seconds: float
    k_u: float
    k_v: float
    machine: dict = dc_field(default_factory=dict)

    def of(self, field):
        """The results for one field, in the order they were defined."""
        return [r for r in self.results if r.field == field]

    def get(self, field, label):
        """The result with this field and label; KeyError if absent."""
        for r in self.results:
            if r.field == field and r.label == label:
                return r
        raise KeyError((field, label))


def methods(name, config, ku, kv):
    """The methods measured on field ``name``: a list of (method, eps, valid, fn, note).

    ``fn(u, v)`` returns (h_u, h_v); ``valid`` is False where the method's
    premise fails (complex step on a field that is not analytic).
    """
    out = [("exact", None, True, lambda u, v: pointwise.exact_gradient(name, u, v, ku, kv), "")]
    for eps in config.central_steps:
        out.append(("central", eps, True,
                    lambda u, v, eps=eps: pointwise.central_gradient(name, u, v, ku, kv, eps), ""))
    for eps in config.forward_steps:
        out.append(("forward", eps, True,
                    lambda u, v, eps=eps: forward_gradient(name, u, v, ku, kv, eps), ""))
    analytic = ANALYTIC[name]
    for eps in config.complex_steps:
        note = "" if analytic else "h is not analytic: Im |f(u + i eps)| = 0"
        out.append(("complex step", eps, analytic,
                    lambda u, v, eps=eps: complex_step_gradient(name, u, v, ku, kv, eps), note))
    if not analytic and F.HEIGHT[name].has(sp.Abs):
        eps = min(config.complex_steps)
        out.append(("complex step, |z| continued", eps, True,
                    lambda u, v, eps=eps: complex_step_gradient(name, u, v, ku, kv, eps, continued=True),
                    "|f| evaluated as f sign(Re f); one-sided on the crease"))
    out.append(("richardson", None, True, lambda u, v: richardson_gradient(name, u, v, ku, kv),
                f"scipy.differentiate.derivative, order {RICHARDSON['order']}"))
    out.append((AD, None, True, lambda u, v: ad_gradient(name, u, v, ku, kv), "jax.jvp, jit-compiled"))
    return out


def _errors(approx, hi, lo):
    err = np.abs((np.stack(approx) - hi) - lo)
    return float(err.max()), float(np.sqrt(np.mean(err**2)))


def measure(config=FAST, *, fields_=FIELDS, uv=None):
    """Time and check every method on every field, with its work per pixel (see the module docstring).

    Parameters
    ----------
    config : Config
        `FAST` (book build) or `FULL` (release).
    fields_ : sequence of field names, keyword-only
    uv : (u, v) pair of (n,) float64 arrays or None, keyword-only
        Chart points of the sphere-A pixels, shared by all fields (they do
        not depend on the field); None computes them with `chart_points`
        for each field.

    Returns
    -------
    Measurement

    Notes
    -----
    Per field, one run of every method at the reference pixels gives the
    errors; the work per pixel is `evaluations` (for scipy's adaptive
    iteration, its own count at those pixels, a sample's mean in `FAST`).
    AD is then called once on all pixels, which compiles its program for
    that size (`MethodResult.compile_seconds`).  Then ``config.repeats``
    rounds time every (field, method) pair on all pixels, in an order shuffled each round, so that drifts of the
    machine's speed fall on all of them alike.
    """
    t_start = time.perf_counter()
    load_start = os.getloadavg() if hasattr(os, "getloadavg") else None
    rng = np.random.default_rng(config.seed)
    scene = DRAFT_SCENE
    ku, kv = float(scene.k_u), float(scene.k_v)
    results, n_ref, n_excl, h_times = [], {}, {}, {}
    pixels = None
    checked, timed = [], []
    for name in fields_:
        u, v = chart_points(name, config.size) if uv is None else uv
        pixels = u.size
        # The error sample: pixels where the gradient exists (off the ridges' crease band).
        off = np.flatnonzero(~pointwise.kink_band(name, u, v, ku, kv))
        n_excl[name] = int(u.size - off.size)
        if config.reference_pixels is not None and config.reference_pixels < off.size:
            pick = np.sort(rng.choice(off, size=config.reference_pixels, replace=False))
        else:
            pick = off
        n_ref[name] = int(pick.size)
        ru, rv = u[pick].copy(), v[pick].copy()
        hi, lo = reference_gradient(name, ru, rv, ku, kv, digits=config.digits)

        # Errors: one run of every method at the reference pixels; the work per pixel.
        for method, eps, valid, fn, note in methods(name, config, ku, kv):
            compile_s = None
            if method == AD:        # the first call at the frame's size traces and compiles: timed apart
                t0 = time.perf_counter()
                fn(u, v)
                compile_s = time.perf_counter() - t0
            if method == "richardson":
                info = {}
                approx = richardson_gradient(name, ru, rv, ku, kv, info=info)
                work = evaluations(name, method, h_per_pixel=info["nfev"] / ru.size)
                if info["not_converged"]:
                    note = (note + "; " if note else "") + \
                        f"{info['not_converged']} of {2 * ru.size} components not converged"
            else:
                approx = fn(ru, rv)
                work = evaluations(name, method)
            checked.append((name, method, eps, valid, note, work, _errors(approx, hi, lo), compile_s))
            timed.append((fn, u, v, config.richardson_repeats if method == "richardson" else config.repeats))
        # One evaluation of h alone, timed with the methods as a unit of cost.
        timed.append((lambda uu, vv, name=name: pointwise.height(name, uu, vv, ku, kv), u, v, config.repeats))

    # Timing: every (field, method) on all pixels, in an order shuffled
    # every round, so that changes in the machine's load fall on all of them alike.
    times = [[] for _ in timed]
    for _ in range(max(q for *_, q in timed)):
        for k in rng.permutation(len(timed)):
            fn, uu, vv, quota = timed[k]
            if len(times[k]) == quota:
                continue
            t0 = time.perf_counter()
            fn(uu, vv)
            times[k].append(time.perf_counter() - t0)
    it = iter(times)            # same order as `timed`: per field, its methods, then h
    for name in fields_:
        for entry in [c for c in checked if c[0] == name]:
            _, method, eps, valid, note, work, (emax, erms), compile_s = entry
            results.append(MethodResult(name, method, eps, valid, tuple(next(it)), work.h, work.h_complex,
                                        work.gradient, emax, erms, note, work.trig, work.h_tangent, compile_s))
        h_times[name] = tuple(next(it))
    machine = {"python": platform.python_version(), "numpy": np.__version__,
               "scipy": sys.modules["scipy"].__version__,
               "jax": sys.modules["jax"].__version__ if "jax" in sys.modules else None, "cpus": os.cpu_count(),
               "processor": platform.processor() or platform.machine(),
               "load_average_1_5_15_min_at_start": load_start}
    return Measurement(config, tuple(results), int(pixels), n_ref, n_excl, h_times,
                       time.perf_counter() - t_start, ku, kv, machine)


# --- presentation --------------------------------------------------------------------------

def _non_dominated(times, errors):
    """Indices of the points not dominated in (time, error), both minimised.

    A point is dominated when another is no worse in both coordinates and
    strictly better in one.  Equal points do not dominate each other.
    """
    t = np.asarray(times, dtype=np.float64)
    e = np.asarray(errors, dtype=np.float64)
    if t.shape != e.shape or t.ndim != 1:
        raise ValueError("times and errors must be 1-D sequences of the same length")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(e))):
        raise ValueError("times and errors must be finite")
    keep = []
    for i in range(t.size):
        dominated = np.any((t <= t[i]) & (e <= e[i]) & ((t < t[i]) | (e < e[i])))
        if not dominated:
            keep.append(i)
    return keep


def pareto_front(results, *, error="max"):
    """The results not dominated in (median time, error), sorted by time.

    Parameters
    ----------
    results : sequence of MethodResult
        Usually one field's results (`Measurement.of`).
    error : {"max", "rms"}, keyword-only
        Which error is minimised with the time.

    Returns
    -------
    list of MethodResult, fastest first.

    Raises
    ------
    ValueError
        If ``error`` is not "max" or "rms", or a time or error is not finite.
    """
    if error not in ("max", "rms"):
        raise ValueError(f"error must be 'max' or 'rms', got {error!r}")
    results = list(results)
    errs = [r.max_error if error == "max" else r.rms_error for r in results]
    keep = _non_dominated([r.median for r in results], errs)
    return sorted((results[i] for i in keep), key=lambda r: r.median)


def to_json(measurement):
    """The measurement as a JSON string (times in seconds, every repeat kept)."""
    out = {"config": asdict(measurement.config), "pixels": measurement.pixels,
           "h_alone_seconds": {k: list(v) for k, v in measurement.h_times.items()},
           "reference_pixels": measurement.reference_pixels,
           "excluded_pixels_crease_band": measurement.excluded_pixels,
           "seconds": measurement.seconds, "k_u": measurement.k_u, "k_v": measurement.k_v,
           "machine": measurement.machine, "results": []}
    for name in dict.fromkeys(r.field for r in measurement.results):
        front = pareto_front(measurement.of(name))
        for r in measurement.of(name):
            d = asdict(r)
            d.update(label=r.label, median=r.median, t_min=r.t_min, t_max=r.t_max, on_front=r in front)
            out["results"].append(d)
    return json.dumps(out, indent=1)
