"""The price of fast math: each backend's sin, cos, atan2, acos and pow against mpmath,
and the U-curve's roundoff floor with each backend's sine.

Four backends evaluate the kernel's transcendental functions on float64 arrays
(`BACKENDS`): ``numba``, the scalar libm the compiled kernel calls (one call per
element, through `numba.vectorize` ufuncs compiled as the kernel is);
``numpy``, numpy's ufuncs (which dispatch to SIMD code where the CPU has it);
``drjit``, Dr.Jit's LLVM backend on ``Float64`` arrays (only where
`renderer.backends.drjit_llvm` finds the system's LLVM); ``jax``, jax.numpy in
float64 under ``jax.jit`` (XLA on the CPU).  (The kernel takes an integral shininess by
repeated squaring, ``renderer.kernel.int_power``; pow here is what it calls for any other.)

Accuracy is counted in ulps: |y - t| / ulp(t), t the true value of the function
at the float64 argument (mpmath at `DIGITS` digits) and ulp(t) the spacing of
float64 numbers at t (2^(e - 52) for |t| in [2^e, 2^(e+1)), 2^-1074 below the
normal range; `ulps`).  A correctly rounded function is within 0.5 ulp
everywhere.  The arguments cover the ranges the render kernel feeds each function
(`arguments`): the sines and cosines of pi k u and 2 pi k v over every accepted
frequency; atan2 of the chart (renderer.formulas.CHART) over the unit sphere;
acos over [-1, 1] (the draft's chart, acos N_z); pow of the specular base in
[0, 1] with every accepted shininess; each with a fixed seeded sample and a set
of hard points.

Working precision: 50 digits, so that the reference's own error (~1e-50
relative) is far below the 2^-53 measured.
"""

from __future__ import annotations

import math
import os
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp
from mpmath import libmp
from numba import vectorize

from renderer import _numba_cache
from renderer import formulas as F
from renderer.scene import FREQUENCY, MAX_FREQUENCY, MAX_SHININESS, MIN_SHININESS, UNIT
from renderer.validate import InvalidValue, choice, positive_int, real, real_array

from ._checks import MAX_COUNT, STEP, broadcast, integers, numbers_array, seed as _seed

_numba_cache()          # where numba caches this module's ufuncs (see renderer.kernel)

__all__ = ["FUNCTIONS", "BACKENDS", "DIGITS", "SAMPLES", "SEED", "QUANTILE", "available", "backend",
           "arguments", "reference", "ulps", "flushes", "ulp_table", "floors", "central_differences", "max_angle"]

#: The transcendental functions of the render kernel, in the order of the tables.
FUNCTIONS = ("sin", "cos", "atan2", "acos", "pow")
#: The backends, in the order of the tables (`available` says which this machine has).
BACKENDS = ("numba", "numpy", "drjit", "jax")
#: mpmath working precision of the references, in decimal digits.
DIGITS = 50
#: Sample size per function (before the hard points), and its seed.
SAMPLES = 2**16
SEED = 9
#: The high quantile of the ulp error reported beside the maximum.
QUANTILE = 0.999


def max_angle():
    """The largest argument of a sine or cosine in the registered height fields and their gradients
    (`renderer.formulas.FIELDS`), at u = v = 1 and the largest k (`MAX_FREQUENCY`): 2 pi k v of the
    rings field among the built-in ones.  A float (radians); each argument is read as growing with
    u, v and k, as every linear phase does."""
    at = {F.u: 1, F.v: 1, F.k_u: MAX_FREQUENCY, F.k_v: MAX_FREQUENCY}
    return max(float(abs(a.args[0].subs(at))) for f in F.FIELDS.values() for e in (f.expr, *f.gradient)
               for a in e.atoms(sp.sin, sp.cos))
#: log2 of the smallest power pow's sample reaches: just above the smallest normal float64, 2^-1022.
MIN_POWER_LOG2 = -1021.0


# ----------------------------------------------------------------- backends
# libm through numba: ufuncs whose loops call math.sin etc. once per value, as the kernel does.
@vectorize(["float64(float64)"], cache=True)
def _numba_sin(x):
    return math.sin(x)


