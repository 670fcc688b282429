"""``symrender``: the renderer's command line (``symrender <command> --help`` for each).

An input error (a bad option, a malformed scene file, an output directory that does not
exist, a value the library refuses with `renderer.validate.InputError`) prints ONE line
``symrender: error: ...`` and returns 2; anything else is a bug: one line ``symrender:
internal error: ...`` and 1, never a traceback.  Ctrl-C prints ``symrender: interrupted``
and returns 130, SIGTERM ``symrender: terminated`` and 143 (whatever exception then ends the command).  The output is
written beside its place, then the report is printed, then the output is renamed into place
(`renderer.files.write_bytes`): an error or a signal at any moment before the rename leaves no
output and no temporary file, and a signal after it is ignored (the command has succeeded).  ``-o -`` (``--plot -``) writes the
PNG to stdout and the report to stderr.  PNGs carry no varying metadata.

Not special-cased, by design (a plain error, or Python's or the library's own behaviour):
closed standard descriptors; ``/dev/stdout`` as the output (the report is not moved to
stderr); ``-o -`` on a terminal; option abbreviations, and values that begin with a minus sign
after a space (``--eps=-1e-3`` and ``--function=-x`` work); numbers in Python's syntax (``1_0e-3``
is 0.01) and digits of other scripts; huge values repeated in messages; TOML
nested thousands deep (a RecursionError, exit 1); integers beyond a float (the library
names them); scene files that are FIFOs, devices or huge; unwritable directories (found
at the write); file names stdout cannot encode; matplotlib's warnings about an unwritable
home. There are no progress bars.  ``NUMBA_NUM_THREADS`` other than an integer in [1,
`renderer.validate.MAX_THREADS`] is refused before numba reads it (numba's pool segfaulted
at 100000), and a ``--set`` value spanning lines (TOML would read the second as a key of
its own, dropped) is refused.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import signal
import sys
import tomllib

from . import files

__all__ = ["main", "load_scene", "view_image"]

VIEWS = ("shaded", "difference", "bump", "kink")
#: Most steps ucurve's ``--eps`` holds; sweep's are `renderer.sweep.MAX_STEPS`, written out as
#: SWEEP_STEPS so that ``--help`` starts without numpy (a test holds them equal).
MAX_STEPS = 10_000
SWEEP_STEPS = 64
#: The census's columns: the step, then `renderer.ledger.Ledger`'s fields.
COLUMNS = ("eps", "max_abs", "rms", "flips", "pixels_a", "mean_abs_kink", "mean_abs_off_kink")
_signal = []                            # the first signal of a `main` run
_placing = []                           # the output's temporary file (None: a device), once it is written


class UsageError(Exception):
    """A bad argument or input: one line, exit code 2."""


#: The library's `renderer.render.MAX_PIXELS`, for the help (not imported: the command line starts
#: without numpy; a test holds them equal).
MAX_PIXELS = 4096 * 4096


class _Parser(argparse.ArgumentParser):
    def error(self, message):          # one line, not the usage and the message
        raise UsageError(message)


# ---------------------------------------------------------------- arguments


def _size(text):
    """``WxH`` as (width, height) ints; their range is the library's."""
    try:
        width, height = text.lower().split("x")
        return int(width), int(height)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH with integer sides (e.g. 256x256), got {text!r}") from None


def _steps(text, most=MAX_STEPS):
    """``a:b:n`` (n log-spaced steps from a to b, both ends exact) or ``e1,e2,...``, as floats; at
    most ``most`` of them (the command's limit, checked before a:b:n is expanded)."""
    try:
        if ":" in text:
            a, b, n = text.split(":")
            a, b, n = float(a), float(b), int(n)
            if not (0 < a < math.inf and 0 < b < math.inf):
                raise ValueError
        else:
            steps = [float(e) for e in text.split(",")]
            n = len(steps)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a:b:n (a, b > 0, n a whole number) or e1,e2,..., "
                                         f"got {text!r}") from None
    if not 1 <= n <= most:
        raise argparse.ArgumentTypeError(f"must hold 1 to {most:,} steps, got {n:,}")
    if ":" not in text:
        return steps
    la, lb = math.log10(a), math.log10(b)
    # 15 digits, so that decades print as 1e-05, not 9.999999999999999e-06; [:n] leaves a alone for n = 1.
    return [a, *(float(f"{10 ** (la + (lb - la) * i / (n - 1)):.15g}") for i in range(1, n - 1)), b][:n]


