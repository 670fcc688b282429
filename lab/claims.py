"""The seed-claims register: every checkable claim of the seed, measured.

Each `Claim` records where the seed says it, what it says (a short quotation),
how it is measured, and the verdict registered for it.  ``measure()``
recomputes the evidence at build time and returns (measured, verdict); the
verdict is one of HOLDS, FAILS ("does not hold") and CORRECTED ("holds with a
correction").  `pytest verify` fails when a computed verdict differs from the
registered one, so a verdict cannot change silently: the register must be
edited with it.  The one timing claim is decided by a count (the sine and
cosine calls per pixel of the generated gradients); its timings are reported
beside it and decide nothing.  Each claim's pass criterion is data (a
`Criterion`: bounds on the numbers its measurement returns, tried in order),
applied by `Claim.measure` and shown in the book's table as written
(`CRITERIA`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

from renderer import DRAFT_SCENE, compare, gbuffer, pointwise, render
from renderer.render import SPHERE_A

from renderer import frame_label

__all__ = ["Bound", "Criterion", "rule", "about", "ABOUT", "Claim", "CLAIMS", "CRITERIA", "HOLDS", "FAILS", "CORRECTED",
           "UNMEASURED", "Unmeasured", "evaluate", "checked", "ClaimChanged", "crease_band_ratio"]

HOLDS, FAILS, CORRECTED = "holds", "does not hold", "holds with a correction"
#: The verdict of a claim whose measurement raised or gave no finite number for a quantity its
#: criterion reads: registered for no claim, so `checked` and `pytest verify` refuse it.
UNMEASURED = "not measured"


class Unmeasured(ValueError):
    """A quantity a criterion reads is missing or not a finite number."""


def _number(x):
    x = float(x)
    return f"{x:,.0f}" if abs(x) < 1e6 and (x.is_integer() or abs(x) >= 100) else f"{x:.3g}"


@dataclass(frozen=True)
class Bound:
    """A test on one measured quantity: ``lo <= value <= hi`` (``<`` where ``strict``);
    ``None`` leaves that side open.  ``quantity`` names the value in the dict a
    claim's measurement returns, and is how the table shows it."""

    quantity: str
    lo: float | None = None
    hi: float | None = None
    strict: bool = False

    def holds(self, values):
        """Whether ``values[quantity]`` lies within the bound (KeyError if it was not measured)."""
        x = values[self.quantity]
        below = (lambda a, b: a < b) if self.strict else (lambda a, b: a <= b)
        return (self.lo is None or below(self.lo, x)) and (self.hi is None or below(x, self.hi))

    def __str__(self):
        le, ge = ("<", ">") if self.strict else ("≤", "≥")
        if self.lo is not None and self.lo == self.hi:
            return f"{self.quantity} = {_number(self.lo)}"
        if self.lo is not None and self.hi is not None:
            return f"{_number(self.lo)} {le} {self.quantity} {le} {_number(self.hi)}"
        if self.lo is not None:
            return f"{self.quantity} {ge} {_number(self.lo)}"
        return f"{self.quantity} {le} {_number(self.hi)}"


@dataclass(frozen=True)
class Criterion:
    """A claim's decision rule as data: ``cases`` is a tuple of (verdict, bounds); the
    first case whose bounds all hold gives the verdict, else ``otherwise``."""

    cases: tuple
    otherwise: str = FAILS

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
                finite = math.isfinite(x) and not isinstance(x, complex)
            except TypeError:
                finite = False
            if not finite:
                raise Unmeasured(f"{quantity} measured {x!r:.80}: a verdict needs a finite number")
        for verdict, bounds in self.cases:
            if all(b.holds(values) for b in bounds):
                return verdict
        return self.otherwise

    def __str__(self):
        return "; ".join([f"{verdict} if {' and '.join(map(str, bounds))}" for verdict, bounds in self.cases]
                         + [f"otherwise {self.otherwise}"])


#: How the register reads "≈ x", "~x", "near x": x's order of magnitude, within half a decade either way.
ABOUT = 10 ** 0.5


def about(quantity, x, lo=True, hi=True):
    """`Bound`: ``quantity`` about ``x`` (within a factor `ABOUT`), from below (``lo``), above (``hi``) or both."""
    return Bound(quantity, x / ABOUT if lo else None, x * ABOUT if hi else None)


