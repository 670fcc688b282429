"""The gradient-methods benchmark as the book and benchmarks/bench_gradients.py show it:
its run time against error as a figure (`pareto_figure`) and as a Markdown table
(`markdown_table`), from the numbers `lab.gradient_benchmark.measure` returns; the sentence
naming every method (`methods_sentence`); and a reader's function of one variable through
the methods (`univariate_figure`, `univariate_table`, `published_table`), from
`lab.gradient_benchmark.univariate_errors`.  Every method's label, style and sources are its
record's (`lab.gradient_methods.METHODS`)."""

from __future__ import annotations

import numpy as np

from lab import gradient_benchmark as gb
from lab import gradient_methods as gm
from renderer import formulas as F

__all__ = ["pareto_figure", "markdown_table", "fastest_on", "FASTEST_MARGIN", "share_in_words", "methods_sentence",
           "univariate_figure", "univariate_table", "published_table", "step_text"]

_NUMBER_WORDS = ("none", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten")


#: The error axis starts this factor below the panel's lowest point.
_Y_ROOM = 30.0
#: The height of a panel, inches.
_ROW_IN = 1.9


def _floor(e):
    # An error of exactly 0 cannot sit on a log axis; plotted at 1e-18 (marked in the legend).
    return max(e, 1e-18)


def _legend(fig, handles, labels):
    """The figure's legend under its panels in two columns, or in one where two would be wider than the
    figure (a method's long label): a legend wider than the figure widens the saved image, and a phone's
    column then shrinks every text in it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    for ncols in (2, 1):
        legend = fig.legend(handles, labels, loc="outside lower center", ncols=ncols, frameon=False)
        if ncols == 1 or legend.get_window_extent(FigureCanvasAgg(fig).get_renderer()).width <= fig.bbox.width:
            return legend
        legend.remove()


def pareto_figure(measurement, *, error="max"):
    """Log-log plot of time per frame against error, one panel per field, each as wide as the figure and
    stacked for a phone's column (5 in wide, every text at the book's size, `chapter.figures.TEXT_PT`, a
    shared time axis labelled on every panel), the legend under them.

    Each point is a method at its median time, with a horizontal bar from the
    fastest to the slowest run; difference sweeps are joined in order of eps, each
    marker labelled with its step (`step_text`) above its bar on the right where the label
    collides with nothing, a sweep's first and last steps before the others
    (`chapter.layout.drop_clashing`); the Pareto front is the
    grey staircase; each error axis starts `_Y_ROOM` times below its panel's
    lowest point, so no marker sits on the frame.  An error of exactly 0 would be drawn at 1e-18.
    Colours, markers, line styles and legend labels are the methods' records', and the legend lists
    them in `lab.gradient_methods.METHODS`' order.

    Parameters
    ----------
    measurement : lab.gradient_benchmark.Measurement
    error : {"max", "rms"}, keyword-only

    Returns
    -------
    matplotlib.figure.Figure (not shown; the caller shows or saves it).

    Raises
    ------
    ValueError
        If ``error`` is not "max" or "rms".
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import LogLocator, NullLocator
    from .layout import drop_clashing
    if error not in ("max", "rms"):
        raise ValueError(f"error must be 'max' or 'rms', got {error!r}")
    names = list(dict.fromkeys(r.field for r in measurement.results))
    # One column: at two panels a row, a phone showed each 140 px wide.
    fig = Figure(figsize=(5.0, _ROW_IN * len(names)), layout="constrained")
    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False).ravel()
    pick = (lambda r: r.max_error) if error == "max" else (lambda r: r.rms_error)
    t_lo = 0.5e3 * min(r.t_min for r in measurement.results)
    t_hi = 2e3 * max(r.t_max for r in measurement.results)
    handles, ends, middles, markers = {}, [], [], {}
    for ax, name in zip(axes, names):
        rs = measurement.of(name)
        front = gb.pareto_front(rs, error=error)
        ft = [1e3 * r.median for r in front]
        fe = [_floor(pick(r)) for r in front]
        handles["Pareto front"], = ax.step(ft + [t_hi], fe + [fe[-1]], where="post", color="0.75",
                                           lw=2.5, zorder=0)
        for method in dict.fromkeys(r.method for r in rs):
            group = [r for r in rs if r.method == method]
            style = gm.method(method).style
            t = np.array([1e3 * r.median for r in group])
            e = np.array([_floor(pick(r)) for r in group])
            ax.hlines(e, [1e3 * r.t_min for r in group], [1e3 * r.t_max for r in group], color=style.colour,
                      lw=0.8)
            line, = ax.plot(t, e, color=style.colour, ls=style.line, lw=0.8 if len(group) > 1 else 0, alpha=0.7,
                            marker=style.marker, ms=style.size)
            handles.setdefault(method, line)
            markers.setdefault(ax, []).extend(zip(t, e))
            for i, r in enumerate(group if len(group) > 1 else ()):
                # At the right end of the marker's bar, which leads the eye from the marker to it, or,
                # where that collides, at its left end.
                (ends if i in (0, len(group) - 1) else middles).append(
                    [_step_label(ax, r.eps, (1e3 * end, e[i]), style.colour, side, marks=(t[i], e[i]))
                     for side, end in (("right", r.t_max), ("left", r.t_min))])
        ax.set_xscale("log")
        ax.set_yscale("log")
        # Every third decade on the error axis, at most five labelled decades on the time axis (the
        # times are the machine's); no minor ticks (they cost most of the drawing time).
        ax.xaxis.set_major_locator(LogLocator(base=10.0, numticks=5))
        ax.yaxis.set_major_locator(LogLocator(base=1000.0, numticks=9))
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_minor_locator(NullLocator())
        ax.set_xlim(t_lo, t_hi)
        ax.set_ylim(min(_floor(pick(r)) for r in rs) / _Y_ROOM, max(_floor(pick(r)) for r in rs) * _Y_ROOM)
        ax.set_title(name + (", off the crease band" if F.field(name).crease_factors else ""))
        ax.set_ylabel(f"{error} error")
        ax.grid(alpha=0.3, lw=0.3)
        ax.xaxis.set_tick_params(labelbottom=True)          # each panel read alone, scrolled to on a phone
    axes[-1].set_xlabel("time per frame, ms")
    handles = {m: handles[m] for m in ("Pareto front", *(m.name for m in gm.methods())) if m in handles}
    labels = [m if m == "Pareto front" else gm.method(m).label for m in handles]
    legend = _legend(fig, list(handles.values()), labels)
    # The figure grows by the legend's height, so that more methods do not squeeze the panels.
    tall = legend.get_window_extent(FigureCanvasAgg(fig).get_renderer()).height / fig.dpi
    fig.set_figheight(_ROW_IN * len(names) + tall)
    drop_clashing(fig, ends + middles, misplaced=lambda label: misleading(label, markers[label.axes]))
    return fig


