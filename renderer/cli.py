"""``symrender``: the renderer's command line.

Subcommands (``symrender <command> --help`` for each)::

    symrender render  [--scene FILE.toml] [--set key=value ...] --size WxH
                      --gradient exact|central|footprint --view shaded|difference|bump|kink
                      [--backend numba|drjit|auto] -o out.png
    symrender sweep   --eps 1e-1:1e-8:8 [--scene ...] [--set ...] [--size WxH] [--format text|csv|json]
    symrender ucurve  --field sine --u 0.31 --v 0.47 --component u [--eps ...] [--plot out.png]

Errors and exit codes are `renderer.cmdline`'s: an input error (a bad argument,
a malformed or unknown scene key, a value the library's validation refuses,
named by its option, a size over the limits, an output path that cannot be
written) prints ONE line ``symrender: error: ...`` and returns 2; anything else
is a bug: one line ``symrender: internal error: ...`` and 1; a traceback is
never printed.  Ctrl-C prints ``symrender: interrupted`` and returns 130,
SIGTERM ``symrender: terminated`` and 143.

Outputs.  The report (the ledger, the census, the U-curve table) is written and
flushed before the output file is put in place, atomically
(`renderer.files.Staged`): a failure or a signal at any moment, or a report
that cannot be written (a full standard output), leaves no output file and no
temporary file.  PNG files carry no varying metadata: two runs give the same
bytes.  ``-o -`` (``--plot -``) writes to standard output, and is refused on a
terminal; the report then goes to standard error (as with ``-o /dev/stdout``).

Limits (refused before anything is allocated): each side of ``--size`` in
[1, 8192]; ``render`` holds two frames at a time (central and exact for the
ledger; the footprint frame, when shown, replaces the central one), at most
``MAX_PIXELS`` = 4096^2 pixels each; ``sweep`` holds one frame per step plus
one, (steps + 1) * W * H <= ``FRAME_PIXEL_BUDGET`` = 2 * 4096^2.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import re
import sys
import tomllib
from pathlib import Path

from . import cmdline, files
from .cmdline import STDOUT, UsageError

__all__ = ["main", "load_scene", "parse_size", "parse_eps", "view_image", "MAX_PIXELS", "FRAME_PIXEL_BUDGET",
           "MAX_UCURVE_STEPS"]

#: Most pixels `render` accepts (W * H): the library's `renderer.render.MAX_PIXELS` (not imported:
#: the command line starts without numpy; a test holds them equal).  The peak of ``render`` is two
#: frames (26 bytes a pixel each; the bump view adds 16 for each gradient it reads) and the
#: display image's float64 temporaries (about 100 bytes a pixel).
MAX_PIXELS = 4096 * 4096
#: Most frame-pixels a command holds at once: render holds 2 frames, a sweep of
#: n steps holds n + 1.
FRAME_PIXEL_BUDGET = 2 * MAX_PIXELS
#: Most steps of one U-curve (each step is a 50-digit mpmath evaluation).
MAX_UCURVE_STEPS = 10_000

VIEWS = ("shaded", "difference", "bump", "kink")
FORMATS = ("text", "csv", "json")
_BARE_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*\Z")


def _field_names():
    """(`Scene` field names, `PointLight` field names), in declaration order."""
    from dataclasses import fields as dataclass_fields

    from renderer.scene import PointLight, Scene
    return (tuple(f.name for f in dataclass_fields(Scene)),
            tuple(f.name for f in dataclass_fields(PointLight)))


def _version():
    """The installed version of the project, or a note when it is not installed."""
    from importlib import metadata
    try:
        return metadata.version("symbolic-rendering-ch9")
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


# ---------------------------------------------------------------- parsing helpers


def parse_size(text):
    """Parse ``"WxH"`` into ``(width, height)`` ints, each in [1, 8192].

    Raises
    ------
    UsageError
        Naming ``--size`` and the text: not of the form WxH with integer
        sides, or a side outside [1, 8192] (negative, zero or huge sides are
        reported with the range).  The pixel limits of a command are checked
        separately, still before any allocation.
    """
    from renderer.render import MAX_SIDE
    m = re.fullmatch(r"\s*([-+]?[0-9]+)\s*[xX]\s*([-+]?[0-9]+)\s*", str(text))    # ASCII digits only
    if not m:
        raise UsageError(f"--size must be WxH with integer sides in [1, {MAX_SIDE}] (e.g. 256x256), "
                         f"got {text!r}")
    for name, digits in (("width", m.group(1)), ("height", m.group(2))):
        # Decided on the digits, so a huge side is never converted to an int.
        if not (len(digits.lstrip("+").lstrip("0")) <= 6 and 1 <= int(digits) <= MAX_SIDE):
            raise UsageError(f"--size {name} must be between 1 and {MAX_SIDE} pixels, got {text!r}")
    return int(m.group(1)), int(m.group(2))


def _check_budget(width, height, frames, what):
    """Refuse a size whose ``frames`` frames exceed the pixel budget (no allocation)."""
    if width * height > MAX_PIXELS:
        raise UsageError(f"--size {width}x{height} is {width * height:,} pixels; {what} accepts at "
                         f"most {MAX_PIXELS:,} (4096x4096)")
    if frames * width * height > FRAME_PIXEL_BUDGET:
        raise UsageError(
            f"--size {width}x{height} with {frames} frames is {frames * width * height:,} frame-pixels; "
            f"{what} accepts at most {FRAME_PIXEL_BUDGET:,} (use a smaller size or fewer steps)")


#: A number as the options take it: ASCII digits, no ``_`` separators (``float`` also takes
#: ``1_0e-3`` and other scripts' digits), or inf/nan for the range checks to name.
_NUMBER = re.compile(r"\s*[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?\s*|\s*[-+]?(inf|infinity|nan)\s*",
                     re.IGNORECASE)


def _number(text):
    """``text`` as a float if it is a plain decimal number (`_NUMBER`); else ValueError."""
    if not _NUMBER.fullmatch(str(text)):
        raise ValueError(text)
    return float(text)


def parse_eps(text, *, name="--eps", max_steps=None):
    """Parse steps: ``"a:b:n"`` (n log-spaced from a to b, both ends exact) or ``"e1,e2,..."``.

    The text only: the range of the steps is the command's (``sweep``: the
    Scene's, ``ucurve``: `renderer.ucurve.measure`'s), checked by
    `renderer.validate.steps`.

    Parameters
    ----------
    text : str
    name : str
        The option named in errors.
    max_steps : int or None
        Most steps accepted; None means `renderer.sweep.MAX_STEPS`.

    Returns
    -------
    tuple of float (chart units), 1 to ``max_steps`` of them.

    Raises
    ------
    UsageError
        Naming ``name``, for a malformed text, a step that is not a number,
        an end of a:b:n that is not a finite number > 0 (they are log-spaced),
        or a count outside [1, max_steps].
    """
    if max_steps is None:
        from renderer.sweep import MAX_STEPS as max_steps

    def number(part):
        try:
            return _number(part)
        except ValueError:
            raise UsageError(f"{name}: {part!r} is not a number") from None

    text = str(text).strip()
    if ":" not in text:
        items = text.split(",")
        if not 1 <= len(items) <= max_steps:
            raise UsageError(f"{name} must hold 1 to {max_steps} steps, got {len(items)}")
        return tuple(number(p) for p in items)
    parts = text.split(":")
    if len(parts) != 3:
        raise UsageError(f"{name} must be a:b:n (n log-spaced steps from a to b) or a comma "
                         f"list, got {text!r}")
    a, b = (number(p) for p in parts[:2])
    if not all(math.isfinite(x) and x > 0 for x in (a, b)):
        raise UsageError(f"{name}: the ends a, b of a:b:n must be finite numbers > 0 (the steps are "
                         f"log-spaced), got {text!r}")
    count = parts[2].strip()
    if not re.fullmatch(r"[-+]?[0-9]+", count):
        raise UsageError(f"{name}: the count n in a:b:n must be an integer in [1, {max_steps}], "
                         f"got {parts[2]!r}")
    if not (len(count.lstrip("+")) <= 6 and 1 <= int(count) <= max_steps):
        raise UsageError(f"{name}: the count n must be between 1 and {max_steps}, got {count}")
    import numpy as np
    # Rounded to 15 significant digits so that decades print as 1e-05, not
    # 9.999999999999999e-06 (a relative change below 1e-15); the ends are the given ones.
    steps = [float(f"{e:.15g}") for e in np.logspace(math.log10(a), math.log10(b), int(count))]
    steps[0], steps[-1] = a, b if len(steps) > 1 else a
    return tuple(steps)


#: Largest scene file `load_scene` reads (bytes); a scene is a few hundred.
MAX_SCENE_BYTES = 1 << 20
#: Deepest nesting of arrays and tables accepted in a scene value (a light's
#: position inside its table inside the lights array is 3 levels).
MAX_NESTING = 8


def _toml_value(key, text):
    """The value of ``--set key=text``: TOML, or a bare word taken as a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except RecursionError:
        raise UsageError(f"--set {key}: the value is nested too deeply (at most {MAX_NESTING} "
                         "levels of arrays and tables)") from None
    except ValueError:  # TOMLDecodeError, or an integer of over 4300 digits
        if _BARE_WORD.match(text):
            return text
        raise UsageError(f"--set {key}: cannot parse {text!r} as a TOML value "
                         f"(quote a string: {key}=\"...\")") from None


