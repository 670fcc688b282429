"""Check a built book: one value per quantity, under its name and under its words.

A quantity shown on several pages is glued under one name (``eps_fitted_sine``,
say) and computed once per build (`lab.store`).  This reads, for each page,
the notebook jupyter-cache holds for the page's current execution (the record
of that page accessed last: the build touches the record it uses) and fails,
naming the pages and values, if two pages glue different values under one name.

A quantity has one source however many names it has.  Every glued name is
registered with the quantity it shows: in `QUANTITIES` if the quantity has
another name or a value in the library, else in `ON_THE_PAGE`.  The names of one
quantity (its aliases) must show one value, and where the library holds the
quantity (a constant, a measurement of `lab` or `renderer`) that value must be
the library's, evaluated when this check runs (stored measurements are read from
the build's store).  A glued name registered nowhere fails, so a second name for
a quantity cannot appear without saying which quantity it shows; a registered
name that no page glues fails too.

Names are for code; a reader sees words.  `NAMED` gives each quantity the prose
names (the words it is called by, e.g. "RMS slope of the census").  In the built
HTML, wherever those words are followed in the same sentence by a number, that
number must be the glued value (to the digits shown): the same words cannot
carry two numbers, whether the number was glued, or written into a measurement's
text, or typed.  Each quantity's words must be met at least once, and no
quantity's words may contain another's.

A count the prose shows is written as the book writes numbers: 29,919, not 29919
(`bare_counts`; a four-digit number from 1900 to 2099 is read as a year), and
a number glued into prose is formatted with ',' (`unseparated_formats`) so that
a measurement that comes out larger on another machine is written so too.  A
negative number is written with the minus sign, −0.651, not a hyphen (`hyphen_minus`).

Usage: python book/check_glue.py [CACHE_DIR [HTML_DIR]]
       (defaults: book/_build/.jupyter_cache, and html/ beside it)
Exit status 0 if every check passes, 1 if not, 2 if there is no cache or no site.
"""

from __future__ import annotations

import ast
import importlib
import json
import math
import os
import re
import sys
from functools import lru_cache
from html.parser import HTMLParser
from pathlib import Path

MIME = "application/papermill.record/"

#: Glue name -> the words the prose calls that quantity by (lower case; matched
#: case-insensitively, in the text a reader sees outside maths and code).
NAMED = {
    "census_rms_slope": "rms slope",
    "census_off_slope": "off-band slope",
    "census_ratio": "crease ratio",
    "dn_residual": "closed form's worst error",
    "eps_fitted_sine": "fitted optimal step",
    "eps_model_sine": "model-optimal step",
    "ucurve_rel_1e9": "relative error at a step of 1e-9",
    "ucurve_rel_1e11": "relative error at a step of 1e-11",
    "beta_median_order": "median order",
    "beta_rms_order": "rms order",
    "tilt_chart": "median tilt of the draft's normal",
    "tilt_surface": "median tilt of the displaced sphere's normal",
}


def _lib(module):
    """A library module, imported when a source is evaluated."""
    return importlib.import_module(module)


@lru_cache(maxsize=None)
def _ucurve():
    """`renderer.ucurve.measure`'s default curve: the U-curve of Cell 2, whose fit gives the optimum."""
    return _lib("renderer.ucurve").measure()


def _crease_share(step, key="share"):
    """`lab.accuracy.crease_share`'s share of straddling stencils at ``step`` (``key``: "share_u", along u only)."""
    share = _lib("lab.accuracy").crease_share()
    return dict(zip(share["steps"], share[key]))[step]


