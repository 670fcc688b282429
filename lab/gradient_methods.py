"""Run time against error for the ways of computing a derivative: of a height field's chart
gradient over a frame, and of a reader's function of one variable at a point.

Each way is one `Method` record in `METHODS`, in the order tables and legends list them:

* ``exact``: the kernel's generated gradient (sympy's derivative,
  `renderer.formulas.HeightField.gradient`), `renderer.pointwise.exact_gradient`;
* ``central``: the kernel's central difference (`HeightField.central`),
  `renderer.pointwise.central_gradient`, at each step of a sweep;
* ``forward``: the one-sided difference (h(u + eps) - h(u)) / eps (`forward_gradient`);
* ``complex step``: Im h(u + i eps) / eps [1]_, h evaluated in complex numpy by
  ``sympy.lambdify`` (`complex_step_gradient`); it applies where h is analytic
  (`HeightField.analytic`, no ``Abs``): lambdify's ``abs`` of a complex number is its
  modulus, a real number, and the plain complex step of |f| returns 0;
* ``complex step, |z| continued``: the usual repair for |f| [2]_, which continues |z| as
  z sign(Re z); it applies to the fields with an ``Abs``;
* ``richardson``: `scipy.differentiate.derivative` [3]_, an adaptive differentiator that
  raises the order of accuracy by combining nested steps (`richardson_gradient`);
* ``forward-mode AD``: ``jax.jvp`` [4]_ of the program that evaluates h, printed from the
  sympy expression by ``sympy.lambdify(..., modules="jax")`` (`ad_gradient`).  AD
  differentiates that program, operation by operation; its one choice that is not a
  derivative is JAX's slope of |x| at x = 0 (`abs_slope_at_zero`, measured).

A record holds everything the measurement, the tables and the figures need of its method:
its function (over chart points of a field, and over one real point of a function of one
variable), its work per pixel, which steps of a `Config` it runs at, its label and style,
where it applies, its sources.  `measure`, `univariate_errors` and book/chapter/benchmark.py
read only the records: adding a method is one record appended to `METHODS`, and nothing
else changes (tests/test_gradient_methods.py appends a backward difference and sees it
measured and drawn).

`measure` times every method that applies to a field over the sphere-A pixels of a
256 x 256 frame of the draft's scene (median, minimum and maximum over repeats, methods
interleaved), counts its work per pixel (`Evaluations`: values of h, evaluations of the
generated gradient, and the sines and cosines they cost, counted from the sympy objects the
kernel is generated from; scipy counts its own evaluations), and measures the largest and
RMS error of both components against an mpmath reference of the exact gradient
(`reference_gradient`).  Where a field has creases the derivative does not exist on them, so
errors are measured off the crease band (`renderer.pointwise.kink_band`); the timings cover
every pixel.  The exact and central gradients and h itself are the kernel's compiled
functions; forward differences call the compiled h three times from numpy; the complex
step evaluates h in complex numpy; Richardson calls the compiled h from scipy's iteration;
AD runs JAX's jit-compiled (XLA) program, whose first call at a frame's size compiles and
is timed apart (`MethodResult.compile_seconds`).  So the times compare the methods as they
are available here, not as each could best be compiled.

`univariate_errors` runs the methods on a reader's f(x) (`renderer.formulas.univariate`) at
any real x where it is differentiable, at each step of a grid, against the mpmath value of
its derivative; the central difference's row is `renderer.ucurve.measure_function`'s
U-curve.  `PUBLISHED` holds what the complex-step papers report about their test function.

`FAST` is the configuration the book runs when it is built; `FULL` the one the benchmark
runs for a release.  `pareto_front` picks a `Measurement`'s non-dominated methods; the book
draws and tabulates it (book/chapter/benchmark.py).

References
----------
.. [1] W. Squire and G. Trapp, "Using complex variables to estimate derivatives of real
   functions", SIAM Review 40(1), 110-112, 1998.
.. [2] J. R. R. A. Martins, P. Sturdza and J. J. Alonso, "The complex-step derivative
   approximation", ACM Trans. Math. Softw. 29(3), 245-262, 2003.
.. [3] SciPy 1.17, ``scipy.differentiate.derivative``.
.. [4] A. Griewank and A. Walther, *Evaluating Derivatives*, 2nd ed., SIAM, 2008.
"""

from __future__ import annotations

import json
import math
import os
import platform
import re
import sys
import time
from dataclasses import asdict, dataclass, field as dc_field
from functools import lru_cache
from typing import Callable

import mpmath
import numpy as np
import sympy as sp

from renderer import DRAFT_SCENE, fieldcode, gbuffer, pointwise, ucurve, validate
from renderer import formulas as F
from renderer.render import SPHERE_A
from renderer.scene import FREQUENCY, UNIT
from renderer.validate import InvalidType, InvalidValue, choice, flag, positive_int, real

from ._checks import MAX_COUNT, MAX_SQUARE, STEP, chart_points as _chart, digits as _digits, instance, optional, seed
from ._checks import sequence, shown

__all__ = [
    "Style", "Method", "METHODS", "method", "Config", "FAST", "FULL", "Evaluations", "MethodResult",
    "Measurement", "chart_points", "forward_gradient", "complex_step_gradient", "richardson_gradient",
    "ad_gradient", "reference_gradient", "trig_calls", "stencil_values", "height_work", "evaluations",
    "measure", "pareto_front", "to_json", "AD", "ad_trig_calls", "abs_slope_at_zero", "crease_values",
    "xla_exact_gradient", "same_compiler_times", "UNIVARIATE_STEPS", "UnivariateRow", "UnivariateErrors",
    "univariate_errors", "Published", "Example", "TEST_FUNCTION", "PUBLISHED", "RICHARDSON",
]

#: The name of forward-mode automatic differentiation in the results.
AD = "forward-mode AD"


# --- the records ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Style:
    """How a method is drawn: ``colour`` (a matplotlib colour), ``marker`` (a matplotlib marker),
    ``size`` (its size, points) and ``line`` (the matplotlib line style joining a sweep's steps,
    or drawn across the plot by a method without a step)."""

    colour: str
    marker: str
    size: float
    line: str = "-"


def _always(field):
    return True


@dataclass(frozen=True)
class Method:
    """One way of computing a derivative: the one record a method is.

    Attributes
    ----------
    name : str
        How results name it (`MethodResult.method`).
    gradient : callable
        ``gradient(field, u, v, k_u, k_v, eps, info) -> (h_u, h_v)``: the chart gradient of
        ``field`` (a `renderer.formulas.HeightField`) at (n,) float64 chart points, two (n,)
        float64 arrays; ``eps`` the step (None for a method without one); ``info`` a dict it
        may fill with what it measured of itself (``"h_per_pixel"``, ``"not_converged"``).
    work : callable
        ``work(field, info) -> Evaluations``: its work per pixel, ``info`` as ``gradient`` left it.
    label : str
        Its name in a legend or a sentence.
    style : Style
    steps : str or None
        The `Config` attribute listing its steps; None for a method without a step.
    repeats : str
        The `Config` attribute saying how many times it is timed.
    applies : callable
        ``applies(record) -> bool`` for a `HeightField` or a `renderer.formulas.Univariate`:
        whether its premise holds there; it is measured only where it does.
    compiles : bool
        Its first call at a new array size compiles: that call is timed apart.
    note : str
        Shown beside its results in the benchmark's table.
    sources : tuple of str
        Keys of book/references.bib.
    derivative : callable or None
        ``derivative(function, x, eps, info) -> float``: f'(x) of a `Univariate` at a float x
        (`univariate_errors`); None where the method has no one-variable form.
    """

    name: str
    gradient: Callable
    work: Callable
    label: str
    style: Style
    steps: str | None = None
    repeats: str = "repeats"
    applies: Callable = _always
    compiles: bool = False
    note: str = ""
    sources: tuple = ()
    derivative: Callable | None = None

    def steps_in(self, config):
        """Its steps in ``config`` (a tuple of floats), or (None,) for a method without a step."""
        return (None,) if self.steps is None else tuple(getattr(config, self.steps))


