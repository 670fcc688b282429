"""Book build: cold, warm, and after a change to one module, in a scratch copy.

The book executes its pages through jupyter-cache (``execute_notebooks: cache``)
and book/_ext/nb_deps.py puts a digest of the project files each page imports
into the page's cache key.  This script shows, by building, that

* a cold ``make book`` executes every notebook page, and a warm one with
  nothing changed executes none;
* a comment appended to one module re-executes exactly the pages that import
  it, directly or transitively (the expected set comes from nb_deps' finder;
  which pages executed comes from jupyter-cache's records: every execution
  adds one);
* an edit that changes what a page shows (the "PROVED" badge of
  proofs/book.py) reaches every page that shows it, and reverting the edit
  executes nothing (the earlier outputs are matched under the earlier key);
* an edit to the simulator's JavaScript executes nothing but re-writes §4 and
  puts the new script into the site;
* control (skip with --no-control): without nb_deps the same badge edit, with
  the two pages' sources touched so Sphinx even re-reads them, is served from
  the cache, stale.

Everything happens in a scratch copy (``git clone`` of this repository at HEAD
or --rev, or with --worktree its working tree) with PYTHONPATH set to the copy, so the
copy's renderer/ and proofs/ are the ones imported (checked); this checkout is
never touched.  Each build is the Makefile's ``book`` target
(``make -o .venv/.installed BIN=<this venv>/bin book``: the venv is used as
installed, not re-installed).  Results go to benchmarks/results/book_build.md.

With ``--cold-vs REV`` the script instead times cold builds only, side by side
in one run: REV, the copy with its pages executed one at a time
(``SYMRENDER_BOOK_JOBS=1``), and the copy as configured, in rotation,
``--repeats`` times each; before each build the copy's book/_build and numba's
cache (renderer/__pycache__) are removed.  Results go to
benchmarks/results/book_cold.md.

Usage: python benchmarks/bench_book.py [--rev REV | --worktree] [--no-control] [--keep] [--out FILE]
       python benchmarks/bench_book.py --cold-vs REV [--repeats N] [--worktree | --rev REV2]
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent

BADGE, EDITED_BADGE = '"proved": "PROVED"', '"proved": "PROVED (bench edit)"'
SHOWN = re.compile(r">PROVED( \(bench edit\))?<")


def _load_nb_deps(repo):
    spec = importlib.util.spec_from_file_location("nb_deps_scratch", repo / "book" / "_ext" / "nb_deps.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class Book:
    """A scratch copy of the repository and its builds."""

    def __init__(self, repo: Path):
        self.repo = repo
        self.env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(repo)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
        self.html = repo / "book" / "_build" / "html"
        self.pages = sorted(p.stem for p in (repo / "book").glob("*.md"))
        self.nb_deps = _load_nb_deps(repo)
        self.packages = {"renderer": repo / "renderer", "proofs": repo / "proofs"}

    def check_imports(self):
        """The copy's packages are the ones Python (and so the kernel) imports."""
        out = subprocess.run([str(BIN / "python"), "-c",
                              "import renderer, proofs; print(renderer.__file__); print(proofs.__file__)"],
                             env=self.env, cwd=self.repo / "book", check=True, capture_output=True, text=True)
        for line in out.stdout.split():
            if not Path(line).resolve().is_relative_to(self.repo.resolve()):
                raise SystemExit(f"bench_book: {line} is imported, not the scratch copy's module")
        return out.stdout.split()

    def cache_records(self):
        from jupyter_cache import get_cache
        path = self.repo / "book" / "_build" / ".jupyter_cache"
        if not path.exists():
            return {}
        return {r.pk: Path(r.uri).stem for r in get_cache(str(path)).list_cache_records()}

    def build(self, **env):
        """Run `make book` (``env``: extra environment variables); return (seconds, pages executed,
        pages written)."""
        before = self.cache_records()
        start_wall = time.time()
        t0 = time.perf_counter()
        result = subprocess.run(["make", "-s", "-o", ".venv/.installed", f"BIN={BIN}", "book"],
                                cwd=self.repo, env={**self.env, **env}, capture_output=True, text=True)
        seconds = time.perf_counter() - t0
        if result.returncode:
            sys.stderr.write(result.stdout[-4000:] + result.stderr[-4000:])
            raise SystemExit(f"bench_book: make book failed ({result.returncode})")
        after = self.cache_records()
        executed = sorted(after[pk] for pk in after.keys() - before.keys())
        written = sorted(p for p in self.pages
                         if (self.html / f"{p}.html").stat().st_mtime >= start_wall)
        return seconds, executed, written

    def make_cold(self):
        """Remove the build (with its jupyter-cache and store) and numba's cache of the kernel."""
        shutil.rmtree(self.repo / "book" / "_build", ignore_errors=True)
        shutil.rmtree(self.repo / "renderer" / "__pycache__", ignore_errors=True)

    def importers(self, relpath):
        """Pages whose code runs or reads ``relpath`` (nb_deps' finder on the copy)."""
        target = (self.repo / relpath).resolve()
        found = []
        for name in self.pages:
            path = self.repo / "book" / f"{name}.md"
            files = self.nb_deps.dependencies(path.read_text(encoding="utf-8"), self.packages, path=path)
            if files and target in files:
                found.append(name)
        return found

    def notebooks(self, *, importing=False):
        """Pages with code cells (with ``importing``: only those that import the project)."""
        found = []
        for name in self.pages:
            path = self.repo / "book" / f"{name}.md"
            text = path.read_text(encoding="utf-8")
            files = self.nb_deps.dependencies(text, self.packages, path=path)
            if self.nb_deps.code_cells(text, path=path) and (files or not importing):
                found.append(name)
        return found

    def empty_notebooks(self):
        """Notebook pages without a code cell: all share one cache key (no code, same kernel)."""
        return [n for n in self.pages
                if self.nb_deps.code_cells((self.repo / "book" / f"{n}.md").read_text(encoding="utf-8")) == []]

    def badges(self):
        """{page: set of badge texts shown}."""
        shown = {}
        for name in self.pages:
            found = {m.group(0) for m in SHOWN.finditer((self.html / f"{name}.html").read_text(encoding="utf-8"))}
            if found:
                shown[name] = found
        return shown