#: The glued quantities with a value in the library or more than one name: quantity -> (its glue
#: names, its library value or None).  The library value is a callable evaluated when the check runs;
#: None where the pages compute the quantity from their own renders (its names must still agree).
QUANTITIES = {
    # The scene and the renderer's constants.
    "the draft's step": (("ix_eps", "s1_eps", "c6_coarse_step"), lambda: _lib("renderer").DRAFT_SCENE.eps),
    "the draft's amplitude": (("s1_beta", "s2_beta"), lambda: _lib("renderer").DRAFT_SCENE.beta),
    "sphere A's radius in the book's scene": (("s1_ex_radius",), lambda: _lib("renderer").Scene().radius_a),
    "the draft's frequency in u": (("s2_k_u", "s3_ku"), lambda: _lib("renderer").DRAFT_SCENE.k_u),
    "the draft's frequency in v": (("s2_k_v", "s3_kv"), lambda: _lib("renderer").DRAFT_SCENE.k_v),
    "the draft's height field": (("s2_field",), lambda: _lib("renderer").DRAFT_SCENE.height_field),
    "the simulator's opening step": (("s4_eps",), lambda: _lib("renderer.ledger").SIMULATOR_SCENE.eps),
    "the window's margin": (("s2_margin",), lambda: _lib("renderer.render").WINDOW_MARGIN),
    "the window's offset": (("s2_offset",), lambda: _lib("renderer.render").WINDOW_OFFSET),
    "the pole threshold of the frame": (("pole_sin_phi",), lambda: float(_lib("renderer.formulas").POLE_SIN_PHI)),
    "the draft's pole threshold (its Cell 7c)": (("draft_pole_sin_phi",), lambda: _lib("lab.claims").CELL7C_POLE_SIN_PHI),
    "the simulator's linear difference gain": (("s4_gain", "c3_gain"),
                                               lambda: _lib("renderer.ledger").DIFFERENCE_LINEAR_GAIN),
    "the simulator's log-scale black": (("s4_log_floor",),
                                        lambda: 10.0 ** _lib("renderer.ledger").DIFFERENCE_LOG_FLOOR),
    "the U-curve reference's digits": (("c2_digits", "s7_digits"), lambda: _lib("renderer.ucurve").DIGITS),
    "the accuracy references' digits": (("c5_digits",), lambda: _lib("lab.accuracy").DIGITS),
    "SciPy's rounds of Richardson's extrapolation": (("s3_scipy_rounds", "c4_scipy_rounds"), lambda: _lib("lab.gradient_methods").RICHARDSON_ROUNDS),
    "the amplitude of §1's diagram of normals": (("s1_normals_beta",), lambda: _lib("chapter.figures").NORMALS_BETA),
    # The U-curve of Cell 2: the fitted optimal step (of the model fitted to it), the model-optimal step.
    "the fitted optimal step": (("eps_fitted_sine",), lambda: _ucurve().eps_fitted),
    "the model-optimal step": (("eps_model_sine", "s3_ex_eps"), lambda: _ucurve().eps_model),
    "the U-curve's label": (("ucurve_label", "s3_ex_label"), lambda: _lib("chapter.labels").ucurve_label(
        "sine", _lib("lab.accuracy").optima()["sine"])),
    "the unit roundoff": (("s3_unit_roundoff",), lambda: _lib("renderer.ucurve").UNIT_ROUNDOFF),
    "the book's default step": (("s3_eps_default",), lambda: _lib("renderer").Scene().eps),
    "the rings field's model-optimal step": (("s3_rings_eps", "ex_rings_model"), lambda: _lib("lab.accuracy").optima()["rings"]["eps_model"]),
    "the rings field's model error at its model-optimal step": (
        ("s3_rings_err",), lambda: _lib("lab.accuracy").optima()["rings"]["error_model"]),
    "the fitted over the model-optimal step (sine)": (
        ("s3_fit_ratio",), lambda: _lib("lab.accuracy").optima()["sine"]["fitted_over_model"]),
    # What the crease does on ridges: the share of sphere-A pixels whose stencil straddles a crease.
    "the straddling share at a step of 1e-2": (("s3_share_e2",), lambda: _crease_share(1e-2)),
    "the straddling share at a step of 1e-3": (("s3_share_e3",), lambda: _crease_share(1e-3)),
    "the straddling share at a step of 1e-4": (("s3_share_e4",), lambda: _crease_share(1e-4)),
    "the straddling census's sphere-A pixels": (("s3_share_pixels",),
                                                lambda: _lib("lab.accuracy").crease_share()["pixels"]),
    "the straddling pixels along u at a step of 1e-4": (("s3_share_rays_e4",), lambda: round(
        _crease_share(1e-4, "share_u") * _lib("lab.accuracy").crease_share()["pixels"])),
    "the straddling pixels at a step of 1e-4": (("s3_share_n4",), lambda: dict(zip(
        *(_lib("lab.claims").census()[key] for key in ("steps", "straddling"))))[1e-4]),
    "the third derivative at the U-curve's point": (("s3_ex_h3",), lambda: abs(_ucurve().third_derivative)),
    "the relative error at a step of 1e-9": (("ucurve_rel_1e9",), lambda: _lib("lab.claims").relative_error_at(1e-9)),
    "the relative error at a step of 1e-11": (("ucurve_rel_1e11",),
                                              lambda: _lib("lab.claims").relative_error_at(1e-11)),
    # The census of Cell 3 and the measurements of Cell 5.
    "the census's RMS slope": (("census_rms_slope",), lambda: _lib("lab.claims").census()["rms_slope"]),
    "the census's off-band slope": (("census_off_slope",), lambda: _lib("lab.claims").census()["off_slope"]),
    "the census's crease ratio": (("census_ratio",), lambda: _lib("lab.claims").census()["ratio"]),
    "the census's step for its ratio": (("census_step",), lambda: _lib("lab.claims").census()["step"]),
    "the step of the draft's crease cell (Cell 7b)": (("s7_crease_step",), lambda: _lib("lab.claims").CELL7B_STEP),
    "Cell 4's error sample, pixels per field": (("c4_ref_pixels",),
                                                 lambda: _lib("lab.gradient_benchmark").FAST.reference_pixels),
    "the census's frame": (("c3_label",), lambda: _lib("chapter.labels").frame_label(
        _lib("lab.claims").census()["scene"], *_lib("lab.claims").census()["size"])),
    "the closed form's worst error": (("dn_residual",), lambda: _lib("lab.accuracy").normal_beta_derivative_residual()),
    "the median order of the β-derivative": (("beta_median_order",),
                                             lambda: _lib("lab.accuracy").image_beta_order()["median_slope"]),
    "the RMS order of the β-derivative": (("beta_rms_order",),
                                          lambda: _lib("lab.accuracy").image_beta_order()["rms_slope"]),
    "the β-derivative's frame": (("c5_label",), lambda: _lib("chapter.labels").frame_label(
        _lib("lab.accuracy").image_beta_order()["scene"], *[_lib("lab.accuracy").image_beta_order()["size"]] * 2)),
    # Cell 4's counts per pixel (from the sympy objects) and the complex step's step; Cell 5's β.
    "values of h per pixel in the sine field's central difference": (
        ("c4_central_h",), lambda: _lib("lab.gradient_methods").stencil_values("sine")),
    "values of h per pixel in the rings field's central difference": (
        ("c4_rings_h",), lambda: _lib("lab.gradient_methods").stencil_values("rings")),
    "sines and cosines per value of the sine field": (
        ("c4_h_trig",), lambda: _lib("lab.gradient_methods").height_work("sine").trig),
    "sines and cosines per pixel of the sine field's central difference": (
        ("c4_central_trig",), lambda: _lib("lab.gradient_methods").evaluations("sine", "central").trig),
    "sines and cosines per pixel of the sine field's exact gradient": (
        ("c4_exact_trig",), lambda: _lib("lab.gradient_methods").evaluations("sine", "exact").trig),
    "the benchmark's complex step": (("c4_cs_step",), lambda: _lib("lab.gradient_benchmark").FAST.complex_steps[0]),
    "the margin by which a method is called the fastest": (("c4_margin",),
                                                           lambda: _lib("chapter.benchmark").FASTEST_MARGIN - 1),
    "sines and cosines per pixel in XLA's program for the sine field's AD gradient": (
        ("c4_ad_trig",), lambda: _lib("lab.gradient_methods").evaluations("sine", "forward-mode AD").trig),
    "JAX's forward-mode slope of |x| at x = 0": (
        ("c4_abs_slope",), lambda: _lib("lab.gradient_methods").abs_slope_at_zero()[0]),
    "the U-curve's chart v": (("c4_crease_v", "s3_torus_v"), lambda: _lib("renderer.ucurve").SEED_POINT[1]),
    "the classic complex-step test function's point": (("c4_classic_x",),
                                                       lambda: _lib("lab.gradient_benchmark").TEST_FUNCTION.x),
    # A fast sine (§7): the ulp sample, its quantile, libm's sine.
    "the fast-math sample per function": (("s7_fm_points",), lambda: _lib("lab.fastmath").SAMPLES),
    "the fast-math quantile (%)": (("s7_fm_quantile",), lambda: 100 * _lib("lab.fastmath").QUANTILE),
    "libm's largest sine error (ulp)": (
        ("s7_fm_libm_sin",), lambda: _lib("lab.fastmath").ulp_table()["errors"]["numba"]["sin"]["max"]),
    "the chapter's amplitude": (("c5_fit_beta", "s3_torus_beta"), lambda: _lib("renderer").Scene().beta),
    "the rings field's image-best step (the simulator's scene and steps, 256 × 256)": (
        ("ex_rings_best",), lambda: _lib("lab.accuracy").image_best_step("rings", 256)["best"]),
    "the sine field's image-best step (the simulator's scene and steps, 256 × 256)": (
        ("s4_best",), lambda: _lib("lab.accuracy").image_best_step("sine", 256)["best"]),
    "the chapter's frequency in u": (("s3_torus_ku", "s3_band_ku"), lambda: _lib("renderer").Scene().k_u),
    "the crease band's half-width": (("s3_band_half",), lambda: float(_lib("renderer.formulas").KINK_BAND_HALF_WIDTH)),
    "the chapter's frequency in v": (("s3_torus_kv", "s3_band_kv"), lambda: _lib("renderer").Scene().k_v),
    # Counted on two pages from their own renders.
    "sphere A's pixels at 256 × 256": (("s1_pixels_a", "s2_count_1", "c4_pixels"), None),
}
#: Glued names each showing a quantity of its own that its page computes (from its renders, counts
#: and choices), with no second name and no value in the library to agree with.
ON_THE_PAGE = ("c6_fine_step", "c6_trunc_ratio", "c6_trunc_size", "ix_label", "s2_draft_diff", "s3_band_u", "s3_band_v", "s1_size", "s2_size", "c1_size", "s4_size", "s7_size",
               "ix_proved", "ix_verified", "ix_claims", "ix_holds", "ix_corrected", "ix_fails", "ix_errata",
               "tilt_chart", "tilt_surface", "s1_steep", "s1_steep_chart", "s1_steep_surface", "s1_away_chart",
               "s1_away_surface", "s1_flips_chart",
               "s1_flips_surface", "s1_ex_factor", "s2_count_0", "s2_count_2", "s2_count_3",
               "s4_label", "s4_field", "s4_max", "s4_rms", "s4_ulp_points", "s4_ulp_shift_e3", "s4_ulp_shift_e10", "s4_ulp_eps_e3",
               "s4_ulp_eps_e10", "c2_fp_u", "c2_fp_ratio", "c4_fastest", "c4_cs_ratio", "c4_ad_ratio", "c4_ad_err_ratio",
               "c4_ad_compile_ms", "c4_xla_ad_lo", "c4_xla_ad_hi", "c4_xla_numba_lo", "c4_xla_numba_hi", "c4_sine_points", "s7_fm_ulps", "s7_fm_floors", "s7_fm_drjit", "s7_fm_worst_ratio", "s7_fm_floor_rise", "s7_fm_off", "c6_beta",
               "c4_methods", "c4_classic_derivative", "c4_classic_table", "c4_classic_published", "c4_classic_cs_from",
               "c4_classic_cs_max", "c4_classic_ad_err", "c4_classic_eps_model", "c4_classic_eps_fitted",
               "c4_classic_central_step", "c4_classic_richardson_f", "c4_classic_fwd_step", "c4_classic_fwd_trunc",
               "c4_classic_fwd_err", "c4_classic_fwd_numpy", "c4_classic_rtol", "c4_classic_rich_first", "c4_classic_rich_nit", "c4_classic_rich_off", "c4_classic_rich_tight", "c4_classic_rich_tight_f",
               "c4_classic_rich_tight_err", "c4_classic_rich_tighter", "c4_classic_rich_tighter_f", "c4_classic_rich_tighter_err", "s2_field_order", "s4_smooth_fields", "s4_creased_fields", "c4_crease_table", "c5_iterates",
               "c2_label", "c5_fit_label", "c5_fit_pixels", "c5_fit_beta_0", "ex_fwd_h2", "ex_fwd_eps", "ex_fwd_err", "ex_fwd_best_eps", "ex_fwd_best_err", "ex_fwd_best_share",
               "ex_fwd_err_1e8", "ex_fwd_small", "ex_fwd_small_bound", "ex_fwd_err_1e3", "ex_cen_err_1e6", "ex_cs_err", "ex_exact_err", "ex_gn_jr0",
               "ex_gn_jj0", "ex_gn_jr1", "ex_gn_jj1", "ex_gn_b1", "ex_gn_b2", "ex_gn_share", "ex_gn_errors",
               "ex_gn_square", "ex_rings_label",
               "s7_crease_label", "s7_crease_err_min", "s7_crease_err_min_left", "s7_crease_fd", "s7_crease_left",
               "s7_crease_right",
               "s7_crease_half_jump", "s7_crease_side", "s7_crease_residue", "s7_tiny_step", "s7_pole_zoom",
               "s7_disp_label", "s7_disp_beta", "s7_disp_pixels", "s7_disp_silhouette", "s7_disp_shadow",
               "s7_disp_self", "s7_disp_samples", "s7_disp_newton_mean", "s7_disp_newton_max", "s7_disp_seconds",
               "s7_render_seconds", "s7_disp_cost_ratio", "s7_ex_size", "s7_ex_pitch", "s7_ex_camera",
               "s7_ex_radius", "s7_ex_magnify", "s7_ex_disc", "s7_ex_expected", "s7_ex_count", "s7_ex_min_sin",
               "s7_ex_half_label", "s7_ex_half_beta", "s7_ex_half_predicted", "s7_ex_half_silhouette",
               "s7_ex_half_ratio", "s8_radius", "s8_factor_theta", "s8_factor_phi", "s3_ex_h", "s3_ex_xh1", "s3_ex_err",
               "s3_ex_C", "s3_ex_arg_share", "s3_rel_model", "s3_fit_B_share", "s3_fit_A_share", "s3_optima_table",
               "s3_steps_table", "s3_points_label", "c2_point_label", "s3_ridges_crease_dist", "s3_ridges_largest", "s3_share_size", "s3_seen_circles", "s3_richardson", "s3_richardson_den", "s3_principal_slopes", "s3_rich_eps", "s3_rich_ku", "s3_rich_point",
               "s3_rich_exact", "s3_rich_d1", "s3_rich_d2", "s3_rich_r", "s3_rich_err1", "s3_rich_err2",
               "s3_rich_errR", "s3_rich_pred", "s3_share_estimate", "s3_rel_model_tiny",
               "s3_rings_h", "s3_rings_xh1", "s3_rings_h3", "s3_rings_C", "s3_k16_ku", "s3_k16_h", "s3_k16_xh1",
               "s3_k16_h3", "s3_k16_eps", "s3_k16_fit", "s3_k16_fit_ratio", "s3_arg_ratio", "s3_ulp_ratio",
               "s3_metric_v", "s3_metric_R", "s3_metric_theta", "s3_metric_phi", "s3_tiny_step", "s3_step_e2",
               "s3_step_e3", "s3_step_e4", "s3_arg_hi", "s3_arg_lo", "ix_mean_off", "census_rms_slope_straddling",
               "census_square_from", "s7_disp_bumped_only",
               "s4_best_label", "s4_best_ratio", "s4_fp_worst", "s4_fp_pixels", "s4_fp_share", "s4_fp_rms", "s4_fp_median_ratio",
               "s6_acc_label", "s7_cap_deg", "s7_crease_dip", "s7_parts_chart",
               "s7_parts_surface", "s7_parts_label", "s7_tilt_chart", "s7_tilt_surface", "s3_torus_a", "s3_torus_r",
               "s3_torus_point", "s3_torus_dot", "s3_torus_Lu", "s3_torus_Lv", "s3_torus_kappa_u",
               "s3_torus_kappa_v", "s3_torus_h", "s3_torus_hu", "s3_torus_hv", "s3_torus_exact", "s3_torus_first",
               "s3_torus_tilt", "s3_torus_agree", "s3_weingarten", "s3_weingarten_axes", "s3_weingarten_agree",
               "s3_weingarten_points", "s3_float32_step_ratio", "s3_frame_model_factor", "s7_far_zoom", "s7_far_size", "s7_far_inside")


