"""What the reader sees, read back and compared with the number it names.

A figure marks values, and its caption or the prose beside it names them with glued numbers.
The book's pages are run here as the build runs them (`tests.pages.run_page` records the
Figures each publishes and the values it glues), each figure is read back from its matplotlib
artists (line, patch and image data; title, legend and annotation texts and positions), and
each marked value is compared with the glued value its caption or prose names, or with the
library's own (`renderer`, `lab`).  The classes of marked values, and where the book has them:

* a line at a named value: Cell 2's fitted and model-optimal steps beside the histogram of the
  footprint steps it counts, the stencil's crease;
* a number in a legend: the stencil's two slopes (the library's central and exact hᵤ at the
  stencil drawn), the band's percentiles (of the page's footprint steps);
* a number in a title: the gain of a difference panel (index, §1, Cell 3), the β of a render
  (§1, Cell 6), the normal diagram's β (that of the displaced curve it draws);
* an annotation at a value: the optimum's, the crease's;
* the data of a curve whose statistic the prose names: Cell 5's convergence orders, §7's floor of
  the error at a crease, the model's error at the fitted step;
* what a caption's glued numbers say a figure shows: §4's panels at its ε with its largest
  difference, §2's fields at its frequencies and its chamber counts, §7's close-ups at its zoom;
* directions a caption states in words: the normal diagram's arrows;
* numbers typed into alt text, which cannot be glued: each is listed in `ALT_NUMBERS` with what
  it names and checked; a number not listed fails;
* the register of §6 and the front page's counts: each row's number is its claim's place in
  `lab.claims.CLAIMS`, its quote and verdict the claim's, each verdict sentence links the row of
  its own claim, and the counts on the front page are those of the lists they count.

Pages run with a copy of the build's stored measurements when there is one (after ``make book``
the pages cost seconds; without it minutes).  The register and the counts are read from the
built site (`book_html`).
"""

from __future__ import annotations

import inspect
import math
import os
import re
import shutil
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from chapter import figures
from chapter.theorems import BADGE_STEPS_PROVED
from renderer import Scene, compare, pointwise, render, to_srgb
from renderer.formulas import FIELDS as HEIGHT_FIELDS
from renderer.ucurve import non_differentiable

from .pages import run_page
from .test_check_glue import check_glue

ROOT = Path(__file__).parents[1]
BOOK = ROOT / "book"
#: A number as a figure or an alt text writes it ("-5.30", "+0.00", "1e-16", "10th", "−1").
NUMBER = re.compile(r"[−+-]?\d+(?:\.\d+)?(?:e[−+-]?\d+)?")


def numbers(text):
    return [float(m.replace("−", "-")) for m in NUMBER.findall(text)]


def shows(shown, value):
    """Whether the number as written (``-5.30``, ``2``) is ``value`` to the digits it shows."""
    return check_glue._matches(shown.replace("+", "").replace("−", "-"), float(value))


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    """``ran(page)``: `run_page` of book/<page>.md, once per page, reading the build's stored
    measurements (a copy of book/_build/.measurements, or of the store beside SYMRENDER_BOOK_HTML)."""
    given = os.environ.get("SYMRENDER_BOOK_HTML")
    built = (Path(given).parent if given else BOOK / "_build") / ".measurements"
    store = tmp_path_factory.mktemp("store")
    if built.is_dir():
        shutil.copytree(built, store, dirs_exist_ok=True)
    runs = {}
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SYMRENDER_STORE", str(store))

        def run(page):
            if page not in runs:
                runs[page] = run_page(BOOK / f"{page}.md")
            return runs[page]
        yield run


def vertical_lines(ax):
    """The x of every vertical line (``axvline``) of ``ax``."""
    return [float(x[0]) for x in (line.get_xdata() for line in ax.get_lines()) if len(x) == 2 and x[0] == x[1]]


def curve(ax, label):
    """(x, y) of the one line of ``ax`` whose label starts with ``label``."""
    found = [line for line in ax.get_lines() if line.get_label().startswith(label)]
    assert len(found) == 1, (label, [line.get_label() for line in ax.get_lines()])
    return np.asarray(found[0].get_xdata(), float), np.asarray(found[0].get_ydata(), float)


def legend_entry(ax, label):
    """The text of the legend entry (as the reader reads it) that starts with ``label``."""
    (text,) = [t.get_text() for t in ax.get_legend().get_texts() if t.get_text().startswith(label)]
    return text


def image(ax):
    return np.asarray(ax.get_images()[0].get_array())


# ---- lines, bands, legends and annotations ---------------------------------------------------