@vectorize(["float64(float64)"], cache=True)
def _numba_cos(x):
    return math.cos(x)


@vectorize(["float64(float64, float64)"], cache=True)
def _numba_atan2(y, x):
    return math.atan2(y, x)


@vectorize(["float64(float64)"], cache=True)
def _numba_acos(x):
    return math.acos(x)


@vectorize(["float64(float64, float64)"], cache=True)
def _numba_pow(base, e):
    return base ** e


def _numba():
    return {"sin": _numba_sin, "cos": _numba_cos, "atan2": _numba_atan2, "acos": _numba_acos, "pow": _numba_pow}


def _numpy():
    return {"sin": np.sin, "cos": np.cos, "atan2": np.arctan2, "acos": np.arccos, "pow": np.power}


def _drjit():
    from renderer.backends import drjit_llvm, llvm_library
    # A library path that is no file: no Dr.Jit (importing it would print its failed load to stderr).
    path = llvm_library()
    llvm = drjit_llvm() if path is not None and os.path.isfile(path) else None
    if llvm is None:
        return None
    import drjit as dr

    def call(f):
        return lambda *args: np.array(f(*(llvm.Float64(a) for a in args)), dtype=np.float64)
    return {"sin": call(dr.sin), "cos": call(dr.cos), "atan2": call(dr.atan2), "acos": call(dr.acos),
            "pow": call(dr.power)}


def _jax():
    import jax
    import jax.numpy as jnp

    def call(f):
        jitted = jax.jit(f)

        def run(*args):
            with jax.enable_x64(True):
                return np.asarray(jitted(*(jnp.asarray(a, dtype=jnp.float64) for a in args)))
        return run
    return {"sin": call(jnp.sin), "cos": call(jnp.cos), "atan2": call(jnp.arctan2), "acos": call(jnp.arccos),
            "pow": call(jnp.power)}


_MAKERS = {"numba": _numba, "numpy": _numpy, "drjit": _drjit, "jax": _jax}


@lru_cache(maxsize=None)
def _functions(name):
    return _MAKERS[name]()


def available():
    """The names of `BACKENDS` this machine runs (tuple of str, in that order): all but
    ``drjit`` always; ``drjit`` where `renderer.backends.drjit_llvm` is not None."""
    return tuple(name for name in BACKENDS if _functions(name) is not None)


def backend(name):
    """The five functions of backend ``name``: a dict {function name: callable} over `FUNCTIONS`.

    Each callable takes 1-D float64 arrays of one length (one for sin, cos, acos; two for
    atan2 (y, x) and pow (base, exponent)) and returns a new 1-D float64 array of that
    length, computed by the backend (radians for angles).

    Raises
    ------
    renderer.validate.InvalidType
        ``name`` is not a string.
    renderer.validate.InvalidValue
        ``name`` is not one of `BACKENDS`, or it is ``"drjit"`` and this machine has no
        Dr.Jit LLVM backend (`available`).
    """
    name = choice("backend", name, BACKENDS)
    functions = _functions(name)
    if functions is None:
        from renderer.backends import missing
        why = missing("drjit") or "Dr.Jit's LLVM backend did not load"
        raise InvalidValue(f"backend 'drjit' is not available on this machine ({why}); "
                           f"available: {', '.join(available())}")
    return functions


