"""Image-wide accuracy of the gradients and of the perturbed normal's
beta-derivative, against mpmath references.

Working precision 50 digits: the references' own error is far below the
float64 quantities they judge.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

from renderer import DRAFT_SCENE, Scene, gbuffer, pointwise, render
from renderer import formulas as F
from renderer.ledger import CURVE_LOG_EPS
from renderer.render import SPHERE_A
from renderer.scene import FREQUENCY, MAX_BETA, UNIT
from renderer.validate import InvalidValue, choice, positive_int, real, real_array, steps as _steps

from ._checks import MAX_COUNT, MAX_SQUARE, STEP, broadcast, seed as _seed


__all__ = ["GradientAccuracy", "gradient_accuracy", "normal_beta_derivative_residual",
           "image_beta_order", "optima", "measure_optimum", "crease_distance", "crease_share", "image_best_step", "frame_model_step", "footprint_steps",
           "footprint_median", "OPTIMUM_POINTS",
           "DIGITS", "HALF_DECADES"]

DIGITS = 50
STEPS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


@dataclass(frozen=True)
class GradientAccuracy:
    """Errors of one pipeline's gradient over sampled sphere-A pixels (both components)."""

    field: str
    method: str            # "exact" or "central eps=..."
    pixels: int
    max_abs: float
    rms_abs: float
    max_ulps: float        # |error| / spacing(formulas.gradient_scale(k_u, k_v)), the gradient's scale
    rms_ulps: float


@lru_cache(maxsize=None)
def _reference(field, ku, kv):
    # First derivatives carry sign(.) but no DiracDelta: usable as they are.
    exprs = [g.subs({F.k_u: sp.nsimplify(ku), F.k_v: sp.nsimplify(kv)}) for g in field.gradient]
    return sp.lambdify((F.u, F.v), exprs, modules="mpmath")


def _sample(scene, size, count, seed):
    g = gbuffer(scene, size, size)
    uv = g.uv[g.chamber == SPHERE_A]
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(uv), size=min(count, len(uv)), replace=False)
    return uv[pick, 0].copy(), uv[pick, 1].copy()


def gradient_accuracy(field, *, count=2000, size=256, seed=4, steps=STEPS, k_u=None, k_v=None):
    """Accuracy of the exact and the central gradient at ``count`` sphere-A pixels.

    ``field`` is a height field as `renderer.formulas.field` takes it; ``k_u``, ``k_v`` default
    to the draft's.  Pixels where a crease factor of the field is within 1e-9 of 0 are excluded
    (the sign there depends on the last bit of the float64 factor, and the derivative does not
    exist).

    Parameters
    ----------
    field : height field
    count : int in [1, 2**24], keyword-only
        Pixels sampled (all of sphere A's where it has fewer).
    size : int in [1, 4096], keyword-only
        Frame side in pixels.
    seed : int in [0, 2**64 - 1], keyword-only
        Seed of the pixel sample.
    steps : sequence of float in [1e-300, 1), keyword-only
        The central difference's steps (chart units), 1 to 64 of them.
    k_u, k_v : float in (0, 1e3] or None, keyword-only

    Returns
    -------
    list of GradientAccuracy: the exact pipeline first, then one per step.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: not of its kind (a bool, a string where a number is meant) or
        outside its range.
    """
    field = F.field(field, "field")
    count = positive_int("count", count, high=MAX_COUNT)
    size = positive_int("size", size, high=MAX_SQUARE)
    seed = _seed("seed", seed)
    steps = _steps("steps", steps, **STEP, max_count=64).tolist()
    k_u = real("k_u", DRAFT_SCENE.k_u if k_u is None else k_u, **FREQUENCY)
    k_v = real("k_v", DRAFT_SCENE.k_v if k_v is None else k_v, **FREQUENCY)
    scene = Scene(height_field=field, k_u=k_u, k_v=k_v)
    uu, vv = _sample(scene, size, count, seed)
    for factor in field.crease_factors:
        keep = np.abs(sp.lambdify(F.FIELD_SYMBOLS, factor, modules="numpy")(uu, vv, *np.float64([k_u, k_v]))) > 1e-9
        uu, vv = uu[keep], vv[keep]
    ref_fn = _reference(field, k_u, k_v)
    with mpmath.workdps(DIGITS):
        ref = [[mpmath.mpf(x) for x in ref_fn(mpmath.mpf(a), mpmath.mpf(b))] for a, b in zip(uu, vv)]

    def summarize(method, hu, hv):
        with mpmath.workdps(DIGITS):
            err = np.array([[float(abs(mpmath.mpf(float(a)) - r[0])), float(abs(mpmath.mpf(float(b)) - r[1]))]
                            for a, b, r in zip(hu, hv, ref)])
        # In units of the float64 spacing at the gradient's natural scale (`formulas.gradient_scale`):
        # the spacing of each reference value would inflate wherever it passes near 0.
        ulps = err / np.spacing(F.gradient_scale(k_u, k_v, field))
        return GradientAccuracy(field.name, method, len(uu), float(err.max()), float(np.sqrt((err**2).mean())),
                                float(ulps.max()), float(np.sqrt((ulps**2).mean())))

    # Through the module attribute, so that a test can put a wrong gradient there.
    out = [summarize("exact", *pointwise.exact_gradient(field, uu, vv, k_u, k_v))]
    for eps in steps:
        out.append(summarize(f"central eps={eps:.0e}", *pointwise.central_gradient(field, uu, vv, k_u, k_v, eps)))
    return out


