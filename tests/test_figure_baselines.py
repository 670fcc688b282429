"""The book's figures against their PNG baselines in tests/figure_baselines (pytest-mpl).

One test per function of the book's library that draws a figure (`chapter.figures`'s
diagrams, `ucurve_anatomy` and `displacement_figure`; `chapter.benchmark`'s
`pareto_figure` and `univariate_figure`), each in the book's style (`chapter.figures.style`)
and saved at `DPI` dots per inch, so small that the module runs in seconds.  The figures
that draw a measurement are given fixed numbers made here (a U-curve, timings and errors,
two renders' masks): their measurements have tests of their own, and measured here they
would differ between machines (timings; a rounding error's noise, in its last bits).  A
figure passes when its PNG's RMS difference from its baseline (over 0-255 levels) is at
most `TOLERANCE`: with numpy's SIMD paths disabled the PNGs are identical, and one line
drawn a shade redder is 1.13 apart (`test_a_changed_figure_fails_its_baseline`).  The
figures a page draws in its own cells (panels of renders) are the book build's.

pytest-mpl compares only with ``--mpl``, which pyproject's addopts give every run
(`test_the_comparison_is_on`); a figure that fails leaves its PNG, the baseline's and their
difference in test-artifacts/figures.  After a deliberate change of a figure, from the repository:

    .venv/bin/python -m pytest tests/test_figure_baselines.py --mpl-generate-path=tests/figure_baselines
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from chapter import figures
from chapter.benchmark import pareto_figure, univariate_figure
from lab import gradient_benchmark as gb
from lab import gradient_methods as gm
from renderer import formulas as F
from renderer.ucurve import UCurve
from tests.scalar_reference import SEED_FIELDS

pytest_plugins = ["pytester"]

BASELINES = Path(__file__).resolve().parent / "figure_baselines"
#: Dots per inch of the compared PNGs (the book's are drawn at 200).
DPI = 40
#: Largest RMS difference from a baseline, in 0-255 levels.
TOLERANCE = 1.0
#: style="default": pytest-mpl resets matplotlib to its defaults; each test then sets the book's style.
FIGURE = pytest.mark.mpl_image_compare(baseline_dir=BASELINES, tolerance=TOLERANCE, style="default",
                                       savefig_kwargs={"dpi": DPI})


@FIGURE
def test_frame_diagram():
    figures.style()
    return figures.frame_diagram()


@FIGURE
def test_normal_diagram():
    figures.style()
    return figures.normal_diagram()


@FIGURE
def test_stencil_diagram():
    figures.style()
    return figures.stencil_diagram()


def _ucurve():
    """A U-curve as `renderer.ucurve.measure` returns one: truncation A eps^2, rounding noise of
    size B / eps (a fixed pattern of signs and sizes), the model and the fitted model's steps."""
    eps = np.geomspace(1e-13, 1e-1, 49)
    A, B = 0.5, 2e-16
    truncation = A * eps**2
    roundoff = B / eps * np.where(np.arange(eps.size) % 3 == 1, -1.0, 1.0) * (0.3 + 0.7 * (np.arange(eps.size) % 5) / 4)
    error = np.abs(truncation + roundoff)
    model = A * eps**2 + 1.5 * B / eps
    eps_model, eps_fitted = (1.5 * B / (2 * A)) ** (1 / 3), (B / (2 * A)) ** (1 / 3)
    low = int(np.argmin(error))
    return UCurve(field="sine", u=0.3, v=0.4, component="u", eps=eps, error=error, truncation=truncation,
                  roundoff=roundoff, model=model, derivative=1.0, third_derivative=6 * A, height=0.5,
                  model_truncation=A, model_cancellation=B, model_argument=0.5 * B, eps_model=eps_model,
                  error_model=float(A * eps_model**2 + 1.5 * B / eps_model), eps_measured_min=float(eps[low]),
                  error_at_measured_min=float(error[low]), fitted_truncation=A, fitted_roundoff=B,
                  eps_fitted=eps_fitted, error_at_fitted=float(A * eps_fitted**2 + B / eps_fitted))


@FIGURE
def test_ucurve_anatomy():
    figures.style()
    return figures.ucurve_anatomy(_ucurve())


def _error(method, eps):
    """A method's error at step ``eps`` (None: a method without one), shaped as the book's measurements are."""
    if eps is None:
        return {"exact": 1e-16, "richardson": 3e-13}.get(method, 2e-16)
    if method.startswith("complex step"):
        return max(0.1 * eps**2, 1e-16)
    return (0.1 * eps if method == "forward" else 0.01 * eps**2) + 1e-16 / eps


#: The methods the baselines draw: fixed input data, as `SEED_FIELDS` are (a method appended to
#: `lab.gradient_methods.METHODS` changes the book's figures, not these baselines;
#: tests/test_benchmark_figure.py draws the figure with more).
BASELINE_METHODS = ("exact", "central", "forward", "complex step", "complex step, |z| continued", "richardson",
                    gm.AD)


