"""``symrender``: the command line for authors and releases.

Subcommands (``symrender <command> --help`` for each)::

    symrender render  [--scene FILE.toml] [--set key=value ...] --size WxH
                      --gradient exact|central --view shaded|difference|bump|kink -o out.png
    symrender sweep   --eps 1e-1:1e-8:8 [--scene ...] [--set ...] [--size WxH]
                      [--format text|csv|json]
    symrender ucurve  --field sine --u 0.31 --v 0.47 --component u [--eps ...] [--plot out.png]
    symrender verify  [-k EXPR]
    symrender figures --out DIR [--pages s1,s4] | --check DIR [--ignore ID-PATTERN ...]

Errors.  Every input error (a bad argument, a malformed or unknown scene key, a
value `Scene` refuses, a size over the limits, an output path that cannot be
written) prints ONE line ``symrender: error: ...`` on stderr naming the bad
argument, writes no file and returns 2.  A Python traceback is never printed;
an error the command line did not anticipate (a bug) prints one line
``symrender: internal error: ...`` and returns 1.  ``verify`` returns pytest's
exit code; ``figures --check`` returns 1 when a figure changed beyond
`CHECK_TOLERANCE_LEVELS` / `CHECK_TOLERANCE_FRACTION`.

Interrupts.  Ctrl-C at any moment of a command, its imports of numpy, sympy
and matplotlib included, prints ONE line ``symrender: interrupted`` on stderr
and returns 130, after the clean-up has run: no output file, temporary file
or staging directory is left, and no child process (the notebook kernel of
``figures``, which jupyter_client starts in a session of its own, is shut
down; the pytest child of ``verify`` gets the same Ctrl-C and is waited for;
a render under way finishes first: it runs compiled,
without Python's signal checks).  A second Ctrl-C is ignored, so it
cannot cut the clean-up short.  ``import proofs.cli`` loads neither numpy
nor the renderer, which `main` imports under its SIGINT handling; only a
Ctrl-C while Python itself starts, before `main` runs, is reported by
Python (see `main`).

Reproducibility.  PNG files carry no timestamp, software tag or other varying
metadata, so two runs on the same code give byte-identical files.  The bytes
are prepared in memory, then written by `renderer.files.write_bytes`: a new or
regular file atomically (a temporary file in the target directory, then
`os.replace`), so an interrupted or failed run leaves no file behind, and
so is the final target of a link to a regular file; a character device or
FIFO (``/dev/null``), or a link to one (``/dev/stdout`` on a pipe), is
written through and keeps its kind; a directory, a dangling link, a block
device, a socket or a path ending in ``/`` is refused.  ``-o -`` (``--plot -``) writes the PNG to standard output, the
report to standard error, and is refused on a terminal.  Files read (scene
files, a ``--check`` directory) are bounded regular files.

Limits (refused before anything is allocated): each side of ``--size`` in
[1, 8192] (`renderer.render.MAX_SIDE`); ``render`` holds two frames, so at most
``MAX_PIXELS`` = 4096^2 = 16,777,216 pixels; ``sweep`` holds one frame per step
plus one, so (steps + 1) * W * H <= ``FRAME_PIXEL_BUDGET`` = 2 * 4096^2 (a frame
takes about 57 bytes per pixel: about 1.9 GB at the limit).
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import hashlib
import io
import json
import math
import os
import re
import signal
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

# numpy, sympy, matplotlib and the renderer (any ``renderer`` module, even
# renderer.files: importing the package loads numpy) are imported where they
# are first used (the functions below import renderer.scene, .render, .ledger,
# .sweep and proofs.ucurve), never by ``import proofs.cli``: the console script
# imports this module before `main` runs, and a Ctrl-C during a heavy import at
# that point would print a traceback.  In `main` it is handled.


class _Module:
    """Stands for the module ``module`` under the global name ``name`` until
    the first ``<name>.<attribute>``, which imports the module and puts the
    module itself in this one's globals."""

    def __init__(self, name, module):
        self._name, self._module = name, module

    def __getattr__(self, attribute):
        import importlib
        module = importlib.import_module(self._module)
        globals()[self._name] = module
        return getattr(module, attribute)


np = _Module("np", "numpy")
files = _Module("files", "renderer.files")

__all__ = ["main", "load_scene", "parse_size", "parse_eps", "write_png", "atomic_write",
           "MAX_PIXELS", "FRAME_PIXEL_BUDGET", "MAX_UCURVE_STEPS"]

#: Most pixels `render` accepts (W * H): the two frames of the ledger then take
#: about 2 * 57 bytes * 4096^2 = 1.9 GB.
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


class UsageError(Exception):
    """A bad argument or input: printed as one line, exit code 2."""


_NEGATIVE_VALUE = re.compile(r"-[0-9.]")


class _Parser(argparse.ArgumentParser):
    """argparse that raises `UsageError` instead of printing usage and exiting,
    and that takes a value starting with ``-`` and a digit or ``.`` as the
    value of the option before it (``--size -5x5``, ``--eps -1e-3``), so that
    such values reach the command's own checks and messages."""

    def error(self, message):
        raise UsageError(message)

    def parse_known_args(self, args=None, namespace=None):
        if args is not None:
            takes_value = {o for a in self._actions if a.nargs is None for o in a.option_strings}
            args, joined = list(args), []
            while args:
                token = args.pop(0)
                if token == "--":
                    joined += [token, *args]
                    break
                if token in takes_value and args and _NEGATIVE_VALUE.match(args[0]):
                    token = f"{token}={args.pop(0)}"
                joined.append(token)
            args = joined
        return super().parse_known_args(args, namespace)


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
    m = re.fullmatch(r"\s*([-+]?\d+)\s*[xX]\s*([-+]?\d+)\s*", str(text))
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


def _positive_float(text, name, bounds=None):
    try:
        x = float(text)
    except ValueError:
        raise UsageError(f"{name}: {text!r} is not a number") from None
    if bounds is not None and not (math.isfinite(x) and bounds[0] <= x <= bounds[1]):
        raise UsageError(f"{name}: each step must be in [{bounds[0]:g}, {bounds[1]:g}] "
                         f"(chart units), got {text.strip()!r}")
    if not (math.isfinite(x) and x > 0):
        raise UsageError(f"{name}: each step must be a finite number > 0, got {text!r}")
    return x