def normal_beta_derivative_residual(trials=2000, seed=5):
    """Worst |float64 (I - N'N'^T) g / |M| - dN'/dbeta| over random (N, frame, gradient, beta), a float:
    the closed form the theorem normal-beta-derivative proves, evaluated in float64 (numpy).

    The reference is mpmath's numerical derivative of the renderer's N'(beta) = M / |M| at 50
    digits (mpmath.diff), independent of the closed form.  One measurement of
    the build (`lab.store`): §5, §6 and the claims register show the same value.
    ``trials``: an int in [1, 2**24]; ``seed``: an int in [0, 2**64 - 1] (InvalidType or
    InvalidValue naming the argument otherwise).
    """
    from .store import measured
    return measured("normal-beta-derivative-residual", _normal_beta_derivative_residual,
                    trials=positive_int("trials", trials, high=MAX_COUNT), seed=_seed("seed", seed))


@lru_cache(maxsize=None)
def _normal_and_derivative():
    """The renderer's chart-mode normal N' (`renderer.formulas.PERTURBED_NORMAL`) as three mpmath functions,
    one per component, and the closed form the theorem normal-beta-derivative proves of it,
    (I - N'N'^T) g / |M|, as a numpy one to a list of three components: each of (N, e_theta, e_phi,
    h_u, h_v, beta)."""
    from proofs import normal, registry
    theorem = registry.get("normal-beta-derivative")
    args = (F.N_x, F.N_y, F.N_z, *F.e_theta, *F.e_phi, F.h_u, F.h_v, F.beta)
    return (tuple(sp.lambdify(args, c, "mpmath") for c in normal.N_PRIME),
            sp.lambdify(args, list(theorem.explicit(normal.CLAIMED_DERIVATIVE)), "numpy"))


def _normal_beta_derivative_residual(trials, seed):
    normal, closed = _normal_and_derivative()
    rng = np.random.default_rng(seed)
    worst = 0.0
    with mpmath.workdps(DIGITS):
        for _ in range(trials):
            N = rng.normal(size=3)
            N /= np.linalg.norm(N)
            frame, gradient = rng.normal(size=6), rng.normal(size=2) * 2.0
            b = float(rng.uniform(0.0, 2.0))
            given = [float(x) for x in (*N, *frame, *gradient)]
            derivative = closed(*given, b)                                  # float64
            for k in range(3):
                ref = mpmath.diff(lambda beta: normal[k](*given, beta), mpmath.mpf(b))
                worst = max(worst, float(abs(mpmath.mpf(float(derivative[k])) - ref)))
    return worst