# ---------------------------------------------------------------- arguments
def arguments(function, count=SAMPLES, seed=SEED):
    """Arguments of ``function`` over the range the render kernel uses it on.

    ``count`` seeded random points (``numpy.random.default_rng(seed)``) followed by the
    hard points:

    * sin, cos: x = pi k u (u, v in [0, 1], k in (0, 1e3]; 2 pi k v for rings), uniform on
      [0, `max_angle`]; hard points: the float64 multiples m pi / 2 up to it and their
      neighbours either side, where one of the two is near 0 and the range reduction must
      keep the digits.
    * atan2 (y, x): the chart's two calls atan2(N_y, N_x) and atan2(sin phi, N_z), N a
      unit vector uniform on the sphere (half the sample each); hard points: the seam
      atan2(+-2^-j, -1) near +-pi and the pole atan2(2^-j, +-1), j = 1 .. 60.
    * acos: x uniform on [-1, 1]; hard points: 1 - j 2^-53 and -1 + j 2^-53, j = 0 .. 999.
    * pow (base, exponent): exponent log-uniform on the accepted shininess [1, 1e4], base
      uniform on [0, 1] where the power is a normal float64 (above 2^`MIN_POWER_LOG2`;
      `flushes` looks below); hard points: bases 1 - 2^-j (j = 1 .. 53) and 0.999 with
      every exponent of a log-spaced grid over [1, 1e4] (those with a normal power).

    Returns
    -------
    tuple of 1-D float64 arrays, one per argument (1 or 2), of one length (``count`` plus
    the hard points), and the number of hard points at the end (int): ``(args, hard)``.

    Raises
    ------
    renderer.validate.InvalidType
        ``function`` is not a string, ``count`` or ``seed`` not an integer (a bool, a float).
    renderer.validate.InvalidValue
        ``function`` is not one of `FUNCTIONS`, ``count`` not in [1, 2**24], ``seed`` not in
        [0, 2**64 - 1].
    """
    function = choice("function", function, FUNCTIONS)
    count = positive_int("count", count, high=MAX_COUNT)
    rng = np.random.default_rng(_seed("seed", seed))
    if function in ("sin", "cos"):
        top = max_angle()
        m = np.arange(1, int(top / (math.pi / 2)) + 1) * (math.pi / 2)
        hard = np.concatenate([m, np.nextafter(m, 0.0), np.nextafter(m, np.inf)])
        return (np.concatenate([rng.uniform(0.0, top, count), hard]),), hard.size
    if function == "atan2":
        N = rng.normal(size=(count, 3))
        N /= np.linalg.norm(N, axis=1, keepdims=True)
        half = count // 2
        y = np.concatenate([N[:half, 1], np.hypot(N[half:, 0], N[half:, 1])])
        x = np.concatenate([N[:half, 0], N[half:, 2]])
        tiny = 2.0 ** -np.arange(1.0, 61.0)
        hy = np.concatenate([tiny, -tiny, tiny, tiny])
        hx = np.concatenate([-np.ones(60), -np.ones(60), np.ones(60), -np.ones(60)])
        return (np.concatenate([y, hy]), np.concatenate([x, hx])), hy.size
    if function == "acos":
        j = np.arange(1000) * 2.0**-53
        hard = np.concatenate([1.0 - j, -1.0 + j])
        return (np.concatenate([rng.uniform(-1.0, 1.0, count), hard]),), hard.size
    # Bases whose power is a normal float64 (>= 2^-1022, `MIN_POWER_LOG2` with a margin):
    # below it lies a specular term no pixel shows, where some backends flush to zero (`flushes`).
    exponent = np.exp(rng.uniform(math.log(MIN_SHININESS), math.log(MAX_SHININESS), count))
    base = rng.uniform(2.0 ** (MIN_POWER_LOG2 / exponent), 1.0)
    hb, he = (a.ravel() for a in np.meshgrid(np.append(1.0 - 2.0 ** -np.arange(1.0, 54.0), 0.999),
                                             np.geomspace(MIN_SHININESS, MAX_SHININESS, 41)))
    keep = he * np.log2(hb) > MIN_POWER_LOG2
    return (np.concatenate([base, hb[keep]]), np.concatenate([exponent, he[keep]])), int(keep.sum())


def flushes(name):
    """Does backend ``name`` flush a subnormal result to zero?  pow(0.5, 1070) = 2^-1070 is a
    float64 (a subnormal one); True where the backend's pow returns 0 for it (bool).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``name`` as `backend` refuses it.
    """
    return bool(backend(name)["pow"](np.array([0.5]), np.array([1070.0]))[0] == 0.0)


