"""``symrender``: the command line for authors and releases (issue 7).

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
exit code; ``figures --check`` returns 1 when a figure changed.

Reproducibility.  PNG files carry no timestamp, software tag or other varying
metadata, so two runs on the same code give byte-identical files; they are
written atomically (a temporary file in the target directory, then
`os.replace`), so an interrupted or failed run leaves no file behind.

Limits (refused before anything is allocated): each side of ``--size`` in
[1, 8192] (`renderer.render.MAX_SIDE`); ``render`` holds two frames, so at most
``MAX_PIXELS`` = 4096^2 = 16,777,216 pixels; ``sweep`` holds one frame per step
plus one, so (steps + 1) * W * H <= ``FRAME_PIXEL_BUDGET`` = 2 * 4096^2 (a frame
takes about 57 bytes per pixel: about 1.9 GB at the limit).
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import tomllib
from dataclasses import fields as dataclass_fields
from pathlib import Path

import numpy as np

from . import files
from .ledger import compare, to_srgb
from .render import MAX_SIDE, SPHERE_A, render
from .scene import HEIGHT_FIELDS, PointLight, Scene
from .sweep import MAX_STEPS, sweep

__all__ = ["main", "load_scene", "parse_size", "parse_eps", "write_png", "atomic_write",
           "MAX_PIXELS", "FRAME_PIXEL_BUDGET", "MAX_UCURVE_STEPS"]

#: Most pixels `render` accepts (W * H): the two frames of the ledger then take
#: about 2 * 57 bytes * 4096^2 = 1.9 GB.
MAX_PIXELS = 4096 * 4096
#: Most frame-pixels a command holds at once: render holds 2 frames, a sweep of
#: n steps holds n + 1.
FRAME_PIXEL_BUDGET = 2 * MAX_PIXELS
#: Most steps of one U-curve (each step is a 50-digit mpmath evaluation, ~1 ms).
MAX_UCURVE_STEPS = 10_000

VIEWS = ("shaded", "difference", "bump", "kink")
FORMATS = ("text", "csv", "json")
_SCENE_FIELDS = tuple(f.name for f in dataclass_fields(Scene))
_LIGHT_FIELDS = tuple(f.name for f in dataclass_fields(PointLight))
_BARE_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*\Z")


class UsageError(Exception):
    """A bad argument or input: printed as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    """argparse that raises `UsageError` instead of printing usage and exiting."""

    def error(self, message):
        raise UsageError(message)


# ---------------------------------------------------------------- parsing helpers


def parse_size(text):
    """Parse ``"WxH"`` into ``(width, height)`` ints, each in [1, 8192].

    Raises
    ------
    UsageError
        Naming ``--size`` and the text, for anything else (negative or zero
        sides, a side above 8192, not of the form WxH).  The pixel limits of a
        command are checked separately, still before any allocation.
    """
    m = re.fullmatch(r"\s*(\d{1,9})\s*[xX]\s*(\d{1,9})\s*", str(text))
    if not m:
        raise UsageError(f"--size must be WxH with positive integers (e.g. 256x256), got {text!r}")
    w, h = int(m.group(1)), int(m.group(2))
    for name, side in (("width", w), ("height", h)):
        if not 1 <= side <= MAX_SIDE:
            raise UsageError(f"--size {name} must be between 1 and {MAX_SIDE} pixels, got {text!r}")
    return w, h


def _check_budget(width, height, frames, what):
    """Refuse a size whose ``frames`` frames exceed the pixel budget (no allocation)."""
    if width * height > MAX_PIXELS:
        raise UsageError(f"--size {width}x{height} is {width * height:,} pixels; {what} accepts at "
                         f"most {MAX_PIXELS:,} (4096x4096)")
    if frames * width * height > FRAME_PIXEL_BUDGET:
        raise UsageError(
            f"--size {width}x{height} with {frames} frames is {frames * width * height:,} frame-pixels; "
            f"{what} accepts at most {FRAME_PIXEL_BUDGET:,} (use a smaller size or fewer steps)")


def _positive_float(text, name):
    try:
        x = float(text)
    except ValueError:
        raise UsageError(f"{name}: {text!r} is not a number") from None
    if not (math.isfinite(x) and x > 0):
        raise UsageError(f"{name}: each step must be a finite number > 0, got {text!r}")
    return x