def image_beta_order(size=64, beta=None, steps=(1e-1, 5e-2, 2e-2, 1e-2, 5e-3, 2e-3)):
    """`_image_beta_order` (``beta`` None: the draft's), one measurement of the build (`lab.store`;
    arrays come back as lists).

    ``size``: an int in [1, 4096] (pixels); ``beta``: a float in [0, 100] or None; ``steps``:
    2 to 64 steps db in (0, 100] with beta +- db in [0, 100] (the scenes rendered).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: not of its kind or outside its range; ``steps`` fewer than two
        (a slope needs two) or reaching outside [0, 100] from ``beta``.
    """
    from .store import measured
    size = positive_int("size", size, high=MAX_SQUARE)
    beta = real("beta", DRAFT_SCENE.beta if beta is None else beta, low=0.0, high=MAX_BETA)
    steps = _steps("steps", steps, low=MIN_DB, high=MAX_BETA, max_count=64).tolist()
    if len(steps) < 2 or not (0.0 <= beta - max(steps) and beta + max(steps) <= MAX_BETA):
        raise InvalidValue(f"steps must be 2 or more steps db with beta +- db in [0, {MAX_BETA:g}] (beta = {beta!r}), "
                           f"got {steps!r:.80}")
    return measured("image-beta-order", _image_beta_order, size=size, beta=beta, steps=steps)


def _image_beta_order(size, beta, steps):
    """Convergence order of the image's central beta-derivative, fitted from renders.

    For each step db, D(db) = (I(beta + db) - I(beta - db)) / (2 db) on the
    sine field; the reference is Richardson's extrapolation of D(db_min) and D(db_min / 2)
    (`proofs.finite_difference.richardson`: (4 D(db_min / 2) - D(db_min)) / 3).
    Over sphere-A pixels, the median and the RMS of |D - ref| are fitted
    against db on log-log axes.  The image is not smooth in beta everywhere:
    where a max(0, .) of Lambert or the lobe, or the clip to [0, 1], switches
    within +/- db, the quotient converges at first order or not at all, and
    those pixels dominate the RMS.

    Returns
    -------
    dict with "median_slope", "rms_slope", "median_errors", "rms_errors", "steps", and
    "scene" (`renderer.Scene.changes`) and "size", the frame's side in pixels.
    """
    scene = DRAFT_SCENE.replace(height_field="sine", beta=beta)   # the draft's scene: its chart normal

    def D(db):
        hi = render(scene.replace(beta=beta + db), size, size).image
        lo = render(scene.replace(beta=beta - db), size, size).image
        return (hi - lo) / (2 * db)

    mask = render(scene, size, size).chamber == SPHERE_A
    h = min(steps)
    from proofs.finite_difference import richardson
    ref = richardson(coarse=D(h), fine=D(h / 2))
    diffs = [np.abs(D(db) - ref)[mask] for db in steps]
    median = np.array([np.median(d) for d in diffs])
    rms = np.array([np.sqrt(np.mean(d**2)) for d in diffs])
    fit = lambda e: float(np.polyfit(np.log(steps), np.log(e), 1)[0])  # noqa: E731
    return {"median_slope": fit(median), "rms_slope": fit(rms), "median_errors": median.tolist(),
            "rms_errors": rms.tolist(), "steps": list(steps), "scene": scene.changes(), "size": size}


#: Smallest step db of `image_beta_order` (β units): a render's β must differ from its neighbour's.
MIN_DB = 1e-12
#: The steps and frame of `crease_share` (the draft's Cell 3 census: its steps, 256 x 256).
CREASE_STEPS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6)
CREASE_SIZE = 256
#: How far `crease_distance` looks along u and v (chart units), and its samples on each side.
CREASE_REACH, CREASE_SAMPLES = 0.25, 64


