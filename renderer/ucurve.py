"""The finite-difference U-curve, measured exactly (seed §3, Cells 2 and 7).

For a height field, a chart point (u, v), a component (h_u or h_v) and a grid
of steps eps, `measure` returns

* the float64 central difference exactly as the renderer computes it (the
  kernel's compiled function, through `renderer.pointwise.central_gradient`);
* its error against the true derivative evaluated with mpmath at 50 digits;
* that error split exactly into *truncation*, the same difference quotient
  taken in exact arithmetic at the float64 abscissae the renderer actually
  used (u +/- eps rounded and wrapped, v +/- eps rounded and clamped: the
  kernel's `renderer.formulas.STENCIL_POINTS`, evaluated in float64) and the
  same denominator, minus the true derivative; and *roundoff*, the rest
  (the rounding of the two values of h and of the subtraction and division);
* the error model E(eps) = eps^2 |h'''| / 6 + u_round (|h| + |x h'|) / eps
  (u_round = 2^-53, the unit roundoff; x the point's coordinate u or v): truncation
  from Taylor's series, cancellation (each value h(x +- eps) rounded, off by up to
  u_round |h|) and argument rounding (each abscissa fl(x +- eps) off by up to
  u_round |x|, which moves h by |h'| u_round |x|); each of the quotient's two
  rounding terms is half their difference over 2 eps, hence the weights 1.  Its
  minimiser, the *model-optimal step* eps* = (3 u_round (|h| + |x h'|) / |h'''|)^(1/3),
  and the model's error there;
* the *fitted optimal step* eps^ = (B / 2A)^(1/3) of A eps^2 + B / eps fitted to
  the measured error (`fit_model`), and the *measured minimum*, the noisy curve's
  lowest point on the grid of steps.

Working precision: 50 digits, so that the reference's own error (~1e-50) is
far below the float64 quantities measured (>= 1e-17).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

from renderer import fieldcode, pointwise, validate
from renderer.scene import DRAFT_SCENE
from renderer import formulas as F
from renderer import univariate as U

__all__ = ["UCurve", "measure", "measure_function", "fit_model", "non_differentiable", "UNIT_ROUNDOFF",
           "DIGITS", "SEED_POINT", "SEED_FREQUENCIES", "DEFAULT_STEPS", "MAX_FUNCTION_STEP"]

#: Unit roundoff of IEEE double precision (round to nearest).
UNIT_ROUNDOFF = 2.0**-53
#: mpmath working precision of the references, in decimal digits.
DIGITS = 50
#: The seed's chart point (u, v) of Cell 2's U-curve (sine field), and its
#: frequencies (k_u, k_v), the draft's scene's.
SEED_POINT = F.SEED_POINT
SEED_FREQUENCIES = (DRAFT_SCENE.k_u, DRAFT_SCENE.k_v)
#: The default steps: 14 per decade from 1e-1 to 1e-15, so that every power of ten is one of them.
DEFAULT_STEPS = np.logspace(-1, -15, 14 * 14 + 1)


def _rational(x):
    """``x`` (a float) as an exact sympy Rational."""
    return sp.Rational(*Fraction(x).as_integer_ratio())


def _exact_at(expr, at):
    """``expr`` with the symbols of ``at`` ({symbol: exact value}) replaced, as ``expr.subs(at)`` gives it, or
    None where a power of two exact numbers would have more digits than Python prints
    (``sys.get_int_max_str_digits()``): sympy would spend minutes computing (3 k_u)**(k_u**k_u) at k_u = 8 before
    any check could refuse it."""
    limit = sys.get_int_max_str_digits() or 4300

    def walk(e):
        if e in at:
            return at[e]
        if not e.args:
            return e
        args = [walk(a) for a in e.args]
        if any(a is None for a in args):
            return None
        if isinstance(e, sp.Pow) and all(a.is_Rational for a in args):
            base, power = args
            if abs(power.p) * math.log10(max(abs(base.p), base.q)) >= limit:
                return None
        return e.func(*args)
    return walk(expr)


def _crease(expr, var, at, x0):
    """The factor under an ``Abs`` of ``expr`` (of the product there, the one in ``var``) that
    changes sign at x0 as ``var`` moves (the other
    variables at ``at``: {symbol: value}), or None.  A zero within one ulp of x0 counts (no float64
    step can tell its two sides apart): |F(x0)| <= |F'(x0)| spacing(x0), with F'(x0) != 0 (where
    F' vanishes too, |F| is flat there: both factors of the ridges vanish, say)."""
    for a in sorted(expr.atoms(sp.Abs), key=sp.default_sort_key):
        inner = a.args[0]
        exact = _exact_at(inner, at), _exact_at(sp.diff(inner, var), at)
        if None in exact:                               # too large to evaluate: `measure` refuses the field
            continue
        f, df = (sp.lambdify(var, e, modules="mpmath") for e in exact)
        with mpmath.workdps(DIGITS):
            X = mpmath.mpf(x0)
            value, slope = _real(f, X), _real(df, X)
            if value is None or slope is None:          # no value there: no sign change to find
                continue
            # |F / F'| is the distance to the zero to first order; 1 + 1e-9 covers the second.
            if abs(slope) > mpmath.mpf(10) ** (-DIGITS // 2) and \
                    abs(value) <= abs(slope) * abs(float(np.spacing(x0))) * (1 + mpmath.mpf(10) ** -9):
                return next((f for f in sp.Mul.make_args(inner) if var in f.free_symbols), inner)
    return None


def non_differentiable(field, u, v, component, k_u, k_v):
    """Why h_u (``component="u"``) or h_v of ``field`` has no derivative at the
    chart point (u, v), or None where it has one.

    Two cases (seed §3 and §7): the pole v = 0 or v = 1, where the chart is
    singular (every u names the same point of the sphere, so a chart
    derivative there is not a derivative of a function on the sphere); and a
    crease, where a factor under an ``Abs`` of h changes sign as the component
    moves (the ridges field h = |sin(pi k_u u) sin(pi k_v v)| on u = m / k_u
    or v = m / k_v), so that the slope jumps.  A point within one ulp of a
    crease counts as on it: no float64 step can tell its two sides apart.
    Where both factors vanish, h is 0 along the component's line and the
    partial derivative exists (it is 0).  mpmath at `DIGITS` digits, the
    frequencies and the point as exact rationals.

    Parameters
    ----------
    field : str, HeightField or sympy expression
        As `renderer.formulas.field` takes it.
    u, v : float
        The chart point (`measure` accepts [0, 1]).
    component : {"u", "v"}
    k_u, k_v : float > 0

    Returns
    -------
    str or None
        The reason, naming the point and the crease or pole; None where the
        derivative exists.
    """
    if v in (0.0, 1.0):
        return (f"v = {v!r} is a pole of the chart: every u names the same point of the sphere, "
                f"so the field is not differentiable there as a function on the sphere")
    record = F.field(field)
    var, x0 = (F.u, u) if component == "u" else (F.v, v)
    at = {F.k_u: _rational(k_u), F.k_v: _rational(k_v)}
    at[F.v if component == "u" else F.u] = _rational(v if component == "u" else u)
    inner = _crease(record.expr, var, at, x0)
    if inner is None:
        return None
    return (f"{component} = {x0!r} lies on a crease of the {record.name} field, where {inner} changes sign "
            f"(k_u = {k_u:g}, k_v = {k_v:g}): h is not differentiable in {component} there (its slope jumps)")


@dataclass(frozen=True)
class UCurve:
    """Result of `measure` (arrays are float64, one entry per step).

    Where the derivative does not exist (``reason`` is not None, see
    `non_differentiable`), ``error`` and ``truncation`` are measured against
    the one-sided derivative from the interior side named in ``reason``'s
    place (from above, or from below at 1), and ``derivative``, the model and
    every step and error named below are NaN: there is no true derivative and
    no optimal step.

    Three steps have names, one each (the book's, the command line's and the
    glue's): ``eps_model`` the *model-optimal step* eps*, minimiser of the error
    model E; ``eps_fitted`` the *fitted optimal step* eps^, minimiser of
    A eps^2 + B / eps fitted to the measured error; ``eps_measured_min`` the
    *measured minimum*, the lowest point of the noisy measured curve.  Steps in
    chart units; errors in units of the derivative (height per chart unit).
    """

    field: str
    u: float
    v: float
    component: str
    eps: np.ndarray
    error: np.ndarray          # |float64 FD - true derivative|
    truncation: np.ndarray     # exact-arithmetic FD at the float64 abscissae - true (signed)
    roundoff: np.ndarray       # float64 FD - exact-arithmetic FD (signed)
    model: np.ndarray          # E(eps) = model_truncation eps^2 + (model_cancellation + model_argument) / eps
    derivative: float          # the true derivative h', rounded to float64
    third_derivative: float    # h''' at the point
    height: float              # h at the point
    #: The error model's three coefficients: |h'''| / 6, u_round |h| and u_round |x h'|.
    model_truncation: float
    model_cancellation: float
    model_argument: float
    eps_model: float           # model-optimal step eps* = (3 u_round (|h| + |x h'|) / |h'''|)^(1/3)
    error_model: float         # E(eps*)
    eps_measured_min: float    # the step of least measured error on the grid
    error_at_measured_min: float
    reason: str | None = None  # why h has no derivative here (`non_differentiable`), or None
    #: The model A eps^2 + B / eps fitted to the measured error (`fit_model`),
    #: its minimiser (B / 2A)^(1/3) (the fitted optimal step) and the fitted
    #: model's error there: they move little with the grid of steps (the
    #: measured minimum of a noisy curve jumps between its dips).
    fitted_truncation: float = float("nan")
    fitted_roundoff: float = float("nan")
    eps_fitted: float = float("nan")
    error_at_fitted: float = float("nan")


def fit_model(eps, error, start=(1.0, UNIT_ROUNDOFF)):
    """(A, B) of the model A eps^2 + B / eps fitted to a measured U-curve.

    Least squares on the logarithms (every decade of error weighs the same;
    Gauss-Newton from ``start``, in log A and log B, until a step moves
    neither by more than 1e-12); steps with zero error are left out.

    Parameters
    ----------
    eps, error : 1-D arrays of real numbers of one length, eps > 0, error >= 0
    start : two real numbers > 0
        First guess, e.g. (|third derivative| / 6, u |h|).

    Raises
    ------
    renderer.validate.InputError
        Naming the argument: not real numbers, eps not positive, an error negative, shapes that
        differ, a start that is not two positive numbers.
    ValueError
        Fewer than 2 steps with nonzero error; or no fit: no convergence in 100
        steps, or an optimum (B / 2A)^(1/3) outside the steps (they see one side of it).
    """
    eps = validate.real_array("eps", eps, low=0.0, low_open=True)
    error = validate.real_array("error", error, low=0.0)
    if eps.ndim != 1 or error.shape != eps.shape:
        raise validate.InvalidValue(f"eps and error must be 1-D arrays of one length, got shapes {eps.shape} "
                                    f"and {error.shape}")
    start = validate.real_array("start", start, low=0.0, low_open=True)
    if start.shape != (2,):
        raise validate.InvalidValue(f"start must be two numbers (A, B), got shape {start.shape}")
    keep = error > 0
    if np.count_nonzero(keep) < 2:
        raise ValueError("error must have at least 2 nonzero entries to fit a two-term model")
    e, err = eps[keep], error[keep]
    p = np.log(start)
    with np.errstate(all="ignore"):
        for _ in range(100):
            trunc, rnd = np.exp(p[0]) * e**2, np.exp(p[1]) / e
            model = trunc + rnd
            jac = np.stack([trunc / model, rnd / model], axis=1)
            if not (np.all(np.isfinite(jac)) and np.all(model > 0)):
                break                        # a term vanished or blew up: the steps see one side only
            step = np.linalg.lstsq(jac, np.log(model / err), rcond=None)[0]
            p -= step
            if not np.all(np.abs(p) < 700):
                break
            if np.max(np.abs(step)) < 1e-12:
                A, B = float(np.exp(p[0])), float(np.exp(p[1]))
                if e.min() <= (B / (2 * A)) ** (1 / 3) <= e.max():
                    return A, B
                break                        # an optimum outside the steps: they see one side only
    raise ValueError("the U-curve model did not fit (steps on one side of the optimum only, or no "
                     "convergence in 100 Gauss-Newton steps)")


#: The most nodes sympy's tree of h' or h'' may have (`_line`): each derivative multiplies the tree (sin
#: nested 30 deep: 466 nodes, h'' 15,781, h''' 253,146, minutes to print and compile).
MAX_DERIVATIVE_NODES = 4_000


def _line(g, var, what):
    """h, h' and h''' as mpmath functions of ``g``, an expression in ``var`` alone, the derivative
    of |f| as sign(f) f' (the derivatives of sign, which vanish off the crease, dropped: sympy's
    DiracDelta, and the derivative it leaves unevaluated where it cannot tell f is real).  Raises
    InvalidValue beginning with ``what`` ("function f") where h' or h'' has more than
    `MAX_DERIVATIVE_NODES` nodes, before the next derivative is taken.  Returns (the three functions,
    (h, h') as sympy expressions, for `_refuse_pole`)."""
    def kink(x):
        return isinstance(x, sp.DiracDelta) or isinstance(x, sp.Derivative) and isinstance(x.expr, sp.sign)

    def smooth(e):
        return e.replace(kink, lambda x: 0)
    d = [g]
    for n in (1, 2, 3):
        d.append(sp.diff(d[-1], var))
        if n < 3 and (nodes := sum(1 for _ in sp.preorder_traversal(d[-1]))) > MAX_DERIVATIVE_NODES:
            raise validate.InvalidValue(f"{what} is too large to measure: sympy's tree of its derivative of "
                                        f"order {n} has {nodes:,} nodes (at most {MAX_DERIVATIVE_NODES:,})")
    return tuple(sp.lambdify(var, smooth(d[n]), modules="mpmath") for n in (0, 1, 3)), (d[0], d[1])


@lru_cache(maxsize=None)
def _stencil():
    """(u_p, u_m, v_p, v_m, den_u, den_v) as float64 functions of (u, v, eps_u, eps_v): the
    kernel's stencil points (`formulas.STENCIL_POINTS`) and its quotients' denominators
    (`formulas.CENTRAL_DENOMINATORS`)."""
    points = dict(F.STENCIL_POINTS)
    dens = [d.subs(points) for d in F.CENTRAL_DENOMINATORS]
    args = (F.u, F.v, F.eps_u, F.eps_v)
    return sp.lambdify(args, [points[p] for p in (F.u_p, F.u_m, F.v_p, F.v_m)] + dens, modules="math")


def _value(fn, X):
    """(``fn(X)``, None) (an mpmath function at an mpf, at the current precision) where it is a real number
    float64 can hold, else (None, why not): infinite (a pole, a logarithm of 0), an overflow, not real
    (a complex value: a root or logarithm of a negative number), beyond float64's range (which the U-curve
    would report as inf), or no value at all."""
    try:
        y = mpmath.mpmathify(fn(X))             # a constant derivative is a Python number
    except ZeroDivisionError:
        return None, "is infinite"
    except OverflowError:
        return None, "overflows (beyond any number mpmath holds)"
    except (ArithmeticError, ValueError, TypeError):
        return None, "has no value"
    if isinstance(y, mpmath.mpc):
        return None, f"is not real ({mpmath.nstr(y, 3)}: a root or logarithm of a negative number, say)"
    if mpmath.isinf(y):
        return None, "is infinite"
    if mpmath.isnan(y):
        return None, "has no value"
    if abs(y) > np.finfo(float).max:
        return None, f"is {mpmath.nstr(y, 3)}, beyond float64's largest number"
    return y, None


def _real(fn, X):
    """`_value`'s value, or None."""
    return _value(fn, X)[0]


def _named(point):
    """("function" or "field", the point as the refusals write it, the names of h, h' and h''')."""
    return (("function", f"x = {point['u']!r}", ("f", "f'", "f'''")) if point["component"] == "x" else
            ("field", f"(u, v) = ({point['u']!r}, {point['v']!r})",
             ("h", f"h_{point['component']}", f"h_{point['component'] * 3}")))


def _undefined(label, point, line, X):
    """The refusal of a point where the function, or a derivative the measurement needs (``line``: h, h',
    h''' as mpmath functions, at ``X``), has no value float64 can hold, saying which and why."""
    what, where, names = _named(point)
    why = next((f"{name} {reason}" for name, fn in zip(names, line) for reason in [_value(fn, X)[1]] if reason),
               "it has no value")
    return validate.InvalidValue(f"{what} {label} must be defined and differentiable at {where}: there {why}")


def _refuse_pole(label, exprs, var, x, point):
    """Raise `_undefined`'s refusal where h or h' (``exprs``, in ``var``) at the float ``x`` taken exactly is
    infinite or undefined to sympy: a pole the 50-digit reference misses, since its pi is not pi
    (1/sin(pi x) at x = 1 is 1e102 there)."""
    what, where, names = _named(point)
    for name, e in zip(names, exprs):
        exact = _exact_at(e, {var: _rational(x)})
        if exact is not None and exact.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
            raise validate.InvalidValue(f"{what} {label} must be defined and differentiable at {where}: there "
                                        f"{name} is not finite (a pole, or no value: sympy, exactly)")


@lru_cache(maxsize=None)
def _error_model():
    """`renderer.formulas.ERROR_MODEL` and `EPS_STAR` as numpy functions of (eps, |h'''|, |h|,
    |x h'|, u_round): the model's coefficient of eps^2 (truncation) and of 1/eps from |h| (the
    rounded values) and from |x h'| (the rounded abscissae), the model, and its minimiser."""
    args = (F.eps, F.H3, F.H, F.HX, F.u_round)
    expanded = sp.expand(F.ERROR_MODEL)
    roundoff = expanded.coeff(F.eps, -1)
    parts = (expanded.coeff(F.eps, 2), roundoff.subs(F.HX, 0), roundoff.subs(F.H, 0), F.ERROR_MODEL, F.EPS_STAR)
    return tuple(sp.lambdify(args, p, "numpy") for p in parts)


def _curve(label, x, steps, quotient, line, reason, point, exact):
    """The U-curve of the float64 quotients ``quotient(eps) -> (value, x_plus, x_minus, den)`` of the
    function ``line`` = (h, h', h''') of one variable at x: `UCurve`'s fields (``label`` and
    ``point`` fill its field, u, v, component).  Raises `renderer.validate.InvalidValue` where h or
    h' (or h''', which the model needs where there is a derivative) is not a real number float64
    can hold at x, or is not finite there exactly (``exact``: h and h' as sympy expressions, and their
    variable; `_refuse_pole`), or, naming ``eps``, where a quotient, or h at one of its abscissae, is not."""
    h_mp, dh_mp, d3h_mp = line
    with mpmath.workdps(DIGITS):
        X = mpmath.mpf(x)
        if reason is None:
            true = _real(dh_mp, X)
        else:
            # The one-sided derivative: the derivative 1e-40 inside (smaller x at the chart's
            # edge 1), where the field is smooth and within ~1e-39 of the one-sided limit.
            true = _real(dh_mp, X + mpmath.mpf(10) ** -(DIGITS - 10) * (-1 if x == 1.0 else 1))
        h0, h3 = _real(h_mp, X), (_real(d3h_mp, X) if reason is None else mpmath.nan)
        if true is None or h0 is None or h3 is None:
            raise _undefined(label, point, line if reason is None else line[:2], X)
        _refuse_pole(label, *exact, x, point)
        error, trunc, roundoff = [], [], []
        for i, e in enumerate(steps):
            fd, plus, minus, den = quotient(float(e))
            # The abscissae and the denominator, exactly as float64 made them.
            ends = _real(h_mp, mpmath.mpf(plus)), _real(h_mp, mpmath.mpf(minus))
            if None in ends or not np.isfinite(fd):
                raise validate.InvalidValue(
                    f"eps must keep {label} finite and real at the abscissae of its quotient; at the step "
                    f"{float(e)!r} (step {i}) it is not, at {minus!r} or {plus!r}")
            exact_fd = (ends[0] - ends[1]) / mpmath.mpf(den)
            trunc.append(float(exact_fd - true))
            roundoff.append(float(mpmath.mpf(fd) - exact_fd))
            error.append(float(abs(mpmath.mpf(fd) - true)))
    error = np.array(error)
    h0f, h3f = float(h0), float(h3)
    measured = dict(field=label, **point, eps=steps, error=error, truncation=np.array(trunc),
                    roundoff=np.array(roundoff), height=h0f)
    best = int(np.argmin(error))
    nan = float("nan")
    if reason is not None:
        return UCurve(**measured, model=np.full(steps.shape, nan), derivative=nan, third_derivative=nan,
                      model_truncation=nan, model_cancellation=nan, model_argument=nan, eps_model=nan,
                      error_model=nan, eps_measured_min=nan, error_at_measured_min=nan, reason=reason)
    trunc, cancel, argument, model_at, star_at = _error_model()
    given = (abs(h3f), abs(h0f), abs(x * float(true)), UNIT_ROUNDOFF)
    T, C, G = (float(f(1.0, *given)) for f in (trunc, cancel, argument))
    model = model_at(steps, *given)
    # No truncation (T = 0): E falls towards 0 as eps grows (eps* infinite); no rounding (C + G = 0,
    # h = 0 at x = 0): E is least, 0, at eps* = 0.
    star = float(star_at(1.0, *given)) if T > 0 else float("inf")
    least = float(model_at(star, *given)) if 0 < star < float("inf") else 0.0
    try:
        A, B = fit_model(steps, error, start=(max(T, 1e-300), max(C + G, 1e-300)))
    except ValueError:              # an exact quotient (h_u of rings: zero error) has no U to fit
        A = B = nan
    eps_fit = (B / (2 * A)) ** (1 / 3)
    return UCurve(**measured, model=model, derivative=float(true), third_derivative=h3f,
                  model_truncation=T, model_cancellation=C, model_argument=G, eps_model=star,
                  error_model=least,
                  eps_measured_min=float(steps[best]), error_at_measured_min=float(error[best]),
                  fitted_truncation=A, fitted_roundoff=B, eps_fitted=float(eps_fit),
                  error_at_fitted=float(A * eps_fit**2 + B / eps_fit))


def measure(field="sine", u=SEED_POINT[0], v=SEED_POINT[1], component="u", eps=None,
            k_u=SEED_FREQUENCIES[0], k_v=SEED_FREQUENCIES[1]):
    """Measure the central-difference U-curve of a height field at one chart point.

    Parameters
    ----------
    field : str, HeightField or sympy expression
        A registered field's name (one of `renderer.formulas.FIELDS`), or a reader's
        field in u, v, k_u, k_v (`renderer.formulas.field`).
    u, v : float in [0, 1]
        Chart point (default `SEED_POINT`, the seed's).
    component : {"u", "v"}
        Which partial derivative.
    eps : array_like of float in [`renderer.pointwise.MIN_STEP`, 1), optional
        Steps (chart units; any shape, taken flat); default `DEFAULT_STEPS`.
    k_u, k_v : float in (0, 1e3]
        Frequencies, as `renderer.Scene` accepts them.

    Scalars are accepted as `renderer.validate.real` says (Python or numpy
    numbers, 0-d arrays; not bools).

    Returns
    -------
    UCurve

    Raises
    ------
    ValueError
        Naming the argument, for an unknown field or component, a chart
        point outside [0, 1], a frequency outside (0, 1e3], no steps or a
        step outside [`renderer.pointwise.MIN_STEP`, 1); naming ``field``, a
        point where h, h' or h''' (the model's, where h' exists) is not a real
        number float64 can hold (a pole of a reader's field, a line where it
        has no value; also where only its exact value is infinite, 1/sin(pi u)
        at u = 1) or whose exact value has too many digits to print, or a
        field whose h' or h'' has more than `MAX_DERIVATIVE_NODES` nodes;
        naming ``eps``, a step at whose abscissae h or the quotient is not.
    TypeError
        Naming the argument, for one of the wrong type (a bool, a string
        for a number).  Both are `renderer.validate.InputError`.

    Notes
    -----
    At a crease (`non_differentiable`: a factor under an ``Abs`` changes sign), or
    at a pole, there is no derivative: the result's ``reason`` says why, the
    reference is the one-sided derivative from the side of larger u or v
    (smaller, at 1), ``truncation`` does not vanish as eps -> 0, and the
    derivative and the optimal step are NaN.
    """
    record = F.field(field, "field")
    component = validate.choice("component", component, ("u", "v"))
    # The ranges of `pointwise.central_gradient`, which the measurement calls.
    u, v, k_u, k_v = (validate.real(name, x, **pointwise.RANGES_CENTRAL[name])
                      for name, x in (("u", u), ("v", v), ("k_u", k_u), ("k_v", k_v)))
    steps = DEFAULT_STEPS if eps is None else validate.steps("eps", eps, **pointwise.RANGES["eps"])
    k = 0 if component == "u" else 1
    var, x = (F.u, u) if k == 0 else (F.v, v)
    at = {F.k_u: _rational(k_u), F.k_v: _rational(k_v), (F.v if k == 0 else F.u): _rational(v if k == 0 else u)}
    point, g = dict(u=u, v=v, component=component), _exact_at(record.expr, at)
    if g is not None and g.has(sp.zoo, sp.nan, sp.oo, -sp.oo):      # no value on the line (tan(pi u), u = 1/2)
        fixed, at_value = (F.v, v) if k == 0 else (F.u, u)
        raise validate.InvalidValue(f"field {record.name} must be defined and differentiable at (u, v) = ({u!r}, "
                                    f"{v!r}): there it has no value on the line {fixed} = {at_value!r}")
    if g is None or sys.get_int_max_str_digits() and any(max(abs(r.p), r.q) >= 10 ** sys.get_int_max_str_digits()
                                                         for r in g.atoms(sp.Rational)):   # which lambdify cannot print
        raise validate.InvalidValue(f"field {record.name} is too large to measure at (u, v) = ({u!r}, {v!r}): "
                                    f"its exact value there has more digits than Python prints")
    line, exact = _line(g, var, f"field {record.name}")
    stencil = _stencil()

    def quotient(e):
        points = stencil(u, v, e, e)
        fd = float(pointwise.central_gradient(record, u, v, k_u, k_v, e)[k])
        return fd, points[2 * k], points[2 * k + 1], points[4 + k]

    return _curve(record.name, x, steps, quotient, line, non_differentiable(record, u, v, component, k_u, k_v),
                  point, (exact, var))


#: The largest step `measure_function` accepts (its smallest is `renderer.pointwise.MIN_STEP`).
MAX_FUNCTION_STEP = 1e3


def measure_function(function, x, eps=None):
    """Measure the central-difference U-curve of a reader's function of one variable at x.

    The float64 quotient is (f(fl(x + eps)) - f(fl(x - eps))) / (2 eps), f compiled by numba
    from the printed expression (`renderer.fieldcode.univariate_code`), split as `measure`
    splits it (the abscissae as float64 made them).

    Parameters
    ----------
    function : sympy expression of one symbol, its text in ``x``, or `renderer.univariate.Univariate`
        E.g. ``"exp(x) / sqrt(sin(x)**3 + cos(x)**3)"`` (Squire and Trapp 1998).
    x : float
        Any real point where f is defined and differentiable, and f(x +- eps) too.
    eps : array_like of float in [`renderer.pointwise.MIN_STEP`, `MAX_FUNCTION_STEP`], optional
        Steps; default `DEFAULT_STEPS`.

    Returns
    -------
    UCurve
        With ``field`` the function's printed form, ``u`` = x, ``v`` NaN and ``component`` "x".

    Raises
    ------
    renderer.validate.InputError
        Naming the argument: an expression refused by `renderer.univariate.univariate`, a point
        or a step that is not a finite float in range, a point where f, f' or f''' is not a real
        number float64 can hold (or f or f' is infinite only exactly: 1/sin(pi x) at x = 1) or f has a
        crease (|g| where g changes sign), an f whose f' or f'' has more than `MAX_DERIVATIVE_NODES`
        nodes, a step at which f(x +- eps) is not.  A stencil that steps over a singularity of f, f finite at both its
        abscissae (tan(x) at x = 1.5, eps = 0.1), is measured, not refused: its error is of the size
        of f' or larger, and the model-optimal step lies below it.  (sympy's singularity finder,
        which could refuse it, took from 1 s to over 20 s on functions of Squire and Trapp's size.)
    """
    record = U.univariate(function, "function")
    x = validate.real("x", x)
    steps = DEFAULT_STEPS if eps is None else validate.steps("eps", eps, low=pointwise.MIN_STEP,
                                                              high=MAX_FUNCTION_STEP)
    (line, exact), point = _line(record.expr, U.x_var, f"function {record.name}"), dict(u=x, v=float("nan"), component="x")
    with mpmath.workdps(DIGITS):
        if any(_real(fn, mpmath.mpf(x)) is None for fn in line[:2]):     # before the crease and float64 checks
            raise _undefined(record.name, point, line[:2], mpmath.mpf(x))
    if _crease(record.expr, U.x_var, {}, x) is not None:
        raise validate.InvalidValue(f"function {record.name} is not differentiable at x = {x!r}: it has a "
                                    f"crease there (the argument of an abs changes sign)")
    code = fieldcode.univariate_code(record)
    if not np.isfinite(code.value(x)):
        raise validate.InvalidValue(f"x must be a point where function {record.name} is a finite float64; "
                                    f"at x = {x!r} it overflows")

    def quotient(e):
        return code.central(x, e), x + e, x - e, 2 * e

    return _curve(record.name, x, steps, quotient, line, None, point, (exact, U.x_var))