def page_glue(notebook: dict) -> dict:
    """{name: shown value} of every glue output of a notebook (a dict, nbformat 4): its
    text/markdown if it has one (`chapter.theorems.glue_math`), else its text/plain."""
    out = {}
    for cell in notebook.get("cells", []):
        for output in cell.get("outputs", []):
            scrap = output.get("metadata", {}).get("scrapbook")
            if scrap:
                data = output.get("data", {})
                prefix = scrap.get("mime_prefix", MIME)
                out[scrap["name"]] = data.get(prefix + "text/markdown", data.get(prefix + "text/plain"))
    return out


def glued(cache_dir) -> dict:
    """{name: {page: value}} over the current record of every page in the cache.

    Raises
    ------
    FileNotFoundError
        If ``cache_dir`` holds no jupyter-cache database.
    """
    from jupyter_cache import get_cache

    cache_dir = Path(cache_dir)
    if not (cache_dir / "global.db").is_file():
        raise FileNotFoundError(f"no jupyter-cache database in {cache_dir}")
    latest = {}
    for record in get_cache(str(cache_dir)).list_cache_records():
        if record.uri not in latest or record.accessed > latest[record.uri].accessed:
            latest[record.uri] = record
    names = {}
    for uri, record in latest.items():
        notebook = json.loads((cache_dir / "executed" / record.hashkey / "base.ipynb").read_text(encoding="utf-8"))
        for name, value in page_glue(notebook).items():
            names.setdefault(name, {})[Path(uri).stem] = value
    return names


