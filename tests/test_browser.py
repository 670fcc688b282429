"""The §4 simulator in a real browser: Debian's Chromium, driven by Playwright.

The built page is loaded from disk (file://), as a reader without a network
opens it, and every request that is not for a local file is blocked and
recorded.  The test checks: no console errors, MathJax typeset from the site,
canvases that are not blank, the ledger's RMS and max at eps = 1e-3 and 1e-6
within the bounds that the JavaScript-vs-Python error model
(tests/test_js_parity.py) puts around the Python renderer's, the hover
readout's (u, v) within the model's chart bound of Python's for a given
pixel, and every control reachable and movable from the keyboard.  It saves a screenshot and the timings to test-artifacts/.

The book is built into a temporary directory for the test unless
SYMRENDER_BOOK_HTML names a freshly built site (.ci/run builds the book first
and passes it).  With CI=true a missing Chromium or Playwright fails the test.
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path

import numpy as np
import pytest

from renderer import Scene, compare, gbuffer, render

from .jsnode import ARTIFACTS, in_ci, require_tool
from .test_js_parity import CHART_TOL, image_bound

CHROMIUM = "/usr/bin/chromium"
ROOT = Path(__file__).parents[1]
SIZE = 256
# Flags for a machine with no network (see the environment notes): without the
# background-networking ones Chromium keeps trying to reach Google's hosts.
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
CONTROLS = ["sim-height_field", "sim-k_u", "sim-k_v", "sim-beta", "sim-numeric", "sim-log_eps", "sim-model",
            "sim-resolution", "sim-view", "sim-zoom", "sim-sphere_b"]
BUTTONS = ["sim-preset-try1", "sim-preset-try2", "sim-preset-try3", "sim-preset-try4", "sim-reset"]


@pytest.fixture(scope="module")
def browser():
    require_tool(CHROMIUM, "the browser test drives Debian's Chromium (apt-get install chromium)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        if in_ci():
            pytest.fail("playwright is not installed (CI=true: this test may not skip)")
        pytest.skip("playwright is not installed")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
        yield b
        b.close()


class Session:
    """One page of the built book, with the network blocked and errors recorded."""

    def __init__(self, browser, url):
        self.context = browser.new_context(viewport={"width": 1200, "height": 1400})
        self.blocked, self.errors = [], []

        def route(r):
            if r.request.url.startswith("file://"):
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

    def set_eps(self, exponent):
        before = self.updates()
        self.page.fill("#sim-log_eps", str(exponent))
        self.wait_update(before)

    def select(self, name, value):
        before = self.updates()
        self.page.select_option(f"#sim-{name}", str(value))
        self.wait_update(before)

    def difference_levels(self):
        """Grey levels (0-255) of the difference canvas at the pixels on sphere A in the symbolic frame."""
        return self.page.evaluate("""() => {
            const sim = document.querySelector('[data-symrender-sim]').symrender;
            const c = document.getElementById('sim-canvas-difference');
            const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
            const chamber = sim.frames.symbolic.chamber, out = [];
            for (let k = 0; k < chamber.length; k++) if (chamber[k] === 1) out.push(d[4 * k]);
            return out;
        }""")

    def close(self):
        self.context.close()


@pytest.fixture(scope="module")
def session(browser, book_html):
    s = Session(browser, (book_html / "s4_simulator.html").as_uri())
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
    stats = session.page.evaluate("""() => ['numeric', 'symbolic', 'difference'].map(name => {
        const c = document.getElementById('sim-canvas-' + name);
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let lit = 0; const colours = new Set();
        for (let k = 0; k < d.length; k += 4) {
            if (d[k] || d[k + 1] || d[k + 2]) lit++;
            colours.add((d[k] << 16) | (d[k + 1] << 8) | d[k + 2]);
        }
        return {name, width: c.width, lit, colours: colours.size};
    })""")
    by = {s["name"]: s for s in stats}
    for name in ("numeric", "symbolic"):
        assert by[name]["width"] == SIZE
        assert by[name]["lit"] > 0.5 * SIZE * SIZE and by[name]["colours"] > 1000, by[name]
    assert by["difference"]["lit"] > 100, by["difference"]   # ridges at eps = 1e-3 differ visibly


def _python_ledger(eps):
    """Python's ledger at eps, and bounds of how far the simulator's RMS and max may lie from it.

    Per pixel and channel the two |I_numeric - I_symbolic| differ by at most
    b = b_central + b_exact (`image_bound` of each pipeline), so the maxima
    differ by at most max b and, the RMS being a norm, the RMS by at most the
    RMS of b over the same pixels (sphere A in both frames)."""
    scene = Scene(eps=eps)
    led = compare(render(scene, SIZE, SIZE, gradient="central"), render(scene, SIZE, SIZE))
    b = image_bound(scene, SIZE, SIZE, "central") + image_bound(scene, SIZE, SIZE, "exact")
    on_a = render(scene, SIZE, SIZE, kink=False, grad=False).chamber == 1
    return led, float(np.sqrt(np.mean(b[on_a] ** 2))), float(b[on_a].max())


def test_eps_slider_moves_the_ledger_as_python_predicts(session):
    got = {}
    for exponent in (-3, -6):
        session.set_eps(exponent)
        assert session.page.text_content("#sim-log_eps-value") == f"1.0e{exponent}"
        got[exponent] = (session.ledger("rms"), session.ledger("max"), session.ledger("flips"))
    report = {}
    for e, eps in ((-3, 1e-3), (-6, 1e-6)):
        led, rms_bound, max_bound = _python_ledger(eps)
        rms, top, flips = got[e]
        assert abs(rms - led.rms) <= rms_bound, (e, rms, led.rms, rms_bound)
        assert abs(top - led.max_abs) <= max_bound, (e, top, led.max_abs, max_bound)
        assert flips == led.flips == 0
        report[f"eps={eps:g}"] = {"rms": rms, "max": top, "python_rms": led.rms, "python_max": led.max_abs,
                                  "rms_bound": rms_bound, "max_bound": max_bound}
    # The slider moves the ledger down the truncation slope: by three orders
    # of magnitude or more from 1e-3 to 1e-6.
    assert got[-6][0] < 1e-3 * got[-3][0]
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / "browser_ledger.json").write_text(json.dumps(report, indent=1))


def test_hover_readout_gives_pythons_chart(session):
    """Mouse events carry whole CSS pixels, so the test aims at a pixel, reads
    which pixel the readout reports (within one of the aim), and compares that
    pixel's (u, v) with Python's, within the error model's chart bound (the
    browser's atan2 may round the last bit differently)."""
    session.set_eps(-3)
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
        session.page.wait_for_function(
            f"Math.abs(Number(document.getElementById('sim-readout').dataset.i) - {i}) <= 1 && "
            f"Math.abs(Number(document.getElementById('sim-readout').dataset.j) - {j}) <= 1", timeout=10_000)
        ri = int(session.page.get_attribute("#sim-readout", "data-i"))
        rj = int(session.page.get_attribute("#sim-readout", "data-j"))
        assert gb.chamber[rj, ri] == int(session.page.get_attribute("#sim-readout", "data-chamber")) == 1
        u = float(session.page.get_attribute("#sim-readout", "data-u"))
        v = float(session.page.get_attribute("#sim-readout", "data-v"))
        assert abs(u - gb.uv[rj, ri, 0]) <= CHART_TOL and abs(v - gb.uv[rj, ri, 1]) <= CHART_TOL, (ri, rj)
        checked.add((ri, rj))
    assert len(checked) == len(pick)
    assert "(u, v)" in session.page.text_content("#sim-readout")