def parse_eps(text, *, name="--eps", max_steps=None, bounds=None):
    """Parse steps: ``"a:b:n"`` (n log-spaced from a to b) or ``"e1,e2,..."``.

    Parameters
    ----------
    text : str
    name : str
        The option named in errors.
    max_steps : int or None
        Most steps accepted; None means `renderer.sweep.MAX_STEPS`.
    bounds : (float, float) or None
        If given, the closed range every step must lie in (chart units), as
        ``(renderer.scene.MIN_EPS, renderer.scene.MAX_EPS)`` for a sweep.

    Returns
    -------
    tuple of float, each finite and > 0 (and within ``bounds``), chart units;
    1 to ``max_steps`` of them.

    Raises
    ------
    UsageError
        Naming ``name``, for a malformed text, a step that is not a finite
        positive number or lies outside ``bounds`` (the range is named), or a
        count outside [1, max_steps].
    """
    if max_steps is None:
        from renderer.sweep import MAX_STEPS as max_steps
    text = str(text).strip()
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise UsageError(f"{name} must be a:b:n (n log-spaced steps from a to b) or a comma "
                             f"list, got {text!r}")
        a, b = (_positive_float(p, name, bounds) for p in parts[:2])
        count = parts[2].strip()
        if not re.fullmatch(r"[-+]?\d+", count):
            raise UsageError(f"{name}: the count n in a:b:n must be an integer in [1, {max_steps}], "
                             f"got {parts[2]!r}")
        if not (len(count.lstrip("+")) <= 6 and 1 <= int(count) <= max_steps):
            raise UsageError(f"{name}: the count n must be between 1 and {max_steps}, got {count}")
        # Rounded to 15 significant digits so that decades print as 1e-05, not
        # 9.999999999999999e-06 (a relative change below 1e-15).
        steps = tuple(float(f"{e:.15g}") for e in np.logspace(math.log10(a), math.log10(b), int(count)))
        if bounds is not None:  # rounding could step just outside the range
            steps = tuple(min(max(e, bounds[0]), bounds[1]) for e in steps)
    else:
        items = [p for p in text.split(",")]
        if not 1 <= len(items) <= max_steps:
            raise UsageError(f"{name} must hold 1 to {max_steps} steps, got {len(items)}")
        steps = tuple(_positive_float(p, name, bounds) for p in items)
    return steps


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
                lights.append(PointLight(**table))
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
        Cell 1).  It must be a regular file (a symbolic link to one is
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
    TypeError, ValueError
        From `Scene`/`PointLight` validation (the message names the field).
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


# ---------------------------------------------------------------- output helpers


#: The output path that means standard output (``-o -``, ``--plot -``).
STDOUT = "-"


def _stdout_bytes():
    """The binary stream under ``sys.stdout``, refused when it is a terminal."""
    stream = sys.stdout
    if stream.isatty():
        raise UsageError("output '-' is standard output, which is a terminal; redirect it to a "
                         "file or a pipe, or give a file name")
    if getattr(stream, "buffer", None) is None:
        raise UsageError("output '-': standard output does not take bytes here; give a file name")
    return stream.buffer


def atomic_write(path, write):
    """Write an output file from ``write(fileobj)`` (a callable given a binary
    file object), after checking the path as a command-line argument.

    The bytes are prepared in memory first (an exception in ``write`` writes
    nothing), then written by `renderer.files.write_bytes`: a path that is
    absent or a regular file is replaced atomically (a temporary file in its
    directory, then `os.replace`; on any exception, KeyboardInterrupt
    included, ``path`` is untouched and no temporary file is left), and so
    is the final target of a symbolic link to a regular file; a character
    device or FIFO (``/dev/null``), or a link to one (``/dev/stdout`` on a
    pipe), is written through and stays what it was.  ``path`` ``-`` writes the bytes to standard output.
    New files get 0666 & ~umask permissions.

    Raises
    ------
    UsageError
        If ``path`` is empty, ends in ``/``, is a directory, a block device, a
        socket or a dangling symbolic link, or its directory does not exist; or if it
        is ``-`` and standard output is a terminal.
    OSError
        If the directory or the target cannot be written (naming ``path``).
    """
    stream = _stdout_bytes() if path == STDOUT else None
    if stream is None:
        _check_output(path, "output")
    buf = io.BytesIO()
    write(buf)
    _stop_if_interrupted()                # a Ctrl-C a C callback dropped while the bytes were made
    if stream is not None:
        sys.stdout.flush()
        stream.write(buf.getbuffer())
        stream.flush()
        return
    try:
        files.write_bytes(path, buf.getbuffer())
    except files.RefusedPath as exc:  # changed since checked
        raise UsageError(f"output {exc}") from None


def _png_bytes_writer(rgb8):
    def write(f):
        import matplotlib.image
        # No tEXt chunks at all ("Software" is matplotlib's only default key),
        # so the bytes depend on the pixels alone.
        matplotlib.image.imsave(f, rgb8, format="png", metadata={"Software": None})
    return write


def write_png(path, rgb):
    """Write an (H, W, 3) float image with values in [0, 1] (already display-
    encoded) as an 8-bit PNG without varying metadata, by `atomic_write`
    (``-`` is standard output).

    Raises
    ------
    UsageError, OSError
        As `atomic_write`.
    """
    rgb8 = np.round(np.clip(np.asarray(rgb, dtype=np.float64), 0.0, 1.0) * 255.0).astype(np.uint8)
    atomic_write(path, _png_bytes_writer(rgb8))


def _check_output(path, flag):
    """Fail fast, before any work, on an output path that cannot be written:
    ``-`` on a terminal; an empty path, a trailing ``/``, a directory, a
    block device, a socket or a dangling link; a new or regular file (or
    the regular file a link leads to) whose directory is missing or not
    writable; a device or FIFO that is not writable (its directory need not
    be writable)."""
    if path == STDOUT:
        try:
            _stdout_bytes()
        except UsageError as exc:
            raise UsageError(f"{flag} {str(exc).removeprefix('output ')}") from None
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


def _progress(iterable=None, **kwargs):
    """A tqdm bar on stderr, shown only when stderr is a terminal and the work
    takes more than a second."""
    from tqdm import tqdm
    return tqdm(iterable, file=sys.stderr, disable=not sys.stderr.isatty(), delay=1.0,
                leave=False, **kwargs)


def _show_progress():
    return sys.stderr.isatty()


def _fmt(x):
    return "nan" if isinstance(x, float) and math.isnan(x) else f"{x:.3e}"


def _ledger_lines(led):
    return [
        "ledger (central vs exact, sphere A)",
        f"  max |dI|            {_fmt(led.max_abs)}",
        f"  RMS |dI|            {_fmt(led.rms)}",
        f"  flips               {led.flips}",
        f"  pixels on A         {led.pixels_a}",
        f"  mean |dI| on band   {_fmt(led.mean_abs_kink)}",
        f"  mean |dI| off band  {_fmt(led.mean_abs_off_kink)}",
    ]


# ---------------------------------------------------------------- subcommands


def view_image(view, selected, numeric, symbolic):
    """The display image (H, W, 3) float64 in [0, 1] of a view (as the §4 simulator).

    shaded: ``to_srgb(selected.image)``.  difference: ``clip(100 |I_central -
    I_exact|, 0, 1)`` per channel (not sRGB-encoded, as book/s4_simulator.md).
    bump: ``to_srgb(|grad h| / max over A of the exact |grad h|)`` on sphere A,
    black elsewhere.  kink: the selected image sRGB-encoded and dimmed to 40 %,
    the exact frame's crease band painted white.
    """
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


def _cmd_render(args, out):
    from renderer.ledger import compare
    from renderer.render import render
    width, height = args.size
    _check_budget(width, height, 2, "render")
    _check_output(args.output, "-o")
    if args.output == STDOUT:  # the PNG takes stdout; the report goes to stderr
        out = sys.stderr
    scene = load_scene(args.scene, args.set)
    frames = {}
    wanted = ("central", "exact") + (() if args.gradient in ("central", "exact") else (args.gradient,))
    for g in _progress(wanted, desc="render", unit="frame"):
        frames[g] = render(scene, width, height, gradient=g)
    numeric, symbolic = frames["central"], frames["exact"]
    selected = frames[args.gradient]
    write_png(args.output, view_image(args.view, selected, numeric, symbolic))
    where = "standard output" if args.output == STDOUT else args.output
    print(f"wrote {where} ({width}x{height}, view {args.view}, gradient {args.gradient})", file=out)
    print("\n".join(_ledger_lines(compare(numeric, symbolic))), file=out)
    return 0


_CENSUS_COLUMNS = ("eps", "max_abs", "rms", "flips", "pixels_a", "mean_abs_kink", "mean_abs_off_kink")


def _run_sweep(scene, steps, width, height):
    """The census of `renderer.sweep` over ``steps``."""
    from renderer.sweep import sweep
    return list(sweep(scene, steps, width, height).census)


def _cmd_sweep(args, out):
    steps = args.eps
    width, height = args.size
    _check_budget(width, height, len(steps) + 1, "sweep")
    scene = load_scene(args.scene, args.set)
    census = _run_sweep(scene, steps, width, height)
    _stop_if_interrupted()
    rows = [dict(zip(_CENSUS_COLUMNS, (e, led.max_abs, led.rms, led.flips, led.pixels_a,
                                       led.mean_abs_kink, led.mean_abs_off_kink)))
            for e, led in zip(steps, census)]
    if args.format == "json":
        clean = lambda x: None if isinstance(x, float) and math.isnan(x) else x  # noqa: E731
        doc = {"size": [width, height], "height_field": scene.height_field,
               "rows": [{k: clean(v) for k, v in r.items()} for r in rows]}
        print(json.dumps(doc, indent=1, allow_nan=False), file=out)
    elif args.format == "csv":
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(_CENSUS_COLUMNS)
        for r in rows:
            w.writerow([repr(r[k]) if isinstance(r[k], float) else r[k] for k in _CENSUS_COLUMNS])
        out.write(buf.getvalue())
    else:
        print(f"census: {scene.height_field}, beta {scene.beta:g}, {width}x{height}, central vs exact on sphere A",
              file=out)
        print(f"{'eps':>9}  {'max |dI|':>9}  {'RMS |dI|':>9}  {'flips':>5}  {'on band':>9}  {'off band':>9}",
              file=out)
        for r in rows:
            print(f"{r['eps']:9.2e}  {_fmt(r['max_abs']):>9}  {_fmt(r['rms']):>9}  {r['flips']:5d}  "
                  f"{_fmt(r['mean_abs_kink']):>9}  {_fmt(r['mean_abs_off_kink']):>9}", file=out)
    return 0


def _measure_ucurve(args):
    from .ucurve import UNIT_ROUNDOFF, UCurve, fit_model, measure
    steps = np.asarray(args.eps, dtype=np.float64)
    kw = dict(field=args.field, u=args.u, v=args.v, component=args.component, k_u=args.k_u, k_v=args.k_v)
    if not _show_progress() or steps.size < 50:
        return measure(eps=steps, **kw)
    parts = []
    with _progress(total=steps.size, desc="ucurve", unit="step") as bar:
        for chunk in np.array_split(steps, math.ceil(steps.size / 25)):
            parts.append(measure(eps=chunk, **kw))
            bar.update(chunk.size)
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts])  # noqa: E731
    error = cat("error")
    best = int(np.argmin(error))
    p0 = parts[0]
    reason = getattr(p0, "reason", None)
    opt = (float("nan"),) * 2 if reason is not None else (float(steps[best]), float(error[best]))
    fit = (float("nan"),) * 4
    if reason is None:
        with contextlib.suppress(ValueError):
            A, B = fit_model(steps, error, start=(max(abs(p0.third_derivative), 1e-300) / 6, UNIT_ROUNDOFF))
            e_fit = (B / (2 * A)) ** (1 / 3)
            fit = (A, B, e_fit, A * e_fit**2 + B / e_fit)
    return UCurve(p0.field, p0.u, p0.v, p0.component, steps, error, cat("truncation"), cat("roundoff"),
                  cat("model"), p0.derivative, p0.third_derivative, p0.eps_opt_predicted, *opt, reason, *fit)