def conflicts(names: dict) -> list:
    """One line per name glued with different values on different pages."""
    return [f"{name}: " + ", ".join(f"{page} = {value}" for page, value in sorted(pages.items()))
            for name, pages in sorted(names.items()) if len(set(pages.values())) > 1]


def _parsed(shown):
    """A glued value as shown (its text/plain repr, or a Markdown math string) as Python reads it."""
    try:
        return ast.literal_eval(shown)
    except (ValueError, SyntaxError, TypeError):
        return shown


def _same(a, b):
    """Whether two values are one: numbers within rounding (a relative 1e-9), anything else equal."""
    number = (int, float)
    if isinstance(a, number) and isinstance(b, number) and not isinstance(a, bool) and not isinstance(b, bool):
        return math.isclose(a, b, rel_tol=1e-9)
    return a == b


def _is(shown, value):
    """Whether the glued ``shown`` is the library's ``value`` (Markdown math as `glue_math` writes it)."""
    if isinstance(shown, str) and shown.startswith("$"):
        from chapter.theorems import tex_number
        return shown == f"${tex_number(value)}$"
    return _same(_parsed(shown), value)


def quantity_conflicts(names: dict, quantities=None, own=None) -> list:
    """One line per glued name registered nowhere (`QUANTITIES`, `ON_THE_PAGE`; figures aside), per
    registered name glued nowhere, per quantity whose names show two values, and per quantity whose
    shown value is not the library's.  ``names`` is `glued`'s."""
    quantities = QUANTITIES if quantities is None else quantities
    own = ON_THE_PAGE if own is None else own
    registered = [n for aliases, _ in quantities.values() for n in aliases] + list(own)
    bad = [f"{n}: the name is registered twice" for n in sorted({n for n in registered if registered.count(n) > 1})]
    bad += [f"{n}: glued on {', '.join(sorted(pages))}, but registered nowhere (QUANTITIES or ON_THE_PAGE): "
            f"say which quantity it shows" for n, pages in sorted(names.items())
            if n not in registered and not all(str(v).startswith("<Figure") for v in pages.values())]
    bad += [f"{n}: registered, but no page glues it" for n in registered if n not in names]
    for quantity, (aliases, source) in quantities.items():
        shown = [(page, n, v) for n in aliases for page, v in sorted(names.get(n, {}).items())]
        listing = ", ".join(f"{page} {n} = {v}" for page, n, v in shown)
        if any(not _same(_parsed(v), _parsed(shown[0][2])) for _, _, v in shown):
            bad.append(f"{quantity}: one quantity, two values: {listing}")
        elif shown and source is not None:
            value = source()
            if not _is(shown[0][2], value):
                bad.append(f"{quantity}: {listing}, but the library's value is {value!r}")
    return bad


