"""Tests of the ``symrender`` command line (renderer/cli.py).

Every subcommand runs on real input through ``main([...])``; the installed
console script and ``python -m renderer.cli`` run once each.  Outputs are checked
against an independent route (the library called directly), PNGs are checked
byte for byte and chunk by chunk, the atomic write is interrupted on purpose,
and bad inputs (hand-picked and hypothesis-generated) must each give exit
code 2, one line on stderr, no traceback and no file.  Each checker is shown
to reject a wrong variant.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import math
import os
import re
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import renderer.cli as cli
from renderer import cmdline
from renderer.cli import main
from renderer import PointLight, Scene, compare, render, sweep, to_srgb

SMALL = "48x40"


# ------------------------------------------------------------------ helpers


def png_chunks(data: bytes):
    """Chunk types of a PNG file, in order (PNG spec, section 5.3)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    types, pos = [], 8
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        types.append(data[pos + 4:pos + 8].decode("ascii"))
        pos += 12 + length
    return types


#: Chunks that depend on the pixels only (no time, text or software tags).
STABLE_CHUNKS = {"IHDR", "pHYs", "IDAT", "IEND"}


def varying_chunks(data: bytes):
    return sorted(set(png_chunks(data)) - STABLE_CHUNKS)


def read_png(path):
    import matplotlib.image
    rgba = matplotlib.image.imread(path)  # float32 in [0, 1]
    return np.round(rgba[..., :3] * 255).astype(np.uint8)


def expected_pixels(rgb):
    return np.round(np.clip(rgb, 0, 1) * 255).astype(np.uint8)


def failure_problems(rc, err, before, after, prog="symrender"):
    """What is wrong with a failed run: a zero or unexpected exit code, a
    stderr that is not one ``<prog>: error:`` line, a traceback, or a
    file left behind."""
    problems = []
    if rc != 2:
        problems.append(f"exit code {rc}")
    lines = err.strip().splitlines()
    if len(lines) != 1 or not lines[0].startswith(f"{prog}: error: "):
        problems.append(f"stderr is not one error line: {err!r}")
    if "Traceback" in err:
        problems.append("traceback")
    if set(after) - set(before):
        problems.append(f"files left: {sorted(set(after) - set(before))}")
    return problems


