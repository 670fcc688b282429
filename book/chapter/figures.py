"""The book's figure style and its explanatory diagrams, drawn when the book is built.

`style` sets matplotlib for every figure of the book: PNG at twice the CSS
size (for high-density screens), mathematical labels in mathtext, and no
creation date in the file, so that a rebuild writes the same bytes; log axes
labelled in plain numbers (``1e-6``, `PlainLogFormatter`: mathtext's ``10^{-6}``
draws its exponent at 70 % of the label's size); inside IPython a figure is
displayed as `figure_png` makes it, which records in the PNG the smallest text
size the figure draws, sub- and superscripts at their drawn size (for the
browser test of the figures' text on a phone).  The
diagrams draw what the text asks the reader to picture, from the renderer's
own functions (`renderer.pointwise`, generated from `renderer.formulas`):

* `frame_diagram`: sphere A with its chart's meridians and parallels and the
  tangent frame (e_theta, e_phi) and normal N at one point;
* `normal_diagram`: the perturbed normal of both bump modes at one point of a
  bumped meridian, beside the normal of the displaced curve itself;
* `stencil_diagram`: the central-difference stencil straddling a crease of the
  ridges field, its secant, and the two one-sided slopes;
* `ucurve_anatomy` (in §3, on the measured curve): the regions of the U-curve, its
  slope guides +2 and -1, the model-optimal and the fitted optimal steps.

Each returns a matplotlib Figure (the caller glues and closes it).

What of a figure collides, and how small its text is drawn, is `chapter.layout`'s.
"""

from __future__ import annotations

import io
import math

import numpy as np
from matplotlib.scale import LogScale
from matplotlib.ticker import LogFormatter

from renderer import Scene, pointwise
from renderer.render import SPHERE_A

from .layout import drawn_size, drawn_texts

__all__ = ["style", "figure_png", "PlainLogFormatter", "SMALLEST_TEXT_KEY", "MASK", "frame_diagram", "normal_diagram",
           "stencil_diagram", "ucurve_anatomy", "displacement_figure", "difference_bar", "chamber_colours"]

#: The book's colours: measured (dark red), exact (dark blue), third quantity (green), guides (grey).
RED, BLUE, GREEN, GREY = "#7a1f1f", "#1f4e7a", "#2a7a1f", "#777777"


def chamber_colours():
    """A chamber map's colours: (ListedColormap indexed by chamber code, {code: colour}); draw the map
    with ``vmin=0, vmax=len(colours) - 1``.  The codes are `renderer.render.CHAMBER_NAMES`'."""
    from matplotlib.colors import ListedColormap

    from renderer.render import BACKGROUND, FLOOR, SPHERE_B
    colours = {BACKGROUND: "black", SPHERE_A: "#a33", SPHERE_B: "#58c", FLOOR: "#ccb"}
    return ListedColormap([colours[c] for c in sorted(colours)]), colours


#: The PNG text chunk (tEXt) in which `figure_png` records the smallest size of a figure's drawn
#: glyphs (`drawn_size`), in the PNG's pixels ("none": the figure draws no text); the browser test of the built pages
#: turns it into CSS pixels at the width each image is shown.
SMALLEST_TEXT_KEY = "symrender:smallest-text-px"

#: The size of every text in the book's figures, in points (`style`).  A figure shown in a phone's column
#: (342 CSS px at 390 px, 323 in a dropdown) is scaled to it, and its text with it: text of ``pt`` points
#: on a figure ``w`` inches wide is then ``pt * 342 / (72 * w)`` CSS px, at least 10 (tests/test_book_pages.py)
#: when ``pt / w`` is at least 2.1: 11 pt on the book's figures, at most 5.2 in wide with what sticks out
#: (4.9 in a dropdown).  A sub- or superscript is drawn at 70 %: none in the figures' text but the frame
#: diagram's labels, drawn larger.
TEXT_PT = 11.0

#: The box behind a label written over a diagram's lines (``ax.text(..., bbox=MASK)``): the page's white,
#: so that no line runs through the letters (`chapter.layout.text_overlaps` lets such a label lie on the lines it hides).
MASK = dict(boxstyle="square,pad=0.1", facecolor="white", edgecolor="none")