def _step_label(ax, eps, at, colour, side, marks):
    """The label "ε = 1e−3" of a difference's marker ``marks`` (time in ms, error) beyond the ``side``
    ("right" or "left") end of its bar, ``at``; the label keeps ``marks`` as its attribute ``marks``."""
    label = ax.annotate(f"\u03b5 = {step_text(eps).replace('-', chr(0x2212))}", at,
                        xytext=(3 if side == "right" else -3, 0), textcoords="offset points",
                        ha="left" if side == "right" else "right", va="center", color=colour)
    label.set_in_layout(False)
    label.marks = marks
    return label


def misleading(label, markers):
    """Whether the drawn ``label`` (a step label of `pareto_figure`, its figure drawn) leaves its panel (it
    would cross the axis line beside the tick labels), or another of ``markers`` [(time in ms, error)] of
    its panel lies nearer to it than the marker it names, ``label.marks``: a reader takes a label for the
    nearest marker's."""
    markers = np.asarray(markers, float)
    xy, own = label.axes.transData.transform(markers), label.axes.transData.transform([label.marks])[0]
    box, panel = label.get_window_extent(), label.axes.bbox
    if box.x0 < panel.x0 or box.x1 > panel.x1 or box.y0 < panel.y0 or box.y1 > panel.y1:
        return True
    def distance(p):
        return np.hypot(np.maximum(0, np.maximum(box.x0 - p[..., 0], p[..., 0] - box.x1)),
                        np.maximum(0, np.maximum(box.y0 - p[..., 1], p[..., 1] - box.y1)))
    others = ~np.all(markers == label.marks, axis=1)                     # the very floats plotted
    return bool(np.any(distance(xy[others]) < distance(own)))


def _fmt_ms(r):
    return f"{1e3 * r.median:,.2f} ({1e3 * r.t_min:,.2f}–{1e3 * r.t_max:,.2f})"       # separated: a slower machine's times run longer


