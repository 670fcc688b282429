"""The book's words about the errata of the draft's code (`lab.seed_errata.ERRATA`): each
erratum's title, what this renderer does instead, and its finding, a template formatted
from the erratum's measured dict.  The draft's own code (``seed``) and where it stands
(``where``) are data of `lab.seed_errata`."""

from __future__ import annotations

from lab.seed_errata import ERRATA

from .claim_words import power

__all__ = ["WORDS", "finding", "errata"]

#: Erratum id -> {"title", "correction" (this renderer's way), "finding" (str.format over the measured dict)}.
WORDS = {
    "sphere-b-quadratic": dict(
        title="Sphere B is intersected from the wrong origin",
        correction=r"$c = |O - C_B|^2 - r_B^2$ for the ray from the eye $O$, roots by the stable pair $q/a,\ c/q$ with $q = -(b + \operatorname{sign}(b)\sqrt{b^2 - ac})$ for $at^2 + 2bt + c = 0$",
        finding=(
            "In the default frame of {pixels:,} pixels every ray hits the draft's sphere B: it "
            "covers {seed_pixels_b:,} pixels where the true sphere covers {true_pixels_b:,}, so "
            "{chamber_flips:,} pixels change chamber and sphere A is not visible at all. Its "
            "'hit points' lie up to {off_surface_max:.3f} scene units ({off_surface_relative:.1f} "
            "radii) off the sphere."
        ),
    ),
    "terminator-leak": dict(
        title="Lights leak past the terminator of the bumped sphere",
        correction=r"a light reaches $P$ only if $N\cdot\omega_i > 0$ (geometric) and no blocker cuts the segment; $N'$ then only weights Lambert's term and the highlight",
        finding=(
            "At the default $\\beta$ the draft's rule and normal, on this renderer's geometry (E1 hides "
            "sphere A), light {leak_pixels_default:,} (pixel, light) "
            "pairs on sphere A whose geometric normal faces away from the light (Lambert term up "
            "to {leak_diffuse_max_default:.2f}); at $\\beta = {beta_large:g}$, {leak_pixels_beta_1_5:,}; at "
            "$\\beta = 0$, none. The lit region's boundary moves with $\\beta$, against the "
            "draft's own theorem."
        ),
    ),
    "specular-ungated": dict(
        title="The highlight is added where the surface faces away from the light",
        correction=r"the highlight is zero where $N'\cdot\omega_i \le 0$",
        finding=(
            "In the default frame {pixels:,} (pixel, light) pairs face away from the light yet "
            "receive a highlight; the largest is {max_specular_added:.1e}, far below one 8-bit level: "
            "invisible here, wrong in principle."
        ),
    ),
    "v-border-branch": dict(
        title="The border test of the v-difference fires in the interior",
        correction=r"the clamped span only at the border; elsewhere $2\varepsilon$, the quotient of §3's error model",
        finding=(
            "At a step of {steps_shown[0]} the branch fires at {fraction_interior[0]:.2%} of interior "
            "sphere-A pixels (relative change of the quotient up to {rel_change[0]:.1e}); at "
            "{steps_shown[1]} at {fraction_interior[1]:.0%} ({rel_change[1]:.1e}); at {steps_shown[2]} at "
            "{fraction_interior[2]:.0%} ({rel_change[2]:.1e}). Where it fires, the rounded span is "
            "the better divisor (it takes the arguments' rounding out): at {steps_shown[1]} its quotient is nearer the "
            "exact $h_v$ at {nearer[1]:.0%} of those pixels. The defect is the mix: rounding, not the border, "
            "picks each pixel's divisor, so no one error model describes the frame."
        ),
    ),
    "acos-pole": dict(
        title="The polar angle loses digits near the pole",
        correction=r"$\varphi = \operatorname{atan2}(\operatorname{hypot}(N_x, N_y), N_z)$ and $\sin\varphi = \operatorname{hypot}(N_x, N_y)$",
        finding=(
            "For unit normals with $\\sin\\varphi$ between 1e-8 and 1e-2 the relative error of "
            "$\\arccos N_z$ reaches {max_rel_error_acos:.1e} against mpmath; atan2 stays within "
            "{max_rel_error_atan2:.1e}."
        ),
    ),
    "fallback-orientation": dict(
        title="The pole fallback frame has the opposite orientation",
        correction="kept as the draft has it (the convention is the draft's); measured and disclosed",
        finding=(
            "$(e_\\theta \\times e_\\varphi)\\cdot N$ is {orientation_regular_min:.0f} on the "
            "regular frame (to rounding) and {orientation_fallback:+.0f} on the fallback at the north "
            "pole, which this camera faces ({orientation_fallback_south:+.0f} at the south): there the "
            "fallback pair is a reflection of the frame it replaces."
        ),
    ),
}


def finding(erratum_id, measured) -> str:
    """The finding of erratum ``erratum_id`` with its ``measured`` numbers (its dict) filled in.

    Raises
    ------
    KeyError
        If ``erratum_id`` has no words in `WORDS`, or the finding reads a number ``measured`` lacks.
    """
    if erratum_id not in WORDS:
        raise KeyError(f"erratum_id must be one of {sorted(WORDS)}, got {erratum_id!r}")
    shown = {"steps_shown": [power(x) for x in measured["steps"]]} if "steps" in measured else {}
    return WORDS[erratum_id]["finding"].format(**measured, **shown)


def errata(measured) -> str:
    """MyST markdown for §6's errata: one paragraph per erratum of `lab.seed_errata.ERRATA`, in order,
    numbered E1, E2, ...: its title, where the draft stands, the draft's code, this renderer's
    correction and the finding.  ``measured``: {erratum id: measured dict}
    (`lab.seed_errata.reproduced`).

    Raises
    ------
    KeyError
        If an erratum has no words or no measurement.
    """
    return "\n\n".join(f"**E{i}. {WORDS[e.id]['title']}** ({e.where}). The draft: {e.seed}. This renderer: "
                        f"{WORDS[e.id]['correction']}. {finding(e.id, measured[e.id])}"
                        for i, e in enumerate(ERRATA, start=1))
