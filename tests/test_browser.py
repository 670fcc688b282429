"""The §4 simulator in a real browser: Debian's Chromium, driven by Playwright.

The built page is loaded from disk (file://), as a reader without a network
opens it, and every request that is not for a local file is blocked and
recorded.  The tests check: no console errors, MathJax typeset from the site,
canvases that are not blank; the opening scene (the draft's, shaded with the
displaced sphere's normal); the ledger's RMS and max at eps = 1e-3 and 1e-6,
and the U-curve's points, within the bounds that the JavaScript-vs-Python
error model (tests/test_js_parity.py) puts around the Python renderer's; an
eps or beta move re-shading sphere A on kept geometry (the update times go to
test-artifacts/, never asserted); each "Try this" preset's end state (its
view, its scale, and what its canvases show); the hover readout's (u, v)
within the model's chart bound of Python's; every position of every control (each
range input stepped from its own min to its max, each option, each preset) a scene that
`renderer.Scene` and `render` accept, carrying the control's value, with every value the page
prints (β, kᵤ, kᵥ, ε wherever it is written) the value computed with, and the frames Python's
for that scene at the extremes of the controls; every control reachable and
movable from the keyboard; the layout at 1280 x 900 (canvases, U-curve and
readout in view together) and at 390 px (canvases stacked, at least 300 px
wide, and a tap on a phone reading out the pixel tapped), and at both widths, scrolled through
the simulator, no control, readout, plot or caption covering another; every control a target of 24 x 24
CSS px or more at both widths, the ε slider landing on each decade by pointer (tick marks) and keyboard
(Page Up / Page Down), and the simulator used from the keyboard alone with its canvases' text alternatives
and live readout kept current.  (Every page's formulas and axe-core's audit are tests/test_book_pages.py's,
on the pages it opens once.)  Screenshots go to test-artifacts/.  Each check is shown rejecting a wrong
variant.

The tests read SYMRENDER_BOOK_HTML's site (``make audit`` builds the book first and
passes it); without it, the book is built into book/_build as ``make book`` builds it
(tests/conftest.py's ``book_html``).  With CI=true a missing Chromium or Playwright fails the test.
"""

from __future__ import annotations

import base64
import dataclasses
import functools
import json
import os
import re
import statistics
from pathlib import Path

import numpy as np
import pytest

from chapter.page import HYPHEN_MINUS
from renderer import DRAFT_SCENE, PointLight, Scene, compare, gbuffer, render
from renderer.formulas import FIELDS
from renderer.jsgen import SIMULATOR_SCENE
from renderer.render import SPHERE_A, check_args

from .jsnode import ARTIFACTS, chromium
from .test_check_glue import check_glue
from .test_js_parity import CHART_TOL, image_bound

ROOT = Path(__file__).parents[1]
SIZE = 256
CONTROLS = ["sim-height_field", "sim-log_eps", "sim-beta", "sim-bump", "sim-view", "sim-scale", "sim-numeric",
            "sim-k_u", "sim-k_v", "sim-model", "sim-resolution", "sim-zoom", "sim-sphere_b"]
BUTTONS = ["sim-preset-try1", "sim-preset-try2", "sim-preset-try3", "sim-preset-try4", "sim-reset"]
#: The readout's button (on a phone, once a pixel is read out): it shows rows and changes no scene.
READOUT_BUTTON = "sim-more"
SIM = "document.querySelector('[data-symrender-sim]').symrender"
#: numpy dtypes of the page's typed arrays, by constructor name.
TYPED = {"Uint8Array": np.uint8, "Uint8ClampedArray": np.uint8, "Int8Array": np.int8, "Uint16Array": "<u2",
         "Int16Array": "<i2", "Uint32Array": "<u4", "Int32Array": "<i4", "Float32Array": "<f4",
         "Float64Array": "<f8"}


@pytest.fixture(scope="module")
def browser():
    yield from chromium("the browser test drives Debian's Chromium")


class Session:
    """One page of the built book, with the network blocked and errors recorded.
    ``options`` go to the browser context (viewport, has_touch, is_mobile); ``bundle(text)``,
    if given, changes the simulator's script as the page receives it (a wrong variant), and
    ``css(text)`` the book's layout sheet, _static/fit.css."""

    def __init__(self, browser, url, bundle=None, css=None, **options):
        options.setdefault("viewport", {"width": 1200, "height": 1400})
        self.context = browser.new_context(**options)
        self.blocked, self.errors = [], []

        def route(r):
            path = r.request.url.split("?")[0]
            change = {"_static/sim/simulator.js": (bundle, "text/javascript"), "_static/fit.css": (css, "text/css")}
            wrong = next((c for end, c in change.items() if c[0] is not None and path.endswith(end)), None)
            if wrong is not None and path.startswith("file://"):
                from urllib.parse import unquote, urlparse
                text = Path(unquote(urlparse(path).path)).read_text(encoding="utf-8")
                r.fulfill(body=wrong[0](text), content_type=wrong[1])
            elif r.request.url.startswith("file://"):
                r.continue_()
            else:
                self.blocked.append(r.request.url)
                r.abort()

        self.context.route("**/*", route)
        self.page = self.context.new_page()
        self.page.on("console", lambda m: m.type == "error" and self.errors.append(m.text))
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.goto(url)
        self.page.wait_for_selector("[data-symrender-sim][data-updates]", state="attached", timeout=30_000)

    def updates(self):
        return int(self.page.get_attribute("[data-symrender-sim]", "data-updates"))

    def wait_update(self, before):
        self.page.wait_for_function(
            f"Number(document.querySelector('[data-symrender-sim]').dataset.updates) > {before}",
            timeout=30_000)

    def ledger(self, name):
        return float(self.page.get_attribute(f"#sim-{name}", "data-value"))

    def wait_curve(self):
        """Wait until the U-curve is drawn over every pixel (the simulator's `refine`), and return it."""
        self.page.wait_for_selector("[data-symrender-sim][data-curve]", state="attached", timeout=30_000)
        return self.sim("sim.curve")

    def fill(self, name, value):
        before = self.updates()
        self.page.fill(f"#sim-{name}", str(value))
        self.wait_update(before)

    def set_eps(self, exponent):
        self.fill("log_eps", exponent)

    def select(self, name, value):
        before = self.updates()
        self.page.select_option(f"#sim-{name}", str(value))
        self.wait_update(before)

    def click(self, button):
        before = self.updates()
        self.page.click(f"#{button}")
        self.wait_update(before)

    def sim(self, expression):
        """``expression`` evaluated on the page's simulator object (``sim``)."""
        return self.page.evaluate(f"(sim => {expression})({SIM})")

    def typed(self, expression):
        """A typed array the page holds (``expression``), as a numpy array of its dtype: its bytes
        cross as base64 (a JSON list of 256² x 4 numbers takes seconds)."""
        kind, b64 = self.page.evaluate(f"""() => {{
            const a = {expression};
            const bytes = new Uint8Array(a.buffer, a.byteOffset, a.byteLength);
            let s = "";
            for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
            return [a.constructor.name, btoa(s)];
        }}""")
        return np.frombuffer(base64.b64decode(b64), TYPED[kind]).copy()

    def canvas(self, name):
        """The canvas's RGBA bytes as an (H, W, 4) uint8 array."""
        w, h = self.page.evaluate(f"() => {{ const c = document.getElementById('sim-canvas-{name}'); "
                                  "return [c.width, c.height]; }")
        return self.typed(f"document.getElementById('sim-canvas-{name}').getContext('2d')"
                          f".getImageData(0, 0, {w}, {h}).data").reshape(h, w, 4)

    def frame(self, key):
        """An array of the symbolic frame the canvases show: chamber, kink or uv, as (H, W[, 2])."""
        n = self.sim("sim.frames.symbolic.width")
        return self.typed(f"({SIM}).frames.symbolic.{key}").reshape(n, n, -1).squeeze()

    def difference_levels(self):
        """Grey levels (0-255) of the difference canvas at the pixels on sphere A in the symbolic frame."""
        return self.canvas("difference")[..., 0][self.frame("chamber") == 1]

    def close(self):
        self.context.close()


def _url(book_html):
    return (book_html / "s4_simulator.html").as_uri()


@pytest.fixture(scope="module")
def session(browser, book_html):
    s = Session(browser, _url(book_html))
    yield s
    s.close()


def test_page_loads_offline_without_errors(session):
    page = session.page
    page.wait_for_function("document.querySelectorAll('mjx-container').length > 0", timeout=30_000)
    assert page.locator("mjx-container").count() > 5
    srcs = page.eval_on_selector_all("script[src]", "els => els.map(e => e.src)")
    # Sphinx may append a ?v=<checksum> query to a static file's address.
    paths = [s.split("?")[0] for s in srcs]
    assert any(s.startswith("file://") and s.endswith("_static/mathjax/tex-chtml.js") for s in paths)
    assert session.errors == []
    assert session.blocked == [], f"the page tried the network: {session.blocked}"


def test_canvases_are_not_blank(session):
    for name in ("numeric", "symbolic"):
        rgb = session.canvas(name)[..., :3]
        assert rgb.shape[:2] == (SIZE, SIZE)
        assert np.count_nonzero(rgb.any(axis=-1)) > 0.5 * SIZE * SIZE, name
        assert len(np.unique(rgb.reshape(-1, 3), axis=0)) > 1000, name
    assert np.count_nonzero(session.canvas("difference")[..., :3].any(axis=-1)) > 100   # sphere A differs visibly


@functools.lru_cache(maxsize=None)
def _python_frames(scene):
    """Python's central and exact frames of ``scene`` at SIZE x SIZE, and the error model's bound
    b = b_central + b_exact of |dI| between the simulator's difference and Python's (H, W, 3)."""
    return (render(scene, SIZE, SIZE, gradient="central"), render(scene, SIZE, SIZE),
            image_bound(scene, SIZE, SIZE, "central") + image_bound(scene, SIZE, SIZE, "exact"))


def _python_ledger(scene, eps, stride=1):
    """Python's ledger at eps (over the pixels of sphere A whose column and row are multiples of
    ``stride``), and bounds of how far the simulator's RMS and max may lie from it.

    Per pixel and channel the two |I_numeric - I_symbolic| differ by at most
    b = b_central + b_exact (`image_bound` of each pipeline), so the maxima
    differ by at most max b and, the RMS being a norm, the RMS by at most the
    RMS of b over the same pixels (sphere A in both frames)."""
    numeric, symbolic, b = _python_frames(scene.replace(eps=eps))
    grid = np.zeros((SIZE, SIZE), bool)
    grid[::stride, ::stride] = True
    on = grid & (numeric.chamber == 1) & (symbolic.chamber == 1)
    d = np.abs(numeric.image - symbolic.image)[on]
    led = compare(numeric, symbolic)
    return (led if stride == 1 else None, float(np.sqrt(np.mean(d**2))), float(d.max()),
            float(np.sqrt(np.mean(b[on] ** 2))), float(b[on].max()))


def _within(got, python):
    """Whether the simulator's (rms, max) lie within the error model's bounds of Python's."""
    _, rms, top, rms_bound, max_bound = python
    return abs(got[0] - rms) <= rms_bound and abs(got[1] - top) <= max_bound


def test_the_simulator_opens_on_the_sine_field_with_the_displaced_sphere_normal(session):
    """The opening scene is the default `Scene()` with the sine field (the field §3 derives), shaded
    with the displaced sphere's normal (renderer.jsgen.SIMULATOR_SCENE), and its ledger is Python's for
    that scene; Python's ledger of the draft's chart formula (the wrong variant: a simulator that ignored
    the bump control) lies outside the bounds, and so does the default field's (ridges)."""
    session.set_eps(-3)
    assert session.page.input_value("#sim-height_field") == "sine"
    assert session.page.input_value("#sim-bump") == "surface"
    assert session.page.input_value("#sim-scale") == "log"           # the sine field's differences are ~1e-4
    opened = session.sim("sim.frames.scene")
    want = json.loads(json.dumps(dataclasses.asdict(SIMULATOR_SCENE)))
    assert opened == want
    assert SIMULATOR_SCENE == Scene(height_field="sine")
    assert SIMULATOR_SCENE.replace(height_field="ridges", bump="chart") == DRAFT_SCENE   # the rest is the draft's
    got = (session.ledger("rms"), session.ledger("max"))
    assert _within(got, _python_ledger(SIMULATOR_SCENE, 1e-3))
    assert not _within(got, _python_ledger(SIMULATOR_SCENE.replace(bump="chart"), 1e-3))
    assert not _within(got, _python_ledger(Scene(), 1e-3))


def test_eps_slider_moves_the_ledger_as_python_predicts(session):
    got = {}
    for exponent in (-3, -6):
        session.set_eps(exponent)
        assert session.page.text_content("#sim-log_eps-value") == f"1.0e{exponent}"
        got[exponent] = (session.ledger("rms"), session.ledger("max"), session.ledger("flips"))
    report = {}
    for e, eps in ((-3, 1e-3), (-6, 1e-6)):
        python = _python_ledger(SIMULATOR_SCENE, eps)
        led, _, _, rms_bound, max_bound = python
        rms, top, flips = got[e]
        assert _within((rms, top), python), (e, rms, led.rms, rms_bound, top, led.max_abs, max_bound)
        assert flips == led.flips == 0
        report[f"eps={eps:g}"] = {"rms": rms, "max": top, "python_rms": led.rms, "python_max": led.max_abs,
                                  "rms_bound": rms_bound, "max_bound": max_bound}
    # The slider moves the ledger down the truncation slope: by three orders
    # of magnitude or more from 1e-3 to 1e-6.
    assert got[-6][0] < 1e-3 * got[-3][0]
    assert not _within(got[-6][:2], _python_ledger(SIMULATOR_SCENE, 1e-3))   # the check tells the steps apart
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / "browser_ledger.json").write_text(json.dumps(report, indent=1))