def _ucurve_plot_writer(uc):
    def write(f):
        import matplotlib
        from matplotlib.figure import Figure
        with matplotlib.rc_context({"svg.hashsalt": "symrender", "path.simplify": False}):
            fig = Figure(figsize=(6.0, 4.0), dpi=100)
            ax = fig.subplots()
            floor = np.finfo(float).tiny
            ax.loglog(uc.eps, np.maximum(uc.error, floor), "k.-", label="measured |error|")
            ax.loglog(uc.eps, np.maximum(np.abs(uc.truncation), floor), "C0--", label="|truncation|")
            ax.loglog(uc.eps, np.maximum(np.abs(uc.roundoff), floor), "C3--", label="|roundoff|")
            ax.loglog(uc.eps, uc.model, "C2:", label="model eps^2|h'''|/6 + u|h|/eps")
            if math.isfinite(uc.eps_opt_predicted):
                ax.axvline(uc.eps_opt_predicted, color="0.6", lw=0.8, label="predicted eps*")
            ax.set_xlabel("eps (chart units)")
            ax.set_ylabel(f"|error| of h_{uc.component}")
            ax.set_title(f"U-curve: {uc.field} at (u, v) = ({uc.u:g}, {uc.v:g})"
                         + (" (not differentiable there)" if uc.reason else ""))
            ax.legend(fontsize=7)
            fig.tight_layout()
            fig.savefig(f, format="png", metadata={"Software": None})
    return write


def _cmd_ucurve(args, out):
    if args.plot is not None:
        _check_output(args.plot, "--plot")
        if args.plot == STDOUT:  # the plot takes stdout; the table goes to stderr
            out = sys.stderr
    for name in ("u", "v"):
        x = getattr(args, name)
        if not (math.isfinite(x) and 0.0 <= x <= 1.0):
            raise UsageError(f"--{name} must be a number in [0, 1], got {x!r}")
    from renderer.scene import MAX_FREQUENCY
    for name in ("k_u", "k_v"):
        x = getattr(args, name)
        if not (math.isfinite(x) and 0.0 < x <= MAX_FREQUENCY):
            raise UsageError(f"--{name.replace('_', '-')} must be a finite number in "
                             f"(0, {MAX_FREQUENCY:g}], got {x!r}")
    uc = _measure_ucurve(args)
    _stop_if_interrupted()
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
        print(f"true derivative {uc.derivative:.17g}; |h'''| = {abs(uc.third_derivative):.6g}", file=out)
        print(f"{'eps':>9}  {'truncation':>11}  {'roundoff':>11}  {'|error|':>10}  {'model':>10}", file=out)
        for i in range(uc.eps.size):
            print(f"{uc.eps[i]:9.2e}  {uc.truncation[i]:11.3e}  {uc.roundoff[i]:11.3e}  "
                  f"{uc.error[i]:10.3e}  {uc.model[i]:10.3e}", file=out)
        print(f"eps* predicted {uc.eps_opt_predicted:.3e}; measured minimum {uc.error_at_measured_opt:.3e} "
              f"at eps {uc.eps_opt_measured:.3e}", file=out)
    if args.plot is not None:
        atomic_write(args.plot, _ucurve_plot_writer(uc))
        print(f"wrote {'standard output' if args.plot == STDOUT else args.plot}", file=out)
    return 0


def _repo_root():
    return Path(__file__).resolve().parent.parent


def _sigint_noted():
    """Context manager for `_cmd_verify`: while pytest runs, a SIGINT that
    `main` would raise as KeyboardInterrupt is only noted (the list it yields
    gets an entry); afterwards SIGINT is ignored if one was noted, as after
    `main`'s first, and the caller raises the interrupt.

    pytest runs in symrender's process group, so a Ctrl-C at the terminal
    reaches it as well: it stops its tests, tears down and exits with 2, and symrender waits for that.  Raising
    at once instead would make `subprocess.run` kill pytest a quarter
    second later, cutting its clean-up short.  (A SIGINT sent to symrender
    alone does not stop pytest: the run then ends first.)  Outside `main`'s
    handling it changes nothing.
    """
    import contextlib

    @contextlib.contextmanager
    def noting():
        noted = []
        if signal.getsignal(signal.SIGINT) is not _interrupt_once:
            yield noted
            return
        signal.signal(signal.SIGINT, lambda signum, frame: noted.append(signum))
        try:
            yield noted
        finally:
            signal.signal(signal.SIGINT, signal.SIG_IGN if noted else _interrupt_once)

    return noting()