def __getattr__(name):
    # OPTIMUM_POINTS: each registered field's `HeightField.optimum_at`, read from the records at each
    # access (verify/test_accuracy.py reads them by this name).
    if name == "OPTIMUM_POINTS":
        return {f.name: f.optimum_at for f in F.FIELDS.values()}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def crease_distance(u, v, k_u, k_v, field=None, along=None):
    """Chart distance from (u, v) to the nearest crease of a height field along u or along v (or
    along ``along`` alone): a central difference with a larger step straddles one (its stencil
    reaches u +- eps, v +- eps; one quotient's, ``along`` +- eps only).

    A crease is a sign change of one of the field's crease factors
    (`renderer.formulas.HeightField.crease_factors`).  Along each chart direction a factor depends
    on, it is sampled at `CREASE_SAMPLES` points on each side out to `CREASE_REACH`, and the first
    sign change is bracketed there and located to float64 precision
    (`scipy.optimize.elementwise.find_root`): two sign changes closer together than the samples
    (``CREASE_REACH / CREASE_SAMPLES``) may be missed.

    Parameters
    ----------
    u, v : float or array_like in [0, 1], broadcast together
        Chart coordinates.
    k_u, k_v : float in (0, 1e3]
    field : height field or None
        As `renderer.formulas.field` takes it; None for the draft's (`renderer.DRAFT_SCENE`).
    along : "u", "v" or None
        The one chart direction searched (a single quotient, D_u h or D_v h); None for both.

    Returns
    -------
    float64 array of the broadcast shape (chart units); ``inf`` where no crease lies within
    `CREASE_REACH` (for a field without creases, everywhere).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: ``u``, ``v`` not real numbers in [0, 1] or not broadcasting
        together; ``k_u``, ``k_v`` not real numbers in (0, 1e3]; ``field`` refused; ``along``
        not "u", "v" or None.
    """
    record = DRAFT_SCENE.field if field is None else F.field(field, "field")
    directions = (True, False) if along is None else (choice("along", along, ("u", "v")) == "u",)
    u, v = broadcast(("u", "v"), real_array("u", u, **UNIT), real_array("v", v, **UNIT))
    return _crease_distance(u, v, real("k_u", k_u, **FREQUENCY), real("k_v", k_v, **FREQUENCY), record,
                            along=directions)


def _crease_distance(u, v, k_u, k_v, record, along=(True, False)):
    """`crease_distance` on validated arrays; ``along``: the directions searched (True: u, False: v)."""
    shape, u, v = u.shape, u.ravel(), v.ravel()
    out = np.full(u.shape, np.inf)
    k_u, k_v = np.float64(k_u), np.float64(k_v)     # numpy's overflow to inf, not Python's OverflowError
    for factor in record.crease_factors:
        g = sp.lambdify((F.u, F.v, F.k_u, F.k_v), factor, modules="numpy")
        for along_u in along:
            if (F.u if along_u else F.v) in factor.free_symbols:
                def g_at(s, at=slice(None), along_u=along_u, g=g):   # s: offsets (n,) or (n, m) at u[at], v[at]
                    uu, vv = (u[at, None], v[at, None]) if np.ndim(s) == 2 else (u[at], v[at])
                    value = g(uu + s, vv, k_u, k_v) if along_u else g(uu, vv + s, k_u, k_v)
                    return np.broadcast_to(value, np.shape(s))
                out = np.minimum(out, _sign_change(g_at, u.size))
    return out.reshape(shape)


def _sign_change(g_at, n):
    """The least |s| <= `CREASE_REACH` at which g_at(s) differs in sign from g_at(0), for each of
    n points (``g_at(s, at)``: offsets s of shape (n,) or (n, m), or at the points of the index
    array ``at``); 0 where g_at(0) is 0, inf where the sign does not change."""
    from scipy.optimize.elementwise import find_root
    sign0 = np.sign(g_at(np.zeros(n)))
    best = np.where(sign0 == 0, 0.0, np.inf)
    grid = np.linspace(0.0, CREASE_REACH, CREASE_SAMPLES + 1)
    for side in (1.0, -1.0):
        changed = np.sign(g_at(np.broadcast_to(side * grid[1:], (n, CREASE_SAMPLES)))) != sign0[:, None]
        found = np.flatnonzero(changed.any(axis=1) & (sign0 != 0))
        if found.size:
            first = changed[found].argmax(axis=1)       # the first sample past the first sign change
            # find_root passes the points still iterating with their index (its args are subset alike).
            root = find_root(lambda s, at: g_at(side * s, at), (grid[first], grid[first + 1]), args=(found,)).x
            best[found] = np.minimum(best[found], root)
    return best


