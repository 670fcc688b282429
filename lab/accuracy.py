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
from renderer.render import SPHERE_A


__all__ = ["GradientAccuracy", "gradient_accuracy", "normal_beta_derivative_residual",
           "image_beta_order", "optima", "crease_distance", "crease_share", "image_best_step", "OPTIMUM_POINTS",
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
    max_ulps: float        # |error| / spacing(pi max(k_u, 2 k_v)), the gradient's scale
    rms_ulps: float


@lru_cache(maxsize=None)
def _reference(field, ku, kv):
    # First derivatives carry sign(.) but no DiracDelta: usable as they are.
    exprs = [g.subs({F.k_u: sp.nsimplify(ku), F.k_v: sp.nsimplify(kv)}) for g in F.GRADIENT[field]]
    return sp.lambdify((F.u, F.v), exprs, modules="mpmath")


def _sample(scene, size, count, seed):
    g = gbuffer(scene, size, size)
    uv = g.uv[g.chamber == SPHERE_A]
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(uv), size=min(count, len(uv)), replace=False)
    return uv[pick, 0].copy(), uv[pick, 1].copy()


def gradient_accuracy(field, *, count=2000, size=256, seed=4, steps=STEPS, k_u=8.0, k_v=4.0):
    """Accuracy of the exact and the central gradient at ``count`` sphere-A pixels.

    Pixels within 1e-9 of a ridges crease are excluded (the sign there depends
    on the last bit of the float64 sine, and the derivative does not exist).

    Returns
    -------
    list of GradientAccuracy: the exact pipeline first, then one per step.
    """
    scene = Scene(height_field=field, k_u=k_u, k_v=k_v)
    uu, vv = _sample(scene, size, count, seed)
    if field == "ridges":
        keep = ((np.abs(np.sin(np.pi * k_u * uu)) > 1e-9) & (np.abs(np.sin(np.pi * k_v * vv)) > 1e-9))
        uu, vv = uu[keep], vv[keep]
    ref_fn = _reference(field, k_u, k_v)
    with mpmath.workdps(DIGITS):
        ref = [[mpmath.mpf(x) for x in ref_fn(mpmath.mpf(a), mpmath.mpf(b))] for a, b in zip(uu, vv)]

    def summarize(method, hu, hv):
        with mpmath.workdps(DIGITS):
            err = np.array([[float(abs(mpmath.mpf(float(a)) - r[0])), float(abs(mpmath.mpf(float(b)) - r[1]))]
                            for a, b, r in zip(hu, hv, ref)])
        # In units of the float64 spacing at the gradient's natural scale pi max(k_u, 2 k_v):
        # the spacing of each reference value would inflate wherever it passes near 0.
        ulps = err / np.spacing(np.pi * max(k_u, 2 * k_v))
        return GradientAccuracy(field, method, len(uu), float(err.max()), float(np.sqrt((err**2).mean())),
                                float(ulps.max()), float(np.sqrt((ulps**2).mean())))

    # Through the module attribute, so that a test can put a wrong gradient there.
    out = [summarize("exact", *pointwise.exact_gradient(field, uu, vv, k_u, k_v))]
    for eps in steps:
        out.append(summarize(f"central eps={eps:.0e}", *pointwise.central_gradient(field, uu, vv, k_u, k_v, eps)))
    return out


def normal_beta_derivative_residual(trials=2000, seed=5):
    """Worst |float64 (I - N'N'^T) g / |M| - dN'/dbeta| over random (N, g, beta), a float.

    The reference is mpmath's numerical derivative of N'(beta) = M / |M| at 50
    digits (mpmath.diff), independent of the closed form.  One measurement of
    the build (`lab.store`): §5, §6 and the claims register show the same value.
    """
    from .store import measured
    return measured("normal-beta-derivative-residual", _normal_beta_derivative_residual, trials=trials, seed=seed)