def _cmd_verify(args, out):
    root = _repo_root()
    if not (root / "verify").is_dir():
        raise UsageError(f"verify needs a source checkout: {str(root / 'verify')!r} not found")
    cmd = [sys.executable, "-m", "pytest", "verify", "-q", "-p", "no:cacheprovider"]
    if args.k is not None:
        cmd += ["-k", args.k]
    out.flush()
    with _sigint_noted() as noted:
        proc = subprocess.run(cmd, cwd=root, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if noted:
        raise KeyboardInterrupt
    out.write(proc.stdout)
    return proc.returncode


# ---------------------------------------------------------------- figures


def _book_pages(book):
    """Page names of the book in table-of-contents order (book/_toc.yml)."""
    import yaml
    toc = yaml.safe_load((book / "_toc.yml").read_text())
    pages = [toc["root"]]
    for ch in toc.get("chapters", []):
        pages.append(ch["file"])
    return pages


def _code_version(root):
    """The code a run used: git commit (and whether the tree differs from it)
    and a SHA-256 over the sources that make figures (renderer/, proofs/, book
    pages), so a manifest says which code it came from without timestamps."""
    digest = hashlib.sha256()
    files = sorted([*root.glob("renderer/**/*.py"), *root.glob("renderer/js/*.js"),
                    *root.glob("proofs/*.py"), *root.glob("book/*.md"), *root.glob("book/_toc.yml")])
    for f in files:
        digest.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
    version = {"source_sha256": digest.hexdigest(), "git_commit": None, "git_dirty": None}
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True)
        if head.returncode == 0:
            version["git_commit"] = head.stdout.strip()
            st = subprocess.run(["git", "status", "--porcelain", "--", "renderer", "proofs", "book"],
                                cwd=root, capture_output=True, text=True)
            version["git_dirty"] = bool(st.stdout.strip()) if st.returncode == 0 else None
    except OSError:
        pass
    return version


def _png_pixels(data):
    """Decode PNG bytes to an (H, W, 4) uint8 RGBA array."""
    import matplotlib.image
    rgba = matplotlib.image.imread(io.BytesIO(data), format="png")
    if rgba.dtype != np.uint8:
        rgba = np.round(np.clip(rgba, 0, 1) * 255).astype(np.uint8)
    if rgba.ndim == 2:
        rgba = np.repeat(rgba[..., None], 3, axis=2)
    if rgba.shape[2] == 3:
        rgba = np.concatenate([rgba, np.full(rgba.shape[:2] + (1,), 255, np.uint8)], axis=2)
    return rgba


#: A book code cell with this tag draws measured run times: its figures are
#: recorded with "varies" in the manifest, and --check reports them without failing.
VARIES_TAG = "measured-timing"


def _kernel_loop():
    """A new asyncio event loop on which nbclient cannot take SIGINT over.

    `nbclient.NotebookClient.async_execute` installs a SIGINT handler on the
    running loop that shuts the kernel down and lets the run go on (to fail
    later with a dead kernel).  This loop refuses signal handlers with
    RuntimeError, which nbclient takes as "no signal handlers here", so a
    Ctrl-C stays `main`'s: a KeyboardInterrupt out of ``run_until_complete``.
    """
    import asyncio

    class Loop(asyncio.SelectorEventLoop):
        def add_signal_handler(self, sig, callback, *args):
            raise RuntimeError("symrender handles signals itself")

    return Loop()


def _close_loop(loop):
    """Cancel the tasks still pending on ``loop`` (nbclient's pollers of a
    cancelled cell), let them finish, and close it, as `asyncio.run` does."""
    import asyncio
    try:
        pending = asyncio.all_tasks(loop)
        for task in pending:
            task.cancel()
        if pending:
            loop.run_until_complete(asyncio.gather(*pending, return_exceptions=True))
        loop.run_until_complete(loop.shutdown_asyncgens())
    finally:
        loop.close()


def _stop_kernel(loop, run, client):
    """After a Ctrl-C during ``run`` (the task of ``client.async_execute``):
    end the run and shut its kernel down, whatever the moment.

    Cancelling the run unwinds nbclient's kernel context, whose clean-up
    (jupyter_client's graceful shutdown) interrupts the kernel and asks it to
    shut down, so that its own clean-up runs;
    a kernel still busy (say, drawing a figure) after half of
    ``shutdown_wait_time`` (5 s) gets SIGTERM, after all of it SIGKILL.  A
    Ctrl-C while the kernel was still starting comes before nbclient arms
    that clean-up; then the kernel is killed here.  SIGINT is ignored
    meanwhile (`main`).
    """
    import atexit
    import warnings
    # A Ctrl-C while the kernel starts can land between nbclient creating a
    # coroutine and awaiting it; the abandoned coroutine would be reported
    # when it is collected at exit, after our one line.  It is abandoned on
    # purpose here.
    warnings.filterwarnings("ignore", message="coroutine .* was never awaited", category=RuntimeWarning)
    if not run.done():
        run.cancel()
        try:
            loop.run_until_complete(run)
        except BaseException:  # noqa: BLE001 - CancelledError, or the run's own failure
            pass
    km = client.km
    if km is not None:
        # The kernel is killed by its manager (which also removes the
        # connection file), not through nbclient's clean-up: that one stops
        # the client's channels and terminates their zmq context, and a
        # context whose channels were still being set up can block that
        # forever (seen here: zmq's term() never returned, also from the
        # client's __del__).  The client's context is left to the process,
        # which `main` ends with os._exit after an interrupt.
        try:
            loop.run_until_complete(km.shutdown_kernel(now=True))
        except Exception:  # noqa: BLE001 - kill the process then
            if getattr(km, "provisioner", None) is not None:
                try:
                    loop.run_until_complete(km.provisioner.kill())
                except Exception:  # noqa: BLE001 - nothing more to try
                    pass
        finally:
            km.cleanup_connection_file()
    # nbclient registers its clean-up with atexit and unregisters it only on
    # its normal way out; at exit it would fail on the manager already gone.
    atexit.unregister(client._cleanup_kernel)