def rule(*cases, otherwise=FAILS):
    """`Criterion` from alternating verdicts and bounds: ``rule(HOLDS, b1, CORRECTED, (b2, b3))``."""
    pairs = [(cases[i], cases[i + 1] if isinstance(cases[i + 1], tuple) else (cases[i + 1],))
             for i in range(0, len(cases), 2)]
    return Criterion(tuple(pairs), otherwise)


@dataclass(frozen=True)
class Claim:
    """One checkable claim of the seed.

    ``where`` is the seed section or cell, ``quote`` the claim in the seed's
    words (short), ``measurement`` how it is tested, ``registered`` the verdict
    on record; ``quantify()`` returns (measured text, {quantity: number}) and
    ``criterion`` decides the verdict from those numbers.
    """

    id: str
    where: str
    quote: str
    measurement: str
    registered: str
    quantify: Callable[[], tuple]
    criterion: Criterion

    def measure(self):
        """(measured text, computed verdict): the measurement, decided by the criterion; or
        ("not measured: <the error>", `UNMEASURED`) when measuring or deciding raised, so
        that one broken claim neither passes nor hides the verdicts of the others."""
        try:
            text, values = self.quantify()
            return text, self.criterion.decide(values)
        except Exception as e:          # noqa: BLE001 - reported as the claim's verdict, never passed
            return f"not measured: {type(e).__name__}: {e}"[:300], UNMEASURED


@lru_cache(maxsize=None)
def _ucurve():
    from renderer.ucurve import measure
    return measure()


@lru_cache(maxsize=None)
def _errata():
    from .seed_errata import measure_all
    return measure_all()


@lru_cache(maxsize=None)
def _frames(field="ridges", beta=0.35, eps=1e-3, size=128):
    scene = DRAFT_SCENE.replace(height_field=field, beta=beta, eps=eps)
    return render(scene, size, size, gradient="central"), render(scene, size, size)


def _on(frame, scene=None):
    """' (label)': the scene and size of the frame a measurement used (`chapter.theorems.frame_label`),
    read from the frame itself.  ``frame``: a `renderer.Frame` or `renderer.GBuffer`; ``scene``:
    the scene to name when the frame carries none (a GBuffer) or a sweep varies it."""
    height, width = frame.chamber.shape
    return f" ({frame_label(scene or frame.scene, width, height)})"


def _err_at(eps):
    c = _ucurve()
    k = np.argmin(np.abs(np.log10(c.eps) - np.log10(eps)))
    if not abs(c.eps[k] / eps - 1) <= 0.01:
        raise ValueError(f"eps={eps!r}: the U-curve's nearest step is {c.eps[k]:.3g}; a claim at a step is "
                         "measured within 1 % of it")
    return float(c.error[k])


def relative_error_at(eps):
    """The central difference's relative error in hᵤ on the U-curve of Cell 2 (`renderer.ucurve.measure`'s
    default curve) at ``eps``, its step within 1 % of it: what the register's claims about 1e-9 and 1e-11
    decide on.

    Raises
    ------
    ValueError
        If no step of the curve lies within 1 % of ``eps``, naming it and the nearest step.
    """
    return _err_at(eps) / abs(_ucurve().derivative)


def _h3_scale():
    value = (np.pi * 8.0) ** 3
    return f"$(\\pi k_u)^3 =$ {value:,.0f} at $k_u = 8$", {"(π kᵤ)³": value}


def _truncation_until():
    c = _ucurve()
    return (f"the predicted optimal step is {c.eps_model:.1e}, from $h'''$ and the unit roundoff "
            f"alone (the measured curve's lowest point is {c.eps_measured_min:.1e})",
            {"model optimum ε": c.eps_model})


def _drowns_below_1e9():
    rel = relative_error_at(1e-9)
    return (f"the quotient's relative error at a step of 1e-9 is {rel:.1e}: {int(-np.log10(rel))} digits still right",
            {"relative error at ε = 1e-9": rel})


def _cell2_minimum():
    from .accuracy import optima
    opt = optima()["sine"]
    return (f"the fitted optimal step is {opt['eps_fitted']:.1e}, where the model's error is "
            f"{opt['error_at_fitted']:.1e}", {"fitted optimum ε": opt["eps_fitted"]})


