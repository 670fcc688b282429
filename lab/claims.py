"""The seed-claims register: every checkable claim of the seed, measured.

Each `Claim` records where the seed says it, what it says (a short quotation),
how it is measured, and the verdict registered for it.  ``measure()``
recomputes the evidence at build time and returns (values, verdict); the
verdict is one of HOLDS, FAILS ("does not hold") and CORRECTED ("holds with a
correction").  `pytest verify` fails when a computed verdict differs from the
registered one, so a verdict cannot change silently: the register must be
edited with it.  The one timing claim is decided by a count (the sine and
cosine calls per pixel of the generated gradients); its timings are reported
beside it and decide nothing.  Each claim's pass criterion is data (a
`Criterion`: bounds on the numbers its measurement returns, tried in order),
applied by `Claim.measure`.  Only numbers, verdicts and the draft's own words
(``quote``, ``where``) live here: the book words the measurements and the rules
(book/chapter/claim_words.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

from proofs.frame import SEED_POLE_SIN_PHI
from renderer import BUMPS, DRAFT_SCENE, compare, gbuffer, pointwise, render
from renderer import kernel
from renderer import formulas as F
from renderer.render import SPHERE_A
from renderer.validate import InvalidType, InvalidValue, choice, flag, real

from ._checks import STEP, instance, optional, shown
from .accuracy import DIGITS
from .seed_errata import CELL6_BETA, CELL6_FIELD

__all__ = ["Bound", "Criterion", "rule", "about", "ABOUT", "Claim", "CLAIMS", "HOLDS", "FAILS", "CORRECTED",
           "UNMEASURED", "Unmeasured", "evaluate", "checked", "ClaimChanged", "census",
           "relative_error_at", "CELL5_EXPECTED", "CELL7B_STEP", "CELL7C_POLE_SIN_PHI", "CENSUS_STEPS",
           "CENSUS_SIZE", "VERDICTS"]

HOLDS, FAILS, CORRECTED = "holds", "does not hold", "holds with a correction"
#: The verdicts a criterion gives.
VERDICTS = (HOLDS, FAILS, CORRECTED)
#: The verdict of a claim whose measurement raised or gave no finite number for a quantity its
#: criterion reads: registered for no claim, so `checked` and `pytest verify` refuse it.
UNMEASURED = "not measured"


class Unmeasured(ValueError):
    """A quantity a criterion reads is missing or not a finite number."""


@dataclass(frozen=True)
class Bound:
    """A test on one measured quantity: ``lo <= value <= hi`` (``<`` where ``strict``);
    ``None`` leaves that side open.  ``quantity`` names the value in the dict a
    claim's measurement returns (the book words the bound, `chapter.claim_words.rule_text`)."""

    quantity: str
    lo: float | None = None
    hi: float | None = None
    strict: bool = False

    def __post_init__(self):
        """InvalidType or InvalidValue naming ``Bound.<field>``: ``quantity`` not a string, ``lo``
        or ``hi`` not a finite real number (nor None), ``lo > hi``, ``strict`` not True or False."""
        instance("Bound.quantity", self.quantity, str, "a string")
        lo, hi = (optional(real, f"Bound.{k}", getattr(self, k)) for k in ("lo", "hi"))
        if lo is not None and hi is not None and lo > hi:
            raise InvalidValue(f"Bound.lo must be <= Bound.hi, got lo = {self.lo!r}, hi = {self.hi!r}")
        flag("Bound.strict", self.strict)

    def holds(self, values):
        """Whether ``values[quantity]`` lies within the bound (KeyError if it was not measured)."""
        x = values[self.quantity]
        below = (lambda a, b: a < b) if self.strict else (lambda a, b: a <= b)
        return (self.lo is None or below(self.lo, x)) and (self.hi is None or below(x, self.hi))


@dataclass(frozen=True)
class Criterion:
    """A claim's decision rule as data: ``cases`` is a tuple of (verdict, bounds); the
    first case whose bounds all hold gives the verdict, else ``otherwise``."""

    cases: tuple
    otherwise: str = FAILS

    def __post_init__(self):
        """InvalidType or InvalidValue naming ``Criterion.<field>``: ``cases`` not a tuple of
        (verdict, tuple of `Bound`) pairs, a verdict or ``otherwise`` not one of `VERDICTS`."""
        instance("Criterion.cases", self.cases, tuple, "a tuple of (verdict, bounds) pairs")
        for i, case in enumerate(self.cases):
            if not (isinstance(case, tuple) and len(case) == 2 and isinstance(case[1], tuple)
                    and all(isinstance(b, Bound) for b in case[1])):
                raise InvalidType(f"Criterion.cases[{i}] must be a pair (verdict, tuple of Bound), got {shown(case)}")
            choice(f"Criterion.cases[{i}][0]", case[0], VERDICTS)
        choice("Criterion.otherwise", self.otherwise, VERDICTS)

    def decide(self, values):
        """The verdict for the measured ``values`` (a dict: quantity name -> number).

        Raises
        ------
        Unmeasured
            If a quantity any case reads is missing or not a finite real number: a
            NaN fails every bound, and would otherwise fall through to ``otherwise``.
        """
        for quantity in dict.fromkeys(b.quantity for _, bounds in self.cases for b in bounds):
            x = values.get(quantity)
            try:
                finite = math.isfinite(x)               # TypeError for a complex, a string, None
            except TypeError:
                finite = False
            if not finite:
                raise Unmeasured(f"{quantity} measured {x!r:.80}: a verdict needs a finite number")
        for verdict, bounds in self.cases:
            if all(b.holds(values) for b in bounds):
                return verdict
        return self.otherwise