def _check_ints(source, name, value):
    """Refuse, naming the key path, a TOML integer too large for a float or a
    value nested deeper than `MAX_NESTING` levels.

    TOML integers are unbounded in tomllib; one beyond about 1.8e308 is
    refused here, with the file (or --set) and the key path, before `Scene`
    sees it.  The walk is iterative and stops at the nesting limit.
    """
    stack = [(name, value, 0)]
    while stack:
        where, item, depth = stack.pop()
        if isinstance(item, (list, dict)):
            if depth >= MAX_NESTING:
                raise UsageError(f"{source}: {where} is nested too deeply (at most {MAX_NESTING} "
                                 "levels of arrays and tables)")
            pairs = item.items() if isinstance(item, dict) else enumerate(item)
            stack.extend((f"{where}.{k}" if isinstance(item, dict) else f"{where}[{k}]", v, depth + 1)
                         for k, v in reversed(list(pairs)))
        elif isinstance(item, int) and not isinstance(item, bool):
            try:
                float(item)
            except OverflowError:
                raise UsageError(f"{source}: {where} = {str(item)[:20]}... is too large for a number "
                                 f"(more than {len(str(item))} digits)") from None


def _scene_mapping(data, source):
    """Turn a TOML mapping into `Scene` keyword arguments, refusing unknown keys."""
    from renderer.scene import PointLight
    from renderer.validate import InputError
    scene_fields, light_fields = _field_names()
    out = {}
    for key, value in data.items():
        if key not in scene_fields:
            raise UsageError(f"{source}: unknown scene field {key!r}; fields are {', '.join(scene_fields)}")
        _check_ints(source, key, value)
        if key == "lights":
            if not isinstance(value, list):
                raise UsageError(f"{source}: lights must be an array of tables with position and "
                                 f"color, got {value!r}")
            lights = []
            for i, table in enumerate(value):
                if not isinstance(table, dict):
                    raise UsageError(f"{source}: lights[{i}] must be a table with position and "
                                     f"color, got {table!r}")
                unknown = sorted(set(table) - set(light_fields))
                if unknown:
                    raise UsageError(f"{source}: unknown light field {unknown[0]!r} in lights[{i}]; "
                                     f"fields are {', '.join(light_fields)}")
                missing = [k for k in light_fields if k not in table]
                if missing:
                    raise UsageError(f"{source}: lights[{i}] has no {missing[0]!r}; each light needs "
                                     f"{' and '.join(light_fields)}")
                try:
                    lights.append(PointLight(**table))
                except InputError as exc:  # the message names the field and the value
                    raise UsageError(f"{source}: lights[{i}]: {exc}") from None
            value = tuple(lights)
        out[key] = value
    return out