def test_the_footprint_histogram_counts_the_pages_steps_against_the_glued_optimal_steps(ran):
    """Cell 2's figure: its vertical lines sit at the glued fitted and model-optimal steps (the
    library's, `lab.accuracy.optima`) and at the glued median footprint step, its bars count every
    sphere-A pixel's footprint step once, the glued median step is the median of those steps, right
    of both optimal steps as the alt text says, and the glued ratio is the median over the fitted
    optimal step."""
    from lab.accuracy import optima
    ns, shown, glued = ran("s5_lab")
    ax = shown["fig-c2-footprint"].axes[0]
    opt = optima()["sine"]
    optimal = [glued["eps_fitted_sine"], glued["eps_model_sine"]]
    assert sorted(vertical_lines(ax)) == sorted(optimal + [glued["c2_fp_u"]])
    assert (glued["eps_fitted_sine"], glued["eps_model_sine"]) == (opt["eps_fitted"], opt["eps_model"])
    heights = [p.get_height() for p in ax.patches]
    assert sum(heights) == ns["fp_u"].size == np.count_nonzero(ns["on_a"])
    assert glued["c2_fp_u"] == np.median(ns["fp_u"]) and glued["c2_fp_u"] > max(optimal)
    assert math.isclose(glued["c2_fp_ratio"], glued["c2_fp_u"] / glued["eps_fitted_sine"], rel_tol=1e-12)


def test_the_gauss_newton_exercise_is_solved_by_its_own_numbers(ran):
    """Cell 5's exercise: a step beta - J.r / J.J from the glued sums lands on the glued answers,
    which are the fit's iterates (to the digits the solution shows), and the fit converges to the
    glued true beta."""
    _, _, glued = ran("s5_lab")
    b1 = glued["c5_fit_beta_0"] - glued["ex_gn_jr0"] / glued["ex_gn_jj0"]
    b2 = glued["ex_gn_b1"] - glued["ex_gn_jr1"] / glued["ex_gn_jj1"]
    assert math.isclose(b1, glued["ex_gn_b1"], rel_tol=1e-9) and math.isclose(b2, glued["ex_gn_b2"], rel_tol=1e-9)
    assert abs(glued["ex_gn_b2"] - glued["c5_fit_beta"]) < abs(glued["ex_gn_b1"] - glued["c5_fit_beta"])


def test_the_u_curve_of_s3_draws_slope_guides_parallel_to_its_arms_with_the_slopes_they_name(ran):
    """§3's figure: each guide line (kept out of the legend) has, on log-log axes, exactly the slope
    its annotation names; it lies above the measured error by a factor between 3 and 300 over its
    span, along an arm of the measured error whose own slope is within 0.2 of it; the vertical lines
    are the fitted optimal step and the model-optimal step of the curve drawn, in that order."""
    ns, shown, glued = ran("s3_math")
    ax = shown["fig-ucurve"].axes[0]
    assert vertical_lines(ax) == [ns["curve"].eps_fitted, ns["curve"].eps_model]
    eps, error = curve(ax, "|error|")
    guides = [line for line in ax.get_lines() if line.get_label().startswith("_guide")]
    assert len(guides) == 2 and not any(t.get_text().startswith("_") for t in ax.get_legend().get_texts())
    for line in guides:
        x, y = (np.log10(np.asarray(d, float)) for d in line.get_data())
        slope, _ = np.polyfit(x, y, 1)
        (note,) = [t for t in ax.texts if np.isclose(np.log10(t.xy[0]), (x[0] + x[-1]) / 2, rtol=0, atol=1e-9)]
        (named,) = numbers(note.get_text().split("\n")[0])
        assert math.isclose(slope, named, abs_tol=1e-9), (slope, note.get_text())
        arm = (eps >= 10 ** x[0]) & (eps <= 10 ** x[-1]) & (error > 0)
        measured = np.polyfit(np.log10(eps[arm]), np.log10(error[arm]), 1)[0]
        assert abs(measured - slope) < 0.2, (measured, slope)
        above = 10 ** np.interp(np.log10(eps[arm]), x, y) / error[arm]
        assert 3 < np.median(above) < 300, np.median(above)


def test_s3s_worked_example_and_exercise_redo_by_hand_from_the_numbers_the_page_gives(ran):
    """The model-optimal step and its error, recomputed from the glued givens as the reader would
    (ε* = (3uC/|h‴|)^(1/3), E(ε*) = ε*²|h‴|/2), are the glued answers, to the digits shown."""
    ns, shown, glued = ran("s3_math")
    u = glued["s3_unit_roundoff"]
    for given in ("s3_ex", "s3_rings"):
        C = glued[f"{given}_h"] + glued[f"{given}_xh1"]
        eps = (3 * u * C / glued[f"{given}_h3"]) ** (1 / 3)
        assert math.isclose(eps, glued[f"{given}_eps"], rel_tol=1e-9), (given, eps)
        assert math.isclose(eps**2 * glued[f"{given}_h3"] / 2, glued[f"{given}_err"], rel_tol=1e-9), given
    assert shows(f"{glued['s3_ex_eps']:.2e}", ns["curve"].eps_model)