#: How the register reads "≈ x", "~x", "near x": x's order of magnitude, within half a decade either way.
ABOUT = 10 ** 0.5


def about(quantity, x, lo=True, hi=True):
    """`Bound`: ``quantity`` about ``x`` (within a factor `ABOUT`), from below (``lo``), above (``hi``) or both.

    ``x``: a finite real number > 0; ``lo``, ``hi``: True or False (InvalidType or InvalidValue
    naming the argument otherwise; ``quantity`` as `Bound` checks it)."""
    x = real("x", x, low=0.0, low_open=True)
    lo, hi = flag("lo", lo), flag("hi", hi)
    return Bound(quantity, x / ABOUT if lo else None, x * ABOUT if hi else None)


def rule(*cases, otherwise=FAILS):
    """`Criterion` from alternating verdicts and bounds: ``rule(HOLDS, b1, CORRECTED, (b2, b3))``.

    Raises InvalidValue naming ``cases`` for an odd number of them (a verdict without its
    bounds); a wrong verdict or bound as `Criterion` refuses it."""
    if len(cases) % 2:
        raise InvalidValue(f"cases must alternate verdicts and bounds, got {len(cases)} of them (odd): "
                           f"{cases!r:.80}")
    pairs = [(cases[i], cases[i + 1] if isinstance(cases[i + 1], tuple) else (cases[i + 1],))
             for i in range(0, len(cases), 2)]
    return Criterion(tuple(pairs), otherwise)


@dataclass(frozen=True)
class Claim:
    """One checkable claim of the seed.

    ``where`` is the seed section or cell, ``quote`` the claim in the seed's
    words (short), ``measurement`` how it is tested, ``registered`` the verdict
    on record; ``quantify()`` returns the measured values, a JSON-safe dict: the numbers
    ``criterion`` decides the verdict from ({quantity: number}), and the numbers and short
    tokens the book's sentence about the claim shows (the frame's ``scene`` and ``size``, say;
    `chapter.claim_words` words them).
    """

    id: str
    where: str
    quote: str
    measurement: str
    registered: str
    quantify: Callable[[], dict]
    criterion: Criterion

    def measure(self):
        """(values, computed verdict): the measured values (a dict, `quantify`), decided by the
        criterion; or ({"error": "<type>: <message>"} (at most 300 characters), `UNMEASURED`)
        when measuring or deciding raised, so that one broken claim neither passes nor hides the
        verdicts of the others."""
        try:
            values = self.quantify()
            return values, self.criterion.decide(values)
        except Exception as e:          # noqa: BLE001 - reported as the claim's verdict, never passed
            return {"error": f"{type(e).__name__}: {e}"[:300]}, UNMEASURED


@lru_cache(maxsize=None)
def _ucurve():
    from renderer.ucurve import measure
    return measure()


@lru_cache(maxsize=None)
def _errata():
    from .seed_errata import measure_all
    return measure_all()


def _frames(field=None, beta=None, eps=None, size=128):
    """(central, exact) frames of the draft's scene, ``size`` squared, with its field, β and step
    replaced where given; rendered once per scene (`_frames_of`: the scene is the key, so a test that
    patches `DRAFT_SCENE` gets its own frames)."""
    changes = {"height_field": field, "beta": beta, "eps": eps}
    return _frames_of(DRAFT_SCENE.replace(**{k: x for k, x in changes.items() if x is not None}), size)


@lru_cache(maxsize=None)
def _frames_of(scene, size):
    return render(scene, size, size, gradient="central"), render(scene, size, size)


def _on(frame, scene=None):
    """{"scene": its fields that differ from the defaults (`renderer.Scene.changes`), "size": [width,
    height]}: the frame a measurement used, read from the frame itself.  ``frame``: a `renderer.Frame`
    or `renderer.GBuffer`; ``scene``: the scene to name when the frame carries none (a GBuffer) or a
    sweep varies it."""
    height, width = frame.chamber.shape
    return {"scene": (scene or frame.scene).changes(), "size": [width, height]}


def relative_error_at(eps):
    """The central difference's relative error in hᵤ on the U-curve of Cell 2 (`renderer.ucurve.measure`'s
    default curve) at ``eps``, its step within 1 % of it: what the register's claims about 1e-9 and 1e-11
    decide on.

    Raises
    ------
    renderer.validate.InvalidType
        ``eps`` is not a real number (a bool, a string).
    renderer.validate.InvalidValue
        ``eps`` is not in [1e-300, 1), or no step of the curve lies within 1 % of it, naming
        it and the nearest step.
    """
    eps, c = real("eps", eps, **STEP), _ucurve()
    k = np.argmin(np.abs(np.log10(c.eps) - np.log10(eps)))
    if not abs(c.eps[k] / eps - 1) <= 0.01:
        raise InvalidValue(f"eps={eps!r}: the U-curve's nearest step is {c.eps[k]:.3g}; a claim at a step is "
                           "measured within 1 % of it")
    return float(c.error[k]) / abs(c.derivative)


def _h3_scale():
    k_u = DRAFT_SCENE.k_u
    return {"(π kᵤ)³": (np.pi * k_u) ** 3, "k_u": k_u}


def _truncation_until():
    c = _ucurve()
    return {"model optimum ε": c.eps_model, "measured_optimum": c.eps_measured_min}


def _drowns_below_1e9():
    rel = relative_error_at(1e-9)
    return {"relative error at ε = 1e-9": rel, "step": 1e-9, "digits": int(-np.log10(rel))}