# ---------------------------------------------------------------- reference
#: mpmath's functions on its raw numbers (mpf tuples; `mpmath.libmp`), each called with a precision in
#: bits and a rounding mode: the functions mpmath.sin etc. call, without their conversions and objects
#: (the references about 1.5 times as fast, bit for bit the same; tests/test_fastmath.py holds them
#: against mpmath.sin etc. at 60 digits).
_LIBMP = {"sin": libmp.mpf_sin, "cos": libmp.mpf_cos, "atan2": libmp.mpf_atan2, "acos": libmp.mpf_acos,
          "pow": libmp.mpf_pow}


def reference(function, *args):
    """The true value of ``function`` at float64 arguments, held as (hi, exponent, rest).

    Parameters
    ----------
    function : one of `FUNCTIONS`
    *args : 1-D arrays of finite real numbers, of one length (as `backend`'s functions take
        them): one for sin, cos and acos, two for atan2 (y, x) and pow (base, exponent)

    Returns
    -------
    hi : float64 array
        The true value t rounded to nearest (the correctly rounded result).
    exponent : int64 array
        e with ulp(t) = 2^e: 2^(floor(log2 |t|) - 52), or 2^-1074 below the normal range.
    rest : float64 array
        (t - hi) / ulp(t), in [-0.5, 0.5]: the part of t that hi leaves out, in ulps
        (rounded once, an error below 2^-54 ulp).

    Raises
    ------
    renderer.validate.InvalidType
        ``function`` is not a string; an argument is not real numbers (a bool, a string).
    renderer.validate.InvalidValue
        ``function`` is not one of `FUNCTIONS`; not as many arguments as it takes; an argument
        not finite (named ``args[i]``); the arguments not 1-D of one length.
    """
    function = choice("function", function, FUNCTIONS)
    args = [real_array(f"args[{i}]", a) for i, a in enumerate(args)]
    if any(a.ndim != 1 or a.shape != args[0].shape for a in args):
        raise InvalidValue(f"args must be 1-D arrays of one length, got shapes {[a.shape for a in args]}")
    arity = 2 if function in ("atan2", "pow") else 1
    if len(args) != arity:
        raise InvalidValue(f"args must be {arity} array(s) for {function}, got {len(args)}")
    return _reference(function, *args)


def _reference(function, *args):
    f, prec = _LIBMP[function], libmp.dps_to_prec(DIGITS)
    n = args[0].size
    hi, rest, exponent = np.empty(n), np.empty(n), np.empty(n, dtype=np.int64)
    for i, point in enumerate(zip(*(a.tolist() for a in args))):
        t = f(*map(libmp.from_float, point), prec, libmp.round_nearest)
        hi[i] = libmp.to_float(t, rnd=libmp.round_nearest)
        # t = man 2^exp with a man of bc bits: 2^(exp + bc - 1) <= |t| < 2^(exp + bc).
        e = exponent[i] = -1074 if t == libmp.fzero else max(t[2] + t[3] - 1, -1022) - 52
        below = libmp.mpf_sub(t, libmp.from_float(hi[i]), prec, libmp.round_nearest)     # t - hi
        rest[i] = libmp.to_float(libmp.mpf_shift(below, -e), rnd=libmp.round_nearest)
    return hi, exponent, rest


def ulps(values, hi, exponent, rest):
    """|values - t| / ulp(t) for the true values t = (hi, exponent, rest) of `reference`.

    values - hi is exact wherever values is within a factor 2 of hi (Sterbenz), so the
    count is exact but for the one rounding of ``rest`` and of the final subtraction (an
    error below 2^-52 ulp for counts below 1); far off it is within a relative 2^-53.
    Returns a float64 array of the common shape (inf where a count exceeds the float64
    range, a value far from a subnormal t; NaN where ``values`` is NaN).

    ``values``: real numbers (inf and NaN allowed: what is judged); ``hi``: finite real numbers;
    ``exponent``: integers in [-1074, 971]; ``rest``: real numbers in [-0.5, 0.5]; all
    broadcasting together.  Raises InvalidType (not real numbers, ``exponent`` not integers)
    or InvalidValue (out of range, not broadcasting) naming the argument.
    """
    values, hi, exponent, rest = broadcast(("values", "hi", "exponent", "rest"), numbers_array("values", values),
                                           real_array("hi", hi), integers("exponent", exponent, -1074, 971),
                                           real_array("rest", rest, low=-0.5, high=0.5))
    return _ulps(values, hi, exponent, rest)