def _read_scene_text(path):
    """The text of a scene file: a regular file of at most `MAX_SCENE_BYTES`,
    UTF-8 with an optional byte-order mark."""
    if not str(path):
        raise UsageError("--scene: the path is empty (give a TOML file)")
    try:
        raw = files.read_regular(path, MAX_SCENE_BYTES)
    except files.RefusedPath as exc:
        raise UsageError(f"--scene {exc}") from None
    except OSError as exc:
        raise UsageError(f"--scene: cannot read {str(path)!r}: {exc.strerror or exc}") from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise UsageError(f"--scene {path}: not UTF-8 text") from None


def load_scene(path=None, sets=()):
    """Build a `Scene` from a TOML file and ``key=value`` overrides.

    Parameters
    ----------
    path : str or None
        A TOML file whose top-level keys are `Scene` field names; ``lights``
        is an array of tables ``[[lights]]``, each with ``position`` and
        ``color``.  Missing fields keep the Scene's defaults (the seed's,
        Cell 1, with the displaced sphere's normal ``bump="surface"``).  It must be a regular file (a symbolic link to one is
        followed) of at most `MAX_SCENE_BYTES` = 1 MiB, UTF-8 (a leading
        byte-order mark is accepted).
    sets : sequence of str
        ``key=value`` overrides applied after the file; ``value`` is parsed
        as TOML (``beta=0.5``, ``floor=false``, ``center_b=[0.5, 0.5, 1.3]``),
        and a bare word that is not TOML is taken as a string (``height_field=sine``).

    Returns
    -------
    Scene

    Raises
    ------
    UsageError
        An empty path; a file that is missing, unreadable, not a regular
        file (a directory, FIFO or device) or over 1 MiB; malformed TOML; a
        value nested more than `MAX_NESTING` levels; an unknown key (named);
        a light without ``position`` or ``color`` (named as ``lights[i]``);
        or a malformed ``--set``.
    renderer.validate.InputError
        What `Scene` and `PointLight` refuse (the message names the field).
    """
    from renderer.scene import Scene
    scene_fields = _field_names()[0]
    data = {}
    if path is not None:
        text = _read_scene_text(path)
        try:
            data = tomllib.loads(text)
        except RecursionError:
            raise UsageError(f"--scene {path}: nested too deeply (at most {MAX_NESTING} levels of "
                             "arrays and tables)") from None
        except ValueError as exc:  # TOMLDecodeError, or an integer of over 4300 digits
            raise UsageError(f"--scene {path}: malformed TOML: {exc}") from None
        data = _scene_mapping(data, f"--scene {path}")
    for item in sets:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise UsageError(f"--set must be key=value, got {item!r}")
        if key not in scene_fields:
            raise UsageError(f"--set: unknown scene field {key!r}; fields are {', '.join(scene_fields)}")
        data.update(_scene_mapping({key: _toml_value(key, text.strip())}, "--set"))
    return Scene(**data)