def _orientation():
    from proofs.frame import _orientation_value
    value = int(_orientation_value())
    return (f"$(e_\\theta \\times e_\\varphi)\\cdot N = {value}$: the frame is left-handed about the outward normal",
            {"(eθ × eφ)·N": value})


def _flips_zero():
    from proofs.no_boundary import render_flips
    frames, values, masks, _ = render_flips()
    return (f"over {frames} independent G-buffers, {values} geometry values (chamber, $t$, $P$, $N$) and {masks} "
            "reach-mask pixels differ", {"geometry values differing": values, "reach-mask pixels differing": masks})


def _shadow_curves_unchanged():
    leak = _errata()["terminator-leak"]["leak_pixels_default"]
    return (f"true of the renderer, not of the draft's code: its shading lights {leak:,} (pixel, light) pairs "
            "past the terminator", {"pairs lit past the terminator": leak})


def _cell1_ripples():
    m = _errata()["sphere-b-quadratic"]
    return (f"the draft's sphere B covers {m['seed_pixels_b']:,} of the {m['pixels']:,} pixels, so sphere A "
            "never appears", {"share of the frame on the draft's sphere B": m["seed_pixels_b"] / m["pixels"]})


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
    off-band mean ~ eps^p over all the steps (``rms_slope``, ``off_slope``); the
    crease ratio at the default step (``ratio``, on-band over off-band mean); and
    the frame's ``label``.
    """
    from .store import measured
    return measured("census", _census, size=CENSUS_SIZE)


def _census(size):
    scene = DRAFT_SCENE
    symbolic = render(scene, size, size)
    on_a = symbolic.chamber == SPHERE_A
    uv = gbuffer(scene, size, size).uv[on_a]
    # Chart distance of each sphere-A pixel to the nearest ridge zero line, in u or in v.
    dist = np.minimum(np.abs(uv[:, 0] * scene.k_u - np.rint(uv[:, 0] * scene.k_u)) / scene.k_u,
                      np.abs(uv[:, 1] * scene.k_v - np.rint(uv[:, 1] * scene.k_v)) / scene.k_v)
    out = {k: [] for k in ("max", "rms", "on_band", "off_band", "flips", "straddling")}
    for eps in CENSUS_STEPS:
        led = compare(render(scene.replace(eps=eps), size, size, gradient="central"), symbolic)
        for key, value in (("max", led.max_abs), ("rms", led.rms), ("on_band", led.mean_abs_kink),
                           ("off_band", led.mean_abs_off_kink), ("flips", led.flips),
                           ("straddling", int(np.count_nonzero(dist < eps)))):
            out[key].append(value)
    logs = np.log(CENSUS_STEPS)
    default = CENSUS_STEPS.index(scene.eps)
    return dict(out, steps=list(CENSUS_STEPS),
                rms_slope=float(np.polyfit(logs, np.log(out["rms"]), 1)[0]),
                off_slope=float(np.polyfit(logs, np.log(out["off_band"]), 1)[0]),
                ratio=out["on_band"][default] / out["off_band"][default],
                label=frame_label(scene, size, size))


def _census_slope():
    c = census()
    return (f"the RMS slope is {c['rms_slope']:.2f}, the off-band slope {c['off_slope']:.2f} (fitted over "
            f"the six steps, {c['label']}): only the pixels off the crease band descend at second order",
            {"RMS slope": c["rms_slope"], "off-band slope": c["off_slope"]})


def _cell3_runs():
    """The draft's Cell 3 reduces |num - sym| over the pixels both maps put on
    sphere A; with its sphere B (erratum sphere-b-quadratic) no pixel of the draft's code's
    map is on A, against this renderer's count on its frame of the same scene."""
    from .seed_errata import seed_chamber
    code = seed_chamber(256)
    on_a = (code & 3) == SPHERE_A
    num, sym = _frames(size=256)
    same = np.ones(code.shape, bool)          # its code_e == code_sym: two maps of one scene
    try:
        np.abs(num.image - sym.image)[same & on_a].max()
    except ValueError as error:
        return (f"the cell crashes before its first row: in the draft's code its sphere A covers "
                f"{np.count_nonzero(on_a)} of the {code.size:,} pixels, where this renderer's frame of the same "
                f"scene has {np.count_nonzero(sym.chamber == SPHERE_A):,} on sphere A{_on(sym)}, and a maximum "
                "over no pixels raises ValueError", {"rows computed": 0})
    return "the sweep's first row is computed" + _on(sym), {"rows computed": 1}