def parse_eps(text, *, name="--eps", max_steps=MAX_STEPS):
    """Parse steps: ``"a:b:n"`` (n log-spaced from a to b) or ``"e1,e2,..."``.

    Returns
    -------
    tuple of float, each finite and > 0, chart units; 1 to ``max_steps`` of them.

    Raises
    ------
    UsageError
        Naming ``name``, for a malformed text, a step that is not a finite
        positive number, or a count outside [1, max_steps].
    """
    text = str(text).strip()
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise UsageError(f"{name} must be a:b:n (n log-spaced steps from a to b) or a comma "
                             f"list, got {text!r}")
        a, b = (_positive_float(p, name) for p in parts[:2])
        if not re.fullmatch(r"\s*\d{1,6}\s*", parts[2]):
            raise UsageError(f"{name}: the count n in a:b:n must be a positive integer, got {parts[2]!r}")
        n = int(parts[2])
        if not 1 <= n <= max_steps:
            raise UsageError(f"{name}: the count n must be between 1 and {max_steps}, got {n}")
        # Rounded to 15 significant digits so that decades print as 1e-05, not
        # 9.999999999999999e-06 (a relative change below 1e-15).
        steps = tuple(float(f"{e:.15g}") for e in np.logspace(math.log10(a), math.log10(b), n))
    else:
        items = [p for p in text.split(",")]
        if not 1 <= len(items) <= max_steps:
            raise UsageError(f"{name} must hold 1 to {max_steps} steps, got {len(items)}")
        steps = tuple(_positive_float(p, name) for p in items)
    return steps