#: "cliff beyond 1e-8" (Cell 2's Expect): the error is measured there and two decades of step further
#: down; a cliff is a rise of at least a decade over those two (roundoff's 1/ε gives two).
CLIFF_STEPS = (1e-8, 1e-10)
CLIFF_GROWTH = "error growth over the two decades"


def _cell2_minimum():
    from .accuracy import optima
    opt = optima()["sine"]
    top, bottom = (relative_error_at(e) for e in CLIFF_STEPS)
    return {"fitted optimum ε": opt["eps_fitted"], "error": opt["error_at_fitted"],
            CLIFF_GROWTH: bottom / top, "error at the top": top, "error at the bottom": bottom,
            "top step": CLIFF_STEPS[0], "bottom step": CLIFF_STEPS[1]}


def _orientation():
    from proofs.frame import _orientation_value
    value = int(_orientation_value())
    return {"(eθ × eφ)·N": value}


def _flips_zero():
    from proofs.no_boundary import render_flips
    frames, values, masks, _ = render_flips()
    return {"geometry values differing": values, "reach-mask pixels differing": masks, "gbuffers": frames}


def _shadow_curves_unchanged():
    """The boundaries themselves (claim flips-zero's G-buffers: chamber, t, P, N and the reach masks
    that draw the shadow curves), and the draft's shading rule lighting pairs past the terminator."""
    from proofs.no_boundary import render_flips
    _, values, masks, _ = render_flips()
    leak = _errata()["terminator-leak"]["leak_pixels_default"]
    return {"G-buffer values moved": values + masks, "pairs lit past the terminator": leak}


def _cell1_ripples():
    m = _errata()["sphere-b-quadratic"]
    return {"draft's sphere-A pixels": m["seed_pixels_a"], "pixels_b": m["seed_pixels_b"], "pixels": m["pixels"]}


#: The draft's Cell 3 sweep of steps, and the frame it renders.
CENSUS_STEPS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6)
CENSUS_SIZE = 256


def census():
    """The draft's Cell 3 census, one measurement of the build (`lab.store`): the
    default scene (ridges) at 256 x 256, the exact frame against the central frame at
    each step of `CENSUS_STEPS`.

    Returns a dict: ``steps``; per step (lists in step order) ``max``, ``rms``,
    ``on_band`` and ``off_band`` (mean |ΔI| on and off the crease band), ``flips``
    and ``straddling`` (sphere-A pixels within the step of a ridge zero line, whose
    stencil straddles a crease); the fitted exponents p of RMS ~ eps^p and of the
    off-band mean ~ eps^p over all the steps (``rms_slope``, ``off_slope``); at the
    scene's step (``step``) the two means (``on``, ``off``) and their ratio (``ratio``); and
    the frame's ``scene`` (`renderer.Scene.changes`) and ``size`` ([width, height]).
    """
    from .store import measured
    return measured("census", _census, size=CENSUS_SIZE)


def _census(size, scene=DRAFT_SCENE):
    symbolic = render(scene, size, size)
    on_a = symbolic.chamber == SPHERE_A
    uv = gbuffer(scene, size, size).uv[on_a]
    from .accuracy import crease_distance
    dist = crease_distance(uv[:, 0], uv[:, 1], scene.k_u, scene.k_v, scene.field)
    out = {k: [] for k in ("max", "rms", "on_band", "off_band", "flips", "straddling")}
    for eps in CENSUS_STEPS:
        led = compare(render(scene.replace(eps=eps), size, size, gradient="central"), symbolic)
        for key, value in (("max", led.max_abs), ("rms", led.rms), ("on_band", led.mean_abs_kink),
                           ("off_band", led.mean_abs_off_kink), ("flips", led.flips),
                           ("straddling", int(np.count_nonzero(dist < eps)))):
            out[key].append(value)
    logs = np.log(CENSUS_STEPS)
    on, off = (out[key][CENSUS_STEPS.index(scene.eps)] for key in ("on_band", "off_band"))
    return dict(out, steps=list(CENSUS_STEPS), step=scene.eps,
                rms_slope=float(np.polyfit(logs, np.log(out["rms"]), 1)[0]),
                off_slope=float(np.polyfit(logs, np.log(out["off_band"]), 1)[0]),
                on=on, off=off, ratio=on / off, scene=scene.changes(), size=[size, size])


def _census_slope():
    c = census()
    return {"RMS slope": c["rms_slope"], "off-band slope": c["off_slope"], "steps": len(c["steps"]),
            "ε range": [c["steps"][0], c["steps"][-1]], "scene": c["scene"], "size": c["size"]}


def _cell3_runs():
    """The draft's Cell 3 reduces |num - sym| over the pixels both maps put on
    sphere A; with its sphere B (erratum sphere-b-quadratic) no pixel of the draft's code's
    map is on A, against this renderer's count on its frame of the same scene."""
    from .seed_errata import seed_chamber
    code = seed_chamber(CENSUS_SIZE)
    on_a = (code & 3) == SPHERE_A
    num, sym = _frames(size=CENSUS_SIZE)
    same = np.ones(code.shape, bool)          # its code_e == code_sym: two maps of one scene
    try:
        np.abs(num.image - sym.image)[same & on_a].max()
    except ValueError as error:
        return {"rows computed": 0, "code_pixels_a": int(np.count_nonzero(on_a)), "pixels": int(code.size),
                "pixels_a": int(np.count_nonzero(sym.chamber == SPHERE_A)), "error": type(error).__name__,
                **_on(sym)}
    return {"rows computed": 1, **_on(sym)}