def _normal_beta_derivative_residual(trials, seed):
    rng = np.random.default_rng(seed)
    worst = 0.0
    with mpmath.workdps(DIGITS):
        for _ in range(trials):
            N = rng.normal(size=3)
            N /= np.linalg.norm(N)
            g = rng.normal(size=3) * 4.0
            b = float(rng.uniform(0.0, 2.0))
            M = N + b * g
            Np = M / np.linalg.norm(M)
            closed = (g - Np * (Np @ g)) / np.linalg.norm(M)        # float64
            Nm = [mpmath.mpf(float(x)) for x in N]
            gm = [mpmath.mpf(float(x)) for x in g]

            def comp(k, beta):
                m = [Nm[i] + beta * gm[i] for i in range(3)]
                return m[k] / mpmath.sqrt(sum(x * x for x in m))

            for k in range(3):
                ref = mpmath.diff(lambda beta: comp(k, beta), mpmath.mpf(b))
                worst = max(worst, float(abs(mpmath.mpf(float(closed[k])) - ref)))
    return worst


def image_beta_order(size=64, beta=0.35, steps=(1e-1, 5e-2, 2e-2, 1e-2, 5e-3, 2e-3)):
    """`_image_beta_order`, one measurement of the build (`lab.store`; arrays come back as lists)."""
    from .store import measured
    return measured("image-beta-order", _image_beta_order, size=size, beta=beta, steps=list(steps))


