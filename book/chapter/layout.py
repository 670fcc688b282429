"""What of a book figure collides when it is drawn, and how small its text is drawn.

`text_overlaps` lists the collisions `chapter.page.show` refuses before a page
publishes a figure: two texts, a text and a legend, a text and another axes'
plotting area, an annotation and its axes' frame, and a line or patch of the
data through a label.  `drawn_size` is the smallest glyph a text draws (a
mathtext sub- or superscript at its drawn size), which `chapter.figures.figure_png`
records in the PNG for the browser test of the figures' text on a phone, and
`drawn_texts` the texts a drawing of the figure draws.
"""

from __future__ import annotations

__all__ = ["drawn_size", "drawn_texts", "text_overlaps", "drop_clashing"]

#: The least clear space between a label and a line of the data, in points, beyond the line's half width.
CLEARANCE = 1.0


def drawn_size(text):
    """The smallest font size, in points, at which ``text`` draws a glyph: its font size, or, for a
    line of mathtext (``$...$``), the size of its smallest glyph (a sub- or superscript is drawn at
    0.7 of its base, a script of a script at 0.49; matplotlib's mathtext layout, as it draws it).

    Parameters
    ----------
    text : matplotlib.text.Text

    Returns
    -------
    float
        Points; ``text.get_fontsize()`` for a text with no mathtext or no glyph.

    Raises
    ------
    TypeError
        ``text`` is not a matplotlib Text.
    """
    from matplotlib.cbook import is_math_text
    from matplotlib.mathtext import MathTextParser
    from matplotlib.text import Text
    if not isinstance(text, Text):
        raise TypeError(f"text must be a matplotlib.text.Text, got {type(text).__name__}")
    sizes = [text.get_fontsize()]
    if text.get_parse_math() and not text.get_usetex():
        for line in text.get_text().split("\n"):
            if is_math_text(line):
                glyphs = MathTextParser("path").parse(line, 72, text.get_fontproperties()).glyphs
                sizes += [g[1] for g in glyphs]
    return float(min(sizes))


def drawn_texts(fig):
    """The text artists of ``fig`` that drawing it draws (visible, not blank, not transparent), in
    drawing order; ``fig`` is drawn once, with an Agg canvas if it has none (a closed pyplot figure).
    Only a drawing tells which are drawn (ticks out of view keep labels that are not) and where
    (layout engines move them)."""
    from matplotlib.text import Text
    if not hasattr(fig.canvas, "get_renderer"):      # a closed pyplot figure keeps a bare canvas
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        FigureCanvasAgg(fig)
    drawn, draw = [], Text.draw

    def recording(text, renderer):
        draw(text, renderer)
        if text.get_visible() and text.get_text().strip() and (text.get_alpha() is None or text.get_alpha() > 0):
            drawn.append(text)
    Text.draw = recording
    try:
        fig.canvas.draw()
    finally:
        Text.draw = draw
    return drawn


def text_overlaps(fig, gap=0.5):
    """What of ``fig``'s text collides when it is drawn, as strings (an empty list when nothing does).

    Every text artist matplotlib draws is a candidate: titles, suptitles, axis
    labels, tick labels (of the ticks in view only), offset texts, legend entries
    and titles, annotations and free text, in every axes of the figure.  It
    reports

    * two texts whose boxes overlap, or two texts of different axes side by side
      on one line with less than ``gap`` times the smaller font size between
      them (tick labels of neighbouring axes that read as one number):
      ``'a' / 'b'``;
    * a text overlapping a framed legend it is not part of (a legend's own
      entries sit inside its box by design, but two of them may not overlap):
      ``'a' / legend``;
    * a text drawn into the plotting area of another axes than its own (a
      y label on the neighbouring image): ``'a' / axes 'title'``.  Axes whose
      boxes overlap (twins, insets) are not each other's "other" axes;
    * a text or annotation placed in an axes with a frame that straddles the
      frame: ``'a' / the frame of its axes``;
    * a text or legend entry in an axes that a line of that axes' data (a Line2D, or a
      LineCollection's segment: hlines, vlines) comes within `CLEARANCE` of, or that one of its
      patches (a bar, a span) covers,
      unless an opaque box drawn above the line hides it (`chapter.figures.MASK`):
      ``'a' / the data's line 'b'`` (its label, if it has one; a line drawn as
      markers only counts where a marker falls).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        Drawn once here (at ``fig.dpi``), with an Agg canvas if it has none
        (a closed pyplot figure).
    gap : float >= 0
        Least clear space between two texts of different axes on one line, in
        units of the smaller one's font size.

    Raises
    ------
    TypeError
        ``fig`` is not a Figure.
    ValueError
        ``gap`` is negative or not finite.
    """
    return [message for _, message in _clashes(fig, gap)]