# ---------------------------------------------------------------- outputs


def _stage_png(outputs, path, rgb, flag):
    """Stage an (H, W, 3) float image with values in [0, 1] (already display-encoded)
    as an 8-bit PNG without varying metadata (``-``: standard output)."""
    import numpy as np
    rgb8 = np.round(np.clip(np.asarray(rgb, dtype=np.float64), 0.0, 1.0) * 255.0).astype(np.uint8)
    outputs.stage_bytes(path, cmdline.png_bytes(rgb8), flag)


def _check_output(path, flag):
    """Fail fast, before any work, on an output path that cannot be written:
    ``-`` on a terminal; an empty path, a trailing ``/``, a directory, a
    block device, a socket or a dangling link; a new or regular file (or
    the regular file a link leads to) whose directory is missing or not
    writable; a device or FIFO that is not writable (its directory need not
    be writable)."""
    if path == STDOUT:
        cmdline.binary_stdout(flag)
        return
    try:
        route = files.output_route(path)
    except files.RefusedPath as exc:
        raise UsageError(f"{flag} {exc}") from None
    except NotADirectoryError:
        route = "replace"  # a parent that is not a directory: named below
    if route == "through":
        if not os.access(path, os.W_OK):
            raise UsageError(f"{flag} {str(path)!r} is not writable")
        return
    parent = Path(os.path.realpath(path) if route == "link" else path).parent
    if not parent.is_dir():
        what = "is not a directory" if parent.exists() else "does not exist"
        raise UsageError(f"{flag} {str(path)!r}: {str(parent)!r} {what}")
    if not os.access(parent, os.W_OK):
        raise UsageError(f"{flag} {str(path)!r}: directory {str(parent)!r} is not writable")


def _fmt(x):
    return f"{x:.3e}"


def _mean(x, where):
    """A band mean for the report: the Ledger's NaN (no pixel in the set) in words."""
    return f"none (no pixel {where})" if math.isnan(x) else _fmt(x)


def _ledger_lines(led):
    return [
        "ledger (central vs exact, sphere A)",
        f"  max |dI|            {_fmt(led.max_abs)}",
        f"  RMS |dI|            {_fmt(led.rms)}",
        f"  flips               {led.flips}",
        f"  pixels on A         {led.pixels_a}",
        f"  mean |dI| on band   {_mean(led.mean_abs_kink, 'in the band')}",
        f"  mean |dI| off band  {_mean(led.mean_abs_off_kink, 'off the band')}",
    ]


# ---------------------------------------------------------------- subcommands


