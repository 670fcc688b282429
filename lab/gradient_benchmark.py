"""Run time against error for the ways of computing a derivative (`lab.gradient_methods.METHODS`):
of a height field's chart gradient over a frame, and of a reader's function of one variable at
a point.

`measure` times every method that applies to a field over the sphere-A pixels of a
256 x 256 frame of the draft's scene (median, minimum and maximum over repeats, methods
interleaved), counts its work per pixel (`lab.gradient_methods.Evaluations`: values of h, evaluations of the
generated gradient, and the sines and cosines they cost, counted from the sympy objects the
kernel is generated from; scipy counts its own evaluations), and measures the largest and
RMS error of both components against an mpmath reference of the exact gradient
(`lab.gradient_methods.reference_gradient`).  Where a field has creases the derivative does not exist on them, so
errors are measured off the crease band (`renderer.pointwise.kink_band`); the timings cover
every pixel.  The exact and central gradients and h itself are the kernel's compiled
functions; forward differences call the compiled h three times from numpy; the complex
step evaluates h in complex numpy; Richardson calls the compiled h from scipy's iteration;
AD runs JAX's jit-compiled (XLA) program, whose first call at a frame's size compiles and
is timed apart (`MethodResult.compile_seconds`).  So the times compare the methods as they
are available here, not as each could best be compiled.

`univariate_errors` runs the methods on a reader's f(x) (`renderer.univariate.univariate`) at
any real x where it is differentiable, at each step of a grid, against the mpmath value of
its derivative; the central difference's row is `renderer.ucurve.measure_function`'s
U-curve.  `PUBLISHED` holds what the complex-step papers report about their test function
(Squire and Trapp 1998, Martins et al. 2003: `lab.gradient_methods`'s references [1] and [2],
book/references.bib's ``squire-trapp`` and ``martins-complex-step``).

`FAST` is the configuration the book runs when it is built; `FULL` the one the benchmark
runs for a release.  `pareto_front` picks a `Measurement`'s non-dominated methods; the book
draws and tabulates it (book/chapter/benchmark.py).
"""

from __future__ import annotations

import json
import math
import os
import platform
import sys
import time
from dataclasses import asdict, dataclass, field as dc_field

import mpmath
import numpy as np
import sympy as sp

from renderer import DRAFT_SCENE, gbuffer, pointwise, ucurve, validate
from renderer import formulas as F
from renderer import univariate as U
from renderer.render import SPHERE_A
from renderer.scene import UNIT
from renderer.validate import InvalidType, InvalidValue, choice, positive_int

from ._checks import MAX_COUNT, MAX_SQUARE, STEP, digits as _digits, height_fields, instance, optional, seed, shown
from . import gradient_methods      # METHODS read at each call: a test may append a record

__all__ = [
    "Config", "FAST", "FULL", "chart_points", "MethodResult", "Measurement", "measure", "pareto_front", "to_json",
    "UNIVARIATE_STEPS", "UnivariateRow", "UnivariateErrors", "univariate_errors", "Published", "Example",
    "TEST_FUNCTION", "PUBLISHED",
]


# --- what a measurement runs ----------------------------------------------------------------

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
#: at 34 digits and one Richardson run per field keep it to about a second.  Nine repeats: with
#: three, one step's median could be twice its neighbours' while the build ran another page beside
#: it (the same stencil at three steps read as 2.7, 6.6 and 2.7 ms); with nine, run alone, they agree
#: within a few percent, and in a build they still spread by about a third (2.3 to 3.3 ms).
#: Steps: the draft's step, near each quotient's optimum (central 1e-6, forward 1e-8),
#: and one past the central optimum, where rounding rules.
FAST = Config("fast", central_steps=(DRAFT_SCENE.eps, 1e-6, 1e-9), forward_steps=(DRAFT_SCENE.eps, 1e-8),
              complex_steps=(1e-20,), repeats=9, richardson_repeats=1, reference_pixels=100)
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
    config, records, uv = _config(config), height_fields("fields_", fields_), None if uv is None else _uv(uv)
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
        hi, lo = gradient_methods.reference_gradient(record, ru, rv, ku, kv, digits=config.digits)
        for m in gradient_methods.methods():
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
    that applies, in `lab.gradient_methods.METHODS` order, per step); ``curve`` the central
    difference's U-curve (`renderer.ucurve.UCurve`, ``eps_model`` and ``eps_fitted`` its optimal
    steps); and
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
    """Every method of `lab.gradient_methods.METHODS` with a one-variable form that applies to
    ``function``, at x, at each step, against an mpmath reference of the derivative.

    The reference is the function's derivative (`renderer.univariate.Univariate.derivative`,
    sympy's) evaluated by mpmath at `renderer.ucurve.DIGITS` digits at x as float64 holds it,
    the derivative `renderer.ucurve.measure_function` measures against; that function also
    validates the input.  Each error is computed at the reference's precision from the
    float64 estimate, so no rounding of the reference enters it.  The central difference is the
    quotient `renderer.ucurve.measure_function` measures (its U-curve is returned as ``curve``).

    Parameters
    ----------
    function : sympy expression of one symbol, its text in ``x``, or `renderer.univariate.Univariate`
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
        One line naming the argument: a function refused by `renderer.univariate.univariate`
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
    record, x = U.univariate(function), validate.real("x", x)
    steps = validate.steps("steps", steps, low=pointwise.MIN_STEP, high=ucurve.MAX_FUNCTION_STEP)
    try:
        # Refuses a point where f or f' is not a real number float64 holds, a crease, a float64 f(x) that
        # overflows, and a step at which f(x +- eps) is not finite.
        curve = ucurve.measure_function(record, x, eps=steps)
    except validate.InvalidValue as exc:                           # its eps is this function's steps
        text = str(exc)
        raise validate.InvalidValue(f"steps{text[3:]}" if text.startswith("eps ") else text) from None
    steps = tuple(float(e) for e in curve.eps)
    true_fn = sp.lambdify(U.x_var, record.derivative, modules="mpmath")
    rows, evaluations = [], {}
    with mpmath.workdps(ucurve.DIGITS):
        true = true_fn(mpmath.mpf(x))
        for m in gradient_methods.methods():
            if m.derivative is None or not m.applies(record):
                continue
            for eps in ((None,) if m.steps is None else steps):
                info = {}
                with np.errstate(all="ignore"):           # a value that is not finite is refused below
                    value = m.derivative(record, x, eps, info)
                if not math.isfinite(value):
                    raise validate.InvalidValue(f"function {record.name}: its {m.name} derivative at x = {x!r}"
                                                + (f" with the step {eps!r}" if eps is not None else "")
                                                + " is not a finite number: it evaluates f where f is not finite"
                                                + " (a smaller step keeps it nearer x)")
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
              "truncation error O(ε²); a small ε trades truncation for subtractive cancellation"),
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