@dataclass(frozen=True)
class Config:
    """What `measure` runs.

    Attributes
    ----------
    name : str
    central_steps, forward_steps, complex_steps : tuple of float in [1e-300, 1)
        The steps eps (chart units) of each sweep (`Method.steps` names them), 1 to 64 each.
    repeats : int in [1, 1000]
        Timed runs of every method (each run: all pixels of the frame) ...
    richardson_repeats : int in [1, 1000]
        ... except ``richardson``, ten to twenty times slower than the rest, which is timed
        this many times (`Method.repeats`).
    reference_pixels : int in [1, 2**24] or None
        Pixels per field at which errors are measured against mpmath (a seeded sample of the
        pixels where the gradient exists); None for all.
    digits : int in [32, 1000]
        mpmath working precision of the reference, in decimal digits.
    size : int in [1, 4096]
        Frame side in pixels.
    seed : int in [0, 2**64 - 1]
        Seed of the pixel sample and of the order in which methods run.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        A field not of its kind or out of its range (a bool where a number is meant, a
        string where steps are), naming ``Config.<field>``.
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

    def __post_init__(self):
        """Checks each field as its kind (`lab._checks`), once, when the record is made (also by
        ``dataclasses.replace``): InvalidType or InvalidValue naming ``Config.<field>``; the steps
        are kept as tuples of floats."""
        def check(attr, kind, *args, **kwargs):
            object.__setattr__(self, attr, kind(f"Config.{attr}", getattr(self, attr), *args, **kwargs))

        check("name", instance, str, "a string")
        for attr in ("central_steps", "forward_steps", "complex_steps"):
            check(attr, lambda *a: tuple(validate.steps(*a, **STEP, max_count=64).tolist()))
        check("repeats", positive_int, high=1000)
        check("richardson_repeats", positive_int, high=1000)
        check("reference_pixels", lambda n, x: optional(positive_int, n, x, high=MAX_COUNT))
        check("digits", _digits)
        check("size", positive_int, high=MAX_SQUARE)
        check("seed", seed)


#: Book build (§5, Cell 4, which reports the time it took): a few hundred reference pixels
#: at 34 digits and one Richardson run per field keep it to about a second.
#: Steps: the draft's step, near each quotient's optimum (central 1e-6, forward 1e-8),
#: and one past the central optimum, where rounding rules.
FAST = Config("fast", central_steps=(DRAFT_SCENE.eps, 1e-6, 1e-9), forward_steps=(DRAFT_SCENE.eps, 1e-8),
              complex_steps=(1e-20,), repeats=3, richardson_repeats=1, reference_pixels=100)
#: Release: every pixel in the reference, twelve steps per sweep, more repeats.
FULL = Config("full", central_steps=tuple(10.0 ** -np.arange(1, 13)),
              forward_steps=tuple(10.0 ** -np.arange(1, 13)),
              complex_steps=(1e-2, 1e-4, 1e-6, 1e-8, 1e-20, 1e-100), repeats=15, richardson_repeats=15,
              reference_pixels=None, digits=40)


# --- chart points --------------------------------------------------------------------------

def chart_points(field=None, size=256):
    """Chart coordinates (u, v) of the sphere-A pixels of a frame of the draft's scene.

    Parameters
    ----------
    field : height field or None
        As `renderer.formulas.field` takes it; None for the draft's.  The chart does not depend
        on it (it is computed from the geometry before any gradient).
    size : int in [1, 4096]
        Frame side in pixels.

    Returns
    -------
    (u, v) : two (n,) float64 arrays, contiguous, in row-major pixel order.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``field`` refused (naming ``field``), ``size`` not an integer in range.
    """
    field = None if field is None else F.field(field, "field")
    scene = DRAFT_SCENE if field is None else DRAFT_SCENE.replace(height_field=field)
    size = positive_int("size", size, high=MAX_SQUARE)
    g = gbuffer(scene, size, size)
    uv = g.uv[g.chamber == SPHERE_A]
    return np.ascontiguousarray(uv[:, 0]), np.ascontiguousarray(uv[:, 1])


# --- the methods over a field --------------------------------------------------------------

#: What the methods over a field take and refuse, once in each docstring's words.
_FIELD_ARGS = """field : height field
        As `renderer.formulas.field` takes it.
    uu, vv : array_like of float in [0, 1], broadcast together
        Chart coordinates ((n,) float64 arrays as a rule).
    ku, kv : float in (0, 1e3]
        Frequencies, as `renderer.Scene` takes them."""
_FIELD_RAISES = """renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: ``field`` refused by `renderer.formulas.field`; ``uu``, ``vv`` not
        real numbers in [0, 1] (a bool, a NaN, a string) or not broadcasting together; ``ku``,
        ``kv`` not real numbers in (0, 1e3] (inf, 10**400, a bool)"""


def _documented(fn):
    """``fn`` with `_FIELD_ARGS` and `_FIELD_RAISES` written into its docstring's placeholders."""
    fn.__doc__ = fn.__doc__.replace("{_FIELD_ARGS}", _FIELD_ARGS).replace("{_FIELD_RAISES}", _FIELD_RAISES)
    return fn


def _field_args(field, uu, vv, ku, kv):
    """(record, uu, vv, ku, kv) checked as `_FIELD_ARGS` says."""
    return (F.field(field, "field"), *_chart(uu, vv, ku, kv))


@_documented
def forward_gradient(field, uu, vv, ku, kv, eps):
    """One-sided (forward) difference chart gradient.

    h_u = (h(u + eps, v) - h(u, v)) / eps with u + eps wrapped modulo 1 (the chart is periodic
    in u), and h_v the same in v, except where v + eps > 1, where the step is taken backwards,
    (h(u, v) - h(u, v - eps)) / eps.  The quotient is divided by the nominal step, as the
    kernel's central difference does.  h(u, v) is shared by both components: three
    evaluations of h per point.  Truncation error O(eps); h is the kernel's,
    `renderer.pointwise.height`.

    Parameters
    ----------
    {_FIELD_ARGS}
    eps : float in [1e-300, 1)
        The step in chart units.

    Returns
    -------
    (h_u, h_v) : two float64 arrays of the broadcast shape.

    Raises
    ------
    {_FIELD_RAISES}; ``eps`` not a real number in [1e-300, 1).
    """
    return _forward_gradient(*_field_args(field, uu, vv, ku, kv), real("eps", eps, **STEP))


def _forward_gradient(field, uu, vv, ku, kv, eps):
    h0 = pointwise.height(field, uu, vv, ku, kv)
    hu = (pointwise.height(field, np.mod(uu + eps, 1.0), vv, ku, kv) - h0) / eps
    step = np.where(vv + eps > 1.0, -eps, eps)
    hv = (pointwise.height(field, uu, vv + step, ku, kv) - h0) / step
    return hu, hv


def _abs_continued(z):
    """|x| continued off the real axis as z sign(Re z) (Martins et al. 2003, sec. 3)."""
    return np.where(np.real(z) < 0, -z, z)