def _census_flips():
    c = census()
    return {"flips": sum(c["flips"]), "steps": len(c["steps"]), "scene": c["scene"], "size": c["size"]}


def _kink_order_of_magnitude():
    c = census()
    return {"on/off ratio": c["ratio"], "on": c["on"], "off": c["off"], "step": c["step"],
            "scene": c["scene"], "size": c["size"]}


def _evals():
    """Values of h per pixel in the kernel's formulas for the draft's field: the stencil points at
    which its central difference (`HeightField.central`) evaluates h, against none in its gradient
    (counted from the sympy objects the kernel is generated from, `gradient_methods.evaluations`)."""
    from .gradient_methods import evaluations
    central, exact = evaluations(DRAFT_SCENE.field, "central"), evaluations(DRAFT_SCENE.field, "exact")
    return {"values of h, central": central.h, "values of h, exact": exact.h, "trig_central": central.trig,
            "trig_exact": exact.trig}


def _cell4_counter():
    """The draft's Cell 4 counting, in its structure: a counter wraps h, but the
    gradients it times call the unwrapped h, so both counts stay 0."""
    class Counter:
        n = 0

    d = DRAFT_SCENE

    def h(u, v):
        return float(pointwise.height(d.field, np.array([u]), np.array([v]), d.k_u, d.k_v)[0])

    def h_counted(u, v):
        Counter.n += 1
        return h(u, v)

    def central(u, v, height, eps=d.eps):
        return ((height(u + eps, v) - height(u - eps, v)) / (2 * eps),
                (height(u, v + eps) - height(u, v - eps)) / (2 * eps))

    counts = []
    for gradient in (lambda: central(0.3, 0.4, h), lambda: pointwise.exact_gradient(d.field, 0.3, 0.4, d.k_u, d.k_v),
                     lambda: central(0.3, 0.4, h_counted)):
        Counter.n = 0
        gradient()
        counts.append(Counter.n)
    numeric, exact, wired = counts
    return {"count printed, numeric": numeric, "count printed, exact": exact, "wired": wired, "step": d.eps}


#: Claim stacking's box filters, in samples per pixel side: the reference (Ch. 6's filter) and the coarser
#: one that must come closer to it than one sample does.
BOX_SIDES = (4, 2)
#: The quantity that decides whether the box filter still converges on the bumped image (claim stacking),
#: and the side of the frame that claim filters to (its reference box's renders are `BOX_SIDES`[0] times as wide).
CONVERGES = f"bumped error, {BOX_SIDES[1]} × {BOX_SIDES[1]} box / one sample"
STACKING_SIZE = 128


def _stacking():
    """Bump under a pixel filter: a `BOX_SIDES`[0]² box filter (4 x 4: a 512² render averaged to
    `STACKING_SIZE`², 128²) against one sample per pixel and against a `BOX_SIDES`[1]² box (2 x 2: a 256²
    render), on sphere-A pixels whose samples of the reference box are all on A, with the bump and without it."""
    err, two, bumped, n = {}, {}, DRAFT_SCENE.beta, STACKING_SIZE
    (a, b), on_a = BOX_SIDES, lambda frame: frame.chamber == SPHERE_A

    def box(frame, k):
        return frame.image.reshape(n, k, n, k, 3).mean(axis=(1, 3))
    for beta in (bumped, 0.0):
        scene = DRAFT_SCENE.replace(beta=beta)
        fine, mid, one = (render(scene, k * n, k * n) for k in (a, b, 1))
        kept = on_a(fine).reshape(n, a, n, a).all(axis=(1, 3)) & on_a(one)
        rms = {k: float(np.sqrt(np.mean((box(fine, a) - image)[kept] ** 2)))
               for k, image in ((1, one.image), (b, box(mid, b)))}
        err[beta], two[beta] = rms[1], rms[b] / rms[1]
    return {"one-sample error, with / without the bump": err[bumped] / err[0.0], CONVERGES: two[bumped],
            "flat_2x2": two[0.0], "bumped": err[bumped], "flat": err[0.0], "box sides": list(BOX_SIDES),
            **_on(one, DRAFT_SCENE)}


def _blinn_exact():
    """Blinn's normal against the displaced sphere's, both in slopes (proofs/blinn.py):
    equal to first order in beta (theorem blinn-perturbation); the second order differs."""
    import sympy as sp

    from proofs.blinn import BLINN, SURFACE, phi, theta
    at = {F.R: 1.0, F.beta: DRAFT_SCENE.beta, F.h: 0.5, F.h_u: 3.0, F.h_v: -2.0, phi: 1.1, theta: 0.4}
    gap = max(abs(float(sp.N(e.subs(at)))) for e in (BLINN - SURFACE))
    first = max(abs(float(sp.N(e.subs(at)))) for e in (BLINN - SURFACE).diff(F.beta).subs(F.beta, 0))
    return {"slope gap": gap, "first-order gap": first, "point": {str(k): v for k, v in at.items() if k != F.R}}