#: How far above the fitted model's arm `ucurve_anatomy` draws each slope guide (a factor in error).
GUIDE_OFFSET = 30.0


def style():
    """Set matplotlib (and, inside IPython, the inline backend) for the book's figures: log axes
    labelled by `PlainLogFormatter` (every ``set_xscale("log")``, ``loglog`` ... of the session);
    a Figure displayed in IPython becomes `figure_png`'s PNG."""
    import matplotlib as mpl
    from matplotlib.scale import register_scale
    mpl.rcParams.update({**{key: TEXT_PT for key in ("font.size", "axes.titlesize", "axes.labelsize", "xtick.labelsize",
                                                     "ytick.labelsize", "legend.fontsize", "legend.title_fontsize",
                                                     "figure.titlesize")},
                         "savefig.bbox": "tight", "svg.hashsalt": "symrender", "image.interpolation": "nearest"})
    register_scale(_PlainLogScale)
    try:
        from IPython.core.interactiveshell import InteractiveShell
        from matplotlib.figure import Figure
        from matplotlib_inline.backend_inline import set_matplotlib_formats
        set_matplotlib_formats("retina", metadata={"Software": None})
        if InteractiveShell.initialized():
            InteractiveShell.instance().display_formatter.formatters["image/png"].for_type(Figure, figure_png)
    except (ImportError, AttributeError, NameError):
        pass                                            # outside IPython: nothing to configure


def difference_bar(fig, ax, *, gain=None, log_floor=None, location="right"):
    """A grey colour bar for difference images drawn on ``ax`` (one axes or a list of them) of ``fig``:
    each channel's |ΔI| (linear colour units) from black to white, linearly from 0 to 1 / ``gain``
    (an image of ``gain`` |ΔI| clipped at 1: the bar's triangle marks the clipping, its label says that its values
    are |ΔI| itself, drawn times the gain) or, with
    ``log_floor``, logarithmically from ``log_floor`` to 1 (an image of 1 - log10 |ΔI| / log10
    ``log_floor``, as the simulator draws it).  Pass exactly one of them.  ``location``: matplotlib's
    (beside the axes, "right", or under them, "bottom").  Returns the Colorbar.

    Raises ValueError naming ``gain`` / ``log_floor`` when not exactly one is a positive number
    (``log_floor`` < 1)."""
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import LogNorm, Normalize
    if (gain is None) == (log_floor is None):
        raise ValueError(f"pass exactly one of gain and log_floor, got gain={gain!r}, log_floor={log_floor!r}")
    if gain is not None and not gain > 0:
        raise ValueError(f"gain must be a positive number, got {gain!r}")
    if log_floor is not None and not 0 < log_floor < 1:
        raise ValueError(f"log_floor must be a number in (0, 1), got {log_floor!r}")
    norm = Normalize(0.0, 1.0 / gain) if gain else LogNorm(log_floor, 1.0)
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap="gray"), ax=ax, shrink=0.8, aspect=16 if location == "right" else 24,
                       extend="max" if gain else "neither", location=location)
    if gain:                      # 0, half way and the clipping value, in the book's plain numbers
        bar.set_ticks([0.0, 0.5 / gain, 1.0 / gain], labels=[f"{x:g}" for x in (0.0, 0.5 / gain, 1.0 / gain)])
    if log_floor:                 # every fourth decade, written plainly (colorbar's default is mathtext's 10^-16)
        bar.set_ticks([10.0**k for k in range(0, math.floor(math.log10(log_floor)) - 1, -4)])
        bar.ax.xaxis.set_major_formatter(PlainLogFormatter())
        bar.ax.yaxis.set_major_formatter(PlainLogFormatter())
        bar.ax.minorticks_off()
    bar.set_label("|ΔI| per channel" + (f" (drawn × {gain:g})" if gain else ""))     # the bar's values, not the image's
    return bar