_SKIP = {"script", "style", "pre", "code", "mjx-container", "math"}
_BLOCK = {"p", "li", "td", "th", "dd", "dt", "figcaption", "summary", "h1", "h2", "h3", "h4", "div", "caption"}
#: A number as the prose shows it: 0.54, −1.3e-12, 2.0e-15, 29,919, 1e-9.
NUMBER = re.compile(r"[−-]?\d[\d,]*(?:\.\d+)?(?:e[−+-]?\d+)?")


class _Prose(HTMLParser):
    """The text a reader sees in each block element, maths (MathJax source) and code left out."""

    def __init__(self):
        super().__init__()
        self.blocks, self._text, self._skip = [], [], []

    def _flush(self):
        text = " ".join("".join(self._text).split())
        if text:
            self.blocks.append(text)
        self._text = []

    def handle_starttag(self, tag, attrs):
        classes = (dict(attrs).get("class") or "").split()
        if tag in _BLOCK:
            self._flush()
        if tag in _SKIP or "math" in classes:
            self._skip.append(tag)
            self._text.append(" ⟨·⟩ ")

    def handle_endtag(self, tag):
        if self._skip and self._skip[-1] == tag:
            self._skip.pop()
        if tag in _BLOCK:
            self._flush()

    def handle_data(self, data):
        if not self._skip:
            self._text.append(data)


