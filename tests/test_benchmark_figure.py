"""Fig. 13's geometry (`chapter.benchmark.pareto_figure`): the lowest marker (the exact
gradient's star) stands a decade or more above its panel's bottom edge."""

from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")

from chapter.benchmark import pareto_figure  # noqa: E402
from lab import gradient_methods as gm  # noqa: E402


def _result(field, method, err, ms, eps=None):
    t = ms / 1e3
    return SimpleNamespace(field=field, method=method, eps=eps, max_error=err, rms_error=err,
                           median=t, t_min=0.8 * t, t_max=1.5 * t, valid=True)


def _fake():
    """The exact gradient fastest and most accurate, as on the page: it is the front's lowest point."""
    rows = []
    for f in gm.FIELDS:
        rows += [_result(f, "exact", 1e-14, 1.0), _result(f, "central", 3e-3, 2.0, 1e-3),
                 _result(f, "central", 3e-9, 3.0, 1e-6), _result(f, "richardson", 1e-12, 100.0)]
    return SimpleNamespace(results=tuple(rows), of=lambda f: [r for r in rows if r.field == f])


def test_the_lowest_marker_stands_clear_of_the_bottom_edge():
    fig = pareto_figure(_fake())
    for ax in [a for a in fig.axes if a.get_title()]:     # the panels (not the legend's cell)
        lines = [ln for ln in ax.get_lines() if ln.get_marker() not in (None, "None", "") and len(ln.get_ydata())]
        front = [ln for ln in ax.get_lines() if ln.get_drawstyle().startswith("steps")]
        assert len(front) == 1 and lines
        lowest = min(min(ln.get_ydata()) for ln in lines)
        bottom = ax.get_ylim()[0]
        assert lowest / bottom >= 10, (ax.get_title(), lowest, bottom)     # a decade or more of room