def _page_figures(book, page):
    """Execute one book page (a MyST notebook) in a fresh kernel; yield
    (figure id, code-cell ordinal, cell source, PNG bytes, cell tags) for every
    PNG it displays or glues.

    The kernel (ipykernel, started by jupyter_client in a session of its
    own, so a terminal's Ctrl-C does not reach it) runs on an event loop of
    its own (`_kernel_loop`); on a KeyboardInterrupt it is shut down before
    the interrupt goes on (`_stop_kernel`).

    Raises
    ------
    UsageError
        If a cell fails (the page's exception, in one line).
    KeyboardInterrupt
        After the kernel has been shut down.
    """
    import base64

    import nbclient
    from myst_nb.core.read import read_myst_markdown_notebook

    path = book / f"{page}.md"
    nb = read_myst_markdown_notebook(path.read_text(encoding="utf-8"), path=path)
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(book)}})
    loop = _kernel_loop()
    try:
        run = loop.create_task(client.async_execute(stderr=subprocess.DEVNULL))
        try:
            loop.run_until_complete(run)
        except KeyboardInterrupt:
            _stop_kernel(loop, run, client)
            raise
        except nbclient.exceptions.CellExecutionError as exc:
            raise UsageError(f"figures: page {page} failed: {exc.ename}: {exc.evalue}") from None
    finally:
        _close_loop(loop)
    ordinal = 0
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        ordinal += 1
        j = 0
        for o in cell.get("outputs", []):
            data = o.get("data", {})
            key = next((k for k in data if k == "image/png" or k.endswith("record/image/png")), None)
            if key is None:
                continue
            meta = o.get("metadata", {})       # proofs.page.show names its figure outside a book build
            glue = ((meta.get("scrapbook") or {}).get("name") or (meta.get("symrender") or {}).get("figure"))
            j += 1
            fid = f"{page}-{glue}" if glue else f"{page}-cell{ordinal:02d}-{j}"
            tags = tuple(cell.get("metadata", {}).get("tags", ()))
            yield fid, ordinal, cell.source, base64.b64decode(data[key]), tags


def _resolve_pages(pages):
    """The book's pages to run: all (None) or the named ones, by name or by
    section prefix (s4 -> s4_simulator)."""
    all_pages = _known_pages()
    if pages is None:
        return all_pages
    resolved = []
    for p in pages:  # a page by name or by its section prefix: s4 -> s4_simulator
        match = [q for q in all_pages if q == p or q.startswith(f"{p}_")]
        if len(match) != 1:
            raise UsageError(f"--pages: unknown page {p!r}; pages are {', '.join(all_pages)}")
        resolved.append(match[0])
    return resolved


def _render_figures(out_dir, pages):
    """Execute the book's ``pages`` and write every figure into ``out_dir``
    (PNG, re-encoded from its pixels without metadata) plus ``manifest.json``.
    Returns the manifest (a dict)."""
    root = _repo_root()
    book = root / "book"
    figures = []
    for page in _progress(pages, desc="figures", unit="page"):
        for fid, ordinal, source, png, tags in _page_figures(book, page):
            rgba = _png_pixels(png)
            name = _figure_file_name(fid, {f["file"] for f in figures})
            data = _png_bytes(rgba)
            files.write_bytes(out_dir / name, data)
            entry = {"id": fid, "page": page, "code_cell": ordinal, "file": name,
                     "width": int(rgba.shape[1]), "height": int(rgba.shape[0]),
                     "sha256": hashlib.sha256(data).hexdigest(),
                     "cell_sha256": hashlib.sha256(source.encode()).hexdigest()}
            if VARIES_TAG in tags:
                # A plot of measured run times: it cannot repeat bit for bit.
                entry["varies"] = "measured timing"
            figures.append(entry)
    manifest = {"code_version": _code_version(root), "pages": list(pages), "figures": figures}
    text = json.dumps(manifest, indent=1, sort_keys=True) + "\n"
    files.write_bytes(out_dir / "manifest.json", text.encode())
    return manifest


def _write_figures_staged(out_dir, pages):
    """Run `_render_figures` into a staging directory beside ``out_dir``, then
    move the result in (the whole directory if ``out_dir`` is new, else file by
    file with manifest.json last).  A failed or interrupted run removes the
    staging directory and leaves ``out_dir`` as it was."""
    import shutil
    try:
        staging = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name[:64]}.", suffix=".part"))
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, str(out_dir)) from None
    try:
        manifest = _render_figures(staging, pages)
        _stop_if_interrupted()
        try:
            os.chmod(staging, 0o777 & ~files.umask())
            if not out_dir.exists():
                os.replace(staging, out_dir)
            else:
                names = sorted(p.name for p in staging.iterdir() if p.name != "manifest.json")
                for name in [*names, "manifest.json"]:
                    os.replace(staging / name, out_dir / name)
        except OSError as exc:
            raise OSError(exc.errno, exc.strerror, str(out_dir)) from None
        return manifest
    finally:
        shutil.rmtree(staging, ignore_errors=True)


#: Largest manifest.json that ``figures --check`` reads (bytes); the whole
#: book's manifest is a few KiB.
MAX_MANIFEST_BYTES = 1 << 20
#: Largest previous figure file that ``--check`` reads (bytes); a book figure
#: is some tens of KiB, and an 8192^2 RGBA PNG that does not compress at all
#: is 256 MiB, far beyond any figure worth comparing.
MAX_FIGURE_BYTES = 64 << 20
#: Largest side (pixels) of a figure a manifest may declare.
MAX_FIGURE_SIDE = 8192
#: A figure file: a plain name inside the directory.
_FIGURE_FILE = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9._-]*\.png\Z")
_SHA256 = re.compile(r"[0-9a-f]{64}\Z")
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

#: Figures whose previous and fresh pixels differ by at most this many 8-bit
#: levels in every channel, on at most `CHECK_TOLERANCE_FRACTION` of their
#: pixels, are reported "within tolerance" and do not fail ``--check``.
#: Bit-identity cannot hold across machines: numpy picks a SIMD loop for
#: pow, exp, sin and log at run time from what the CPU offers, and the loops
#: round differently in the last bit.  A figure that plots such values (the
#: U-curve's step grid from logspace, a roundoff measured in float64) then
#: moves its lines by a small fraction of a pixel; only the antialiased edge
#: pixels change, and, along a dashed or dotted line, the phase of every dash,
#: each by part of the line's contrast.  A real change of a figure (a curve
#: that moves by a pixel, a different image) changes more pixels or more
#: levels than that.  `make test-baseline-simd` and ``figures --check`` across
#: ``NPY_DISABLE_CPU_FEATURES`` settings show the differences that occur.
CHECK_TOLERANCE_LEVELS = 32
#: See `CHECK_TOLERANCE_LEVELS`: the most pixels, as a fraction of the
#: figure, that may differ for it to count as within tolerance.
CHECK_TOLERANCE_FRACTION = 0.02


def _figure_file_name(fid, taken):
    """A plain file name for figure ``fid`` (characters outside [A-Za-z0-9._-]
    become ``_``), distinct from the names in ``taken``."""
    base = re.sub(r"[^A-Za-z0-9._-]", "_", fid).lstrip(".").replace("..", "_") or "figure"
    name, k = f"{base}.png", 1
    while name in taken:
        k += 1
        name = f"{base}-{k}.png"
    return name


def _png_bytes(rgb8):
    """PNG bytes of an (H, W, 3 or 4) uint8 image, without metadata."""
    buf = io.BytesIO()
    _png_bytes_writer(rgb8)(buf)
    return buf.getvalue()


def _known_pages():
    book = _repo_root() / "book"
    if not (book / "_toc.yml").is_file():
        raise UsageError(f"figures needs a source checkout: {str(book / '_toc.yml')!r} not found")
    return _book_pages(book)


def _manifest_error(path, what):
    return UsageError(f"--check: {str(path)!r} is not a valid symrender manifest: {what}")