def test_the_u_curve_is_the_ledger_over_every_pixel_and_follows_the_controls(session):
    """The plot's points are the ledger (RMS, max |dI| on sphere A) at each step of the slider's
    range in half decades, over every pixel, within the error model of Python's ledger; the curve of
    the sample it is first drawn from (the wrong variant: on ridges it misses the pixels that straddle a
    crease) is not.  Its dots at the current step are the ledger's own numbers.  An eps move moves
    the marker only; a beta move recomputes the curve."""
    session.select("height_field", "ridges")
    session.fill("beta", SIMULATOR_SCENE.beta)
    session.set_eps(-3)
    curve = session.wait_curve()
    assert curve_table_problems(session) == []
    sample = session.sim(f"Math.max(1, Math.ceil({SIZE} / 48))")
    assert curve["stride"] == 1 and sample > 1
    steps = [p["eps"] for p in curve["points"]]
    assert len(steps) == 27 and steps[0] == 1e-14 and steps[-1] == 0.1
    assert curve["here"]["eps"] == 1e-3
    assert (curve["here"]["rms"], curve["here"]["max_abs"]) == (session.ledger("rms"), session.ledger("max"))
    # The means on and off the crease band the difference canvas's label says: Python's, within the largest
    # bound of a pixel's |ΔI| (a mean moves no further than its terms).
    led, _, _, _, max_bound = _python_ledger(SIMULATOR_SCENE.replace(height_field="ridges"), 1e-3)
    js = session.sim("sim.frames.ledger")
    assert all(abs(js[k] - getattr(led, k)) <= max_bound for k in ("mean_abs_kink", "mean_abs_off_kink")), (js, led)
    # Near 1e-3 and 10^-2.5, where the model's bound is far below the differences; each point against
    # Python at its own step (which steps the page computes with is the control tests' business).
    for near in (-3.0, -2.5):
        point = min(curve["points"], key=lambda p: abs(np.log10(p["eps"]) - near))
        eps, got = point["eps"], (point["rms"], point["max_abs"])
        ridges = SIMULATOR_SCENE.replace(height_field="ridges")
        assert _within(got, _python_ledger(ridges, eps)), eps
        assert not _within(got, _python_ledger(ridges, eps, sample)), eps
    plot = session.page.locator("#sim-curve")
    rms_line = plot.locator("#sim-curve-rms").get_attribute("points")
    assert len(rms_line.split()) == 27
    marker = plot.locator("#sim-curve-marker").get_attribute("x1")
    session.set_eps(-6)
    assert plot.locator("#sim-curve-rms").get_attribute("points") == rms_line          # the curve stays
    assert plot.locator("#sim-curve-marker").get_attribute("x1") != marker            # the marker moves
    session.fill("beta", 0.6)
    session.wait_curve()
    assert plot.locator("#sim-curve-rms").get_attribute("points") != rms_line          # recomputed
    assert curve_table_problems(session) == []                                         # and its table with it
    session.fill("beta", SIMULATOR_SCENE.beta)
    session.wait_curve()
    assert plot.locator("#sim-curve-rms").get_attribute("points") == rms_line
    assert session.errors == []


#: Run in the page: the U-curve's folded table (the simulator's ``draw_curve``), its caption and each row's cells.
CURVE_TABLE_JS = """() => ({caption: document.getElementById('sim-curve-table-caption').textContent,
  rows: [...document.querySelectorAll('#sim-curve-rows tr')].map((tr) => [...tr.children].map((c) => c.textContent))})"""


def curve_table_problems(s):
    """Where the U-curve's table departs from the curve it tabulates, once drawn over every pixel
    (`Session.wait_curve`): a row count other than the points'; a row whose ε, RMS or max |ΔI| is not its
    point's to the digits it prints; a step marked best other than the triangle's, or current other than the
    marker's (none with footprint steps); a caption that does not say every pixel."""
    curve, table = s.wait_curve(), s.page.evaluate(CURVE_TABLE_JS)
    found = [] if len(table["rows"]) == len(curve["points"]) else [
        f"{len(table['rows'])} rows for the curve's {len(curve['points'])} points"]
    triangle = s.page.locator("#sim-curve-best")
    best = float(triangle.get_attribute("data-eps")) if triangle.count() else None
    current = float(s.page.locator("#sim-curve").get_attribute("data-eps")) \
        if s.page.locator("#sim-curve-marker").count() else None
    for (eps, rms, top), p in zip(table["rows"], curve["points"]):
        marks = re.findall(r" \((best|current)\)", eps)
        cells = {"ε": (float(eps.split(" (")[0]), p["eps"], 0.05), "RMS": (float(rms), p["rms"], 5e-3),
                 "max": (float(top), p["max_abs"], 5e-3)}
        found += [f"{name} {shown!r} in the row of the point at ε = {p['eps']:.1e}, {value!r}"
                  for name, (shown, value, rel) in cells.items() if not abs(shown - value) <= rel * value]
        for mark, at in (("best", best), ("current", current)):
            if (mark in marks) != (p["eps"] == at):
                found.append(f"the row of ε = {p['eps']:.1e} {'marked' if mark in marks else 'not marked'} {mark}, "
                             f"the {'triangle' if mark == 'best' else 'marker'} at {at}")
    if "every pixel" not in table["caption"]:
        found.append(f"the table's caption: {table['caption']!r}")
    return found


#: Wrong variants of the U-curve's table: (old text of the bundle, new text).
WRONG_TABLE = {
    "filled once, from the sampled curve": ("this.curve_rows.replaceChildren(",
                                           "if (!this.curve_rows.children.length) this.curve_rows.replaceChildren("),
    "the best step unmarked": ('marked && i === best && "best"', 'false'),
    "the current step unmarked": ('i === current && "current"', 'false'),
    "the current step marked with footprint steps too": ("const current = unused ? -1 : ", "const current = "),
    "the RMS under max": ('el("td", { text: fmt(p.max_abs, 2) })', 'el("td", { text: fmt(p.rms, 2) })'),
    "a caption naming the sample": ("over ${sample};", "over a sample;"),
}


@pytest.mark.parametrize("variant", sorted(WRONG_TABLE))
def test_the_table_check_catches_a_stale_or_wrong_curve_table(browser, book_html, variant):
    s = _simulator_at(browser, book_html, 1280, bundle=_replaced_once(*WRONG_TABLE[variant], variant))
    try:
        if not curve_table_problems(s):          # as it opens, else with footprint steps
            s.select("numeric", "footprint")
            assert curve_table_problems(s), variant
    finally:
        s.close()


def test_the_curve_marks_its_image_best_step_and_names_its_right_arm_per_field(session):
    """The triangle stands at the step of least RMS among the curve's points (a marker at the largest
    RMS, the wrong variant, stands elsewhere) and is labelled; at beta = 0 every RMS is 0 and there is
    none.  The caption names the right arm per field: crease error on ridges, truncation on sine and
    rings (whose captions agree)."""
    session.select("height_field", "ridges")
    session.fill("beta", SIMULATOR_SCENE.beta)
    session.set_eps(-3)
    points = session.wait_curve()["points"]
    best, worst = min(points, key=lambda p: p["rms"]), max(points, key=lambda p: p["rms"])
    plot = session.page.locator("#sim-curve")
    eps = float(plot.locator("#sim-curve-best").get_attribute("data-eps"))
    assert eps == best["eps"] and eps != worst["eps"]
    # Its step printed beside it and spoken in the plot's label, as the ε slider prints a step.
    printed = f"{eps:.1e}".replace("e-0", "e-")
    assert plot.locator("#sim-curve-best-label").text_content() == f"best ε = {printed}"
    assert plot.get_attribute("aria-label").endswith(f"; the image-best step: {printed}")
    captions = {}
    for field in FIELDS:
        session.select("height_field", field)
        captions[field] = session.page.text_content("#sim-curve-caption")
    smooth = {captions[f] for f in FIELDS if not FIELDS[f].crease_factors}
    assert all(("crease" in captions[f]) == bool(FIELDS[f].crease_factors) for f in FIELDS), captions
    assert len(smooth) == 1 and "truncation" in smooth.pop(), captions
    session.fill("beta", 0)
    assert plot.locator("#sim-curve-best").count() == 0 and "image-best" not in plot.get_attribute("aria-label")
    session.fill("beta", SIMULATOR_SCENE.beta)
    assert session.errors == []


def test_an_eps_or_beta_move_reshades_sphere_a_only_and_is_timed(browser, book_html):
    """Slider moves of eps re-shade the numeric pipeline only, of beta both, on the kept
    geometry; a resolution change (the wrong variant for "kept") makes new geometry.  The
    update times (median of the moves, at 256 x 256) go to test-artifacts/browser_timing.json,
    with the machine's load: they are reported, not asserted."""
    s = Session(browser, _url(book_html))
    try:
        moves = {"eps": ("log_eps", [-3.1, -3]), "beta": ("beta", [0.3, 0.4])}
        report = {"size": SIZE, "load_average_1min": os.getloadavg()[0]}
        for kind, (control, values) in moves.items():
            start = len(s.sim("sim.timings"))
            for k in range(16):
                s.fill(control, values[k % 2])
            timings = s.sim("sim.timings")[start:]
            assert len(timings) == 16 and not any(t["full"] for t in timings), kind
            want = ["numeric"] if kind == "eps" else ["symbolic", "numeric"]
            assert all(t["shaded"] == want for t in timings), kind
            assert all(t["resolution"] == SIZE for t in timings)
            ms = [t["ms"] for t in timings[1:]]          # the first move warms the JIT up
            report[kind] = {"updates": len(ms), "median_ms": statistics.median(ms), "min_ms": min(ms),
                            "max_ms": max(ms), **{f"median_{p}": statistics.median(t[p] for t in timings[1:])
                                                  for p in ("shade_ms", "draw_ms", "curve_ms")}}
        s.select("resolution", 128)
        assert s.sim("sim.timings.at(-1).full") is True
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        (ARTIFACTS / "browser_timing.json").write_text(json.dumps(report, indent=1))
        print("simulator update at 256^2:", json.dumps(report))
        assert s.errors == [] and s.blocked == []
    finally:
        s.close()