def view_image(view, selected, numeric, symbolic):
    """The display image (H, W, 3) float64 in [0, 1] of a view (as the §4 simulator).

    shaded: ``to_srgb(selected.image)``.  difference: ``clip(100 |I_central -
    I_exact|, 0, 1)`` per channel (not sRGB-encoded, as book/s4_simulator.md).
    bump: ``to_srgb(|grad h| / max over A of the exact |grad h|)`` on sphere A,
    black elsewhere.  kink: the selected image sRGB-encoded and dimmed to 40 %,
    the exact frame's crease band painted white.  The difference view reads
    ``numeric`` and ``symbolic`` only, the others ``selected`` and ``symbolic``
    (``numeric`` may then be None).
    """
    import numpy as np
    from renderer.ledger import to_srgb
    from renderer.render import SPHERE_A
    if view == "shaded":
        return to_srgb(selected.image)
    if view == "difference":
        return np.clip(100.0 * np.abs(numeric.image - symbolic.image), 0.0, 1.0)
    if view == "bump":
        on_a_exact = symbolic.chamber == SPHERE_A
        gmax = float(np.hypot(symbolic.grad[..., 0], symbolic.grad[..., 1])[on_a_exact].max(initial=0.0))
        g = np.hypot(selected.grad[..., 0], selected.grad[..., 1]) / (gmax or 1.0)
        g = np.where(selected.chamber == SPHERE_A, to_srgb(np.minimum(g, 1.0)), 0.0)
        return np.repeat(g[..., None], 3, axis=2)
    if view == "kink":
        out = 0.4 * to_srgb(selected.image)
        out[symbolic.kink] = 1.0
        return out
    raise UsageError(f"--view must be one of {VIEWS}, got {view!r}")


def _cmd_render(args, outputs):
    from renderer.ledger import compare
    from renderer.render import render
    width, height = args.size
    _check_budget(width, height, 2, "render")
    _check_output(args.output, "-o")
    outputs.to_stderr = cmdline.is_stdout(args.output)    # the PNG takes stdout: the report goes to stderr
    scene = load_scene(args.scene, args.set)
    bump = args.view == "bump"     # the gradients only for the bump view: 16 bytes a pixel each
    footprint = args.gradient == "footprint" and args.view != "difference"
    with cmdline.progress(total=2 + footprint, desc="render", unit="frame") as bar:
        numeric = render(scene, width, height, gradient="central", kink=False,
                         grad=bump and args.gradient == "central", backend=args.backend)
        bar.update()
        symbolic = render(scene, width, height, gradient="exact", grad=bump,   # its kink: the ledger's band
                          backend=args.backend)
        bar.update()
        ledger = compare(numeric, symbolic)
        selected = symbolic if args.gradient == "exact" else numeric
        if footprint:
            # The footprint frame takes the central frame's place: two frames at a time.
            numeric = selected = None
            selected = render(scene, width, height, gradient="footprint", kink=False, grad=bump,
                              backend=args.backend)
            bar.update()
    _stage_png(outputs, args.output, view_image(args.view, selected, numeric, symbolic), "-o")
    where = "standard output" if args.output == STDOUT else args.output
    print(f"wrote {where} ({width}x{height}, view {args.view}, gradient {args.gradient})", file=outputs)
    print("\n".join(_ledger_lines(ledger)), file=outputs)
    return 0


_CENSUS_COLUMNS = ("eps", "max_abs", "rms", "flips", "pixels_a", "mean_abs_kink", "mean_abs_off_kink")


def _cmd_sweep(args, outputs):
    from renderer.scene import MAX_EPS, MIN_EPS
    from renderer.sweep import sweep
    from renderer.validate import steps as valid_steps
    steps = tuple(float(e) for e in valid_steps("--eps", args.eps, low=MIN_EPS, high=MAX_EPS))
    width, height = args.size
    _check_budget(width, height, len(steps) + 1, "sweep")
    scene = load_scene(args.scene, args.set)
    census = sweep(scene, steps, width, height).census
    rows = [dict(zip(_CENSUS_COLUMNS, (e, led.max_abs, led.rms, led.flips, led.pixels_a,
                                       led.mean_abs_kink, led.mean_abs_off_kink)))
            for e, led in zip(steps, census)]
    missing = lambda x: isinstance(x, float) and math.isnan(x)  # noqa: E731  (no pixel in the set)
    if args.format == "json":
        doc = {"size": [width, height], "height_field": scene.height_field,
               "rows": [{k: None if missing(v) else v for k, v in r.items()} for r in rows]}
        print(json.dumps(doc, indent=1, allow_nan=False), file=outputs)
    elif args.format == "csv":
        w = csv.writer(outputs, lineterminator="\n")
        w.writerow(_CENSUS_COLUMNS)
        for r in rows:
            w.writerow(["" if missing(r[k]) else repr(r[k]) if isinstance(r[k], float) else r[k]
                        for k in _CENSUS_COLUMNS])
    else:
        print(f"census: {scene.height_field}, beta {scene.beta:g}, {width}x{height}, central vs exact on sphere A",
              file=outputs)
        print(f"{'eps':>9}  {'max |dI|':>9}  {'RMS |dI|':>9}  {'flips':>5}  {'on band':>9}  {'off band':>9}",
              file=outputs)
        cell = lambda x: "none" if missing(x) else _fmt(x)  # noqa: E731
        for r in rows:
            print(f"{r['eps']:9.2e}  {_fmt(r['max_abs']):>9}  {_fmt(r['rms']):>9}  {r['flips']:5d}  "
                  f"{cell(r['mean_abs_kink']):>9}  {cell(r['mean_abs_off_kink']):>9}", file=outputs)
    return 0