def _validate_manifest(doc, path, known_pages):
    """Check a parsed manifest's structure; return ``(figures by id, pages)``."""
    bad = lambda what: _manifest_error(path, what)  # noqa: E731
    if not isinstance(doc, dict):
        raise bad(f"a JSON object is needed, got {type(doc).__name__}")
    pages = doc.get("pages")
    if not (isinstance(pages, list) and pages and all(isinstance(p, str) for p in pages)):
        raise bad('"pages" must be a non-empty list of page names')
    unknown = [p for p in pages if p not in known_pages]
    if unknown:
        raise bad(f"unknown page {unknown[0][:80]!r} in \"pages\"; pages are {', '.join(known_pages)}")
    version = doc.get("code_version", {})
    if not (isinstance(version, dict)
            and all(isinstance(version.get(k), (str, type(None))) for k in ("git_commit", "source_sha256"))):
        raise bad('"code_version" must be an object with string git_commit and source_sha256')
    entries = doc.get("figures")
    if not isinstance(entries, list):
        raise bad('"figures" must be a list')
    figures, names = {}, set()
    for i, f in enumerate(entries):
        if not isinstance(f, dict):
            raise bad(f"figures[{i}] must be an object")
        for key in ("id", "file", "sha256"):
            if not isinstance(f.get(key), str) or not f[key]:
                raise bad(f"figures[{i}].{key} must be a non-empty string")
        for key in ("width", "height"):
            v = f.get(key)
            if type(v) is not int or not 1 <= v <= MAX_FIGURE_SIDE:
                raise bad(f"figures[{i}].{key} must be an integer in [1, {MAX_FIGURE_SIDE}], got {v!r:.40}")
        name = f["file"]
        if not _FIGURE_FILE.match(name) or ".." in name:
            raise bad(f"figures[{i}].file {name[:80]!r} must be a plain file name in the directory "
                      "(letters, digits, '.', '_', '-', ending .png; no '/' or '..')")
        if not _SHA256.match(f["sha256"]):
            raise bad(f"figures[{i}].sha256 must be 64 lowercase hex digits")
        if not isinstance(f.get("varies", ""), str):
            raise bad(f"figures[{i}].varies must be a string")
        if f["id"] in figures:
            raise bad(f"figure id {f['id'][:80]!r} appears twice")
        if name in names:
            raise bad(f"file {name!r} is listed twice")
        figures[f["id"]] = f
        names.add(name)
    return figures, pages


def _read_figure(old_dir, entry):
    """The bytes of a previous figure file, checked against its manifest entry:
    a regular file (not a link) of at most `MAX_FIGURE_BYTES`, with the
    manifest's SHA-256, a PNG whose header declares the manifest's size."""
    path = Path(old_dir) / entry["file"]
    try:
        data = files.read_regular(path, MAX_FIGURE_BYTES, follow=False)
    except files.RefusedPath as exc:
        raise UsageError(f"--check: figure {entry['id']!r}: {exc}") from None
    except OSError as exc:
        raise UsageError(f"--check: figure {entry['id']!r}: cannot read {str(path)!r}: "
                         f"{exc.strerror or exc}") from None
    if hashlib.sha256(data).hexdigest() != entry["sha256"]:
        raise UsageError(f"--check: {str(path)!r} does not match its sha256 in manifest.json "
                         "(the directory was changed after it was written)")
    size = (int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big"))
    if data[:8] != _PNG_SIGNATURE or data[12:16] != b"IHDR" or size != (entry["width"], entry["height"]):
        raise UsageError(f"--check: {str(path)!r} is not a {entry['width']}x{entry['height']} PNG, "
                         "as manifest.json says")
    return data


def _decode_figure(data, what):
    """`_png_pixels` of a checked figure; a corrupt PNG is a usage error."""
    try:
        return _png_pixels(data)
    except Exception as exc:  # PIL and matplotlib raise many kinds on bad data
        raise UsageError(f"--check: {what} is not a readable PNG ({type(exc).__name__})") from None


def _load_manifest(old_dir, known_pages):
    """Read and validate ``old_dir/manifest.json`` and every figure file it lists
    before any page runs.

    Returns
    -------
    (doc, figures, pages) : the manifest (dict), its figure entries by id, its page names.

    Raises
    ------
    UsageError
        If manifest.json is not a regular file (a link, FIFO or device) of
        at most `MAX_MANIFEST_BYTES`, not UTF-8 JSON, or not a manifest: an
        object with a non-empty list of known ``pages`` and a list of
        ``figures``, each with a unique string ``id``, a plain ``file`` name
        inside ``old_dir``, a 64-hex-digit ``sha256`` and integer ``width``,
        ``height`` in [1, 8192]; or if a listed file is not a regular file of
        at most `MAX_FIGURE_BYTES`, does not match its sha256, or is not a
        PNG of the stated size.
    """
    if not str(old_dir):
        raise UsageError("--check: the directory path is empty")
    path = Path(old_dir) / "manifest.json"
    try:
        raw = files.read_regular(path, MAX_MANIFEST_BYTES, follow=False)
    except files.RefusedPath as exc:
        raise UsageError(f"--check: {exc}") from None
    except OSError as exc:
        raise UsageError(f"--check: cannot read {str(path)!r}: {exc.strerror or exc}") from None
    try:
        doc = json.loads(raw.decode("utf-8"))
    except (ValueError, RecursionError) as exc:  # bad UTF-8, bad JSON, nesting too deep
        raise _manifest_error(path, f"not JSON ({_one_line(exc)[:120]})") from None
    figures, pages = _validate_manifest(doc, path, known_pages)
    for entry in figures.values():
        _read_figure(old_dir, entry)
    for entry in figures.values():
        _decode_figure(_read_figure(old_dir, entry), repr(str(Path(old_dir) / entry["file"])))
    return doc, figures, pages


def compare_figure(old_png, new_png):
    """Compare a previous figure with a fresh one.

    Parameters
    ----------
    old_png, new_png : bytes
        PNG files (any size; decoded to 8-bit RGBA).

    Returns
    -------
    verdict : {"unchanged", "within tolerance", "changed"}
        ``"unchanged"`` if the bytes are equal; ``"within tolerance"`` if the
        sizes agree and every channel differs by at most
        `CHECK_TOLERANCE_LEVELS` of 255 on at most `CHECK_TOLERANCE_FRACTION`
        of the pixels; else ``"changed"``.
    how : str
        The size change, or the largest per-channel difference (as a fraction
        of full scale) and the number of pixels that differ; empty when unchanged.
    """
    if old_png == new_png:
        return "unchanged", ""
    a, b = _png_pixels(old_png), _png_pixels(new_png)
    if a.shape != b.shape:
        return "changed", f"size {a.shape[1]}x{a.shape[0]} -> {b.shape[1]}x{b.shape[0]}"
    d = np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=2)
    levels, count = int(d.max()), int(np.count_nonzero(d))
    how = f"max |dI| = {levels / 255:.4f} ({count:,} pixels differ)"
    within = levels <= CHECK_TOLERANCE_LEVELS and count <= CHECK_TOLERANCE_FRACTION * d.size
    return ("within tolerance" if within else "changed"), how