def _timing():
    """Exact vs central: the verdict rests on a count, the transcendental calls per
    pixel in the kernel's generated gradients (`gradient_methods.evaluations`), not
    on a clock; the gradient stage and whole-frame timings (min of repeated runs)
    are reported beside it."""
    import time

    from .gradient_methods import evaluations
    g = gbuffer(DRAFT_SCENE, 128, 128)
    uv = g.uv[g.chamber == SPHERE_A]
    u, v = uv[:, 0].copy(), uv[:, 1].copy()

    def best(fn, n=25):
        times = []
        for _ in range(n):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        return min(times)

    d = DRAFT_SCENE
    t_exact = best(lambda: pointwise.exact_gradient(d.field, u, v, d.k_u, d.k_v))
    t_central = best(lambda: pointwise.central_gradient(d.field, u, v, d.k_u, d.k_v, d.eps))
    f_exact = best(lambda: render(d, 128, 128), 7)
    f_central = best(lambda: render(d, 128, 128, gradient="central"), 7)
    stage = t_central / t_exact
    central, exact = evaluations(d.field, "central"), evaluations(d.field, "exact")
    return {"sin/cos calls, exact minus central": exact.trig - central.trig, "trig_exact": exact.trig,
            "trig_central": central.trig, "stage_ratio": stage, "frame_ratio": f_central / f_exact,
            "step": d.eps, **_on(g, DRAFT_SCENE)}


#: The draft's expected worst component error of its Cell 5 check ("~1e-9"): its criterion's centre,
#: and what the measured worst is compared with; and the random cases the check draws.
CELL5_EXPECTED = 1e-9
CELL5_TRIALS = 2000


def _cell5_fd():
    rng, trials, step = np.random.default_rng(5), CELL5_TRIALS, 1e-7    # the draft's check, as its cell runs it
    beta, worst = DRAFT_SCENE.beta, 0.0
    for _ in range(trials):
        N = rng.normal(size=3)
        N /= np.linalg.norm(N)
        g = rng.normal(size=3) * 4.0
        M = N + beta * g
        Np = M / np.linalg.norm(M)
        exact = (g - Np * (Np @ g)) / np.linalg.norm(M)
        M2 = N + (beta + step) * g
        worst = max(worst, float(np.abs(exact - (M2 / np.linalg.norm(M2) - Np) / step).max()))
    return {"worst component": worst, "expected": CELL5_EXPECTED, "ratio": worst / CELL5_EXPECTED, "step": step,
            "trials": trials}


def _dn_1e12():
    """The closed form against mpmath, and the draft's own check (`_cell5_fd`), which would have to
    show the same for the claim to hold as worded."""
    from .accuracy import normal_beta_derivative_residual
    r = normal_beta_derivative_residual()
    return {"closed form's worst error": r, "draft's check's worst error": _cell5_fd()["worst component"],
            "digits": DIGITS}


def _beta_order():
    from .accuracy import image_beta_order
    o = image_beta_order()
    return {"median order": o["median_slope"], "RMS order": o["rms_slope"], "scene": o["scene"],
            "size": [o["size"], o["size"]]}


def _beta0():
    a, b = _frames(beta=0.0)
    d = float(np.abs(a.image - b.image).max())
    return {"max |ΔI|": d, **_on(b)}


def _bump_nonzero():
    s, flat = DRAFT_SCENE.replace(height_field=CELL6_FIELD, beta=CELL6_BETA), 0.0
    bumped = render(s, 128, 128)
    d = float(np.abs(bumped.image - render(s.replace(beta=flat), 128, 128).image).mean())
    return {"mean |ΔI|": d, "flat β": flat, **_on(bumped)}


def _cell6_truncation():
    """The draft's Cell 6 at its step and at a tenth of it (its field, `CELL6_FIELD`, and its strong bump)."""
    coarse, fine = DRAFT_SCENE.eps, DRAFT_SCENE.eps / 10
    a = compare(*_frames(CELL6_FIELD, CELL6_BETA, coarse)).max_abs
    b = compare(*_frames(CELL6_FIELD, CELL6_BETA, fine)).max_abs
    return {"max |ΔI| ratio": a / b, "coarse": a, "fine": b, "coarse_step": coarse, "fine_step": fine,
            **_on(_frames(CELL6_FIELD, CELL6_BETA, coarse)[1])}


def _noise_below_1e11():
    rel = relative_error_at(1e-11)
    return {"relative error at ε = 1e-11": rel, "step": 1e-11}


#: The step of the draft's Cell 7b (its crease: ``{**SCr, 'eps': 1e-4}``).
CELL7B_STEP = 1e-4
#: How near the exact hᵤ's size at Cell 7b's crease must be to the one-sided slope's to be that slope
#: (relative): far above float64's rounding of the two, far below any other multiple of the slope.
SIDE_WHOLE = 1e-9
#: The draft's pole cut-off (Cell 7c; seed Cell 1, ``tangent_frame``): its fixed basis below this
#: sin(phi), as the frame's theorems name it (`proofs.frame.SEED_POLE_SIN_PHI`).  The renderer keeps
#: the chart's frame down to `formulas.POLE_SIN_PHI` (2^-1022).
CELL7C_POLE_SIN_PHI = SEED_POLE_SIN_PHI


def _crease_values():
    """Cell 7b: the draft's field (ridges, |sin(πk_u u) sin(πk_v v)|) at u = 1/k_u (its first crease
    in u) and the U-curve's v; and the size of its one-sided slopes there, πk_u |sin(πk_v v)| (the
    slope of the product under the bars, whose cos(πk_u u) is ±1 on the crease), which an exact
    gradient that picks a side returns whole."""
    d = DRAFT_SCENE
    u, v = 1.0 / d.k_u, F.SEED_POINT[1]
    fd = float(pointwise.central_gradient(d.field, u, v, d.k_u, d.k_v, CELL7B_STEP)[0])
    ex = float(pointwise.exact_gradient(d.field, u, v, d.k_u, d.k_v)[0])
    side = math.pi * d.k_u * abs(math.sin(math.pi * d.k_v * v))
    return {"|central hᵤ|": abs(fd), "|exact hᵤ|": abs(ex), "||exact hᵤ| / one-sided slope − 1|": abs(abs(ex) / side - 1),
            "central": fd, "exact": ex, "step": CELL7B_STEP}