def prose_sentences(html: str) -> list:
    """The sentences of a page's prose (outside maths and code), one string each."""
    parser = _Prose()
    parser.feed(html)
    parser._flush()
    return [s.replace("’", "'") for block in parser.blocks for s in re.split(r"(?<=[.;!?])\s+(?=[A-Z(“])", block)]


def _value(text):
    """A glued text/plain value as a float, or None if it is not a number."""
    try:
        return float(str(text).strip("'\""))
    except ValueError:
        return None


def _matches(shown: str, value: float) -> bool:
    """Whether the number as shown (``0.54``, ``2.0e-15``, ``29,919``) is ``value`` to the digits it shows."""
    shown = shown.replace("−", "-").replace(",", "")
    mantissa, _, exponent = shown.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    unit = 10.0 ** (int(exponent or 0) - decimals)
    return abs(float(shown) - value) <= 0.5 * unit * (1 + 1e-9) + 1e-300


def _plain(text):
    """``text`` as the words rule compares it: lower case, a hyphen or dash between two letters a space
    (one in a number, ``1.3e-12``, stays), spaces collapsed: "Model‑optimal  step" and "model optimal
    step" are one phrase."""
    return " ".join(re.sub(r"(?<=[^\W\d])[-‐‑‒–—](?=[^\W\d])", " ", text.lower()).split())