def _measurement(methods=BASELINE_METHODS):
    """Each of ``methods`` (names of `lab.gradient_methods.METHODS`) on each of the seed's fields
    (`scalar_reference.SEED_FIELDS`: fixed input data, as the times and errors are; a field
    registered later changes the book's figure, not this test's) where it applies, at the `FAST`
    configuration's steps, with fixed times and errors."""
    rows = []
    for i, field in enumerate(SEED_FIELDS):
        for k, m in enumerate(map(gm.method, methods)):
            if m.applies(F.field(field)):
                for j, eps in enumerate(m.steps_in(gb.FAST)):
                    t, err = 1e-3 * (1 + k) * (1 + 0.3 * j) * (1 + 0.2 * i), _error(m.name, eps)
                    rows.append(gb.MethodResult(field, m.name, eps, (0.8 * t, t, 1.5 * t), 1.0, 0.0, 0.0, err, err))
    return gb.Measurement(gb.FAST, tuple(rows), 1000, {}, {}, {}, 1.0, 8.0, 4.0)


@FIGURE
def test_pareto_figure():
    figures.style()
    return pareto_figure(_measurement())


@FIGURE
def test_univariate_figure():
    figures.style()
    steps = gb.UNIVARIATE_STEPS[::4]
    rows = [gb.UnivariateRow(m.name, eps, 1.0, _error(m.name, eps), _error(m.name, eps))
            for m in map(gm.method, BASELINE_METHODS) if m.derivative is not None
            and m.name != "complex step, |z| continued"
            for eps in m.steps_in(SimpleNamespace(central_steps=steps, forward_steps=steps, complex_steps=steps))]
    return univariate_figure(gb.UnivariateErrors("f", 1.5, 1.0, 50, tuple(rows), None, {}))


def _displaced(n=32):
    """What `displacement_figure` reads of a `lab.displaced.Displaced`: on an n x n frame, the
    bumped sphere a disc (chamber 1, the floor 3 elsewhere), the displaced one a disc with a
    wavy rim; each shaded by one light; their cast shadows two shifted crescents, and the
    displaced sphere's a patch on itself."""
    y, x = np.mgrid[-1:1:n * 1j, -1:1:n * 1j]
    r, angle = np.hypot(x, y), np.arctan2(y, x)
    bumped_covered, covered = r < 0.6, r < 0.6 + 0.06 * np.sin(8 * angle)

    def shade(disc):
        z = np.sqrt(np.clip(1 - (r / 0.7) ** 2, 0, 1))
        lit = np.clip(0.4 * -x + 0.4 * y + 0.8 * z, 0, 1)
        return np.where(disc[..., None], lit[..., None] * [0.8, 0.5, 0.3], [0.2, 0.2, 0.25])

    shadow = (~covered & (np.hypot(x - 0.25, y + 0.2) < 0.65)) | (bumped_covered & (np.hypot(x - 0.3, y - 0.3) < 0.2))
    bumped_shadow = ~bumped_covered & (np.hypot(x - 0.2, y + 0.2) < 0.6)
    bumped = SimpleNamespace(image=shade(bumped_covered), chamber=np.where(bumped_covered, 1, 3).astype(np.uint8))
    return SimpleNamespace(image=shade(covered), covered=covered, shadow=shadow, bumped=bumped,
                           bumped_shadow=bumped_shadow)


@FIGURE
def test_displacement_figure():
    figures.style()
    return figures.displacement_figure(_displaced())


@FIGURE
def test_difference_bar():
    """Both scales of `figures.difference_bar`: the log one beside a panel, the linear one under two."""
    import matplotlib.pyplot as plt
    figures.style()
    ramp = np.repeat(np.linspace(0.0, 1.0, 32)[None, :, None], 3, axis=2).repeat(8, axis=0)
    fig, ax = plt.subplot_mosaic([["log", "log"], ["a", "b"]], figsize=(4.8, 4.0), layout="constrained")
    for a in ax.values():
        a.imshow(ramp)
        a.axis("off")
    figures.difference_bar(fig, ax["log"], log_floor=1e-16)
    figures.difference_bar(fig, [ax["a"], ax["b"]], gain=100.0, location="bottom")
    return fig


