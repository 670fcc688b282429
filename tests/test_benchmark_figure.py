"""Fig. 13's geometry (`chapter.benchmark.pareto_figure`): the lowest marker (the exact
gradient's star) stands a decade or more above its panel's bottom edge."""

from types import SimpleNamespace

import matplotlib
import pytest

matplotlib.use("Agg")

from chapter.benchmark import pareto_figure  # noqa: E402
from renderer import formulas as F  # noqa: E402


def _result(field, method, err, ms, eps=None):
    t = ms / 1e3
    return SimpleNamespace(field=field, method=method, eps=eps, max_error=err, rms_error=err,
                           median=t, t_min=0.8 * t, t_max=1.5 * t)


def _fake():
    """The exact gradient fastest and most accurate, as on the page: it is the front's lowest point."""
    rows = []
    for f in F.FIELDS:
        rows += [_result(f, "exact", 1e-14, 1.0), _result(f, "central", 3e-3, 2.0, 1e-3),
                 _result(f, "central", 3e-9, 3.0, 1e-6), _result(f, "richardson", 1e-12, 100.0)]
    return SimpleNamespace(results=tuple(rows), of=lambda f: [r for r in rows if r.field == f])


def misleading_labels(fig):
    """The step labels of the drawn ``fig`` (texts "ε = …" with the attribute ``marks``, the marker each names)
    that stand outside their panel or nearer to another marker of it (its plotted lines' points) than to
    their own: [(label, the nearer marker, or "outside")]."""
    import numpy as np
    out = []
    for ax in fig.axes:
        points = np.vstack([ln.get_xydata() for ln in ax.get_lines() if ln.get_marker() not in (None, "None", "")]
                           or [np.empty((0, 2))])
        for label in [t for t in ax.texts if hasattr(t, "marks")]:
            box = label.get_window_extent()
            if not (ax.bbox.x0 <= box.x0 and box.x1 <= ax.bbox.x1 and ax.bbox.y0 <= box.y0 and box.y1 <= ax.bbox.y1):
                out.append((label.get_text(), "outside"))
                continue
            at = ax.transData.transform(points)
            gap = np.hypot(np.clip(np.maximum(box.x0 - at[:, 0], at[:, 0] - box.x1), 0, None),
                           np.clip(np.maximum(box.y0 - at[:, 1], at[:, 1] - box.y1), 0, None))
            own = np.all(points == label.marks, axis=1)                # the very floats plotted
            if own.any() and gap[~own].size and gap[~own].min() < gap[own].min():
                out.append((label.get_text(), tuple(points[~own][gap[~own].argmin()])))
    return out


def test_the_lowest_marker_stands_clear_of_the_bottom_edge():
    fig = pareto_figure(_fake())
    for ax in [a for a in fig.axes if a.get_title()]:     # the panels
        lines = [ln for ln in ax.get_lines() if ln.get_marker() not in (None, "None", "") and len(ln.get_ydata())]
        front = [ln for ln in ax.get_lines() if ln.get_drawstyle().startswith("steps")]
        assert len(front) == 1 and lines
        lowest = min(min(ln.get_ydata()) for ln in lines)
        bottom = ax.get_ylim()[0]
        assert lowest / bottom >= 10, (ax.get_title(), lowest, bottom)     # a decade or more of room


def test_each_step_of_a_difference_is_labelled_at_its_bar_in_its_colour():
    """The sweeps as the page draws them, at one time per method: every step's label, `step_text`'s
    words in the method's colour at the right end of its marker's bar; a method without steps has none."""
    from chapter.benchmark import step_text
    from chapter.layout import text_overlaps
    from lab import gradient_methods as gm
    rows = []
    for f in F.FIELDS:
        rows += [_result(f, "exact", 1e-14, 1.0), _result(f, "richardson", 1e-12, 100.0)]
        rows += [_result(f, "central", err, 2.0, eps) for eps, err in ((1e-3, 3e-3), (1e-6, 3e-11), (1e-9, 3e-7))]
    fig = pareto_figure(SimpleNamespace(results=tuple(rows), of=lambda f: [r for r in rows if r.field == f]))
    assert text_overlaps(fig) == []
    for ax in [a for a in fig.axes if a.get_title()]:
        labels = {t.get_text(): t for t in ax.texts}
        said = lambda e: "\u03b5 = " + step_text(e).replace("-", "\u2212")       # noqa: E731
        assert set(labels) == {said(e) for e in (1e-3, 1e-6, 1e-9)}
        for eps, err in ((1e-3, 3e-3), (1e-6, 3e-11), (1e-9, 3e-7)):
            label = labels[said(eps)]
            assert label.xy == pytest.approx((1.5 * 2.0, err)) and label.get_color() == gm.method("central").style.colour
    # A middle step's label on an end's gives way to it, whichever comes first in the sweep: the end keeps the
    # right end of its bar, the middle one moves to the left end of its own.
    for order in (1, -1):
        steps = ((1e-3, 3e-3), (1e-6, 3.1e-3), (1e-9, 3e-7))[::order]
        rows = [_result("sine", "exact", 1e-14, 1.0)] + [_result("sine", "central", err, 2.0, eps) for eps, err in steps]
        fig = pareto_figure(SimpleNamespace(results=tuple(rows), of=lambda f: rows))
        sides = {t.get_text(): t.get_horizontalalignment() for t in fig.axes[0].texts}
        assert sides == {"\u03b5 = 1e\u22123": "left", "\u03b5 = 1e\u22126": "right", "\u03b5 = 1e\u22129": "left"}


