"""The ways of computing a derivative, of a height field's chart gradient at chart points and
of a reader's function of one variable at a point: each one `Method` record in `METHODS`, in
the order tables and legends list them:

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
variable), its work per pixel, which steps of a `lab.gradient_benchmark.Config` it runs at,
its label and style, where it applies, its sources.  `lab.gradient_benchmark`, which times
the methods and measures their errors, and book/chapter/benchmark.py, which draws them, read
only the records: adding a method is one record appended to `METHODS`, and nothing else
changes (tests/test_gradient_benchmark.py appends a backward difference and sees it measured
and drawn).  Its place in the list is its place in tables and legends, and its name must be
its own (`methods` refuses a second record of one name).  Its one-variable form
(`Method.derivative`) is built, as the differences' are, from
`renderer.fieldcode.univariate_code(function)`: the function's compiled value and its central
and forward quotients.  §5's tables, legends and the sentence naming the methods are generated
from the list, and its figures make room for a new one (a legend too wide for two columns takes
one; the baselines in tests/figure_baselines draw a fixed list and do not change).  Three things stay the author's: the prose that describes
the figures (their alt text, §5's "What it shows", book/s5_lab.md); a public function beside the
record (as `forward_gradient` is) joins the table of tests/test_lab_validation.py, which names a
function missing from it; and the book's length: a record adds words to §5's sentence and rows
to its tables and figures, which may push the reading path's words or §5's height past the limits
of tests/test_book_pages.py, which only the audit of the built site checks (``make audit`` says
so; make room, or raise the limit with the reason in its comment).

Beside the methods: their work per pixel (`Evaluations`: values of h, evaluations of the
generated gradient, and the sines and cosines they cost, counted from the sympy objects the
kernel is generated from; scipy counts its own evaluations), the mpmath reference of the exact
gradient (`reference_gradient`), and AD's compiler set apart from the method
(`same_compiler_times`, `abs_slope_at_zero`).

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

import math
import re
import time
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import mpmath
import numpy as np
import sympy as sp

from renderer import DRAFT_SCENE, fieldcode, pointwise, ucurve, validate
from renderer import formulas as F
from renderer import univariate as U
from renderer.scene import FREQUENCY, UNIT
from renderer.validate import InvalidType, InvalidValue, choice, flag, positive_int, real

from ._checks import STEP, chart_points as _chart, digits as _digits, height_fields, instance, optional

__all__ = [
    "Style", "Method", "METHODS", "methods", "method", "Evaluations", "forward_gradient", "complex_step_gradient",
    "richardson_gradient", "ad_gradient", "reference_gradient", "trig_calls", "stencil_values", "height_work",
    "evaluations", "AD", "ad_trig_calls", "abs_slope_at_zero", "crease_values", "xla_exact_gradient",
    "same_compiler_times", "RICHARDSON", "RICHARDSON_ROUNDS",
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
        How results name it (`lab.gradient_benchmark.MethodResult.method`).
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
    steps : str, tuple of float or None
        The `Config` attribute listing its steps (``"central_steps"``, ``"forward_steps"`` or
        ``"complex_steps"``: it runs at the steps a configuration gives that sweep); or its own steps,
        1 to 64 floats in [1e-300, 1) (chart units), the same in every configuration; None for a
        method without a step.
    repeats : str
        The `Config` attribute saying how many times it is timed.
    applies : callable
        ``applies(record) -> bool`` for a `HeightField` or a `renderer.univariate.Univariate`:
        whether its premise holds there; it is measured only where it does.
    compiles : bool
        Its first call at a new array size compiles: that call is timed apart.
    note : str
        Shown beside its results in the benchmark's table.
    sources : tuple of str
        Keys of book/references.bib.
    derivative : callable or None
        ``derivative(function, x, eps, info) -> float``: f'(x) of a `Univariate` at a float x
        (`lab.gradient_benchmark.univariate_errors`); None where the method has no one-variable form.
    """

    name: str
    gradient: Callable
    work: Callable
    label: str
    style: Style
    steps: str | tuple | None = None
    repeats: str = "repeats"
    applies: Callable = _always
    compiles: bool = False
    note: str = ""
    sources: tuple = ()
    derivative: Callable | None = None

    def __post_init__(self):
        """Its own steps, if given, are checked once, when the record is made: InvalidType or
        InvalidValue naming ``Method.steps``."""
        if self.steps is not None and not isinstance(self.steps, str):
            object.__setattr__(self, "steps", tuple(validate.steps("Method.steps", self.steps, **STEP,
                                                                   max_count=64).tolist()))

    def steps_in(self, config):
        """Its steps in ``config`` (a `lab.gradient_benchmark.Config`; a tuple of floats), or (None,)
        for a method without a step.  InvalidValue if ``steps`` names no step list of ``config``."""
        if self.steps is None:
            return (None,)
        if isinstance(self.steps, tuple):
            return self.steps
        lists = tuple(name for name in vars(config) if name.endswith("_steps"))
        return tuple(getattr(config, choice("Method.steps", self.steps, lists)))


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
#: At these settings SciPy's first estimate is Richardson's extrapolation (4^k D(s/2) - D(s)) / (4^k - 1)
#: of central differences D at the initial step halved this many times: its stencil of order 8 on the
#: nested steps s / step_factor^j is the unique one there, and step_factor 2 makes them halvings
#: (§3; tests/test_gradient_methods.py checks it against an mpmath table).
RICHARDSON_ROUNDS = RICHARDSON["order"] // 2 - 1


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
    for record in height_fields("fields_", fields_):
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
    ku : float in [1, 1e3] or None, keyword-only
        The frequency in u, at least 1 so that the crease u = 1/k_u is on the chart; None for the
        U-curve's (`renderer.ucurve.SEED_FREQUENCIES`).
    kv : float in (0, 1e3] or None, keyword-only
        The frequency in v; None for the U-curve's.

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
    ku = real("ku", ku0 if ku is None else ku, **{**FREQUENCY, "low": 1.0, "low_open": False})
    kv = real("kv", kv0 if kv is None else kv, **FREQUENCY)
    eps = real("eps", DRAFT_SCENE.eps if eps is None else eps, **STEP)
    f_u = sp.lambdify(F.FIELD_SYMBOLS, sp.diff(sp.Mul(*record.crease_factors), F.u), modules="mpmath")
    factor_u = sp.lambdify(F.FIELD_SYMBOLS, next(c for c in record.crease_factors if F.u in c.free_symbols))
    out = []
    for u0 in (0.0, 1.0 / ku):
        uu, vv = np.array([u0]), np.array([v])
        slope = abs(float(f_u(mpmath.mpf(u0), mpmath.mpf(v), mpmath.mpf(ku), mpmath.mpf(kv))))
        out.append(dict(u=u0, factor=float(factor_u(u0, v, ku, kv)),
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


def methods():
    """`METHODS`, as a tuple, once no two of its records share a name: results, tables, legends and
    `method` find a record by its name, and would take the first of two for both.  Raises
    ValueError naming the name used twice."""
    names = [m.name for m in METHODS]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"lab.gradient_methods.METHODS holds more than one record named {twice[0]!r}: "
                         "each method needs a name of its own")
    return tuple(METHODS)


def method(name):
    """The record of `METHODS` named ``name``.  Raises InvalidValue (InvalidType for a name that is
    not a string) naming the names, and ValueError as `methods` does."""
    records = methods()
    name = choice("method", name, tuple(m.name for m in records))
    return next(m for m in records if m.name == name)


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
        return float(sp.lambdify(U.x_var, function.derivative, modules="math")(x))
    except (ArithmeticError, ValueError):   # math's overflow, pole or domain error: no float64 value
        return math.nan


def _central_1d(function, x, eps, info):
    return float(fieldcode.univariate_code(function).central(x, eps))


def _forward_1d(function, x, eps, info):
    return float(fieldcode.univariate_code(function).forward(x, eps))


def _complex_1d(continued):
    def derivative_(function, x, eps, info):
        return float(np.imag(_complex_fn(function.expr, (U.x_var,), continued)(complex(x, eps))) / eps)
    return derivative_


def _richardson_1d(function, x, eps, info):
    from scipy.differentiate import derivative
    res = derivative(_complex_fn(function.expr, (U.x_var,), False), np.float64(x))
    info["h_per_pixel"] = float(res.nfev)
    return float(res.df)


def _ad_1d(function, x, eps, info):
    import jax
    import jax.numpy as jnp
    f = sp.lambdify(U.x_var, function.expr, modules="jax")
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