class PlainLogFormatter(LogFormatter):
    """Log-axis tick labels as plain numbers, every character at the label's size, one notation per
    axis: decimals (``0.01`` to ``1000``) on an axis whose view lies within [0.01, 1e4], else
    ``1e-6``, ``1e-2``, ``2e5`` throughout but for ``1`` (matplotlib's default, mathtext's
    ``10^{-6}``, draws the exponent at 70 % of the label's size: 6-7 CSS px on a phone)."""

    def _num_to_string(self, x, vmin, vmax):
        if x == 1 or 1e-2 <= min(vmin, vmax) and max(vmin, vmax) <= 1e4:
            return f"{x:g}"
        mantissa, exponent = f"{x:.0e}".split("e")
        return f"{mantissa}e{int(exponent)}"


class _PlainLogScale(LogScale):
    """The "log" scale with `PlainLogFormatter` on its major and minor ticks (`style` registers it)."""

    def __init__(self, *, base=10, subs=None, nonpositive="clip"):     # no axis: matplotlib >= 3.11's form
        super().__init__(base=base, subs=subs, nonpositive=nonpositive)

    def set_default_locators_and_formatters(self, axis):
        super().set_default_locators_and_formatters(axis)
        axis.set_major_formatter(PlainLogFormatter())
        axis.set_minor_formatter(PlainLogFormatter(labelOnlyBase=self.subs is not None))


def figure_png(fig):
    """``fig`` as the book's PNG, the way IPython's "retina" format makes it (drawn at twice
    ``fig.dpi``: two device pixels per CSS pixel; cropped to its content), without a software
    name, and with the smallest size of its drawn glyphs recorded under `SMALLEST_TEXT_KEY`.

    Parameters
    ----------
    fig : matplotlib.figure.Figure

    Returns
    -------
    (bytes, dict) or None
        The PNG file, and {"width": w, "height": h}, its size in CSS pixels (half its pixels;
        IPython's image metadata); None for a figure with nothing in it, as IPython's own
        formatter.  The chunk holds the smallest glyph size drawn (`drawn_size` of every
        text drawn: titles, labels, tick labels in view, legend entries, annotations; a
        mathtext superscript at its drawn 70 %), in the PNG's pixels (``2 * dpi / 72`` per point), as a decimal with two places, or "none" when
        the figure draws no text.

    Raises
    ------
    TypeError
        ``fig`` is not a Figure.
    """
    from IPython.core.pylabtools import print_figure
    from matplotlib.figure import Figure
    from PIL import Image
    if not isinstance(fig, Figure):
        raise TypeError(f"fig must be a matplotlib.figure.Figure, got {type(fig).__name__}")
    sizes = [drawn_size(t) * 2 * fig.dpi / 72 for t in drawn_texts(fig)]
    smallest = f"{min(sizes):.2f}" if sizes else "none"
    png = print_figure(fig, "retina", metadata={"Software": None, SMALLEST_TEXT_KEY: smallest})
    if png is None:
        return None
    width, height = Image.open(io.BytesIO(png)).size
    return png, {"width": width // 2, "height": height // 2}


def _sphere_point(theta, phi):
    return np.array([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)])