def _pole_pixels():
    g = gbuffer(DRAFT_SCENE, 256, 256)
    n = int(np.count_nonzero((g.chamber == SPHERE_A) & (pointwise.chart(*np.moveaxis(g.N, -1, 0))[2] <= CELL7C_POLE_SIN_PHI)))
    return {"fallback pixels": n, **_on(g, DRAFT_SCENE)}


#: "brightens again past 1e-8" (§4's first Try this): the RMS from this step down to the sweep's smallest.
BRIGHTENS_PAST = 1e-8


def _sweep_best():
    """§4's sweep of the sine field: the image-best step, the one measurement the book shows of it
    (`lab.accuracy.image_best_step`: the simulator's scene, its half-decade steps), and how much the
    RMS grows from `BRIGHTENS_PAST` down to the sweep's smallest step."""
    from .accuracy import image_best_step
    best = image_best_step("sine")
    steps, rms = best["steps"], best["rms"]
    past, smallest = steps.index(BRIGHTENS_PAST), int(np.argmin(steps))
    return {"best ε": best["best"], "RMS growth past 1e-8": rms[smallest] / rms[past], "from": steps[past],
            "to": steps[smallest], "scene": best["scene"], "size": best["size"]}


def _creases_part():
    num, sym = _frames()
    diff = np.abs(num.image - sym.image).max(axis=-1)
    big = diff > LARGE_DIFFERENCE
    share = float(np.count_nonzero(big & sym.kink) / max(1, np.count_nonzero(big)))
    return {"share in the band": share, "threshold": LARGE_DIFFERENCE, "step": num.scene.eps, **_on(sym)}


#: Where `_rings_pinch` looks either side of the pole: the polar angle φ (radians).
PINCH_PHI = 1e-3
#: A difference of the frames in linear colour that `_creases_part` counts as large.
LARGE_DIFFERENCE = 1e-3


def _rings_pinch():
    """rings: h = sin(2 pi k_v v) has h_v = 2 pi k_v at the pole, where e_phi turns with theta,
    so the displaced sphere comes to a cone's point there and N' turns over across the pole
    with either bump: the kernel's own N' (`renderer.kernel.shading_normal`), either side of it."""
    phi, d = PINCH_PHI, DRAFT_SCENE.replace(height_field="rings")
    turn = {}
    for bump in BUMPS:
        record = kernel.params(d.replace(bump=bump), skip=False)[0][0]
        out = []
        for theta in (0.0, np.pi):
            N = np.array([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)])
            u, v, sin_phi = (float(c) for c in pointwise.chart(*N))
            h = float(pointwise.height(d.field, u, v, d.k_u, d.k_v))
            hu, hv = (float(c) for c in pointwise.exact_gradient(d.field, u, v, d.k_u, d.k_v))
            frame = tuple(float(c) for e in pointwise.tangent_frame(*N, sin_phi) for c in e)
            out.append(np.array(kernel.shading_normal(record, N, frame, h, hu, hv, sin_phi)))
        turn[bump] = float(np.degrees(np.arccos(np.clip(out[0] @ out[1], -1, 1))))
    return {"angle (degrees)": turn["chart"], "displaced sphere's angle (degrees)": turn["surface"],
            "sin_phi": float(np.sin(phi)), "field": d.height_field, "beta": d.beta}


def _beta_zero_slider():
    flat = render(DRAFT_SCENE.replace(beta=0.0), 96, 96)
    b = render(DRAFT_SCENE.replace(beta=0.0, height_field="sine"), 96, 96, gradient="central").image
    n = int(np.count_nonzero(flat.image != b))
    return {"values differing": n, **_on(flat)}