def optima():
    """The optimum of the central difference for each registered height field, one measurement of
    the build (`lab.store`).

    For each field at its point (`renderer.formulas.HeightField.optimum_at`), the curve of
    `renderer.ucurve.measure` over its default steps below the point's distance to the field's
    nearest crease along the component's coordinate, the one direction its stencil moves
    (`crease_distance` along it alone: no stencil of the curve straddles one), with the draft's
    frequencies; a dict of floats (steps in chart units, errors in height per chart unit): ``u``,
    ``v``, ``component``, ``k_u``, ``k_v``, ``steps`` (how many), ``largest_step``,
    ``smallest_step``, ``crease_distance`` (inf for a field without creases); ``h`` = |h|,
    ``h1`` = |h'|, ``x_h1`` = |x h'| (x the component's coordinate), ``h3`` = |h'''|;
    ``model_truncation`` and ``model_roundoff``, the error model's coefficients of eps^2 and 1/eps
    (`renderer.formulas.ERROR_MODEL`: |h'''| / 6 and u_round (|h| + |x h'|));
    ``eps_model`` the model-optimal step eps* and ``error_model`` the model's error E(eps*);
    ``eps_fitted`` the fitted optimal step eps^, ``error_at_fitted`` the fitted model's error there
    and ``measured_at_fitted`` the float64 quotient's measured error at eps^;
    ``fitted_over_model`` = eps^ / eps*; ``argument_share``, the argument-rounding term's share of
    the model's rounding coefficient, |x h'| / (|h| + |x h'|).

    Raises
    ------
    RuntimeError
        A field's point lies so close to a crease that fewer than two default steps are below it.
    """
    from .store import measured
    return measured("ucurve.optima", _optima,
                    fields={f.name: [str(f.expr), list(f.optimum_at)] for f in F.FIELDS.values()})


def _optima(fields):
    return {field: measure_optimum(field, u, v, component) for field, (_, (u, v, component)) in fields.items()}


def measure_optimum(field, u, v, component):
    """What `optima` measures of a field, at any chart point: the dict of one field of `optima` (its keys
    there), measured now, not stored, with the draft's frequencies.  ``field``: a name, a `HeightField`
    or an expression (`renderer.formulas.field`); ``u``, ``v`` in [0, 1]; ``component`` "u" or "v".
    Before registering a field with ``optimum=``, try points here: `pytest verify` holds
    ``measured_at_fitted / error_at_fitted`` within a factor 3.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming the argument: ``field`` refused, ``u`` or ``v`` not a real number in [0, 1],
        ``component`` not "u" or "v", or a direction along which h''' is 0 at the point, or so small that the
        model-optimal step lies past the largest step tried (no optimum to measure).
    RuntimeError
        The point lies so close to a crease that fewer than two default steps are below it.
    """
    from renderer.ucurve import DEFAULT_STEPS, DIGITS, UNIT_ROUNDOFF, measure
    record = F.field(field, "field")
    u, v = (real(name, x, low=0.0, high=1.0) for name, x in (("u", u), ("v", v)))
    component = choice("component", component, ("u", "v"))
    k_u, k_v = DRAFT_SCENE.k_u, DRAFT_SCENE.k_v
    distance = float(_crease_distance(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64),
                                      k_u, k_v, record, along=(component == "u",)))   # where its stencil moves
    steps = DEFAULT_STEPS[DEFAULT_STEPS < distance]
    if steps.size < 2:
        raise RuntimeError(f"the {record.name} field's point ({u}, {v}) is {distance:g} from a crease: fewer "
                           "than two of the default steps lie below that")
    c = measure(record, u, v, component, eps=steps, k_u=k_u, k_v=k_v)
    # h''' = 0, or 0 but for the reference's last digits (sin(pi k_u u)**2 where the sine is 0: below
    # 1e-30 at 50 digits), or so small that the model's optimum lies past every step tried: a fitted
    # step would fit noise.
    zero = abs(c.third_derivative) < 10.0 ** (20 - DIGITS)
    if zero or not c.eps_model < steps.max():
        if zero:
            why = "is 0" + (f" (to the reference's {DIGITS} digits: {abs(c.third_derivative):.3g})"
                            if c.third_derivative else "") + ", so its central difference has no truncation error"
        else:
            why = (f"is {abs(c.third_derivative):.3g}, so small that its model-optimal step ({c.eps_model:.3g}) "
                   f"lies past every step tried (the largest {steps.max():.3g})")
        raise InvalidValue(f"component must be a direction along which h has a third derivative at the point, got "
                           f"{component!r}: the {record.name} field's h''' along {component} at ({u}, {v}) {why}; "
                           "there is no optimal step to measure there")
    at_fitted = float(measure(record, u, v, component, eps=[c.eps_fitted], k_u=k_u, k_v=k_v).error[0])
    return dict(u=u, v=v, component=component, k_u=k_u, k_v=k_v, steps=int(steps.size),
                largest_step=float(steps.max()), smallest_step=float(steps.min()),
                crease_distance=distance, h=abs(c.height), h1=abs(c.derivative),
                x_h1=c.model_argument / UNIT_ROUNDOFF, h3=abs(c.third_derivative),
                model_truncation=c.model_truncation, model_roundoff=c.model_cancellation + c.model_argument,
                eps_model=c.eps_model, error_model=c.error_model, eps_fitted=c.eps_fitted,
                error_at_fitted=c.error_at_fitted, measured_at_fitted=at_fitted,
                fitted_over_model=c.eps_fitted / c.eps_model,
                argument_share=c.model_argument / (c.model_cancellation + c.model_argument))


