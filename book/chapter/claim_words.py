"""The book's words about the draft's claims: one sentence per claim, formatted from the
values its measurement returns (`lab.claims.Claim.measure`), and the wording of the rules
that decide the verdicts (`lab.claims.Criterion`, shown in §6's register).

`lab.claims` holds the draft's own words (``quote``, ``where``), the numbers and the rules'
structure; the sentences a reader sees are written here.  A template reads a value by its
key: a quantity a rule decides on (``{on/off ratio:,.0f}``) or a context value
(``{trials:,}``); ``{frame}`` is the label of the frame the values carry (``scene``,
``size``: `chapter.labels.frame_label`).
"""

from __future__ import annotations

import re

from lab.claims import CONVERGES, CORRECTED, FAILS, HOLDS

from .labels import frame_label

__all__ = ["SENTENCES", "WORDS", "measured_text", "rule_text", "bound_text", "power"]

#: How a verdict reads (each is a term of the glossary).
WORDS = {HOLDS: "Holds", CORRECTED: "Holds with a correction", FAILS: "Does not hold"}

_DI = "$\\lvert\\Delta I\\rvert$"

#: Claim id -> its sentence, formatted from the claim's values (see the module's docstring).
SENTENCES = {
    "h3-scale": "$(\\pi k_u)^3 =$ {(π kᵤ)³:,.0f} at $k_u = {k_u:g}$",
    "truncation-until-1e-6": "the model-optimal step ε* is {model optimum ε:.1e}, from $h'''$, $h$, $u h'$ and "
                             "the unit roundoff",
    "roundoff-drowns-1e-9": "the quotient's relative error at a step of {step_shown} is "
                            "{relative error at ε = 1e-9:.1e}: {digits} digits still right",
    "cell2-minimum": "the fitted optimal step ε̂ is {fitted optimum ε:.1e}, where the fitted model's error is {error:.1e}; "
                     "from a step of {top step:.0e} to {bottom step:.0e} the relative error grows "
                     "{error growth over the two decades:.0f}-fold",
    "frame-aligned": "$(e_\\theta \\times e_\\varphi)\\cdot N = {(eθ × eφ)·N}$: the frame is left-handed about "
                     "the outward normal",
    "flips-zero": "over {gbuffers} independent {{term}}`G-buffers <G-buffer>`, {geometry values differing} geometry values (chamber, $t$, "
                  "$P$, $N$) and {reach-mask pixels differing} reach-mask pixels differ",
    "shadow-curves-unchanged": "true of the renderer ({G-buffer values moved} G-buffer values move), not of the "
                               "draft's shading rule: on this renderer's geometry it lights "
                               "{pairs lit past the terminator:,} (pixel, light) pairs past the geometric terminator",
    "cell1-ripples": "the draft's sphere B covers {pixels_b:,} of the {pixels:,} pixels and its sphere A "
                     "{draft's sphere-A pixels:,}: sphere A never appears",
    "census-slope": "the RMS slope is {RMS slope:.2f}, the off-band slope {off-band slope:.2f} (fitted over the "
                    "{steps} steps, {frame}): only the pixels off the crease band descend at second order",
    "census-flips": "{flips} flips over the {steps} steps ({frame})",
    "cell3-runs": "the cell crashes before its first row: the draft's code puts {code_pixels_a} of the "
                  "{pixels:,} pixels on its sphere A, where this renderer's frame of the same scene has "
                  "{pixels_a:,} ({frame}), and a maximum over no pixels raises {error}",
    "cell3-runs/ran": "the sweep's first row is computed ({frame})",
    "kink-order-of-magnitude": "the crease ratio is {on/off ratio:,.0f}, far more than an order of magnitude: mean "
                               f"{_DI} {{on:.1e}} on the band against {{off:.1e}} off it at the default step "
                               "({frame})",
    "four-evals-vs-one": "the central stencil evaluates $h$ {values of h, central:g} times per pixel "
                         "({trig_central:g} sines once common factors are shared); the exact gradient evaluates $h$ "
                         "{values of h, exact:g} times, and its generated code calls {trig_exact:g} sines and cosines",
    "cell4-counter": "the counter prints {count printed, numeric} and {count printed, exact}: the gradients call the "
                     "unwrapped $h$, so the wrapper never runs (wired into the central gradient it counts {wired})",
    "stacking": "no new integral, but a harder integrand: one sample per pixel misses a {box sides[0]} × {box sides[0]} "
                "box filter (Ch. 6's) by RMS {bumped:.1e} with the bump, {flat:.1e} without, and a {box sides[1]} × "
                f"{{box sides[1]}} box leaves {{{CONVERGES}:.0%}} of that miss ({{flat_2x2:.0%}} without; {{frame}})",
    "blinn-exact": "read as exact in $\\beta$ (how he evaluated $F_u$, $F_v$ is not measured here): derived from the "
                   "surface, but exact only to first order in $\\beta$: at $\\beta = {point[beta]:g}$ "
                   "($h = {point[h]:g}$, $h_u = {point[h_u]:g}$, $h_v = {point[h_v]:g}$, $\\varphi = {point[phi]:g}$) "
                   "his slopes differ from the displaced sphere's by {slope gap:.2e}, while their first-order terms "
                   "agree exactly",
    "symbolic-not-slower": "by count: the exact gradient calls {trig_exact:g} sines and cosines per pixel, the central "
                           "stencil {trig_central:g}; timed, deciding nothing, the central stage takes "
                           "{stage_ratio:.1f} times as long as the exact one, the whole frame {frame_ratio:.2f} times "
                           "({frame})",
    "cell5-fd-1e-9": "the draft's own check, a forward difference with step {step_shown} over {trials:,} random cases, "
                     "has a worst component error of {worst component:.1e}, about {ratio_shown:,.0f} times the "
                     "draft's expected {expected_shown}",
    "dn-verified-1e-12": "the closed form's worst error is {closed form's worst error:.1e} against a {digits}-digit mpmath "
                         "derivative; the draft's forward-difference check errs by up to "
                         "{draft's check's worst error:.1e}",
    "beta-quadratic": "the median order of the image's β-derivative is {median order:.2f}, but its RMS order "
                      "{RMS order:.2f}: second order at most pixels, not where a clip or a max(0, ·) switches "
                      "({frame})",
    "beta0-1e-16": "the two pipelines differ by at most {max |ΔI|:g} at $\\beta = 0$: exactly zero, since the "
                   "gradient is never used there ({frame})",
    "bump-nonzero": f"the bump moves the frame by a mean {_DI} of {{mean |ΔI|:.3f}} ({{frame}})",
    "cell6-truncation": f"the largest {_DI} falls from {{coarse:.1e}} at a step of {{coarse_step_shown}} to {{fine:.1e}} "
                        "at {fine_step_shown}, {max |ΔI| ratio:.0f} times, as a second-order error should ({frame})",
    "noise-below-1e-11": "the quotient's relative error at a step of {step_shown} is "
                         "{relative error at ε = 1e-11:.1e}: digits lost, not noise",
    "crease-fd-zero": "the central difference at a step of {step_shown} gives {central:+.1e} on the crease, but the exact gradient "
                      "{exact:+.3f}: float64's $\\sin(\\pi k_u u)$ at $u = 1/k_u$ is the sine of $\\pi$ rounded, not zero, "
                      "so the sign "
                      "picks a side",
    "pole-pixels": "{fallback pixels} pixels lie inside the draft's fallback disc ({frame}); the draft counts points of a grid of $N_z$ "
                   "values unrelated to the image",
    "try-sweep": f"of the simulator's half-decade steps, the image-best step (least RMS {_DI} over sphere A) is "
                 "{best ε:.0e}, and from {from:.0e} down to {to:.0e} the RMS grows {RMS growth past 1e-8:.1e} times "
                 "({frame})",
    "try-creases": f"{{share in the band:.0%}} of the pixels whose {_DI} exceeds {{threshold_shown}} lie in the "
                   "crease band ({frame})",
    "try-pinch": "with the draft's formula, $N'$ on opposite sides of the pole ($\\sin\\varphi = {sin_phi:g}$, "
                 "{field}, $\\beta = {beta:g}$) differ by {angle (degrees):.0f}°; the displaced "
                 "sphere's, by {displaced sphere's angle (degrees):.0f}°",
    "try-beta0": "at $\\beta = 0$, renders of two fields by the two pipelines differ in {values differing} values "
                 "({frame})",
}