def test_s3s_tiny_step_sets_the_measured_error_against_the_model_at_that_same_step(ran):
    """"Why not a tiny step": the model's relative error at the tiny step, redone from the worked
    example's glued givens (E(ε)/|h'| with |h'| = E(ε*) / (E(ε*)/|h'|)), is the glued one, and the
    measured relative error there lies within it (the model bounds each rounding error)."""
    ns, shown, glued = ran("s3_math")
    t, u = glued["s3_tiny_step"], glued["s3_unit_roundoff"]
    h1 = glued["s3_ex_err"] / glued["s3_rel_model"]
    model = (t**2 * glued["s3_ex_h3"] / 6 + u * (glued["s3_ex_h"] + glued["s3_ex_xh1"]) / t) / h1
    assert math.isclose(model, glued["s3_rel_model_tiny"], rel_tol=1e-9), (model, glued["s3_rel_model_tiny"])
    assert glued["ucurve_rel_1e11"] <= glued["s3_rel_model_tiny"]


def test_s1s_pixels_facing_away_from_both_lights_are_counted_and_shade_as_if_unlit(ran):
    """§1's count of sphere-A pixels tilted past the glued angle and facing away from both lights
    (N'·(L − P) <= 0 for each light) is the glued share, at most the tilted share, and each such
    pixel of the exact render is the pixel of the same scene with no lights: they are the black
    wedges the caption names, for both normals."""
    ns, shown, glued = ran("s1_what_changes")
    for bump in ("surface", "chart"):
        f = ns["frames"][bump]
        g, on_a = f["geometry"], f["geometry"].chamber == 1
        tilt = np.degrees(np.arccos(np.clip(np.sum(g.N * g.Ns, axis=-1), -1.0, 1.0)))
        scene = f["symbolic"].scene
        away = np.all([np.sum(g.Ns * (np.asarray(light.position) - g.P), axis=-1) <= 0 for light in scene.lights],
                      axis=0)
        counted = on_a & away & (tilt > glued["s1_steep"])
        assert math.isclose(100 * counted.sum() / on_a.sum(), glued[f"s1_away_{bump}"], rel_tol=1e-12), bump
        assert glued[f"s1_away_{bump}"] <= glued[f"s1_steep_{bump}"]
        unlit = render(scene.replace(lights=()), *on_a.shape[::-1], gradient="exact").image
        assert np.array_equal(f["symbolic"].image[counted], unlit[counted]), bump
    assert glued["s1_away_chart"] > glued["s1_away_surface"]


#: The stencil diagram as §3 draws it (its defaults), a stencil left of another crease, and one
#: at another frequency and row.
STENCILS = [{}, dict(k_u=5.0, v=0.3, eps=0.01, offset=-0.004), dict(k_u=12.0, k_v=3.0, v=0.8, eps=0.005, offset=0.002)]


@pytest.mark.parametrize("kwargs", STENCILS)
def test_the_stencil_legend_names_the_slopes_the_library_computes_at_the_stencil_drawn(kwargs):
    """§3's stencil diagram: the legend's central slope is the library's central hᵤ
    (`pointwise.central_gradient`) at the stencil drawn (its centre and half-width read back from
    the red points) and the slope of the secant drawn; its exact slope is `pointwise.exact_gradient`
    there and the slope of the blue line; the dotted line and its annotation sit on a crease
    (`renderer.ucurve.non_differentiable`), between the stencil's points."""
    from renderer import DRAFT_SCENE
    from renderer.formulas import SEED_POINT
    p = {**{k: v.default for k, v in inspect.signature(figures.stencil_diagram).parameters.items()},
         "k_u": DRAFT_SCENE.k_u, "k_v": DRAFT_SCENE.k_v, "v": SEED_POINT[1], **kwargs}     # None: the draft's
    ax = figures.stencil_diagram(**kwargs).axes[0]
    (a, b), (h_a, h_b) = curve(ax, "central stencil")
    u0, eps = (a + b) / 2, (b - a) / 2
    central, exact = (NUMBER.findall(legend_entry(ax, label))[-1] for label in ("central stencil", "exact slope"))
    library = pointwise.central_gradient("ridges", u0, p["v"], p["k_u"], p["k_v"], eps)[0]
    assert shows(central, library) and shows(central, (h_b - h_a) / (b - a)), (central, library)
    u, h = curve(ax, "exact slope")
    library = pointwise.exact_gradient("ridges", u0, p["v"], p["k_u"], p["k_v"])[0]
    assert shows(exact, library) and math.isclose((h[1] - h[0]) / (u[1] - u[0]), library, rel_tol=1e-9)
    (crease,) = vertical_lines(ax)
    assert non_differentiable("ridges", crease, p["v"], "u", p["k_u"], p["k_v"]) and a < crease < b
    (note,) = [t for t in ax.texts if "crease" in t.get_text()]
    assert note.xy[0] == crease
    # The legend's markers must not read as data: the legend stands wholly below the plotting area.
    fig = ax.figure
    fig.canvas.draw()
    legend, area = ax.get_legend().get_window_extent(), ax.get_window_extent()
    assert legend.y1 < area.y0, (legend, area)