def test_every_control_is_reachable_and_movable_from_the_keyboard(browser, book_html):
    s = Session(browser, (book_html / "s4_simulator.html").as_uri())
    try:
        page = s.page
        page.focus("#sim-canvas-numeric")
        seen = []
        for _ in range(40):
            page.keyboard.press("Tab")
            seen.append(page.evaluate("document.activeElement.id"))
        missing = [c for c in CONTROLS + BUTTONS if c not in seen]
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
            if cid == "sim-resolution":
                key = "ArrowUp"          # 256 -> 128: keeps the test quick
            page.keyboard.press(key)
            s.wait_update(n)
            assert value() != before, (cid, kind, key)
        for bid in BUTTONS:
            page.focus(f"#{bid}")
            n = s.updates()
            page.keyboard.press("Enter")
            s.wait_update(n)
        assert page.input_value("#sim-height_field") == "ridges"     # reset was last
        # The probe moves with the arrow keys on a focused canvas.
        page.focus("#sim-canvas-symbolic")
        page.keyboard.press("ArrowRight")
        assert page.get_attribute("#sim-readout", "data-i") is not None
        assert s.errors == [] and s.blocked == []
    finally:
        s.close()


def test_update_time_is_measured_and_a_screenshot_saved(browser, book_html):
    s = Session(browser, (book_html / "s4_simulator.html").as_uri())
    try:
        for k in range(16):
            s.set_eps(-3 if k % 2 else -3.1)
        timings = s.page.evaluate(
            "document.querySelector('[data-symrender-sim]').symrender.timings")
        ms = [t["ms"] for t in timings if t["resolution"] == SIZE][1:]     # drop the first (JIT warm-up)
        assert len(ms) >= 15 and all(np.isfinite(ms))
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        s.page.set_viewport_size({"width": 1200, "height": 1600})
        s.page.locator("#sim").scroll_into_view_if_needed()
        s.page.screenshot(path=str(ARTIFACTS / "s4_simulator.png"), full_page=False)
        report = {"updates": len(ms), "median_ms": statistics.median(ms), "min_ms": min(ms),
                  "max_ms": max(ms), "size": SIZE}
        (ARTIFACTS / "browser_timing.json").write_text(json.dumps(report, indent=1))
        print("simulator update at 256^2 (both pipelines + difference):", report)
        assert s.errors == [] and s.blocked == []
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