def _cmd_figures(args, out):
    import fnmatch
    pages = None
    if args.pages is not None:
        pages = [p.strip() for p in args.pages.split(",") if p.strip()]
        if not pages:
            raise UsageError(f"--pages names no page ({args.pages!r}); give names like s1,s4")
    if args.check is None:
        if not args.out or args.out == STDOUT:
            raise UsageError(f"--out {args.out!r}: give a directory to write the figures into")
        out_dir = Path(args.out)
        if out_dir.exists() and not out_dir.is_dir():
            raise UsageError(f"--out {args.out!r} is not a directory")
        if not out_dir.parent.is_dir():
            raise UsageError(f"--out {args.out!r}: directory {str(out_dir.parent)!r} does not exist")
        pages = _resolve_pages(pages)
        manifest = _write_figures_staged(out_dir, pages)
        for f in manifest["figures"]:
            print(f"{f['id']:40s} {f['width']:4d}x{f['height']:<4d} {f['sha256'][:16]}", file=out)
        v = manifest["code_version"]
        print(f"wrote {len(manifest['figures'])} figures and manifest.json to {out_dir} "
              f"(code {v['git_commit'] or 'no git'}{' + local changes' if v['git_dirty'] else ''}, "
              f"sources {v['source_sha256'][:16]})", file=out)
        return 0
    old_doc, old, old_pages = _load_manifest(args.check, _known_pages())
    pages = _resolve_pages(old_pages if pages is None else pages)
    with tempfile.TemporaryDirectory(prefix="symrender-figures-") as tmp:
        tmp = Path(tmp)
        new_doc = _render_figures(tmp, pages)
        new = {f["id"]: f for f in new_doc["figures"]}
        changed = 0
        ignored = lambda fid: any(fnmatch.fnmatchcase(fid, pat) for pat in args.ignore)  # noqa: E731
        for fid in sorted(set(old) | set(new), key=lambda i: (i not in new, i)):
            varies = (old.get(fid) or {}).get("varies") or (new.get(fid) or {}).get("varies")
            tag = " (ignored)" if ignored(fid) else f" ({varies}: varies by run)" if varies else ""
            if fid not in new:
                print(f"removed    {fid}{tag}", file=out)
            elif fid not in old:
                print(f"added      {fid}{tag}", file=out)
            elif old[fid]["sha256"] == new[fid]["sha256"]:
                print(f"unchanged  {fid}", file=out)
                continue
            else:
                verdict, how = compare_figure(_read_figure(args.check, old[fid]),
                                              (tmp / new[fid]["file"]).read_bytes())
                if verdict == "within tolerance":
                    print(f"within tolerance {fid}: {how}", file=out)
                    continue
                print(f"changed    {fid}: {how}{tag}", file=out)
            if not tag:
                changed += 1
    ov, nv = old_doc.get("code_version", {}), new_doc["code_version"]
    commit = lambda c: (c or "no git")[:12]  # noqa: E731
    print(f"code: previous {commit(ov.get('git_commit'))} sources {str(ov.get('source_sha256'))[:16]}; "
          f"now {commit(nv['git_commit'])}{' + local changes' if nv['git_dirty'] else ''} "
          f"sources {nv['source_sha256'][:16]}", file=out)
    print(f"{changed} figure(s) changed" if changed else "no figure changed", file=out)
    return 1 if changed else 0


# ---------------------------------------------------------------- argument parser


def _size_arg(text):
    try:
        return parse_size(text)
    except UsageError as exc:
        raise argparse.ArgumentTypeError(str(exc).removeprefix("--size ")) from None


def _eps_arg(max_steps, bounds=None):
    def parse(text):
        try:
            return parse_eps(text, name="", max_steps=max_steps, bounds=bounds)
        except UsageError as exc:
            raise argparse.ArgumentTypeError(str(exc).lstrip(": ")) from None
    return parse


def _float_arg(text):
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


def build_parser():
    """The argparse parser of ``symrender`` (one subparser per command)."""
    from renderer.render import MAX_SIDE
    from renderer.scene import HEIGHT_FIELDS
    from renderer.sweep import MAX_STEPS
    limits = (f"Limits: each side 1..{MAX_SIDE}; render at most {MAX_PIXELS:,} pixels (4096^2); "
              f"sweep at most (steps + 1) * W * H <= {FRAME_PIXEL_BUDGET:,}; refused before allocating.")
    p = _Parser(prog="symrender", description="Render, sweep, measure and verify the Chapter-9 scene.",
                epilog=limits)
    p.add_argument("--version", action="version", version=f"symrender {_version()}")
    sub = p.add_subparsers(dest="command", metavar="command", required=True, parser_class=_Parser)

    def scene_opts(sp):
        sp.add_argument("--scene", metavar="FILE.toml",
                        help="TOML file with Scene field names ([[lights]] tables with position, color); "
                             "unknown keys are errors")
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
    r.add_argument("--view", choices=VIEWS, default="shaded",
                   help="shaded image; difference clip(100|dI|); bump |grad h|; kink band over dimmed image")
    r.add_argument("-o", "--output", required=True, metavar="out.png", help="PNG to write (atomically)")

    s = sub.add_parser("sweep", help="eps sweep: census table of central vs exact",
                       description="Render the exact frame and one central frame per step; print the census: "
                                   "eps, max and RMS |dI| on A, flips, mean |dI| on and off the kink band.",
                       epilog=limits)
    scene_opts(s)
    from renderer.scene import MAX_EPS, MIN_EPS
    s.add_argument("--eps", type=_eps_arg(MAX_STEPS, (MIN_EPS, MAX_EPS)), default=parse_eps("1e-1:1e-8:8"),
                   metavar="a:b:n|e1,e2,..",
                   help=f"n log-spaced steps from a to b, or a comma list; 1..{MAX_STEPS} steps, each in "
                        f"[{MIN_EPS:g}, {MAX_EPS:g}] (default 1e-1:1e-8:8)")
    s.add_argument("--size", type=_size_arg, default=(256, 256), metavar="WxH",
                   help="image size (default 256x256); (steps + 1) * W * H <= "
                        f"{FRAME_PIXEL_BUDGET:,}")
    s.add_argument("--format", choices=FORMATS, default="text", help="output format (default text)")

    u = sub.add_parser("ucurve", help="the measured finite-difference U-curve at one chart point",
                       description="Central-difference error against a 50-digit mpmath reference, split "
                                   "into truncation and roundoff, per step (proofs/ucurve.py).")
    u.add_argument("--field", choices=HEIGHT_FIELDS, default="sine")
    u.add_argument("--u", type=_float_arg, default=0.31, help="chart u in [0, 1] (default 0.31)")
    u.add_argument("--v", type=_float_arg, default=0.47, help="chart v in [0, 1] (default 0.47)")
    u.add_argument("--component", choices=("u", "v"), default="u", help="h_u or h_v (default u)")
    u.add_argument("--k-u", dest="k_u", type=_float_arg, default=8.0, help="frequency k_u (default 8)")
    u.add_argument("--k-v", dest="k_v", type=_float_arg, default=4.0, help="frequency k_v (default 4)")
    u.add_argument("--eps", type=_eps_arg(MAX_UCURVE_STEPS), default=parse_eps("1e-1:1e-15:15"),
                   metavar="a:b:n|e1,e2,..",
                   help=f"steps, as for sweep; 1..{MAX_UCURVE_STEPS} (default 1e-1:1e-15:15)")
    u.add_argument("--plot", metavar="out.png", help="also save a log-log plot (PNG, atomically)")

    v = sub.add_parser("verify", help="run the proof checker (pytest verify) and print its ledger",
                       description="Runs `python -m pytest verify` from the repository root; exits with "
                                   "pytest's code.")
    v.add_argument("-k", metavar="EXPR", help="pytest -k expression (select theorems)")

    f = sub.add_parser("figures", help="execute the book's pages; write every figure and a manifest, "
                                       "or --check against a previous manifest",
                       description="Execute each page of the book (book/_toc.yml order) in a fresh kernel "
                                   "and write every PNG figure it displays or glues into DIR, re-encoded "
                                   "without metadata, with manifest.json (figure id, page, code cell, "
                                   "content hash, code version). --check DIR runs afresh and reports each "
                                   "figure that changed and by how much (max |dI|), exiting 1 on a change "
                                   f"of more than {CHECK_TOLERANCE_LEVELS}/255 in a channel or on more "
                                   f"than {CHECK_TOLERANCE_FRACTION:.0%} of a figure's pixels (the "
                                   "tolerance across numpy's SIMD paths); a malformed or "
                                   "tampered DIR is refused before any page runs.")
    what = f.add_mutually_exclusive_group(required=True)
    what.add_argument("--out", metavar="DIR", help="directory to write the figures and manifest.json into")
    what.add_argument("--check", metavar="DIR", help="a previous --out directory to compare a fresh run with")
    f.add_argument("--pages", metavar="s1,s4,...", help="only these pages (default: all; --check: those "
                                                         "of the manifest)")
    f.add_argument("--ignore", action="append", default=[], metavar="ID-PATTERN",
                   help="with --check: report but do not fail on figures matching this pattern "
                        "(e.g. timing plots); repeatable")
    return p