# ---- numbers in titles -------------------------------------------------------------------------

def _beta(title):
    (beta,) = numbers(title.partition("beta")[2])
    return beta


@pytest.mark.parametrize("kwargs", [{}, dict(field="rings", beta=0.2), dict(field="sine", beta=0.05, theta=1.0)])
def test_the_normal_diagram_draws_the_displacement_its_title_names_and_the_normals_its_caption_describes(kwargs):
    """§1's diagram: the dashed curve is the sphere displaced by β h with the β and field of the
    title ((r - R) / h read back from the curve); at the middle point (§1's figure, the rings
    field) the displaced curve's own normal (green) covers the displaced sphere's (blue) and the
    draft's (red) tilts the other way from N, and further, as the caption says."""
    p = {**{k: v.default for k, v in inspect.signature(figures.normal_diagram).parameters.items()}, **kwargs}
    ax = figures.normal_diagram(**kwargs).axes[0]
    title = ax.get_title()
    beta = _beta(title)
    assert f"{p['field']} field" in title and beta == p["beta"]
    (dashed,) = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
    x, z = (np.asarray(c, float) for c in dashed.get_data())
    scene = Scene(height_field=p["field"])
    h = pointwise.height(p["field"], np.full_like(x, (p["theta"] + np.pi) / (2 * np.pi)), np.arctan2(x, z) / np.pi,
                         scene.k_u, scene.k_v)
    big = np.abs(h) > 0.1
    assert np.allclose((np.hypot(x, z) - scene.radius_a)[big] / h[big], beta, rtol=1e-9, atol=0)
    if kwargs:
        return
    arrows = {}
    for t in ax.texts:
        if getattr(t, "arrow_patch", None) is not None:
            arrows.setdefault((t.arrowprops["color"], t.arrowprops["lw"]), []).append(np.subtract(t.xy, t.xyann))
    (wide,), (own,), (draft,) = (arrows[k] for k in ((figures.BLUE, 3.5), (figures.GREEN, 1.0), (figures.RED, 1.4)))
    (flat,) = arrows["black", 1.4]
    angle = lambda a, b: np.degrees(np.arctan2(a[0] * b[1] - a[1] * b[0], a @ b))  # noqa: E731
    assert abs(angle(own, wide)) < 1.0, angle(own, wide)
    tilt, draft_tilt = angle(flat, wide), angle(flat, draft)
    assert np.sign(draft_tilt) == -np.sign(tilt) and abs(draft_tilt) > abs(tilt), (tilt, draft_tilt)


#: The difference panels: the page, the figure, and the (numeric, symbolic) frames of its rows,
#: read from the page's namespace.
DIFFERENCE_PANELS = {
    "fig-hero": ("index", lambda ns: [(ns["numeric"], ns["symbolic"])]),
    "fig-s1-bump": ("s1_what_changes", lambda ns: [(ns["frames"][b]["numeric"], ns["frames"][b]["symbolic"])
                                                   for b in ("surface", "chart")]),
    "fig-c3-panels": ("s5_lab", lambda ns: [(ns["numeric"], ns["symbolic"])]),
}


@pytest.mark.parametrize("name", sorted(DIFFERENCE_PANELS))
def test_a_difference_panel_is_the_difference_amplified_by_the_gain_its_title_names(ran, name):
    """The panel titled "× g" shows min(1, g |ΔI|) of its row's frames, g is the simulator's linear
    gain that §4 and Cell 3 glue, and Cell 3's caption names the same g."""
    page, frames = DIFFERENCE_PANELS[name]
    ns, shown, glued = ran(page)
    axes = [ax for ax in shown[name].axes if "×" in ax.get_title()]
    assert len(axes) == len(frames(ns))
    for ax, (numeric, symbolic) in zip(axes, frames(ns)):
        (gain,) = numbers(ax.get_title().partition("×")[2])
        assert np.array_equal(image(ax), np.clip(gain * np.abs(numeric.image - symbolic.image), 0, 1)), ax.get_title()
        assert gain == check_glue.QUANTITIES["the simulator's linear difference gain"][1]()
        assert gain == glued.get("c3_gain", gain)


