"""Tests of book/check_figures.py, the maintainers' figure rebuild and check.

The real §1 page runs once (its figures written and checked afresh); manifests are
tampered with on purpose and must be refused before any page runs; the tolerance
is shown passing a last-bit change and failing a real one.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import os
import signal
import struct
import sys
from pathlib import Path

import numpy as np
import pytest

from renderer.cmdline import png_bytes

from .test_cli import failure_problems as _failure_problems
from .test_cli import read_png, varying_chunks

_SPEC = importlib.util.spec_from_file_location("check_figures", Path(__file__).parents[1] / "book" / "check_figures.py")
cli = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(cli)


#: The tool's own page runner (some tests replace it on the module).
RENDER_FIGURES = cli._render_figures


def failure_problems(rc, err, before, after):
    return _failure_problems(rc, err, before, after, prog="check_figures")


def main(argv):
    return cli.main([a for a in argv if a != "figures"])


def run(argv, capsys):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture(scope="module")
def s1_figures(tmp_path_factory):
    """`check_figures.py --out` of the real §1 page (one figure), run once."""
    d = tmp_path_factory.mktemp("figs")
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(["figures", "--out", str(d / "a"), "--pages", "s1"])
    assert rc == 0, err.getvalue()
    return d / "a", out.getvalue()


def sha256_of(path):
    import hashlib
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def copy_dir(src, dst):
    import shutil
    shutil.copytree(src, dst)
    return dst


def test_figures_writes_pngs_and_manifest(s1_figures, tmp_path, capsys):
    a, stdout = s1_figures
    doc = json.loads((a / "manifest.json").read_text())
    assert [f["id"] for f in doc["figures"]] == ["s1_what_changes-fig-normals", "s1_what_changes-fig-s1-bump"]
    fig = doc["figures"][0]
    data = (a / fig["file"]).read_bytes()
    import hashlib
    assert hashlib.sha256(data).hexdigest() == fig["sha256"] and varying_chunks(data) == []
    assert read_png(a / fig["file"]).shape == (fig["height"], fig["width"], 3)
    assert len(doc["code_version"]["source_sha256"]) == 64 and "timestamp" not in json.dumps(doc)
    assert "wrote 2 figures" in stdout
    # That a second run gives byte-identical PNGs: test_figures_check_reports_changes ("unchanged").


def replay(monkeypatch, fresh):
    """Replace page execution by the real run in ``fresh`` (a previous ``--out`` directory):
    the figures a rerun of its pages gives, without running them again."""
    import shutil
    manifest = json.loads((fresh / "manifest.json").read_text())

    def render_figures(out_dir, pages):
        for f in manifest["figures"]:
            shutil.copy(fresh / f["file"], out_dir / f["file"])
        return manifest
    monkeypatch.setattr(cli, "_render_figures", render_figures)


def test_figures_check_reports_changes(s1_figures, tmp_path, capsys, monkeypatch):
    a, _ = s1_figures
    rc, out, err = run(["figures", "--check", str(a)], capsys)          # the page runs again, for real
    # "unchanged": the rerun's PNGs are byte for byte the first run's.
    assert rc == 0 and "unchanged  s1_what_changes-fig-s1-bump" in out and "no figure changed" in out
    assert "unchanged  s1_what_changes-fig-normals" in out
    replay(monkeypatch, a)                                               # the wrong variants: replayed
    # Wrong variant: one pixel changed by 51/255 in the previous run's file.
    old = copy_dir(a, tmp_path / "old")
    doc = json.loads((old / "manifest.json").read_text())
    f = old / doc["figures"][0]["file"]
    px = read_png(f)
    px[10, 10] = np.where(px[10, 10] >= 128, px[10, 10].astype(int) - 51, px[10, 10].astype(int) + 51)
    f.write_bytes(png_bytes(px.astype(np.uint8)))
    doc["figures"][0]["sha256"] = sha256_of(f)
    (old / "manifest.json").write_text(json.dumps(doc))
    rc, out, _ = run(["figures", "--check", str(old)], capsys)
    assert rc == 1 and "changed    s1_what_changes-fig-normals: max |dI| = 0.2000 (1 pixels differ)" in out
    rc, out, _ = run(["figures", "--check", str(old), "--ignore", "s1_*"], capsys)
    assert rc == 0 and "(ignored)" in out
    # A figure the previous manifest does not have is reported as added.
    doc["figures"] = doc["figures"][:1]
    (old / "manifest.json").write_text(json.dumps(doc))
    rc, out, _ = run(["figures", "--check", str(old)], capsys)
    assert rc == 1 and "added      s1_what_changes-fig-s1-bump" in out


def fake_book(root, cell):
    (root / "book").mkdir(parents=True)
    (root / "book" / "_toc.yml").write_text("format: jb-book\nroot: index\nchapters:\n  - file: s1_bad\n")
    head = "---\nkernelspec:\n  display_name: Python 3\n  language: python\n  name: python3\n---\n\n# T\n\n"
    (root / "book" / "index.md").write_text(head)
    (root / "book" / "s1_bad.md").write_text(head + "```{code-cell} ipython3\n" + cell + "\n```\n")


def test_figures_failing_page_is_one_line(tmp_path, capsys, monkeypatch):
    fake_book(tmp_path / "repo", "x = 1 / 0")
    monkeypatch.setattr(cli, "_repo_root", lambda: tmp_path / "repo")
    out_dir = tmp_path / "out"
    rc, stdout, err = run(["figures", "--out", str(out_dir)], capsys)
    assert failure_problems(rc, err, [], []) == []
    assert "page s1_bad failed: ZeroDivisionError" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["repo"]  # no out dir, no staging dir


@pytest.mark.parametrize("argv, word", [
    (["figures"], "--out"),
    (["figures", "--out", "DIR/a", "--check", "DIR/a"], "--check"),
    (["figures", "--check", "DIR/none"], "--check"),
    (["figures", "--check", "DIR"], "--check"),
    (["figures", "--out", "DIR/a", "--pages", "s99"], "--pages"),
    (["figures", "--out", "DIR/no/such"], "--out"),
    (["figures", "--out", "DIR/file.txt"], "--out"),
    (["figures", "--out", ""], "--out"),
    (["figures", "--out", "-"], "--out"),
    (["figures", "--check", ""], "--check"),
    (["figures", "--out", "DIR/a", "--pages", ""], "--pages"),
    (["figures", "--out", "DIR/a", "--pages", ","], "--pages"),
])
def test_figures_bad_input(tmp_path, capsys, argv, word):
    (tmp_path / "file.txt").write_text("x")
    (tmp_path / "manifest.json").write_text("{not json")
    argv = [a.replace("DIR", str(tmp_path)) for a in argv]
    before = sorted(p.name for p in tmp_path.iterdir())
    rc, stdout, err = run(argv, capsys)
    assert failure_problems(rc, err, before, sorted(p.name for p in tmp_path.iterdir())) == []
    assert word in err


def test_figures_marks_measured_timing_plots_and_check_does_not_fail_on_them(s1_figures, tmp_path,
                                                                               capsys, monkeypatch):
    a, _ = s1_figures
    replay(monkeypatch, a)
    old = copy_dir(a, tmp_path / "old")
    doc = json.loads((old / "manifest.json").read_text())
    f = old / doc["figures"][0]["file"]
    px = read_png(f)
    px[5, 5] = 255 - px[5, 5]
    f.write_bytes(png_bytes(px.astype(np.uint8)))
    doc["figures"][0]["sha256"] = sha256_of(f)
    doc["figures"][0]["varies"] = "measured timing"
    (old / "manifest.json").write_text(json.dumps(doc))
    rc, out, _ = run(["figures", "--check", str(old)], capsys)
    assert rc == 0 and "measured timing: varies by run" in out and "no figure changed" in out
    # Without the mark the same difference fails the check (the mark is what lets it pass).
    del doc["figures"][0]["varies"]
    (old / "manifest.json").write_text(json.dumps(doc))
    rc, out, _ = run(["figures", "--check", str(old)], capsys)
    assert rc == 1
    # A cell tagged measured-timing is marked in the manifest; an untagged one is not.
    png = (a / json.loads((a / "manifest.json").read_text())["figures"][0]["file"]).read_bytes()
    monkeypatch.setattr(cli, "_page_figures", lambda book, page: iter([
        ("p-cell01-1", 1, "plot()", png, (cli.VARIES_TAG,)), ("p-cell02-1", 2, "plot()", png, ())]))
    (tmp_path / "new").mkdir()
    manifest = RENDER_FIGURES(tmp_path / "new", ["p"])
    marks = {f["id"]: f.get("varies") for f in manifest["figures"]}
    assert marks == {"p-cell01-1": "measured timing", "p-cell02-1": None}


# ------------------------------------------------------------------ --check: manifest validation


def figure_pixels(h=40, w=50):
    """A deterministic RGB test image with no flat regions."""
    y, x = np.mgrid[0:h, 0:w]
    return np.stack([(7 * x + 3 * y) % 256, (5 * x * y) % 256, (x ^ y) * 4 % 256], axis=2).astype(np.uint8)


def write_check_dir(d, px=None, **entry):
    """A previous ``--out`` directory with one synthetic figure; returns the manifest."""
    import hashlib
    d.mkdir(exist_ok=True)
    data = png_bytes(figure_pixels() if px is None else px)
    (d / "fig.png").write_bytes(data)
    h, w = (px if px is not None else figure_pixels()).shape[:2]
    page = cli._known_pages()[1]
    doc = {"code_version": {"git_commit": None, "git_dirty": None, "source_sha256": "0" * 64},
           "pages": [page],
           "figures": [{"id": f"{page}-cell01-1", "page": page, "code_cell": 1, "file": "fig.png",
                        "sha256": hashlib.sha256(data).hexdigest(), "width": w, "height": h, **entry}]}
    (d / "manifest.json").write_text(json.dumps(doc))
    return doc


def fake_run(monkeypatch, new_pngs):
    """Replace page execution by writing ``new_pngs`` (id -> PNG bytes) as the fresh run."""
    def render_figures(out_dir, pages):
        import hashlib
        figs = []
        for fid, data in new_pngs.items():
            (out_dir / f"{fid}.png").write_bytes(data)
            figs.append({"id": fid, "file": f"{fid}.png", "sha256": hashlib.sha256(data).hexdigest()})
        return {"code_version": {"git_commit": None, "git_dirty": False, "source_sha256": "1" * 64},
                "pages": pages, "figures": figs}
    monkeypatch.setattr(cli, "_render_figures", render_figures)


def no_run(out_dir, pages):
    raise AssertionError("pages were executed")


#: Tamperings that name a figure file outside the directory or not a plain name.
BAD_FILE_NAMES = {"dev-zero": "/dev/zero", "dotdot": "../../x", "dotdot-png": "../x.png",
                  "subdir": "sub/fig.png", "nul": "fig\0.png", "double-dot-name": "..png"}


def tamper(name):
    """Mutations of a valid check directory ``d`` with manifest ``doc``."""
    def apply(d, doc):
        f = doc["figures"][0]
        if name in BAD_FILE_NAMES:
            f["file"] = BAD_FILE_NAMES[name]
        elif name == "bad-json":
            return "{not json"
        elif name == "deep-json":
            return "[" * 100_000 + "]" * 100_000
        elif name == "not-utf8":
            return b'{"pages": ["\xff"]}'
        elif name == "list":
            return "[]"
        elif name == "no-pages":
            del doc["pages"]
        elif name == "empty-pages":
            doc["pages"] = []
        elif name == "unknown-page":
            doc["pages"] = ["s99_nope"]
        elif name == "page-int":
            doc["pages"] = [1]
        elif name == "figures-dict":
            doc["figures"] = {"a": f}
        elif name == "figure-str":
            doc["figures"] = ["fig.png"]
        elif name == "id-int":
            f["id"] = 3
        elif name == "no-file":
            del f["file"]
        elif name == "sha-short":
            f["sha256"] = f["sha256"][:63]
        elif name == "sha-upper":
            f["sha256"] = f["sha256"].upper()
        elif name == "width-str":
            f["width"] = str(f["width"])
        elif name == "width-bool":
            f["width"] = True
        elif name == "width-zero":
            f["width"] = 0
        elif name == "height-huge":
            f["height"] = 8193
        elif name == "height-float":
            f["height"] = float(f["height"])
        elif name == "varies-int":
            f["varies"] = 1
        elif name == "code-version-list":
            doc["code_version"] = []
        elif name == "duplicate-id":
            doc["figures"].append(dict(f, file="fig2.png"))
        elif name == "duplicate-file":
            doc["figures"].append(dict(f, id="other"))
        elif name == "sha-mismatch":
            f["sha256"] = "0" * 64
        elif name == "file-changed":
            (d / "fig.png").write_bytes(png_bytes(255 - figure_pixels()))
        elif name == "missing-file":
            (d / "fig.png").unlink()
        elif name == "link-to-dev-zero":
            (d / "fig.png").unlink()
            (d / "fig.png").symlink_to("/dev/zero")
        elif name == "fifo-figure":
            (d / "fig.png").unlink()
            os.mkfifo(d / "fig.png")
        elif name in ("corrupt-png", "bomb-header"):
            import hashlib
            data = bytearray((d / "fig.png").read_bytes())
            if name == "corrupt-png":
                data[41:-12] = bytes(len(data) - 53)  # IDAT contents zeroed, header kept
            else:
                data[16:24] = struct.pack(">II", 100_000, 100_000)
            (d / "fig.png").write_bytes(bytes(data))
            f["sha256"] = hashlib.sha256(bytes(data)).hexdigest()
        elif name == "manifest-link":
            (d / "manifest.json").unlink()
            (d / "manifest.json").symlink_to("/dev/zero")
            return None
        elif name == "manifest-sparse":
            with open(d / "manifest.json", "wb") as fh:
                fh.truncate(2 << 30)
            return None
        elif name == "manifest-fifo":
            (d / "manifest.json").unlink()
            os.mkfifo(d / "manifest.json")
            return None
        elif name == "manifest-dir":
            (d / "manifest.json").unlink()
            (d / "manifest.json").mkdir()
            return None
        else:
            raise KeyError(name)
        return json.dumps(doc)
    return apply


TAMPERED = ["dev-zero", "dotdot", "dotdot-png", "subdir", "nul", "double-dot-name", "bad-json", "deep-json",
            "not-utf8", "list", "no-pages", "empty-pages", "unknown-page", "page-int", "figures-dict",
            "figure-str", "id-int", "no-file", "sha-short", "sha-upper", "width-str", "width-bool",
            "width-zero", "height-huge", "height-float", "varies-int", "code-version-list", "duplicate-id",
            "duplicate-file", "sha-mismatch", "file-changed", "missing-file", "link-to-dev-zero",
            "fifo-figure", "corrupt-png", "bomb-header", "manifest-link", "manifest-sparse",
            "manifest-fifo", "manifest-dir"]


def test_check_accepts_the_untampered_directory(tmp_path, capsys, monkeypatch):
    """The control for the refusals below: the same directory, untouched, is
    validated and compared (so each refusal is the tampering's doing)."""
    d = tmp_path / "old"
    doc = write_check_dir(d)
    fake_run(monkeypatch, {doc["figures"][0]["id"]: (d / "fig.png").read_bytes()})
    rc, out, err = run(["figures", "--check", str(d)], capsys)
    assert rc == 0 and err == "" and f"unchanged  {doc['figures'][0]['id']}" in out


@pytest.mark.parametrize("name", TAMPERED)
def test_check_refuses_a_tampered_directory_before_running_pages(tmp_path, capsys, monkeypatch, name):
    d = tmp_path / "old"
    doc = write_check_dir(d)
    text = tamper(name)(d, doc)
    if text is not None:
        (d / "manifest.json").write_bytes(text if isinstance(text, bytes) else text.encode())
    monkeypatch.setattr(cli, "_render_figures", no_run)
    decoded = []
    if name == "bomb-header":  # refused on the header, before any decoding
        monkeypatch.setattr(cli, "_png_pixels", lambda data: decoded.append(1) or no_run(None, None))
    reads = []
    if name == "manifest-sparse":
        real_read = os.read
        monkeypatch.setattr(cli.files.os, "read", lambda fd, n: reads.append(n) or real_read(fd, n))
    rc, out, err = run(["figures", "--check", str(d)], capsys)
    assert failure_problems(rc, err, [], []) == [], err
    assert err.startswith("check_figures: error: --check") and out == ""
    assert decoded == [] and reads == []             # no page ran (no_run), nothing decoded or read


def test_check_names_what_is_wrong(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(cli, "_render_figures", no_run)
    expect = {"dev-zero": "plain file name", "dotdot": "plain file name", "duplicate-id": "appears twice",
              "sha-mismatch": "does not match its sha256", "link-to-dev-zero": "symbolic link",
              "corrupt-png": "not a readable PNG", "bomb-header": "is not a 50x40 PNG",
              "manifest-sparse": "larger than 1,048,576 bytes", "manifest-link": "symbolic link",
              "manifest-fifo": "FIFO", "bad-json": "not JSON", "width-bool": "width must be an integer"}
    for i, (name, words) in enumerate(expect.items()):
        d = tmp_path / f"old{i}"
        text = tamper(name)(d, write_check_dir(d))
        if text is not None:
            (d / "manifest.json").write_text(text)
        rc, _, err = run(["figures", "--check", str(d)], capsys)
        assert rc == 2 and words in err, (name, err)


# ------------------------------------------------------------------ --check: tolerance


def test_compare_figure_tolerance_on_synthetic_pngs():
    base = figure_pixels()
    n = base.shape[0] * base.shape[1]
    allowed = int(cli.CHECK_TOLERANCE_FRACTION * n)
    levels = cli.CHECK_TOLERANCE_LEVELS
    assert allowed >= 1
    png = png_bytes(base)

    def changed(count, by):
        px = base.astype(int)
        flat = px.reshape(-1, 3)
        idx = np.arange(count) * (n // max(count, 1))
        flat[idx, 1] = np.where(flat[idx, 1] >= 128, flat[idx, 1] - by, flat[idx, 1] + by)
        return png_bytes(px.astype(np.uint8))

    assert cli.compare_figure(png, png) == ("unchanged", "")
    verdict, how = cli.compare_figure(png, changed(allowed, levels))
    assert verdict == "within tolerance" and f"({allowed:,} pixels differ)" in how
    assert cli.compare_figure(png, changed(1, 1))[0] == "within tolerance"
    # Wrong variants: one level more, one pixel more, another size.
    verdict, how = cli.compare_figure(png, changed(1, levels + 1))
    assert verdict == "changed" and how == f"max |dI| = {(levels + 1) / 255:.4f} (1 pixels differ)"
    assert cli.compare_figure(png, changed(allowed + 1, 1))[0] == "changed"
    assert cli.compare_figure(png, png_bytes(base[:-1]))[0] == "changed"
    assert cli.compare_figure(png, changed(1, 127))[0] == "changed"


def test_check_passes_within_tolerance_and_fails_beyond(tmp_path, capsys, monkeypatch):
    d = tmp_path / "old"
    doc = write_check_dir(d)
    fid = doc["figures"][0]["id"]
    px = figure_pixels().astype(int)
    near, far = px.copy(), px.copy()
    near[3, 4] += np.where(near[3, 4] < 255, 1, -1)
    far[3, 4] += np.where(far[3, 4] < 128, cli.CHECK_TOLERANCE_LEVELS + 1, -cli.CHECK_TOLERANCE_LEVELS - 1)
    fake_run(monkeypatch, {fid: png_bytes(near.astype(np.uint8))})
    rc, out, _ = run(["figures", "--check", str(d)], capsys)
    assert rc == 0 and f"within tolerance {fid}: max |dI| = 0.0039 (1 pixels differ)" in out
    assert "no figure changed" in out
    fake_run(monkeypatch, {fid: png_bytes(far.astype(np.uint8))})
    rc, out, _ = run(["figures", "--check", str(d)], capsys)
    assert rc == 1 and f"changed    {fid}: max |dI|" in out and "1 figure(s) changed" in out


def test_check_of_some_pages_compares_only_their_figures(s1_figures, tmp_path, capsys, monkeypatch):
    """``--check DIR --pages s1`` used to report every figure of the other pages "removed"."""
    import shutil
    a, _ = s1_figures
    old = copy_dir(a, tmp_path / "old")
    doc = json.loads((old / "manifest.json").read_text())
    shutil.copy(old / doc["figures"][0]["file"], old / "s2_scene-fig-x.png")
    doc["pages"].append("s2_scene")
    doc["figures"].append({**doc["figures"][0], "id": "s2_scene-fig-x", "page": "s2_scene",
                           "file": "s2_scene-fig-x.png"})
    (old / "manifest.json").write_text(json.dumps(doc))
    replay(monkeypatch, a)                                     # a rerun of s1 alone gives a's figures
    rc, out, err = run(["figures", "--check", str(old), "--pages", "s1"], capsys)
    assert rc == 0 and "removed" not in out and "no figure changed" in out, out + err
    monkeypatch.setattr(cli, "_resolve_pages", lambda pages: list(pages))   # all of the manifest's pages
    rc, out, _ = run(["figures", "--check", str(old)], capsys)
    assert rc == 1 and "removed    s2_scene-fig-x" in out              # a page that lost its figure still fails
    doc["figures"][-1]["page"] = "s9_roadmap"                               # not a page of the manifest
    (old / "manifest.json").write_text(json.dumps(doc))
    rc, _, err = run(["figures", "--check", str(old), "--pages", "s1"], capsys)
    assert rc == 2 and "figures[2].page must be one of the manifest's pages" in err


#: A page that announces that it runs (the harness's READY file), then runs on.
RUNNING_PAGE = "import os, time\nopen(os.environ['READY'], 'w').close()\ntime.sleep(120)"


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("what, moment", [("--out", "page"), ("--check", "page"), ("--out", "commit")])
def test_a_signal_at_any_moment_leaves_nothing_behind(tmp_path, what, moment, signum):
    """SIGTERM while a page ran was reported as an interrupt (nbclient's handler took it); now
    each signal gives its own line and code, while a page runs (its kernel shut down) and
    when the figures are about to be moved into place.  No DIR, no staging or temporary
    directory, no process (the kernel included) is left."""
    from .test_interrupts import Run, check
    fake_book(tmp_path / "repo", RUNNING_PAGE if moment == "page" else "print('no figure')")
    scratch, work = tmp_path / "tmp", tmp_path / "work"
    scratch.mkdir()
    work.mkdir()
    if what == "--check":
        write_check_dir(work / "old")
        doc = json.loads((work / "old" / "manifest.json").read_text())
        doc["pages"], doc["figures"][0]["page"] = ["s1_bad"], "s1_bad"
        (work / "old" / "manifest.json").write_text(json.dumps(doc))
    before = sorted(p.name for p in work.iterdir())
    run = Run("--tool", "check_figures", what, work / ("old" if what == "--check" else "figs"), "--pages", "s1",
              cwd=work, moment=moment, env={"BOOK_ROOT": str(tmp_path / "repo"), "TMPDIR": str(scratch)})
    run.at_the_moment()
    run.send(signum)
    check(run, work, before, grace=30, signum=signum, prog="check_figures")
    assert list(scratch.iterdir()) == []


def test_abbreviations_are_not_options(tmp_path, capsys, monkeypatch):
    """``--chec DIR`` ran the check, ``--pag`` took pages: the tool had a parser of its own."""
    monkeypatch.setattr(cli, "_render_figures", no_run)
    for argv, words in ((["--chec", str(tmp_path)], "one of the arguments --out --check is required"),
                        (["--out", str(tmp_path / "a"), "--pag", "s1"], "unrecognized arguments: --pag s1"),
                        (["--o", str(tmp_path / "a")], "one of the arguments --out --check is required")):
        rc, out, err = run(argv, capsys)
        assert failure_problems(rc, err, [], []) == [] and words in err and out == "", err
    assert list(tmp_path.iterdir()) == []


def test_a_report_that_cannot_be_written_leaves_no_directory(tmp_path, capsys, monkeypatch):
    """The figures are moved into DIR after the report is out: with standard output full,
    exit 2 and DIR as it was (absent), no staging directory."""
    class Full(io.StringIO):
        def write(self, text):
            raise OSError(28, "No space left on device")

    def render_figures(out_dir, pages):
        (out_dir / "manifest.json").write_text("{}")
        return {"figures": [], "code_version": {"git_commit": None, "git_dirty": None, "source_sha256": "0" * 64}}

    monkeypatch.setattr(cli, "_render_figures", render_figures)
    monkeypatch.setattr(sys, "stdout", Full())
    rc = main(["--out", str(tmp_path / "figs"), "--pages", "s1"])
    err = capsys.readouterr().err
    assert (rc, err) == (2, "check_figures: error: standard output: No space left on device\n")
    assert list(tmp_path.iterdir()) == []
    monkeypatch.setattr(sys, "stdout", io.StringIO())          # the control: the same run, reported
    assert main(["--out", str(tmp_path / "figs"), "--pages", "s1"]) == 0
    assert [p.name for p in tmp_path.iterdir()] == ["figs"] and "wrote 0 figures" in sys.stdout.getvalue()


def test_a_bad_environment_is_an_error_before_any_page(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(cli, "_render_figures", no_run)
    monkeypatch.setenv("NUMBA_NUM_THREADS", "0")
    rc, _, err = run(["--out", str(tmp_path / "figs")], capsys)
    assert rc == 2 and err.startswith("check_figures: error: the environment variable NUMBA_NUM_THREADS must be")


def test_the_tools_signal_handlers_are_back_after_a_page(tmp_path, monkeypatch):
    """nbclient leaves SIGTERM at its default after a page: a SIGTERM between pages (or while the
    figures are compared) killed the tool with its temporary directory left behind."""
    import signal
    fake_book(tmp_path, "print('one cell')")
    monkeypatch.setattr(cli, "_repo_root", lambda: tmp_path)
    mine = lambda signum, frame: None  # noqa: E731
    previous = signal.signal(signal.SIGTERM, mine)
    try:
        list(cli._page_figures(tmp_path / "book", "s1_bad"))
        assert signal.getsignal(signal.SIGTERM) is mine
    finally:
        signal.signal(signal.SIGTERM, previous)