def test_hover_readout_gives_pythons_chart(session):
    """Mouse events carry whole CSS pixels, so the test aims at a pixel, reads
    which pixel the readout reports (within one of the aim), and compares that
    pixel's (u, v) with Python's, within the error model's chart bound (the
    browser's atan2 may round the last bit differently)."""
    session.select("resolution", SIZE)
    session.select("zoom", 1)
    gb = gbuffer(Scene(), SIZE, SIZE)
    rows, cols = np.nonzero(gb.chamber == 1)
    pick = [(int(cols[k]), int(rows[k])) for k in (len(rows) // 5, len(rows) // 3, len(rows) // 2,
                                                   4 * len(rows) // 5)]
    canvas = session.page.locator("#sim-canvas-symbolic")
    # Centre it in the viewport: the theme's sticky header covers the top of the page.
    canvas.evaluate("c => c.scrollIntoView({block: 'center'})")
    box = canvas.bounding_box()
    checked = set()
    for i, j in pick:
        session.page.mouse.move(box["x"] + (i + 0.5) * box["width"] / SIZE,
                                box["y"] + (j + 0.5) * box["height"] / SIZE)
        ri, rj = _readout_pixel(session, i, j)
        assert gb.chamber[rj, ri] == int(session.page.get_attribute("#sim-readout", "data-chamber")) == 1
        u = float(session.page.get_attribute("#sim-readout", "data-u"))
        v = float(session.page.get_attribute("#sim-readout", "data-v"))
        assert abs(u - gb.uv[rj, ri, 0]) <= CHART_TOL and abs(v - gb.uv[rj, ri, 1]) <= CHART_TOL, (ri, rj)
        checked.add((ri, rj))
    assert len(checked) == len(pick)
    assert "(u, v)" in session.page.text_content("#sim-readout")


def _readout_pixel(session, i, j):
    """Wait until the readout shows a pixel within one of (i, j); return the pixel it shows."""
    session.page.wait_for_function(
        f"Math.abs(Number(document.getElementById('sim-readout').dataset.i) - {i}) <= 1 && "
        f"Math.abs(Number(document.getElementById('sim-readout').dataset.j) - {j}) <= 1", timeout=10_000)
    return (int(session.page.get_attribute("#sim-readout", "data-i")),
            int(session.page.get_attribute("#sim-readout", "data-j")))


# ---- the controls held against the Python scene --------------------------------------------

#: Run in the page with a list of moves [[element id, how], ...].  ``how`` is "min" or "max" (a
#: range input's own min or max, a select's first or last option), a value, or "every": each
#: position the control has (a range input from its min to its max by the browser's own stepUp,
#: as the arrow keys move it; each option of a select; both states of a checkbox; a button's
#: click).  Each move is made as a reader makes it (the input or change event a drag or a choice
#: fires, or a click) and the update it schedules is awaited; the page's requestAnimationFrame is
#: made to call back at the next task, so the test does not wait for the screen's refresh.  After
#: each position of an "every" the page is recorded: every input's value, every range's printed
#: value, the scene object the renderer was handed, the renderer's other arguments (width, height,
#: numeric gradient, zoom: `render.check_args`'s order, read off its frame and G-buffer), and
#: every text that prints ε (the numeric canvas's caption and text alternative, the U-curve's label and marker, the
#: readout's step at the centre pixel).  A move the page does not update after (an uncaught error
#: came first, or 5 s passed) is recorded as such and ends the run.  Returns the records.
MOVES_JS = """async (moves) => {
  const root = document.querySelector('[data-symrender-sim]'), sim = root.symrender;
  window.requestAnimationFrame = (cb) => setTimeout(() => cb(performance.now()), 0);
  let threw = false;
  window.addEventListener('error', () => { threw = true; });
  window.addEventListener('unhandledrejection', () => { threw = true; });
  const inputs = [...root.querySelectorAll('input, select')];
  // Make a change and wait for the update it schedules; false if the page threw first or none came in 5 s.
  const act = async (change) => {
    const n = Number(root.dataset.updates), t0 = performance.now();
    change();
    while (Number(root.dataset.updates) <= n) {
      if (threw || performance.now() - t0 > 5000) return false;
      await new Promise((r) => setTimeout(r, 0));
    }
    return true;
  };
  const set = (e, value) => act(() => {
    if (e.type === 'checkbox') e.checked = value; else e.value = String(value);
    e.dispatchEvent(new Event(e.type === 'range' ? 'input' : 'change'));
  });
  const record = (id, updated) => {
    const values = Object.fromEntries(inputs.map((e) => [e.id.slice(4), e.type === 'checkbox' ? e.checked : e.value]));
    if (!updated) return { id, updated, inputs: values };
    const f = sim.frames, res = f.numeric.width, plot = document.getElementById('sim-curve');
    sim.show_probe(res >> 1, res >> 1);
    const step = [...document.querySelectorAll('#sim-readout dt')].find((dt) => dt.textContent === 'step');
    return { id, updated, inputs: values, scene: f.scene,
             args: [f.numeric.width, f.numeric.height, f.numeric.gradient, sim.renderer.gb.zoom],
             printed: Object.fromEntries(inputs.filter((e) => e.type === 'range').map((e) =>
                                         [e.id.slice(4), document.getElementById(e.id + '-value').textContent])),
             eps_texts: [document.getElementById('sim-caption-numeric').textContent, plot.getAttribute('aria-label'),
                         document.getElementById('sim-canvas-numeric').getAttribute('aria-label'),
                         'ε = ' + plot.dataset.eps, step ? step.nextElementSibling.textContent : ''] };
  };
  const out = [];
  // Record a position; false (stop: the page is stuck) if it did not update.
  const keep = (id, updated) => { out.push(record(id, updated)); return updated; };
  for (const [id, how] of moves) {
    const e = document.getElementById(id);
    const options = e.tagName === 'SELECT' ? [...e.options].map((o) => o.value) : null;
    let updated = true;
    if (e.tagName === 'BUTTON') {
      updated = await act(() => e.click());
      if (how === 'every' && !keep(id, updated)) break;
    } else if (how !== 'every') {
      const [low, high] = options ? [options[0], options.at(-1)] : [e.min, e.max];
      updated = await set(e, how === 'min' ? low : how === 'max' ? high : how);
    } else if (e.type === 'range') {
      if (!keep(id, await set(e, e.min))) break;
      while (updated && Number(e.value) < Number(e.max)) {
        const before = e.value;
        updated = await act(() => { e.stepUp(); e.dispatchEvent(new Event('input')); });
        if (e.value === before) break;
        updated = keep(id, updated);
      }
    } else {
      for (const value of options ?? [false, true]) if (!(updated = keep(id, await set(e, value)))) break;
    }
    if (!updated) { if (how !== 'every') keep(id, false); break; }
  }
  return out;
}"""


#: Where each control's value lands: a field of the scene object the simulator hands its renderer
#: (``("scene", field)``; log_eps's value x lands as ε = 10^x), one of the renderer's other
#: arguments (``("args", k)``: width, numeric gradient, zoom), or nowhere (``None``: how the frames
#: are shown).  A control of the page missing here is a problem: a new one cannot go unchecked.
LANDS = {"log_eps": ("scene", "eps"), "beta": ("scene", "beta"), "k_u": ("scene", "k_u"), "k_v": ("scene", "k_v"),
         "height_field": ("scene", "height_field"), "model": ("scene", "model"), "bump": ("scene", "bump"),
         "sphere_b": ("scene", "sphere_b"), "resolution": ("args", 0), "numeric": ("args", 2),
         "zoom": ("args", 3), "view": None, "scale": None}
#: ε as the page prints it in words ("ε = 1.3e-3"; the readout's "εᵤ = ..." of a footprint is not ε).
EPS_TEXT = re.compile(r"ε = ([-+0-9.e]+)")


def js_scene(obj):
    """The `renderer.Scene` of the simulator's scene object (JSON); raises as `Scene` does."""
    fields = {k: tuple(v) if isinstance(v, list) else v for k, v in obj.items()}
    fields["lights"] = tuple(PointLight(tuple(light["position"]), tuple(light["color"])) for light in obj["lights"])
    return Scene(**fields)


def control_problems(records):
    """Every way the recorded positions (`MOVES_JS`) depart from the Python scene, as strings: a
    scene or renderer argument `renderer.Scene` or `render` refuses; a control whose value is not
    what the scene object (or the renderer's arguments) carries; a printed value that is not the
    value computed with; a printed ε that does not name 10^x to the digits it shows; ε not
    strictly increasing along a sweep of its slider; a move the simulator did not update after."""
    problems, sweep = [], []
    for r in records:
        at = f"{r['id']} at {', '.join(f'{k}={v}' for k, v in r['inputs'].items())}"
        bad = problems.append
        if not r["updated"]:
            bad(f"{at}: the simulator did not update (its renderer threw)")
            continue
        try:
            scene = js_scene(r["scene"])
            check_args(scene, *r["args"])
        except (TypeError, ValueError) as error:
            bad(f"{at}: the Python renderer refuses what the simulator renders: {error}")
            continue
        for name, value in r["inputs"].items():
            if name not in LANDS:
                bad(f"{at}: the control {name!r} lands nowhere the test knows (LANDS)")
                continue
            if LANDS[name] is None:
                continue
            kind, key = LANDS[name]
            landed = getattr(scene, key) if kind == "scene" else r["args"][key]
            if name == "log_eps":
                printed = r["printed"][name].removesuffix(", unused")      # footprint steps: ε is carried, unused
                shown = [printed] + [m for text in r["eps_texts"] for m in EPS_TEXT.findall(text)]
                if any(float(s) != landed for s in shown):
                    bad(f"{at}: ε is printed as {shown} but computed with {landed!r}")
                if not check_glue._matches(printed, 10.0 ** float(value)):
                    bad(f"{at}: ε printed {r['printed'][name]} is not 10^{value} to the digits it shows")
            elif type(landed)(value) != landed or (name in r["printed"] and float(r["printed"][name]) != landed):
                bad(f"{at}: {name} is {value!r} (printed {r['printed'].get(name)!r}) but the renderer gets {landed!r}")
        if r["id"] == "sim-log_eps":
            sweep.append((float(r["inputs"]["log_eps"]), scene.eps))
    for (x0, e0), (x1, e1) in zip(sweep, sweep[1:]):
        if x1 > x0 and not e1 > e0:
            problems.append(f"ε does not increase from log_eps={x0:g} ({e0!r}) to {x1:g} ({e1!r})")
    return problems


def every_position(s):
    """`MOVES_JS` over every position of every control of the page, presets and reset included, at
    the smallest resolution (the largest once): β's range under each shading normal (its top
    depends on it), the other ranges, each select and checkbox, then the buttons."""
    layout = s.page.evaluate("""() => [...document.querySelectorAll('[data-symrender-sim] :is(input, select, button)')]
        .map((e) => [e.id, e.tagName === 'SELECT' ? [...e.options].map((o) => o.value) : e.type])""")
    moves = [("sim-resolution", "min")]
    for bump in dict(layout)["sim-bump"]:
        moves += [("sim-bump", bump), ("sim-beta", "every")]
    moves += [(i, "every") for i, k in layout if k == "range" and i != "sim-beta"]
    moves += [(i, "every") for i, k in layout if isinstance(k, list) or k == "checkbox"]
    moves += [("sim-resolution", "min")] + [(i, "every") for i, k in layout if k in ("button", "submit") and i != READOUT_BUTTON]
    return s.page.evaluate(MOVES_JS, moves)


def test_every_position_of_every_control_is_a_scene_python_renders_and_prints_what_it_computes_with(browser, book_html):
    """Every slider position (ε, β under both shading normals, kᵤ, kᵥ; enumerated from each input's
    own min, max and step), every option of every select, the checkbox and every preset: the scene
    object the simulator hands its renderer is one `renderer.Scene` accepts and `render` renders
    (size, zoom, numeric gradient), each control's value is what the scene carries, and each value
    the page prints (β, kᵤ, kᵥ, and ε in its label, the numeric caption, the U-curve's label and
    marker, the readout's step) is the value computed with; the printed ε names 10^x to its digits
    and grows with x.  Wrong variants of the simulator are rejected below."""
    s = Session(browser, _url(book_html))
    try:
        records = every_position(s)
        problems = control_problems(records)
        assert not problems, f"{len(problems)} problems, e.g. " + "\n".join(problems[:10])
        assert len({r["id"] for r in records}) >= len(LANDS) + len(BUTTONS)         # every control was moved
        assert s.errors == []
    finally:
        s.close()


#: Positions at which the simulator's frames are held against Python's: each a list of moves
#: (`MOVES_JS`) from the opening state at the smallest resolution: the extremes of every slider,
#: under both shading normals for β, and of the selects that change what is rendered.
FRAME_POSITIONS = {
    "ε smallest": [("sim-log_eps", "min")],
    "ε largest": [("sim-log_eps", "max")],
    "β 0": [("sim-beta", "min")],
    "β largest, the displaced sphere": [("sim-beta", "max")],
    "β largest, the draft's normal": [("sim-bump", "chart"), ("sim-beta", "max")],
    "kᵤ, kᵥ smallest, sine": [("sim-height_field", "sine"), ("sim-k_u", "min"), ("sim-k_v", "min")],
    "kᵤ, kᵥ largest, rings": [("sim-height_field", "rings"), ("sim-k_u", "max"), ("sim-k_v", "max")],
    "footprint, phong, no sphere B, the pole at its largest zoom": [
        ("sim-numeric", "footprint"), ("sim-model", "phong"), ("sim-sphere_b", False), ("sim-zoom", "max")],
}


def frame_problems(s):
    """Where the simulator's two frames depart from `render` of the scene object it rendered (at its
    size, zoom and numeric gradient): a chamber code, or an image value beyond the JS-parity error
    model's bound (`image_bound`)."""
    at = s.sim("[sim.frames.scene, sim.frames.numeric.width, sim.frames.numeric.height, "
               "sim.frames.numeric.gradient, sim.renderer.gb.zoom]")
    scene, (w, h, numeric, zoom) = js_scene(at[0]), at[1:]
    out = []
    for key, gradient in (("numeric", numeric), ("symbolic", "exact")):
        py = render(scene, w, h, gradient=gradient, zoom=zoom)
        chamber = s.typed(f"({SIM}).frames.{key}.chamber").reshape(h, w)
        image = s.typed(f"({SIM}).frames.{key}.image").reshape(h, w, 3)
        if not np.array_equal(chamber, py.chamber):
            out.append(f"{key}: {np.count_nonzero(chamber != py.chamber)} chamber codes differ")
            continue
        ratio = np.abs(image - py.image) / image_bound(scene, w, h, gradient, zoom)
        if not ratio.max() <= 1.0:
            out.append(f"{key} ({gradient}): {np.count_nonzero(~(ratio <= 1.0))} values beyond the bound, "
                       f"worst |d| / bound {ratio.max():.3g}")
    return out


def test_with_footprint_steps_the_eps_slider_is_disabled_and_says_it_is_unused(session):
    """Each pixel's footprint as its step leaves ε nothing to do: the slider is disabled and its printed value
    says "unused" (a reader once moved it and watched nothing change), and the U-curve marks no current ε,
    its caption saying why (the frame's error had been drawn at ε), and its label speaks the frame's ledger; back on
    central differences all is live."""
    s = session
    try:
        s.select("numeric", "footprint")
        assert s.page.is_disabled("#sim-log_eps") and s.page.text_content("#sim-log_eps-value").endswith(", unused")
        assert s.page.locator("#sim-curve-marker").count() == 0
        assert "no ε is marked" in s.page.text_content("#sim-curve-caption")
        assert curve_table_problems(s) == []                # no row marked current
        label = s.page.get_attribute("#sim-curve", "aria-label")
        # The label speaks the frame's own numbers, the ledger's (it had kept those of the last ε).
        said = [f"{s.ledger(name):.1e}".replace("e-0", "e-") for name in ("rms", "max")]     # as the page prints
        assert f"footprint as its step: RMS {said[0]}, max {said[1]}" in label, label
        s.select("numeric", "central")
        assert s.page.is_enabled("#sim-log_eps") and "unused" not in s.page.text_content("#sim-log_eps-value")
        assert s.page.locator("#sim-curve-marker").count() == 1
    finally:
        s.click("sim-reset")


def test_the_simulators_frames_are_pythons_at_the_extremes_of_its_controls(browser, book_html):
    """At each of `FRAME_POSITIONS`, both frames the simulator shows are `renderer.render`'s of the
    Scene built from the simulator's own scene object, within the bound tests/test_js_parity.py
    derives (chamber codes exactly)."""
    s = Session(browser, _url(book_html))
    try:
        found = {}
        for name, moves in FRAME_POSITIONS.items():
            stuck = control_problems(s.page.evaluate(MOVES_JS, [("sim-reset", "click"), ("sim-resolution", "min"),
                                                                *moves]))
            found[name] = stuck or frame_problems(s)
        assert not any(found.values()), found
        assert s.errors == []
    finally:
        s.close()


#: Wrong variants of the simulator's script, served to the page in place of the built one:
#: (old text, new text, the moves that show it, what the problem says).
WRONG_CONTROLS = {
    "ε rounded to one significant digit": (
        "Math.pow(10, log_eps).toPrecision(2)", "Math.pow(10, log_eps).toPrecision(1)",
        [("sim-log_eps", "every")], "is not 10^"),
    "ε computed unrounded, printed rounded": (
        "eps: eps_of(state.log_eps)", "eps: Math.pow(10, state.log_eps)", [("sim-log_eps", "every")],
        "but computed with"),
    "β up to R under the displaced sphere's normal": (
        "Math.round(100 * (SIMULATOR_SCENE.radius_a - BETA.step)) / 100", "SIMULATOR_SCENE.radius_a",
        [("sim-bump", "surface"), ("sim-beta", "max")], "did not update"),
    "kᵤ from 0": ('name: "k_u", label: "kᵤ, frequency in u (even)", kind: "range", min: 2',
                 'name: "k_u", label: "kᵤ, frequency in u (even)", kind: "range", min: 0', [("sim-k_u", "every")], "refuses"),
    "the renderer handed a β of its own": (
        "this.renderer.update(scene,", "this.renderer.update({ ...scene, beta: 0.9 * scene.beta },", None,
        "values beyond"),
}


@pytest.mark.parametrize("variant", sorted(WRONG_CONTROLS))
def test_the_control_checks_reject_a_wrong_simulator(browser, book_html, variant):
    old, new, moves, message = WRONG_CONTROLS[variant]

    def bundle(text):
        assert text.count(old) == 1, f"variant {variant!r} no longer applies to the bundle"
        return text.replace(old, new)

    s = Session(browser, _url(book_html), bundle=bundle)
    try:
        if moves is None:
            s.page.evaluate(MOVES_JS, [("sim-resolution", "min"), ("sim-beta", "max")])
            found = frame_problems(s)
        else:
            found = control_problems(s.page.evaluate(MOVES_JS, [("sim-resolution", "min"), *moves]))
        assert any(message in p for p in found), (variant, found[:5])
    finally:
        s.close()


def test_every_control_is_reachable_and_movable_from_the_keyboard(browser, book_html):
    s = Session(browser, _url(book_html))
    try:
        page = s.page
        page.focus("#sim-preset-try1")
        seen = ["sim-preset-try1"]
        for _ in range(40):
            page.keyboard.press("Tab")
            seen.append(page.evaluate("document.activeElement.id"))
        missing = [c for c in CONTROLS + BUTTONS + ["sim-canvas-numeric"] if c not in seen]
        assert not missing, f"not reachable with Tab: {missing}"
        # Move each control with the keys a keyboard user has.
        for cid in CONTROLS:
            page.focus(f"#{cid}")
            kind = page.evaluate(f"document.getElementById('{cid}').type")
            value = lambda: page.evaluate(  # noqa: E731
                f"(e => e.type === 'checkbox' ? e.checked : e.value)(document.getElementById('{cid}'))")
            before, n = value(), s.updates()
            key = {"range": "ArrowLeft" if cid == "sim-log_eps" else "ArrowRight",
                   "checkbox": "Space"}.get(kind, "ArrowDown")
            if cid in ("sim-resolution", "sim-bump"):
                key = "ArrowUp"          # 256 -> 128 keeps the test quick; the displaced sphere is the last option
            page.keyboard.press(key)
            s.wait_update(n)
            assert value() != before, (cid, kind, key)
        for bid in BUTTONS:
            page.focus(f"#{bid}")
            n = s.updates()
            page.keyboard.press("Enter")
            s.wait_update(n)
        assert page.input_value("#sim-height_field") == "sine"       # reset was last
        # The probe moves with the arrow keys on a focused canvas.
        page.focus("#sim-canvas-symbolic")
        page.keyboard.press("ArrowRight")
        assert page.get_attribute("#sim-readout", "data-i") is not None
        assert s.errors == [] and s.blocked == []
    finally:
        s.close()


# ---- the simulator for every hand, keyboard and screen reader --------------------------------------

#: Run in the page: each control of the simulator (input, select, button) shown as [id, width, height] in CSS px.
CONTROL_BOXES_JS = """() => [...document.querySelectorAll('[data-symrender-sim] :is(input, select, button)')]
  .filter(e => e.checkVisibility()).map(e => {
  const r = e.getBoundingClientRect(); return [e.id, +r.width.toFixed(1), +r.height.toFixed(1)]; })"""
#: The least target, CSS px a side (WCAG 2.2, 2.5.8, AA).
MIN_TARGET_PX = 24


def _simulator_at(browser, book_html, width, bundle=None):
    """The §4 page at ``width`` px, 844 px tall with touch at 390 px (a phone), 900 at 1280."""
    phone = width < 720
    options = dict(viewport={"width": width, "height": 844 if phone else 900})
    if phone:
        options.update(has_touch=True, is_mobile=True, device_scale_factor=2)
    return Session(browser, _url(book_html), bundle=bundle, **options)


def small_targets(s):
    """The simulator's controls smaller than `MIN_TARGET_PX` either way, and the count of all."""
    boxes = s.page.evaluate(CONTROL_BOXES_JS)
    return [b for b in boxes if min(b[1], b[2]) < MIN_TARGET_PX], len(boxes)


@pytest.mark.parametrize("width", [390, 1280])
def test_every_control_is_a_target_of_at_least_24_px(browser, book_html, width):
    """Every slider, menu, checkbox and button of the simulator at least 24 x 24 CSS px (the browser's
    own: sliders 16 px tall, menus 20, the checkbox 13), on a phone with a pixel read out (its readout's button
    shown); the boxes go to test-artifacts/s4_targets_<width>.json."""
    s = _simulator_at(browser, book_html, width)
    try:
        phone = width < 720
        if phone:
            s.page.tap("#sim-canvas-symbolic")
        small, count = small_targets(s)
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        (ARTIFACTS / f"s4_targets_{width}.json").write_text(json.dumps(s.page.evaluate(CONTROL_BOXES_JS), indent=1))
        assert count == len(CONTROLS) + len(BUTTONS) + phone
        assert not small, small
    finally:
        s.close()


#: Run in the page: ["<menu id>: <option>"] for each option of each of the simulator's menus whose label, in the
#: menu's font, is wider than the menu's box less its padding and what Chromium draws beside the text
#: (`MENU_ARROW_PX`: 4 px before it, the arrow and its margin after it).
MENU_ARROW_PX = 32
CLIPPED_OPTIONS_JS = """() => {
  const ruler = document.createElement('span');
  ruler.style.cssText = 'position: absolute; visibility: hidden; white-space: pre';
  document.body.append(ruler);
  const found = [];
  for (const menu of document.querySelectorAll('[data-symrender-sim] select')) {
    const s = getComputedStyle(menu);
    ruler.style.font = s.font;
    const room = menu.clientWidth - parseFloat(s.paddingLeft) - parseFloat(s.paddingRight) - ARROW;
    for (const o of menu.options) {
      ruler.textContent = o.textContent;
      if (ruler.getBoundingClientRect().width > room) found.push(menu.id + ': ' + o.textContent);
    }
  }
  ruler.remove();
  return found;
}""".replace("ARROW", str(MENU_ARROW_PX))


@pytest.mark.parametrize("width", [390, 1280])
def test_every_menu_shows_each_option_whole(browser, book_html, width):
    """No option of the simulator's menus is cut off by the menu's box (`CLIPPED_OPTIONS_JS`); with the numeric
    gradient's old, longer label (the wrong variant) the check finds it cut at 1280 px, three menus a row."""
    s = _simulator_at(browser, book_html, width)
    try:
        assert s.page.evaluate(CLIPPED_OPTIONS_JS) == []
    finally:
        s.close()
    if width == 1280:
        old = 'central: "central, one step ε"'
        s = _simulator_at(browser, book_html, width,
                          bundle=_replaced_once(old, 'central: "central differences, step ε"', "a longer label"))
        try:
            assert s.page.evaluate(CLIPPED_OPTIONS_JS) == ["sim-numeric: central differences, step ε"]
        finally:
            s.close()


def test_the_target_check_catches_the_browsers_20_px_menus(browser, book_html):
    """Wrong variant: the menus at the browser's height (20 px) are caught, every one of them."""
    old = ".symrender-sim select { min-height: 1.75rem; }"

    def bundle(text):
        assert text.count(old) == 1
        return text.replace(old, "")

    s = _simulator_at(browser, book_html, 390, bundle=bundle)
    try:
        small, _ = small_targets(s)
        menus = s.page.evaluate("document.querySelectorAll('[data-symrender-sim] select').length")
        assert len(small) == menus and all(b[2] == 20 for b in small), small
    finally:
        s.close()


#: The decades of the ε slider (log10 ε).
DECADES = range(-14, 0)
#: Chromium's range thumb, CSS px wide: the slider's value v sits at left + THUMB/2 + (v - min)/(max - min)
#: (width - THUMB).
THUMB = 16


def eps_pointer_landings(s, offsets, tap):
    """{decade: [value of the ε slider after a click (``tap``: a tap) at the decade's position + offset
    px, for each of ``offsets``]}; before each, the slider is moved to the end of its range away from
    the decade (a click on the thumb itself would not move it)."""
    slider = s.page.locator("#sim-log_eps")
    slider.evaluate("e => e.scrollIntoView({block: 'center'})")
    box = slider.bounding_box()
    lo, hi = (float(slider.get_attribute(a)) for a in ("min", "max"))
    out = {}
    for k in DECADES:
        out[k] = []
        for dx in offsets:
            slider.evaluate("(e, v) => { e.value = v; e.dispatchEvent(new Event('input')); }",
                            str(lo if k > (lo + hi) / 2 else hi))
            x = box["x"] + THUMB / 2 + (k - lo) / (hi - lo) * (box["width"] - THUMB) + dx
            y = box["y"] + box["height"] / 2
            if tap:
                s.page.touchscreen.tap(x, y)
            else:
                s.page.mouse.click(x, y)
            out[k].append(slider.input_value())
    return out


#: Keys pressed on the focused ε slider from the opening step, 1e-3, and the value after each.
EPS_KEYS = [("PageDown", "-4"), ("PageDown", "-5"), ("PageDown", "-6"), ("ArrowLeft", "-6.1"), ("PageUp", "-6"),
            *[("ArrowLeft", None)] * 9, ("ArrowLeft", "-7"), ("PageDown", "-8"), ("ArrowRight", "-7.9"),
            ("PageDown", "-8"), ("Home", "-14"), ("PageDown", "-14"), ("End", "-1"), ("PageUp", "-1")]


def eps_key_landings(s):
    """[(key, value of the ε slider after it)] for `EPS_KEYS`, from the opening step, the slider focused."""
    s.page.focus("#sim-log_eps")
    out = []
    for key, _ in EPS_KEYS:
        s.page.keyboard.press(key)
        out.append((key, s.page.input_value("#sim-log_eps")))
    return out


@pytest.mark.parametrize("width", [390, 1280])
def test_the_eps_slider_lands_on_every_decade_by_pointer_and_by_keyboard(browser, book_html, width):
    """The ε slider moves by tenths of a decade; each decade is a tick mark to which the pointer snaps:
    a click (a tap on the phone) 3 px either side of a decade's place lands on that decade exactly (a
    tenth of a decade is 1.6 px at 1280, 2.6 px at 390), and the page prints 1.0e-k.  From the keyboard,
    the arrow keys move a tenth, Page Up and Page Down to the next decade, Home and End to the ends."""
    s = _simulator_at(browser, book_html, width)
    try:
        landed = eps_pointer_landings(s, (-3, 3), tap=width < 720)
        missed = {k: v for k, v in landed.items() if v != [str(k)] * 2}
        assert not missed, missed
        s.page.locator("#sim-log_eps").evaluate("(e) => { e.value = '-6'; e.dispatchEvent(new Event('input')); }")
        # (an update the clicks scheduled may come first: wait for the frame of this step)
        s.page.wait_for_function(f"{SIM}.frames.scene.eps === 1e-6", timeout=30_000)
        assert s.page.text_content("#sim-log_eps-value") == "1.0e-6"
        assert s.page.get_attribute("#sim-log_eps", "aria-valuetext") == "1.0e-6"
        s.page.evaluate(f"(sim => sim.apply_preset({{set: {{}}}}))({SIM})")           # back to the opening 1e-3
        got = eps_key_landings(s)
        want = [(k, v) for k, v in EPS_KEYS]
        assert [g for g, w in zip(got, want) if w[1] is not None] == [w for w in want if w[1] is not None], got
        assert s.errors == []
    finally:
        s.close()


#: Wrong variants of the ε slider: (old text of the bundle, new text, which landing must fail).
WRONG_EPS = {
    "no tick marks (the pointer lands a tenth or two off)": (
        'input.setAttribute("list", ticks[0].id);', "", "pointer"),
    "Page Up and Page Down left to the browser (a tenth of the range: 1.3 decades)": (
        'input.addEventListener("keydown", (ev) => this.tick_key(c, input, ev));', "", "keys"),
}


def _replaced_once(old, new, variant):
    """A bundle transform for a wrong variant: ``old`` (which must occur once) replaced by ``new``."""
    def bundle(text):
        assert text.count(old) == 1, f"variant {variant!r} no longer applies to the bundle"
        return text.replace(old, new)
    return bundle


@pytest.mark.parametrize("variant", sorted(WRONG_EPS))
def test_the_decade_check_catches_a_slider_without_ticks_or_decade_keys(browser, book_html, variant):
    old, new, which = WRONG_EPS[variant]
    s = _simulator_at(browser, book_html, 390, bundle=_replaced_once(old, new, variant))
    try:
        if which == "pointer":
            landed = eps_pointer_landings(s, (-3, 3), tap=True)
            assert sum(v != [str(k)] * 2 for k, v in landed.items()) >= len(DECADES) // 2, landed
        else:
            got = dict(enumerate(eps_key_landings(s)))
            assert got[0] != ("PageDown", "-4"), got
    finally:
        s.close()


#: Run in the page: what a screen reader is given for the simulator: each canvas's role and label, the
#: hint's live region, the status line's role and text, the other live regions (the readout, the ledger, the
#: sliders' printed values: none may be one), the U-curve's role and label, the ε slider's value text.
SPOKEN_JS = """() => {
  const attr = (sel, a) => document.querySelector(sel).getAttribute(a);
  return {canvases: Object.fromEntries(['numeric', 'symbolic', 'difference'].map(n =>
            [n, [attr('#sim-canvas-' + n, 'role') + ' ' + attr('#sim-canvas-' + n, 'aria-roledescription'),
                 attr('#sim-canvas-' + n, 'aria-label')]])),
          hint: attr('#sim-hint', 'aria-live'), curve: [attr('#sim-curve', 'role'), attr('#sim-curve', 'aria-label')],
          status: [attr('#sim-status', 'role'), document.getElementById('sim-status').textContent],
          live: [...document.querySelectorAll('.symrender-sim :is(table, output, [aria-live])')].filter(e =>
            e.getAttribute('aria-hidden') !== 'true' && (e.tagName === 'OUTPUT' ? e.getAttribute('aria-live') !== 'off'
            : e.getAttribute('aria-live') && e.getAttribute('aria-live') !== 'off') && !['sim-hint', 'sim-note'].includes(e.id))
            .map(e => e.id || e.className),
          eps: attr('#sim-log_eps', 'aria-valuetext'),
          // What reads after the difference canvas, of the readout and the U-curve, in document order.
          order: ['#sim-readout', '#sim-curve'].sort((a, b) => document.querySelector(a).compareDocumentPosition(
            document.querySelector(b)) & Node.DOCUMENT_POSITION_FOLLOWING ? -1 : 1)
            .filter(sel => document.getElementById('sim-canvas-difference').compareDocumentPosition(
              document.querySelector(sel)) & Node.DOCUMENT_POSITION_FOLLOWING),
          note: document.getElementById('sim-note').textContent ? null : getComputedStyle(document.getElementById('sim-note')).display,
          tables: [...document.querySelectorAll('.symrender-sim table')].map(t => t.getAttribute('aria-label')
            || (t.caption ? t.caption.textContent : '')),
          labels: [...document.querySelectorAll('.symrender-sim :is(select, input)')].map(
            e => e.closest('label').querySelector('span').firstChild.textContent.trim())};
}"""


def _js_exponential(x):
    """``x`` as JavaScript's ``toExponential(1)`` prints it (1.2e-3, not 1.2e-03)."""
    return re.sub(r"e([+-])0*(\d)", r"e\1\2", f"{x:.1e}")


def spoken_problems(s):
    """Where what a screen reader is given departs from what the simulator shows (`SPOKEN_JS`): a canvas
    that is not an application (a screen reader in browse mode keeps the arrow keys that move the probe from
    anything else) described as an image with a probe, with a label naming the field, β, the view and the
    normal, the numeric canvas's ε
    and the difference's largest |ΔI| and RMS as the ledger prints them, and its means on and off the crease
    band where the frame has both (none where it has not); a hint that is no polite live
    region; a status line (role status) that does not give the difference's largest |ΔI| and RMS as the
    ledger prints them, and the band's means as the label does; another live region (the readout, read whole after every change once a pixel was
    read; the ledger table, its changed cells without their headers; a slider's printed value, said twice);
    the U-curve not an image labelled with the current ε; the readout not read after the canvases and before
    the U-curve; the β note's live region out of the tree while empty; a table of the simulator without a name;
    the ε slider's value text not what it prints; a control whose accessible name does not begin with its
    label."""
    said, st = s.page.evaluate(SPOKEN_JS), s.sim("sim.state")
    found = []
    eps = s.page.text_content("#sim-log_eps-value")
    for name, (role, label) in said["canvases"].items():
        label = label or ""
        if role != "application image with a probe":
            found.append(f"{name} canvas: role {role!r}")
        if name != "difference":
            for part in (f"the {st['height_field']} field", f"β = {st['beta']:.2f}", {"shaded": "shaded", "bump": "size of ∇h",
                         "kink": "crease band"}[st["view"]], s.page.evaluate(
                         "document.querySelector('#sim-bump').selectedOptions[0].textContent")):
                if part not in label:
                    found.append(f"{name} canvas: {part!r} not in {label!r}")
    if st["numeric"] == "central" and f"ε = {eps}" not in said["canvases"]["numeric"][1]:
        found.append(f"numeric canvas: ε = {eps} not in {said['canvases']['numeric'][1]!r}")
    difference = said["canvases"]["difference"][1] or ""
    if st["view"] == "bump" and "the shaded renders' on sphere A" not in difference:    # the ledger is of those
        found.append(f"difference canvas: the ledger not said to be the shaded renders' in the bump view: {difference!r}")
    led = s.sim("sim.frames.ledger")
    for where, text in (("difference canvas", difference), ("status", said["status"][1] or "")):
        band = re.search(r"mean \|ΔI\| (\S+) in the crease band, (\S+) off it", text)
        if np.isfinite([led["mean_abs_kink"], led["mean_abs_off_kink"]]).all():
            want = (_js_exponential(led["mean_abs_kink"]), _js_exponential(led["mean_abs_off_kink"]))
            if band is None or band.groups() != want:
                found.append(f"{where}: the ledger's means on and off the crease band {want} not in {text!r}")
        elif band:
            found.append(f"{where}: means on a crease band the frame has not: {text!r}")
    for cell in ("max", "rms"):
        value = _js_exponential(s.ledger(cell))
        if value not in difference:
            found.append(f"difference canvas: the ledger's {cell} {value} not in {difference!r}")
        if said["status"][0] != "status" or value not in said["status"][1]:
            found.append(f"status: the ledger's {cell} {value} not said: {said['status']}")
    if said["live"]:
        found.append(f"live regions saying numbers again: {said['live']}")
    if said["hint"] != "polite":
        found.append(f"hint: aria-live {said['hint']!r}")
    if said["curve"][0] != "img" or f"ε = {eps}" not in (said["curve"][1] or ""):
        found.append(f"U-curve: {said['curve']}")
    if said["eps"] != eps:
        found.append(f"ε slider: aria-valuetext {said['eps']!r}, printed {eps!r}")
    if said["order"] != ["#sim-readout", "#sim-curve"]:
        found.append(f"reading order after the canvases: {said['order']}, not the readout and then the U-curve")
    if said["note"] == "none":
        found.append("the β note's live region out of the accessibility tree while empty (display: none)")
    if not all(said["tables"]):
        found.append(f"a table of the simulator unnamed: {said['tables']}")
    # Each control's name in Chromium's accessibility tree (axe passes a control inside a <label> whose
    # first labelable element, an <output>, takes the label instead: the sliders were once nameless).
    named = re.findall(r'- (?:slider|combobox|checkbox)(?: "([^"]*)")?', s.page.locator(".symrender-sim").aria_snapshot())
    for label, name in zip(said["labels"], named, strict=True):
        if not name.startswith(label):
            found.append(f"control {label!r}: accessible name {name!r}")
    return found


#: Run in the page: for each canvas of the simulator, the canvas pixel [i, j] under the centre of its ring
#: (the read-out pixel's mark), or null while the ring is not shown.
MARKS_JS = """() => [...document.querySelectorAll('.symrender-sim canvas')].map(c => {
  const m = c.parentElement.querySelector('.sim-probe');
  if (!m || !m.checkVisibility()) return null;
  const r = c.getBoundingClientRect(), k = m.getBoundingClientRect();
  return [Math.floor((k.left + k.width / 2 - r.left) * c.width / r.width),
          Math.floor((k.top + k.height / 2 - r.top) * c.height / r.height)];
})"""


#: Run in the page: the readout's crease row ("in the band: ..." or "not in the band"), "" off sphere A.
CREASE_ROW_JS = """() => [...document.querySelectorAll('#sim-readout dt')]
  .find((dt) => dt.textContent === 'crease')?.nextElementSibling.textContent ?? ''"""


def mark_problems(s):
    """Where the ring on a canvas is not centred on the pixel the readout reads."""
    d = s.page.evaluate("({...document.getElementById('sim-readout').dataset})")
    marks = s.page.evaluate(MARKS_JS)
    want = [int(d["i"]), int(d["j"])]
    return [] if marks and all(m == want for m in marks) else [f"the rings at {marks}, the readout at {want}"]


def _keyboard_walk(s, readouts):
    """Use the simulator from the keyboard alone, checking `spoken_problems` after each move: Tab to the
    field menu and change it, Tab to ε and move it a decade, to β and move it, on to the symbolic canvas
    and move the probe with the arrow keys (the readout reads the pixel, a ring on each canvas marks it, the status
    line says the pixel and whether it is in the crease band as the readout does; B to the next pixel in the band,
    Shift+B back to the one before), to the shading normal and change
    it (the note beside it, a live region, must then say the β slider's new range), then on to the view
    menu and change it (the note must be gone).  Yields (move, problems) as it goes, so that a wrong variant's
    walk stops where its problem shows; appends the readout's texts to ``readouts``."""
    page = s.page

    def move(key):
        n = s.updates()
        page.keyboard.press(key)
        s.wait_update(n)
        return spoken_problems(s)

    def tab_to(target):
        for _ in range(60):
            if page.evaluate("document.activeElement.id") == target:
                return
            page.keyboard.press("Tab")
        raise AssertionError(f"Tab never reached #{target}")

    page.focus("#sim-preset-try1")
    yield "opening", spoken_problems(s)
    tab_to("sim-height_field"); yield "field", move("ArrowDown")
    tab_to("sim-log_eps"); yield "ε", move("PageDown")
    tab_to("sim-beta"); yield "β", move("ArrowRight")
    tab_to("sim-canvas-symbolic")
    probe = [] if not any(page.evaluate(MARKS_JS)) else ["a ring before any pixel was read"]
    res, at, bands = s.sim("sim.state.resolution"), [], set()

    def press(key):
        page.keyboard.press(key)
        readouts.append(page.text_content("#sim-readout"))
        d, said = s.page.evaluate("({...document.getElementById('sim-readout').dataset})"), page.text_content("#sim-status")
        at.append((int(d["i"]), int(d["j"])))
        found = [] if said.startswith(f"Pixel x {d['i']}, y {d['j']},") and "|ΔI|" in said else [
            f"the probe's pixel not said: status {said!r} at ({d['i']}, {d['j']})"]
        band = page.evaluate(CREASE_ROW_JS).startswith("in the band")
        bands.add(band)
        if band != ("in the crease band" in said):
            found.append(f"the crease band {'not said' if band else 'said'} at ({d['i']}, {d['j']}), "
                         f"{'in' if band else 'out of'} it by the readout: status {said!r}")
        return found + mark_problems(s) + [f"a hyphen for a minus sign in the readout: {m.group()}"
                                           for m in HYPHEN_MINUS.finditer(readouts[-1])]
    for key in ("ArrowRight", "ArrowDown", "Shift+ArrowRight"):
        probe += press(key)
    c = res // 2                        # the first press reads the centre, the next a pixel on, with Shift ten
    if at != [(c, c), (c, c + 1), (c + 10, c + 1)]:
        probe.append(f"the probe went {at}, not from the centre ({c}, {c}) one pixel down, ten right")
    # B to the next pixel of sphere A in the crease band (row by row from the probe's), Shift+B to the one before.
    kink, chamber = s.page.evaluate("""() => { const f = document.querySelector('[data-symrender-sim]').symrender
      .frames.symbolic; return [Array.from(f.kink), Array.from(f.chamber)]; }""")
    band_pixels = [k for k in range(res * res) if kink[k] and chamber[k] == SPHERE_A]
    for key, pick in (("b", lambda k: min((b for b in band_pixels if b > k), default=band_pixels[0])),
                      ("Shift+B", lambda k: max((b for b in band_pixels if b < k), default=band_pixels[-1]))):
        want = pick(at[-1][1] * res + at[-1][0])
        probe += press(key)
        if at[-1] != (want % res, want // res):
            probe.append(f"{key} moved the probe to {at[-1]}, not to the crease band's pixel {(want % res, want // res)}")
    if bands != {True, False}:
        probe.append(f"the walk read pixels {'in' if True in bands else 'out of'} the crease band only")
    yield "probe", probe
    tab_to("sim-bump"); normal = move("ArrowUp")        # to the draft's chart formula
    top = page.get_attribute("#sim-beta", "max")
    if f"β now runs to {top}" not in page.text_content("#sim-note"):         # the slider's range changed with it
        normal.append(f"β's range changed to {top} silently: note {page.text_content('#sim-note')!r}")
    yield "normal", normal
    tab_to("sim-view"); view = move("ArrowDown")
    if page.text_content("#sim-note"):                                       # the note said its piece
        view.append(f"the β note outlived the next change: {page.text_content('#sim-note')!r}")
    yield "view", view


def test_the_simulator_works_from_the_keyboard_and_speaks_what_it_shows(browser, book_html):
    """From the keyboard alone (Tab, arrow keys, Page Down): the field, ε, β, the normal and the view change, and
    the probe walks over the symbolic canvas, the readout reading each pixel and the status line saying which, whether
    it is in the crease band (the walk reads pixels in it and out of it), and its |ΔI|;
    after every move each canvas is an image whose label says what it draws (field, β, normal, view;
    the numeric canvas's ε; the difference's largest |ΔI| and RMS as the ledger prints them), the
    U-curve's label the current ε, the ε slider's value text the ε printed (`spoken_problems`)."""
    s = _simulator_at(browser, book_html, 1280)
    try:
        readouts = []
        found = dict(_keyboard_walk(s, readouts))
        assert found == dict.fromkeys(found, []), found
        assert len(set(readouts)) == len(readouts) >= 4 and all(r.startswith("pixel") for r in readouts), readouts
        assert s.errors == []
    finally:
        s.close()


#: Wrong variants of what a screen reader is given, and of the rings marking the read-out pixel: (old text of
#: the bundle, new text, a problem it must cause).
WRONG_SPOKEN = {
    "the canvases' labels written once, not kept current": ("${this.describe(ledger)}", "max |ΔI|", "not in"),
    "sliders named by the value beside them": ('return el("label", { for: input.id }, [el("span"',
                                              'return el("label", {}, [el("span"', "accessible name"),
    "the β slider's range changed without a word": ("      this.note.textContent = beta_range_note(value, this.state.beta < before.beta);\n",
                                                     "", "silently"),
    "the β note never giving way": ("      this.note.textContent = \"\";                                 // the note said its piece\n",
                                     "", "outlived"),
    "the canvases images, whose arrow keys browse mode keeps": ('role: "application"', 'role: "img"', "role"),
    "Shift ignored by the probe": ("n = ev.shiftKey ? 10 : 1", "n = 1", "not from the centre"),
    "the first press a step past the centre": ("if (!this.probe) { this.show_probe(res >> 1, res >> 1); return; }",
                                               "if (!this.probe) this.probe = { i: res >> 1, j: res >> 1 };",
                                               "not from the centre"),
    "the readout a live region again": ('class: "sim-readout" }', 'class: "sim-readout", "aria-live": "polite" }', "live regions"),
    "the probe's pixel not said": ("if (say) this.status.textContent", "if (false) this.status.textContent", "the probe's pixel not said"),
    "the crease band left unsaid": ('const band = a.kink ? ", in the crease band" : "";', 'const band = "";',
                                    "the crease band not said"),
    "the difference's band means left unsaid": ("`on sphere A ${totals}${where}.`", "`on sphere A ${totals}.`",
                                                "means on and off the crease band"),
    "the status without the band's means": ("return totals + where;", "return totals;", "status: the ledger's means"),
    "B to the next pixel of sphere A, in the band or not": ("if (f.kink[k] && f.chamber[k] === SPHERE_A)",
                                                           "if (f.chamber[k] === SPHERE_A)", "not to the crease band's pixel"),
    "Shift+B forward too": ("this.probe_band(ev.shiftKey ? -1 : 1)", "this.probe_band(1)", "Shift+B moved the probe"),
    "the readout read after the U-curve": ('[...figs, el("div", { class: "sim-readout-box" }, [this.readout, more]), curve]',
                                          '[...figs, curve, el("div", { class: "sim-readout-box" }, [this.readout, more])]',
                                          "reading order"),
    "the empty note hidden from the tree": (".sim-note:empty { position: absolute;", ".sim-note:empty { display: none;",
                                            "out of the accessibility tree"),
    "the ledger table unnamed": ('"aria-label": "the ledger of the two renders" ', "", "table of the simulator unnamed"),
    "the bump view's ledger said to be of the sizes of ∇h": ("the two renders, ${scale}; the shaded renders' `",
                                                              "the two renders, ${scale}; `", "shaded renders'"),
    "every pixel of sphere A said in the crease band": ('const band = a.kink ?', 'const band = a.chamber === SPHERE_A ?',
                                                        "the crease band said"),
    "the rings a pixel off the one read": ("mark.style.left = `${(100 * (i + 0.5)) / res}%`;",
                                           "mark.style.left = `${(100 * (i + 1.5)) / res}%`;", "the rings at"),
    "a ring shown before any pixel is read": ('"aria-hidden": "true", hidden: "" }', '"aria-hidden": "true" }',
                                              "a ring before any pixel"),
    "the readout's negative numbers with a hyphen": ('.replace(/^-/, "\\u2212")', "", "a hyphen for a minus sign"),
    "the ledger table a live region": ('el("table", { class: "sim-ledger",', 'el("table", { class: "sim-ledger", "aria-live": "polite",',
                                       "live regions"),
    "the sliders' printed values live": ('for: `sim-${c.name}`, "aria-hidden": "true" }', 'for: `sim-${c.name}` }', "live regions"),
    "a status that never changes": ("this.status.textContent = `On sphere A", "this.status.dataset.said = `On sphere A", "status:"),
    "the rings left where the first probe put them": ("mark.hidden = false;", "if (!mark.hidden) continue; mark.hidden = false;",
                                                      "the rings at"),
}


@pytest.mark.parametrize("variant", sorted(WRONG_SPOKEN))
def test_the_spoken_check_catches_stale_labels_and_a_silent_readout(browser, book_html, variant):
    old, new, message = WRONG_SPOKEN[variant]
    s = _simulator_at(browser, book_html, 1280, bundle=_replaced_once(old, new, variant))
    try:
        seen = {}
        for move, problems in _keyboard_walk(s, []):          # stopped at the first move that shows the problem
            seen[move] = problems
            if any(message in p for p in problems):
                break
        else:
            pytest.fail(f"{variant!r} not caught: {seen}")
    finally:
        s.close()


def test_the_session_catches_network_use_and_errors(browser, tmp_path):
    """The checks above can fail: a page that reaches for the network and logs an
    error is caught (and its request never leaves the machine)."""
    page = tmp_path / "bad.html"
    page.write_text('<html><body><div data-symrender-sim data-updates="1"></div>'
                    '<script src="https://cdn.example.invalid/x.js"></script>'
                    '<script>console.error("boom"); undefinedFunction();</script></body></html>')
    s = Session(browser, page.as_uri())
    try:
        assert any("cdn.example.invalid" in url for url in s.blocked)
        assert any("boom" in e for e in s.errors) and any("undefinedFunction" in e for e in s.errors)
    finally:
        s.close()


LOG_EPS = (-1, -3, -6, -9, -12, -14)


@pytest.mark.parametrize("field", list(FIELDS))
def test_the_log_difference_view_shows_the_u_curve(browser, book_html, field):
    """On the log scale the difference canvas is visible on sphere A at every step from
    1e-1 to 1e-14, and its mean level follows the U-curve: lower at the optimum than at
    either end.  On the linear scale (the wrong variant for small steps) it is black."""
    s = Session(browser, _url(book_html))
    try:
        s.select("height_field", field)
        s.select("scale", "log")
        means = {}
        for e in LOG_EPS:
            s.set_eps(e)
            levels = s.difference_levels()
            assert np.count_nonzero(levels) > 0.5 * levels.size, (field, e)   # visible: not black
            means[e] = float(levels.mean())
            if field == "sine" and e in (-3, -6, -12):
                ARTIFACTS.mkdir(parents=True, exist_ok=True)
                s.page.locator("#sim").scroll_into_view_if_needed()
                s.page.locator(".sim-stage").screenshot(path=str(ARTIFACTS / f"s4_log_view_eps_1e{e}.png"))
        assert min(means[-6], means[-9]) < min(means[-1], means[-14]), means
        s.set_eps(-6)
        s.select("scale", "linear")
        assert np.count_nonzero(s.difference_levels()) == 0 or field == "ridges"   # creases stay visible
        assert s.errors == []
    finally:
        s.close()


# ---- the "Try this" presets: each opens on the view that makes its point ------------------

def _preset(s, preset):
    """Click a preset; the controls' values afterwards."""
    s.click(f"sim-preset-{preset}")
    return {c: s.page.input_value(f"#sim-{c}")
            for c in ("height_field", "view", "scale", "zoom", "bump", "log_eps", "beta", "numeric")}


def _rgb(canvas):
    return canvas[..., :3]


def test_preset_one_sweeps_eps_down_and_the_symbolic_canvas_stays(browser, book_html):
    """Sine at the slider's largest step, shaded, log scale, the eps slider focused: the arrow
    keys sweep eps down, the RMS falls along the truncation slope, and the symbolic canvas keeps
    every byte (a beta move, the wrong variant, changes it)."""
    s = Session(browser, _url(book_html))
    try:
        state = _preset(s, "try1")
        assert state == dict(height_field="sine", view="shaded", scale="log", zoom="1", bump="surface",
                             log_eps="-1", beta=str(SIMULATOR_SCENE.beta), numeric="central")
        assert s.page.evaluate("document.activeElement.id") == "sim-log_eps"
        assert s.sim("sim.curve.here.eps") == 0.1
        assert "move ε down" in s.page.text_content("#sim-hint")
        symbolic, rms = _rgb(s.canvas("symbolic")), [s.ledger("rms")]
        for _ in range(20):                       # 0.1 decade a key: down to 1e-3
            n = s.updates()
            s.page.keyboard.press("ArrowLeft")
            s.wait_update(n)
            rms.append(s.ledger("rms"))
        assert s.page.text_content("#sim-log_eps-value") == "1.0e-3"
        assert np.array_equal(_rgb(s.canvas("symbolic")), symbolic)
        assert rms[-1] < 1e-3 * rms[0] and sorted(rms, reverse=True) == rms
        s.fill("beta", 0.3)
        assert not np.array_equal(_rgb(s.canvas("symbolic")), symbolic)
    finally:
        s.close()


#: A difference this large is "where the pipelines part" (the register's claim try-creases).
BIG = 1e-3


def _share_in_band(s):
    """(pixels of sphere A whose difference canvas is brighter than BIG on the linear scale, the
    share of them in the crease band); the band's blue tint is not counted (red channel only)."""
    from renderer.jsgen import DIFFERENCE_LINEAR_GAIN
    bright = (s.canvas("difference")[..., 0] >= round(255 * min(1.0, DIFFERENCE_LINEAR_GAIN * BIG))) \
        & (s.frame("chamber") == 1)
    return int(bright.sum()), float((bright & (s.frame("kink") == 1)).sum() / max(1, bright.sum()))


def test_preset_two_shows_the_pipelines_parting_on_the_crease_band(browser, book_html):
    """Ridges, kink view, linear difference scale: the crease band white on both renders, and
    the bright pixels of the difference canvas in the band.  On the log scale (the view the
    preset does not open on: the wrong variant) nearly all of sphere A is bright."""
    s = Session(browser, _url(book_html))
    try:
        state = _preset(s, "try2")
        assert (state["height_field"], state["view"], state["scale"]) == ("ridges", "kink", "linear")
        kink = s.frame("kink") == 1
        assert kink.sum() > 500
        for name in ("numeric", "symbolic"):
            assert (_rgb(s.canvas(name))[kink] == 255).all(), name
        bright, share = _share_in_band(s)
        assert bright > 100 and share > 0.9, (bright, share)
        # The band the hint names stands out from the black of no difference: 3:1 at least (WCAG's
        # contrast for graphics; a blue of at most 90 was 1.1:1).
        band = _rgb(s.canvas("difference"))[kink & (s.frame("chamber") == 1)] / 255.0
        linear = np.where(band <= 0.04045, band / 12.92, ((band + 0.055) / 1.055) ** 2.4)
        assert ((linear @ [0.2126, 0.7152, 0.0722] + 0.05) / 0.05).min() >= 3
        s.select("scale", "log")
        bright_log, share_log = _share_in_band(s)
        assert bright_log > 10 * bright and share_log < 0.5, (bright_log, share_log)
    finally:
        s.close()


def _pole_ring_spread(s, radius=8, angles=32):
    """Spread (max - min, grey levels) of the symbolic canvas around the pole: on a circle of
    ``radius`` pixels about the pixel of sphere A nearest the pole (smallest v)."""
    uv, chamber = s.frame("uv"), s.frame("chamber")
    v = np.where(chamber == 1, uv[..., 1], np.inf)
    j0, i0 = np.unravel_index(np.argmin(v), v.shape)
    grey = _rgb(s.canvas("symbolic")).mean(axis=-1)
    t = 2 * np.pi * np.arange(angles) / angles
    ring = grey[np.round(j0 + radius * np.sin(t)).astype(int), np.round(i0 + radius * np.cos(t)).astype(int)]
    return float(ring.max() - ring.min())


def test_preset_three_magnifies_the_pole_where_the_shading_flips(browser, book_html):
    """Rings, the pole magnified, shaded: around the pole the shading turns over, from dark
    to light, on a small circle; with beta = 0 (the wrong variant) the same circle is even."""
    s = Session(browser, _url(book_html))
    try:
        state = _preset(s, "try3")
        assert (state["height_field"], state["view"], state["zoom"], state["bump"]) == \
            ("rings", "shaded", "4", "chart")
        assert s.page.text_content("#sim-note").startswith(f"β now runs to {s.page.get_attribute('#sim-beta', 'max')}:")
        _preset(s, "try1")                                  # back to the displaced sphere's range, said again
        assert s.page.text_content("#sim-note").startswith(f"β now runs to {s.page.get_attribute('#sim-beta', 'max')}:")
        _preset(s, "try3")
        spread = _pole_ring_spread(s)
        assert spread > 60, spread
        s.fill("beta", 0)
        flat = _pole_ring_spread(s)
        assert flat < 10, flat
    finally:
        s.close()


def test_preset_four_returns_the_smooth_sphere(browser, book_html):
    """beta = 0, its slider focused: the ledger reads exactly zero, the two renders are the
    same bytes, the difference is black and the U-curve lies on its floor; at beta = 0.01
    (the wrong variant) none of that holds."""
    s = Session(browser, _url(book_html))
    try:
        state = _preset(s, "try4")
        assert state["beta"] == "0" and s.page.evaluate("document.activeElement.id") == "sim-beta"
        assert s.ledger("max") == 0.0 and s.ledger("rms") == 0.0
        assert np.array_equal(_rgb(s.canvas("numeric")), _rgb(s.canvas("symbolic")))
        assert not _rgb(s.canvas("difference")).any()
        assert all(p["rms"] == 0 == p["max_abs"] for p in s.sim("sim.curve.points"))
        s.fill("beta", 0.01)
        assert s.ledger("max") > 0.0 and _rgb(s.canvas("difference")).any()
        assert not np.array_equal(_rgb(s.canvas("numeric")), _rgb(s.canvas("symbolic")))
    finally:
        s.close()


# ---- the page around the simulator -------------------------------------------------------

#: What the reader must not meet in the page's text (outside code, maths and file names):
#: raw TeX, dollar signs, Python names with underscores, slashes standing between quantities.
RAW = {"TeX command": r"\\[A-Za-z]+", "dollar": r"\$", "underscore name": r"\b[A-Za-z]+_[A-Za-z_]+\b",
       "slash between words": r"\w \/ \w"}
_TEXT_JS = """() => {
  document.querySelectorAll('details').forEach(d => d.open = true);
  const main = document.querySelector('article.bd-article').cloneNode(true);
  main.querySelectorAll('pre, code, mjx-container, .cell_input, script, style, a[href$=".ipynb"]')
      .forEach(e => e.remove());
  document.body.append(main);
  const text = main.innerText;
  main.remove();
  return text;
}"""


def _raw(text):
    import re
    return {kind: re.findall(pattern, text) for kind, pattern in RAW.items() if re.search(pattern, text)}


def test_the_page_is_short_and_reads_without_code_names_or_raw_tex(browser, book_html):
    """At 1280 px with its dropdowns closed the page is at most 12,000 px tall, and its text
    (every dropdown open, the simulator's labels, captions and readout included; code, maths and
    file names left out) holds no raw TeX, dollar sign, underscore name or slash between
    quantities.  Wrong variants: the page's text with a Python name and raw TeX added, and the
    page repeated five times, are caught."""
    s = Session(browser, _url(book_html), viewport={"width": 1280, "height": 900})
    try:
        s.page.wait_for_function("document.querySelectorAll('mjx-container').length > 0", timeout=30_000)
        _scroll_to_canvases(s)
        canvas = _box(s, "#sim-canvas-symbolic")
        s.page.mouse.move(canvas["x"] + canvas["width"] / 2, canvas["y"] + canvas["height"] / 3)
        _readout_pixel(s, SIZE // 2, SIZE // 3)
        height = s.page.evaluate("document.documentElement.scrollHeight")
        assert height <= 12_000, height
        text = s.page.evaluate(_TEXT_JS)
        assert "RGB exact" in text and "Try this" in text                     # the readout and the prose
        assert _raw(text) == {}
        assert set(_raw(text + " the field height_field and \\varepsilon cost $5")) == \
            {"underscore name", "TeX command", "dollar"}
        assert _raw(text + " max / RMS") == {"slash between words": ["x / R"]}
        s.page.evaluate("(a => a.innerHTML = a.innerHTML.repeat(5))(document.querySelector('article.bd-article'))")
        assert s.page.evaluate("document.documentElement.scrollHeight") > 12_000
    finally:
        s.close()


# ---- layout: 1280 x 900 and a phone --------------------------------------------------------

def _box(s, selector):
    return s.page.locator(selector).bounding_box()


def _inside(box, width, height, top=0.0):
    return box["x"] >= 0 and box["x"] + box["width"] <= width + 0.5 and box["y"] >= top - 0.5 \
        and box["y"] + box["height"] <= height + 0.5


def _scroll_to_canvases(s):
    """Scroll the canvases to just below the theme's sticky header; return the header's bottom."""
    header = s.page.evaluate("Math.max(0, ...[...document.querySelectorAll('header')]"
                             ".map(h => h.getBoundingClientRect().bottom))")
    s.page.locator("#sim-canvas-numeric").evaluate("c => c.scrollIntoView({block: 'start'})")
    s.page.evaluate(f"window.scrollBy(0, -{header + 8})")
    s.page.wait_for_timeout(100)
    return header


#: Run in the page: the names of the readout's rows on the screen (not hidden).
SHOWN_ROWS = "[...document.querySelectorAll('#sim-readout dt')].filter(dt => dt.checkVisibility()).map(dt => dt.textContent)"


def _canvases_and_readout_in_view(s, width, height, header):
    """Whether the three canvases, the U-curve and the readout are all within the viewport
    below the header, and the readout beside the plot; and their boxes."""
    boxes = {sel: _box(s, sel) for sel in ("#sim-canvas-numeric", "#sim-canvas-symbolic", "#sim-canvas-difference",
                                            "#sim-curve", "#sim-readout")}
    beside = boxes["#sim-readout"]["x"] >= boxes["#sim-curve"]["x"] + boxes["#sim-curve"]["width"] - 1
    return all(_inside(b, width, height, header) for b in boxes.values()) and beside, boxes


def test_at_1280_the_readout_and_the_u_curve_sit_beside_the_canvases(browser, book_html):
    """At 1280 x 900, with the canvases in view, the U-curve and the readout (filled in by hovering
    over a pixel of sphere A, every row shown, no button) are in view too, the readout beside the plot; the readout moved
    under the controls (the wrong variant) is not in view."""
    s = Session(browser, _url(book_html), viewport={"width": 1280, "height": 900})
    try:
        header = _scroll_to_canvases(s)
        canvas = _box(s, "#sim-canvas-symbolic")
        i, j = SIZE // 2, SIZE // 3
        s.page.mouse.move(canvas["x"] + (i + 0.5) * canvas["width"] / SIZE,
                          canvas["y"] + (j + 0.5) * canvas["height"] / SIZE)
        _readout_pixel(s, i, j)
        assert "(u, v)" in s.page.evaluate(SHOWN_ROWS) and len(s.page.evaluate(SHOWN_ROWS)) == 10   # every row
        assert not s.page.is_visible(".sim-more")
        in_view, boxes = _canvases_and_readout_in_view(s, 1280, 900, header)
        assert in_view, boxes
        row = [boxes[f"#sim-canvas-{n}"] for n in ("numeric", "symbolic", "difference")]
        assert max(b["y"] for b in row) - min(b["y"] for b in row) < 1                   # one row
        assert max(b["width"] for b in row) - min(b["width"] for b in row) < 1           # equal
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        s.page.screenshot(path=str(ARTIFACTS / "s4_simulator.png"))
        s.page.evaluate("document.querySelector('[data-symrender-sim]').append(document.getElementById('sim-readout'))")
        assert not _canvases_and_readout_in_view(s, 1280, 900, header)[0]
        assert s.errors == []
    finally:
        s.close()


#: Run in the page: for each margin note, how far (px) its top lies below the top of what it annotates
#: (the element after the cell that prints it: the theme floats a note beside what follows it).
MARGIN_DRIFT_JS = """() => [...document.querySelectorAll('article aside.margin')].map(note => {
  const next = note.closest('.cell').nextElementSibling;
  return [next.textContent.trim().slice(0, 40), note.getBoundingClientRect().top - next.getBoundingClientRect().top];
})"""


@pytest.mark.parametrize("variant", [None, "the theme's blank title line above each note"])
def test_at_1280_each_margin_note_stands_beside_its_item(browser, book_html, variant):
    """At 1280 px the theme floats §4's margin notes beside the Try-this items they annotate; each
    note's top lies within half a line (8 px) of its item's, none pushed down beside the next item.
    With the empty title paragraph's space kept above each note (the wrong variant) the first note
    starts a line low and the rest drift further."""
    def css(text):
        old = "aside.margin p.sidebar-title:empty + p { margin-top: 0; }"
        assert text.count(old) == 1
        return text.replace(old, "") if variant else text

    s = Session(browser, _url(book_html), css=css, viewport={"width": 1280, "height": 900})
    try:
        drift = s.page.evaluate(MARGIN_DRIFT_JS)
        assert len(drift) == 4, drift
        beside = all(abs(d) <= 8 for _, d in drift)
        assert beside != bool(variant), drift
        assert s.errors == []
    finally:
        s.close()


def _canvases_stacked(s):
    """(whether the three canvases are stacked one above the other, each at least 300 px wide; boxes)."""
    boxes = [_box(s, f"#sim-canvas-{n}") for n in ("numeric", "symbolic", "difference")]
    stacked = all(b["y"] >= a["y"] + a["height"] for a, b in zip(boxes, boxes[1:]))
    return stacked and min(b["width"] for b in boxes) >= 300, boxes


def test_on_a_phone_the_canvases_stack_and_a_tap_reads_a_pixel(browser, book_html):
    """At 390 px, with touch: the canvases stacked, each at least 300 px wide; a tap on a canvas
    shows the pixel tapped in the readout, which stays in view (it sticks to the bottom of the
    screen while the canvases scroll by) with two rows, which pixel and its |ΔI|, until its button asks
    for all ten; a ring on each canvas marks the pixel.  Without the narrow-screen rule (the wrong variant)
    the canvases sit side by side, too small."""
    s = Session(browser, _url(book_html), viewport={"width": 390, "height": 844}, has_touch=True,
                is_mobile=True, device_scale_factor=2)
    try:
        stacked, boxes = _canvases_stacked(s)
        assert stacked, boxes
        gb = gbuffer(Scene(), SIZE, SIZE)
        rows, cols = np.nonzero(gb.chamber == 1)
        canvas = s.page.locator("#sim-canvas-symbolic")
        canvas.evaluate("c => c.scrollIntoView({block: 'center'})")
        box = canvas.bounding_box()
        for k in (len(rows) // 3, 2 * len(rows) // 3):
            i, j = int(cols[k]), int(rows[k])
            s.page.tap("#sim-canvas-symbolic", position={"x": (i + 0.5) * box["width"] / SIZE,
                                                         "y": (j + 0.5) * box["height"] / SIZE})
            ri, rj = _readout_pixel(s, i, j)
            assert s.page.get_attribute("#sim-readout", "data-chamber") == str(gb.chamber[rj, ri]) == "1"
            assert mark_problems(s) == []
            assert _inside(_box(s, "#sim-readout"), 390, 844), _box(s, "#sim-readout")
        assert s.page.evaluate(SHOWN_ROWS) == ["pixel", "|ΔI|"]             # until the reader asks for all
        s.page.tap(".sim-more")
        assert s.page.get_attribute(".sim-more", "aria-expanded") == "true"
        assert "(u, v)" in s.page.evaluate(SHOWN_ROWS) and len(s.page.evaluate(SHOWN_ROWS)) == 10
        assert _inside(_box(s, ".sim-readout-box"), 390, 844), _box(s, ".sim-readout-box")
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        s.page.screenshot(path=str(ARTIFACTS / "s4_at_390px.png"))
        s.page.evaluate("(st => st.textContent = st.textContent.replace(/@media[^]*$/, ''))"
                        "(document.getElementById('symrender-sim-style'))")
        assert not _canvases_stacked(s)[0]
        assert s.errors == []
    finally:
        s.close()


#: The share of a phone's screen (390 x 844 px) that what sticks at the top (the theme's header and the
#: simulator's main controls) may cover while the canvases scroll by beneath it.
MAX_STUCK = 0.25

#: Run in the page with the name of a reading position: scrolls there and returns [target,
#: what covers it] for each point of a target that something else covers (document.elementFromPoint
#: at a 5 x 5 grid of points inside the target's box, within the viewport).  The positions: "top"
#: (the simulator just below the theme's sticky header), "canvases" (the symbolic canvas in the
#: middle of the screen), "difference" (the difference canvas in the middle), "ucurve_bottom" and
#: "ucurve_middle" (the U-curve's plot with its caption at the bottom of the screen, as it comes into
#: view, and in the middle) and "ledger" (the ledger in the middle).  The targets: the main controls
#: (the field, ε and β: at every position where they stick to the screen, else at "top"), the readout
#: (its part below what sticks at the top: a box scrolled under a bar is not covered by it; on a phone
#: at "canvases", what sticks at the top at most `MAX_STUCK` of the screen), and at
#: both "ucurve" positions the plot and its caption, which must also lie wholly on the screen,
#: and on a phone (under 720 px) the ε slider, wholly on the screen with them; on a phone at
#: "difference", the ε slider and the difference canvas wholly on the screen, uncovered (dragging ε
#: shows the difference change); on a phone at "together" (the difference canvas just below what sticks at
#: the top, before a pixel is read out: the readout, one line until then, lies between them), the ε slider,
#: the difference canvas and the U-curve's plot wholly on the screen, uncovered (dragging ε shows the image
#: and the curve move together); and so again at "together_read", with a pixel read out (the readout's two
#: rows, which pixel and its |ΔI|, until the reader asks for all).  Besides covering, the check measures what a reader must read:
#: at the "ucurve" positions the caption's font at least 12 px and every text of the plot at least
#: 10 px as drawn (its font size times the plot's scale), and at "ledger" every column of the
#: ledger inside the ledger's visible box (none cut off, no sideways scrolling).
COVERED_JS = """async (where) => {
  const sticky = el => getComputedStyle(el).position === 'sticky';
  const main = document.querySelector('.sim-main'), readout = document.getElementById('sim-readout');
  const header = () => Math.max(0, ...[...document.querySelectorAll('header, .bd-header-article')]
    .map(h => h.getBoundingClientRect().bottom));
  const bar = () => Math.max(header(), sticky(main) ? main.getBoundingClientRect().bottom : 0);
  const settle = () => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)));
  const [at, block] = {top: ['[data-symrender-sim]', 'start'], canvases: ['#sim-canvas-symbolic', 'center'],
                        difference: ['#sim-canvas-difference', 'center'], together: ['#sim-canvas-difference', 'start'],
                        together_read: ['#sim-canvas-difference', 'start'],
                        ucurve_bottom: ['.sim-curve', 'end'], ucurve_middle: ['.sim-curve', 'center'],
                        ledger: ['.sim-ledger', 'center']}[where];
  document.querySelector(at).scrollIntoView({block});
  await settle();
  if (where === 'top') { window.scrollBy(0, -header() - 8); await settle(); }
  if (where.startsWith('together')) {
    window.scrollBy(0, document.querySelector(at).getBoundingClientRect().top - bar() - 4); await settle();
  }
  // What covers a point: the theme's header, or the nearest element with an id (the simulator's parts).
  const name = hit => {
    if (!hit) return 'nothing (off the screen)';
    const el = hit.closest('.bd-header-article, header, [id]') || hit;
    return el.tagName.toLowerCase() + (el.id ? '#' + el.id : '.' + [...el.classList].slice(0, 1).join('.'));
  };
  const found = [];
  const check = (el, label, from = 0, whole = false) => {
    const r = el.getBoundingClientRect();
    for (let a = 0; a < 5; a++) for (let b = 0; b < 5; b++) {
      const x = r.left + 2 + (r.width - 4) * a / 4, y = r.top + 2 + (r.height - 4) * b / 4;
      const on = x >= 0 && x < innerWidth && y >= 0 && y < innerHeight;
      if (!on) { if (whole) found.push(label + ' covered by ' + name(null)); continue; }
      if (y < from) continue;
      const hit = document.elementFromPoint(x, y);
      if (hit !== el && !el.contains(hit)) found.push(label + ' covered by ' + name(hit));
    }
  };
  // On a phone what sticks at the top (the theme's header and the main controls) leaves the page most of the screen.
  if (where === 'canvases' && innerWidth < 720 && bar() > MAX_STUCK * innerHeight)
    found.push(`what sticks at the top covers ${Math.round(100 * bar() / innerHeight)} % of the screen (over ${100 * MAX_STUCK} %)`);
  if (where === 'top' || sticky(main))
    for (const id of ['sim-height_field', 'sim-log_eps', 'sim-beta']) check(document.getElementById(id), '#' + id);
  check(readout, '#sim-readout', bar());
  if (where.startsWith('ucurve')) {
    // On a phone the ε slider must be on the screen with the plot, so that moving it shows the curve move.
    if (innerWidth < 720) check(document.getElementById('sim-log_eps'), '#sim-log_eps beside the plot', 0, true);
    check(document.getElementById('sim-curve'), '#sim-curve', 0, true);
    check(document.getElementById('sim-curve-caption'), '#sim-curve-caption', 0, true);
    const px = el => parseFloat(getComputedStyle(el).fontSize);
    const caption = px(document.getElementById('sim-curve-caption'));
    if (caption < 12) found.push(`#sim-curve-caption's font ${caption} px (under 12)`);
    const plot = document.getElementById('sim-curve'), scale = plot.getScreenCTM().a;
    for (const t of plot.querySelectorAll('text'))
      if (px(t) * scale < 10) found.push(`#sim-curve's text at ${(px(t) * scale).toFixed(1)} px (under 10)`);
  }
  if (where === 'difference' && innerWidth < 720) {
    check(document.getElementById('sim-log_eps'), '#sim-log_eps beside the difference canvas', 0, true);
    check(document.getElementById('sim-canvas-difference'), '#sim-canvas-difference', 0, true);
  }
  if (where.startsWith('together') && innerWidth < 720)
    for (const id of ['sim-log_eps', 'sim-canvas-difference', 'sim-curve'])
      check(document.getElementById(id), '#' + id + ' with the difference canvas and the plot', 0, true);
  if (where === 'ledger') {
    const ledger = document.querySelector('.sim-ledger'), box = ledger.getBoundingClientRect();
    if (ledger.scrollWidth > ledger.clientWidth + 1) found.push('.sim-ledger scrolls sideways');
    for (const th of ledger.querySelectorAll('th'))
      if (th.getBoundingClientRect().right > box.left + ledger.clientWidth + 1) found.push(`ledger column "${th.textContent}" cut off`);
  }
  return [...new Set(found)];
}""".replace("MAX_STUCK", str(MAX_STUCK))
READING_POSITIONS = ("together", "together_read", "top", "canvases", "difference", "ucurve_bottom", "ucurve_middle", "ledger")


def _layout(browser, book_html, width, bundle=None, css=None, shots=None):
    """{position: what covers the controls, the readout, the plot or its caption there} at ``width``
    px (844 px tall on a phone, with touch; 900 on a desktop), with a pixel of sphere A read out
    (tapped on a phone, hovered over at 1280) at every position but "together", on a phone with all its rows
    shown after "together_read"; with ``shots``, a screenshot of each position
    to test-artifacts/s4_<width>px_<position><shots>.png."""
    phone = width < 720
    options = dict(viewport={"width": width, "height": 844 if phone else 900})
    if phone:
        options.update(has_touch=True, is_mobile=True, device_scale_factor=2)
    s = Session(browser, _url(book_html), bundle=bundle, css=css, **options)
    try:
        found = {"together": s.page.evaluate(COVERED_JS, "together")}         # before a pixel is read out
        if shots is not None:
            ARTIFACTS.mkdir(parents=True, exist_ok=True)
            s.page.screenshot(path=str(ARTIFACTS / f"s4_{width}px_together{shots}.png"))
        gb = gbuffer(Scene(), SIZE, SIZE)
        rows, cols = np.nonzero(gb.chamber == 1)
        i, j = int(cols[len(rows) // 2]), int(rows[len(rows) // 2])
        canvas = s.page.locator("#sim-canvas-symbolic")
        canvas.evaluate("c => c.scrollIntoView({block: 'center'})")
        box = canvas.bounding_box()
        point = {"x": (i + 0.5) * box["width"] / SIZE, "y": (j + 0.5) * box["height"] / SIZE}
        if phone:
            s.page.tap("#sim-canvas-symbolic", position=point)
        else:
            s.page.hover("#sim-canvas-symbolic", position=point)
        _readout_pixel(s, i, j)
        for where in READING_POSITIONS[1:]:
            found[where] = s.page.evaluate(COVERED_JS, where)
            if shots is not None:
                ARTIFACTS.mkdir(parents=True, exist_ok=True)
                s.page.screenshot(path=str(ARTIFACTS / f"s4_{width}px_{where}{shots}.png"))
            if where == "together_read" and phone:          # the rest with every row shown, the tallest readout
                s.page.tap(".sim-more")
        assert s.errors == []
        return found
    finally:
        s.close()


@pytest.mark.parametrize("width", [390, 1280])
def test_the_controls_readout_and_u_curve_never_cover_each_other(browser, book_html, width):
    """Scrolled to the simulator's top, its canvases, its U-curve and its ledger, with a pixel read
    out: the main controls are never under the theme's header or the readout, the readout is
    under nothing but what sticks at the top, and the U-curve's plot with its caption, at the
    bottom of the screen and in its middle, lies on the screen covered by nothing, on a phone with the ε slider;
    on a phone the ε slider is on the screen with the difference canvas; the caption and the plot's
    text are large enough to read and the ledger shows every column (`COVERED_JS`).  Screenshots of each
    position go to test-artifacts/s4_<width>px_<position>.png."""
    found = _layout(browser, book_html, width, shots="")
    assert found == dict.fromkeys(READING_POSITIONS, []), found


#: Wrong layouts of the simulator on a phone: (the sheet changed: "bundle", the simulator's STYLE, or
#: "css", the book's _static/fit.css; the text replaced, its replacement, a finding the layout check
#: must report at 390 px).
WRONG_LAYOUTS = {
    "the sticky controls under the theme's header": ("bundle",
        "position: sticky; top: 3.5rem;", "position: sticky; top: 0;", "#sim-height_field covered by div.bd-header-article"),
    "the sticky readout below the U-curve, over its caption": ("bundle",
        '[...figs, el("div", { class: "sim-readout-box" }, [this.readout, more]), curve]',
        '[...figs, curve, el("div", { class: "sim-readout-box" }, [this.readout, more])]', "#sim-curve-caption covered by dl#sim-readout"),
    "the controls scrolled away from the U-curve": ("bundle",
        "position: sticky; top: 3.5rem;", "position: static;", "#sim-log_eps beside the plot covered by nothing (off the screen)"),
    "the controls scrolled away from the difference canvas": ("bundle",
        "position: sticky; top: 3.5rem;", "position: static;",
        "#sim-log_eps beside the difference canvas covered by nothing (off the screen)"),
    "the readout scrolled over the sticky controls": ("bundle",
        "z-index: 3; /* above the readout */", "z-index: 1;", "covered by dl#sim-readout"),
    "the field's menu under its name, the panel a quarter of the screen": ("bundle",
        "padding: 0.2rem 0;\n    gap: 0 1rem; font-size: 0.9rem; }\n  /* The field's menu beside its name: with the theme's header, the panel covers under a quarter of a phone's screen. */\n"
        "  .symrender-sim .sim-main label:has(select) { flex-direction: row;",
        "padding: 0.3rem 0; }\n  .symrender-sim .sim-main label:has(select) { flex-direction: column;",
        "what sticks at the top covers"),
    "the plot's labels drawn small": ("bundle",
        ".sim-curve text { fill: currentColor; font-size: 11px; }", ".sim-curve text { fill: currentColor; font-size: 8px; }",
        "#sim-curve's text at 8.0 px (under 10)"),
    "the U-curve's caption in small print": ("css",
        "#sim-curve-caption { font-size: 0.875rem;", "#sim-curve-caption { font-size: 0.7rem;",
        "#sim-curve-caption's font 11.2 px (under 12)"),
    "every row of the readout on a phone, the plot pushed off the screen": ("bundle",
        ' .sim-readout > :not(.sim-brief) { display: none; }', ' .sim-readout > :not(.sim-brief) { }',
        "#sim-curve with the difference canvas and the plot covered by nothing (off the screen)"),
    "the theme's margin under the readout, the plot pushed off the screen": ("bundle",
        ".symrender-sim .sim-stage dl.sim-readout { margin: 0; }", "",
        "#sim-curve with the difference canvas and the plot covered by nothing (off the screen)"),
    "the ledger's wide cells on a phone": ("css",
        "table.sim-ledger td { padding: 0.1rem 0.25rem; }", "table.sim-ledger td { }", 'ledger column "last update" cut off'),
}


@pytest.mark.parametrize("variant", sorted(WRONG_LAYOUTS))
def test_the_layout_check_catches_overlapping_controls(browser, book_html, variant):
    sheet, old, new, message = WRONG_LAYOUTS[variant]

    def wrong(text):
        assert text.count(old) == 1, f"variant {variant!r} no longer applies to the {sheet}"
        return text.replace(old, new)

    found = _layout(browser, book_html, 390, **{sheet: wrong})
    assert any(message in f for where in found.values() for f in where), (variant, found)