@lru_cache(maxsize=None)
def _complex_fn(expr, symbols, continued):
    """``expr`` as a complex numpy function of ``symbols``; with ``continued`` its Abs is
    `_abs_continued` (with "Abs" in a user namespace, lambdify prints Abs(...) and calls it)."""
    return sp.lambdify(symbols, expr, modules=[{"Abs": _abs_continued}, "numpy"] if continued else "numpy")


@_documented
def complex_step_gradient(field, uu, vv, ku, kv, eps, *, continued=False):
    """Complex-step chart gradient, h_u = Im h(u + i eps, v) / eps, h_v likewise.

    h is the field's sympy expression evaluated in complex128 numpy by ``sympy.lambdify``.
    No difference is taken, so there is no cancellation and eps may be tiny (1e-20 is
    usual); the truncation error is O(eps^2).  Two complex evaluations of h per point.
    Valid only where h is analytic (`renderer.formulas.HeightField.analytic`): numpy's abs of
    a complex number is its modulus, a real number, and the result is 0.  With
    ``continued=True`` the expression's Abs is evaluated as z sign(Re z) [Martins et al.
    2003], which gives the one-sided derivative of |f|.

    Parameters
    ----------
    {_FIELD_ARGS}
    eps : float in [1e-300, 1)
        The imaginary step in chart units.
    continued : bool, keyword-only

    Returns
    -------
    (h_u, h_v) : two float64 arrays of the broadcast shape.

    Raises
    ------
    {_FIELD_RAISES}; ``eps`` not a real number in [1e-300, 1); ``continued`` not True or False.
    """
    return _complex_step_gradient(*_field_args(field, uu, vv, ku, kv), real("eps", eps, **STEP),
                                  continued=flag("continued", continued))


def _complex_step_gradient(field, uu, vv, ku, kv, eps, *, continued=False):
    h = _complex_fn(field.expr, F.FIELD_SYMBOLS, continued)
    shape = np.broadcast(uu, vv).shape
    ku, kv = np.float64(ku), np.float64(kv)     # k_u**k_u overflows to inf, as in the kernel, not raising
    hu = np.imag(h(uu + 1j * eps, vv, ku, kv)) / eps
    hv = np.imag(h(uu, vv + 1j * eps, ku, kv)) / eps
    return np.broadcast_to(hu, shape), np.broadcast_to(hv, shape)


#: scipy.differentiate.derivative's settings over a field.  The first step is half a radian of
#: phase at the highest frequency of the draft's scene (pi k_u = 8 pi); atol lets it stop where a
#: component is exactly 0 (rings: h_u = 0), which its default (the smallest normal float) never does.
RICHARDSON = dict(initial_step=0.02, order=8, step_factor=2.0, maxiter=10, tolerances=dict(atol=1e-12))


@_documented
def richardson_gradient(field, uu, vv, ku, kv, *, info=None):
    """Chart gradient by `scipy.differentiate.derivative` (settings `RICHARDSON`).

    Both components are computed in one vectorised call: the 2n abscissae are u (moving u)
    followed by v (moving v).  h is `renderer.pointwise.height`, evaluated at whatever steps
    scipy chooses.  Elements whose iteration did not converge (scipy status != 0) keep
    scipy's last estimate.

    Parameters
    ----------
    {_FIELD_ARGS}
    info : dict or None, keyword-only
        If given, receives ``"not_converged"`` (int, elements with status != 0),
        ``"iterations"`` (float, mean iterations per element) and ``"h_per_pixel"`` (float,
        scipy's own count of points evaluated per pixel, both components).

    Returns
    -------
    (h_u, h_v) : two float64 arrays of the broadcast shape.

    Raises
    ------
    {_FIELD_RAISES}; ``info`` not a dict or None.
    """
    return _richardson_gradient(*_field_args(field, uu, vv, ku, kv),
                                info=optional(instance, "info", info, dict, "a dict or None"))


def _richardson_gradient(record, uu, vv, ku, kv, *, info=None):
    uu, vv = np.broadcast_arrays(np.asarray(uu, dtype=np.float64), np.asarray(vv, dtype=np.float64))
    n = uu.size
    x = np.concatenate([uu.ravel(), vv.ravel()])
    other = np.concatenate([vv.ravel(), uu.ravel()])
    moves_v = np.repeat(np.array([False, True]), n)

    def h(x, other, moves_v):
        return pointwise.height(record, np.where(moves_v, other, x), np.where(moves_v, x, other), ku, kv)

    from scipy.differentiate import derivative        # here: scipy's import is 0.8 s from a fresh clone
    res = derivative(h, x, args=(other, moves_v), **RICHARDSON)
    if info is not None:
        info.update(not_converged=int(np.count_nonzero(res.status != 0)), iterations=float(np.mean(res.nit)),
                    h_per_pixel=float(np.sum(res.nfev)) / max(n, 1))
    return res.df[:n].reshape(uu.shape), res.df[n:].reshape(uu.shape)


@lru_cache(maxsize=None)
def _ad_program(height):
    """The jit-compiled forward-mode gradient of the program that evaluates ``height``.

    ``height`` (a sympy expression in u, v, k_u, k_v) is printed as a JAX function by
    ``sympy.lambdify``; ``jax.jvp`` pushes the tangent 1 through it once along u (v held)
    and once along v.  JAX is imported here, not with the module: only AD needs it.
    """
    import jax
    import jax.numpy as jnp
    h = sp.lambdify(F.FIELD_SYMBOLS, height, modules="jax")

    def height_at(uu, vv, ku, kv):      # a float: a constant field (0) prints as an int, whose tangent is float0
        return jnp.asarray(h(uu, vv, ku, kv), dtype=jnp.float64)

    def gradient(uu, vv, ku, kv):
        one = jnp.ones_like(uu)
        h_u = jax.jvp(lambda x: height_at(x, vv, ku, kv), (uu,), (one,))[1]
        h_v = jax.jvp(lambda y: height_at(uu, y, ku, kv), (vv,), (one,))[1]
        return h_u, h_v
    return jax.jit(gradient)


@_documented
def ad_gradient(field, uu, vv, ku, kv, *, height=None):
    """Chart gradient by forward-mode automatic differentiation (``jax.jvp``).

    The program differentiated is h as the field's expression writes it, printed for JAX by
    ``sympy.lambdify`` and jit-compiled by XLA, in float64 (``jax.enable_x64`` around the call
    only; JAX's global setting is left as it is).  Two forward passes per point, one tangent
    each.  No step, no truncation: the result is the derivative of the program, rounded as the
    program's operations round.  Where the program takes |x| of x = 0 it uses JAX's slope of
    |x| there (`abs_slope_at_zero`).  The first call at a new array shape compiles (tens of
    milliseconds); later calls reuse it.

    Parameters
    ----------
    {_FIELD_ARGS}
    height : sympy expression or None, keyword-only
        The program to differentiate, in u, v, k_u, k_v, checked as a reader's field is; None
        (the default) for the field's expression.  A test hands in a wrong one to see it caught.

    Returns
    -------
    (h_u, h_v) : two float64 numpy arrays of the broadcast shape.

    Raises
    ------
    {_FIELD_RAISES}; ``height`` not a sympy expression (nor None), or one a field could not be
        (`renderer.formulas.field`, naming ``height``: not real, a symbol other than u, v, k_u, k_v).
    """
    record, uu, vv, ku, kv = _field_args(field, uu, vv, ku, kv)
    if height is not None:
        # A program a field could be: real, in u, v, k_u, k_v, of the functions the printers know.
        height = F.field(instance("height", height, sp.Expr, "a sympy expression in u, v, k_u, k_v or None"),
                         "height").expr
    return _ad_gradient(record, uu, vv, ku, kv, height=height)


