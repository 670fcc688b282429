"""Tests of the ``symrender`` command line (renderer/cli.py), in-process through ``main([...])``.

Each subcommand runs once on real input and its output is checked against the library
called directly, with the views' formulas written out here; each kind of failure is one
line and its exit code once; the report comes before the output.  Signals are
tests/test_interrupts.py's, the atomic write tests/test_files.py's.
"""

from __future__ import annotations

import contextlib
import errno
import csv
import io
import json
import math
import os
import re
import signal
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import renderer.cli as cli
from renderer import PointLight, Scene, compare, render, sweep, to_srgb
from renderer.formulas import FIELDS
from renderer.cli import main


def run(argv, capsys):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def one_line(rc, err, code=2, kind="error"):
    """Whether a run failed as it should: exit ``code`` and one line ``symrender: <kind>: ...``."""
    return rc == code and err.count("\n") == 1 and err.startswith(f"symrender: {kind}: ")


def read_png(path_or_bytes):
    from PIL import Image
    with Image.open(io.BytesIO(path_or_bytes) if isinstance(path_or_bytes, bytes) else path_or_bytes) as im:
        return np.asarray(im.convert("RGB"))


def png_chunks(data):
    """The chunk types of a PNG file, in order (PNG spec, section 5.3)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    types, pos = [], 8
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        types.append(data[pos + 4:pos + 8].decode("ascii"))
        pos += 12 + length
    return types


def bytes8(rgb):
    return np.round(np.clip(rgb, 0, 1) * 255).astype(np.uint8)


def agrees(text, want):
    """A printed value (4 significant digits, "none..." for NaN) against the library's."""
    if text.startswith("none"):
        return math.isnan(want)
    return math.isclose(float(text), want, rel_tol=1e-3, abs_tol=1e-300)


LEDGER = {"max |dI|": "max_abs", "RMS |dI|": "rms", "flips": "flips", "pixels on A": "pixels_a",
          "mean |dI| on band": "mean_abs_kink", "mean |dI| off band": "mean_abs_off_kink"}


def ledger_problems(report, led):
    """The `Ledger` fields the report's labelled lines do not show under their own label."""
    got = {m[1]: m[2] for m in re.finditer(r"^  (.+?)\s{2,}(\S.*)$", report, re.M)}
    return [f for label, f in LEDGER.items() if label not in got or not agrees(got[label], getattr(led, f))]


# ------------------------------------------------------------------ render


@pytest.mark.parametrize("view, gradient", [("shaded", "exact"), ("difference", "central"), ("bump", "central"),
                                            ("kink", "footprint"), ("bump", "footprint")])
def test_render_writes_the_view_and_prints_the_ledger(tmp_path, capsys, view, gradient):
    out = tmp_path / "o.png"
    rc, report, err = run(["render", "--size", "48x40", "--view", view, "--gradient", gradient,
                           "--set", "beta=0.5", "-o", out], capsys)
    assert rc == 0 and err == "" and report.startswith(f"wrote {out}")
    scene = Scene(beta=0.5)
    numeric, symbolic = render(scene, 48, 40, gradient="central"), render(scene, 48, 40)
    sel = {"exact": symbolic, "central": numeric}.get(gradient) or render(scene, 48, 40, gradient="footprint")
    if view == "shaded":
        want = to_srgb(sel.image)
    elif view == "difference":
        want = np.clip(100 * np.abs(numeric.image - symbolic.image), 0, 1)
    elif view == "bump":
        gmax = np.hypot(*np.moveaxis(symbolic.grad, 2, 0))[symbolic.chamber == 1].max()
        g = np.where(sel.chamber == 1, to_srgb(np.minimum(np.hypot(*np.moveaxis(sel.grad, 2, 0)) / gmax, 1)), 0)
        want = np.stack([g] * 3, axis=2)
    else:
        want = 0.4 * to_srgb(sel.image)
        want[symbolic.kink] = 1.0
    np.testing.assert_array_equal(read_png(out), bytes8(want))
    assert ledger_problems(report, compare(numeric, symbolic)) == []