def test_the_univariate_figure_draws_each_method_in_its_style_for_a_phone():
    """`univariate_figure`: one line per method in its record's colour and line style, a method without a
    step drawn across the plot, every text at least 10 pt in a figure at most 5 in wide, nothing overlapping."""
    from chapter.benchmark import univariate_figure
    from chapter.layout import drawn_texts, text_overlaps
    from lab import gradient_benchmark as gb
    from lab import gradient_methods as gm

    steps = (1e-2, 1e-6, 1e-10)
    rows = [gb.UnivariateRow(m, e, 1.0, err, err) for m, errs in (("central", (1e-5, 1e-11, 1e-6)),
                                                                   ("complex step", (1e-5, 1e-16, 1e-16)))
            for e, err in zip(steps, errs)] + [gb.UnivariateRow(gm.AD, None, 1.0, 1e-16, 1e-16)]
    fake = gb.UnivariateErrors("f", 1.5, 1.0, 50, tuple(rows), None, {})
    fig = univariate_figure(fake)
    lines = {ln.get_label(): ln for ln in fig.axes[0].get_lines()}
    from matplotlib.lines import Line2D
    for name in ("central", "complex step", gm.AD):
        m, drawn = gm.method(name), lines[gm.method(name).label]
        assert drawn.get_color() == m.style.colour
        assert drawn.get_linestyle() == Line2D([], [], linestyle=m.style.line).get_linestyle()
        assert drawn.get_marker() == (m.style.marker if m.steps else "None")
    assert len({lines[gm.method(n).label].get_linestyle() for n in ("central", "complex step", gm.AD)}) == 3
    assert list(lines[gm.method(gm.AD).label].get_xdata()) == [0, 1]           # across the axes
    assert fig.get_figwidth() <= 5.0 and min(t.get_fontsize() for t in drawn_texts(fig)) >= 10
    assert text_overlaps(fig) == []


@pytest.mark.parametrize("figure", ["univariate", "pareto"])
def test_a_methods_long_label_stacks_the_legend_and_leaves_the_figure_its_width(figure, monkeypatch):
    """A legend wider than the figure widens the saved PNG (tight bounding box), and a phone's column then
    shrinks every text in it below the audit's floor (a newcomer's 31-character label did): with a long
    label the legend takes one column and the drawn figure stays within its width."""
    import dataclasses
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from chapter.benchmark import univariate_figure
    from lab import gradient_benchmark as gb
    from lab import gradient_methods as gm

    long = dataclasses.replace(gm.method("central"), label="a fourth-order central difference, five points")
    monkeypatch.setattr(gm, "METHODS", [long if m.name == "central" else m for m in gm.METHODS])
    if figure == "univariate":
        rows = [gb.UnivariateRow(m, e, 1.0, 1e-8, 1e-8) for m in ("central", "complex step") for e in (1e-2, 1e-6)]
        fig = univariate_figure(gb.UnivariateErrors("f", 1.5, 1.0, 50, tuple(rows), None, {}))
    else:
        fig = pareto_figure(_fake())
    drawn = fig.get_tightbbox(FigureCanvasAgg(fig).get_renderer())
    assert drawn.width <= fig.get_figwidth() + 0.05 and len(fig.legends) == 1