CLAIMS = (
    Claim("h3-scale", "§3", "(π kᵤ)³ ≈ 2,000 at kᵤ = 8", "evaluate (π kᵤ)³", FAILS, _h3_scale,
          rule(HOLDS, about("(π kᵤ)³", 2000))),
    Claim("truncation-until-1e-6", "§3", "truncation dominates until ε ~ 10⁻⁶",
          "U-curve at the seed's point against an mpmath reference (renderer/ucurve.py)", HOLDS, _truncation_until,
          rule(HOLDS, about("model optimum ε", 1e-6))),
    Claim("roundoff-drowns-1e-9", "§3", "roundoff drowns everything below ~10⁻⁹",
          "relative error of the float64 quotient at ε = 1e-9", FAILS, _drowns_below_1e9,
          rule(HOLDS, about("relative error at ε = 1e-9", 1.0, hi=False))),
    Claim("cell2-minimum", "Cell 2, Expect", "minimum near ε ≈ 1e-6, cliff beyond 1e-8",
          "optimum of the two-term model fitted to the measured U-curve, and the measured error's growth "
          f"from ε = {CLIFF_STEPS[0]:g} to {CLIFF_STEPS[1]:g} (renderer/ucurve.py)", HOLDS, _cell2_minimum,
          rule(HOLDS, (about("fitted optimum ε", 1e-6), Bound(CLIFF_GROWTH, lo=10.0)),
               CORRECTED, (Bound("fitted optimum ε", 1e-8, 10 * 1e-6), Bound(CLIFF_GROWTH, lo=10.0)))),
    Claim("frame-aligned", "Cell 2", "`e_th × e_ph` … (unit, aligned with N)",
          "sympy: (eθ × eφ)·N", FAILS, _orientation,
          rule(HOLDS, Bound("(eθ × eφ)·N", 1, 1))),
    Claim("flips-zero", "§1, §3", "Chamber flips are zero by construction",
          "independent G-buffers across fields, β, ε, bump modes and pipelines (proofs/no_boundary.py)",
          HOLDS, _flips_zero,
          rule(HOLDS, (Bound("geometry values differing", 0, 0), Bound("reach-mask pixels differing", 0, 0)))),
    Claim("shadow-curves-unchanged", "§1", "Silhouettes, seams, shadow curves: unchanged",
          "claim flips-zero's G-buffers, and the terminator leak of the seed's shading rule (errata E2)", CORRECTED,
          _shadow_curves_unchanged,
          rule(FAILS, Bound("G-buffer values moved", lo=0, strict=True),
               CORRECTED, Bound("pairs lit past the terminator", lo=0, strict=True), otherwise=HOLDS)),
    Claim("cell1-ripples", "Cell 1, Expect", "sphere A's shading ripples with the height field",
          "the seed's sphere-B quadratic on the default frame (errata E1)", FAILS, _cell1_ripples,
          rule(FAILS, Bound("draft's sphere-A pixels", 0, 0), otherwise=HOLDS)),
    Claim("census-slope", "Cell 3, Expect", "the ε-sweep table descending the truncation slope",
          f"fitted slope of the census over ε = {CENSUS_STEPS[0]:.0e} … {CENSUS_STEPS[-1]:.0e} "
          f"({DRAFT_SCENE.height_field}, {CENSUS_SIZE}²)",
          CORRECTED, _census_slope,
          rule(HOLDS, Bound("RMS slope", lo=1.8, strict=True), CORRECTED, Bound("off-band slope", lo=1.8, strict=True))),
    Claim("census-flips", "Cell 3, Expect", "flips = 0 everywhere", f"the census of Cell 3 ({DRAFT_SCENE.height_field}, {CENSUS_SIZE}²)",
          HOLDS,
          _census_flips,
          rule(HOLDS, Bound("flips", 0, 0))),
    Claim("cell3-runs", "Cell 3", "the census as an epsilon sweep … print the table",
          f"the draft's reduction over its own chamber map (its sphere B), {CENSUS_SIZE}²", FAILS, _cell3_runs,
          rule(HOLDS, Bound("rows computed", lo=1))),
    Claim("kink-order-of-magnitude", "Cell 3, Expect",
          "the kink-loci error an order of magnitude above the smooth interior",
          f"mean |ΔI| on / off the crease band at ε = {DRAFT_SCENE.eps:g}, 256²", CORRECTED,
          _kink_order_of_magnitude,
          rule(HOLDS, about("on/off ratio", 10), CORRECTED, Bound("on/off ratio", lo=10 * ABOUT, strict=True))),
    Claim("four-evals-vs-one", "Cell 4, Expect; §6", "4 evals vs 1",
          "values of h in the kernel's formulas (sympy objects)", CORRECTED, _evals,
          rule(HOLDS, (Bound("values of h, central", 4, 4), Bound("values of h, exact", 1, 1)),
               CORRECTED, (Bound("values of h, central", 4, 4), Bound("values of h, exact", 0, 0)))),
    Claim("cell4-counter", "Cell 4, printout", "h-evals per numeric gradient … per symbolic gradient",
          "the draft's counting scheme, run: a counter around h, gradients calling h", FAILS, _cell4_counter,
          rule(HOLDS, (Bound("count printed, numeric", 4, 4), Bound("count printed, exact", 1, 1)))),
    Claim("stacking", "§6, Stacking", "bump composes under Ch. 6's filter … no new integral, ever",
          f"{BOX_SIDES[0]} × {BOX_SIDES[0]} box filter against one sample and a {BOX_SIDES[1]} × {BOX_SIDES[1]} box "
          "per pixel, with and without the bump "
          f"({STACKING_SIZE}²)", CORRECTED,
          _stacking,
          rule(FAILS, Bound(CONVERGES, lo=1),
               CORRECTED, Bound("one-sample error, with / without the bump", lo=2, strict=True), otherwise=HOLDS)),
    Claim("blinn-exact", "§8", "Blinn computed his perturbation exactly",
          f"Blinn's slopes against the displaced sphere's, exact at β = {DRAFT_SCENE.beta:g}", CORRECTED, _blinn_exact,
          rule(CORRECTED, (Bound("slope gap", lo=1e-6, strict=True), Bound("first-order gap", hi=1e-12, strict=True)), HOLDS, Bound("slope gap", hi=1e-12))),
    Claim("symbolic-not-slower", "Cell 4, Expect", "the symbolic column at or under the numeric",
          "transcendental calls in the generated gradients; timings beside", HOLDS, _timing,
          rule(HOLDS, Bound("sin/cos calls, exact minus central", hi=0))),
    Claim("cell5-fd-1e-9", "Cell 5, Expect", "~1e-9 worst component on the normal derivative",
          f"the seed's forward-difference check over {CELL5_TRIALS:,} trials", FAILS, _cell5_fd,
          rule(HOLDS, about("worst component", CELL5_EXPECTED))),
    Claim("dn-verified-1e-12", "§3, §6", "∂N′/∂β … verified to 10⁻¹²",
          f"float64 closed form against mpmath at {DIGITS} digits", CORRECTED, _dn_1e12,
          rule(HOLDS, (Bound("closed form's worst error", hi=1e-12, strict=True),
                       Bound("draft's check's worst error", hi=1e-12, strict=True)),
               CORRECTED, Bound("closed form's worst error", hi=1e-12, strict=True))),
    Claim("beta-quadratic", "Cell 5, Expect", "clean quadratic convergence — 100× per decade",
          "fitted order of the image's central β-derivative (lab/accuracy.py)", CORRECTED, _beta_order,
          rule(HOLDS, (Bound("median order", 1.8, 2.2), Bound("RMS order", 1.8, 2.2)), CORRECTED, Bound("median order", 1.8, 2.2))),
    Claim("beta0-1e-16", "Cell 6, Expect", "β=0 agreement at ~1e-16",
          "numeric vs symbolic at β = 0", HOLDS, _beta0,
          rule(HOLDS, about("max |ΔI|", 1e-16, lo=False))),
    Claim("bump-nonzero", "Cell 6, Expect", "the β=1.5 bump demonstrably nonzero",
          f"mean |ΔI| between β = {CELL6_BETA:g} and β = 0", HOLDS, _bump_nonzero,
          rule(HOLDS, Bound("mean |ΔI|", lo=1e-2, strict=True))),
    Claim("cell6-truncation", "Cell 6, Expect", "the FD error sitting at its truncation-slope value",
          f"max |ΔI| at ε = {DRAFT_SCENE.eps:g} and {DRAFT_SCENE.eps / 10:g} ({CELL6_FIELD}, β = {CELL6_BETA:g})", HOLDS,
          _cell6_truncation,
          rule(HOLDS, about("max |ΔI| ratio", 10 ** 2))),
    Claim("noise-below-1e-11", "Cell 7a", "below eps ~ 1e-11 the difference quotient is noise",
          "relative error at ε = 1e-11", FAILS, _noise_below_1e11,
          rule(HOLDS, about("relative error at ε = 1e-11", 1.0, hi=False))),
    Claim("crease-fd-zero", "Cell 7b, Expect", "the crease showing FD≈0 vs exact sign-ambiguity",
          "the central and exact hᵤ at u = 1/kᵤ as float64 represents it", CORRECTED, _crease_values,
          rule(CORRECTED, (Bound("|central hᵤ|", hi=1e-6, strict=True),
                           Bound("||exact hᵤ| / one-sided slope − 1|", hi=SIDE_WHOLE)),
               HOLDS, (Bound("|central hᵤ|", hi=1e-6, strict=True), Bound("|exact hᵤ|", lo=0, hi=0)))),
    Claim("pole-pixels", "Cell 7c", "fallback engages below 1e-4. Pixels affected at 256²: …",
          "count from the rendered geometry", FAILS, _pole_pixels,
          rule(HOLDS, Bound("fallback pixels", lo=1))),
    Claim("try-sweep", "§4 Try this (1)", "bottoms out near 1e-6, and brightens again past 1e-8",
          "RMS |ΔI| on A for the sine field over ε", HOLDS, _sweep_best,
          rule(HOLDS, (about("best ε", 1e-6), Bound("RMS growth past 1e-8", lo=ABOUT)))),
    Claim("try-creases", "§4 Try this (2)", "the white creases are exactly where the two pipelines part",
          "share of large differences inside the crease band", HOLDS, _creases_part,
          rule(HOLDS, Bound("share in the band", lo=0.95, strict=True))),
    Claim("try-pinch", "§4 Try this (3)", "rings + magnify the pole: the pinch returns",
          "angle between N' just either side of the pole", HOLDS, _rings_pinch,
          rule(HOLDS, Bound("angle (degrees)", lo=90, strict=True))),
    Claim("try-beta0", "§4 Try this (4)", "bump β to 0: both panels return Chapter 5",
          "β = 0 renders across fields and pipelines, bit for bit", HOLDS, _beta_zero_slider,
          rule(HOLDS, Bound("values differing", 0, 0))),
)