@pytest.mark.parametrize("page, name, frames", [
    ("s5_lab", "fig-c6-beta", lambda ns: [ns["flat"], ns["strong"]]),
    ("s1_what_changes", "fig-s1-bump", lambda ns: [ns["frames"]["surface"]["flat"]]),   # beta = 0: one for both
])
def test_a_render_titled_with_its_beta_is_the_render_at_that_beta(ran, page, name, frames):
    """Each panel whose title gives β shows its frame, rendered at that β (and, in Cell 6, on the
    field the title names), and Cell 6's caption names the same β."""
    ns, shown, glued = ran(page)
    axes = [ax for ax in shown[name].axes if "beta" in ax.get_title()]
    assert len(axes) == len(frames(ns))
    for ax, frame in zip(axes, frames(ns)):
        assert np.array_equal(image(ax), to_srgb(frame.image)) and _beta(ax.get_title()) == frame.scene.beta
        assert "field" not in ax.get_title() or f"{frame.scene.height_field} field" in ax.get_title()
    if name == "fig-c6-beta":
        assert glued["c6_beta"] == frames(ns)[1].scene.beta


# ---- the data of curves whose statistic the prose names -------------------------------------

def test_the_orders_cell_5_names_are_the_slopes_of_its_lines(ran):
    """Cell 5's figure: the log-log slope of its median line and of its RMS line are the glued
    median and RMS orders of the β-derivative."""
    _, shown, glued = ran("s5_lab")
    ax = shown["fig-c5-order"].axes[0]
    for label, name in (("median", "beta_median_order"), ("RMS", "beta_rms_order")):
        x, y = curve(ax, label)
        assert math.isclose(np.polyfit(np.log(x), np.log(y), 1)[0], glued[name], rel_tol=1e-9), label


def test_the_crease_figure_bottoms_out_where_the_prose_says(ran):
    """§7: "the error never falls below" the glued floor: the least of the error line drawn."""
    _, shown, glued = ran("s7_pitfalls")
    _, error = curve(shown["fig-crease"].axes[0], "error at the crease")
    assert error.min() == glued["s7_crease_err_min"]


# ---- what a caption's glued numbers say a figure shows --------------------------------------

def test_the_simulators_static_panels_are_its_opening_frame_at_the_captions_step(ran):
    """§4's panels are Python's frames of the simulator's opening scene at the ε the caption glues,
    and the caption's largest difference and RMS are those frames' ledger."""
    from chapter.theorems import tex_number
    from renderer.ledger import SIMULATOR_SCENE
    ns, shown, glued = ran("s4_simulator")
    eps = ns["numeric"].scene.eps
    assert glued["s4_eps"].data == f"${tex_number(eps)}$" and ns["numeric"].scene == SIMULATOR_SCENE.replace(eps=eps)
    size = ns["numeric"].image.shape[0]
    numeric = render(SIMULATOR_SCENE.replace(eps=eps), size, size, gradient="central")
    symbolic = render(SIMULATOR_SCENE, size, size)
    axes = shown["fig-s4-pipelines"].axes
    assert np.array_equal(image(axes[0]), to_srgb(numeric.image))
    assert np.array_equal(image(axes[1]), to_srgb(symbolic.image))
    from renderer.ledger import DIFFERENCE_LOG_FLOOR        # the simulator opens on the log scale
    d = np.abs(numeric.image - symbolic.image)
    with np.errstate(divide="ignore"):
        level = np.where(d > 0, np.clip(1 - np.log10(d) / DIFFERENCE_LOG_FLOOR, 0, 1), 0)
    assert "log" in axes[2].get_title() and np.array_equal(image(axes[2]), level)
    ledger = compare(numeric, symbolic)
    assert (glued["s4_max"], glued["s4_rms"]) == (ledger.max_abs, ledger.rms)