def _measure_ucurve(args, steps):
    import dataclasses

    import numpy as np
    from renderer.ucurve import fit_model, measure
    kw = dict(field=args.field, u=args.u, v=args.v, component=args.component, k_u=args.k_u, k_v=args.k_v)
    if not cmdline.show_progress() or steps.size < 50:
        return measure(eps=steps, **kw)
    parts = []
    with cmdline.progress(total=steps.size, desc="ucurve", unit="step") as bar:
        for chunk in np.array_split(steps, math.ceil(steps.size / 25)):
            parts.append(measure(eps=chunk, **kw))
            bar.update(chunk.size)
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts])  # noqa: E731
    error = cat("error")
    nan = float("nan")
    # The model's coefficients are the point's, the same in every part; the steps named by
    # the whole curve (its measured minimum and fitted optimal step) are found on all of it.
    uc = dataclasses.replace(parts[0], eps=steps, error=error, truncation=cat("truncation"),
                             roundoff=cat("roundoff"), model=cat("model"), fitted_truncation=nan,
                             fitted_roundoff=nan, eps_fitted=nan, error_at_fitted=nan)
    if uc.reason is not None:
        return uc
    best = int(np.argmin(error))
    uc = dataclasses.replace(uc, eps_measured_min=float(steps[best]), error_at_measured_min=float(error[best]))
    try:
        A, B = fit_model(steps, error, start=(max(uc.model_truncation, 1e-300),
                                              max(uc.model_cancellation + uc.model_argument, 1e-300)))
    except ValueError:
        return uc
    e_fit = (B / (2 * A)) ** (1 / 3)
    return dataclasses.replace(uc, fitted_truncation=A, fitted_roundoff=B, eps_fitted=e_fit,
                               error_at_fitted=A * e_fit**2 + B / e_fit)


def _ucurve_png(uc):
    """The U-curve's log-log plot as PNG bytes without varying metadata."""
    import numpy as np
    matplotlib = cmdline.import_matplotlib()
    from matplotlib.figure import Figure
    with matplotlib.rc_context({"svg.hashsalt": "symrender", "path.simplify": False}):
        fig = Figure(figsize=(6.0, 4.0), dpi=100)
        ax = fig.subplots()
        floor = np.finfo(float).tiny
        ax.loglog(uc.eps, np.maximum(uc.error, floor), "k.-", label="measured |error|")
        ax.loglog(uc.eps, np.maximum(np.abs(uc.truncation), floor), "C0--", label="|truncation|")
        ax.loglog(uc.eps, np.maximum(np.abs(uc.roundoff), floor), "C3--", label="|roundoff|")
        ax.loglog(uc.eps, uc.model, "C2:", label="model E = eps^2|h'''|/6 + u(|h| + |x h'|)/eps")
        if math.isfinite(uc.eps_model):
            ax.axvline(uc.eps_model, color="0.6", lw=0.8, label="model-optimal step eps*")
        if math.isfinite(uc.eps_fitted):
            ax.axvline(uc.eps_fitted, color="0.3", lw=0.8, ls="--", label="fitted optimal step eps^")
        ax.set_xlabel("eps (chart units)")
        ax.set_ylabel(f"|error| of h_{uc.component}")
        ax.set_title(f"U-curve: {uc.field} at (u, v) = ({uc.u:g}, {uc.v:g})"
                     + (" (not differentiable there)" if uc.reason else ""))
        ax.legend(fontsize=7)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