def _ad_gradient(record, uu, vv, ku, kv, *, height=None):
    import jax
    fn = _ad_program(record.expr if height is None else height)
    uu, vv = np.broadcast_arrays(np.asarray(uu, dtype=np.float64), np.asarray(vv, dtype=np.float64))
    with jax.enable_x64(True):
        h_u, h_v = fn(uu, vv, float(ku), float(kv))
        # A height that does not vary with u or v (2 k_u) gives JAX's scalar tangent: one per point.
        return tuple(np.array(np.broadcast_to(np.asarray(g), uu.shape)) for g in (h_u, h_v))


def ad_trig_calls(field):
    """Sines and cosines per point in the program XLA compiled for `ad_gradient` of ``field`` (as
    `renderer.formulas.field` takes it), counted in the optimised HLO text, after XLA's
    common-subexpression elimination has merged what it could of the two passes, at a small
    array size (the program is the same at every size).  Raises InvalidType or InvalidValue
    naming ``field`` if it is refused."""
    return _ad_trig_calls(F.field(field, "field"))


@lru_cache(maxsize=None)
def _ad_trig_calls(record):
    import jax
    x = np.zeros(4)
    with jax.enable_x64(True):
        text = _ad_program(record.expr).lower(x, x, 1.0, 1.0).compile().as_text()
    return len(re.findall(r"\b(?:sine|cosine)\(", text))


@lru_cache(maxsize=None)
def _xla_exact_program(field):
    """The exact gradient of ``field`` printed for JAX by ``sympy.lambdify`` (common
    subexpressions shared) and jit-compiled by XLA, as `_ad_program` compiles the program AD
    differentiates."""
    import jax
    fn = sp.lambdify(F.FIELD_SYMBOLS, list(field.gradient), modules="jax", cse=True)
    return jax.jit(lambda uu, vv, ku, kv: tuple(fn(uu, vv, ku, kv)))


@_documented
def xla_exact_gradient(field, uu, vv, ku, kv):
    """The exact chart gradient compiled by XLA, AD's compiler: (h_u, h_v), two float64 arrays
    of the broadcast shape.  `same_compiler_times` times it beside `ad_gradient`.

    Parameters
    ----------
    {_FIELD_ARGS}

    Raises
    ------
    {_FIELD_RAISES}.
    """
    return _xla_exact_gradient(*_field_args(field, uu, vv, ku, kv))


def _xla_exact_gradient(record, uu, vv, ku, kv):
    import jax
    program = _xla_exact_program(record)
    uu, vv = np.broadcast_arrays(np.asarray(uu, dtype=np.float64), np.asarray(vv, dtype=np.float64))
    with jax.enable_x64(True):
        h_u, h_v = program(uu, vv, float(ku), float(kv))
        return np.broadcast_to(np.asarray(h_u), uu.shape), np.broadcast_to(np.asarray(h_v), uu.shape)


def same_compiler_times(uu, vv, *, ku=None, kv=None, rounds=21, fields_=None):
    """AD and the exact gradient through one compiler (XLA), and the exact gradient compiled
    by numba, timed side by side.

    Per field, after one call of each (which compiles), ``rounds`` interleaved rounds of
    `xla_exact_gradient`, `ad_gradient` and `renderer.pointwise.exact_gradient` (numba) on the
    chart points ``uu``, ``vv`` ((n,) float64); ``ku``, ``kv`` default to the draft's scene's,
    ``fields_`` to every registered field.  Separates what the method costs from what the
    compiler costs: §5's benchmark sets AD (XLA) beside the exact gradient compiled by numba.

    Returns
    -------
    dict field name -> {"exact": seconds, "ad": seconds, "numba": seconds, "ratio": ad / exact,
    "compiler": exact / numba}, medians.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: ``uu``, ``vv``, ``ku``, ``kv`` as `ad_gradient` refuses them;
        ``rounds`` not an integer in [1, 10000]; ``fields_`` not a non-empty list or tuple of
        height fields (each refused as ``fields_[i]``).
    """
    uu, vv, ku, kv = _chart(uu, vv, DRAFT_SCENE.k_u if ku is None else ku, DRAFT_SCENE.k_v if kv is None else kv)
    rounds = positive_int("rounds", rounds, high=10_000)
    out = {}
    for record in _fields(fields_):
        calls = {"exact": lambda: _xla_exact_gradient(record, uu, vv, ku, kv),
                 "ad": lambda: _ad_gradient(record, uu, vv, ku, kv),
                 "numba": lambda: pointwise.exact_gradient(record, uu, vv, ku, kv)}
        times = {k: [] for k in calls}
        for call in calls.values():                  # the first call compiles
            call()
        for _ in range(rounds):
            for k, call in calls.items():
                t0 = time.perf_counter()
                call()                               # returns numpy arrays: the work is done
                times[k].append(time.perf_counter() - t0)
        exact, ad, numba = (float(np.median(times[k])) for k in ("exact", "ad", "numba"))
        out[record.name] = {"exact": exact, "ad": ad, "numba": numba, "ratio": ad / exact,
                            "compiler": exact / numba}
    return out


def _fields(fields_, name="fields_"):
    """The records of ``fields_`` (None: every registered field), a non-empty list or tuple."""
    if fields_ is None:
        return tuple(F.FIELDS.values())
    return tuple(F.field(f, f"{name}[{i}]") for i, f in enumerate(sequence(name, fields_, "height fields")))


def abs_slope_at_zero():
    """JAX's forward-mode slope of |x| at x = +0.0 and x = -0.0, measured: (float, float).

    |x| has no derivative at 0; an AD tool must still return a number there, and which one
    is its convention.
    """
    import jax
    import jax.numpy as jnp
    with jax.enable_x64(True):
        return tuple(float(jax.jvp(jnp.abs, (jnp.float64(x),), (jnp.float64(1.0),))[1]) for x in (0.0, -0.0))


def crease_values(*, v=None, eps=None, ku=None, kv=None):
    """h_u of the draft's field (ridges, |f| with f the product of its crease factors) on two of
    its creases in u, by three methods, beside the one-sided slopes.

    The creases are u = 0, where the factor sin(pi k_u u) is exactly 0 in float64, and u = 1/k_u
    as float64 holds it, where the float64 factor is a rounding residue, not 0, so the sign of f
    picks a side.

    Parameters
    ----------
    v : float in [0, 1] or None, keyword-only
        The chart v of both points; None for the U-curve's point (`renderer.ucurve.SEED_POINT`),
        off the creases in v.
    eps : float in [1e-300, 1) or None, keyword-only
        The central difference's step in chart units; None for the draft's step.
    ku, kv : float in (0, 1e3] or None, keyword-only
        The frequencies; None for the U-curve's (`renderer.ucurve.SEED_FREQUENCIES`).

    Returns
    -------
    list of two dicts of floats: ``u``; ``factor``, sin(pi k_u u) in float64; ``exact``, the
    generated gradient (sign(0) = 0); ``ad``, `ad_gradient`; ``central``, the kernel's central
    difference at ``eps``; ``left`` and ``right``, the one-sided slopes of |f| in u, -|f_u| and
    +|f_u| with f_u sympy's derivative of the product evaluated by mpmath.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: not a real number (a bool, a string) or outside its range.
    """
    record = DRAFT_SCENE.field
    ku0, kv0 = ucurve.SEED_FREQUENCIES
    v = real("v", ucurve.SEED_POINT[1] if v is None else v, **UNIT)
    ku, kv = (real(n, k0 if k is None else k, **FREQUENCY) for n, k, k0 in (("ku", ku, ku0), ("kv", kv, kv0)))
    eps = real("eps", DRAFT_SCENE.eps if eps is None else eps, **STEP)
    f_u = sp.lambdify(F.FIELD_SYMBOLS, sp.diff(sp.Mul(*record.crease_factors), F.u), modules="mpmath")
    out = []
    for u0 in (0.0, 1.0 / ku):
        uu, vv = np.array([u0]), np.array([v])
        slope = abs(float(f_u(mpmath.mpf(u0), mpmath.mpf(v), mpmath.mpf(ku), mpmath.mpf(kv))))
        out.append(dict(u=u0, factor=float(np.sin(np.pi * ku * u0)),
                        exact=float(pointwise.exact_gradient(record, uu, vv, ku, kv)[0][0]),
                        ad=float(_ad_gradient(record, uu, vv, ku, kv)[0][0]),
                        central=float(pointwise.central_gradient(record, uu, vv, ku, kv, eps)[0][0]),
                        left=-slope, right=slope))
    return out