#: Everything on a page that has a width of its own; each must fit in the article's column.
_OVERFLOW_JS = """(strip) => {
  if (strip) {     // the wrong variant: the page without fit.css and fit.js's scaling
    document.querySelectorAll('link[href*="fit.css"]').forEach(l => l.remove());
    document.querySelectorAll('mjx-container').forEach(m => m.style.fontSize = '');
  }
  const main = document.querySelector('article.bd-article');
  const right = main.getBoundingClientRect().right;
  const els = [...main.querySelectorAll('mjx-container[display="true"], table, pre, img, canvas')];
  const over = els.map(e => [e.tagName, Math.max(e.scrollWidth - e.clientWidth,
                                                  e.getBoundingClientRect().right - right),
                             (e.textContent || '').trim().slice(0, 60)]).filter(x => x[1] > 1);
  return {checked: els.length, overflowing: over};
}"""
PAGES = ("index", "s1_what_changes", "s2_scene", "s3_math", "s4_simulator", "s5_lab", "s6_ledger",
         "s7_pitfalls", "s8_history", "s9_roadmap", "glossary")


def _evaluate(browser, book_html, page, script, arg, width=1280):
    """``script(arg)`` on a built page opened offline at ``width`` px, once MathJax and fit.js are done."""
    context = browser.new_context(viewport={"width": width, "height": 900})
    context.route("**/*", lambda r: r.continue_() if r.request.url.startswith("file://") else r.abort())
    try:
        p = context.new_page()
        p.goto((book_html / f"{page}.html").as_uri())
        p.wait_for_load_state("load")
        p.wait_for_function("!window.MathJax || !MathJax.startup || MathJax.startup.promise", timeout=30_000)
        p.evaluate("() => window.MathJax && MathJax.startup ? MathJax.startup.promise : null")
        p.wait_for_timeout(300)                      # fit.js runs after MathJax's promise
        return p.evaluate(script, arg)
    finally:
        context.close()


def _measure_overflow(browser, book_html, width, page, strip=False):
    return _evaluate(browser, book_html, page, _OVERFLOW_JS, strip, width)


@pytest.mark.parametrize("width", [1280, 390])
def test_no_display_table_or_code_block_is_wider_than_its_column(browser, book_html, width):
    """Every display equation, table, code block, image and canvas of every page fits the
    article's column at a desktop and a phone width (fit.css, fit.js); the report goes to
    test-artifacts/overflow_<width>.json."""
    report = {page: _measure_overflow(browser, book_html, width, page) for page in PAGES}
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / f"overflow_{width}.json").write_text(json.dumps(
        {"checked": sum(r["checked"] for r in report.values()),
         "overflowing": sum(len(r["overflowing"]) for r in report.values()), "pages": report}, indent=1))
    assert sum(r["checked"] for r in report.values()) > 100
    assert {p: r["overflowing"] for p, r in report.items() if r["overflowing"]} == {}


def test_the_overflow_check_rejects_the_pages_without_their_fitting(browser, book_html):
    stripped = _measure_overflow(browser, book_html, 390, "s3_math", strip=True)
    assert len(stripped["overflowing"]) > 5


#: Every image of the article: in a numbered, captioned figure, with alt text, at
#: ``sharpness`` device pixels per CSS pixel or more.
_FIGURES_JS = """(sharpness) => {
  const main = document.querySelector('article.bd-article');
  return [...main.querySelectorAll('img')].map(img => {
    const fig = img.closest('figure');
    const cap = fig && fig.querySelector('figcaption');
    const number = cap && cap.querySelector('.caption-number');
    return {src: img.getAttribute('src').slice(-24), alt: (img.getAttribute('alt') || '').length,
            numbered: !!(number && /Fig\\. \\d+/.test(number.textContent)),
            caption: cap ? cap.textContent.trim().length : 0,
            ratio: img.naturalWidth / img.clientWidth, sharp: img.naturalWidth >= sharpness * img.clientWidth - 1};
  });
}"""