def test_the_scene_figures_show_the_fields_and_chambers_their_captions_name(ran):
    """§2: each field panel is `pointwise.height` of the field its title names at the glued
    frequencies; the chamber map's counts are the glued counts, and the render beside it is the
    scene of the glued field, frequencies and β."""
    _, shown, glued = ran("s2_scene")
    fields = [ax for ax in shown["fig-s2-fields"].axes if ax.get_images()]
    for ax in fields:
        field, (x0, x1, y0, y1) = ax.get_title().partition(":")[0], ax.get_images()[0].get_extent()
        u, v = np.meshgrid(np.linspace(x0, x1, image(ax).shape[1]), np.linspace(y0, y1, image(ax).shape[0]))
        assert np.array_equal(image(ax), pointwise.height(field, u, v, glued["s2_k_u"], glued["s2_k_v"])), field
    assert sorted(ax.get_title().partition(":")[0] for ax in fields) == sorted(HEIGHT_FIELDS)
    scene_ax, chamber_ax = shown["fig-s2-chambers"].axes
    counts = np.bincount(image(chamber_ax).ravel().astype(int), minlength=4)
    assert [glued[f"s2_count_{code}"] for code in range(4)] == counts.tolist()
    scene = Scene(height_field=glued["s2_field"], k_u=glued["s2_k_u"], k_v=glued["s2_k_v"], beta=glued["s2_beta"],
                  bump="surface")
    assert np.array_equal(image(scene_ax), to_srgb(render(scene, *image(chamber_ax).shape[::-1]).image))


def test_the_pole_close_ups_are_the_normals_their_titles_name_at_the_captions_zoom(ran):
    """§7: each close-up is the render, at the glued zoom, with the normal its title names."""
    ns, shown, glued = ran("s7_pitfalls")
    words = {"the draft's normal": "chart", "the displaced sphere's normal": "surface"}
    for ax in shown["fig-pole-modes"].axes:
        size = image(ax).shape[0]
        frame = render(ns["scene"].replace(bump=words[ax.get_title()]), size, size, zoom=glued["s7_pole_zoom"])
        assert np.array_equal(image(ax), to_srgb(frame.image)), ax.get_title()



def test_the_displaced_frame_cuts_the_lobes_and_the_silhouette_count_scales_with_beta_inside_it(ran):
    """§7: the caption says the frame cuts the displaced lobes at its top and sides (the bumped
    sphere stays inside), and the exercise says the silhouette count inside that frame halves with
    β: the measured ratio is within a tenth of one half."""
    ns, _, glued = ran("s7_pitfalls")
    covered, bumped = ns["disp"].covered, ns["disp"].bumped.chamber == 1
    assert covered[0].any() and covered[:, 0].any() and covered[:, -1].any()
    assert not (bumped[0].any() or bumped[-1].any() or bumped[:, 0].any() or bumped[:, -1].any())
    assert glued["s7_ex_half_beta"] == glued["s7_disp_beta"] / 2
    assert abs(glued["s7_ex_half_ratio"] - 0.5) < 0.05

# ---- numbers typed into alt text ------------------------------------------------------------

def _arm(side, figure):
    """The log-log slope of a U-curve figure's error line on one arm: steps 10 times the optimum
    or more ("right"), a tenth of it or less ("left")."""
    def slope(ns, shown, glued):
        ax = shown[figure].axes[0]
        eps, error = curve(ax, "|error|")
        opt = vertical_lines(ax)[0]  # the fitted optimal step (a U-curve may mark the model's too)
        arm = eps >= 10 * opt if side == "right" else eps <= opt / 10
        return np.polyfit(np.log10(eps[arm]), np.log10(error[arm]), 1)[0]
    return slope


#: (page, figure) -> {the words of its alt text that carry a number: what the number names}.
ALT_NUMBERS = {
    ("s3_math", "fig-ucurve"): {"labelled slope +2": _arm("right", "fig-ucurve"),
                                "labelled slope −1": _arm("left", "fig-ucurve")},
    ("s5_lab", "fig-c5-order"): {"with slope about 2": lambda ns, shown, glued: glued["beta_median_order"]},
}
_ALT = re.compile(r"```\{glue:figure\} (?P<name>\S+)\n(?:.*\n)*?:alt: (?P<alt>.*)")


def test_every_number_typed_into_alt_text_is_the_value_it_names(ran):
    """Every number in a figure's alt text lies in words listed in `ALT_NUMBERS`, and the number
    names what they name, to the digits it shows."""
    found = {}
    for page in sorted(BOOK.glob("*.md")):
        for m in _ALT.finditer(page.read_text(encoding="utf-8")):
            listed = ALT_NUMBERS.get((page.stem, m["name"]), {})
            alt = m["alt"]
            for words in listed:
                assert words in alt, (page.stem, m["name"], words)
                alt = alt.replace(words, "")
            found[page.stem, m["name"]] = NUMBER.findall(alt)
    assert not any(found.values()), {k: v for k, v in found.items() if v}
    for (page, _), listed in ALT_NUMBERS.items():
        for words, value in listed.items():
            (number,) = NUMBER.findall(words)
            assert shows(number, value(*ran(page))), (words, value(*ran(page)))


# ---- the register of §6 and the counts of the front page ------------------------------------