# --- the reference -------------------------------------------------------------------------

@lru_cache(maxsize=None)
def _reference_fn(field, ku, kv):
    # Exact rational frequencies, so that mpmath does not inherit float64 rounding.
    # First derivatives of |f| carry sign(f), no DiracDelta: usable as they are.
    ks = {F.k_u: sp.nsimplify(ku), F.k_v: sp.nsimplify(kv)}
    return sp.lambdify((F.u, F.v), [g.subs(ks) for g in field.gradient], modules="mpmath", cse=True)


@_documented
def reference_gradient(field, uu, vv, ku, kv, *, digits=34):
    """The exact gradient at float64 chart points, evaluated by mpmath.

    sympy's derivative of the field (`renderer.formulas.HeightField.gradient`) is evaluated
    with mpmath at ``digits`` decimal digits, at the chart points exactly as float64
    represents them, and returned as a double-double: the value rounded to float64 (``hi``)
    and the rounding residual (``lo``).  An error |x - ref| of a float64 estimate x is then
    ``|(x - hi) - lo|``, exact up to one rounding of the error itself.  Working precision: 34
    digits put the reference's own error (~1e-33 relative) sixteen orders below the float64
    spacing it judges; ``lo`` needs only 32.

    Parameters
    ----------
    {_FIELD_ARGS}  (ku, kv converted to exact rationals)
    digits : int in [32, 1000], keyword-only

    Returns
    -------
    (hi, lo) : two (2, n) float64 arrays (n points of the broadcast uu, vv, flattened); row 0
    is h_u, row 1 is h_v; NaN (hi and lo) where a component is not a finite real number: a
    reader's field past a branch point, or at a pole (both components, mpmath raising), where
    the float64 methods give NaN or inf.

    Raises
    ------
    {_FIELD_RAISES}; ``digits`` not an integer in [32, 1000].
    """
    return _reference_gradient(*_field_args(field, uu, vv, ku, kv), digits=_digits("digits", digits))


def _reference_gradient(record, uu, vv, ku, kv, *, digits=34):
    fn = _reference_fn(record, float(ku), float(kv))
    uu, vv = np.broadcast_arrays(np.ravel(uu), np.ravel(vv))
    hi = np.empty((2, uu.size))
    lo = np.empty((2, uu.size))
    with mpmath.workdps(digits):
        for j, (a, b) in enumerate(zip(uu.tolist(), vv.tolist())):
            try:
                values = [mpmath.mpmathify(g) for g in fn(mpmath.mpf(a), mpmath.mpf(b))]
            except (ArithmeticError, ValueError, TypeError):        # a pole of the field's gradient
                values = [mpmath.nan, mpmath.nan]
            for c, val in enumerate(values):
                if not (isinstance(val, mpmath.mpf) and mpmath.isfinite(val)):   # complex, or infinite
                    val = mpmath.nan
                hi[c, j] = float(val)
                lo[c, j] = float(val - hi[c, j]) if mpmath.isfinite(val) else math.nan
    return hi, lo


# --- the work per pixel -------------------------------------------------------------------

@dataclass(frozen=True)
class Evaluations:
    """Work per pixel: real values of h, complex values of h, evaluations of the generated
    gradient, forward-mode passes through h's program (a value and one tangent each), and
    the real sines and cosines all of them cost."""

    h: float = 0.0
    h_complex: float = 0.0
    gradient: float = 0.0
    trig: float = 0.0
    h_tangent: float = 0.0


def trig_calls(exprs):
    """Sines and cosines evaluated per point by the code generated from ``exprs``.

    ``renderer.codegen`` prints a function's outputs after one common-subexpression
    elimination over all of them (``sympy.cse``); a sine or cosine left in the eliminated code
    is computed once per point, so this counts the sin and cos nodes of the replacements and
    the reduced outputs.  The numba kernel calls exactly these (tests/test_gradient_methods.py
    compares the count with the text of renderer/generated.py).

    ``exprs``: a list or tuple of sympy expressions (real numbers among them count 0).  Raises
    InvalidType naming ``exprs`` (or ``exprs[i]``) for anything else (a string, one expression).
    """
    for i, e in enumerate(instance("exprs", exprs, (list, tuple), "a list or tuple of sympy expressions")):
        if isinstance(e, bool) or not isinstance(e, (sp.Basic, int, float)):
            raise InvalidType(f"exprs[{i}] must be a sympy expression or a real number, got {type(e).__name__} "
                              f"{e!r:.80}")
    return _trig_calls(exprs)


def _trig_calls(exprs):
    exprs = [e for e in exprs if isinstance(e, sp.Basic)]
    subs, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x"))
    return sum(isinstance(node, (sp.sin, sp.cos))
               for e in [x for _, x in subs] + list(reduced) for node in sp.preorder_traversal(e))


def _generated(kind, field):
    """The outputs of the generated function ``kind`` (a key of `formulas.FIELD_FUNCTIONS`) of a field."""
    return F.FIELD_FUNCTIONS[kind][1](field)


def stencil_values(field):
    """Values of h per point in the kernel's central difference of ``field``: the stencil points
    (`formulas.STENCIL_POINTS`) that its quotients read.  4 for sine and ridges; 2 for rings,
    whose u-difference sympy reduced to 0.  ``field`` as `renderer.formulas.field` takes it (refused:
    InvalidType or InvalidValue naming ``field``)."""
    return _stencil_values(F.field(field, "field"))


def _stencil_values(field):
    used = set().union(*(c.free_symbols for c in field.central))
    return sum(p in used for p, _ in F.STENCIL_POINTS)


def height_work(field):
    """One value of h per pixel, with the sines and cosines it costs: the unit of cost.  ``field``
    as `renderer.formulas.field` takes it (refused: InvalidType or InvalidValue naming ``field``)."""
    return Evaluations(h=1.0, trig=float(_trig_calls((F.field(field, "field").expr,))))


def _measured_h(info):
    if "h_per_pixel" not in info:
        raise InvalidValue(f"info must hold 'h_per_pixel' for richardson, whose evaluations are measured: "
                           f"pass the dict its gradient filled; got {sorted(info)!r}")
    return info["h_per_pixel"]


def method(name):
    """The record of `METHODS` named ``name``.  Raises InvalidValue (InvalidType for a name that is
    not a string) naming the names."""
    name = choice("method", name, tuple(m.name for m in METHODS))
    return next(m for m in METHODS if m.name == name)