def _figures(browser, book_html, page, sharpness):
    return _evaluate(browser, book_html, page, _FIGURES_JS, sharpness)


def test_every_image_is_a_numbered_captioned_figure_with_alt_text_at_twice_its_size(browser, book_html):
    """No bare plot: each image of each page sits in a figure numbered "Fig. n" with a caption and
    alt text, and has at least two device pixels per CSS pixel (for high-density screens)."""
    found = {page: _figures(browser, book_html, page, 2) for page in PAGES}
    images = [dict(i, page=page) for page, imgs in found.items() for i in imgs]
    assert len(images) >= 15
    bad = [i for i in images if not (i["numbered"] and i["caption"] > 40 and i["alt"] > 40 and i["sharp"])]
    assert bad == []


def test_the_figure_check_rejects_images_below_the_sharpness_asked(browser, book_html):
    # The wrong variant: asking for four device pixels per CSS pixel, which no figure has.
    assert not any(i["sharp"] for i in _figures(browser, book_html, "s5_lab", 4))


LOG_EPS = (-1, -3, -6, -9, -12, -14)


@pytest.mark.parametrize("field", ["sine", "ridges", "rings"])
def test_the_log_difference_view_shows_the_u_curve(browser, book_html, field):
    """On the default log scale the difference canvas is visible on sphere A at every step from
    1e-1 to 1e-14, and its mean level follows the U-curve: lower at the optimum than at
    either end.  On the linear scale (the wrong variant for small steps) it is black."""
    s = Session(browser, (book_html / "s4_simulator.html").as_uri())
    try:
        s.select("height_field", field)
        means = {}
        for e in LOG_EPS:
            s.set_eps(e)
            levels = np.array(s.difference_levels())
            assert np.count_nonzero(levels) > 0.5 * levels.size, (field, e)   # visible: not black
            means[e] = float(levels.mean())
            if field == "sine" and e in (-3, -6, -12):
                ARTIFACTS.mkdir(parents=True, exist_ok=True)
                s.page.locator("#sim").scroll_into_view_if_needed()
                s.page.locator(".sim-canvases").screenshot(path=str(ARTIFACTS / f"s4_log_view_eps_1e{e}.png"))
        assert min(means[-6], means[-9]) < min(means[-1], means[-14]), means
        s.set_eps(-6)
        s.select("scale", "linear")
        assert np.count_nonzero(s.difference_levels()) == 0 or field == "ridges"   # creases stay visible
        assert s.errors == []
    finally:
        s.close()


def test_preset_three_shows_the_pinch_in_the_shaded_view(browser, book_html):
    """Rings, pole magnified: the shaded canvas, which the preset shows, changes by more
    across the pole than anywhere near it in the unmagnified frame."""
    s = Session(browser, (book_html / "s4_simulator.html").as_uri())
    try:
        before = s.updates()
        s.page.click("#sim-preset-try3")
        s.wait_update(before)
        assert s.page.input_value("#sim-view") == "shaded" and s.page.input_value("#sim-zoom") == "8"
        spread = s.page.evaluate("""() => {
            const c = document.getElementById('sim-canvas-symbolic');
            const n = c.width, d = c.getContext("2d").getImageData(n / 2 - 24, n / 2 - 24, 48, 48).data;
            let lo = 255, hi = 0;
            for (let k = 0; k < d.length; k += 4) { const y = d[k] + d[k + 1] + d[k + 2];
                                                   lo = Math.min(lo, y / 3); hi = Math.max(hi, y / 3); }
            return hi - lo;
        }""")
        assert spread > 60, spread          # a light and a dark side meet at the pole
    finally:
        s.close()


@pytest.mark.parametrize("width", [1280, 390])
def test_the_three_canvases_are_equal_and_side_by_side_at_every_width(browser, book_html, width):
    s = Session(browser, (book_html / "s4_simulator.html").as_uri())
    try:
        s.page.set_viewport_size({"width": width, "height": 1200})
        s.page.wait_for_timeout(200)
        boxes = [s.page.locator(f"#sim-canvas-{n}").bounding_box() for n in ("numeric", "symbolic", "difference")]
        assert max(b["width"] for b in boxes) - min(b["width"] for b in boxes) < 1, boxes
        assert max(b["y"] for b in boxes) - min(b["y"] for b in boxes) < 1, boxes          # one row
        if width == 390:
            ARTIFACTS.mkdir(parents=True, exist_ok=True)
            s.page.locator(".sim-canvases").scroll_into_view_if_needed()
            s.page.screenshot(path=str(ARTIFACTS / "s4_at_390px.png"), full_page=False)
    finally:
        s.close()