def test_the_register_numbers_each_claim_by_its_place_in_the_register():
    """`chapter.verdicts.register`: entry n is the n-th claim of `lab.claims.CLAIMS`, numbered n
    from 1 (claims' measurements stubbed: their verdicts are the registered ones)."""
    from chapter import verdicts
    from lab.claims import CLAIMS
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(verdicts, "_results", lambda ids=None: {c.id: (c, {}, c.registered) for c in CLAIMS})
        patch.setattr(verdicts, "measured_text", lambda claim_id, values: "measured")
        markdown = verdicts.register()
    rows = re.findall(r"^\(claim-(?P<id>[^)]+)\)=\n\*\*(?P<n>\d+)\. ", markdown, re.M)
    assert rows == [(c.id, str(n)) for n, c in enumerate(CLAIMS, start=1)]


def _soup(path):
    from bs4 import BeautifulSoup
    return BeautifulSoup(path.read_text(encoding="utf-8"), "html.parser")


def test_the_built_register_its_links_and_the_front_pages_counts_agree_with_the_claims(book_html):
    """The built §6: row n is `lab.claims.CLAIMS`[n - 1], numbered n, with its place, quote and
    registered verdict, and it links to the section that measures it; every verdict sentence on
    every page links to the row of the claim it quotes, with that row's verdict; the front page's
    counts of claims (by verdict), errata and theorems (by status) are those of §6's lists."""
    from chapter.verdicts import WORDS, place_of, section_of
    from lab.claims import CLAIMS
    quoted = lambda claim: f"“{claim.quote.replace('`', '')}”"  # noqa: E731  (its code spans set as code)
    text = lambda element: element.get_text().replace("’", "'")  # noqa: E731  (Sphinx's typographic apostrophe)
    s6 = _soup(book_html / "s6_ledger.html")
    rows = s6.select("p[id^=claim-]")
    assert [r["id"] for r in rows] == [f"claim-{c.id}" for c in CLAIMS]
    for n, (row, claim) in enumerate(zip(rows, CLAIMS), start=1):
        head, verdict = (b.get_text() for b in row.find_all("strong")[:2])
        assert head == f"{n}. {claim.where}:" and quoted(claim) in text(row), (n, head)
        assert verdict == WORDS[claim.registered], (claim.id, verdict)
        # Each links first to the section whose margin note shows it.
        assert row.find("a")["href"].endswith(f"#{section_of(place_of(claim.id))}"), claim.id
    by_id = {c.id: c for c in CLAIMS}
    linked = []
    for page in sorted(book_html.glob("*.html")):
        for sentence in _soup(page).select("aside.margin p"):
            if not sentence.find("a", href=re.compile("#claim-")):
                continue
            claim = by_id[sentence.find("a", href=re.compile("#claim-"))["href"].rpartition("#claim-")[2]]
            assert quoted(claim) in text(sentence), (page.name, claim.id)
            term = sentence.find("a", href=re.compile("glossary.html#term-"))
            assert term.get_text() == WORDS[claim.registered], (page.name, claim.id)
            linked.append(claim.id)
    assert sorted(linked) == sorted(by_id)
    counts = ("ix_claims", "ix_holds", "ix_corrected", "ix_fails", "ix_errata", "ix_proved", "ix_verified")
    cache = check_glue.glued(book_html.parent / ".jupyter_cache")
    glued = {name: float(cache[name]["index"]) for name in counts}
    verdicts = Counter(row.find_all("strong")[1].get_text() for row in rows)
    section = lambda label: s6.find(id=label).find_parent("section")  # noqa: E731
    errata = [p for p in section("errata").select("p") if re.match(r"E\d+\. ", p.get_text())]
    statuses = Counter(b.get_text() for b in section("theorems").select("li > p > strong"))
    assert glued == {"ix_claims": len(rows), "ix_holds": verdicts[WORDS["holds"]],
                     "ix_corrected": verdicts[WORDS["holds with a correction"]],
                     "ix_fails": verdicts[WORDS["does not hold"]], "ix_errata": len(errata),
                     "ix_proved": statuses["PROVED"],
                     "ix_verified": statuses["VERIFIED numerically"] + statuses[BADGE_STEPS_PROVED]}, glued


#: The glued errors §5's exercises 8 and 9 compare with, and the row of Cell 4's table (method, step)
#: each must be read from.
EXERCISE_ROWS = {"ex_fwd_err_1e8": ("forward", "1e-08"), "ex_fwd_err_1e3": ("forward", "1e-03"),
                 "ex_cen_err_1e6": ("central", "1e-06"), "ex_cs_err": ("complex step", "1e-20"),
                 "ex_exact_err": ("exact", "")}