def evaluations(field, name, info=None):
    """The work per pixel of the method ``name`` on ``field`` (`Method.work`), an `Evaluations`.
    ``info``: what the method's gradient measured of itself (Richardson's count of values of h), a
    dict or None.  Raises InvalidType or InvalidValue for a refused field (naming ``field``), an
    unknown method (``method``), an ``info`` that is not a dict, or Richardson's without
    ``"h_per_pixel"`` in ``info`` (naming ``info``)."""
    record = F.field(field, "field")
    return method(name).work(record, optional(instance, "info", info, dict, "a dict or None") or {})


# --- the methods over a function of one variable ---------------------------------------------

def _exact_1d(function, x, eps, info):
    try:
        return float(sp.lambdify(F.x_var, function.derivative, modules="math")(x))
    except (ArithmeticError, ValueError):   # math's overflow, pole or domain error: no float64 value
        return math.nan


def _central_1d(function, x, eps, info):
    return float(fieldcode.univariate_code(function).central(x, eps))


def _forward_1d(function, x, eps, info):
    return float(fieldcode.univariate_code(function).forward(x, eps))


def _complex_1d(continued):
    def derivative_(function, x, eps, info):
        return float(np.imag(_complex_fn(function.expr, (F.x_var,), continued)(complex(x, eps))) / eps)
    return derivative_


def _richardson_1d(function, x, eps, info):
    from scipy.differentiate import derivative
    res = derivative(_complex_fn(function.expr, (F.x_var,), False), np.float64(x))
    info["h_per_pixel"] = float(res.nfev)
    return float(res.df)


def _ad_1d(function, x, eps, info):
    import jax
    import jax.numpy as jnp
    f = sp.lambdify(F.x_var, function.expr, modules="jax")
    with jax.enable_x64(True):
        return float(jax.jvp(f, (jnp.float64(x),), (jnp.float64(1.0),))[1])


# --- the list of methods ------------------------------------------------------------------

def _has_abs(record):
    return record.expr.has(sp.Abs)


def _ad_work(field, info):
    return Evaluations(h_tangent=2.0, trig=float(_ad_trig_calls(field)))


#: The methods, in the order tables and legends list them.  Adding a method is one record here.
METHODS = [
    Method("exact", lambda f, u, v, ku, kv, eps, info: pointwise.exact_gradient(f, u, v, ku, kv),
           lambda f, info: Evaluations(gradient=1.0, trig=float(_trig_calls(_generated("exact", f)))),
           "exact (sympy)", Style("#1b5e20", "*", 12, "-"), derivative=_exact_1d),
    Method("central", lambda f, u, v, ku, kv, eps, info: pointwise.central_gradient(f, u, v, ku, kv, eps),
           lambda f, info: Evaluations(h=float(_stencil_values(f)), trig=float(_trig_calls(_generated("central", f)))),
           "central difference", Style("#7a1f1f", "o", 5, "-"), steps="central_steps", derivative=_central_1d),
    Method("forward", lambda f, u, v, ku, kv, eps, info: _forward_gradient(f, u, v, ku, kv, eps),
           lambda f, info: Evaluations(h=3.0, trig=3.0 * _trig_calls((f.expr,))),
           "forward difference", Style("#b26b00", "s", 5, "--"), steps="forward_steps", derivative=_forward_1d),
    Method("complex step", lambda f, u, v, ku, kv, eps, info: _complex_step_gradient(f, u, v, ku, kv, eps),
           lambda f, info: Evaluations(h_complex=2.0), "complex step", Style("#1f4e7a", "D", 6, ":"),
           steps="complex_steps", applies=lambda f: f.analytic, sources=("squire-trapp", "martins-complex-step"),
           derivative=_complex_1d(False)),
    Method("complex step, |z| continued",
           lambda f, u, v, ku, kv, eps, info: _complex_step_gradient(f, u, v, ku, kv, eps, continued=True),
           lambda f, info: Evaluations(h_complex=2.0), "complex step, |z| continued",
           Style("#5b7fa6", "d", 7, "-."), steps="complex_steps", applies=_has_abs,
           note="|f| evaluated as f sign(Re f); one-sided on the crease", sources=("martins-complex-step",),
           derivative=_complex_1d(True)),
    Method("richardson", lambda f, u, v, ku, kv, eps, info: _richardson_gradient(f, u, v, ku, kv, info=info),
           lambda f, info: Evaluations(h=_measured_h(info), trig=_measured_h(info) * _trig_calls((f.expr,))),
           "SciPy (Richardson)", Style("#6a1b9a", "^", 8, (0, (5, 2, 1, 2))), repeats="richardson_repeats",
           note=f"scipy.differentiate.derivative, order {RICHARDSON['order']}", derivative=_richardson_1d),
    Method(AD, lambda f, u, v, ku, kv, eps, info: _ad_gradient(f, u, v, ku, kv), _ad_work,
           "forward-mode AD (JAX)", Style("#00838f", "P", 8, (0, (1, 1))), compiles=True,
           note="jax.jvp, jit-compiled", sources=("griewank-walther",), derivative=_ad_1d),
]


# --- the measurement over a field -------------------------------------------------------------

@dataclass(frozen=True)
class MethodResult:
    """One method on one field.

    Times are seconds per frame (all sphere-A pixels, both components); evaluations are per
    pixel; errors are absolute, in units of h per chart unit, over both components at the
    reference pixels.
    """

    field: str
    method: str                 # a `Method.name`
    eps: float | None           # the step, or None
    times: tuple                # seconds, one per repeat
    h_evals: float              # real evaluations of h per pixel (`Method.work`)
    h_complex_evals: float      # complex evaluations of h per pixel
    gradient_evals: float       # evaluations of the generated gradient per pixel
    max_error: float
    rms_error: float
    note: str = ""
    trig_evals: float = 0.0     # real sines and cosines per pixel
    h_tangent_evals: float = 0.0        # forward-mode passes through h per pixel (AD)
    compile_seconds: float | None = None    # its first call at the frame's size (`Method.compiles`)

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

    ``pixels`` is the number of sphere-A pixels timed per frame; ``reference_pixels`` maps
    each field to the number of pixels whose error was measured, ``excluded_pixels`` to the
    number of the frame's pixels on the crease band, where no error is measured (0 for a
    field without creases); ``h_times`` to the times (seconds) of one evaluation of h at all
    pixels, timed among the methods as a unit of cost; ``seconds`` is the wall time of the run.
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
        """The results for one field, in the order they were defined; KeyError naming the fields
        measured if ``field`` is not one of them."""
        found = [r for r in self.results if r.field == field]
        if not found:
            raise KeyError(f"field {field!r} was not measured; measured: {sorted({r.field for r in self.results})}")
        return found

    def get(self, field, label):
        """The result with this field and label; KeyError naming the labels of the field if absent."""
        for r in self.of(field):
            if r.label == label:
                return r
        raise KeyError(f"no result labelled {label!r} for {field!r}; its labels: {[r.label for r in self.of(field)]}")


def _errors(approx, hi, lo):
    err = np.abs((np.stack(approx) - hi) - lo)
    return float(err.max()), float(np.sqrt(np.mean(err**2)))


def _config(config):
    """``config`` as a `Config`: one, or the name of `FAST` or `FULL`."""
    names = {c.name: c for c in (FAST, FULL)}
    if isinstance(config, str):
        return names[choice("config", config, tuple(names))]
    return instance("config", config, Config, f"a Config or one of {tuple(names)}")