def _toml_value(key, text):
    """The value of ``--set key=text``: TOML, or a bare word taken as a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        if _BARE_WORD.match(text):
            return text
        raise UsageError(f"--set {key}: cannot parse {text!r} as a TOML value "
                         f"(quote a string: {key}=\"...\")") from None


def _check_ints(source, name, value):
    """Refuse a TOML integer too large for a float, naming the key.

    TOML integers are unbounded in tomllib; one beyond about 1.8e308 is refused
    here, with the file (or --set) and the key path, before `Scene` sees it.
    """
    if isinstance(value, int) and not isinstance(value, bool):
        try:
            float(value)
        except OverflowError:
            raise UsageError(f"{source}: {name} = {str(value)[:20]}... is too large for a number "
                             f"(more than {len(str(value))} digits)") from None
    elif isinstance(value, list):
        for i, item in enumerate(value):
            _check_ints(source, f"{name}[{i}]", item)
    elif isinstance(value, dict):
        for k, item in value.items():
            _check_ints(source, f"{name}.{k}", item)


def _scene_mapping(data, source):
    """Turn a TOML mapping into `Scene` keyword arguments, refusing unknown keys."""
    out = {}
    for key, value in data.items():
        if key not in _SCENE_FIELDS:
            raise UsageError(f"{source}: unknown scene field {key!r}; fields are {', '.join(_SCENE_FIELDS)}")
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
                unknown = sorted(set(table) - set(_LIGHT_FIELDS))
                if unknown:
                    raise UsageError(f"{source}: unknown light field {unknown[0]!r} in lights[{i}]; "
                                     f"fields are {', '.join(_LIGHT_FIELDS)}")
                lights.append(PointLight(**table))
            value = tuple(lights)
        out[key] = value
    return out


def load_scene(path=None, sets=()):
    """Build a `Scene` from a TOML file and ``key=value`` overrides.

    Parameters
    ----------
    path : str or None
        A TOML file whose top-level keys are `Scene` field names; ``lights``
        is an array of tables ``[[lights]]`` with ``position`` and ``color``.
        Missing fields keep the Scene's defaults (the seed's, Cell 1).
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
        Unreadable file, malformed TOML, an unknown key (named), or a
        malformed ``--set``.
    TypeError, ValueError
        From `Scene`/`PointLight` validation (the message names the field).
    """
    data = {}
    if path is not None:
        try:
            raw = Path(path).read_bytes()
        except OSError as exc:
            raise UsageError(f"--scene: cannot read {path!r}: {exc.strerror or exc}") from None
        try:
            data = tomllib.loads(raw.decode("utf-8"))
        except UnicodeDecodeError:
            raise UsageError(f"--scene {path}: not UTF-8 text") from None
        except tomllib.TOMLDecodeError as exc:
            raise UsageError(f"--scene {path}: malformed TOML: {exc}") from None
        data = _scene_mapping(data, f"--scene {path}")
    for item in sets:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise UsageError(f"--set must be key=value, got {item!r}")
        if key not in _SCENE_FIELDS:
            raise UsageError(f"--set: unknown scene field {key!r}; fields are {', '.join(_SCENE_FIELDS)}")
        data.update(_scene_mapping({key: _toml_value(key, text.strip())}, "--set"))
    return Scene(**data)


# ---------------------------------------------------------------- output helpers


def atomic_write(path, write):
    """Write a file atomically: ``write(fileobj)`` into a temporary file in the
    target directory, then `os.replace` it onto ``path`` (`renderer.files`),
    after checking the path as a command-line argument.

    On any exception (including KeyboardInterrupt) the temporary file is
    removed and the exception propagates; ``path`` is then untouched (absent
    if it did not exist).  The file gets the usual 0666 & ~umask permissions.

    Raises
    ------
    UsageError
        If ``path`` is a directory or its directory does not exist.
    OSError
        If the directory cannot be written.
    """
    target = Path(path)
    if target.is_dir():
        raise UsageError(f"output {str(path)!r} is a directory")
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"output {str(path)!r}: directory {str(parent)!r} does not exist")
    files.atomic_write(target, write)


def _png_bytes_writer(rgb8):
    def write(f):
        import matplotlib.image
        # No tEXt chunks at all ("Software" is matplotlib's only default key),
        # so the bytes depend on the pixels alone.
        matplotlib.image.imsave(f, rgb8, format="png", metadata={"Software": None})
    return write


def write_png(path, rgb):
    """Write an (H, W, 3) float image with values in [0, 1] (already display-
    encoded) as an 8-bit PNG, atomically and without varying metadata.

    Raises
    ------
    UsageError, OSError
        As `atomic_write`.
    """
    rgb8 = np.round(np.clip(np.asarray(rgb, dtype=np.float64), 0.0, 1.0) * 255.0).astype(np.uint8)
    atomic_write(path, _png_bytes_writer(rgb8))


def _check_output(path, flag):
    """Fail fast, before rendering, on an output path that cannot be written."""
    target = Path(path)
    if target.is_dir():
        raise UsageError(f"{flag} {str(path)!r} is a directory")
    parent = target.parent
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
    width, height = args.size
    _check_budget(width, height, 2, "render")
    _check_output(args.output, "-o")
    scene = load_scene(args.scene, args.set)
    frames = {}
    for g in _progress(("central", "exact"), desc="render", unit="frame"):
        frames[g] = render(scene, width, height, gradient=g)
    numeric, symbolic = frames["central"], frames["exact"]
    selected = frames[args.gradient]
    write_png(args.output, view_image(args.view, selected, numeric, symbolic))
    print(f"wrote {args.output} ({width}x{height}, view {args.view}, gradient {args.gradient})", file=out)
    print("\n".join(_ledger_lines(compare(numeric, symbolic))), file=out)
    return 0


_CENSUS_COLUMNS = ("eps", "max_abs", "rms", "flips", "pixels_a", "mean_abs_kink", "mean_abs_off_kink")


def _run_sweep(scene, steps, width, height):
    """`renderer.sweep` over ``steps``, with a progress bar over its tiles when
    stderr is a terminal."""
    if not _show_progress():
        return list(sweep(scene, steps, width, height).census)
    with _progress(total=width * height, desc="sweep", unit="px", unit_scale=True) as bar:
        def report(done, total):
            bar.update(done - bar.n)
        return list(sweep(scene, steps, width, height, progress=report).census)


def _cmd_sweep(args, out):
    steps = args.eps
    width, height = args.size
    _check_budget(width, height, len(steps) + 1, "sweep")
    scene = load_scene(args.scene, args.set)
    census = _run_sweep(scene, steps, width, height)
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
    from proofs.ucurve import UCurve, measure
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
    return UCurve(p0.field, p0.u, p0.v, p0.component, steps, error, cat("truncation"), cat("roundoff"),
                  cat("model"), p0.derivative, p0.third_derivative, p0.eps_opt_predicted,
                  float(steps[best]), float(error[best]))


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
            ax.set_title(f"U-curve: {uc.field} at (u, v) = ({uc.u:g}, {uc.v:g})")
            ax.legend(fontsize=7)
            fig.tight_layout()
            fig.savefig(f, format="png", metadata={"Software": None})
    return write


def _cmd_ucurve(args, out):
    if args.plot is not None:
        _check_output(args.plot, "--plot")
    for name in ("u", "v"):
        x = getattr(args, name)
        if not (math.isfinite(x) and 0.0 <= x <= 1.0):
            raise UsageError(f"--{name} must be a number in [0, 1], got {x!r}")
    for name in ("k_u", "k_v"):
        x = getattr(args, name)
        if not (math.isfinite(x) and 0.0 < x <= 1e6):
            raise UsageError(f"--{name.replace('_', '-')} must be a finite number in (0, 1e6], got {x!r}")
    uc = _measure_ucurve(args)
    print(f"U-curve: {uc.field}, h_{uc.component} at (u, v) = ({uc.u:g}, {uc.v:g}), "
          f"k = ({args.k_u:g}, {args.k_v:g}); reference mpmath 50 digits", file=out)
    print(f"true derivative {uc.derivative:.17g}; |h'''| = {abs(uc.third_derivative):.6g}", file=out)
    print(f"{'eps':>9}  {'truncation':>11}  {'roundoff':>11}  {'|error|':>10}  {'model':>10}", file=out)
    for i in range(uc.eps.size):
        print(f"{uc.eps[i]:9.2e}  {uc.truncation[i]:11.3e}  {uc.roundoff[i]:11.3e}  "
              f"{uc.error[i]:10.3e}  {uc.model[i]:10.3e}", file=out)
    print(f"eps* predicted {uc.eps_opt_predicted:.3e}; measured minimum {uc.error_at_measured_opt:.3e} "
          f"at eps {uc.eps_opt_measured:.3e}", file=out)
    if args.plot is not None:
        atomic_write(args.plot, _ucurve_plot_writer(uc))
        print(f"wrote {args.plot}", file=out)
    return 0


def _repo_root():
    return Path(__file__).resolve().parent.parent


def _cmd_verify(args, out):
    root = _repo_root()
    if not (root / "verify").is_dir():
        raise UsageError(f"verify needs a source checkout: {str(root / 'verify')!r} not found")
    cmd = [sys.executable, "-m", "pytest", "verify", "-q", "-p", "no:cacheprovider"]
    if args.k is not None:
        cmd += ["-k", args.k]
    out.flush()
    proc = subprocess.run(cmd, cwd=root, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
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


def _page_figures(book, page):
    """Execute one book page (a MyST notebook) in a fresh kernel; yield
    (figure id, code-cell ordinal, cell source, PNG bytes, cell tags) for every
    PNG it displays or glues.

    Raises
    ------
    UsageError
        If a cell fails (the page's exception, in one line).
    """
    import base64

    import nbclient
    from myst_nb.core.read import read_myst_markdown_notebook

    path = book / f"{page}.md"
    nb = read_myst_markdown_notebook(path.read_text(encoding="utf-8"), path=path)
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(book)}})
    try:
        client.execute(stderr=subprocess.DEVNULL)
    except nbclient.exceptions.CellExecutionError as exc:
        raise UsageError(f"figures: page {page} failed: {exc.ename}: {exc.evalue}") from None
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
            glue = (o.get("metadata", {}).get("scrapbook", {}) or {}).get("name")
            j += 1
            fid = f"{page}-{glue}" if glue else f"{page}-cell{ordinal:02d}-{j}"
            tags = tuple(cell.get("metadata", {}).get("tags", ()))
            yield fid, ordinal, cell.source, base64.b64decode(data[key]), tags


def _resolve_pages(pages):
    """The book's pages to run: all (None) or the named ones, by name or by
    section prefix (s4 -> s4_simulator)."""
    book = _repo_root() / "book"
    if not (book / "_toc.yml").is_file():
        raise UsageError(f"figures needs a source checkout: {str(book / '_toc.yml')!r} not found")
    all_pages = _book_pages(book)
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
            name = f"{fid}.png"
            atomic_write(out_dir / name, _png_bytes_writer(rgba))
            data = (out_dir / name).read_bytes()
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
    atomic_write(out_dir / "manifest.json", lambda f: f.write(text.encode()))
    return manifest


def _write_figures_staged(out_dir, pages):
    """Run `_render_figures` into a staging directory beside ``out_dir``, then
    move the result in (the whole directory if ``out_dir`` is new, else file by
    file with manifest.json last).  A failed or interrupted run removes the
    staging directory and leaves ``out_dir`` as it was."""
    import shutil
    staging = Path(tempfile.mkdtemp(dir=out_dir.parent, prefix=f".{out_dir.name}.", suffix=".part"))
    try:
        manifest = _render_figures(staging, pages)
        os.chmod(staging, 0o777 & ~files.umask())
        if not out_dir.exists():
            os.replace(staging, out_dir)
        else:
            names = sorted(p.name for p in staging.iterdir() if p.name != "manifest.json")
            for name in [*names, "manifest.json"]:
                os.replace(staging / name, out_dir / name)
        return manifest
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def _load_manifest(old_dir):
    path = Path(old_dir) / "manifest.json"
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        figures = {f["id"]: f for f in doc["figures"]}
        pages = list(doc["pages"])
    except OSError as exc:
        raise UsageError(f"--check: cannot read {str(path)!r}: {exc.strerror or exc}") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise UsageError(f"--check: {str(path)!r} is not a symrender manifest ({exc})") from None
    return doc, figures, pages


def _cmd_figures(args, out):
    import fnmatch
    pages = None if args.pages is None else [p.strip() for p in args.pages.split(",") if p.strip()]
    if args.check is None:
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
    old_doc, old, old_pages = _load_manifest(args.check)
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
                try:
                    a = _png_pixels((Path(args.check) / old[fid]["file"]).read_bytes())
                except OSError:
                    a = None
                b = _png_pixels((tmp / new[fid]["file"]).read_bytes())
                if a is None:
                    how = "previous file missing"
                elif a.shape != b.shape:
                    how = f"size {a.shape[1]}x{a.shape[0]} -> {b.shape[1]}x{b.shape[0]}"
                else:
                    d = np.abs(a.astype(np.int16) - b.astype(np.int16)).max(axis=2)
                    how = f"max |dI| = {d.max() / 255:.4f} ({np.count_nonzero(d):,} pixels differ)"
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


def _eps_arg(max_steps):
    def parse(text):
        try:
            return parse_eps(text, name="", max_steps=max_steps)
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
    limits = (f"Limits: each side 1..{MAX_SIDE}; render at most {MAX_PIXELS:,} pixels (4096^2); "
              f"sweep at most (steps + 1) * W * H <= {FRAME_PIXEL_BUDGET:,}; refused before allocating.")
    p = _Parser(prog="symrender", description="Render, sweep, measure and verify the Chapter-9 scene.",
                epilog=limits)
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
    r.add_argument("--gradient", choices=("exact", "central"), default="exact",
                   help="pipeline shown by the shaded, bump and kink views (default exact)")
    r.add_argument("--view", choices=VIEWS, default="shaded",
                   help="shaded image; difference clip(100|dI|); bump |grad h|; kink band over dimmed image")
    r.add_argument("-o", "--output", required=True, metavar="out.png", help="PNG to write (atomically)")

    s = sub.add_parser("sweep", help="eps sweep: census table of central vs exact",
                       description="Render the exact frame and one central frame per step; print the census: "
                                   "eps, max and RMS |dI| on A, flips, mean |dI| on and off the kink band.",
                       epilog=limits)
    scene_opts(s)
    s.add_argument("--eps", type=_eps_arg(MAX_STEPS), default=parse_eps("1e-1:1e-8:8"), metavar="a:b:n|e1,e2,..",
                   help=f"n log-spaced steps from a to b, or a comma list; 1..{MAX_STEPS} steps "
                        "(default 1e-1:1e-8:8)")
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
                                   "figure that changed and by how much (max |dI|), exiting 1 on a change.")
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


def main(argv=None) -> int:
    """Run ``symrender`` with ``argv`` (default ``sys.argv[1:]``); return the exit code.

    Returns 0 on success, 2 on any input error (one line ``symrender: error:
    ...`` on stderr, nothing written), 1 on an unanticipated error (one line
    ``symrender: internal error: ...``), 130 on Ctrl-C, 1 silently when stdout
    is closed early (a broken pipe), 1 when ``figures --check`` finds a
    changed figure, and pytest's code for
    ``verify``.  ``--help`` prints to stdout and returns 0.  Never raises.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    out = sys.stdout
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit as exc:  # --help (argparse prints, then exits 0)
            return exc.code if isinstance(exc.code, int) else 0
        return _COMMANDS[args.command](args, out)
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
        print("symrender: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug: still one line, no traceback
        print(f"symrender: internal error: {type(exc).__name__}: {_one_line(exc)}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