def drop_clashing(fig, labels, gap=0.5, misplaced=None):
    """Remove from ``fig`` the optional ``labels`` that `text_overlaps` would report: in order of
    importance, each label keeps its first placement that collides with nothing but labels not kept,
    or, where only one kept label's placement stands in its way, that label moves to another of its
    placements if it can, to make room.  A placement for which ``misplaced`` (a function of the
    Text, called once the figure is drawn) is true counts as colliding.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        Drawn once here (see `text_overlaps`), every placement shown; give the labels
        ``set_in_layout(False)`` so that removing them moves nothing else.
    labels : sequence of matplotlib.text.Text, or of sequences of them
        Optional labels of ``fig``, the most important first; a sequence holds one label's
        placements, the preferred first.
    gap : float >= 0
        As in `text_overlaps`.
    misplaced : callable or None
        Text -> bool: a placement that would mislead where it stands (beside another's marker, say).

    Returns
    -------
    list of matplotlib.text.Text
        The placements kept, at most one per label, in the order given.

    Raises
    ------
    TypeError, ValueError
        As `text_overlaps`.
    """
    from matplotlib.text import Text
    options = [(item,) if isinstance(item, Text) else tuple(item) for item in labels]
    ours = {id(t) for placements in options for t in placements}
    bad, near = set(), {}                          # clashing with what stays; clashing with another label
    for texts, _ in _clashes(fig, gap):
        mine = [t for t in texts if id(t) in ours]
        if len(mine) < len(texts) or len(mine) == 1:
            bad.update(id(t) for t in mine)
        else:
            a, b = mine
            near.setdefault(id(a), set()).add(id(b))
            near.setdefault(id(b), set()).add(id(a))
    bad.update(id(t) for placements in options for t in placements if misplaced is not None and misplaced(t))
    def free(t, kept):                               # t collides with nothing that stays, nor a kept label
        return id(t) not in bad and not near.get(id(t), set()) & {id(k) for k in kept if k is not None}
    kept = []
    for placements in options:
        choice = next((t for t in placements if free(t, kept)), None)
        for t in placements if choice is None else ():
            blocking = [i for i, k in enumerate(kept) if k is not None and id(k) in near.get(id(t), set())]
            if id(t) in bad or len(blocking) != 1:
                continue
            i = blocking[0]
            others = kept[:i] + kept[i + 1:] + [t]
            move = next((m for m in options[i] if m is not kept[i] and free(m, others)), None)
            if move is not None:
                kept[i], choice = move, t
                break
        kept.append(choice)
    kept = [t for t in kept if t is not None]
    for placements in options:
        for t in placements:
            if t not in kept:
                t.remove()
    return kept