def _ulps(values, hi, exponent, rest):
    values = np.asarray(values, dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        d = values - hi
        # Scaled by 2^-e in two halves: 2^1074 itself is not a float64.
        half = exponent // 2
        return np.abs(np.ldexp(np.ldexp(d, -half), -(exponent - half)) - rest)


def _summary(err, hard):
    sample = err[:err.size - hard]
    return {"max": float(sample.max()), "quantile": float(np.quantile(sample, QUANTILE)),
            "hard_max": float(err[err.size - hard:].max()) if hard else float("nan"),
            "points": int(sample.size), "hard_points": int(hard)}


def _versions():
    from importlib.metadata import version
    packages = {"numba": "numba", "numpy": "numpy", "drjit": "drjit", "jax": "jax"}
    return {name: version(packages[name]) for name in available()}


def ulp_table(count=SAMPLES, seed=SEED):
    """The ulp error of each available backend's functions, one measurement of the build (`lab.store`).

    Returns
    -------
    dict
        ``{"backends": [names available, `BACKENDS` order], "missing": [the others],
        "quantile": QUANTILE, "digits": DIGITS, "errors": {backend: {function: {"max",
        "quantile", "hard_max", "points", "hard_points"}}, "flushes": {backend: bool}}``:
        over the ``count`` sampled points of `arguments`, the largest ulp error and its
        ``QUANTILE`` quantile; over its hard points, the largest (floats, ulps; counts as
        ints); whether the backend flushes subnormal results to zero (`flushes`).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``count`` or ``seed`` as `arguments` refuses them.
    """
    from .store import measured
    return measured("fastmath.ulps", _ulp_table, count=positive_int("count", count, high=MAX_COUNT),
                    seed=_seed("seed", seed), versions=_versions())


def _ulp_table(count, seed, versions):
    names = list(versions)
    errors = {name: {} for name in names}
    for function in FUNCTIONS:
        args, hard = arguments(function, count, seed)
        true = _reference(function, *args)
        for name in names:
            errors[name][function] = _summary(_ulps(backend(name)[function](*args), *true), hard)
    return {"backends": names, "missing": [b for b in BACKENDS if b not in names], "quantile": QUANTILE,
            "digits": DIGITS, "errors": errors, "flushes": {name: flushes(name) for name in names}}


# ------------------------------------------------------------- the U-curve
def _quotient(sin):
    """The sine field's central difference h_u as renderer/generated.py computes it, as a
    numpy function of (u, v, k_u, k_v, eps) with ``sin`` as the sine: the stencil points
    of `renderer.formulas.STENCIL_POINTS` and the quotient of `renderer.formulas.HeightField.central`
    through the same common subexpressions (sympy.cse) and so the same operations."""
    points = dict(F.STENCIL_POINTS)
    plus, minus = (sp.lambdify((F.u, F.eps_u), points[p], modules="numpy") for p in (F.u_p, F.u_m))
    args = (F.u_p, F.u_m, F.u, F.v, F.k_u, F.k_v, F.eps_u)
    quotient = sp.lambdify(args, F.FIELDS["sine"].central[0], modules=[{"sin": sin}, "numpy"], cse=True)

    def h_u(u, v, k_u, k_v, eps):
        eps = np.asarray(eps, dtype=np.float64)
        full = lambda x: np.full_like(eps, x)  # noqa: E731
        return quotient(plus(u, eps), minus(u, eps), full(u), full(v), full(k_u), full(k_v), eps)
    return h_u


def central_differences(name, eps, u, v, k_u, k_v):
    """The sine field's central difference h_u at (u, v) for each step of ``eps``, with
    backend ``name``'s sine (`backend`) and otherwise the renderer's operations.

    Parameters
    ----------
    name : one of `available`
    eps : array_like of float in [1e-300, 1), steps (chart units; u + eps wraps past 1)
    u, v : float in [0, 1]; k_u, k_v : float in (0, 1e3]

    Returns
    -------
    float64 array of eps's shape (height per chart unit).  With ``"numba"`` these are
    the bits of `renderer.pointwise.central_gradient` (tests/test_fastmath.py checks it).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``name`` as `backend` refuses it; ``eps`` (any entry), ``u``, ``v``, ``k_u`` or ``k_v``
        not a real number (a bool, a string) or outside its range (0, NaN, inf), naming it.
    """
    sin = backend(name)["sin"]
    eps = real_array("eps", eps, **STEP)
    u, v = real("u", u, **UNIT), real("v", v, **UNIT)
    return _quotient(sin)(u, v, real("k_u", k_u, **FREQUENCY), real("k_v", k_v, **FREQUENCY), eps)


def floors():
    """The U-curve's roundoff floor with each available backend's sine, one measurement of the
    build (`lab.store`).

    At the book's U-curve (`lab.accuracy.optima`'s sine field: h_u at its point, the seed's
    frequencies, `renderer.ucurve.DEFAULT_STEPS`),
    the central difference `central_differences` with each backend's sine, its error
    against the true derivative (mpmath, 50 digits) at every step.

    Raises
    ------
    RuntimeError
        `lab.accuracy.optima`'s sine curve is no longer h_u over the default steps.

    Returns
    -------
    dict
        ``{"backends": [...], "missing": [...], "u", "v", "k_u", "k_v", "steps": int,
        "model": {"step": eps*, "error": E(eps*), "roundoff": the model's rounding
        coefficient u_round (|h| + |u h_u|)} (`renderer.ucurve.UCurve`), "floors": {backend:
        {"error": the least error over the steps, "step": the step attaining it,
        "fitted_step", "fitted_error", "fitted_roundoff": the optimum and the coefficient B
        of A eps^2 + B / eps fitted to the curve (`renderer.ucurve.fit_model`), "differ":
        how many steps give other bits than the numba (libm) quotient}}}``; steps in chart
        units, errors in height per chart unit, B in height.
    """
    from .store import measured
    return measured("fastmath.floors", _floors, versions=_versions())


def _floors(versions):
    from renderer.ucurve import DEFAULT_STEPS, fit_model

    from .accuracy import optima
    o = optima()["sine"]                   # the book's U-curve: its point and the error model's optimum
    u, v, k_u, k_v = o["u"], o["v"], o["k_u"], o["k_v"]
    if o["component"] != "u" or o["steps"] != DEFAULT_STEPS.size:
        raise RuntimeError(f"the sine field's U-curve is no longer h_u over the default steps: {o}")
    roundoff = o["model_roundoff"]                     # the error model's B (renderer.formulas.ERROR_MODEL)
    true = sp.lambdify((F.u, F.v), F.FIELDS["sine"].gradient[0].subs({F.k_u: sp.nsimplify(k_u),
                                                                 F.k_v: sp.nsimplify(k_v)}), modules="mpmath")
    out, libm = {}, _quotient(backend("numba")["sin"])(u, v, k_u, k_v, DEFAULT_STEPS)
    with mpmath.workdps(DIGITS):
        t = true(mpmath.mpf(u), mpmath.mpf(v))
        for name in versions:
            fd = _quotient(backend(name)["sin"])(u, v, k_u, k_v, DEFAULT_STEPS)
            error = np.array([float(abs(mpmath.mpf(float(y)) - t)) for y in fd])
            best = int(np.argmin(error))
            A, B = fit_model(DEFAULT_STEPS, error, start=(o["model_truncation"], roundoff))
            fitted = (B / (2 * A)) ** (1 / 3)
            out[name] = {"error": float(error[best]), "step": float(DEFAULT_STEPS[best]), "fitted_step": fitted,
                         "fitted_error": A * fitted**2 + B / fitted, "fitted_roundoff": B,
                         "differ": int(np.count_nonzero(fd != libm))}
    return {"backends": list(versions), "missing": [b for b in BACKENDS if b not in versions], "u": u, "v": v,
            "k_u": k_u, "k_v": k_v, "steps": int(DEFAULT_STEPS.size),
            "model": {"step": o["eps_model"], "error": o["error_model"], "roundoff": roundoff}, "floors": out}