def power(x):
    """``x`` (a float) to one significant digit as the draft writes a power of ten: 1e-9, 3e-6."""
    return re.sub(r"e([-+])0*", lambda m: "e" + m.group(1).replace("+", ""), f"{x:.0e}")


def measured_text(claim_id, values) -> str:
    """The book's sentence for the measurement ``values`` (a dict, `lab.claims.Claim.measure`)
    of the claim ``claim_id``, without the verdict.

    Raises
    ------
    KeyError
        If ``claim_id`` has no sentence in `SENTENCES`, or the sentence reads a value that
        ``values`` lacks (naming it).
    """
    if claim_id not in SENTENCES:
        raise KeyError(f"claim_id must be one of {sorted(SENTENCES)}, got {claim_id!r}")
    v = dict(values)
    if "scene" in v:
        v["frame"] = frame_label(v["scene"], *v["size"])
    for key in [k for k in v if k.endswith("step") or k in ("expected", "threshold")]:
        v[f"{key}_shown"] = power(v[key])                       # a power of ten as the draft writes it
    if "ratio" in v:
        v["ratio_shown"] = float(f"{v['ratio']:.2g}")           # "about 16,000 times": two digits
    template = SENTENCES[claim_id + "/ran"] if v.get("rows computed") == 1 else SENTENCES[claim_id]
    return template.format_map(v)


def _number(x):
    x = float(x)
    return f"{x:,.0f}" if abs(x) < 1e6 and (x.is_integer() or abs(x) >= 100) else f"{x:.3g}"


def bound_text(bound) -> str:
    """A `lab.claims.Bound` as §6's register shows it: ``1 ≤ ratio ≤ 2``, ``flips = 0``,
    ``error < 2.5e-07`` (numbers in full from 100 to a million, else 3 significant digits)."""
    le, ge = ("<", ">") if bound.strict else ("≤", "≥")
    q, lo, hi = bound.quantity, bound.lo, bound.hi
    if lo is not None and lo == hi:
        return f"{q} = {_number(lo)}"
    if lo is not None and hi is not None:
        return f"{_number(lo)} {le} {q} {le} {_number(hi)}"
    if lo is not None:
        return f"{q} {ge} {_number(lo)}"
    return f"{q} {le} {_number(hi)}"


def rule_text(criterion) -> str:
    """A `lab.claims.Criterion` as §6's register shows it: its cases in order, each a verdict
    and its bounds joined by "and", then the verdict otherwise, unless that is "does not hold"
    (`lab.claims.FAILS`), which the register states once for every rule."""
    default = [] if criterion.otherwise == FAILS else [f"otherwise {WORDS[criterion.otherwise].lower()}"]
    return "; ".join([f"{WORDS[verdict].lower()} if {' and '.join(map(bound_text, bounds))}"
                      for verdict, bounds in criterion.cases] + default)