def _edit(path, old, new):
    text = path.read_text(encoding="utf-8")
    if old not in text:
        raise SystemExit(f"bench_book: {path} no longer contains {old!r}; update the benchmark")
    path.write_text(text.replace(old, new, 1), encoding="utf-8")


def _scratch_copy(dest, worktree, rev):
    if not worktree:
        subprocess.run(["git", "clone", "--quiet", str(ROOT), str(dest)], check=True)
        subprocess.run(["git", "checkout", "--quiet", rev], cwd=dest, check=True)
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=dest, check=True,
                              capture_output=True, text=True).stdout.strip()
    files = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT, check=True,
                           capture_output=True, text=True).stdout.split("\0")
    for name in filter(None, files):
        if (ROOT / name).is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, dest / name)
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, check=True,
                          capture_output=True, text=True).stdout.strip()
    return f"working tree on {head}"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rev", default="HEAD", help="the commit to clone (default HEAD)")
    parser.add_argument("--worktree", action="store_true", help="copy the working tree instead of a commit")
    parser.add_argument("--no-control", action="store_true", help="skip the build without nb_deps")
    parser.add_argument("--keep", action="store_true", help="keep the scratch copy")
    parser.add_argument("--out", type=Path, default=None,
                        help="results file (default results/book_build.md, or book_cold.md with --cold-vs)")
    parser.add_argument("--cold-vs", metavar="REV", help="time cold builds only, against commit REV")
    parser.add_argument("--repeats", type=int, default=3, help="cold builds of each kind with --cold-vs")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error(f"--repeats must be >= 1, got {args.repeats}")
    if args.cold_vs:
        return cold_side_by_side(args)
    args.out = args.out or ROOT / "benchmarks" / "results" / "book_build.md"

    scratch = Path(tempfile.mkdtemp(prefix="bench_book_"))
    repo = scratch / "repo"
    repo.mkdir()
    source = _scratch_copy(repo, args.worktree, args.rev)
    book = Book(repo)
    imported = book.check_imports()
    rows, failures = [], []

    def step(kind, expected, note="", *, ignore=()):
        seconds, executed, written = book.build()
        ok = [p for p in executed if p not in ignore] == sorted(expected)
        if not ok:
            failures.append(f"{kind}: executed {executed}, expected {sorted(expected)}")
        rows.append((kind, seconds, executed, written, sorted(expected), "yes" if ok else "NO", note))
        print(f"{kind:<52} {seconds:6.1f} s  executed: {', '.join(executed) or '-'}"
              f"  (expected: {', '.join(sorted(expected)) or '-'}){'' if ok else '  MISMATCH'}", flush=True)

    print(f"scratch copy {repo} ({source}); imports {imported[0]}", flush=True)
    empty = book.empty_notebooks()
    step("cold (empty cache)", book.notebooks(), ignore=empty,
         note=(f"{' and '.join(empty)} have no code cell and so one cache key: the first "
               "executes (a kernel starts, nothing runs), the rest match its record") if empty else "")
    step("warm, nothing changed", [])

    ucurve = repo / "proofs" / "ucurve.py"
    ucurve.write_text(ucurve.read_text(encoding="utf-8") + "# bench: a harmless comment\n", encoding="utf-8")
    step("comment appended to proofs/ucurve.py", book.importers("proofs/ucurve.py"))

    ledger = repo / "renderer" / "ledger.py"
    ledger.write_text(ledger.read_text(encoding="utf-8") + "# bench: a harmless comment\n", encoding="utf-8")
    step("comment appended to renderer/ledger.py", book.importers("renderer/ledger.py"))

    proofs_book = repo / "proofs" / "book.py"
    original = proofs_book.read_text(encoding="utf-8")
    shown_before = book.badges()
    _edit(proofs_book, BADGE, EDITED_BADGE)
    step("badge text edited in proofs/book.py", book.importers("proofs/book.py"))
    shown_after = book.badges()
    stale = sorted(p for p, b in shown_after.items() if ">PROVED<" in b)
    fresh = sorted(p for p, b in shown_after.items() if ">PROVED (bench edit)<" in b)
    badge_note = f"badge shown before on {sorted(shown_before)}; after: new on {fresh}, old on {stale or 'none'}"
    if stale or fresh != sorted(shown_before):
        failures.append("badge edit: " + badge_note)
    rows[-1] = rows[-1][:-1] + (badge_note,)

    proofs_book.write_text(original, encoding="utf-8")
    step("badge edit reverted", [])
    reverted = book.badges()
    if reverted != shown_before:
        failures.append(f"after the revert the badges are {reverted}, not {shown_before}")
    rows[-1] = rows[-1][:-1] + ("served from the earlier cache records; badges as before the edit"
                                if reverted == shown_before else "badges differ from before the edit",)

    sim = repo / "renderer" / "js" / "render.js"
    sim.write_text(sim.read_text(encoding="utf-8") + "// bench: a harmless comment\n", encoding="utf-8")
    step("comment appended to renderer/js/render.js", [])
    in_site = "// bench: a harmless comment" in (book.html / "_static" / "sim" / "simulator.js").read_text()
    if not in_site or "s4_simulator" not in rows[-1][3]:
        failures.append("the simulator's edit did not reach the site with §4 re-written")
    rows[-1] = rows[-1][:-1] + (f"§4 re-written from the cache; new script in the site: {in_site}",)

    if not args.no_control:
        config = repo / "book" / "_config.yml"
        _edit(config, "    nb_deps: _ext\n", "")
        step("control: nb_deps removed (config change)", book.notebooks(importing=True),
             "every page that imports the project loses its nb-deps cell, so its key changes")
        _edit(proofs_book, BADGE, EDITED_BADGE)
        for name in book.importers("proofs/book.py"):
            (repo / "book" / f"{name}.md").touch()
        seconds, executed, written = book.build()
        control = book.badges()
        stale = sorted(p for p, b in control.items() if ">PROVED<" in b)
        rows.append(("control: badge edited, its pages touched", seconds, executed, written, [],
                     "stale" if stale else "fresh",
                     f"without nb_deps the old badge is served on {stale or 'no page'}"))
        print(f"{rows[-1][0]:<52} {seconds:6.1f} s  executed: {', '.join(executed) or '-'}"
              f"  stale badge on: {', '.join(stale) or '-'}", flush=True)

    text = _report(rows, source, failures, imported)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text, encoding="utf-8")
    print(f"\n{text}\nwritten to {args.out}")
    if args.keep:
        print(f"scratch copy kept at {repo}")
    else:
        shutil.rmtree(scratch)
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures), file=sys.stderr)
        return 1
    return 0