def words_conflicts(html_dir, names: dict, named=None) -> list:
    """One line per place where a quantity's words (`NAMED`) carry a number other than its
    glued value, per quantity whose words are met nowhere (or that is glued nowhere), and
    per pair of quantities whose words contain one another.  ``names`` is `glued`'s."""
    named = NAMED if named is None else named
    bad = [f"the words {a!r} ({n}) contain {b!r} ({m}): a sentence naming one names both"
           for n, a in named.items() for m, b in named.items() if n != m and _plain(b) in _plain(a)]
    met = {n: 0 for n in named}
    for page in sorted(Path(html_dir).glob("*.html")):
        for sentence in prose_sentences(page.read_text(encoding="utf-8")):
            low = _plain(sentence)
            for name, words in named.items():
                at = low.find(_plain(words))
                if at < 0:
                    continue
                met[name] += 1
                number = NUMBER.search(low, at + len(_plain(words)))
                values = {_value(v) for v in names.get(name, {}).values()} - {None}
                if number is None or not values or re.search(r"[<>≤≥]", low[at:number.start()]):
                    continue                     # no number, or a threshold of a rule, not a value
                if not any(_matches(number.group(), v) for v in values):
                    bad.append(f"{page.stem}: {words!r} is followed by {number.group()}, but {name} "
                               f"= {', '.join(f'{v:g}' for v in sorted(values))}: “{sentence}”")
    bad += [f"{name}: glued nowhere" for name in named if name not in names]
    bad += [f"{name}: the prose never calls it {words!r}" for name, words in named.items() if not met[name]]
    return bad


#: Four digits or more before any decimal point, written without thousands separators, and not in a
#: word, a decimal's fraction, an exponent, a range or an identifier (a DOI's digits follow a point).
BARE_COUNT = re.compile(r"(?<![\w.,−\-/^#])\d{4,}(?![\w,]?\d|[\w])")
#: A number glued into prose: {glue:text}`name` or {glue:text}`name:spec`.
GLUE_TEXT = re.compile(r"\{glue:text\}`([\w-]+)(?::([^`]*))?`")