def evaluate():
    """[(claim, measured values, computed verdict)] for every claim (`Claim.measure`)."""
    return [(c, *c.measure()) for c in CLAIMS]


def _register():
    return [[c.id, m, v] for c, m, v in evaluate()]


class ClaimChanged(AssertionError):
    """A claim's computed verdict is not the one registered for it."""


def checked(results=None):
    """`evaluate`'s results (or ``results``), after checking every computed
    verdict against the registered one: the book shows the register only
    through this, so its build fails as `pytest verify` does.  Without
    ``results`` the evaluation is one measurement of the build
    (`lab.store`, "claims-register"), shared by the pages that show it.

    ``results``: None, or a list or tuple of (Claim, dict, str) triples as `evaluate` returns.

    Raises
    ------
    renderer.validate.InvalidType
        ``results`` (or ``results[i]``) is not of that form.
    ClaimChanged
        Naming every claim whose verdict changed, with its measurement.
    """
    if results is not None:
        instance("results", results, (list, tuple), "a list of (Claim, dict, verdict) triples or None")
        for i, r in enumerate(results):
            if not (isinstance(r, tuple) and len(r) == 3 and isinstance(r[0], Claim) and isinstance(r[1], dict)
                    and isinstance(r[2], str)):
                raise InvalidType(f"results[{i}] must be a triple (Claim, dict, verdict), got {shown(r)}")
    if results is None:
        from .store import measured
        by_id = {c.id: c for c in CLAIMS}
        results = [(by_id[i], m, v) for i, m, v in measured("claims-register", _register)]
    changed = [f"{c.id}: registered {c.registered!r}, computed {v!r} ({m})"
               for c, m, v in results if v != c.registered]
    if changed:
        raise ClaimChanged("; ".join(changed) + " (edit the register in lab/claims.py with the change)")
    return results