def _drawn(base, rng):
    """``base``'s results, each with a time drawn from 0.5 ms to 0.5 s and an error from 1e-16 to 2."""
    import dataclasses
    return tuple(dataclasses.replace(r, times=(0.8 * t, t, 1.5 * t), max_error=e, rms_error=e)
                 for r in base.results for t, e in [10 ** rng.uniform((-3.3, -16), (-0.3, 0.3))])


def test_the_label_check_catches_a_step_label_beside_another_marker(monkeypatch):
    """With `chapter.benchmark.misleading` never true, the first seeded draw of the test below puts a step
    label nearer another marker than its own, and `misleading_labels` says so."""
    import dataclasses

    import numpy as np

    from chapter import benchmark, figures
    from lab import gradient_methods as gm

    from .test_figure_baselines import _measurement

    figures.style()
    monkeypatch.setattr(benchmark, "misleading", lambda label, markers: False)
    base = _measurement([m.name for m in gm.METHODS])
    rows = _drawn(base, np.random.default_rng(20261125))
    assert misleading_labels(benchmark.pareto_figure(dataclasses.replace(base, results=rows)))


def test_a_step_label_that_leaves_its_panel_is_misleading():
    """A label drawn past the panel's left edge (over the axis line, beside the tick labels) is refused by
    `chapter.benchmark.misleading` and found by `misleading_labels`, though its own marker is the nearest;
    moved inside, beside that marker, it is neither."""
    from matplotlib.figure import Figure

    from chapter.benchmark import misleading

    fig = Figure(figsize=(4, 2))
    ax = fig.subplots()
    ax.plot([1.0, 10.0], [1.0, 1.0], marker="o")
    ax.set_xlim(0.5, 20)
    label = ax.annotate("ε = 1e−3", (1.0, 1.0), xytext=(-3, 0), textcoords="offset points", ha="right")
    label.marks = (1.0, 1.0)
    fig.draw_without_rendering()
    assert misleading(label, [(1.0, 1.0), (10.0, 1.0)]) and misleading_labels(fig) == [("ε = 1e−3", "outside")]
    label.set_horizontalalignment("left")
    label.set_position((3, 0))
    fig.draw_without_rendering()
    assert not misleading(label, [(1.0, 1.0), (10.0, 1.0)]) and misleading_labels(fig) == []


@pytest.mark.parametrize("added", [0, 1, 4])
def test_no_text_of_the_figure_collides_whatever_the_machine_times(monkeypatch, added):
    """The times are the machine's, so the panels' widths move with the tick labels the time axis
    needs; a panel's title (two lines for a field with creases) must not reach the neighbouring tick
    labels at any of them, nor at any errors.  Seeded draws of every run's time from 0.5 ms to 0.5 s
    (the page's methods span about that, the fastest to the slowest) and its error from 1e-16 to 2,
    in the book's style; no step label stands nearer another marker than its own (`misleading_labels`).  With ``added`` methods appended to `METHODS` (a taller legend), the panels
    keep the height they have without them, and the legend lists the records' order."""
    import dataclasses

    import numpy as np

    from chapter import figures
    from chapter.layout import text_overlaps
    from lab import gradient_methods as gm

    from .test_figure_baselines import _measurement

    figures.style()

    def panels(fig):                                          # each panel's height in inches, laid out
        fig.draw_without_rendering()
        return [a.get_position().height * fig.get_figheight() for a in fig.axes if a.get_title()]

    alone = panels(pareto_figure(_measurement()))
    central = gm.method("central")
    monkeypatch.setattr(gm, "METHODS", [*gm.METHODS, *(dataclasses.replace(
        central, name=f"toy {i}", label=f"toy difference {i}", style=dataclasses.replace(central.style, marker="v"))
        for i in range(added))])
    base, rng = _measurement([m.name for m in gm.METHODS]), np.random.default_rng(20261125)
    for _ in range(6):
        rows = _drawn(base, rng)
        fig = pareto_figure(dataclasses.replace(base, results=rows))
        assert text_overlaps(fig) == [], [(r.field, r.method, r.times, r.max_error) for r in rows]
        assert misleading_labels(fig) == [], [(r.field, r.method, r.times, r.max_error) for r in rows]
    grown = panels(pareto_figure(base))
    assert len(grown) == len(alone) and min(h / a for h, a in zip(grown, alone)) > 0.97, (grown, alone)
    legend = [t.get_text() for lg in fig.legends for t in lg.get_texts()]
    assert legend == ["Pareto front", *(m.label for m in gm.METHODS if m.name in {r.method for r in rows})]