def _fmt_evals(r):
    parts = []
    if r.h_evals:
        parts.append(f"{r.h_evals:.4g} h")
    if r.h_complex_evals:
        parts.append(f"{r.h_complex_evals:.4g} complex h")
    if r.gradient_evals:
        parts.append(f"{r.gradient_evals:.4g} ∇h")
    if r.h_tangent_evals:
        parts.append(f"{r.h_tangent_evals:.4g} h with tangent")
    text = ", ".join(parts) or "0"
    return f"{text} ({r.trig_evals:.4g} sin/cos)" if r.trig_evals else text


def markdown_table(measurement, *, rows="all", error="max", include=()):
    """The measurement as a Markdown table, one row per (field, method).

    Parameters
    ----------
    measurement : lab.gradient_benchmark.Measurement
    rows : {"all", "front", "best"}, keyword-only
        "all": every result; "front": the Pareto front of each field;
        "best": per field, the exact gradient and, of every other method, the
        step with the smallest error (plus any result on the front).
    error : {"max", "rms"}, keyword-only
        The error that defines the front and "best".
    include : sequence of str, keyword-only
        Labels (`lab.gradient_benchmark.MethodResult.label`, e.g. ``"central 1e-03"``) shown in
        every field even when ``rows`` would leave them out.

    Returns
    -------
    str (GitHub-flavoured Markdown; ``|`` inside cells is escaped).

    Raises
    ------
    ValueError
        If ``rows`` is not one of the three choices.
    """
    if rows not in ("all", "front", "best"):
        raise ValueError(f"rows must be 'all', 'front' or 'best', got {rows!r}")
    head = ("field", "method", "evaluations per pixel", "time per frame, ms: median (min–max)",
            "max error", "RMS error", "on the front", "note")
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    key = (lambda r: r.max_error) if error == "max" else (lambda r: r.rms_error)
    for name in dict.fromkeys(r.field for r in measurement.results):
        rs = measurement.of(name)
        front = gb.pareto_front(rs, error=error)
        if rows == "front":
            chosen = list(front)
        elif rows == "best":
            chosen = []
            for method in dict.fromkeys(r.method for r in rs):
                group = [r for r in rs if r.method == method]
                chosen.append(min(group, key=key))
        else:
            chosen = list(rs)
        for r in front + [r for r in rs if r.label in include]:
            if r not in chosen:
                chosen.append(r)
        chosen.sort(key=rs.index)
        for r in chosen:
            cells = (name, r.label, _fmt_evals(r), _fmt_ms(r), f"{r.max_error:.2e}", f"{r.rms_error:.2e}",
                     "yes" if r in front else "", r.note)
            lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(lines)


def share_in_words(count, total):
    """``count`` of ``total`` as prose says it: "all three", "two of the three", "none of the three".

    Raises
    ------
    ValueError
        If ``count`` and ``total`` are not integers with 0 <= count <= total, 1 <= total <= 10.
    """
    if not (isinstance(count, (int, np.integer)) and isinstance(total, (int, np.integer))
            and 1 <= total <= 10 and 0 <= count <= total):
        raise ValueError(f"count and total must be integers with 0 <= count <= total <= 10 and total >= 1, "
                         f"got count={count!r}, total={total!r}")
    whole = "both" if total == 2 else f"all {_NUMBER_WORDS[total]}"
    return whole if count == total else f"{_NUMBER_WORDS[count]} of the {_NUMBER_WORDS[total]}"


#: A method is called the fastest on a field only when every other method's median time is at least this
#: factor of its own: closer medians are a tie that the machine's noise decides (on rings the exact gradient
#: and forward-mode AD differ by about 1 %, and which one "won" changed from build to build).
FASTEST_MARGIN = 1.1


def fastest_on(measurement, method="exact", margin=FASTEST_MARGIN):
    """On which fields ``method`` is the fastest by ``margin``: every other method's median time at
    least ``margin`` times its own; in words, their count (`share_in_words`) and, when some but not
    all, their names: "two of the three fields (sine and ridges)", "all three fields".

    Parameters
    ----------
    measurement : lab.gradient_benchmark.Measurement
    method : str
        A method's name as the measurement's rows carry it.
    margin : float >= 1

    Returns
    -------
    str
    """
    fields = list(dict.fromkeys(r.field for r in measurement.results))
    wins = []
    for f in fields:
        own = [r.median for r in measurement.of(f) if r.method == method]
        others = [r.median for r in measurement.of(f) if r.method != method]
        if own and all(o >= margin * min(own) for o in others):
            wins.append(f)
    words = f"{share_in_words(len(wins), len(fields))} fields"
    return words + (f" ({_and(wins)})" if 0 < len(wins) < len(fields) else "")