def cold_side_by_side(args):
    """Cold builds of REV and of the copy (pages one at a time, and as configured), in rotation."""
    scratch = Path(tempfile.mkdtemp(prefix="bench_book_cold_"))
    (scratch / "base").mkdir()
    (scratch / "new").mkdir()
    base_source = _scratch_copy(scratch / "base", False, args.cold_vs)
    new_source = _scratch_copy(scratch / "new", args.worktree, args.rev)
    base, new = Book(scratch / "base"), Book(scratch / "new")
    base.check_imports()
    new.check_imports()
    kinds = [(f"{base_source} (baseline)", base, {}),
             (f"{new_source}, pages one at a time (SYMRENDER_BOOK_JOBS=1)", new, {"SYMRENDER_BOOK_JOBS": "1"}),
             (f"{new_source}, as configured ({os.cpu_count()} pages at a time)", new, {})]
    times = {kind: [] for kind, _, _ in kinds}
    for repeat in range(args.repeats):
        for kind, book, env in kinds:
            book.make_cold()
            seconds, executed, _ = book.build(**env)
            times[kind].append(seconds)
            print(f"{repeat + 1}/{args.repeats}  {kind:<70} {seconds:6.1f} s  ({len(executed)} pages executed)",
                  flush=True)
    first = statistics.median(times[kinds[0][0]])
    lines = ["# Book build: cold, side by side", "",
             f"`python benchmarks/bench_book.py --cold-vs {args.cold_vs} --repeats {args.repeats}` on "
             f"{datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, {os.cpu_count()} CPUs, "
             f"Python {platform.python_version()}.",
             "Each build is `make book` after removing book/_build (with its jupyter-cache and store of "
             "measurements) and numba's cache in renderer/__pycache__; the three kinds run in rotation, "
             "so that a change in the machine's speed reaches all three alike.", "",
             "| build | median s | min–max s | builds | vs baseline |", "|---|---:|---:|---:|---:|"]
    for kind, _, _ in kinds:
        t = times[kind]
        lines.append(f"| {kind} | {statistics.median(t):.1f} | {min(t):.1f}–{max(t):.1f} | {len(t)} | "
                     f"{statistics.median(t) / first:.2f} |")
    lines += ["", "Target: cold `make book` ≤ 45 s.", ""]
    out = args.out or ROOT / "benchmarks" / "results" / "book_cold.md"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines), encoding="utf-8")
    print("\n".join(lines) + f"\nwritten to {out}")
    shutil.rmtree(scratch)
    return 0