_COMMANDS = {"render": _cmd_render, "sweep": _cmd_sweep, "ucurve": _cmd_ucurve, "verify": _cmd_verify,
             "figures": _cmd_figures}


def _one_line(msg):
    return " ".join(str(msg).split())


#: Whether `_interrupt_once` has run during this `main`.  Python code that C
#: calls back (a ctypes callback: llvmlite's object cache while numba
#: compiles the kernel) cannot pass an exception on: the KeyboardInterrupt
#: raised there is dropped, and the command would go on to write its output.
#: The flag keeps the Ctrl-C: `_stop_if_interrupted` raises it again before
#: anything is written, and `_quiet_dropped_interrupt` keeps the dropped
#: one's "Exception ignored" report off stderr.
_sigint_seen = False


def _interrupt_once(signum, frame):
    """`main`'s SIGINT handler: raise KeyboardInterrupt once, then ignore
    SIGINT, so that a second Ctrl-C cannot cut the clean-up short."""
    global _sigint_seen
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _sigint_seen = True
    raise KeyboardInterrupt


def _stop_if_interrupted():
    """Raise KeyboardInterrupt if a Ctrl-C came during this `main`, even one
    that a C callback dropped; called before every output is written."""
    if _sigint_seen:
        raise KeyboardInterrupt


def _quiet_dropped_interrupt(previous):
    """A `sys.unraisablehook` that drops the report of the KeyboardInterrupt
    `_interrupt_once` raised inside a C callback (the flag has it) and passes
    every other unraisable exception to ``previous``."""
    def hook(unraisable):
        if _sigint_seen and isinstance(unraisable.exc_value, KeyboardInterrupt):
            return
        previous(unraisable)
    return hook


def main(argv=None) -> int:
    """Run ``symrender`` with ``argv`` (default ``sys.argv[1:]``); return the exit code.

    Parameters
    ----------
    argv : list of str or None
        The arguments after the program name.  None means ``sys.argv[1:]``
        and running as the program (the console script, ``python -m
        proofs``): see Ctrl-C below.

    Returns
    -------
    int
        0 on success, 2 on any input error (one line ``symrender: error:
        ...`` on stderr, nothing written), 1 on an unanticipated error (one
        line ``symrender: internal error: ...``), 130 on Ctrl-C, 1 silently
        when stdout is closed early (a broken pipe), 1 when ``figures
        --check`` finds a changed figure, and pytest's code for ``verify``.
        ``--help`` prints to stdout and returns 0.  Never raises.

    Notes
    -----
    Ctrl-C.  `main` takes SIGINT over on entry (unless it is ignored, as in a
    background job): the first SIGINT raises KeyboardInterrupt wherever the
    command is, its imports of numpy, sympy and matplotlib included, and
    SIGINT is ignored from then on, so that a second Ctrl-C cannot cut the
    clean-up short: the partial output file or staging directory is
    removed, the notebook kernel of ``figures`` shut down (`_stop_kernel`).
    While ``verify``'s pytest runs, a SIGINT is noted and pytest, which got
    the same Ctrl-C, is waited for (`_sigint_noted`).  A KeyboardInterrupt
    that a C callback drops (llvmlite's, while numba compiles) is not lost:
    the handler notes it, the command is stopped before it writes anything
    (`_stop_if_interrupted`), and the callback's "Exception ignored" report
    is kept off stderr (`_quiet_dropped_interrupt`; the previous
    `sys.unraisablehook` is restored like the SIGINT handler).  Then one line
    ``symrender: interrupted`` on stderr and 130.

    Called with an argument list (in-process use), `main` restores the
    previous SIGINT handler when it returns.  Run as the program, it leaves
    SIGINT ignored when it returns, as the process is about to exit: a Ctrl-C during the
    interpreter's exit would print an "Exception ignored" traceback.  After
    an interrupt it ends the process with ``os._exit(130)`` once its own
    clean-up has run, without the interpreter's finalizers: that of a
    half-started kernel client can block forever in zmq's term().

    What `main` cannot cover is Python's own start-up before it runs (the
    interpreter, site, and this module's standard-library imports;
    importing this module loads neither numpy nor the renderer): a Ctrl-C
    then gets Python's report.
    """
    as_program = argv is None
    reported = []

    def interrupted():
        if not reported:
            reported.append(True)
            print("symrender: interrupted", file=sys.stderr)
        return 130

    global _sigint_seen
    restore = None  # the SIGINT handler to put back, once main's is in place
    _sigint_seen = False
    previous_hook = sys.unraisablehook
    sys.unraisablehook = _quiet_dropped_interrupt(previous_hook)
    try:
        try:
            try:
                previous = signal.getsignal(signal.SIGINT)
                if previous is not signal.SIG_IGN:
                    signal.signal(signal.SIGINT, _interrupt_once)
                    restore = signal.default_int_handler if previous is None else previous
            except ValueError:  # not the main thread: signals are left alone
                pass
            code = _run(sys.argv[1:] if as_program else list(argv), interrupted)
        except KeyboardInterrupt:  # before the handler was in place, or while an error was reported
            code = interrupted()
        if as_program:
            try:
                if restore is not None:
                    signal.signal(signal.SIGINT, signal.SIG_IGN)
            except KeyboardInterrupt:  # the first one, just before it was ignored
                code = interrupted()
            if code == 130:
                # Our clean-up has run (outputs removed, kernel killed); the
                # interpreter's own finalizers are not waited for: one of a
                # half-started kernel client (zmq's term()) can block forever.
                for stream in (sys.stdout, sys.stderr):
                    try:
                        stream.flush()
                    except (OSError, ValueError):
                        pass
                os._exit(130)
        return code
    finally:
        if not as_program:
            sys.unraisablehook = previous_hook
            if restore is not None:
                signal.signal(signal.SIGINT, restore)


def _run(argv, interrupted):
    """`main` without its signal handling."""
    out = sys.stdout
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit as exc:  # --help (argparse prints, then exits 0)
            return exc.code if isinstance(exc.code, int) else 0
        code = _COMMANDS[args.command](args, out)
        _stop_if_interrupted()
        return code
    except UsageError as exc:
        print(f"symrender: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except (TypeError, ValueError, OverflowError) as exc:  # Scene / render validation
        print(f"symrender: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # stdout closed early (| head): stop quietly, as cat does
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return 1
    except OSError as exc:
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        print(f"symrender: error: {where}{_one_line(exc.strerror or exc)}", file=sys.stderr)
        return 2
    except MemoryError:
        print("symrender: error: out of memory (use a smaller --size)", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return interrupted()
    except Exception as exc:  # a bug: still one line, no traceback
        print(f"symrender: internal error: {type(exc).__name__}: {_one_line(exc)}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