def frame_diagram(theta=-0.35, phi=0.8):
    """Sphere A (unit radius) seen obliquely: lines of constant u (meridians) and v (parallels)
    of the renderer's chart, and at N(theta, phi) the normal and the tangent frame the
    renderer computes there (`pointwise.tangent_frame`)."""
    import matplotlib.pyplot as plt
    toward = np.array([1.0, 0.35, 0.55]) / np.linalg.norm([1.0, 0.35, 0.55])   # towards the viewer
    right = np.cross([0.0, 0.0, 1.0], toward)
    right /= np.linalg.norm(right)
    view = np.array([right, np.cross(toward, right)])                # an oblique orthographic view
    depth = toward

    def project(p):
        return view @ p

    fig, ax = plt.subplots(figsize=(4.0, 4.0))
    t = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(t), np.sin(t), color=GREY, lw=1)
    for k in range(12):                                               # meridians: u = k / 12
        th = 2 * np.pi * k / 12 - np.pi
        pts = np.array([_sphere_point(th, p) for p in np.linspace(0, np.pi, 60)])
        front = pts @ depth > 0
        xy = pts @ view.T
        ax.plot(np.where(front, xy[:, 0], np.nan), np.where(front, xy[:, 1], np.nan), color=BLUE, lw=0.6, alpha=0.6)
    for k in range(1, 6):                                             # parallels: v = k / 6
        ph = np.pi * k / 6
        pts = np.array([_sphere_point(th, ph) for th in np.linspace(-np.pi, np.pi, 120)])
        front = pts @ depth > 0
        xy = pts @ view.T
        ax.plot(np.where(front, xy[:, 0], np.nan), np.where(front, xy[:, 1], np.nan), color=GREEN, lw=0.6, alpha=0.6)
    N = _sphere_point(theta, phi)
    sin_phi = pointwise.chart(*N)[2]
    e_t, e_p = (np.array(v, float).ravel() for v in pointwise.tangent_frame(N[0], N[1], N[2], sin_phi))
    base = project(N)
    for vec, colour, label in ((N, RED, r"$N$"), (e_t, BLUE, r"$e_\theta$ (along $u$)"),
                               (e_p, GREEN, r"$e_\varphi$ (along $v$)")):
        tip = project(N + 0.45 * vec)
        ax.annotate("", tip, base, arrowprops=dict(arrowstyle="-|>", color=colour, lw=1.8))
        way = (tip - base) / max(np.linalg.norm(tip - base), 1e-9)
        side = lambda d, names: names[0] if d < -0.3 else names[2] if d > 0.3 else names[1]    # noqa: E731
        ax.text(*(tip + 0.04 * way), label, color=colour, fontsize=12.5, bbox=MASK,   # subscript: 0.7 x 12.5 = 8.75 pt
                ha=side(way[0], ("right", "center", "left")), va=side(way[1], ("top", "center", "bottom")))  # past the tip
    ax.plot(*project(_sphere_point(0.0, 0.0)), "o", color="k", ms=3)
    ax.text(*(project(_sphere_point(0.0, 0.0)) + [0.03, 0.03]), r"pole $\varphi = 0$", bbox=MASK)
    ax.set_aspect("equal"); ax.axis("off")
    ax.set_title(r"lines of constant $u = (\theta + \pi)/2\pi$ and $v = \varphi/\pi$")
    return fig


#: The amplitude of Fig. 2's bump (§1), below the book's default so that the displaced curve stays near the arc.
NORMALS_BETA = 0.08