def _report(rows, source, failures, imported):
    head = [
        "# Book build: cold, warm, one module changed",
        "",
        f"`python benchmarks/bench_book.py` on {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, "
        f"{os.cpu_count()} CPUs, Python {platform.python_version()}, source: {source}.",
        "Each row is one `make book` (jupyter-book build + offline check) in a scratch copy "
        "whose own renderer/ and proofs/ are imported (checked), one after the other, in the order shown.",
        "\"executed\" is read from jupyter-cache's records (each execution adds one); "
        "\"expected\" is the set of pages whose imports reach the changed file, by "
        "book/_ext/nb_deps.py's finder; \"re-written\" is the pages whose HTML the build wrote.",
        "",
        "| build | seconds | pages executed | pages re-written | expected executed | as expected | note |",
        "|---|---:|---|---|---|---|---|",
    ]
    for kind, seconds, executed, written, expected, ok, note in rows:
        head.append(f"| {kind} | {seconds:.1f} | {', '.join(executed) or '—'} | {', '.join(written) or '—'} | "
                    f"{', '.join(expected) or '—'} | {ok} | {note} |")
    head += ["", "Targets: cold ≤ 120 s, warm with nothing changed ≤ 15 s.", ""]
    head.append("All checks passed." if not failures else "FAILED:\n\n" + "\n".join(f"- {f}" for f in failures))
    return "\n".join(head) + "\n"


if __name__ == "__main__":
    sys.exit(main())