def _census_flips():
    c = census()
    return (f"{sum(c['flips'])} flips over the six steps ({c['label']})", {"flips": sum(c["flips"])})


def crease_band_ratio():
    """The crease ratio of the census at the default step (`census`): mean |ΔI| on the
    crease band over the mean off it, with the two means (``on``, ``off``) and the label."""
    c = census()
    default = c["steps"].index(DRAFT_SCENE.eps)
    return dict(on=c["on_band"][default], off=c["off_band"][default], ratio=c["ratio"], label=c["label"])


def _kink_order_of_magnitude():
    band = crease_band_ratio()
    return (f"the crease ratio is {band['ratio']:,.0f}, far more than an order of magnitude: mean "
            f"$\\lvert\\Delta I\\rvert$ {band['on']:.1e} on the band against {band['off']:.1e} off it at "
            f"the default step ({band['label']})",
            {"on/off ratio": band["ratio"]})


def _evals():
    """Values of h per pixel in the kernel's formulas: the stencil points at which
    `formulas.CENTRAL` evaluates h, against none in `formulas.GRADIENT` (counted
    from the sympy objects the kernel is generated from, `gradient_methods.evaluations`)."""
    from .gradient_methods import evaluations
    central, exact = evaluations("ridges", "central"), evaluations("ridges", "exact")
    return (f"the central stencil evaluates $h$ {central.h:g} times per pixel ({central.trig:g} sines once "
            f"common factors are shared); the exact gradient evaluates $h$ {exact.h:g} times, and its "
            f"generated code calls {exact.trig:g} sines and cosines",
            {"values of h, central": central.h, "values of h, exact": exact.h})


def _cell4_counter():
    """The draft's Cell 4 counting, in its structure: a counter wraps h, but the
    gradients it times call the unwrapped h, so both counts stay 0."""
    class Counter:
        n = 0

    def h(u, v):
        return float(pointwise.height("ridges", np.array([u]), np.array([v]), 8.0, 4.0)[0])

    def h_counted(u, v):
        Counter.n += 1
        return h(u, v)

    def central(u, v, height, eps=1e-3):
        return ((height(u + eps, v) - height(u - eps, v)) / (2 * eps),
                (height(u, v + eps) - height(u, v - eps)) / (2 * eps))

    counts = []
    for gradient in (lambda: central(0.3, 0.4, h), lambda: pointwise.exact_gradient("ridges", 0.3, 0.4, 8.0, 4.0),
                     lambda: central(0.3, 0.4, h_counted)):
        Counter.n = 0
        gradient()
        counts.append(Counter.n)
    numeric, exact, wired = counts
    return (f"the counter prints {numeric} and {exact}: the gradients call the unwrapped $h$, so the wrapper "
            f"never runs (wired into the central gradient it counts {wired})",
            {"count printed, numeric": numeric, "count printed, exact": exact})


def _stacking():
    """Bump under a pixel filter: a 4 x 4 box filter (a 512² render averaged to
    128²) against one sample per pixel, on sphere-A pixels whose 16 samples
    are all on A, with the bump and without it."""
    err = {}
    for beta in (0.35, 0.0):
        scene = DRAFT_SCENE.replace(beta=beta)
        fine, one = render(scene, 512, 512).image, render(scene, 128, 128)
        box = fine.reshape(128, 4, 128, 4, 3).mean(axis=(1, 3))
        all_a = (render(scene, 512, 512, kink=False, grad=False).chamber == SPHERE_A).reshape(128, 4, 128, 4).all(axis=(1, 3))
        d = (box - one.image)[all_a & (one.chamber == SPHERE_A)]
        err[beta] = float(np.sqrt(np.mean(d ** 2)))
    ratio = err[0.35] / err[0.0]
    return (f"no new integral, but a harder integrand: one sample per pixel misses the 4 × 4 box filter "
            f"by RMS {err[0.35]:.1e} with the bump, {err[0.0]:.1e} without{_on(one, DRAFT_SCENE)}",
            {"one-sample error, with / without the bump": ratio})