def crease_share():
    """What the crease does on the ridges field, one measurement of the build (`lab.store`): in
    the draft's scene at `CREASE_SIZE` squared, the share of sphere-A pixels whose stencil
    straddles a crease (chart distance to one below the step, `crease_distance`) at each step
    of `CREASE_STEPS`.  Returns a dict: ``steps``, ``share`` (list of floats in [0, 1], step
    order), ``share_u`` (the same for a crease reached along u alone: on the draft's frame the
    rays u = m/k_u from the pole) and ``pixels`` (sphere-A pixels of the frame)."""
    from .store import measured
    return measured("crease-share", _crease_share, size=CREASE_SIZE, steps=list(CREASE_STEPS))


def _crease_share(size, steps, scene=DRAFT_SCENE):
    g = gbuffer(scene, size, size)
    uv = g.uv[g.chamber == SPHERE_A]
    along_u, along_v = (_crease_distance(uv[:, 0], uv[:, 1], scene.k_u, scene.k_v, scene.field, along=(a,))
                        for a in (True, False))
    dist = np.minimum(along_u, along_v)
    return dict(steps=steps, share=[float(np.mean(dist < eps)) for eps in steps],
                share_u=[float(np.mean(along_u < eps)) for eps in steps], pixels=int(dist.size))


def footprint_steps(scene=None, size=256):
    """The footprint step in u of every sphere-A pixel: the chart distance one pixel covers, which
    ``gradient="footprint"`` takes as its central-difference step (`renderer.pointwise.footprint`,
    pbrt-v4's bump-mapping rule), in ``scene`` (default the book's, `renderer.Scene()`) at ``size`` ×
    ``size`` pixels.  Seed Cell 2's question: which steps does a renderer that sets them from the
    footprint use?

    Returns
    -------
    float64 array (k,)
        Chart units, one per sphere-A pixel of the frame, in row-major pixel order.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``scene`` is not a `renderer.Scene` (`renderer.gbuffer`), or ``size`` is not an integer in [1, 4096].
    """
    scene = Scene() if scene is None else scene
    size = positive_int("size", size, high=MAX_SQUARE)
    geo = gbuffer(scene, size, size)
    on_a = geo.chamber == SPHERE_A
    P, N = geo.P[on_a].T, geo.N[on_a].T
    _, _, sin_phi = pointwise.chart(*N)
    e_theta, e_phi = pointwise.tangent_frame(*N, sin_phi)
    X, Y = np.meshgrid(geo.x, geo.y)
    step_u, _ = pointwise.footprint(X[on_a], Y[on_a], geo.x[1] - geo.x[0], geo.y[0] - geo.y[1], scene.camera_z,
                                    P, N, e_theta, e_phi, scene.radius_a, sin_phi)
    return np.asarray(step_u, dtype=np.float64)


def footprint_median(size=256):
    """The median of `footprint_steps` over the book's scene, `renderer.Scene()`, at ``size`` × ``size``
    pixels: one measurement of the build (`lab.store`), which §3's table of steps and §5's Cell 2 both
    show (seed Cell 2's question; the footprint rule is pbrt-v4's).  A float, chart units.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``size`` is not an integer in [1, 4096].
    """
    from .store import measured
    size = positive_int("size", size)           # a Python int, which the store's JSON holds; too large a
    return measured("footprint-median",         # size is footprint_steps' to refuse
                    lambda size: float(np.median(footprint_steps(size=size))), size=size)


#: The steps of the simulator's U-curve (`renderer.ledger.CURVE_LOG_EPS`), chart units.
HALF_DECADES = tuple(10.0 ** e for e in CURVE_LOG_EPS)