def test_the_exercises_compare_with_numbers_cell_4s_table_shows(ran, book_html):
    """Exercises 8 and 9 ask for Cell 4's errors on the sine field: the built Cell 4 shows a table
    of the sine panel's points (method, step, largest error), one row per measured method, and
    each error the solutions glue is the one its row shows, to the digits shown."""
    ns, _, glued = ran("s5_lab")
    cell4 = _soup(book_html / "s5_lab.html").find(id="cell4").find_parent("section")     # the label's section
    (table,) = [t for t in cell4.find_all("table") if "largest absolute error" in t.get_text()]
    rows = {tuple(td.get_text().strip() for td in tr.find_all("td")[:2]): tr.find_all("td")[2].get_text().strip()
            for tr in table.find_all("tr") if tr.find_all("td")}
    assert len(rows) == len(ns["fast"].of("sine"))
    for name, row in EXERCISE_ROWS.items():
        assert shows(rows[row], glued[name]), (name, rows[row], glued[name])


# ---- what a solution shows, redone from the numbers the page gives ----------------------------

def test_the_torus_solution_is_redone_from_its_givens(ran):
    """The torus exercise's answers, recomputed by hand from the glued radii, point, field values and
    β with the solution's own formulas (|p_u| = 2π(a + r cos 2πv), |p_v| = 2πr, κ_u = cos 2πv /
    (a + r cos 2πv), κ_v = 1/r; the exact and first-order slopes; the tilt atan|t|), are the glued ones."""
    ns, shown, glued = ran("s3_math")
    a, r, v, b = glued["s3_torus_a"], glued["s3_torus_r"], glued["s3_torus_v"], glued["s3_torus_beta"]
    h, hu, hv = glued["s3_torus_h"], glued["s3_torus_hu"], glued["s3_torus_hv"]
    c = math.cos(2 * math.pi * v)
    Lu, Lv, ku, kv = 2 * math.pi * (a + r * c), 2 * math.pi * r, c / (a + r * c), 1 / r
    for key, value in (("Lu", Lu), ("Lv", Lv), ("kappa_u", ku), ("kappa_v", kv)):
        assert math.isclose(glued[f"s3_torus_{key}"], value, rel_tol=1e-12), key
    exact = (-b * hu / ((1 + b * h * ku) * Lu), -b * hv / ((1 + b * h * kv) * Lv))
    first = (-b * hu / Lu, -b * hv / Lv)
    for key, t in (("exact", exact), ("first", first)):
        assert numbers(glued[f"s3_torus_{key}"]) == [round(x, 4) for x in t], key
    assert math.isclose(glued["s3_torus_tilt"], math.degrees(math.atan(math.hypot(*exact))), rel_tol=1e-12)
    assert glued["s3_torus_agree"] < 1e-15


def test_the_pole_and_crease_solutions_of_s7_are_redone_from_their_givens(ran):
    """§7's pole exercise (the disc R sin φ₀ magnified e/(e − R) onto the image plane; the expected
    count π radius² / pitch²) and its crease exercise (the half jump |h_R − h_L|/2; the dip, that half
    jump less the measured floor), recomputed from the glued givens."""
    ns, shown, glued = ran("s7_pitfalls")
    e, R = glued["s7_ex_camera"], glued["s7_ex_radius"]
    assert math.isclose(glued["s7_ex_magnify"], e / (e - R), rel_tol=1e-12)
    assert math.isclose(glued["s7_ex_disc"], R * glued["draft_pole_sin_phi"] * e / (e - R), rel_tol=1e-12)
    assert math.isclose(glued["s7_ex_expected"], math.pi * glued["s7_ex_disc"] ** 2 / glued["s7_ex_pitch"] ** 2,
                        rel_tol=1e-12)
    half = abs(glued["s7_crease_right"] - glued["s7_crease_left"]) / 2
    assert math.isclose(glued["s7_crease_half_jump"], half, rel_tol=1e-12)
    assert math.isclose(glued["s7_crease_dip"], half - glued["s7_crease_err_min"], rel_tol=1e-9)
    # Against the left-hand slope: the float64 quotients from the curve's signed parts (the right-hand
    # slope, its reference, plus truncation and roundoff), not from the page's central differences.
    crease = ns["crease"]
    q = glued["s7_crease_right"] + crease.truncation + crease.roundoff
    assert math.isclose(glued["s7_crease_err_min_left"], float(np.abs(q - glued["s7_crease_left"]).min()),
                        rel_tol=1e-12)
    # "Either way": the quotient came nearer each slope than half the jump at some step.
    assert max(glued["s7_crease_err_min"], glued["s7_crease_err_min_left"]) < half