def _cmd_ucurve(args, outputs):
    from renderer import pointwise, validate
    from renderer.ucurve import UNIT_ROUNDOFF
    if args.plot is not None:
        _check_output(args.plot, "--plot")
        outputs.to_stderr = cmdline.is_stdout(args.plot)   # the plot takes stdout: the table goes to stderr
    # `measure`'s own checks (its ranges are `pointwise.central_gradient`'s), named by the
    # options, before the slow import of the U-curve's sympy formulas.
    for name in ("u", "v", "k_u", "k_v"):
        validate.real(f"--{name.replace('_', '-')}", getattr(args, name), **pointwise.RANGES_CENTRAL[name])
    uc = _measure_ucurve(args, validate.steps("--eps", args.eps, **pointwise.RANGES_CENTRAL["eps"]))
    out = outputs
    print(f"U-curve: {uc.field}, h_{uc.component} at (u, v) = ({uc.u:g}, {uc.v:g}), "
          f"k = ({args.k_u:g}, {args.k_v:g}); reference mpmath 50 digits", file=out)
    if uc.reason is not None:
        # No derivative: no "true derivative", no model and no optimal step to print.
        print(f"not differentiable: {uc.reason}", file=out)
        print("error, truncation: against the one-sided derivative from the side of larger "
              f"{uc.component} (smaller at 1); no true derivative and no optimal step exist here", file=out)
        print(f"{'eps':>9}  {'truncation':>11}  {'roundoff':>11}  {'|error|':>10}", file=out)
        for i in range(uc.eps.size):
            print(f"{uc.eps[i]:9.2e}  {uc.truncation[i]:11.3e}  {uc.roundoff[i]:11.3e}  "
                  f"{uc.error[i]:10.3e}", file=out)
    else:
        print(f"true derivative {uc.derivative:.17g}; |h'''| = {abs(uc.third_derivative):.6g}; "
              f"|h| = {abs(uc.height):.6g}; |{uc.component} h'| = {uc.model_argument / UNIT_ROUNDOFF:.6g}", file=out)
        print(f"{'eps':>9}  {'truncation':>11}  {'roundoff':>11}  {'|error|':>10}  {'model':>10}", file=out)
        for i in range(uc.eps.size):
            print(f"{uc.eps[i]:9.2e}  {uc.truncation[i]:11.3e}  {uc.roundoff[i]:11.3e}  "
                  f"{uc.error[i]:10.3e}  {uc.model[i]:10.3e}", file=out)
        print(f"model-optimal step eps* {uc.eps_model:.3e}, model error there {uc.error_model:.3e}", file=out)
        print(f"fitted optimal step eps^ {uc.eps_fitted:.3e}, fitted error there {uc.error_at_fitted:.3e}", file=out)
        print(f"measured minimum {uc.error_at_measured_min:.3e} at eps {uc.eps_measured_min:.3e}", file=out)
    if args.plot is not None:
        outputs.stage_bytes(args.plot, _ucurve_png(uc), "--plot")
        print(f"wrote {'standard output' if args.plot == STDOUT else args.plot}", file=out)
    return 0


# ---------------------------------------------------------------- argument parser


def _size_arg(text):
    try:
        return parse_size(text)
    except UsageError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--size ")) from None


def _eps_arg(max_steps):
    def parse(text):
        try:
            return parse_eps(text, name="steps", max_steps=max_steps)
        except UsageError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    return parse