@pytest.mark.parametrize("seed", range(3))
def test_the_difference_bar_maps_each_difference_to_its_grey_in_the_image(seed):
    """The bar's grey for |ΔI| = d is the image's: min(gain d, 1) on the linear scale, and
    1 - log10 d / log10 floor on the log one (renderer/js/simulator.js's), at random d, gain, floor;
    its tick labels are plain numbers (no mathtext)."""
    import matplotlib.pyplot as plt
    rng = np.random.default_rng(seed)
    gain, floor = 10.0 ** rng.uniform(0, 4), 10.0 ** -rng.integers(4, 20)
    d = 10.0 ** rng.uniform(np.log10(floor), 0, 50)
    fig, ax = plt.subplots()
    try:
        linear = figures.difference_bar(fig, ax, gain=gain)
        log = figures.difference_bar(fig, ax, log_floor=floor)
        assert np.allclose(np.clip(linear.norm(d), 0, 1), np.minimum(gain * d, 1.0), rtol=1e-12, atol=0)
        assert np.allclose(log.norm(d), 1.0 - np.log10(d) / np.log10(floor), rtol=1e-9, atol=1e-12)
        fig.canvas.draw()
        labels = [t.get_text() for bar in (linear, log) for t in bar.ax.get_yticklabels()]
        assert labels and not any("$" in t for t in labels), labels
    finally:
        plt.close(fig)


@pytest.mark.parametrize("kwargs", [{}, {"gain": 1.0, "log_floor": 0.1}, {"gain": 0.0}, {"gain": float("nan")},
                                    {"log_floor": 1.0}, {"log_floor": -1e-3}])
def test_the_difference_bar_refuses_a_scale_it_cannot_draw(kwargs):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    try:
        with pytest.raises(ValueError, match="gain|log_floor"):
            figures.difference_bar(fig, ax, **kwargs)
    finally:
        plt.close(fig)


def test_the_comparison_is_on(request):
    """pytest-mpl compares a figure with its baseline only under ``--mpl`` (or writes the
    baselines under ``--mpl-generate-path``); without either every test above passes unchecked."""
    assert request.config.getoption("--mpl") or request.config.getoption("--mpl-generate-path")


PLANTED = """
from chapter import figures
from tests import test_figure_baselines as t


@t.FIGURE
def test_stencil_diagram(monkeypatch):
    monkeypatch.setattr(figures, "RED", {colour!r})
    return t.test_stencil_diagram()
"""


@pytest.fixture
def drawn_once():
    """The stencil diagram drawn before `pytester` is set up.  pytester forgets, at its teardown, every
    module imported since its setup; a module the planted test imported first (pyplot's, numba's
    registries, loaded with the first kernel) would be imported again by a later test of this worker,
    beside classes and registrations that outlived the first copy ("duplicate registration for
    PolynomialType"; "Single argument to subplot must be a three-digit integer, not GridSpec")."""
    import matplotlib.pyplot as plt
    plt.close(figures.stencil_diagram())


def test_a_changed_figure_fails_its_baseline(drawn_once, pytester):
    """The stencil diagram with its stencil drawn a shade redder (#a02d2d for #7a1f1f), compared as this
    module compares it (`FIGURE`), with its baseline: it fails, the two PNGs 1.13 apart, just past
    `TOLERANCE` (a tolerance raised by a fifth would pass it; the stencil drawn green is 3.2 apart)."""
    pytester.makepyfile(test_planted=PLANTED.format(colour="#a02d2d"))
    result = pytester.runpytest_inprocess("--mpl", "--mpl-results-path", str(pytester.path / "results"),
                                          "-p", "no:cacheprovider", "-p", "no:xdist")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*Image files did not match*", "*RMS Value: *", "*Tolerance:*", f"* {TOLERANCE}"])


def test_every_function_that_draws_a_figure_has_a_baseline():
    """A function of the book's library (book/chapter) that makes a matplotlib figure is named by a
    test here: a new figure comes with its baseline."""
    import importlib
    import inspect
    import pkgutil

    import chapter
    drawing = ("plt.subplots(", "plt.figure(", "subplot_mosaic(", "Figure(")
    here = Path(__file__).read_text(encoding="utf-8")
    found = [f"{info.name}.{name}" for info in pkgutil.iter_modules(chapter.__path__, "chapter.")
             for name, f in vars(importlib.import_module(info.name)).items()
             if inspect.isfunction(f) and f.__module__ == info.name and any(d in inspect.getsource(f) for d in drawing)]
    assert len(found) >= 7 and [f for f in found if f"{f.rsplit('.', 1)[1]}(" not in here] == []


def test_the_chamber_colours_cover_every_chamber_code_in_order():
    """`figures.chamber_colours`: one colour per code of `renderer.render.CHAMBER_NAMES`, the colour map
    indexed by code (0 to the last), each colour distinct."""
    from matplotlib.colors import to_rgb

    from renderer.render import CHAMBER_NAMES
    cmap, colours = figures.chamber_colours()
    assert sorted(colours) == sorted(CHAMBER_NAMES) == list(range(cmap.N))
    assert [to_rgb(cmap(code)) for code in sorted(colours)] == [to_rgb(colours[code]) for code in sorted(colours)]
    assert len(set(colours.values())) == len(colours)