def bare_counts(html_dir) -> list:
    """One line per count of 1,000 or more that a page's prose (outside maths and code) writes
    without thousands separators: "13686 pixels" where the book writes "13,686"."""
    bad = []
    for page in sorted(Path(html_dir).glob("*.html")):
        for sentence in prose_sentences(page.read_text(encoding="utf-8")):
            for m in BARE_COUNT.finditer(sentence):
                if not (len(m.group()) == 4 and 1900 <= int(m.group()) <= 2099):
                    bad.append(f"{page.stem}: {m.group()} in “{sentence[:160]}”")
    return bad


def hyphen_minus(html_dir) -> list:
    """One line per negative number that a page's prose (outside maths and code) writes with a
    hyphen-minus, "-0.651", where the book writes the minus sign, "−0.651" (`chapter.page.HYPHEN_MINUS`;
    book/_ext/a11y_markup.py typesets them)."""
    from chapter.page import HYPHEN_MINUS
    return [f"{page.stem}: {m.group()}{sentence[m.end():m.end() + 12]} in “{sentence[:160]}”"
            for page in sorted(Path(html_dir).glob("*.html"))
            for sentence in prose_sentences(page.read_text(encoding="utf-8"))
            for m in HYPHEN_MINUS.finditer(sentence)]


def unseparated_formats(names: dict, book_dir=Path(__file__).parent) -> list:
    """One line per number glued into a page's prose (``book_dir/*.md``) by a format without ','
    that could write it as four digits or more (any but an e-format): a time that shows 986 ms on
    this machine shows 2286 on a slower one, so `bare_counts` on one build cannot vouch for it.
    ``names`` is `glued`'s."""
    bad = []
    for page in sorted(Path(book_dir).glob("*.md")):
        for m in GLUE_TEXT.finditer(page.read_text(encoding="utf-8")):
            name, spec = m.group(1), m.group(2) or ""
            value = _parsed(next(iter(names.get(name, {}).values()), None))
            number = isinstance(value, (int, float)) and not isinstance(value, bool)
            if number and "," not in spec and not spec.lower().endswith("e"):
                bad.append(f"{page.stem}: {m.group()} (write {{glue:text}}`{name}:,{spec}`)")
    return bad


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    cache_dir = Path(argv[0] if argv else "book/_build/.jupyter_cache")
    html_dir = Path(argv[1]) if len(argv) > 1 else cache_dir.parent / "html"
    try:
        names = glued(cache_dir)
        if not html_dir.is_dir():
            raise FileNotFoundError(f"no built site in {html_dir}")
    except FileNotFoundError as error:
        print(f"check_glue: {error}", file=sys.stderr)
        return 2
    bad = conflicts(names)
    shared = sum(len(pages) > 1 for pages in names.values())
    if bad:
        print("check_glue: the same name shows different values on different pages:\n  " + "\n  ".join(bad),
              file=sys.stderr)
        return 1
    # The library's stored measurements are the build's (computed again where the code has changed), for
    # this check only: a process that calls main() keeps its own store, or none.
    from lab.store import ENV
    own = ENV in os.environ
    os.environ.setdefault(ENV, str(cache_dir.parent / ".measurements"))
    try:
        sourced = quantity_conflicts(names)
    finally:
        if not own:
            del os.environ[ENV]
    if sourced:
        print("check_glue: a glued quantity is unregistered, or shows two values, or not the library's:\n  "
              + "\n  ".join(sourced), file=sys.stderr)
        return 1
    worded = words_conflicts(html_dir, names)
    if worded:
        print("check_glue: the same words carry different numbers:\n  " + "\n  ".join(worded), file=sys.stderr)
        return 1
    bare = unseparated_formats(names) + bare_counts(html_dir)
    if bare:
        print("check_glue: a count without thousands separators (write 13,686, or format the glue with ','):\n  "
              + "\n  ".join(bare), file=sys.stderr)
        return 1
    hyphens = hyphen_minus(html_dir)
    if hyphens:
        print("check_glue: a negative number with a hyphen where the book writes the minus sign (−):\n  "
              + "\n  ".join(hyphens), file=sys.stderr)
        return 1
    print(f"check_glue: {len(names)} glued names; {shared} shown on several pages, each with one value; "
          f"{len(QUANTITIES)} quantities with one value under all their names, "
          f"{sum(s is not None for _, s in QUANTITIES.values())} of them the library's; "
          f"{len(NAMED)} quantities named in prose, each with one value under its words; every count with its "
          f"thousands separators, every negative number with its minus sign")
    return 0


if __name__ == "__main__":
    sys.exit(main())