def _float_arg(text):
    try:
        return _number(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


def build_parser():
    """The argparse parser of ``symrender`` (one subparser per command)."""
    from renderer.pointwise import MIN_STEP
    from renderer.render import MAX_SIDE
    from renderer.scene import MAX_EPS, MAX_FREQUENCY, MIN_EPS
    from renderer.sweep import MAX_STEPS
    limits = (f"Limits: each side 1..{MAX_SIDE}; render at most {MAX_PIXELS:,} pixels (4096^2); "
              f"sweep at most (steps + 1) * W * H <= {FRAME_PIXEL_BUDGET:,}; refused before allocating.")
    p = cmdline.Parser(prog="symrender", description="Render, sweep and measure the Chapter-9 scene.",
                       epilog=limits)
    p.add_argument("--version", action="version", version=f"symrender {_version()}")
    sub = p.add_subparsers(dest="command", metavar="command", required=True, parser_class=cmdline.Parser)

    def scene_opts(sp):
        sp.add_argument("--scene", metavar="FILE.toml",
                        help="TOML file with Scene field names ([[lights]] tables with position, color); "
                             "unknown keys are errors; missing fields keep the defaults: the draft's "
                             "scene with the displaced sphere's normal (bump=surface; the draft's own "
                             "normal is bump=chart)")
        sp.add_argument("--set", action="append", default=[], metavar="key=value",
                        help="override a Scene field; value is TOML (a bare word is a string); repeatable")

    r = sub.add_parser("render", help="render a PNG and print the frame's ledger",
                       description="Render the scene (both pipelines), write an sRGB PNG of one view, "
                                   "print the ledger (central vs exact on sphere A).", epilog=limits)
    scene_opts(r)
    r.add_argument("--size", type=_size_arg, default=(256, 256), metavar="WxH",
                   help=f"image size, each side 1..{MAX_SIDE}, W*H <= {MAX_PIXELS:,} (default 256x256)")
    r.add_argument("--gradient", choices=("exact", "central", "footprint"), default="exact",
                   help="pipeline shown by the shaded, bump and kink views (default exact)")
    r.add_argument("--backend", choices=("numba", "drjit", "auto"), default="numba",
                   help="renderer: numba (default), drjit (Dr.Jit's LLVM backend; needs the system's "
                        "libLLVM), auto (drjit where available, else numba)")
    r.add_argument("--view", choices=VIEWS, default="shaded",
                   help="shaded image; difference clip(100|dI|); bump |grad h|; kink band over dimmed image")
    r.add_argument("-o", "--output", required=True, metavar="out.png", help="PNG to write (atomically)")

    s = sub.add_parser("sweep", help="eps sweep: census table of central vs exact",
                       description="Render the exact frame and one central frame per step; print the census: "
                                   "eps, max and RMS |dI| on A, flips, mean |dI| on and off the kink band "
                                   "(none: no pixel of A there).",
                       epilog=limits)
    scene_opts(s)
    s.add_argument("--eps", type=_eps_arg(MAX_STEPS), default=parse_eps("1e-1:1e-8:8"),
                   metavar="a:b:n|e1,e2,..",
                   help=f"n log-spaced steps from a to b, or a comma list; 1..{MAX_STEPS} steps, each in "
                        f"[{MIN_EPS:g}, {MAX_EPS:g}] (default 1e-1:1e-8:8)")
    s.add_argument("--size", type=_size_arg, default=(256, 256), metavar="WxH",
                   help="image size (default 256x256); (steps + 1) * W * H <= "
                        f"{FRAME_PIXEL_BUDGET:,}")
    s.add_argument("--format", choices=FORMATS, default="text", help="output format (default text)")

    u = sub.add_parser("ucurve", help="the measured finite-difference U-curve at one chart point",
                       description="Central-difference error against a 50-digit mpmath reference, split "
                                   "into truncation and roundoff, per step (renderer/ucurve.py).")
    u.add_argument("--field", default="sine", help="a height field's name or an expression in u, v, k_u, k_v")
    u.add_argument("--u", type=_float_arg, default=0.31, help="chart u in [0, 1] (default 0.31)")
    u.add_argument("--v", type=_float_arg, default=0.47, help="chart v in [0, 1] (default 0.47)")
    u.add_argument("--component", choices=("u", "v"), default="u", help="h_u or h_v (default u)")
    u.add_argument("--k-u", dest="k_u", type=_float_arg, default=8.0,
                   help=f"frequency k_u in (0, {MAX_FREQUENCY:g}] (default 8)")
    u.add_argument("--k-v", dest="k_v", type=_float_arg, default=4.0,
                   help=f"frequency k_v in (0, {MAX_FREQUENCY:g}] (default 4)")
    u.add_argument("--eps", type=_eps_arg(MAX_UCURVE_STEPS), default=parse_eps("1e-1:1e-15:15"),
                   metavar="a:b:n|e1,e2,..",
                   help=f"steps, as for sweep; 1..{MAX_UCURVE_STEPS} steps, each in [{MIN_STEP:g}, 1) "
                        "(default 1e-1:1e-15:15)")
    u.add_argument("--plot", metavar="out.png", help="also save a log-log plot (PNG, atomically)")

    return p


_COMMANDS = {"render": _cmd_render, "sweep": _cmd_sweep, "ucurve": _cmd_ucurve}


def _command(argv, outputs):
    args = build_parser().parse_args(argv)
    try:
        return _COMMANDS[args.command](args, outputs)
    except MemoryError:
        raise UsageError("out of memory (use a smaller --size)") from None


def main(argv=None) -> int:
    """Run ``symrender`` with ``argv`` (default ``sys.argv[1:]``); return the exit code
    (`renderer.cmdline.main`: 0; 1 a bug or a broken pipe; 2 an input error; 130
    SIGINT; 143 SIGTERM).  Never raises; ``--help`` prints to stdout and returns 0."""
    return cmdline.main("symrender", _command, sys.argv[1:] if argv is None else list(argv))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