def _version():
    from importlib import metadata
    try:
        return metadata.version("symbolic-rendering-ch9")
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


def build_parser():
    """The parser of ``symrender``.  The limits in the help are the library's (a test holds
    them equal), written out so that ``--help`` starts without numpy."""
    p = _Parser(prog="symrender", description="Render, sweep and measure the Chapter-9 scene.")
    p.add_argument("--version", action="version", version=f"symrender {_version()}")
    sub = p.add_subparsers(dest="command", metavar="command", required=True)
    size = f"image size WxH (default 256x256); each side in [1, 8192], W*H <= {MAX_PIXELS:,} (4096x4096)"

    def scene_options(sp):
        sp.add_argument("--scene", metavar="FILE.toml",
                        help="TOML file of Scene fields (lights as [[lights]] tables of position and color); "
                             "missing fields keep the defaults: the draft's scene with the displaced sphere's "
                             "normal, bump=surface (the draft's own normal is bump=chart)")
        sp.add_argument("--field", metavar="NAME|EXPR",
                        help="the height field, after the file: a registered name (an unknown one is refused with "
                             "the list) or an expression in u, v, k_u, k_v, as for ucurve")
        sp.add_argument("--set", action="append", default=[], metavar="key=value",
                        help="override a Scene field after the file and --field; the value is TOML, or else a string "
                             "(height_field=sine); repeatable")

    r = sub.add_parser("render", help="render a PNG and print the ledger",
                       description="Render the scene by both pipelines, write an sRGB PNG of one view and "
                                   "print the ledger (central vs exact on sphere A).")
    scene_options(r)
    r.add_argument("--size", type=_size, default=(256, 256), metavar="WxH", help=size)
    r.add_argument("--gradient", choices=("exact", "central", "footprint"), default="exact",
                   help="the pipeline the shaded, bump and kink views show (default exact)")
    r.add_argument("--view", choices=VIEWS, default="shaded", help="shaded image; difference clip(100 |dI|); "
                   "bump |grad h|; kink: the crease band over the dimmed image (default shaded)")
    r.add_argument("--backend", choices=("numba", "drjit", "auto"), default="numba",
                   help="numba (default); drjit: Dr.Jit's LLVM backend (needs the system's libLLVM >= 17); "
                        "auto: drjit where available")
    r.add_argument("-o", "--output", required=True, metavar="out.png", help="the PNG to write; - for stdout")

    s = sub.add_parser("sweep", help="eps sweep: census of central vs exact",
                       description="Render the exact frame and one central frame per step; print per step max "
                                   "and RMS |dI| on sphere A, flips, and mean |dI| on and off the crease band "
                                   "(none: no pixel of A there).")
    scene_options(s)
    s.add_argument("--eps", type=lambda text: _steps(text, SWEEP_STEPS), default=_steps("1e-1:1e-8:8"),
                   metavar="a:b:n|e1,e2,...",
                   help=f"n log-spaced steps from a to b, or a list; 1 to {SWEEP_STEPS} steps, each in [1e-16, 0.25] "
                        "(default 1e-1:1e-8:8)")
    s.add_argument("--size", type=_size, default=(256, 256), metavar="WxH",
                   help=f"{size}; (steps + 1) * W * H <= 33,554,432")
    s.add_argument("--format", choices=("text", "csv", "json"), default="text",
                   help="the census as a table, CSV or JSON (NaN: empty, null) (default text)")

    u = sub.add_parser("ucurve", help="the finite-difference U-curve at one chart point, or of f(x) at x",
                       description="Central-difference error against a 50-digit mpmath reference, split into "
                                   "truncation and roundoff, per step: of a height field's h_u or h_v at a "
                                   "chart point (--field), or of a function of one variable at any real x "
                                   "(--function, --x).")
    what = u.add_mutually_exclusive_group()
    what.add_argument("--field", default="sine",
                      help="the height field: a registered name (an unknown one is refused with the list) or an "
                           "expression in u, v, k_u, k_v such as 'sin(pi*k_u*u)**2 * sin(pi*k_v*v)**2' (default sine)")
    what.add_argument("--function", metavar="EXPR",
                      help="instead of a field, a function of x, e.g. 'exp(x)/sqrt(sin(x)**3 + cos(x)**3)' "
                           "(pi, E, + - * / ** and sin cos tan asin acos atan sinh cosh tanh exp log sqrt abs)")
    # Each option of one kind of measurement only (`_cmd_ucurve`); None when not given.
    u.add_argument("--x", type=float, help="with --function: the point x, any real where f is "
                                           f"differentiable (default {FUNCTION_X:g})")
    u.add_argument("--u", type=float, help="chart u in [0, 1] (default 0.31)")
    u.add_argument("--v", type=float, help="chart v in [0, 1] (default 0.47)")
    u.add_argument("--component", choices=("u", "v"), help="h_u or h_v (default u)")
    u.add_argument("--k-u", type=float, help="frequency k_u in (0, 1000] (default 8)")
    u.add_argument("--k-v", type=float, help="frequency k_v in (0, 1000] (default 4)")
    u.add_argument("--eps", type=_steps, default=_steps("1e-1:1e-15:15"), metavar="a:b:n|e1,e2,...",
                   help=f"as for sweep; 1 to {MAX_STEPS:,} steps, each in [1e-300, 1) (with --function "
                        "[1e-300, 1000]) (default 1e-1:1e-15:15)")
    u.add_argument("--plot", metavar="out.png", help="also write a log-log plot (PNG); - for stdout")
    return p