def _blinn_exact():
    """Blinn's normal against the displaced sphere's, both in slopes (proofs/blinn.py):
    equal to first order in beta (theorem blinn-perturbation); the second order differs."""
    import sympy as sp

    from renderer import formulas as F

    from proofs.blinn import BLINN, SURFACE, phi, theta
    at = {F.R: 1.0, F.beta: 0.35, F.h: 0.5, F.h_u: 3.0, F.h_v: -2.0, phi: 1.1, theta: 0.4}
    gap = max(abs(float(sp.N(e.subs(at)))) for e in (BLINN - SURFACE))
    first = max(abs(float(sp.N(e.subs(at)))) for e in (BLINN - SURFACE).diff(F.beta).subs(F.beta, 0))
    return (f"derived from the surface, but exact only to first order in $\\beta$: at $\\beta = 0.35$ "
            f"($h = 0.5$, $h_u = 3$, $h_v = -2$, $\\varphi = 1.1$) his slopes differ from the displaced "
            f"sphere's by {gap:.2e}, while their first-order terms agree exactly",
            {"slope gap": gap, "first-order gap": first})


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

    t_exact = best(lambda: pointwise.exact_gradient("ridges", u, v, 8.0, 4.0))
    t_central = best(lambda: pointwise.central_gradient("ridges", u, v, 8.0, 4.0, 1e-3))
    f_exact = best(lambda: render(DRAFT_SCENE, 128, 128), 7)
    f_central = best(lambda: render(DRAFT_SCENE, 128, 128, gradient="central"), 7)
    stage = t_central / t_exact
    central, exact = evaluations("ridges", "central"), evaluations("ridges", "exact")
    return (f"by count: the exact gradient calls {exact.trig:g} sines and cosines per pixel, the central "
            f"stencil {central.trig:g}; timed, deciding nothing, the central stage takes {stage:.1f} times as "
            f"long, the whole frame {f_central / f_exact:.2f} times{_on(g, DRAFT_SCENE)}",
            {"sin/cos calls, exact minus central": exact.trig - central.trig})


#: The draft's expected worst component error of its Cell 5 check ("~1e-9"): its criterion's centre,
#: and what the measured worst is compared with.
CELL5_EXPECTED = 1e-9


def _cell5_fd():
    rng, trials, step = np.random.default_rng(5), 2000, 1e-7      # the draft's check, as its cell runs it
    worst = 0.0
    for _ in range(trials):
        N = rng.normal(size=3)
        N /= np.linalg.norm(N)
        g = rng.normal(size=3) * 4.0
        M = N + 0.35 * g
        Np = M / np.linalg.norm(M)
        exact = (g - Np * (Np @ g)) / np.linalg.norm(M)
        M2 = N + (0.35 + step) * g
        worst = max(worst, float(np.abs(exact - (M2 / np.linalg.norm(M2) - Np) / step).max()))
    ratio = worst / CELL5_EXPECTED
    return (f"the draft's own check, a forward difference with step {_power(step)} over {trials:,} random cases, has a "
            f"worst component error of {worst:.1e}, about {float(f'{ratio:.2g}'):,.0f} times the draft's "
            f"expected {_power(CELL5_EXPECTED)}",
            {"worst component": worst})


def _power(x):
    """A power of ten as the draft writes it: 1e-9."""
    return re.sub(r"e([-+])0*", lambda m: "e" + m.group(1).replace("+", ""), f"{x:.0e}")


def _dn_1e12():
    from .accuracy import normal_beta_derivative_residual
    r = normal_beta_derivative_residual()
    return (f"the closed form's worst error is {r:.1e} against a 50-digit mpmath derivative, which the "
            "draft's forward difference cannot show", {"closed form's residual": r})


def _beta_order():
    from .accuracy import image_beta_order
    o = image_beta_order()
    return (f"the median order of the image's β-derivative is {o['median_slope']:.2f}, but its RMS order "
            f"{o['rms_slope']:.2f}: second order at most pixels, not where a clip or a max(0, ·) switches "
            f"({o['label']})", {"median order": o["median_slope"], "RMS order": o["rms_slope"]})


def _beta0():
    a, b = _frames(beta=0.0)
    d = float(np.abs(a.image - b.image).max())
    return (f"the two pipelines differ by at most {d:g} at $\\beta = 0$: exactly zero, since the gradient is "
            f"never used there{_on(b)}", {"max |ΔI|": d})