def run(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def test_failure_checker_rejects_wrong_variants():
    assert failure_problems(2, "symrender: error: x\n", [], []) == []
    assert failure_problems(0, "symrender: error: x\n", [], [])
    assert failure_problems(1, "symrender: error: x\n", [], [])
    assert failure_problems(2, "usage: symrender\nsymrender: error: x\n", [], [])
    assert failure_problems(2, "Traceback (most recent call last):\n", [], [])
    assert failure_problems(2, "symrender: error: x\n", [], ["out.png"])


# ------------------------------------------------------------------ reading the reports back


#: Each labelled line of the render ledger and the `Ledger` field it reports.
LEDGER_LABELS = {"max |dI|": "max_abs", "RMS |dI|": "rms", "flips": "flips", "pixels on A": "pixels_a",
                 "mean |dI| on band": "mean_abs_kink", "mean |dI| off band": "mean_abs_off_kink"}
#: Each column of the sweep's text census and the `Ledger` field it reports.
CENSUS_LABELS = {"max |dI|": "max_abs", "RMS |dI|": "rms", "flips": "flips", "on band": "mean_abs_kink",
                 "off band": "mean_abs_off_kink"}
#: Each column of the U-curve table and the `UCurve` field it reports.
UCURVE_LABELS = {"eps": "eps", "truncation": "truncation", "roundoff": "roundoff", "|error|": "error", "model": "model"}


def value_of(text):
    """A reported number: an int, a float, or None for "none" (no pixel in that set)."""
    if text.startswith("none"):
        return None
    return int(text) if re.fullmatch(r"-?[0-9]+", text) else float(text)


def agrees(got, want, rel=1e-3):
    """A printed value (4 significant digits) against the library's; None stands for NaN."""
    if got is None or (isinstance(want, float) and math.isnan(want)):
        return got is None and math.isnan(want)
    return got == want if isinstance(want, int) else math.isclose(got, want, rel_tol=rel, abs_tol=1e-300)


def ledger_lines(report):
    """{Ledger field: value} read from a render report's labelled lines (by their labels)."""
    found = (re.fullmatch(r"  (.+?)\s{2,}(\S.*)", line) for line in report.splitlines())
    return {LEDGER_LABELS[m[1]]: value_of(m[2]) for m in found if m}


def table(report, labels):
    """A report's table read by its header: one {field: value} per row."""
    lines = report.splitlines()
    head = next(i for i, line in enumerate(lines) if line.split()[:1] == ["eps"])
    columns = [labels.get(c, c) for c in re.split(r"\s{2,}", lines[head].strip())]
    rows = [line.split() for line in lines[head + 1:]]
    return [dict(zip(columns, map(value_of, row))) for row in rows if len(row) == len(columns)]


def ledger_problems(report, led):
    """The fields of `Ledger` ``led`` that the report's ledger lines do not show."""
    got = ledger_lines(report)
    return [f for f in LEDGER_LABELS.values() if f not in got or not agrees(got[f], getattr(led, f))]


# ------------------------------------------------------------------ render


@pytest.mark.parametrize("view", ["shaded", "difference", "bump", "kink"])
@pytest.mark.parametrize("gradient", ["exact", "central"])
def test_render_views_match_the_library(tmp_path, capsys, view, gradient):
    out = tmp_path / "out.png"
    rc, stdout, err = run(["render", "--size", SMALL, "--gradient", gradient, "--view", view,
                           "--set", "beta=0.5", "-o", str(out)], capsys)
    assert rc == 0 and err == ""
    scene = Scene(beta=0.5)
    numeric = render(scene, 48, 40, gradient="central")
    symbolic = render(scene, 48, 40, gradient="exact")
    sel = symbolic if gradient == "exact" else numeric
    on_a = sel.chamber == 1
    if view == "shaded":
        want = to_srgb(sel.image)
    elif view == "difference":
        want = np.clip(100 * np.abs(numeric.image - symbolic.image), 0, 1)
    elif view == "bump":
        gmax = np.hypot(*np.moveaxis(symbolic.grad, 2, 0))[symbolic.chamber == 1].max()
        g = np.where(on_a, to_srgb(np.hypot(*np.moveaxis(sel.grad, 2, 0)) / gmax), 0.0)
        want = np.stack([g] * 3, axis=2)
    else:
        want = 0.4 * to_srgb(sel.image)
        want[symbolic.kink] = 1.0
    got = read_png(out)
    assert got.shape == (40, 48, 3)
    np.testing.assert_array_equal(got, expected_pixels(want))
    # The ledger printed is compare(central, exact), each value under its own label.
    assert ledger_problems(stdout, compare(numeric, symbolic)) == []


def test_a_frame_with_no_band_pixel_says_so(tmp_path, capsys):
    """4x4 of the draft's scene has no pixel in the crease band: its mean is none, not nan."""
    rc, out, _ = run(["render", "--size", "4x4", "-o", str(tmp_path / "o.png")], capsys)
    led = compare(render(Scene(), 4, 4, gradient="central"), render(Scene(), 4, 4))
    assert rc == 0 and math.isnan(led.mean_abs_kink) and led.pixels_a > 0
    assert "  mean |dI| on band   none (no pixel in the band)\n" in out and "nan" not in out
    assert ledger_problems(out, led) == []


def test_the_report_checkers_see_swapped_labels():
    """A ledger whose two band means are printed under each other's labels, and a census
    whose RMS and max columns are swapped, are caught."""
    led = compare(render(Scene(), 24, 20, gradient="central"), render(Scene(), 24, 20))
    lines = cli._ledger_lines(led)
    assert ledger_problems("\n".join(lines), led) == []
    swapped = [*lines[:5], lines[6].replace("off band", "on band "), lines[5].replace("on band ", "off band")]
    assert ledger_problems("\n".join(swapped), led) == ["mean_abs_kink", "mean_abs_off_kink"]
    header = "      eps   max |dI|   RMS |dI|  flips    on band   off band"
    row = (f" 1.00e-03  {led.rms:.3e}  {led.max_abs:.3e}  {led.flips:5d}  {led.mean_abs_kink:.3e}  "
           f"{led.mean_abs_off_kink:.3e}")
    (got,) = table(f"{header}\n{row}", CENSUS_LABELS)
    assert [f for f in CENSUS_LABELS.values() if not agrees(got[f], getattr(led, f))] == ["max_abs", "rms"]


def test_views_differ_so_the_pixel_check_can_fail(tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    assert run(["render", "--size", SMALL, "--view", "shaded", "-o", str(a)], capsys)[0] == 0
    assert run(["render", "--size", SMALL, "--view", "kink", "-o", str(b)], capsys)[0] == 0
    assert not np.array_equal(read_png(a), read_png(b))


def test_two_runs_give_byte_identical_png_without_varying_chunks(tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    for p in (a, b):
        assert run(["render", "--size", SMALL, "--view", "difference", "-o", str(p)], capsys)[0] == 0
    assert a.read_bytes() == b.read_bytes()
    assert varying_chunks(a.read_bytes()) == []
    # Wrong variant: matplotlib's default metadata adds a Software tEXt chunk.
    import matplotlib.image
    c = tmp_path / "c.png"
    matplotlib.image.imsave(c, read_png(a))
    assert varying_chunks(c.read_bytes()) == ["tEXt"]


def test_render_with_scene_file_and_set(tmp_path, capsys):
    toml = tmp_path / "scene.toml"
    toml.write_text('height_field = "rings"\nbeta = 0.8\nfloor = false\ncenter_b = [0.4, 0.5, 1.2]\n'
                    "[[lights]]\nposition = [5, 5, 10]\ncolor = [1.0, 0.9, 0.8]\n")
    out = tmp_path / "o.png"
    rc, stdout, err = run(["render", "--scene", str(toml), "--set", "beta=0.25", "--set", "k_u=6",
                           "--size", SMALL, "-o", str(out)], capsys)
    assert rc == 0, err
    scene = Scene(height_field="rings", beta=0.25, floor=False, center_b=(0.4, 0.5, 1.2), k_u=6.0,
                  lights=(PointLight((5, 5, 10), (1.0, 0.9, 0.8)),))
    assert cli.load_scene(str(toml), ["beta=0.25", "k_u=6"]) == scene
    np.testing.assert_array_equal(read_png(out), expected_pixels(to_srgb(render(scene, 48, 40).image)))
    # --set overrides the file; without it the file's beta is used.
    assert cli.load_scene(str(toml)).beta == 0.8


@pytest.mark.parametrize("text, value", [
    ("height_field=sine", "sine"), ('height_field="sine"', "sine"), ("model=phong", "phong"),
    ("floor=false", False), ("beta=0", 0.0), ("center_b=[0.5, 0.5, 1.4]", (0.5, 0.5, 1.4)),
])
def test_set_parses_toml_and_bare_words(text, value):
    key = text.partition("=")[0]
    assert getattr(cli.load_scene(None, [text]), key) == value


def test_set_lights_inline_tables():
    s = cli.load_scene(None, ["lights=[{position=[1, 2, 3], color=[0.5, 0.5, 0.5]}]"])
    assert s.lights == (PointLight((1, 2, 3), (0.5, 0.5, 0.5)),)


# ------------------------------------------------------------------ atomic write


class Boom(OSError):
    pass


def test_failure_mid_write_leaves_no_file(tmp_path, capsys, monkeypatch):
    import matplotlib.image

    def half_then_fail(f, *a, **k):
        f.write(b"\x89PNG\r\n\x1a\n half a file")
        raise Boom(28, "No space left on device")

    monkeypatch.setattr(matplotlib.image, "imsave", half_then_fail)
    out = tmp_path / "o.png"
    rc, stdout, err = run(["render", "--size", "8x8", "-o", str(out)], capsys)
    assert failure_problems(rc, err, [], list(tmp_path.iterdir())) == []
    assert "No space left on device" in err


# ------------------------------------------------------------------ bad inputs


def bad_toml(tmp_path, text):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    return str(p)


BAD = [
    # (argv with OUT / DIR placeholders, optional TOML text, a word the error must contain)
    (["render", "--size", "0x0", "-o", "OUT"], None, "--size"),
    (["render", "--size=-5x5", "-o", "OUT"], None, "--size"),
    (["render", "--size", "64", "-o", "OUT"], None, "--size"),
    (["render", "--size", "100000x100000", "-o", "OUT"], None, "--size"),
    (["render", "--size", "8192x8192", "-o", "OUT"], None, "--size"),
    (["sweep", "--size", "2048x2048", "--eps", "1e-1:1e-8:8"], None, "--size"),
    (["render", "--set", "beta=nan", "-o", "OUT"], None, "beta"),
    (["render", "--set", "beta=inf", "-o", "OUT"], None, "beta"),
    (["render", "--set", "beta=-1", "-o", "OUT"], None, "beta"),
    (["render", "--set", "beta=abc", "-o", "OUT"], None, "beta"),
    (["render", "--set", "k_u=1e400", "-o", "OUT"], None, "k_u"),
    (["render", "--set", "floor=1", "-o", "OUT"], None, "floor"),
    (["render", "--set", "radius_a=100000000000000000000000000000000000000000000000000000000000"
      "0000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
      "0000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
      "0000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
      "-o", "OUT"], None, "radius_a"),
    (["render", "--set", "colour=1", "-o", "OUT"], None, "colour"),
    (["render", "--set", "beta", "-o", "OUT"], None, "--set"),
    (["render", "--set", "beta=[1,", "-o", "OUT"], None, "beta"),
    (["render", "--set", "lights=[{position=[1,2,3], colour=[1,1,1]}]", "-o", "OUT"], None, "colour"),
    (["render", "--scene", "TOML", "-o", "OUT"], "beta = 0.5\nshine = 3\n", "shine"),
    (["render", "--scene", "TOML", "-o", "OUT"], "beta = \n", "malformed TOML"),
    (["render", "--scene", "TOML", "-o", "OUT"], "beta = 'x'\n", "beta"),
    (["render", "--scene", "TOML", "-o", "OUT"], "beta = nan\n", "beta"),
    (["render", "--scene", "TOML", "-o", "OUT"], "[[lights]]\nposition = [1, 2]\ncolor = [1, 1, 1]\n",
     "position"),
    (["render", "--scene", "TOML", "-o", "OUT"], "[[lights]]\nposition = [1, 2, 3]\nspin = 1\n", "spin"),
    (["render", "--scene", "TOML", "-o", "OUT"], "lights = 3\n", "lights"),
    (["render", "--scene", "DIR/missing.toml", "-o", "OUT"], None, "--scene"),
    (["render", "--size", "8x8", "-o", "DIR/no/such/dir/o.png"], None, "does not exist"),
    (["render", "--size", "8x8", "-o", "DIR"], None, "directory"),
    (["render", "--size", "8x8", "-o", "DIR/file.txt/o.png"], None, "is not a directory"),
    (["render", "--view", "sideways", "-o", "OUT"], None, "--view"),
    (["render", "--size", "8x8"], None, "-o"),
    (["sweep", "--eps", "0:1:3"], None, "--eps"),
    (["sweep", "--eps", "1e-3,-1e-4"], None, "--eps"),
    (["sweep", "--eps", "1e-1:1e-8:0"], None, "--eps"),
    (["sweep", "--eps", "1e-1:1e-8:65"], None, "--eps"),
    (["sweep", "--eps", "nan"], None, "--eps"),
    (["sweep", "--format", "xml"], None, "--format"),
    (["ucurve", "--u", "1.5"], None, "--u"),
    (["ucurve", "--v", "nan"], None, "--v"),
    (["ucurve", "--u", "x"], None, "--u"),
    (["ucurve", "--k-u", "0"], None, "--k-u"),
    (["ucurve", "--field", "waves"], None, "--field"),
    (["ucurve", "--plot", "DIR/no/such/p.png"], None, "--plot"),
    (["frobnicate"], None, "frobnicate"),
    ([], None, "command"),
    # Negative and huge numbers reach the command's own checks and get the range.
    (["render", "--size", "-5x5", "-o", "OUT"], None, "between 1 and 8192"),
    (["render", "--size", "99999999999x5", "-o", "OUT"], None, "between 1 and 8192"),
    (["render", "--size", "5x" + "9" * 5000, "-o", "OUT"], None, "between 1 and 8192"),
    (["sweep", "--eps", "1e-1:1e-8:99999999999"], None, "between 1 and 64"),
    (["sweep", "--eps", "-1e-3"], None, "[1e-16, 0.25]"),
    (["sweep", "--eps", "0.5"], None, "[1e-16, 0.25]"),
    (["sweep", "--eps", "1e-1:1e-20:4"], None, "[1e-16, 0.25]"),
    (["ucurve", "--u", "-0.5"], None, "[0, 1]"),
    (["ucurve", "--k-u", "-3"], None, "(0, 1000]"),
    (["ucurve", "--k-v", "5000"], None, "(0, 1000]"),
    # Empty and directory-like paths.
    (["render", "--size", "8x8", "-o", ""], None, "empty"),
    (["render", "--size", "8x8", "-o", "OUT/"], None, "trailing '/'"),
    (["ucurve", "--plot", ""], None, "empty"),
    (["render", "--scene", "", "-o", "OUT"], None, "empty"),
    (["render", "--scene", "DIR", "-o", "OUT"], None, "directory"),
    (["render", "--scene", "/dev/zero", "-o", "OUT"], None, "regular file"),
    # Lights need both keys; nesting is bounded; huge integers are named.
    (["render", "--scene", "TOML", "-o", "OUT"], "[[lights]]\n", "lights[0] has no 'position'"),
    (["render", "--scene", "TOML", "-o", "OUT"], "[[lights]]\nposition = [1, 2, 3]\n", "lights[0] has no 'color'"),
    (["render", "--set", "lights=[{color=[1, 1, 1]}]", "-o", "OUT"], None, "lights[0] has no 'position'"),
    (["render", "--scene", "TOML", "-o", "OUT"], "a = " + "[" * 5000 + "]" * 5000 + "\n", "nested too deeply"),
    (["render", "--set", "center_b=" + "[" * 5000 + "]" * 5000, "-o", "OUT"], None, "nested too deeply"),
    (["render", "--set", "center_b=" + "[" * 20 + "]" * 20, "-o", "OUT"], None, "center_b[0]"),
    (["render", "--scene", "TOML", "-o", "OUT"], "beta = " + "9" * 5000 + "\n", "--scene"),
]


@pytest.mark.parametrize("argv, toml, word", BAD, ids=[" ".join(b[0])[:60] for b in BAD])
def test_bad_input_one_line_no_file(tmp_path, capsys, monkeypatch, argv, toml, word):
    """Each is refused in one line naming the input, before any work: the work itself (a render,
    a sweep, a U-curve) is replaced by a failure that would show as an internal error."""
    import importlib

    def no_work(*a, **k):
        raise AssertionError("the work started")
    for module, name in (("renderer.render", "render"), ("renderer.render", "gbuffer"),
                         ("renderer.sweep", "sweep"), ("renderer.ucurve", "measure")):
        monkeypatch.setattr(importlib.import_module(module), name, no_work)
    (tmp_path / "file.txt").write_text("x")
    argv = [a.replace("OUT", str(tmp_path / "o.png")).replace("DIR", str(tmp_path)) for a in argv]
    if toml is not None:
        argv = [bad_toml(tmp_path, toml) if a == "TOML" else a for a in argv]
    before = sorted(p.name for p in tmp_path.iterdir())
    rc, stdout, err = run(argv, capsys)
    assert failure_problems(rc, err, before, sorted(p.name for p in tmp_path.iterdir())) == []
    assert word in err
    assert stdout == ""


def test_huge_size_refused_before_allocating(tmp_path, capsys, monkeypatch):
    def no_render(*a, **k):
        raise AssertionError("render called")

    import importlib
    for module, name in ((importlib.import_module("renderer.render"), "render"),
                         (importlib.import_module("renderer.sweep"), "sweep"), (cli, "render"), (cli, "sweep")):
        monkeypatch.setattr(module, name, no_render, raising=module is not cli)
    for argv in (["render", "--size", "100000x100000", "-o", str(tmp_path / "o.png")],
                 ["render", "--size", "8192x8192", "-o", str(tmp_path / "o.png")],
                 ["sweep", "--size", "4096x4096"]):
        rc, _, err = run(argv, capsys)
        assert rc == 2 and "--size" in err
    # Wrong variant: a size within the limits does reach render.
    rc, _, err = run(["render", "--size", "8x8", "-o", str(tmp_path / "o.png")], capsys)
    assert rc == 1 and "render called" in err and not (tmp_path / "o.png").exists()


# ------------------------------------------------------------------ argument edge cases


@pytest.mark.parametrize("argv, word", [
    (["render", "--size", "-5x5", "-o", "OUT"], "--size: width must be between 1 and 8192"),
    (["ucurve", "--u", "-0.5"], "--u must be in [0, 1], got -0.5"),
    (["ucurve", "--k-u", "-3"], "--k-u must be in (0, 1000], got -3.0"),
    (["sweep", "--eps", "-1e-3"], "--eps must be in [1e-16, 0.25], got -0.001 at flat index 0"),
    (["sweep", "--eps", "-.5"], "--eps must be in [1e-16, 0.25], got -0.5 at flat index 0"),
])
def test_negative_values_reach_our_checks(tmp_path, capsys, argv, word):
    argv = [a.replace("OUT", str(tmp_path / "o.png")) for a in argv]
    rc, _, err = run(argv, capsys)
    assert rc == 2 and word in err and "expected one argument" not in err
    # Wrong variant: plain argparse takes "-5x5" and "-1e-3" for options.
    plain = argparse.ArgumentParser(exit_on_error=False)
    plain.add_argument("--size")
    with pytest.raises(argparse.ArgumentError, match="expected one argument"):
        plain.parse_args(["--size", "-5x5"])


def test_a_value_after_double_dash_is_left_alone():
    p = cmdline.Parser(prog="t")
    p.add_argument("--u")
    p.add_argument("rest", nargs="*")
    assert p.parse_args(["--u", "-1", "--", "--u", "-2"]) == argparse.Namespace(u="-1", rest=["--u", "-2"])


def test_version(capsys, monkeypatch):
    from importlib import metadata
    rc, out, err = run(["--version"], capsys)
    assert rc == 0 and err == "" and out == f"symrender {metadata.version('symbolic-rendering-ch9')}\n"

    def not_installed(name):
        raise metadata.PackageNotFoundError(name)

    monkeypatch.setattr(metadata, "version", not_installed)
    rc, out, _ = run(["--version"], capsys)
    assert rc == 0 and out == "symrender unknown (not installed)\n"


# ------------------------------------------------------------------ standard output


class BinaryStdout(io.TextIOWrapper):
    """A non-terminal stdout whose bytes can be read back."""

    def __init__(self, tty=False):
        super().__init__(io.BytesIO(), encoding="utf-8")
        self.tty = tty

    def isatty(self):
        return self.tty

    def data(self):
        self.flush()
        return self.buffer.getvalue()


def test_output_dash_writes_the_png_to_stdout_and_the_report_to_stderr(tmp_path, capsys, monkeypatch):
    out = tmp_path / "o.png"
    rc, stdout, _ = run(["render", "--size", SMALL, "--view", "kink", "-o", str(out)], capsys)
    assert rc == 0
    fake = BinaryStdout()
    monkeypatch.setattr(sys, "stdout", fake)
    rc = main(["render", "--size", SMALL, "--view", "kink", "-o", "-"])
    err = capsys.readouterr().err
    assert rc == 0 and fake.data() == out.read_bytes()  # the PNG and nothing else
    assert "wrote standard output" in err and stdout.splitlines()[1:] == err.splitlines()[1:]
    assert list(tmp_path.iterdir()) == [out]


def test_plot_dash_writes_the_plot_to_stdout_and_the_table_to_stderr(tmp_path, capsys, monkeypatch):
    plot = tmp_path / "u.png"
    rc, table, _ = run(["ucurve", "--eps", "1e-1:1e-6:6", "--plot", str(plot)], capsys)
    assert rc == 0
    fake = BinaryStdout()
    monkeypatch.setattr(sys, "stdout", fake)
    rc = main(["ucurve", "--eps", "1e-1:1e-6:6", "--plot", "-"])
    err = capsys.readouterr().err
    assert rc == 0 and fake.data() == plot.read_bytes()
    assert err.splitlines()[:-1] == table.splitlines()[:-1] and err.endswith("wrote standard output\n")


@pytest.mark.parametrize("argv", [["render", "--size", "8x8", "-o", "-"], ["ucurve", "--plot", "-"]])
def test_dash_on_a_terminal_is_refused(capsys, monkeypatch, argv):
    fake = BinaryStdout(tty=True)
    monkeypatch.setattr(sys, "stdout", fake)
    rc = main(argv)
    err = capsys.readouterr().err
    assert failure_problems(rc, err, [], []) == [] and "terminal" in err and fake.data() == b""
    # The same run with stdout not a terminal writes (the refusal is about the terminal).
    fake.tty = False
    if argv[0] == "render":
        assert main(argv) == 0 and fake.data().startswith(b"\x89PNG")


def test_stdout_and_dev_stdout_in_a_real_process(tmp_path):
    """Through a real pipe: ``-o -`` gives the PNG alone on stdout; so does ``-o
    /dev/stdout`` (a link written through), the report going to stderr (it went
    into the PNG stream); a pseudo-terminal is refused."""
    cmd = [sys.executable, "-m", "renderer.cli", "render", "--size", "8x8", "-o"]
    ref = tmp_path / "ref.png"
    assert main(["render", "--size", "8x8", "-o", str(ref)]) == 0
    dash = subprocess.run([*cmd, "-"], capture_output=True)
    assert dash.returncode == 0 and dash.stdout == ref.read_bytes() and b"ledger" in dash.stderr
    dev = subprocess.run([*cmd, "/dev/stdout"], capture_output=True)
    assert dev.returncode == 0 and dev.stdout == ref.read_bytes() and b"ledger" in dev.stderr
    primary, secondary = os.openpty()
    try:
        tty = subprocess.run([*cmd, "-"], stdout=secondary, stderr=subprocess.PIPE)
    finally:
        os.close(secondary)
        os.close(primary)
    assert tty.returncode == 2 and tty.stderr.count(b"\n") == 1 and b"terminal" in tty.stderr


def test_device_output_needs_no_writable_directory(tmp_path, capsys, monkeypatch):
    """As a user who cannot write /dev: a writable device passes the early
    check; a new file in a directory that is not writable does not."""
    real_access = os.access
    monkeypatch.setattr(cli.os, "access",
                        lambda p, mode: False if os.path.isdir(p) else real_access(p, mode))
    assert cli._check_output("/dev/null", "-o") is None
    with pytest.raises(cli.UsageError, match="not writable"):
        cli._check_output(str(tmp_path / "o.png"), "-o")


# ------------------------------------------------------------------ scene files


def test_scene_file_with_a_byte_order_mark(tmp_path):
    text = 'beta = 0.8\nheight_field = "rings"\n'
    plain, bom = tmp_path / "a.toml", tmp_path / "b.toml"
    plain.write_text(text, encoding="utf-8")
    bom.write_text(text, encoding="utf-8-sig")
    assert bom.read_bytes().startswith(b"\xef\xbb\xbf")
    assert cli.load_scene(str(bom)) == cli.load_scene(str(plain)) == Scene(beta=0.8, height_field="rings")


def returns_without_blocking(fn, deadline=30.0):
    """``fn()``'s result, from a thread; fails if it has not returned after
    ``deadline`` seconds (a blocked open or read never returns at all)."""
    import threading
    box = []
    t = threading.Thread(target=lambda: box.append(fn()), daemon=True)
    t.start()
    t.join(deadline)
    assert box, f"still blocked after {deadline} s"
    return box[0]


def test_scene_fifo_is_refused_without_blocking(tmp_path, capsys):
    fifo = tmp_path / "scene.toml"
    os.mkfifo(fifo)
    rc = returns_without_blocking(lambda: main(["render", "--scene", str(fifo), "-o", str(tmp_path / "o.png")]))
    err = capsys.readouterr().err
    assert failure_problems(rc, err, [], []) == [] and "FIFO" in err and "regular file" in err


def test_the_blocking_check_sees_a_blocked_open(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(AssertionError, match="still blocked"):
        returns_without_blocking(lambda: open(fifo, "rb"), deadline=0.5)
    with open(fifo, "wb"):          # release the blocked reader
        pass


def test_scene_file_size_cap(tmp_path, capsys, monkeypatch):
    big = tmp_path / "big.toml"
    with open(big, "wb") as f:
        f.truncate(2 << 30)
    reads = []
    real_read = os.read
    monkeypatch.setattr(cli.files.os, "read", lambda fd, n: reads.append(n) or real_read(fd, n))
    rc, _, err = run(["render", "--scene", str(big), "-o", str(tmp_path / "o.png")], capsys)
    assert rc == 2 and "larger than 1,048,576 bytes" in err and reads == []      # refused unread
    monkeypatch.undo()
    # A file at the cap is read (padded with a comment).
    ok = tmp_path / "ok.toml"
    ok.write_bytes(b"beta = 0.5\n#" + b"x" * (cli.MAX_SCENE_BYTES - 13) + b"\n")
    assert ok.stat().st_size == cli.MAX_SCENE_BYTES and cli.load_scene(str(ok)).beta == 0.5


def test_check_ints_walks_deep_values_without_recursion():
    deep = 1
    for _ in range(100_000):
        deep = [deep]
    with pytest.raises(cli.UsageError, match=r"x\[0\]\[0\].* is nested too deeply"):
        cli._check_ints("--set", "x", deep)
    cli._check_ints("--set", "x", [[[1, 2]], {"a": [3]}])  # shallow values pass
    with pytest.raises(cli.UsageError, match=r"x\[1\]\.a\[0\] = 1000"):
        cli._check_ints("--set", "x", [[[1, 2]], {"a": [10 ** 400]}])

    # Wrong variant: the recursive walk this replaced overflows the stack.
    def recursive(value):
        if isinstance(value, list):
            for item in value:
                recursive(item)

    with pytest.raises(RecursionError):
        recursive(deep)


# ------------------------------------------------------------------ sweep


def test_sweep_formats_match_renderer_sweep(capsys):
    steps = cli.parse_eps("1e-1:1e-6:6")
    np.testing.assert_allclose(steps, np.logspace(-1, -6, 6), rtol=1e-15)
    assert steps == (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6)  # decades exactly (15-digit rounding)
    assert cli.parse_eps("1e-3, 2e-4") == (1e-3, 2e-4)
    ref = sweep(Scene(), steps, 40, 32).census
    rc, out, err = run(["sweep", "--eps", "1e-1:1e-6:6", "--size", "40x32", "--format", "csv"], capsys)
    assert rc == 0 and err == ""
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 6
    for row, e, led in zip(rows, steps, ref):
        assert float(row["eps"]) == e
        assert float(row["max_abs"]) == led.max_abs and float(row["rms"]) == led.rms
        assert int(row["flips"]) == led.flips and int(row["pixels_a"]) == led.pixels_a
        assert float(row["mean_abs_kink"]) == led.mean_abs_kink
        assert float(row["mean_abs_off_kink"]) == led.mean_abs_off_kink
    rc, out, _ = run(["sweep", "--eps", "1e-2,1e-5", "--size", "40x32", "--format", "json",
                      "--set", "height_field=sine"], capsys)
    doc = json.loads(out)
    assert rc == 0 and [r["eps"] for r in doc["rows"]] == [1e-2, 1e-5]
    assert doc["size"] == [40, 32] and doc["height_field"] == "sine"       # as --size says it: W, H
    assert doc["rows"][0]["mean_abs_kink"] is None  # sine has no crease band: nan -> null
    rc, out, _ = run(["sweep", "--eps", "1e-1:1e-6:6", "--size", "40x32"], capsys)
    lines = out.strip().splitlines()
    assert rc == 0 and len(lines) == 2 + 6 and lines[2].split()[0] == "1.00e-01"
    rows = table(out, CENSUS_LABELS)
    assert len(rows) == 6
    for row, e, led in zip(rows, steps, ref):     # each column under its own label
        assert agrees(row["eps"], e, rel=1e-2) and all(agrees(row[f], getattr(led, f)) for f in CENSUS_LABELS.values())


def test_sweep_of_a_field_without_a_crease_band_says_none(capsys):
    """The sine field has no crease band: the on-band mean is a missing value in every format."""
    argv = ["sweep", "--eps", "1e-2,1e-5", "--size", "24x20", "--set", "height_field=sine"]
    ref = sweep(Scene(height_field="sine"), (1e-2, 1e-5), 24, 20).census
    assert all(math.isnan(led.mean_abs_kink) for led in ref)
    rc, out, _ = run(argv, capsys)
    rows = table(out, CENSUS_LABELS)
    assert rc == 0 and "nan" not in out and [r["mean_abs_kink"] for r in rows] == [None, None]
    assert all(agrees(r[f], getattr(led, f)) for r, led in zip(rows, ref) for f in CENSUS_LABELS.values())
    rc, out, _ = run([*argv, "--format", "csv"], capsys)
    assert rc == 0 and [r["mean_abs_kink"] for r in csv.DictReader(io.StringIO(out))] == ["", ""]


# ------------------------------------------------------------------ ucurve


def test_ucurve_table_matches_measure(tmp_path, capsys):
    from renderer.ucurve import measure
    plot = tmp_path / "u.png"
    rc, out, err = run(["ucurve", "--field", "sine", "--u", "0.31", "--v", "0.47", "--component", "u",
                        "--eps", "1e-1:1e-12:12", "--plot", str(plot)], capsys)
    assert rc == 0 and err == ""
    uc = measure("sine", 0.31, 0.47, "u", eps=cli.parse_eps("1e-1:1e-12:12", max_steps=100))
    rows = table(out, UCURVE_LABELS)
    assert len(rows) == 12
    for i, row in enumerate(rows):                # each column under its own label
        assert agrees(row["eps"], uc.eps[i], rel=1e-2)
        assert all(agrees(row[f], float(getattr(uc, f)[i])) for f in ("truncation", "roundoff", "error", "model"))
    m = re.search(r"^true derivative (\S+); \|h'''\| = (\S+); \|h\| = (\S+); \|u h'\| = (\S+)$", out, re.M)
    assert float(m[1]) == uc.derivative and agrees(float(m[2]), abs(uc.third_derivative))
    assert agrees(float(m[3]), abs(uc.height)) and agrees(float(m[4]), abs(uc.u * uc.derivative))
    # One name per step: the model-optimal step, the fitted optimal step, the measured minimum.
    for pattern, names in ((r"model-optimal step eps\* (\S+), model error there (\S+)", ("eps_model", "error_model")),
                           (r"fitted optimal step eps\^ (\S+), fitted error there (\S+)",
                            ("eps_fitted", "error_at_fitted")),
                           (r"measured minimum (\S+) at eps (\S+)", ("error_at_measured_min", "eps_measured_min"))):
        m = re.search(f"^{pattern}$", out, re.M)
        assert all(agrees(float(m[i]), getattr(uc, f)) for i, f in enumerate(names, 1)), pattern
    first = plot.read_bytes()
    assert varying_chunks(first) == []
    rc, _, _ = run(["ucurve", "--eps", "1e-1:1e-12:12", "--plot", str(plot)], capsys)
    assert rc == 0 and plot.read_bytes() == first


@pytest.mark.parametrize("argv, where", [
    (["--field", "ridges", "--u", "0.125"], "crease u = 1/k_u"),
    (["--field", "sine", "--v", "0"], "pole"),
])
def test_ucurve_says_where_the_field_is_not_differentiable(argv, where, tmp_path, capsys):
    plot = tmp_path / "u.png"
    rc, out, err = run(["ucurve", *argv, "--eps", "1e-2:1e-10:5", "--plot", str(plot)], capsys)
    assert rc == 0 and err == ""
    assert "not differentiable: " in out and where in out
    # Neither a "true derivative" nor an optimum is printed; the table still is.
    assert not any(line.startswith(("true derivative", "model-optimal", "fitted optimal", "measured minimum"))
                   for line in out.splitlines())
    assert len([line for line in out.splitlines() if line.split()[0][:1].isdigit()]) == 5
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # At a smooth point of the same field the derivative and optimum are printed.
    rc, out, _ = run(["ucurve", "--field", "ridges", "--u", "0.1", "--eps", "1e-2:1e-10:5"], capsys)
    assert rc == 0 and "true derivative" in out and "model-optimal step" in out and "not differentiable" not in out


def test_ucurve_in_chunks_for_progress_equals_one_measure(capsys, monkeypatch):
    argv = ["ucurve", "--field", "ridges", "--component", "v", "--eps", "1e-1:1e-14:120"]
    rc, plain, _ = run(argv, capsys)
    monkeypatch.setattr(cmdline, "show_progress", lambda: True)
    rc2, chunked, _ = run(argv, capsys)
    assert rc == rc2 == 0 and plain == chunked and len(plain.splitlines()) == 3 + 120 + 3


# ------------------------------------------------------------------ verify, help, entry points




class ClosedPipe(io.StringIO):
    def write(self, text):
        raise BrokenPipeError(32, "Broken pipe")


def test_broken_pipe_is_quiet(capsys, monkeypatch):
    monkeypatch.setattr(sys, "stdout", ClosedPipe())
    rc = main(["sweep", "--size", "8x8", "--eps", "1e-2"])
    assert rc == 1 and capsys.readouterr().err == ""
    # Wrong variant: any other OSError on output is still reported.
    monkeypatch.setattr(ClosedPipe, "write", lambda self, t: (_ for _ in ()).throw(OSError(5, "I/O error")))
    rc = main(["sweep", "--size", "8x8", "--eps", "1e-2"])
    assert rc == 2 and capsys.readouterr().err == "symrender: error: standard output: I/O error\n"




@pytest.mark.parametrize("command", ["render", "sweep", "ucurve"])
def test_help_on_each_subcommand(capsys, command):
    rc, out, err = run([command, "--help"], capsys)
    assert rc == 0 and out.startswith(f"usage: symrender {command}") and err == ""


def test_help_states_the_limits(capsys):
    _, out, _ = run(["render", "--help"], capsys)
    assert "8192" in out and "16,777,216" in out


def test_console_script_and_module(tmp_path):
    exe = Path(sys.executable).parent / "symrender"
    out = tmp_path / "o.png"
    proc = subprocess.run([str(exe), "render", "--size", "16x12", "-o", str(out)],
                          capture_output=True, text=True)
    assert proc.returncode == 0 and "ledger" in proc.stdout and out.exists()
    proc = subprocess.run([sys.executable, "-m", "renderer.cli", "render", "--size", "0x0", "-o", str(out)],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr


# ------------------------------------------------------------------ fuzzing

TOKENS = [
    "render", "sweep", "ucurve", "--size", "--set", "--scene", "--eps", "--view", "--gradient", "-o",
    "--format", "--field", "--u", "--v", "--component", "--k-u", "--plot", "--help",
    "8x8", "12x6", "0x0", "-1x4", "100000x100000", "4097x4096", "x", "1x", "8X8",
    "beta=nan", "beta=inf", "beta=-1", "beta=0.5", "beta=1e400", "k_u=0", "foo=1", "beta",
    "height_field=sine", "height_field=\"nope\"", "floor=false", "floor=1", "center_b=[1,2]",
    "lights=[]", "lights=[1]", "lights=[{position=[1,2,3], color=[1,1,1]}]", "model=phong",
    "bump=surface", "beta=[1,", "radius_a=0", "camera_z=0.5",
    "1e-1:1e-8:8", "1e-2,1e-4", "0:1:2", "1e-3,-1", "nan", "inf", "-0.5", "0.31", "2",
    "shaded", "difference", "bump", "kink", "exact", "central", "text", "csv", "json", "xml",
    "sine", "ridges", "rings", "u", "v", "OUT", "PLOT", "GOODTOML", "BADTOML", "NOFILE", "DIR",
]
TOML_TEXTS = ['beta = 0.5\nheight_field = "rings"\n', "beta = \n", "shine = 1\n", "beta = nan\n",
              "[[lights]]\nposition = [1, 2, 3]\ncolor = [1, 1, -1]\n", "lights = \"x\"\n",
              "radius_a = 1e999\n", "[beta]\nx = 1\n"]


#: Option -> values, good and bad, so that many generated runs get past argparse.
OPTION_VALUES = {
    "--size": ["8x8", "12x6", "1x1", "0x0", "-3x3", "100000x100000", "8192x8192", "8x", "abc"],
    "--set": ["beta=0.5", "beta=nan", "beta=inf", "beta=-1", "height_field=rings", "height_field=waves",
              "k_u=3", "k_v=1e400", "foo=1", "floor=false", "sphere_b=0", "bump=surface", "beta=2",
              "lights=[{position=[1,2,3], color=[1,1,1]}]", "lights=[{position=[1,2,3]}]", "eps=0",
              "center_b=[0,0,3.9]", "model=\"phong\"", "ambient=[1,1]"],
    "--scene": ["GOODTOML", "BADTOML", "NOFILE", "DIR"],
    "--eps": ["1e-1:1e-8:8", "1e-2,1e-4", "1e-3", "0:1:2", "1e-3,-1", "nan", "inf", "1:2:3:4", "1e-1:1e-3:99"],
    "--view": ["shaded", "difference", "bump", "kink", "xray"],
    "--gradient": ["exact", "central", "forward"],
    "-o": ["OUT", "DIR", "DIR/none/o.png", "NOFILE/o.png"],
    "--format": ["text", "csv", "json", "xml"],
    "--field": ["sine", "ridges", "rings", "waves"],
    "--u": ["0.31", "0", "1", "1.5", "-0.1", "nan", "inf", "x"],
    "--v": ["0.47", "0.999", "nan"],
    "--component": ["u", "v", "w"],
    "--k-u": ["8", "0", "-1", "1e300"],
    "--plot": ["PLOT", "DIR", "DIR/none/p.png"],
}


@st.composite
def argv_tokens(draw):
    """Mostly option/value pairs (good and bad values), some free tokens."""
    out = []
    for _ in range(draw(st.integers(0, 5))):
        if draw(st.integers(0, 4)) == 0:
            out.append(draw(st.one_of(st.sampled_from(TOKENS), st.text(max_size=12))))
        else:
            opt = draw(st.sampled_from(sorted(OPTION_VALUES)))
            out += [opt, draw(st.sampled_from(OPTION_VALUES[opt]))]
    return out


FUZZ_CODES = []


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(command=st.sampled_from(["render", "sweep", "ucurve"]), tokens=argv_tokens(),
       toml=st.sampled_from(TOML_TEXTS))
def test_fuzz_main(command, tokens, toml):
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        (d / "good.toml").write_text(TOML_TEXTS[0])
        (d / "bad.toml").write_text(toml)
        subs = {"OUT": str(d / "o.png"), "PLOT": str(d / "p.png"), "GOODTOML": str(d / "good.toml"),
                "BADTOML": str(d / "bad.toml"), "NOFILE": str(d / "none.toml"), "DIR": str(d)}
        argv = [command] + (["--size", "8x8"] if command != "ucurve" else ["--eps", "1e-2,1e-6"])
        argv += [subs.get(t.split("/")[0], t.split("/")[0]) + t[len(t.split("/")[0]):] if t.split("/")[0] in subs
                 else t for t in tokens]
        before = sorted(p.name for p in d.iterdir())
        out, err = io.StringIO(), io.StringIO()
        # In the directory: a free token taken as a relative output path lands there.
        with contextlib.chdir(d), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(argv)
        after = sorted(p.name for p in d.iterdir())
        err = err.getvalue()
        FUZZ_CODES.append(rc)
        assert "Traceback" not in err and "internal error" not in err, (argv, err)
        if rc == 0:
            assert set(after) - set(before) <= {"o.png", "p.png"}, (argv, after)
            assert not any(n.endswith(".part") for n in after)
        else:
            assert failure_problems(rc, err, before, after) == [], (argv, err)


def test_fuzz_reached_both_outcomes():
    """The fuzzing above exercised successful runs as well as refusals."""
    if not FUZZ_CODES:
        pytest.skip("run together with test_fuzz_main")
    print(f"fuzz: {len(FUZZ_CODES)} runs, {FUZZ_CODES.count(0)} exit 0, {FUZZ_CODES.count(2)} exit 2")
    assert FUZZ_CODES.count(0) >= 10 and FUZZ_CODES.count(2) >= 10, (len(FUZZ_CODES), FUZZ_CODES.count(0))


# ------------------------------------------------------------------ figures


@pytest.mark.parametrize("command", [["render", "--size", "8x8", "-o"], ["ucurve", "--eps", "1e-3", "--plot"]],
                         ids=["render", "ucurve"])
def test_a_file_name_stdout_cannot_encode_is_written_and_reported(tmp_path, command):
    """With a strict UTF-8 stdout, a name from undecodable bytes used to be written, then its
    report raised UnicodeEncodeError and the command exited 2: it now succeeds, the name escaped."""
    name = os.fsdecode(b"\xff.png")
    env = {**os.environ, "PYTHONIOENCODING": "utf-8:strict"}
    done = subprocess.run([sys.executable, "-m", "renderer.cli", *command, name], cwd=tmp_path, env=env,
                          capture_output=True, timeout=600)
    assert done.returncode == 0 and done.stderr == b"", done.stderr
    assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"wrote \\udcff.png" in done.stdout


@pytest.mark.parametrize("command", [["render", "--size", "8x8", "-o", "-"], ["sweep", "--size", "8x8"],
                                     ["render", "--size", "8x8", "-o", "x.png"]])
def test_a_closed_stdout_is_an_error_before_any_work(tmp_path, command):
    """`>&-`: the report (and `-o -`'s image) would be lost; an AttributeError or exit 0 before."""
    done = subprocess.run([sys.executable, "-m", "renderer.cli", *command], cwd=tmp_path, capture_output=False,
                          stderr=subprocess.PIPE, preexec_fn=lambda: os.close(1), timeout=600)
    assert done.returncode == 2, done.stderr
    assert done.stderr == b"symrender: error: standard output is closed: symrender reports there\n", done.stderr
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("argv, fragment", [
    (["--v"], "required: command"),                                   # was taken as --version
    (["render", "-o", "x.png", "--siz", "8x8"], "unrecognized arguments: --siz 8x8"),
    (["render", "--size", "٥x٥"], "--size"),                           # Arabic-Indic digits
    (["render", "--size", "8x８"], "--size"),                           # a full-width digit
    (["sweep", "--eps", "1_0e-3"], "is not a number"),                 # float() takes underscores
    (["ucurve", "--u", "0_3"], "is not a number"),
    (["ucurve", "--eps", "1e-3,٣e-4"], "is not a number"),
])
def test_options_take_neither_abbreviations_nor_other_digits(argv, fragment, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)                 # a wrong variant that accepts --siz writes x.png here
    rc, out, err = run(argv, capsys)
    assert rc == 2 and out == "" and fragment in err and err.count("\n") == 1, err


def test_an_error_line_does_not_repeat_a_huge_value(capsys):
    rc, out, err = run(["render", "--size", "9" * 900_000], capsys)
    assert rc == 2 and err.startswith("symrender: error: ") and err.count("\n") == 1
    assert len(err) < 700 and err.rstrip().endswith("characters)"), err[-200:]


# ------------------------------------------------------------------ render's frames


@pytest.mark.parametrize("view", cli.VIEWS)
@pytest.mark.parametrize("gradient", ["exact", "central", "footprint"])
def test_render_holds_at_most_two_frames(tmp_path, capsys, monkeypatch, gradient, view):
    """The pixel budget counts two frames: when another frame is rendered, at most one
    earlier frame is still held (the footprint frame replaces the central one; the
    difference view does not render it at all)."""
    import importlib
    import weakref
    module = importlib.import_module("renderer.render")
    real, made, held = module.render, [], []

    def counting(*args, **kwargs):
        held.append(sum(ref() is not None for ref in made))
        frame = real(*args, **kwargs)
        made.append(weakref.ref(frame.image))
        return frame

    monkeypatch.setattr(module, "render", counting)
    out = tmp_path / "o.png"
    assert run(["render", "--size", "16x12", "--gradient", gradient, "--view", view, "-o", str(out)], capsys)[0] == 0
    shown = gradient == "footprint" and view != "difference"
    assert len(held) == 2 + shown and max(held) <= 1, held


@pytest.mark.parametrize("view", cli.VIEWS)
def test_footprint_views_match_the_library(tmp_path, capsys, view):
    out = tmp_path / "o.png"
    rc, stdout, _ = run(["render", "--size", SMALL, "--gradient", "footprint", "--view", view, "-o", str(out)], capsys)
    numeric, symbolic = render(Scene(), 48, 40, gradient="central"), render(Scene(), 48, 40)
    selected = render(Scene(), 48, 40, gradient="footprint")
    want = cli.view_image(view, selected, numeric, symbolic)
    assert rc == 0 and ledger_problems(stdout, compare(numeric, symbolic)) == []
    np.testing.assert_array_equal(read_png(out), expected_pixels(want))
    if view != "difference":                  # the view shows the footprint frame, not the central one
        assert not np.array_equal(want, cli.view_image(view, numeric, numeric, symbolic))


# ------------------------------------------------------------------ every limit at the limit and one past


class Reached(Exception):
    """Raised by a stand-in for the work: the arguments passed every check."""


def _past(x, direction):
    return repr(float(np.nextafter(x, direction)))


LIMIT_CASES = [
    # (argv, the word of the refusal or None: accepted)
    (["render", "--size", "8192x1"], None), (["render", "--size", "8193x1"], "between 1 and 8192"),
    (["render", "--size", "1x1"], None), (["render", "--size", "1x0"], "between 1 and 8192"),
    (["render", "--size", "4096x4096"], None), (["render", "--size", "4097x4096"], "at most 16,777,216"),
    (["sweep", "--eps", "1e-3", "--size", "4096x4096"], None),
    (["sweep", "--eps", "1e-3", "--size", "4097x4096"], "at most 16,777,216"),
    (["sweep", "--eps", "1e-1:1e-7:7", "--size", "2048x2048"], None),
    (["sweep", "--eps", "1e-1:1e-8:8", "--size", "2048x2048"], "at most 33,554,432"),
    (["sweep", "--eps", "1e-1:1e-8:64", "--size", "8x8"], None),
    (["sweep", "--eps", "1e-1:1e-8:65", "--size", "8x8"], "between 1 and 64"),
    (["sweep", "--eps", ",".join(["1e-3"] * 65), "--size", "8x8"], "1 to 64 steps"),
    (["sweep", "--eps", "1e-16,0.25", "--size", "8x8"], None),
    (["sweep", "--eps", _past(0.25, 1), "--size", "8x8"], f"--eps must be in [1e-16, 0.25], got {_past(0.25, 1)}"),
    (["sweep", "--eps", _past(1e-16, 0), "--size", "8x8"], "--eps must be in [1e-16, 0.25]"),
    (["ucurve", "--u", "0", "--v", "1"], None), (["ucurve", "--u", "1"], None),
    (["ucurve", "--u", _past(1.0, 2)], f"--u must be in [0, 1], got {_past(1.0, 2)}"),
    (["ucurve", "--v", "-5e-324"], "--v must be in [0, 1], got -5e-324"),
    (["ucurve", "--k-u", "1000", "--k-v", "5e-324"], None),
    (["ucurve", "--k-u", _past(1e3, 2e3)], f"--k-u must be in (0, 1000], got {_past(1e3, 2e3)}"),
    (["ucurve", "--k-v", "0"], "--k-v must be in (0, 1000], got 0.0"),
    (["ucurve", "--eps", f"1e-300,{_past(1.0, 0)}"], None),
    (["ucurve", "--eps", "1"], "--eps must be in [1e-300, 1), got 1.0 at flat index 0"),
    (["ucurve", "--eps", f"1e-3,{_past(1e-300, 0)}"], "--eps must be in [1e-300, 1)"),
    (["ucurve", "--eps", "1e-1:1e-15:10000"], None), (["ucurve", "--eps", "1e-1:1e-15:10001"], "between 1 and 10000"),
    (["render", "--set", "center_b=" + "[" * 8 + "]" * 8], "Scene.center_b"),
    (["render", "--set", "center_b=" + "[" * 9 + "]" * 9], "nested too deeply (at most 8 levels"),
]


@pytest.mark.parametrize("argv, word", LIMIT_CASES, ids=[" ".join(a)[:50] for a, _ in LIMIT_CASES])
def test_command_line_limits_at_the_limit_and_one_past(tmp_path, capsys, monkeypatch, argv, word):
    """Accepted: the command reaches its work (a stand-in raises `Reached`, reported as a bug);
    refused: exit 2 with the limit named, before any work."""
    import importlib

    def reach(*args, **kwargs):
        raise Reached
    for module, name in (("renderer.render", "render"), ("renderer.sweep", "sweep"), ("renderer.ucurve", "measure")):
        monkeypatch.setattr(importlib.import_module(module), name, reach)
    if argv[0] == "render":
        argv = [*argv, "-o", str(tmp_path / "o.png")]
    rc, out, err = run(argv, capsys)
    if word is None:
        assert (rc, err) == (1, "symrender: internal error: Reached: \n"), err
    else:
        assert rc == 2 and err.startswith("symrender: error: ") and word in err, err
    assert out == "" and list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ input errors and bugs


def test_an_input_error_the_library_finds_is_exit_2_and_a_bug_is_exit_1(tmp_path, capsys, monkeypatch):
    """``ucurve --eps 2`` passed the command line's checks and `measure` refused it:
    "internal error", exit 1.  A ValueError that is not the library's validation stays a bug."""
    rc, _, err = run(["ucurve", "--eps", "2"], capsys)
    assert (rc, err) == (2, "symrender: error: --eps must be in [1e-300, 1), got 2.0 at flat index 0\n")
    rc, _, err = run(["render", "--size", "8x8", "--set", "bump=surface", "--set", "beta=1",
                      "-o", str(tmp_path / "o.png")], capsys)
    assert rc == 2 and err.startswith("symrender: error: Scene.beta must be < radius_a")
    import importlib

    def broken(*args, **kwargs):
        raise ValueError("a bug")
    monkeypatch.setattr(importlib.import_module("renderer.render"), "render", broken)
    rc, _, err = run(["render", "--size", "8x8", "-o", str(tmp_path / "o.png")], capsys)
    assert (rc, err) == (1, "symrender: internal error: ValueError: a bug\n") and list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ full and closed standard streams


def symrender(argv, cwd, code=None, **kwargs):
    """Run ``python -m renderer.cli`` (or ``code``, a harness) with ``argv``; the CompletedProcess."""
    head = [sys.executable, "-c", code] if code else [sys.executable, "-m", "renderer.cli"]
    return subprocess.run([*head, *argv], cwd=cwd, timeout=600, **kwargs)


@pytest.fixture(scope="module")
def reference_png(tmp_path_factory):
    """The bytes of ``render --size 8x8`` (the PNG every stream test expects, or none)."""
    d = tmp_path_factory.mktemp("ref")
    assert main(["render", "--size", "8x8", "-o", str(d / "ref.png")]) == 0
    return (d / "ref.png").read_bytes()


@pytest.mark.parametrize("argv", [["render", "--size", "8x8", "-o", "y.png"],
                                  ["ucurve", "--eps", "1e-3", "--plot", "y.png"]], ids=["render", "ucurve"])
def test_a_full_stdout_leaves_no_output_file(tmp_path, argv):
    """``>/dev/full``: the report cannot be written, so the output is not put in place (it was
    written, and the command exited 2)."""
    with open("/dev/full", "w") as full:
        done = symrender(argv, tmp_path, stdout=full, stderr=subprocess.PIPE)
    assert done.returncode == 2, done.stderr
    assert done.stderr == b"symrender: error: standard output: No space left on device\n"
    assert list(tmp_path.iterdir()) == []


def test_a_full_stderr_changes_nothing_written(tmp_path, reference_png):
    """``2>/dev/full``: nothing needs stderr for ``-o y.png``: the PNG and the report as ever."""
    with open("/dev/full", "w") as full:
        done = symrender(["render", "--size", "8x8", "-o", "y.png"], tmp_path, stdout=subprocess.PIPE, stderr=full)
    assert done.returncode == 0 and b"ledger" in done.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["y.png"] and (tmp_path / "y.png").read_bytes() == reference_png


def test_output_on_stdout_with_a_full_stderr_writes_no_png(tmp_path):
    """``-o - 2>/dev/full``: the report (on stderr) cannot be written: exit 2 and no PNG on stdout."""
    with open("/dev/full", "w") as full:
        done = symrender(["render", "--size", "8x8", "-o", "-"], tmp_path, stdout=subprocess.PIPE, stderr=full)
    assert done.returncode == 2 and done.stdout == b"" and list(tmp_path.iterdir()) == []


#: A harness: symrender, with a message written to descriptor 2 while the output file is
#: open (as a C library's warning would be), then the PNG completed.
NOISY = ("import os, sys, renderer.files as files\n"
         "real = files.os.fsync\n"
         "def fsync(fd):\n"
         "    try:\n"
         "        os.write(2, b'a message for standard error\\n')\n"
         "    except OSError:\n"
         "        pass\n"
         "    real(fd)\n"
         "files.os.fsync = fsync\n"
         "from renderer.cli import main\n"
         "sys.exit(main())\n")


def test_a_closed_stderr_loses_messages_and_changes_nothing_written(tmp_path, reference_png):
    """``2>&-``: the run used to end in an AttributeError printed on stdout (``-o -``: into the
    PNG stream).  Now the PNG and the report are as ever, though a message goes to descriptor
    2 while the output is open (`NOISY`): with the descriptor left closed, the output file
    would take its number, and the message would land in the PNG."""
    done = symrender(["render", "--size", "8x8", "-o", "x.png"], tmp_path, NOISY, stdout=subprocess.PIPE,
                     preexec_fn=lambda: os.close(2))
    assert done.returncode == 0 and done.stdout.startswith(b"wrote x.png")
    assert [p.name for p in tmp_path.iterdir()] == ["x.png"] and (tmp_path / "x.png").read_bytes() == reference_png
    done = symrender(["render", "--size", "8x8", "-o", "-"], tmp_path, NOISY, stdout=subprocess.PIPE,
                     preexec_fn=lambda: os.close(2))
    assert done.returncode == 0 and done.stdout == reference_png


# ------------------------------------------------------------------ the environment


@pytest.mark.parametrize("value", ["0", "-1", "abc", "", "2.5", "1e3"])
def test_numba_num_threads_that_is_not_a_positive_integer_is_one_line(tmp_path, value):
    """numba printed a 9-line warning with a traceback for "abc" and failed as a bug for "0"."""
    done = symrender(["render", "--size", "4x4", "-o", "z.png"], tmp_path, capture_output=True, text=True,
                     env={**os.environ, "NUMBA_NUM_THREADS": value})
    assert (done.returncode, done.stderr) == (2, "symrender: error: the environment variable NUMBA_NUM_THREADS must "
                                                 f"be a positive integer (numba's thread count), got {value!r}\n")
    assert list(tmp_path.iterdir()) == []


def test_numba_num_threads_at_its_limit_renders(tmp_path):
    done = symrender(["render", "--size", "4x4", "-o", "z.png"], tmp_path, capture_output=True, text=True,
                     env={**os.environ, "NUMBA_NUM_THREADS": "1"})
    assert done.returncode == 0 and done.stderr == "" and (tmp_path / "z.png").exists()


def test_an_unwritable_home_adds_nothing_to_stderr(tmp_path):
    """matplotlib logged two warnings (its config and cache directories fell back to a
    temporary one) where $HOME cannot be written: here HOME is a file (root writes anywhere
    else), with the XDG directories unset (matplotlib would use them first)."""
    home = tmp_path / "home"
    home.write_text("not a directory")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("XDG_", "MPLCONFIGDIR"))}
    done = symrender(["ucurve", "--eps", "1e-3", "--plot", "p.png"], tmp_path, capture_output=True,
                     env={**env, "HOME": str(home)})
    assert done.returncode == 0 and done.stderr == b"", done.stderr
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