def test_the_checks_see_a_wrong_view_and_swapped_labels(tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    rc, report, _ = run(["render", "--size", "24x20", "-o", a], capsys)
    assert rc == 0 and run(["render", "--size", "24x20", "--view", "kink", "-o", b], capsys)[0] == 0
    assert not np.array_equal(read_png(a), read_png(b))
    led = compare(render(Scene(), 24, 20, gradient="central"), render(Scene(), 24, 20))
    swapped = report.replace("max |dI|  ", "XXX").replace("RMS |dI|  ", "max |dI|  ").replace("XXX", "RMS |dI|  ")
    assert ledger_problems(report, led) == [] and ledger_problems(swapped, led) == ["max_abs", "rms"]


def test_png_bytes_are_the_same_on_every_run_and_carry_no_metadata(tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    for p in (a, b):
        assert run(["render", "--size", "16x12", "-o", p], capsys)[0] == 0
    assert a.read_bytes() == b.read_bytes() and set(png_chunks(a.read_bytes())) == {"IHDR", "IDAT", "IEND"}
    # Wrong variant: matplotlib's default metadata adds a Software tEXt chunk.
    import matplotlib.image
    buf = io.BytesIO()
    matplotlib.image.imsave(buf, read_png(a), format="png")
    assert "tEXt" in png_chunks(buf.getvalue())


def test_render_holds_at_most_two_frames(tmp_path, capsys, monkeypatch):
    """The library's pixel limit is per frame, and render holds two: the footprint frame
    takes the central frame's place."""
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
    assert run(["render", "--size", "16x12", "--gradient", "footprint", "-o", tmp_path / "o.png"], capsys)[0] == 0
    assert held == [0, 1, 1]


def test_output_dash_is_the_png_on_stdout_and_the_report_on_stderr(tmp_path, capsys, monkeypatch):
    out = tmp_path / "o.png"
    rc, report, _ = run(["render", "--size", "16x12", "-o", out], capsys)
    stdout = io.TextIOWrapper(io.BytesIO(), encoding="utf-8")
    monkeypatch.setattr(sys, "stdout", stdout)
    assert main(["render", "--size", "16x12", "-o", "-"]) == 0
    stdout.flush()
    assert stdout.buffer.getvalue() == out.read_bytes()
    assert capsys.readouterr().err.splitlines()[1:] == report.splitlines()[1:]


# ------------------------------------------------------------------ scenes


def test_a_scene_file_with_set_overrides(tmp_path, capsys):
    toml = tmp_path / "scene.toml"
    toml.write_text('height_field = "rings"\nbeta = 0.8\nfloor = false\ncenter_b = [0.4, 0.5, 1.2]\n'
                    "[[lights]]\nposition = [5, 5, 10]\ncolor = [1.0, 0.9, 0.8]\n", encoding="utf-8-sig")
    out = tmp_path / "o.png"
    rc, _, err = run(["render", "--scene", toml, "--set", "beta=0.25", "--set", "k_u=6", "--size", "24x20",
                      "-o", out], capsys)
    scene = Scene(height_field="rings", beta=0.25, floor=False, center_b=(0.4, 0.5, 1.2), k_u=6.0,
                  lights=(PointLight((5, 5, 10), (1.0, 0.9, 0.8)),))
    assert rc == 0 and cli.load_scene(toml).beta == 0.8
    np.testing.assert_array_equal(read_png(out), bytes8(to_srgb(render(scene, 24, 20).image)))


@pytest.mark.parametrize("text, value", [
    ("height_field=sine", "sine"), ("height_field=0", "0"), ('model="phong"', "phong"), ("floor=false", False), ("k_v=3", 3.0),
    ("center_b=[0.5, 0.5, 1.4]", (0.5, 0.5, 1.4)),
    ("lights=[{position=[1, 2, 3], color=[0.5, 0.5, 0.5]}]", (PointLight((1, 2, 3), (0.5, 0.5, 0.5)),)),
])
def test_set_takes_toml_values_and_bare_words(text, value):
    key = text.partition("=")[0]
    assert getattr(cli.load_scene(None, [text]), key) == value


def test_field_sets_the_height_field_after_the_file_and_before_set(tmp_path, capsys):
    """``--field`` of render and sweep, as ucurve's: a name or an expression, over the file's field, under
    ``--set``'s; a wrong one refused in one line naming --field."""
    toml = tmp_path / "scene.toml"
    toml.write_text('height_field = "rings"\n', encoding="utf-8")
    assert cli.load_scene(toml, (), "ridges").height_field == "ridges"
    assert cli.load_scene(toml, ("height_field=sine",), "ridges").height_field == "sine"
    assert cli.load_scene(None, (), "u*v").height_field == "u*v"
    rc, out, err = run(["sweep", "--field", "ridges", "--size", "8x8", "--eps", "1e-3"], capsys)
    assert rc == 0 and out.startswith("census: ridges,")
    rc, _, err = run(["render", "--field", "bumpz", "-o", tmp_path / "o.png"], capsys)
    assert one_line(rc, err) and "--field" in err and "'bumpz'" in err and not (tmp_path / "o.png").exists()


def test_a_value_that_is_not_toml_reaches_the_library_as_a_string(tmp_path, capsys):
    """``height_field`` may be an expression of u and v: the library accepts it, or refuses it by name."""
    assert cli._toml_value("sin(2*pi*u) * v") == "sin(2*pi*u) * v"
    rc, _, err = run(["render", "--size", "8x8", "--set", "height_field=sin(2*pi*u)*v", "-o", tmp_path / "o.png"],
                     capsys)
    assert (rc, err) == (0, "") and (tmp_path / "o.png").stat().st_size > 0
    rc, _, err = run(["render", "--set", "height_field=sin(2*pi*w)", "-o", tmp_path / "p.png"], capsys)
    assert one_line(rc, err) and "height_field" in err and "'w'" in err and not (tmp_path / "p.png").exists()


def test_ucurve_of_a_function_of_one_variable(capsys):
    """``--function`` measures f(x) at ``--x`` (Squire and Trapp's test function); a point where f is not
    differentiable is one input error naming --function."""
    f = "exp(x)/sqrt(sin(x)**3 + cos(x)**3)"
    rc, out, err = run(["ucurve", "--function", f, "--x", "1.5", "--eps", "1e-2,1e-5"], capsys)
    assert rc == 0 and err == "" and "true derivative 4.05342789389862" in out and "f' at x = 1.5" in out
    rc, _, err = run(["ucurve", "--function", "abs(x - 1)", "--x", "1"], capsys)
    assert one_line(rc, err) and err.startswith("symrender: error: --function")


LIGHTS = "[[lights]]\nposition = [1, 2, 3]\ncolor = [1, 1, 1]\n"


@pytest.mark.parametrize("text, path", [
    (LIGHTS + LIGHTS.replace("[1, 1, 1]", "[1, 1, -1]"), "lights[1].color"),
    ("[[lights]]\nposition = [1, 2, 3]\n", "lights[0]"),
    ("lights = 3\n", "lights"),
    ("beta = 0.5\nshine = 3\n", "shine"),
    ("beta = 'x'\n", "beta"),
    ("beta = \n", "line 1"),
])
def test_scene_file_errors_name_the_file_and_the_key(tmp_path, capsys, text, path):
    toml = tmp_path / "bad.toml"
    toml.write_text(text)
    rc, out, err = run(["render", "--scene", toml, "-o", tmp_path / "o.png"], capsys)
    assert one_line(rc, err) and str(toml) in err and path in err and out == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


# ------------------------------------------------------------------ errors


@pytest.mark.parametrize("argv, name", [
    (["render", "--view", "sideways", "-o", "OUT"], "--view"),                     # argparse
    (["render", "--size", "64", "-o", "OUT"], "--size"),                           # the command's parser
    (["render", "--set", "beta", "-o", "OUT"], "--set"),
    (["render", "--set", "beta=0.5\nradius_a=2", "-o", "OUT"], "--set"),        # TOML dropped the second line
    (["render", "--set", "beta=-1", "-o", "OUT"], "beta"),                         # the library: Scene
    (["render", "--size", "0x8", "-o", "OUT"], "width"),                           # render
    (["sweep", "--eps", "1e-3,0.5", "--size", "8x8"], "--eps"),                    # sweep's steps
    (["ucurve", "--k-v", "0"], "--k-v"),                                           # measure
    (["render", "--scene", "DIR/none.toml", "-o", "OUT"], "none.toml"),            # a file not found
    (["render", "-o", "DIR/no/o.png"], "-o"),                                      # no such directory
    (["ucurve", "--eps", "1e-3", "--plot", "DIR"], "--plot"),
])
def test_an_input_error_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, argv, name):
    argv = [a.replace("OUT", str(tmp_path / "o.png")).replace("DIR", str(tmp_path)) for a in argv]
    rc, out, err = run(argv, capsys)
    assert one_line(rc, err) and name in err and out == "" and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command, most", [("sweep", 64), ("ucurve", 10_000)])
def test_each_command_refuses_more_steps_than_it_takes_naming_its_own_limit(capsys, command, most):
    """``--eps`` as a:b:n or as a list: one step more than the command takes (sweep's are the library's
    `renderer.sweep.MAX_STEPS`), or none, is refused by the parser naming the command's limit; as many
    as it takes are accepted."""
    from renderer.sweep import MAX_STEPS
    assert most == {"sweep": MAX_STEPS, "ucurve": cli.MAX_STEPS}[command]
    size = ["--size", "2x2"] if command == "sweep" else []
    for eps in (f"1e-1:1e-8:{most + 1}", ",".join(["1e-3"] * (most + 1)), "1e-1:1e-8:0"):
        rc, out, err = run([command, "--eps", eps, *size], capsys)
        got = "0" if eps.endswith(":0") else f"{most + 1:,}"
        assert one_line(rc, err) and f"--eps: must hold 1 to {most:,} steps, got {got}" in err and out == "", err
    if command == "sweep":
        assert run([command, "--eps", f"1e-1:1e-8:{most}", *size], capsys)[0] == 0


def test_a_bug_is_one_line_exit_1_and_writes_nothing(tmp_path, capsys, monkeypatch):
    """A ValueError that is not the library's `InputError` is a bug, not an input error."""
    import importlib

    def broken(*args, **kwargs):
        raise ValueError("a bug")
    monkeypatch.setattr(importlib.import_module("renderer.render"), "render", broken)
    rc, out, err = run(["render", "--size", "8x8", "-o", tmp_path / "o.png"], capsys)
    assert one_line(rc, err, 1, "internal error") and "ValueError" in err and "Traceback" not in err
    assert out == "" and list(tmp_path.iterdir()) == []


def test_field_reaches_the_library_as_given(capsys, monkeypatch):
    """No argparse choices for --field: the library decides, and its refusal is named by the option."""
    import renderer.ucurve
    from renderer.validate import InvalidValue
    seen = []

    def measure(field, **kwargs):
        seen.append(field)
        raise InvalidValue(f"field cannot be {field!r}")
    monkeypatch.setattr(renderer.ucurve, "measure", measure)
    rc, _, err = run(["ucurve", "--field", "sin(2*pi*u)*v"], capsys)
    assert seen == ["sin(2*pi*u)*v"] and one_line(rc, err) and err.startswith("symrender: error: --field")


def test_a_full_stdout_leaves_no_output(tmp_path, capsys, monkeypatch):
    """The report comes first: when it cannot be written, the output is not put in place."""
    with open("/dev/full", "w") as full:
        monkeypatch.setattr(sys, "stdout", full)
        rc = main(["render", "--size", "8x8", "-o", str(tmp_path / "o.png")])
    assert one_line(rc, capsys.readouterr().err) and list(tmp_path.iterdir()) == []


def test_a_reader_that_left_is_quiet(capsys, monkeypatch):
    """``symrender sweep | head -1``: exit 1 and nothing on stderr."""
    read, write = os.pipe()
    os.close(read)
    with open(write, "w") as pipe:
        monkeypatch.setattr(sys, "stdout", pipe)
        rc = main(["sweep", "--size", "8x8", "--eps", "1e-2"])
    assert rc == 1 and capsys.readouterr().err == ""


# ------------------------------------------------------------------ sweep and ucurve


def test_sweep_reports_the_librarys_census_in_each_format(capsys):
    steps = cli._steps("1e-1:1e-6:6")
    assert steps == [1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6] and cli._steps("1e-3,2e-4") == [1e-3, 2e-4]
    ridges = sweep(Scene(), steps, 40, 32).census
    rc, out, _ = run(["sweep", "--eps", "1e-1:1e-6:6", "--size", "40x32", "--format", "csv"], capsys)
    rows = list(csv.DictReader(io.StringIO(out)))
    assert rc == 0 and [float(r["eps"]) for r in rows] == steps
    assert all(float(r[c]) == getattr(led, c) for r, led in zip(rows, ridges) for c in cli.COLUMNS[1:])
    sine = sweep(Scene(height_field="sine"), [1e-2, 1e-5], 40, 32).census
    args = ["sweep", "--eps", "1e-2,1e-5", "--size", "40x32", "--set", "height_field=sine", "--format"]
    rc, out, _ = run([*args, "csv"], capsys)
    assert rc == 0 and [r["mean_abs_kink"] for r in csv.DictReader(io.StringIO(out))] == ["", ""]   # no band
    rc, out, _ = run([*args, "json"], capsys)
    doc = json.loads(out)
    assert rc == 0 and doc["size"] == [40, 32] and doc["height_field"] == "sine"          # W, H as --size
    assert [r["mean_abs_kink"] for r in doc["rows"]] == [None, None]
    assert all(r["rms"] == led.rms for r, led in zip(doc["rows"], sine))
    rc, out, _ = run([*args, "text"], capsys)
    lines = out.splitlines()
    assert rc == 0 and lines[1].split() == ["eps", "max", "|dI|", "RMS", "|dI|", "flips", "on", "band", "off", "band"]
    fields = ("eps", "max_abs", "rms", "flips", "mean_abs_kink", "mean_abs_off_kink")
    for line, e, led in zip(lines[2:], [1e-2, 1e-5], sine, strict=True):
        assert all(agrees(c, e if f == "eps" else getattr(led, f)) for c, f in zip(line.split(), fields, strict=True))


def test_ucurve_prints_the_measurement_and_plots_it(tmp_path, capsys):
    from renderer.ucurve import measure
    plot = tmp_path / "u.png"
    rc, out, err = run(["ucurve", "--field", "sine", "--u", "0.3", "--v", "0.4", "--k-u", "6", "--k-v", "3",
                        "--eps", "1e-1:1e-12:12", "--plot", plot], capsys)
    assert rc == 0 and err == ""
    uc = measure("sine", 0.3, 0.4, "u", eps=cli._steps("1e-1:1e-12:12"), k_u=6, k_v=3)
    rows = [line.split() for line in out.splitlines() if re.match(r" *\d\.\d\de-\d\d  ", line)]
    assert len(rows) == 12
    for i, row in enumerate(rows):
        fields = ("eps", "truncation", "roundoff", "error", "model")
        assert all(agrees(c, getattr(uc, f)[i]) for c, f in zip(row, fields, strict=True))
    for pattern, names in ((r"model-optimal step eps\* (\S+), model error there (\S+)", ("eps_model", "error_model")),
                           (r"fitted optimal step eps\^ (\S+), fitted error there (\S+)",
                            ("eps_fitted", "error_at_fitted")),
                           (r"measured minimum (\S+) at eps (\S+)", ("error_at_measured_min", "eps_measured_min"))):
        m = re.search(f"^{pattern}$", out, re.M)
        assert all(agrees(m[i], getattr(uc, f)) for i, f in enumerate(names, 1)), pattern
    first = plot.read_bytes()
    assert run(["ucurve", "--field", "sine", "--u", "0.3", "--v", "0.4", "--k-u", "6", "--k-v", "3",
                "--eps", "1e-1:1e-12:12", "--plot", plot], capsys)[0] == 0
    assert plot.read_bytes() == first and "tEXt" not in png_chunks(first)
    # Where there is no derivative (at a pole) there is no optimum to print.
    rc, out, _ = run(["ucurve", "--field", "sine", "--u", "0.3", "--v", "0", "--k-u", "6", "--k-v", "3",
                      "--eps", "1e-2:1e-10:5"], capsys)
    assert rc == 0 and "not differentiable: " in out
    assert not re.search("^(true derivative|model-optimal|fitted optimal|measured minimum)", out, re.M)
    # A function with no third derivative (a line) has no model optimum, and its errors no U to fit: said so.
    rc, out, _ = run(["ucurve", "--function", "2*x + 1", "--x", "0.7", "--eps", "1e-3,1e-6"], capsys)
    assert rc == 0 and "model-optimal step eps*: none, |h'''| = 0" in out and "fitted optimal step eps^: none" in out
    assert not re.search(r"\b(inf|nan)\b", out), out


# ------------------------------------------------------------------ help and entry point


def test_help_documents_every_option_and_the_librarys_limits(capsys):
    from renderer.pointwise import MIN_STEP
    from renderer.render import MAX_PIXELS, MAX_SIDE
    from renderer.scene import MAX_EPS, MAX_FREQUENCY, MIN_EPS
    from renderer.sweep import MAX_STEPS, MAX_SWEEP_PIXELS
    limits = {"render": [MAX_SIDE, f"{MAX_PIXELS:,}"],
              "sweep": [MAX_SIDE, f"{MAX_PIXELS:,}", f"{MAX_SWEEP_PIXELS:,}", f"1 to {MAX_STEPS} steps",
                        f"[{MIN_EPS:g}, {MAX_EPS:g}]"],
              "ucurve": [f"{cli.MAX_STEPS:,}", f"[{MIN_STEP:g}, 1)", f"(0, {MAX_FREQUENCY:g}]"]}
    parsers = cli.build_parser()._subparsers._group_actions[0].choices
    for command, words in limits.items():
        rc, out, err = run([command, "--help"], capsys)
        options = [o for a in parsers[command]._actions for o in a.option_strings]
        assert rc == 0 and err == "" and out.startswith(f"usage: symrender {command}")
        assert [w for w in [*options, *map(str, words)] if str(w) not in " ".join(out.split())] == []
    from importlib import metadata
    assert run(["--version"], capsys)[1] == f"symrender {metadata.version('symbolic-rendering-ch9')}\n"


def test_the_console_script(tmp_path):
    symrender = Path(sys.executable).with_name("symrender")
    done = subprocess.run([symrender, "render", "--size", "16x12", "-o", "o.png"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0 and done.stderr == "" and "ledger" in done.stdout
    assert read_png(tmp_path / "o.png").shape == (12, 16, 3)


# ------------------------------------------------------------------ any input


OPTIONS = {
    "--size": ["8x8", "12x6", "0x0", "-3x3", "8192x8192", "8x", "abc"],
    "--set": ["beta=0.5", "beta=nan", "beta=-1", "height_field=rings", "height_field=waves", "k_v=1e400", "foo=1",
              "floor=0", "bump=surface", "beta=2", "lights=[{position=[1,2,3], color=[1,1,1]}]", "lights=[{}]",
              "eps=0", "ambient=[1,1]", "beta"],
    "--scene": ["GOOD", "BAD", "NONE", "DIR"],
    "--eps": ["1e-1:1e-8:8", "1e-2,1e-4", "1e-3", "0:1:2", "1e-3,-1", "nan", "1:2:3:4", "1e-1:1e-3:99", "x"],
    "--view": ["shaded", "difference", "bump", "kink", "xray"],
    "--gradient": ["exact", "central", "footprint", "forward"],
    "-o": ["OUT", "DIR", "DIR/none/o.png"],
    "--format": ["text", "csv", "json", "xml"],
    "--field": [*FIELDS, "waves"],
    "--u": ["0.31", "0", "1", "1.5", "nan", "x"],
    "--component": ["u", "v", "w"],
    "--k-u": ["8", "0", "1e300"],
    "--plot": ["PLOT", "DIR", "DIR/none/p.png"],
}
TOML = ['beta = 0.5\nheight_field = "rings"\n', "beta = \n", "shine = 1\n", "beta = nan\n", "lights = \"x\"\n",
        "[[lights]]\nposition = [1, 2, 3]\ncolor = [1, 1, -1]\n", "radius_a = 1e999\n", "[beta]\nx = 1\n"]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(command=st.sampled_from(["render", "sweep", "ucurve"]), toml=st.sampled_from(TOML), pairs=st.lists(
    st.sampled_from(sorted(OPTIONS)).flatmap(lambda o: st.tuples(st.just(o), st.sampled_from(OPTIONS[o]))),
    max_size=4))
def test_any_input_succeeds_or_is_one_input_error(command, toml, pairs):
    """Whatever the options: exit 0 with only the named outputs, or one line, exit 2 and nothing written."""
    with tempfile.TemporaryDirectory() as d:
        (Path(d) / "good.toml").write_text(TOML[0])
        (Path(d) / "bad.toml").write_text(toml)
        names = {"OUT": "o.png", "PLOT": "p.png", "GOOD": "good.toml", "BAD": "bad.toml", "NONE": "none.toml",
                 "DIR": ""}
        argv = [command, *(["--size", "8x8"] if command != "ucurve" else ["--eps", "1e-2,1e-6"])]
        for option, value in pairs:
            head, _, tail = value.partition("/")
            argv += [option, str(Path(d, names[head], tail)) if head in names else value]
        before = sorted(os.listdir(d))
        out, err = io.StringIO(), io.StringIO()
        with contextlib.chdir(d), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(argv)
        added = set(os.listdir(d)) - set(before)
        ok = rc == 0 and added <= {"o.png", "p.png"} or one_line(rc, err.getvalue()) and not added
        assert ok, (argv, err.getvalue())


def ucurve_drift(parser, measure):
    """Where ``symrender ucurve``'s parser departs from the library it calls: each option that passes a
    parameter of ``measure`` whose default differs from that parameter's default in the signature, or
    whose help does not print the default the command runs with (an option given no default passes
    nothing, and the library's default applies)."""
    import inspect
    parsers = parser._subparsers._group_actions[0].choices
    actions = {a.dest: a for a in parsers["ucurve"]._actions}
    out = []
    for name, p in inspect.signature(measure).parameters.items():
        if name not in actions or p.default is None:
            continue
        a = actions[name]
        runs = p.default if a.default is None else a.default
        shown = f"{runs:g}" if isinstance(runs, float) else str(runs)
        if runs != p.default or f"(default {shown})" not in a.help:
            out.append(f"--{name.replace('_', '-')}: default {a.default!r}, help {a.help!r}; the library's {p.default!r}")
    return out


def test_the_ucurve_commands_defaults_are_the_librarys(monkeypatch):
    """The parser types its defaults (importing sympy for ``--help`` would cost half a second), so they are
    held to `renderer.ucurve.measure`'s: the seed's point and frequencies, the field and the component, each
    also as its help prints it.  A library default moved (the seed's point nudged) and a help printing
    another default are caught."""
    import inspect

    import renderer.ucurve
    assert ucurve_drift(cli.build_parser(), renderer.ucurve.measure) == []
    real = renderer.ucurve.measure

    def moved(field="sine", u=0.32, v=real.__defaults__[2], component="v", eps=None, k_u=8.0, k_v=5.0):
        raise AssertionError("not called")
    assert [line.split(":")[0] for line in ucurve_drift(cli.build_parser(), moved)] == ["--u", "--component", "--k-v"]
    parser = cli.build_parser()
    v = next(a for a in parser._subparsers._group_actions[0].choices["ucurve"]._actions if a.dest == "v")
    d = inspect.signature(real).parameters["v"].default
    v.help = v.help.replace(f"(default {d:g})", f"(default {d / 2:g})")
    assert [line.split(":")[0] for line in ucurve_drift(parser, real)] == ["--v"]


@pytest.mark.parametrize("output", ["", "sub/", "{tmp}/"])
def test_an_output_that_names_no_file_is_refused_before_any_work(tmp_path, monkeypatch, capsys, output):
    """An empty name and a name ending in a slash (a directory, existing or not) are refused in one line
    naming ``-o``; before, "sub/" wrote a file named sub and "" failed at the end with "Is a directory"."""
    monkeypatch.chdir(tmp_path)
    rc, out, err = run(["render", "--size", "4x4", "-o", output.format(tmp=tmp_path)], capsys)
    assert one_line(rc, err) and err.startswith("symrender: error: -o ") and out == "", err
    assert list(tmp_path.iterdir()) == []


def test_a_write_that_fails_says_so_without_having_said_wrote(tmp_path, monkeypatch, capsys):
    """A full disk (the write into the temporary file fails) and a full device (/dev/full, written
    through) are one line naming the path, and the report, which says "wrote", is not printed."""
    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")
    with monkeypatch.context() as m:
        m.setattr(os, "fsync", full)
        rc, out, err = run(["render", "--size", "4x4", "-o", tmp_path / "a.png"], capsys)
    assert one_line(rc, err) and f"{tmp_path / 'a.png'}: No space left" in err and out == "", (out, err)
    assert list(tmp_path.iterdir()) == []
    if Path("/dev/full").exists():
        rc, out, err = run(["render", "--size", "4x4", "-o", "/dev/full"], capsys)
        assert one_line(rc, err) and "/dev/full: No space left" in err and out == "", (out, err)


def test_a_signal_once_the_output_is_in_place_is_held_and_the_command_succeeds(tmp_path, monkeypatch, capsys):
    """A signal between the output's rename and the command's end: the work is done, so exit 0 with
    the output and its report, the signal ignored.  Before, a signal there (or after the handlers were
    restored) ended the command 130, the output in place, without a word.  One just before the rename
    still stops it: 130, "interrupted", nothing left."""
    real = os.replace

    def signal_then_replace(after):
        def replace(src, dst):
            if not after:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.1)                 # the handler runs at the next bytecode, before the rename
            real(src, dst)
            if after:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.1)
        return replace
    monkeypatch.setattr(os, "replace", signal_then_replace(after=True))
    rc, out, err = run(["render", "--size", "4x4", "-o", tmp_path / "a.png"], capsys)
    assert (rc, err) == (0, "") and out.startswith("wrote ") and (tmp_path / "a.png").is_file()
    monkeypatch.setattr(os, "replace", signal_then_replace(after=False))
    rc, out, err = run(["render", "--size", "4x4", "-o", tmp_path / "b.png"], capsys)
    assert (rc, err) == (130, "symrender: interrupted\n") and sorted(p.name for p in tmp_path.iterdir()) == ["a.png"]


@pytest.mark.parametrize("argv, said", [
    (["--x", "2"], "--x applies only with --function"),
    (["--function", "x", "--k-u", "0"], "--k-u measures a height field, not --function"),
    (["--function", "x", "--u", "0.3"], "--u measures a height field, not --function"),
    (["--function", "x", "--component", "v"], "--component measures a height field, not --function"),
])
def test_an_option_of_the_other_measurement_is_refused_not_ignored(capsys, argv, said):
    """``ucurve``'s options each belong to one kind of measurement, a field's or a function's; given with
    the other, it was silently ignored (an out-of-range --k-u 0 too)."""
    rc, out, err = run(["ucurve", *argv], capsys)
    assert one_line(rc, err) and said in err and out == "", err


@pytest.mark.parametrize("command, size", [("render", "0x5"), ("sweep", "5x9000")])
def test_a_size_out_of_range_is_refused_naming_the_option(tmp_path, capsys, command, size):
    """A side outside the library's range is refused naming ``--size`` and the side (the library's own
    message named only "width", which the command line has no option for)."""
    rc, out, err = run([command, "--size", size, *(["-o", tmp_path / "a.png"] if command == "render" else [])], capsys)
    side = "width" if size.startswith("0") else "height"
    assert one_line(rc, err) and err.startswith(f"symrender: error: --size {side} must be") and out == "", err