def normal_diagram(field="rings", beta=NORMALS_BETA, theta=0.4, phi0=3 * np.pi / 8, span=0.4, count=9):
    """What a bump does, in one meridian of sphere A (theta fixed): the sphere (solid) keeps its
    shape, while the shading normals drawn on it follow the sphere displaced to (R + beta h) N
    (dashed).  At ``count`` points of the sphere, the displaced sphere's normal (the sympy object
    `formulas.PERTURBED_NORMAL["surface"]`, fed the frame and gradient `pointwise` computes
    there); at the middle point also the unbumped N and the draft's normal (``["chart"]``), and,
    at the displaced point above it, the displaced curve's own normal.  With the rings field
    (h_u = 0) every vector lies in the meridian's plane."""
    import matplotlib.pyplot as plt
    import sympy as sp

    from renderer import formulas as F
    scene = Scene(height_field=field, beta=beta)
    r0 = scene.radius_a
    phis = np.linspace(phi0 - span, phi0 + span, 400)
    u, v, _ = pointwise.chart(*np.array([_sphere_point(theta, p) for p in phis]).T)      # the chart's (u, v)
    h = pointwise.height(field, u, v, scene.k_u, scene.k_v)
    base = np.stack([r0 * np.sin(phis), r0 * np.cos(phis)], axis=-1)       # x along the meridian's plane, z up
    bumped = np.stack([(r0 + beta * h) * np.sin(phis), (r0 + beta * h) * np.cos(phis)], axis=-1)
    in_plane = np.array([[np.cos(theta), np.sin(theta), 0.0], [0.0, 0.0, 1.0]])
    normal = {mode: sp.lambdify([F.N_x, F.N_y, F.N_z, *F.e_theta, *F.e_phi, F.h_u, F.h_v, F.beta, F.h, F.R,
                                 F.sin_phi], sp.Matrix(F.PERTURBED_NORMAL[mode]), "numpy")
              for mode in ("chart", "surface")}

    def shading(mode, phi):
        N3 = _sphere_point(theta, phi)
        u_at, v_at, sin_phi = (float(np.ravel(c)[0]) for c in pointwise.chart(*N3))
        e_t, e_p = (np.array(x, float).ravel() for x in pointwise.tangent_frame(N3[0], N3[1], N3[2], sin_phi))
        hu, hv = (float(np.asarray(g).ravel()[0]) for g in pointwise.exact_gradient(field, u_at, v_at, scene.k_u, scene.k_v))
        hh = float(pointwise.height(field, u_at, v_at, scene.k_u, scene.k_v))
        return in_plane @ np.array(normal[mode](*N3, *e_t, *e_p, hu, hv, beta, hh, r0, sin_phi), float).ravel()

    fig, ax = plt.subplots(figsize=(4.2, 5.4))          # for a phone's column: text at TEXT_PT, 2.1 pt per inch or more
    ax.plot(*base.T, color=GREY, lw=1.5)
    ax.plot(*bumped.T, color=GREY, lw=1.0, ls="--")
    length = 0.22

    def arrow(at, vec, colour, lw=1.4):
        tip = at + length * vec / np.linalg.norm(vec)
        ax.plot(*np.array([at, tip]).T, alpha=0.0)          # keeps the arrow inside the axes' limits
        ax.annotate("", tip, at, arrowprops=dict(arrowstyle="-|>", color=colour, lw=lw))

    for phi in np.linspace(phi0 - 0.85 * span, phi0 + 0.85 * span, count):
        arrow(r0 * np.array([np.sin(phi), np.cos(phi)]), shading("surface", phi), BLUE)
    mid = len(phis) // 2
    arrow(base[mid], shading("surface", phis[mid]), BLUE, lw=3.5)     # wide, under the displaced curve's normal
    at = base[mid]
    arrow(at, in_plane @ _sphere_point(theta, phis[mid]), "black")     # not grey: the geometry is grey
    arrow(at, shading("chart", phis[mid]), RED)
    tangent = np.gradient(bumped, axis=0)[mid]
    own = np.array([tangent[1], -tangent[0]]) * np.sign(np.array([tangent[1], -tangent[0]]) @ bumped[mid])
    arrow(bumped[mid], own, GREEN, lw=1.0)
    handles = [plt.Line2D([], [], color=c, lw=lw, ls=ls) for c, lw, ls in
               ((GREY, 1.5, "-"), (GREY, 1.0, "--"), (BLUE, 1.4, "-"), (GREEN, 1.0, "-"), (RED, 1.4, "-"), ("black", 1.4, "-"))]
    ax.legend(handles, ["sphere A: the geometry, unchanged", r"the sphere displaced by $\beta h$",
                        "shading normal: the displaced sphere's", "the displaced curve's own normal",
                        "the draft's formula", r"$N$, no bump"],
              loc="upper center", bbox_to_anchor=(0.5, -0.01), ncols=1, frameon=False)
    ax.set_aspect("equal"); ax.axis("off")
    ax.set_title(rf"one meridian, {field} field, $\beta = {beta:g}$")
    return fig