def _bump_nonzero():
    s = DRAFT_SCENE.replace(height_field="sine", beta=1.5)
    bumped = render(s, 128, 128)
    d = float(np.abs(bumped.image - render(s.replace(beta=0.0), 128, 128).image).mean())
    return (f"the sine bump at $\\beta = 1.5$ moves the frame by a mean $\\lvert\\Delta I\\rvert$ of {d:.3f}"
            + _on(bumped), {"mean |ΔI|": d})


def _cell6_truncation():
    a = compare(*_frames("sine", 1.5, 1e-3)).max_abs
    b = compare(*_frames("sine", 1.5, 1e-4)).max_abs
    return (f"the largest $\\lvert\\Delta I\\rvert$ falls from {a:.1e} at a step of 1e-3 to {b:.1e} at 1e-4, "
            f"{a / b:.0f} times, as a second-order error should" + _on(_frames("sine", 1.5, 1e-3)[1]),
            {"max |ΔI| ratio": a / b})


def _noise_below_1e11():
    rel = relative_error_at(1e-11)
    return (f"the quotient's relative error at a step of 1e-11 is {rel:.1e}: digits lost, not noise",
            {"relative error at ε = 1e-11": rel})


def _crease_values():
    fd = float(pointwise.central_gradient("ridges", 1.0 / 8.0, 0.47, 8.0, 4.0, 1e-4)[0])
    ex = float(pointwise.exact_gradient("ridges", 1.0 / 8.0, 0.47, 8.0, 4.0)[0])
    return (f"the central difference gives {fd:+.1e} on the crease, but the exact gradient {ex:+.3f}: "
            f"$\\sin(\\pi k_u u)$ at the float nearest $1/k_u$ is not zero, so the sign picks a side",
            {"|central hᵤ|": abs(fd), "|exact hᵤ|": abs(ex)})


def _pole_pixels():
    g = gbuffer(DRAFT_SCENE, 256, 256)
    n = int(np.count_nonzero((g.chamber == SPHERE_A) & (np.hypot(g.N[..., 0], g.N[..., 1]) <= 1e-4)))
    return (f"{n} pixels use the fallback{_on(g, DRAFT_SCENE)}; the draft counts points of a grid of "
            "$N_z$ values unrelated to the image", {"fallback pixels": n})


def _sweep_best():
    a = {eps: compare(*_frames("sine", 0.35, eps)).rms for eps in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10)}
    best = min(a, key=a.get)
    return (f"of the steps tried, {best:.0e} gives the smallest RMS difference"
            + _on(_frames("sine")[1], DRAFT_SCENE.replace(height_field="sine")), {"best ε": best})


def _creases_part():
    num, sym = _frames()
    diff = np.abs(num.image - sym.image).max(axis=-1)
    big = diff > 1e-3
    share = float(np.count_nonzero(big & sym.kink) / max(1, np.count_nonzero(big)))
    return (f"{share:.0%} of the pixels whose $\\lvert\\Delta I\\rvert$ exceeds 1e-3 lie in the crease band"
            + _on(sym), {"share in the band": share})


def _rings_pinch():
    """rings: h_v = 2 pi k_v cos(2 pi k_v v) is nonzero at the pole while e_phi turns
    with theta, so N' points in opposite directions on opposite sides of the pole."""
    phi = 1e-3
    out = []
    for theta in (0.0, np.pi):
        N = np.array([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)])
        _, hv = pointwise.exact_gradient("rings", (theta + np.pi) / (2 * np.pi), phi / np.pi, 8.0, 4.0)
        _, e_phi = pointwise.tangent_frame(*N, np.sin(phi))
        M = N + 0.35 * float(hv) * np.array([float(c) for c in e_phi])
        out.append(M / np.linalg.norm(M))
    angle = float(np.degrees(np.arccos(np.clip(out[0] @ out[1], -1, 1))))
    return (f"with the draft's formula, $N'$ on opposite sides of the pole ($\\sin\\varphi = 10^{{-3}}$, "
            f"rings, $\\beta = 0.35$) differ by {angle:.0f}°", {"angle (degrees)": angle})