def image_best_step(field, size=256):
    """The image-best step of the simulator's scene (`renderer.ledger.SIMULATOR_SCENE`) with the
    height field ``field``: of the steps `HALF_DECADES`, the one whose central-difference frame has
    the least RMS |ΔI| over sphere A against the exact frame, every pixel of a ``size`` × ``size``
    frame counted; one measurement of the build (`lab.store`).

    Returns
    -------
    dict
        ``best`` (float, chart units), ``steps`` and ``rms`` (lists of floats, one per step, RMS in
        linear colour units), ``scene`` (the fields that differ from `renderer.Scene`'s defaults,
        `renderer.Scene.changes`) and ``size`` ([width, height], pixels).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``field`` is refused by `renderer.formulas.field` (naming ``field``) or by the scene
        (naming ``Scene.height_field``: h or its gradient not finite on the chart), or ``size``
        is not an integer in [1, 4096].
    """
    from renderer.ledger import SIMULATOR_SCENE

    from .store import measured
    record = F.field(field, "field")
    SIMULATOR_SCENE.replace(height_field=record)              # the scene's own refusals
    return measured("image-best-step", _image_best_step, field=record.name,
                    size=positive_int("size", size, high=MAX_SQUARE), steps=list(HALF_DECADES))


def frame_model_step(field, k_u=None, k_v=None, samples=1201):
    """The model-optimal step for a whole frame, per chart direction x (u, then v): §3's
    ε* = (3 u_round C / |h'''|)^{1/3} (`renderer.formulas.EPS_STAR`) with C = |h| + |x h_x| and |h'''|
    (the third derivative along x) at their largest over the chart, each sampled on a ``samples`` ×
    ``samples`` grid of [0, 1]², its edges included.  |h'''| is taken off the creases: the Dirac deltas that
    the derivatives of a field's |.| leave on its kink loci are dropped.  The step a
    renderer without an exact frame can take (§3 compares it with `image_best_step`); the trade-off as in
    Higham, *Accuracy and Stability of Numerical Algorithms*, bounded over the chart.

    Parameters
    ----------
    field : str or renderer.formulas.HeightField
    k_u, k_v : float in (0, 1e3], optional
        Frequencies (default: the simulator's scene's, as `image_best_step` renders).
    samples : int
        Grid points per direction, in [1, 4096].

    Returns
    -------
    dict
        ``{"u": step, "v": step}`` in chart units (float), ``None`` for a direction along which h is
        constant (no truncation to balance).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        ``field`` refused by `renderer.formulas.field`, ``k_u`` or ``k_v`` not a real number in (0, 1e3],
        or ``samples`` not an integer in [1, 4096].
    """
    from renderer.ledger import SIMULATOR_SCENE
    from renderer.ucurve import UNIT_ROUNDOFF
    record = F.field(field, "field")
    k_u = real("k_u", SIMULATOR_SCENE.k_u if k_u is None else k_u, **FREQUENCY)
    k_v = real("k_v", SIMULATOR_SCENE.k_v if k_v is None else k_v, **FREQUENCY)
    n = positive_int("samples", samples, high=4096)
    grid = np.linspace(0.0, 1.0, n)                   # the edges too: C is often largest at u or v = 1
    at = dict(zip((F.u, F.v), np.meshgrid(grid, grid, indexing="ij")))
    h = record.expr.subs({F.k_u: k_u, F.k_v: k_v})
    step = sp.lambdify((F.H, F.HX, F.H3, F.u_round), F.EPS_STAR)

    def largest(expr):
        return float(np.max(np.abs(np.broadcast_to(sp.lambdify((F.u, F.v), expr, "numpy")(at[F.u], at[F.v]),
                                                   at[F.u].shape))))

    out = {}
    for x in (F.u, F.v):
        h3 = largest(sp.diff(h, x, 3).replace(sp.DiracDelta, lambda *a: sp.S.Zero))
        c = largest(sp.Abs(h) + sp.Abs(x * sp.diff(h, x)))     # the largest C itself, not two maxima
        out[str(x)] = float(step(c, 0.0, h3, UNIT_ROUNDOFF)) if h3 > 0 else None
    return out


def _image_best_step(field, size, steps):
    from renderer import sweep
    from renderer.ledger import SIMULATOR_SCENE
    scene = SIMULATOR_SCENE.replace(height_field=field)
    rms = [float(led.rms) for led in sweep(scene, steps, size, size).census]
    return dict(best=steps[int(np.argmin(rms))], steps=steps, rms=rms, scene=scene.changes(), size=[size, size])