def stencil_diagram(k_u=None, v=None, k_v=None, eps=0.02, offset=0.006):
    """h along u across the crease u = 1/k_u of the ridges field, the central stencil
    u0 +- eps with its centre u0 just beside the crease, its secant (the central difference),
    and the exact one-sided slope at u0 (`pointwise.height`, `pointwise.central_gradient`,
    `pointwise.exact_gradient`).  ``k_u``, ``k_v`` None: the draft's; ``v`` None: the seed's point's."""
    import matplotlib.pyplot as plt

    from renderer import DRAFT_SCENE
    from renderer.formulas import SEED_POINT
    k_u, k_v = (DRAFT_SCENE.k_u if k_u is None else k_u), (DRAFT_SCENE.k_v if k_v is None else k_v)
    v = SEED_POINT[1] if v is None else v
    crease = 1.0 / k_u
    u = np.linspace(crease - 3 * eps, crease + 3 * eps, 400)
    h = pointwise.height("ridges", u, np.full_like(u, v), k_u, k_v)
    u0 = crease + offset
    (h_m, h_0, h_p) = pointwise.height("ridges", np.array([u0 - eps, u0, u0 + eps]), np.full(3, v), k_u, k_v)
    secant = float(np.asarray(pointwise.central_gradient("ridges", u0, v, k_u, k_v, eps)[0]).ravel()[0])
    exact = float(np.asarray(pointwise.exact_gradient("ridges", u0, v, k_u, k_v)[0]).ravel()[0])
    fig, ax = plt.subplots(figsize=(5.0, 3.2), layout="constrained")
    ax.plot(u, h, color=GREY, lw=1.5, label=r"$h(u, v)$, ridges field")
    ax.axvline(crease, color=GREY, lw=0.8, ls=":")
    ax.annotate("crease", (crease, 1), xycoords=("data", "axes fraction"), xytext=(-4, -4),
                textcoords="offset points", ha="right", va="top")      # inside the axes, clear of the title
    ax.plot([u0 - eps, u0 + eps], [h_m, h_p], "o-", color=RED, label=rf"central stencil: slope {secant:+.2f}")
    du = np.array([-1.5 * eps, 1.5 * eps])
    ax.plot(u0 + du, h_0 + exact * du, color=BLUE, lw=1.5, label=rf"exact slope at the centre: {exact:+.2f}")
    ax.plot([u0], [h_0], "o", color=BLUE)
    ax.set_xlabel(r"$u$"); ax.set_ylabel(r"$h$")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)   # below: clear of the data
    ax.set_title(f"stencil centre u = {u0:.3f} at v = {v:g}, step ε = {eps:g}")     # all at TEXT_PT
    return fig


def ucurve_anatomy(curve):
    """The measured U-curve of a `renderer.ucurve.UCurve`, drawn for the narrow column (5 in wide,
    text at `TEXT_PT`).

    Lines: the float64 quotient's error (label ``|error| ...``), its exact split into exact
    arithmetic at the rounded u +- eps (dashed) and the rounding of the float64 evaluation
    (dotted), over a wide translucent band, the model A eps^2 + B / eps fitted to the error
    (label ``model ...``: a band, so that it shows on both sides of the measured curve it
    follows), the model E(eps) that charges each rounding a full unit roundoff (``curve.model``,
    black, dotted, as the line of its minimiser), two vertical lines, at the model-optimal step eps*
    (dotted, labelled right of it) and the fitted optimal step eps^ (dash-dotted, labelled left of it), and two slope
    guides (labels ``_guide slope +2`` and ``_guide slope -1``, kept out of the legend), each
    parallel to one arm of the fitted model (A eps^2 on steps of 100 eps^ and more, B / eps
    on steps of eps^ / 100 and less) a factor `GUIDE_OFFSET` above it, with its slope written
    beside it.  No sub- or superscript anywhere (mathtext draws them at 70 %: under 8 CSS px
    on a phone).  Steps in chart units, errors in height per chart unit.  Returns the Figure.
    """
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.0, 3.1))
    A, B = curve.fitted_truncation, curve.fitted_roundoff
    ax.loglog(curve.eps, A * curve.eps**2 + B / curve.eps, color=GREY, lw=7, alpha=0.4, solid_capstyle="butt",
              label="model fitted to the error", zorder=1)
    ax.loglog(curve.eps, curve.error, lw=1.6, color=RED, label="|error| of the float64 quotient", zorder=3)
    ax.loglog(curve.eps, curve.model, ":", color="k", lw=1.0, label="model E(ε), a full unit roundoff each", zorder=2)
    ax.loglog(curve.eps, np.abs(curve.truncation), "--", color=BLUE, lw=1.2,
              label="exact arithmetic at the rounded $u \\pm \\varepsilon$", zorder=4)
    ax.loglog(curve.eps, np.abs(curve.roundoff), ":", color=GREEN, lw=1.2, label="rounding of the float64 evaluation",
              zorder=4)
    fitted, model = curve.eps_fitted, curve.eps_model
    ax.axvline(fitted, color=GREY, lw=0.9, ls="-.")
    ax.axvline(model, color="k", lw=0.9, ls=":")
    right = np.geomspace(100 * fitted, curve.eps.max(), 20)
    left = np.geomspace(curve.eps.min(), fitted / 100, 20)
    for steps, arm, slope, words in ((right, lambda e: A * e**2, "+2", "truncation"),
                                     (left, lambda e: B / e, "\u22121", "rounding")):
        ax.loglog(steps, GUIDE_OFFSET * arm(steps), color="k", lw=1.2, label=f"_guide slope {slope}")
        mid = np.sqrt(steps[0] * steps[-1])                      # the guide's middle on log axes
        ax.annotate(f"slope {slope}\n{words}", (mid, GUIDE_OFFSET * arm(mid)), (mid, 60 * GUIDE_OFFSET * arm(mid)),
                    ha="right" if slope == "+2" else "center", va="bottom",     # off the rising guide's way
                    arrowprops=dict(arrowstyle="-", color="k", lw=0.6))
    ax.annotate(r"fitted $\hat\varepsilon$", (fitted / 1.6, 1e-20), ha="right")      # below the curves' floor
    ax.annotate("model-optimal \u03b5*", (model * 1.6, 1e-20), ha="left")            # no superscript: 70 % size
    ax.set_xlabel(r"step $\varepsilon$"); ax.set_ylabel(r"error in $\partial h/\partial u$"); ax.set_ylim(1e-21, 1e5)
    ax.xaxis.set_major_locator(plt.matplotlib.ticker.LogLocator(numticks=6))
    ax.yaxis.set_major_locator(plt.matplotlib.ticker.LogLocator(numticks=7))
    handles, labels = ax.get_legend_handles_labels()                 # the measured curves first, the model last
    ax.legend(handles[1:] + handles[:1], labels[1:] + labels[:1], loc="upper center", bbox_to_anchor=(0.5, -0.2),
              frameon=False)                                         # below the axes
    ax.grid(alpha=0.3)
    return fig