def _uv(uv):
    """``uv`` as two contiguous (n,) float64 arrays of chart coordinates in [0, 1], n >= 1."""
    if not (isinstance(uv, (tuple, list)) and len(uv) == 2):
        raise InvalidType(f"uv must be a pair (u, v) of 1-D arrays, got {type(uv).__name__} {uv!r:.80}")
    u, v = (validate.real_array(n, a, **UNIT) for n, a in zip(("uv[0]", "uv[1]"), uv))
    if u.ndim != 1 or u.shape != v.shape or u.size == 0:
        raise InvalidValue(f"uv must be two 1-D arrays of one length n >= 1, got shapes {u.shape} and {v.shape}")
    return np.ascontiguousarray(u), np.ascontiguousarray(v)


def measure(config=FAST, *, fields_=None, uv=None):
    """Time and check every method on every field where it applies, with its work per pixel
    (see the module docstring).

    Parameters
    ----------
    config : Config, or the name of `FAST` or `FULL` ("fast", "full")
        `FAST` (book build) or `FULL` (release), or another `Config`.  A name stands for its
        record, as the configuration's name is what a reader (and `Config.name`) calls it.
    fields_ : list or tuple of height fields, or None, keyword-only
        As `renderer.formulas.field` takes them; None for every registered field.
    uv : (u, v) pair of (n,) float64 arrays or None, keyword-only
        Chart points of the sphere-A pixels (in [0, 1], n >= 1), shared by all fields (they do
        not depend on the field); None computes them with `chart_points`.

    Returns
    -------
    Measurement

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: ``config`` neither a `Config` nor "fast" or "full"; ``fields_``
        not a non-empty list or tuple of height fields (``fields_[i]`` the one refused);
        ``uv`` not a pair of 1-D arrays of one length of chart coordinates in [0, 1].

    Notes
    -----
    Per field, one run of every method at the reference pixels gives the errors and the work
    per pixel (`Method.work`; for scipy's adaptive iteration its own count at those pixels, a
    sample's mean in `FAST`).  A method that compiles is then called once on all pixels
    (`MethodResult.compile_seconds`).  Then rounds time every (field, method) pair on all
    pixels, in an order shuffled each round, so that drifts of the machine's speed fall on
    all of them alike.
    """
    config, records, uv = _config(config), _fields(fields_), None if uv is None else _uv(uv)
    t_start = time.perf_counter()
    load_start = os.getloadavg() if hasattr(os, "getloadavg") else None
    rng = np.random.default_rng(config.seed)
    ku, kv = float(DRAFT_SCENE.k_u), float(DRAFT_SCENE.k_v)
    u, v = chart_points(size=config.size) if uv is None else uv
    checked, timed, n_ref, n_excl = [], [], {}, {}
    for record in records:
        name = record.name
        # The error sample: pixels where the gradient exists (off the crease band).
        off = np.flatnonzero(~pointwise.kink_band(record, u, v, ku, kv))
        n_excl[name] = int(u.size - off.size)
        if config.reference_pixels is not None and config.reference_pixels < off.size:
            pick = np.sort(rng.choice(off, size=config.reference_pixels, replace=False))
        else:
            pick = off
        n_ref[name] = int(pick.size)
        ru, rv = u[pick].copy(), v[pick].copy()
        hi, lo = _reference_gradient(record, ru, rv, ku, kv, digits=config.digits)
        for m in METHODS:
            if not m.applies(record):
                continue
            for eps in m.steps_in(config):
                def fn(uu, vv, info=None, m=m, eps=eps, record=record):
                    return m.gradient(record, uu, vv, ku, kv, eps, {} if info is None else info)
                compile_s = None
                if m.compiles:                  # the first call at the frame's size compiles: timed apart
                    t0 = time.perf_counter()
                    fn(u, v)
                    compile_s = time.perf_counter() - t0
                info = {}
                errors = _errors(fn(ru, rv, info), hi, lo)
                note = m.note
                if info.get("not_converged"):
                    note = (note + "; " if note else "") + \
                        f"{info['not_converged']} of {2 * ru.size} components not converged"
                checked.append((name, m.name, eps, note, m.work(record, info), errors, compile_s))
                timed.append((fn, getattr(config, m.repeats)))
        # One evaluation of h alone, timed with the methods as a unit of cost.
        timed.append((lambda uu, vv, record=record: pointwise.height(record, uu, vv, ku, kv), config.repeats))

    # Timing: every (field, method) on all pixels, in an order shuffled every round, so that
    # changes in the machine's load fall on all of them alike.
    times = [[] for _ in timed]
    for _ in range(max(q for _, q in timed)):
        for k in rng.permutation(len(timed)):
            fn, quota = timed[k]
            if len(times[k]) < quota:
                t0 = time.perf_counter()
                fn(u, v)
                times[k].append(time.perf_counter() - t0)
    it = iter(times)            # the order of `timed`: per field, its methods, then h
    results, h_times = [], {}
    for record in records:
        for name, method_name, eps, note, work, (emax, erms), compile_s in (c for c in checked if c[0] == record.name):
            results.append(MethodResult(name, method_name, eps, tuple(next(it)), work.h, work.h_complex,
                                        work.gradient, emax, erms, note, work.trig, work.h_tangent, compile_s))
        h_times[record.name] = tuple(next(it))
    machine = {"python": platform.python_version(), "numpy": np.__version__,
               "scipy": sys.modules["scipy"].__version__,
               "jax": sys.modules["jax"].__version__ if "jax" in sys.modules else None, "cpus": os.cpu_count(),
               "processor": platform.processor() or platform.machine(),
               "load_average_1_5_15_min_at_start": load_start}
    return Measurement(config, tuple(results), int(u.size), n_ref, n_excl, h_times,
                       time.perf_counter() - t_start, ku, kv, machine)


# --- presentation --------------------------------------------------------------------------

def _non_dominated(times, errors):
    """Indices of the points not dominated in (time, error), both minimised.

    A point is dominated when another is no worse in both coordinates and strictly better in
    one.  Equal points do not dominate each other.
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
    results : list or tuple of MethodResult
        Usually one field's results (`Measurement.of`); any records with ``median``,
        ``max_error`` and ``rms_error`` do.
    error : {"max", "rms"}, keyword-only
        Which error is minimised with the time.

    Returns
    -------
    list of MethodResult, fastest first.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``results`` not a list or tuple of `MethodResult` (``results[i]`` the one refused);
        ``error`` not "max" or "rms".
    ValueError
        A time or error is not finite.
    """
    if not isinstance(error, str):
        raise InvalidType(f"error must be 'max' or 'rms', got {shown(error)}")
    if error not in ("max", "rms"):
        raise InvalidValue(f"error must be 'max' or 'rms', got {error!r:.80}")
    results = list(instance("results", results, (list, tuple), "a list or tuple of MethodResult records"))
    for i, r in enumerate(results):
        if not all(hasattr(r, a) for a in ("median", "max_error", "rms_error")):
            raise InvalidType(f"results[{i}] must be a MethodResult (a record with median, max_error and "
                              f"rms_error), got {shown(r)}")
    errs = [r.max_error if error == "max" else r.rms_error for r in results]
    keep = _non_dominated([r.median for r in results], errs)
    return sorted((results[i] for i in keep), key=lambda r: r.median)


def to_json(measurement):
    """The measurement (a `Measurement`) as a JSON string (times in seconds, every repeat kept).
    Raises InvalidType naming ``measurement`` for anything else."""
    instance("measurement", measurement, Measurement, "a Measurement")
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


# --- a function of one variable ---------------------------------------------------------------

#: The steps of `univariate_errors`: half decades from 1e-1 to 1e-20.
UNIVARIATE_STEPS = tuple(float(10.0 ** (-k / 2)) for k in range(2, 41))