def _clashes(fig, gap):
    """`text_overlaps`' findings as (the texts involved, the message)."""
    import math

    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure
    from matplotlib.legend import Legend
    from matplotlib.text import Text
    if not isinstance(fig, Figure):
        raise TypeError(f"fig must be a matplotlib.figure.Figure, got {type(fig).__name__}")
    if not (isinstance(gap, (int, float)) and math.isfinite(gap) and gap >= 0):
        raise ValueError(f"gap must be a finite number >= 0 (font sizes), got {gap!r}")
    drawn = drawn_texts(fig)
    renderer = fig.canvas.get_renderer()
    px = fig.dpi / 72                                       # pixels per point
    boxes = [t.get_window_extent(renderer) for t in drawn]
    axes = [ax for ax in fig.axes if ax.get_visible()]
    owner = {id(t): ax for ax in axes for t in ax.findobj(Text)}
    name = lambda t: repr(t.get_text())                      # noqa: E731
    out = []
    for i, (a, ba) in enumerate(zip(drawn, boxes)):
        for b, bb in zip(drawn[i + 1:], boxes[i + 1:]):
            across = min(ba.x1, bb.x1) - max(ba.x0, bb.x0)      # > 0: the boxes share columns
            down = min(ba.y1, bb.y1) - max(ba.y0, bb.y0)        # > 0: the boxes share rows
            room = gap * min(a.get_fontsize(), b.get_fontsize()) * px
            if (across > 0 and down > 0) or (owner.get(id(a)) is not owner.get(id(b))
                                                 and down > 0.5 * min(ba.height, bb.height) and across > -room):
                out.append(((a, b), f"{name(a)} / {name(b)}"))
    legends = [lg for lg in fig.findobj(Legend) if lg.get_visible() and lg.get_frame_on()]
    for lg in legends:
        own = {id(t) for t in lg.findobj(Text)}
        frame = lg.get_window_extent(renderer)
        out += [((t,), f"{name(t)} / legend") for t, bt in zip(drawn, boxes) if id(t) not in own and frame.overlaps(bt)]
    for ax in axes:
        legend = ax.get_legend()
        own = {id(t) for t in ax.texts + (legend.get_texts() if legend is not None else [])}
        data = [a for a in [*ax.lines, *ax.patches, *(c for c in ax.collections if isinstance(c, LineCollection))]
                if a.get_visible()]
        for t in (t for t in drawn if id(t) in own):                # its labels and legend entries, as drawn
            bt, box = Text.get_window_extent(t, renderer), t.get_bbox_patch()     # an annotation's text, not its arrow
            masked = box is not None and box.get_visible() and box.get_facecolor()[3] == 1
            out += list(dict.fromkeys(((t,), f"{name(t)} / the data's {_kind(a)}") for a in data
                                      if _crosses(a, bt, renderer) and not (masked and t.get_zorder() > a.get_zorder())))
    for t, bt in zip(drawn, boxes):
        home = owner.get(id(t))
        if home is not None and home.axison and t in home.texts:
            frame = home.get_window_extent(renderer)
            inside = frame.padded(1)
            if bt.padded(-1).overlaps(frame) and not (inside.contains(bt.x0, bt.y0) and inside.contains(bt.x1, bt.y1)):
                out.append(((t,), f"{name(t)} / the frame of its axes"))
        for ax in axes:
            area = ax.get_window_extent(renderer)
            if ax is home or (home is not None and home.get_window_extent(renderer).overlaps(area)):
                continue
            if bt.padded(-1).overlaps(area):
                label = ax.get_title() or f"{fig.axes.index(ax) + 1} of {len(fig.axes)}"
                out.append(((t,), f"{name(t)} / axes {label!r}"))
    return out


def _kind(artist):
    """'line' (a Line2D or a LineCollection) or 'patch', and the artist's label if it has one: "line 'fitted'"."""
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D
    label = artist.get_label()
    return ("line" if isinstance(artist, (Line2D, LineCollection)) else "patch") + ("" if label.startswith("_") or not label
                                                                   else f" {label!r}")


def _crosses(artist, box, renderer):
    """Whether a Line2D as drawn (its path's stroke, or its markers if it draws no line), or a segment of
    a LineCollection (hlines, vlines), comes within `CLEARANCE` of ``box`` (display units), or a patch
    meets it."""
    from matplotlib.collections import LineCollection
    from matplotlib.lines import Line2D
    if isinstance(artist, LineCollection):
        to_display = artist.get_transform()
        widths = artist.get_linewidths()
        pad = renderer.points_to_pixels((max(widths) if len(widths) else 1.0) / 2 + CLEARANCE)
        return any(to_display.transform_path(p).intersects_bbox(box.padded(pad), filled=False)
                   for p in artist.get_paths())
    if not isinstance(artist, Line2D):
        return artist.get_window_extent(renderer).overlaps(box)
    path = artist.get_transform().transform_path(artist.get_path())
    if artist.get_linestyle() in ("None", "", " ", "none"):
        box = box.padded(renderer.points_to_pixels(artist.get_markersize() / 2 + CLEARANCE))
        return any(box.contains(x, y) for x, y in path.vertices)
    return path.intersects_bbox(box.padded(renderer.points_to_pixels(artist.get_linewidth() / 2 + CLEARANCE)),
                                filled=False)