def displacement_figure(result):
    """The displaced sphere beside the bumped one, and where their silhouettes and shadows differ.

    ``result`` is a `lab.displaced.Displaced`.  Top: the bumped render and the displaced one
    (sRGB), each with the other's silhouette outlined (white on black).  Bottom: coverage of sphere A (grey in
    both, red only displaced, blue only bumped) and cast shadows (red only displaced, blue only
    bumped, green where the bumps shadow each other and the bumped render is lit).  5 in wide,
    text at `TEXT_PT`.  Returns a matplotlib Figure.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgb
    from matplotlib.patches import Patch
    from renderer import to_srgb
    covered, bumped_covered = result.covered, result.bumped.chamber == SPHERE_A
    fig, axes = plt.subplots(2, 2, figsize=(5.0, 5.6), layout="constrained")

    def panel(ax, rgb, title, outline=None):
        ax.imshow(rgb)
        if outline is not None:           # white on black: seen over the dark sphere and the light floor
            for colour, width in (("black", 2.0), ("white", 0.8)):
                ax.contour(outline.astype(float), levels=[0.5], colors=colour, linewidths=width)
        ax.set_title(title)
        ax.set_xticks([])
        ax.set_yticks([])

    def categories(shape, layers):
        out = np.ones(shape + (3,))
        for mask, colour in layers:
            out[mask] = to_rgb(colour)
        return out

    panel(axes[0, 0], to_srgb(result.bumped.image), "bumped", covered)
    panel(axes[0, 1], to_srgb(result.image), "displaced", bumped_covered)
    shape = covered.shape
    panel(axes[1, 0], categories(shape, [(covered & bumped_covered, "#bbbbbb"), (covered & ~bumped_covered, RED),
                                         (~covered & bumped_covered, BLUE)]), "silhouette")
    self_shadow = result.shadow & covered & bumped_covered & ~result.bumped_shadow
    panel(axes[1, 1], categories(shape, [(result.shadow & ~result.bumped_shadow, RED),
                                         (~result.shadow & result.bumped_shadow, BLUE), (self_shadow, GREEN)]),
          "cast shadow")
    fig.legend(handles=[Patch(color=RED, label="displaced only"), Patch(color=BLUE, label="bumped only"),
                        Patch(color=GREEN, label="self-shadow")], loc="outside lower center", ncols=3,
               frameon=False, handlelength=1.2, handletextpad=0.5, columnspacing=1.0)   # within the figure's width
    return fig