def _beta_zero_slider():
    flat = render(DRAFT_SCENE.replace(beta=0.0), 96, 96)
    b = render(DRAFT_SCENE.replace(beta=0.0, height_field="sine"), 96, 96, gradient="central").image
    n = int(np.count_nonzero(flat.image != b))
    return (f"at $\\beta = 0$, renders of two fields by the two pipelines differ in {n} values" + _on(flat),
            {"values differing": n})


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
          "optimum of the two-term model fitted to the measured U-curve (renderer/ucurve.py)", HOLDS,
          _cell2_minimum,
          rule(HOLDS, about("fitted optimum ε", 1e-6), CORRECTED, Bound("fitted optimum ε", 1e-8, 10 * 1e-6))),
    Claim("frame-aligned", "Cell 2", "`e_th × e_ph` … (unit, aligned with N)",
          "sympy: (eθ × eφ)·N", FAILS, _orientation,
          rule(HOLDS, Bound("(eθ × eφ)·N", 1, 1))),
    Claim("flips-zero", "§1, §3", "Chamber flips are zero by construction",
          "independent G-buffers across fields, β, ε, bump modes and pipelines (proofs/no_boundary.py)",
          HOLDS, _flips_zero,
          rule(HOLDS, (Bound("geometry values differing", 0, 0), Bound("reach-mask pixels differing", 0, 0)))),
    Claim("shadow-curves-unchanged", "§1", "Silhouettes, seams, shadow curves: unchanged",
          "terminator leak of the seed's shading rule (errata E2)", CORRECTED, _shadow_curves_unchanged,
          rule(CORRECTED, Bound("pairs lit past the terminator", lo=0, strict=True), otherwise=HOLDS)),
    Claim("cell1-ripples", "Cell 1, Expect", "sphere A's shading ripples with the height field",
          "the seed's sphere-B quadratic on the default frame (errata E1)", FAILS, _cell1_ripples,
          rule(FAILS, Bound("share of the frame on the draft's sphere B", 1, 1), otherwise=HOLDS)),
    Claim("census-slope", "Cell 3, Expect", "the ε-sweep table descending the truncation slope",
          "fitted slope of the census over ε = 1e-1 … 1e-6 (ridges, 256²)", CORRECTED, _census_slope,
          rule(HOLDS, Bound("RMS slope", lo=1.8, strict=True), CORRECTED, Bound("off-band slope", lo=1.8, strict=True))),
    Claim("census-flips", "Cell 3, Expect", "flips = 0 everywhere", "the census of Cell 3 (ridges, 256²)", HOLDS,
          _census_flips,
          rule(HOLDS, Bound("flips", 0, 0))),
    Claim("cell3-runs", "Cell 3", "the census as an epsilon sweep … print the table",
          "the draft's reduction over its own chamber map (its sphere B), 256²", FAILS, _cell3_runs,
          rule(HOLDS, Bound("rows computed", lo=1))),
    Claim("kink-order-of-magnitude", "Cell 3, Expect",
          "the kink-loci error an order of magnitude above the smooth interior",
          "mean |ΔI| on / off the crease band at ε = 1e-3, 256²", CORRECTED, _kink_order_of_magnitude,
          rule(HOLDS, about("on/off ratio", 10), CORRECTED, Bound("on/off ratio", lo=10 * ABOUT, strict=True))),
    Claim("four-evals-vs-one", "Cell 4, Expect; §6", "4 evals vs 1",
          "values of h in the kernel's formulas (sympy objects)", CORRECTED, _evals,
          rule(HOLDS, (Bound("values of h, central", 4, 4), Bound("values of h, exact", 1, 1)),
               CORRECTED, (Bound("values of h, central", 4, 4), Bound("values of h, exact", 0, 0)))),
    Claim("cell4-counter", "Cell 4", "h-evals per numeric gradient … per symbolic gradient",
          "the draft's counting scheme, run: a counter around h, gradients calling h", FAILS, _cell4_counter,
          rule(HOLDS, (Bound("count printed, numeric", 4, 4), Bound("count printed, exact", 1, 1)))),
    Claim("stacking", "§6, Stacking", "bump composes under Ch. 6's filter … no new integral, ever",
          "4 × 4 box filter against one sample per pixel, with and without the bump (128²)", CORRECTED,
          _stacking,
          rule(CORRECTED, Bound("one-sample error, with / without the bump", lo=2, strict=True), otherwise=HOLDS)),
    Claim("blinn-exact", "§8", "Blinn computed his perturbation exactly",
          "Blinn's slopes against the displaced sphere's, exact at β = 0.35", CORRECTED, _blinn_exact,
          rule(CORRECTED, (Bound("slope gap", lo=1e-6, strict=True), Bound("first-order gap", hi=1e-12, strict=True)), HOLDS, Bound("slope gap", hi=1e-12))),
    Claim("symbolic-not-slower", "Cell 4, Expect", "the symbolic column at or under the numeric",
          "transcendental calls in the generated gradients; timings beside", HOLDS, _timing,
          rule(HOLDS, Bound("sin/cos calls, exact minus central", hi=0))),
    Claim("cell5-fd-1e-9", "Cell 5, Expect", "~1e-9 worst component on the normal derivative",
          "the seed's forward-difference check over 2,000 trials", FAILS, _cell5_fd,
          rule(HOLDS, about("worst component", CELL5_EXPECTED))),
    Claim("dn-verified-1e-12", "§3, §6", "∂N′/∂β … verified to 10⁻¹²",
          "float64 closed form against mpmath at 50 digits", CORRECTED, _dn_1e12,
          rule(CORRECTED, Bound("closed form's residual", hi=1e-12, strict=True))),
    Claim("beta-quadratic", "Cell 5, Expect", "clean quadratic convergence — 100× per decade",
          "fitted order of the image's central β-derivative (lab/accuracy.py)", CORRECTED, _beta_order,
          rule(HOLDS, (Bound("median order", 1.8, 2.2), Bound("RMS order", 1.8, 2.2)), CORRECTED, Bound("median order", 1.8, 2.2))),
    Claim("beta0-1e-16", "Cell 6, Expect", "β=0 agreement at ~1e-16",
          "numeric vs symbolic at β = 0", HOLDS, _beta0,
          rule(HOLDS, about("max |ΔI|", 1e-16, lo=False))),
    Claim("bump-nonzero", "Cell 6, Expect", "the β=1.5 bump demonstrably nonzero",
          "mean |ΔI| between β = 1.5 and β = 0", HOLDS, _bump_nonzero,
          rule(HOLDS, Bound("mean |ΔI|", lo=1e-2, strict=True))),
    Claim("cell6-truncation", "Cell 6, Expect", "the FD error sitting at its truncation-slope value",
          "max |ΔI| at ε = 1e-3 and 1e-4 (sine, β = 1.5)", HOLDS, _cell6_truncation,
          rule(HOLDS, about("max |ΔI| ratio", 10 ** 2))),
    Claim("noise-below-1e-11", "Cell 7a", "below eps ~ 1e-11 the difference quotient is noise",
          "relative error at ε = 1e-11", FAILS, _noise_below_1e11,
          rule(HOLDS, about("relative error at ε = 1e-11", 1.0, hi=False))),
    Claim("crease-fd-zero", "Cell 7b, Expect", "the crease showing FD≈0 vs exact sign-ambiguity",
          "the central and exact hᵤ at u = 1/kᵤ as float64 represents it", CORRECTED, _crease_values,
          rule(CORRECTED, (Bound("|central hᵤ|", hi=1e-6, strict=True), Bound("|exact hᵤ|", lo=0, strict=True)), HOLDS, Bound("|central hᵤ|", hi=1e-6, strict=True))),
    Claim("pole-pixels", "Cell 7c", "fallback engages below 1e-4. Pixels affected at 256²: …",
          "count from the rendered geometry", FAILS, _pole_pixels,
          rule(HOLDS, Bound("fallback pixels", lo=1))),
    Claim("try-sweep", "§4 Try this (1)", "bottoms out near 1e-6, and brightens again past 1e-8",
          "RMS |ΔI| on A for the sine field over ε", HOLDS, _sweep_best,
          rule(HOLDS, about("best ε", 1e-6))),
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


#: Each claim's decision rule, as the table shows it (generated from the `Criterion` it applies).
CRITERIA = {c.id: str(c.criterion) for c in CLAIMS}


def evaluate():
    """[(claim, measured text, computed verdict)] for every claim."""
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

    Raises
    ------
    ClaimChanged
        Naming every claim whose verdict changed, with its measurement.
    """
    if results is None:
        from .store import measured
        by_id = {c.id: c for c in CLAIMS}
        results = [(by_id[i], m, v) for i, m, v in measured("claims-register", _register)]
    changed = [f"{c.id}: registered {c.registered!r}, computed {v!r} ({m})"
               for c, m, v in results if v != c.registered]
    if changed:
        raise ClaimChanged("; ".join(changed) + " (edit the register in lab/claims.py with the change)")
    return results