@dataclass(frozen=True)
class UnivariateRow:
    """One method at one step: ``eps`` (None for a method without a step), ``value`` its f'(x)
    (float64), ``error`` = |value - f'(x)| against the mpmath reference, and ``relative_error``
    = error / |f'(x)| (inf where f'(x) = 0 and the error is not)."""

    method: str
    eps: float | None
    value: float
    error: float
    relative_error: float


@dataclass(frozen=True)
class UnivariateErrors:
    """What `univariate_errors` returns: the function (its printed form) and the point x; the
    derivative f'(x) (mpmath at ``digits`` digits, rounded to float64); ``rows`` (per method
    that applies, in `METHODS` order, per step); ``curve`` the central difference's U-curve
    (`renderer.ucurve.UCurve`, ``eps_model`` and ``eps_fitted`` its optimal steps); and
    ``evaluations``, per method without a step, the values of f it took (Richardson's count)."""

    function: str
    x: float
    derivative: float
    digits: int
    rows: tuple
    curve: object
    evaluations: dict

    def of(self, name):
        """The rows of the method ``name``, in step order."""
        return [r for r in self.rows if r.method == name]

    def best(self, name):
        """The row of the method ``name`` with the least error (the first of equals); KeyError naming
        the methods measured if ``name`` is not one of them."""
        rows = self.of(name)
        if not rows:
            raise KeyError(f"method {name!r} was not measured; measured: {sorted({r.method for r in self.rows})}")
        return min(rows, key=lambda r: r.error)


def univariate_errors(function, x, *, steps=UNIVARIATE_STEPS):
    """Every method of `METHODS` with a one-variable form that applies to ``function``, at x,
    at each step, against an mpmath reference of the derivative.

    The reference is the function's derivative (`renderer.formulas.Univariate.derivative`,
    sympy's) evaluated by mpmath at `renderer.ucurve.DIGITS` digits at x as float64 holds it,
    the derivative `renderer.ucurve.measure_function` measures against; that function also
    validates the input.  Each error is computed at the reference's precision from the
    float64 estimate, so no rounding of the reference enters it.  The central difference is the
    quotient `renderer.ucurve.measure_function` measures (its U-curve is returned as ``curve``).

    Parameters
    ----------
    function : sympy expression of one symbol, its text in ``x``, or `renderer.formulas.Univariate`
        E.g. ``"exp(x) / sqrt(sin(x)**3 + cos(x)**3)"`` (`TEST_FUNCTION`).
    x : float
        Any real point where f is defined and differentiable (and f(x +- eps) for each step).
    steps : sequence of float in [`renderer.pointwise.MIN_STEP`, `renderer.ucurve.MAX_FUNCTION_STEP`], keyword-only
        The steps of the methods that take one (default `UNIVARIATE_STEPS`).

    Returns
    -------
    UnivariateErrors

    Raises
    ------
    renderer.validate.InputError
        One line naming the argument: a function refused by `renderer.formulas.univariate`
        (an unknown name or operator, more than one variable, a complex constant); a point
        (``x``) or a step (``steps``) that is not a finite real number in range (a bool, NaN); a point where f or f' is not a
        finite real number, or f has a crease, or float64 f overflows; a step at which
        f(x +- eps) is not finite; a method whose value there is not finite (Richardson's steps
        reach where f is not).

    Examples
    --------
    >>> e = univariate_errors(TEST_FUNCTION.function, TEST_FUNCTION.x)       # doctest: +SKIP
    >>> e.best("complex step").relative_error < 1e-15                       # doctest: +SKIP
    True
    """
    record, x = F.univariate(function), validate.real("x", x)
    steps = validate.steps("steps", steps, low=pointwise.MIN_STEP, high=ucurve.MAX_FUNCTION_STEP)
    with np.errstate(all="ignore"):
        value = fieldcode.univariate_code(record).value(x)
    if math.isinf(value):                     # finite at 50 digits (measure_function's test) is not enough
        raise validate.InvalidValue(f"x = {x!r} is too large for function {record.name}: f(x) overflows float64")
    try:
        curve = ucurve.measure_function(record, x, eps=steps)      # checks f and f' at x, and f at x +- eps
    except validate.InvalidValue as exc:                           # its eps is this function's steps
        text = str(exc)
        raise validate.InvalidValue(f"steps{text[3:]}" if text.startswith("eps ") else text) from None
    steps = tuple(float(e) for e in curve.eps)
    true_fn = sp.lambdify(F.x_var, record.derivative, modules="mpmath")
    rows, evaluations = [], {}
    with mpmath.workdps(ucurve.DIGITS):
        true = true_fn(mpmath.mpf(x))
        for m in METHODS:
            if m.derivative is None or not m.applies(record):
                continue
            for eps in ((None,) if m.steps is None else steps):
                info = {}
                value = m.derivative(record, x, eps, info)
                if not math.isfinite(value):
                    raise validate.InvalidValue(f"function {record.name}: its {m.name} derivative at x = {x!r}"
                                                + (f" with the step {eps!r}" if eps is not None else "")
                                                + " is not a finite number (f is not finite where it looks)")
                if "h_per_pixel" in info:
                    evaluations[m.name] = info["h_per_pixel"]
                error = float(abs(mpmath.mpf(value) - true))
                # In mpmath: a derivative below float64's range (exp(x) at x = -780) is not 0 there.
                relative = float(error / abs(true)) if true != 0 else (0.0 if error == 0 else math.inf)
                rows.append(UnivariateRow(m.name, eps, value, error, relative))
    return UnivariateErrors(record.name, x, float(true), ucurve.DIGITS, tuple(rows), curve, evaluations)


# --- what the papers report ----------------------------------------------------------------------

@dataclass(frozen=True)
class Published:
    """What a paper reports about a test of the methods, with where it says it: ``source`` (a
    key of book/references.bib), ``where`` (its section, figure or table), ``method`` (a
    `Method.name`, or None for the test itself), ``statement`` (what it reports, in our words,
    not a quotation) and ``value`` (a number it reports, or None where it reports a behaviour)."""

    source: str
    where: str
    method: str | None
    statement: str
    value: float | None = None


@dataclass(frozen=True)
class Example:
    """A published test function: ``function`` (text in x for `univariate_errors`) and the point ``x``."""

    function: str
    x: float


#: The classic complex-step test function and point: f(x) = e^x / sqrt(sin^3 x + cos^3 x) at x = 1.5.
TEST_FUNCTION = Example("exp(x) / sqrt(sin(x)**3 + cos(x)**3)", 1.5)

#: What the two papers report (the text of neither is in this repository; the statements are ours).
PUBLISHED = (
    Published("squire-trapp", "§1, eq. (1)", "central",
              "truncation error O(h²); a small h trades truncation for subtractive cancellation"),
    Published("squire-trapp", "abstract", "complex step",
              "avoids the subtractive cancellation of the classical difference quotients"),
    Published("martins-complex-step", "§2, Fig. 1", None,
              "the test function e^x/√(sin³x + cos³x) at x = 1.5, relative errors against the analytic "
              "derivative over steps down to far below machine precision"),
    Published("martins-complex-step", "§2, Fig. 1", "forward",
              "the error falls with the step until subtractive cancellation takes over, then grows"),
    Published("martins-complex-step", "§2, Fig. 1", "central",
              "falls faster than the forward difference's, and is also ruined by cancellation at small steps"),
    Published("martins-complex-step", "§2, Fig. 1", "complex step",
              "falls quadratically with the step, then stays at the precision of f's evaluation however "
              "small the step"),
)