def _image_beta_order(size, beta, steps):
    """Convergence order of the image's central beta-derivative, fitted from renders.

    For each step db, D(db) = (I(beta + db) - I(beta - db)) / (2 db) on the
    sine field; the reference is Richardson's (4 D(db_min / 2) - D(db_min)) / 3.
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
    ref = (4 * D(h / 2) - D(h)) / 3
    diffs = [np.abs(D(db) - ref)[mask] for db in steps]
    median = np.array([np.median(d) for d in diffs])
    rms = np.array([np.sqrt(np.mean(d**2)) for d in diffs])
    fit = lambda e: float(np.polyfit(np.log(steps), np.log(e), 1)[0])  # noqa: E731
    return {"median_slope": fit(median), "rms_slope": fit(rms), "median_errors": median.tolist(),
            "rms_errors": rms.tolist(), "steps": list(steps), "scene": scene.changes(), "size": size}


#: Where `optima` measures each field's U-curve, with the seed's frequencies (k_u, k_v) = (8, 4):
#: (u, v, component).  The seed's sine point; ridges at the same point, whose distance to every
#: crease line (u = m / k_u, v = m / k_v) exceeds `RIDGES_LARGEST_STEP` (no stencil of the curve
#: straddles a crease; `optima` checks it); rings in v, since its h_u is 0 everywhere.
OPTIMUM_POINTS = {"sine": (0.31, 0.47, "u"), "ridges": (0.31, 0.47, "u"), "rings": (0.31, 0.47, "v")}
#: The ridges curve's largest step (chart units): the default steps up to it.
RIDGES_LARGEST_STEP = 1e-2
#: The steps and frame of `crease_share` (the draft's Cell 3 census: its steps, 256 x 256).
CREASE_STEPS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6)
CREASE_SIZE = 256


def crease_distance(u, v, k_u, k_v):
    """Chart distance from (u, v) to the nearest crease line of the ridges field, u = m / k_u or
    v = m / k_v (m an integer): a central difference with a step beyond it straddles a crease.
    ``u``, ``v``: floats or arrays of one shape (chart units); ``k_u``, ``k_v`` > 0.  Returns
    float64 of that shape."""
    u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
    return np.minimum(np.abs(u * k_u - np.rint(u * k_u)) / k_u, np.abs(v * k_v - np.rint(v * k_v)) / k_v)


def optima():
    """The optimum of the central difference for each height field, one measurement of the
    build (`lab.store`).

    For each field at its point of `OPTIMUM_POINTS` (curve of `renderer.ucurve.measure` over
    its default steps; on ridges those up to `RIDGES_LARGEST_STEP`), a dict of floats (steps
    in chart units, errors in height per chart unit): ``u``, ``v``, ``component``, ``k_u``,
    ``k_v``, ``steps`` (how many), ``largest_step``, ``smallest_step``; ``h`` = |h|,
    ``h1`` = |h'|, ``x_h1`` = |x h'| (x the component's coordinate), ``h3`` = |h'''|;
    ``eps_model`` the model-optimal step eps* and ``error_model`` the model's error E(eps*);
    ``eps_fitted`` the fitted optimal step eps^, ``error_at_fitted`` the fitted model's error
    there and ``measured_at_fitted`` the float64 quotient's measured error at eps^;
    ``fitted_over_model`` = eps^ / eps*; ``argument_share``, the argument-rounding term's
    share of the model's rounding coefficient, |x h'| / (|h| + |x h'|).  The ridges entry
    also holds ``crease_distance``, its point's (`crease_distance`).

    Raises
    ------
    RuntimeError
        The ridges point is within `RIDGES_LARGEST_STEP` of a crease.
    """
    from .store import measured
    return measured("ucurve.optima", _optima, points=OPTIMUM_POINTS, ridges_largest=RIDGES_LARGEST_STEP)


def _optima(points, ridges_largest):
    from renderer.ucurve import DEFAULT_STEPS, SEED_FREQUENCIES, UNIT_ROUNDOFF, measure
    k_u, k_v = SEED_FREQUENCIES
    out = {}
    for field, (u, v, component) in points.items():
        steps = DEFAULT_STEPS[DEFAULT_STEPS <= ridges_largest] if field == "ridges" else DEFAULT_STEPS
        c = measure(field, u, v, component, eps=steps, k_u=k_u, k_v=k_v)
        at_fitted = float(measure(field, u, v, component, eps=[c.eps_fitted], k_u=k_u, k_v=k_v).error[0])
        out[field] = dict(u=u, v=v, component=component, k_u=k_u, k_v=k_v, steps=int(steps.size),
                          largest_step=float(steps.max()), smallest_step=float(steps.min()),
                          h=abs(c.height), h1=abs(c.derivative), x_h1=c.model_argument / UNIT_ROUNDOFF,
                          h3=abs(c.third_derivative), eps_model=c.eps_model, error_model=c.error_model,
                          eps_fitted=c.eps_fitted, error_at_fitted=c.error_at_fitted,
                          measured_at_fitted=at_fitted, fitted_over_model=c.eps_fitted / c.eps_model,
                          argument_share=c.model_argument / (c.model_cancellation + c.model_argument))
    ridges = out["ridges"]
    ridges["crease_distance"] = float(crease_distance(ridges["u"], ridges["v"], k_u, k_v))
    if not ridges["crease_distance"] > ridges["largest_step"]:
        raise RuntimeError(f"the ridges point ({ridges['u']}, {ridges['v']}) is {ridges['crease_distance']:g} "
                           f"from a crease, within the largest step {ridges['largest_step']:g}")
    return out


def crease_share():
    """What the crease does on the ridges field, one measurement of the build (`lab.store`): in
    the draft's scene at `CREASE_SIZE` squared, the share of sphere-A pixels whose stencil
    straddles a crease (chart distance to one below the step, `crease_distance`) at each step
    of `CREASE_STEPS`.  Returns a dict: ``steps``, ``share`` (list of floats in [0, 1], step
    order) and ``pixels`` (sphere-A pixels of the frame)."""
    from .store import measured
    return measured("crease-share", _crease_share, size=CREASE_SIZE, steps=list(CREASE_STEPS))


def _crease_share(size, steps):
    g = gbuffer(DRAFT_SCENE, size, size)
    uv = g.uv[g.chamber == SPHERE_A]
    dist = crease_distance(uv[:, 0], uv[:, 1], DRAFT_SCENE.k_u, DRAFT_SCENE.k_v)
    return dict(steps=steps, share=[float(np.mean(dist < eps)) for eps in steps], pixels=int(dist.size))


#: The steps of the simulator's U-curve (``CURVE_LOG_EPS`` in renderer/js/simulator.js): half decades
#: from 1e-14 to 1e-1, chart units.
HALF_DECADES = tuple(float(x) for x in 10.0 ** (np.arange(-28, -1) / 2))


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
    ValueError
        ``field`` is not a height field of `renderer.Scene`, or ``size`` is below 1.
    TypeError
        ``size`` is not an integer.
    """
    from renderer.ledger import SIMULATOR_SCENE
    from renderer.validate import positive_int

    from .store import measured
    SIMULATOR_SCENE.replace(height_field=field)              # the scene's own error for a bad field
    return measured("image-best-step", _image_best_step, field=field, size=positive_int("size", size),
                    steps=list(HALF_DECADES))


def _image_best_step(field, size, steps):
    from renderer import sweep
    from renderer.ledger import SIMULATOR_SCENE
    scene = SIMULATOR_SCENE.replace(height_field=field)
    rms = [float(led.rms) for led in sweep(scene, steps, size, size).census]
    return dict(best=steps[int(np.argmin(rms))], steps=steps, rms=rms, scene=scene.changes(), size=[size, size])