def step_text(eps):
    """A step as the book writes a power of ten: ``1e-3``, ``3.2e-6`` (``1e-03``'s zero dropped)."""
    mantissa, exponent = f"{eps:.1e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".")
    return f"{mantissa}e{int(exponent)}"


def _and(items):
    items = list(items)
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def methods_sentence(config, fields=None):
    """The sentence (MyST) naming every method of `lab.gradient_methods.METHODS` the benchmark runs:
    its label, its sources (a citation), its steps in ``config`` and, where it does not apply to
    every field, the fields it runs on.

    Parameters
    ----------
    config : lab.gradient_benchmark.Config
    fields : sequence of height fields or None
        As `renderer.formulas.field` takes them; None for every registered field.

    Returns
    -------
    str
    """
    records = [F.field(f) for f in (tuple(F.FIELDS) if fields is None else fields)]
    parts = []
    for m in gm.methods():
        text = m.label + (f" {{cite:p}}`{','.join(m.sources)}`" if m.sources else "")
        steps = m.steps_in(config)
        if steps != (None,):
            text += " at ε = " + _and([step_text(e) for e in steps])
        where = [f.name for f in records if m.applies(f)]
        if len(where) < len(records):
            text += " (on " + _and(where) + ")"
        parts.append(text)
    count = _NUMBER_WORDS[len(parts)] if len(parts) < len(_NUMBER_WORDS) else str(len(parts))
    return f"{count.capitalize()} methods, each a record of `lab.gradient_methods.METHODS`: " + "; ".join(parts) + "."


def univariate_figure(errors):
    """Relative error of f'(x) against the step, log-log, one line per method of ``errors`` (a
    `lab.gradient_benchmark.UnivariateErrors`), the step growing to the right; a method without a step
    is a horizontal line across; hollow markers, so that two methods with equal errors both show.
    Drawn for a phone's column: 4.6 in wide, every text at `chapter.figures.TEXT_PT`.  An error of exactly 0 would be drawn at
    1e-18.  Returns a matplotlib Figure (not shown)."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import LogLocator, NullLocator
    fig = Figure(figsize=(4.6, 2.6), layout="constrained")
    ax = fig.subplots()
    steps = [r.eps for r in errors.rows if r.eps is not None]
    for name in dict.fromkeys(r.method for r in errors.rows):
        m, rows = gm.method(name), errors.of(name)
        style = m.style
        if rows[0].eps is None:
            ax.axhline(_floor(rows[0].relative_error), color=style.colour, ls=style.line, lw=1.4, label=m.label)
        else:
            ax.plot([r.eps for r in rows], [_floor(r.relative_error) for r in rows], color=style.colour,
                    ls=style.line, lw=1.2, marker=style.marker, ms=min(style.size, 6), mfc="none", label=m.label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(min(steps) / 3, max(steps) * 3)          # the step grows to the right, as in every U-curve here
    ax.xaxis.set_major_locator(LogLocator(base=10.0 ** 4, numticks=8))
    ax.yaxis.set_major_locator(LogLocator(base=10.0 ** 4, numticks=8))
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_minor_locator(NullLocator())
    ax.set_xlabel("step")
    ax.set_ylabel("relative error of f′(x)")
    ax.grid(alpha=0.3, lw=0.3)
    _legend(fig, *ax.get_legend_handles_labels())
    return fig


def univariate_table(errors):
    """A Markdown table of ``errors`` (`lab.gradient_benchmark.UnivariateErrors`): per method its best
    step (the one of least error; "adaptive" or "none" for a method without one) and the relative
    error there."""
    lines = ["| method | best step | relative error there |", "|---|---|---|"]
    for name in dict.fromkeys(r.method for r in errors.rows):
        best = errors.best(name)
        where = step_text(best.eps) if best.eps is not None else ("adaptive" if name in errors.evaluations
                                                                   else "none")
        lines.append(f"| {gm.method(name).label} | {where} | {best.relative_error:.1e} |")
    return "\n".join(lines)


def published_table(published):
    """A Markdown table of what papers report (`lab.gradient_benchmark.PUBLISHED`): the method (its label),
    the source (a citation) with where it says it, and the statement (with its number where it has one)."""
    lines = ["| method | source | what it reports |", "|---|---|---|"]
    for p in published:
        label = "the test" if p.method is None else gm.method(p.method).label
        value = "" if p.value is None else f" ({p.value:.3g})"
        lines.append(f"| {label} | {{cite:t}}`{p.source}`, {p.where} | {p.statement}{value} |")
    return "\n".join(lines)