# ---------------------------------------------------------------- scene


def _toml_value(text):
    """``--set``'s value: TOML, or else the text itself as a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text.strip()


def _replace(scene, table, source):
    """``scene`` with the fields of the TOML ``table``; an error names ``source`` and the key path."""
    from renderer.scene import PointLight
    from renderer.validate import InputError
    table = dict(table)
    if "lights" in table:
        if not isinstance(table["lights"], list):
            raise UsageError(f"{source}: lights must be an array of tables [[lights]] of position and color")
        lights = []
        for i, light in enumerate(table["lights"]):
            if not (isinstance(light, dict) and light.keys() == {"position", "color"}):
                raise UsageError(f"{source}: lights[{i}] must be a table of position and color, got {light!r:.80}")
            try:
                lights.append(PointLight(**light))
            except InputError as exc:
                raise UsageError(f"{source}: {str(exc).replace('PointLight.', f'lights[{i}].', 1)}") from None
        table["lights"] = lights
    try:
        return scene.replace(**table)
    except InputError as exc:
        raise UsageError(f"{source}: {str(exc).replace('Scene.', '')}") from None


def load_scene(path=None, sets=(), field=None):
    """The `Scene` of a TOML file (its keys are Scene fields; missing ones keep the defaults),
    then the height field ``field`` (a name or an expression; None keeps the file's), then the
    ``key=value`` overrides ``sets``.

    Raises
    ------
    UsageError
        Naming the file (or ``--set``) and the key path (``lights[1].color[2]``): malformed
        TOML or UTF-8, an unknown key, a light without exactly position and color, a value
        `Scene` or `PointLight` refuses.
    OSError
        The file cannot be read.
    """
    from renderer.scene import Scene
    scene = Scene()
    if path is not None:
        try:
            with open(path, encoding="utf-8-sig") as f:
                table = tomllib.loads(f.read())
        except ValueError as exc:      # TOMLDecodeError, UnicodeDecodeError
            raise UsageError(f"{path}: {exc}") from None
        scene = _replace(scene, table, path)
    if field is not None:
        scene = _replace(scene, {"height_field": field}, "--field")
    overrides = {}
    for item in sets:
        key, eq, text = item.partition("=")
        if not eq or "\n" in item or "\r" in item:
            raise UsageError(f"--set expects key=value on one line, got {item!r:.200}")
        overrides[key.strip()] = _toml_value(text)
    return _replace(scene, overrides, "--set")


# ---------------------------------------------------------------- commands


def _check_output(path, flag):
    """Refuse, before any work, an output that is empty, names a directory (``out/`` too) or whose
    directory does not exist."""
    if path != "-" and (not path or path.endswith(os.sep) or os.path.isdir(path)
                        or not os.path.isdir(os.path.dirname(os.path.realpath(path)))):
        raise UsageError(f"{flag} {path!r}: not a file in an existing directory")


def _frame_size(args):
    """``--size``'s sides, each held to the library's range, naming ``--size`` (the library names width)."""
    from renderer.render import MAX_SIDE
    from renderer.validate import positive_int
    return tuple(positive_int(f"--size {name}", side, high=MAX_SIDE) for name, side in zip(("width", "height"), args.size))


def _png(rgb):
    """PNG bytes of an (H, W, 3) display-encoded image in [0, 1] (Pillow writes no metadata)."""
    import numpy as np
    from PIL import Image
    rgb8 = np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(rgb8).save(buf, format="PNG")
    return buf.getvalue()


def view_image(view, selected, numeric, symbolic):
    """The (H, W, 3) float64 display image of a view, as the §4 simulator draws it (1 is white).

    shaded: ``to_srgb(selected.image)``.  difference: ``clip(100 |I_central - I_exact|)``
    per channel (not sRGB-encoded).  bump: ``to_srgb(|grad h| / max over A of the exact
    |grad h|)`` on sphere A, black elsewhere.  kink: the selected image sRGB-encoded and
    dimmed to 40 %, the exact frame's crease band white.
    """
    import numpy as np
    from renderer.ledger import to_srgb
    from renderer.render import SPHERE_A
    if view == "shaded":
        return to_srgb(selected.image)
    if view == "difference":
        return np.clip(100.0 * np.abs(numeric.image - symbolic.image), 0.0, 1.0)
    if view == "bump":
        gmax = float(np.hypot(*np.moveaxis(symbolic.grad, 2, 0))[symbolic.chamber == SPHERE_A].max(initial=0.0))
        g = to_srgb(np.hypot(*np.moveaxis(selected.grad, 2, 0)) / (gmax or 1.0))    # above 1: white in the PNG
        return np.repeat(np.where(selected.chamber == SPHERE_A, g, 0.0)[..., None], 3, axis=2)
    out = 0.4 * to_srgb(selected.image)
    out[symbolic.kink] = 1.0
    return out


def _cell(x):
    """A census value: an int, 4 digits, or ``none`` for a mean over no pixel (NaN)."""
    return str(x) if isinstance(x, int) else "none" if math.isnan(x) else f"{x:.3e}"


def _cmd_render(args):
    from renderer.ledger import compare
    from renderer.render import render
    _check_output(args.output, "-o")
    scene, (width, height), bump = load_scene(args.scene, args.set, args.field), _frame_size(args), args.view == "bump"
    numeric = render(scene, width, height, gradient="central", kink=False, grad=bump, backend=args.backend)
    symbolic = render(scene, width, height, gradient="exact", grad=bump, backend=args.backend)
    led = compare(numeric, symbolic)
    selected = symbolic if args.gradient == "exact" else numeric
    if args.gradient == "footprint" and args.view != "difference":
        numeric = selected = None       # the footprint frame takes the central one's place: two frames at most
        selected = render(scene, width, height, gradient="footprint", kink=False, grad=bump, backend=args.backend)
    data = _png(view_image(args.view, selected, numeric, symbolic))
    labels = ("max |dI|", "RMS |dI|", "flips", "pixels on A", "mean |dI| on band", "mean |dI| off band")
    return ([f"wrote {args.output} ({width}x{height}, view {args.view}, gradient {args.gradient})",
             "ledger (central vs exact, sphere A)"]
            + [f"  {label:<20}{_cell(getattr(led, c))}" for label, c in zip(labels, COLUMNS[1:])],
            [(args.output, data)])


def _cmd_sweep(args):
    from renderer import validate
    from renderer.scene import MAX_EPS, MIN_EPS
    from renderer.sweep import sweep
    steps = [float(e) for e in validate.steps("--eps", args.eps, low=MIN_EPS, high=MAX_EPS)]
    scene, (width, height) = load_scene(args.scene, args.set, args.field), _frame_size(args)
    census = sweep(scene, steps, width, height).census
    rows = [(e, *(getattr(led, c) for c in COLUMNS[1:])) for e, led in zip(steps, census)]
    if args.format == "json":
        doc = {"size": [width, height], "height_field": scene.height_field,
               "rows": [{c: None if x != x else x for c, x in zip(COLUMNS, row)} for row in rows]}  # NaN: null
        return [json.dumps(doc, indent=1, allow_nan=False)], []
    if args.format == "csv":
        out = io.StringIO()
        csv.writer(out, lineterminator="\n").writerows([COLUMNS, *([x if x == x else "" for x in r] for r in rows)])
        return [out.getvalue().rstrip("\n")], []
    return ([f"census: {scene.height_field}, beta {scene.beta:g}, {width}x{height}, central vs exact on sphere A",
             f"{'eps':>9}  {'max |dI|':>9}  {'RMS |dI|':>9}  {'flips':>5}  {'on band':>9}  {'off band':>9}"]
            + [f"{e:9.2e}  {_cell(mx):>9}  {_cell(rms):>9}  {flips:5d}  {_cell(on):>9}  {_cell(off):>9}"
               for e, mx, rms, flips, _, on, off in rows], [])


def _ucurve_png(uc):
    """The U-curve's log-log plot as PNG bytes without varying metadata."""
    import numpy as np
    from matplotlib.figure import Figure
    fig = Figure(figsize=(6.0, 4.0), dpi=100)
    ax = fig.subplots()
    tiny = np.finfo(float).tiny
    ax.loglog(uc.eps, np.maximum(uc.error, tiny), "k.-", label="measured |error|")
    ax.loglog(uc.eps, np.maximum(np.abs(uc.truncation), tiny), "C0--", label="|truncation|")
    ax.loglog(uc.eps, np.maximum(np.abs(uc.roundoff), tiny), "C3--", label="|roundoff|")
    ax.loglog(uc.eps, uc.model, "C2:", label="model E = eps^2|h'''|/6 + u(|h| + |x h'|)/eps")
    if math.isfinite(uc.eps_model):
        ax.axvline(uc.eps_model, color="0.6", lw=0.8, label="model-optimal step eps*")
    if math.isfinite(uc.eps_fitted):
        ax.axvline(uc.eps_fitted, color="0.3", lw=0.8, ls="--", label="fitted optimal step eps^")
    ax.set(xlabel="eps", ylabel=f"|error| of {_derivative(uc)}", title=f"U-curve: {uc.field} at {_point(uc)}"
           + (" (not differentiable there)" if uc.reason else ""))
    ax.legend(fontsize=7)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


#: ``ucurve --x``'s default (`renderer.ucurve.measure_function` has none; `measure`'s are the field options').
FUNCTION_X = 1.5


def _cmd_ucurve(args):
    if args.plot is not None:
        _check_output(args.plot, "--plot")
    import inspect

    from renderer.ucurve import UNIT_ROUNDOFF, measure, measure_function
    from renderer.validate import InputError
    kind = "function" if args.function is not None else "field"
    # Each kind's own options: its function's parameters that are options, but the expression and the steps.
    only = {k: [p for p in inspect.signature(fn).parameters if p not in ("field", "function", "eps") and hasattr(args, p)]
            for k, fn in (("field", measure), ("function", measure_function))}
    stray = [p for other in only if other != kind for p in only[other] if getattr(args, p) is not None]
    if stray:
        raise UsageError(f"--{stray[0].replace('_', '-')} " + ("measures a height field, not --function"
                                                                 if kind == "function" else "applies only with --function"))
    given = {p: getattr(args, p) for p in only[kind] if getattr(args, p) is not None}
    try:
        if kind == "function":
            uc = measure_function(args.function, given.get("x", FUNCTION_X), eps=args.eps)
        else:
            uc = measure(field=args.field, eps=args.eps, **given)
    except InputError as exc:           # the message starts with the parameter, which names the option
        name, _, rest = str(exc).partition(" ")
        raise UsageError(f"--{name.replace('_', '-')} {rest}") from None
    k = {n: given.get(n, inspect.signature(measure).parameters[n].default) for n in ("k_u", "k_v")}
    report = [f"U-curve: {uc.field}, {_derivative(uc)} at {_point(uc)}"
              + ("" if args.function else f", k = ({k['k_u']:g}, {k['k_v']:g})") + "; reference mpmath 50 digits"]
    rows = zip(uc.eps, uc.truncation, uc.roundoff, uc.error, uc.model)
    head = f"{'eps':>9}  {'truncation':>11}  {'roundoff':>11}  {'|error|':>10}"
    if uc.reason is not None:           # no derivative: no model and no optimal step
        report += [f"not differentiable: {uc.reason}",
                   f"error, truncation: against the one-sided derivative from the side of larger {uc.component} "
                   "(smaller at 1); no true derivative and no optimal step exist here", head]
        report += [f"{e:9.2e}  {t:11.3e}  {r:11.3e}  {x:10.3e}" for e, t, r, x, _ in rows]
    else:
        report += [f"true derivative {uc.derivative:.17g}; |h'''| = {abs(uc.third_derivative):.6g}; "
                   f"|h| = {abs(uc.height):.6g}; |x h'| = {uc.model_argument / UNIT_ROUNDOFF:.6g}",
                   f"{head}  {'model':>10}"]
        report += [f"{e:9.2e}  {t:11.3e}  {r:11.3e}  {x:10.3e}  {m:10.3e}" for e, t, r, x, m in rows]
        report += ["truncation: the quotient in exact arithmetic at the float64 abscissae minus the true "
                   "derivative (so it holds their rounding too); roundoff: the rest"]
        report.append(f"model-optimal step eps* {uc.eps_model:.3e}, model error there {uc.error_model:.3e}"
                      if math.isfinite(uc.eps_model) else
                      "model-optimal step eps*: none, |h'''| = 0 (no truncation term: the model falls as eps grows)")
        report.append(f"fitted optimal step eps^ {uc.eps_fitted:.3e}, fitted error there {uc.error_at_fitted:.3e}"
                      if math.isfinite(uc.eps_fitted) else "fitted optimal step eps^: none (the errors fit no "
                      "A eps^2 + B / eps with A, B > 0)")
        report.append(f"measured minimum {uc.error_at_measured_min:.3e} at eps {uc.eps_measured_min:.3e}")
    if args.plot is None:
        return report, []
    return [*report, f"wrote {args.plot}"], [(args.plot, _ucurve_png(uc))]


def _derivative(uc):
    """What a U-curve differentiates: h_u, h_v, or f' (a function of one variable)."""
    return "f'" if uc.component == "x" else f"h_{uc.component}"


def _point(uc):
    return f"x = {uc.u:g}" if uc.component == "x" else f"(u, v) = ({uc.u:g}, {uc.v:g})"


_COMMANDS = {"render": _cmd_render, "sweep": _cmd_sweep, "ucurve": _cmd_ucurve}


# ---------------------------------------------------------------- main


#: The signals that stop a command (`_on_signal`).
SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _on_signal(signum, frame):
    if _placing and not (_placing[0] and os.path.lexists(_placing[0])):
        return                          # the output is in place (its temporary file renamed): done
    if not _signal:                     # a second signal does not cut the clean-up short
        _signal.append(signum)
        raise KeyboardInterrupt


def _stop_if_signalled():
    """Stop before writing if a signal came whose KeyboardInterrupt a C callback dropped
    (llvmlite's, while numba compiles)."""
    if _signal:
        raise KeyboardInterrupt


def _emit(stream, data, name):
    """Write and flush ``data``; an OSError names the stream, whose descriptor then goes to
    /dev/null so that Python's flush at exit does not fail again."""
    try:
        stream.write(data)
        stream.flush()
    except OSError as exc:
        os.dup2(os.open(os.devnull, os.O_WRONLY), stream.fileno())
        raise type(exc)(exc.errno, exc.strerror, name) from None


def _run(argv):
    args = build_parser().parse_args(argv)
    if "NUMBA_NUM_THREADS" in os.environ:          # before numba reads it (0 fails its import)
        from renderer.validate import thread_count
        thread_count("NUMBA_NUM_THREADS", os.environ["NUMBA_NUM_THREADS"])
    report, outputs = _COMMANDS[args.command](args)         # at most one output
    _stop_if_signalled()
    on_stdout = any(path == "-" for path, _ in outputs)      # then the report goes to stderr

    def tell():
        _emit(sys.stderr if on_stdout else sys.stdout, "\n".join(report) + "\n",
              "standard error" if on_stdout else "standard output")
    if not outputs or on_stdout:
        tell()
    for path, data in outputs:
        if path == "-":
            _emit(sys.stdout.buffer, data, "standard output")
        else:
            # The report once the image is written beside its place (a full disk fails before it says
            # "wrote"); from its rename on, the command has succeeded (`_on_signal`).
            files.write_bytes(path, data, before=lambda tmp: (tell(), _placing.append(tmp)))
    return 0


def main(argv=None) -> int:
    """Run ``symrender`` with ``argv`` (default ``sys.argv[1:]``); return the exit code: 0 done
    (``--help``, ``--version`` too), 1 a bug (or a reader that left: ``| head``), 2 an input
    error, 130 SIGINT, 143 SIGTERM.  Never raises."""
    say = lambda text: print("symrender: " + " ".join(str(text).split()), file=sys.stderr)  # noqa: E731
    _signal.clear()
    _placing.clear()
    previous = {sig: signal.signal(sig, _on_signal) for sig in SIGNALS}
    hook = sys.unraisablehook           # a KeyboardInterrupt a C callback dropped is `_signal`'s
    sys.unraisablehook = lambda u: None if isinstance(u.exc_value, KeyboardInterrupt) else hook(u)
    try:
        return _run(sys.argv[1:] if argv is None else list(argv))
    except SystemExit as exc:           # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    # After a signal, whatever ends the command is the signal's: code it interrupts may turn the
    # KeyboardInterrupt into another exception (numba, typing a band's arguments, raised a TypeError).
    except (KeyboardInterrupt, Exception) if _signal else KeyboardInterrupt:
        signum = _signal[0] if _signal else signal.SIGINT
        say("terminated" if signum == signal.SIGTERM else "interrupted")
        return 128 + signum
    except BrokenPipeError:             # the reader left (| head): quiet, as cat
        return 1
    except (UsageError, OSError, MemoryError) as exc:
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        say(f"error: {where}{getattr(exc, 'strerror', None) or str(exc) or 'out of memory'}")
        return 2
    except Exception as exc:
        validate = sys.modules.get("renderer.validate")     # loaded if it raised
        if validate and isinstance(exc, validate.InputError):
            say(f"error: {exc}")
            return 2
        say(f"internal error: {type(exc).__name__}: {exc}")  # a bug: no traceback
        return 1
    finally:
        sys.unraisablehook = hook
        for sig, handler in previous.items():     # as the program exits (argv None), ignored: it is done
            signal.signal(sig, handler if argv is not None else signal.SIG_IGN)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
