"""The author's loop, timed side by side: a base revision against this working tree.

For each tree (REV checked out with ``git worktree`` into a temporary directory, and a
copy of this working tree) the same commands run with this ``.venv`` and ``PYTHONPATH``
set to the tree, so that the tree's packages are the ones imported (checked before
timing).  The trees alternate, ``--repeats`` times; the table gives each command's
median in seconds and the ratio base / head.

* ``verify``: ``pytest verify`` (the proof checker; numba's cache warm);
* ``book cold``: ``make book`` with no book/_build;
* ``book no change``: ``make book`` again;
* ``book ledger.py edited``: a comment appended to renderer/ledger.py, ``make book``;
* ``test``: ``make test`` after ``make book`` (``--test``: slow, the base's takes minutes).

Usage: python benchmarks/bench_loop.py --base REV [--repeats N] [--test]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mutation_audit import scratch_copy      # benchmarks/: this working tree, copied

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def env_for(tree: Path) -> dict:
    return {**os.environ, "PYTHONPATH": f"{tree}{os.pathsep}{tree / 'book'}", "CI": "true"}


def timed(tree: Path, cmd: list[str], must_pass=True) -> float:
    """Seconds ``cmd`` takes in ``tree``; a failure stops the benchmark unless ``must_pass`` is
    false (then it is reported, with the end of its output, and the time still counts)."""
    start = time.monotonic()
    run = subprocess.run(cmd, cwd=tree, env=env_for(tree), capture_output=True, text=True)
    seconds = time.monotonic() - start
    if run.returncode != 0:
        if must_pass:
            raise SystemExit(f"{' '.join(cmd)} failed in {tree}:\n{(run.stdout + run.stderr)[-3000:]}")
        print(f"{' '.join(cmd)} failed in {tree} ({seconds:.0f} s): {run.stdout.strip().splitlines()[-1:]}",
              file=sys.stderr, flush=True)
    return seconds


def make(target):
    return ["make", "-o", ".venv/.installed", f"BIN={BIN}", target]


def rounds(tree: Path, with_test: bool) -> dict[str, float]:
    """One timing of each command in ``tree``."""
    out = {"verify": timed(tree, [str(BIN / "python"), "-m", "pytest", "verify", "-q", "-p", "no:cacheprovider"])}
    shutil.rmtree(tree / "book" / "_build", ignore_errors=True)
    out["book cold"] = timed(tree, make("book"))
    out["book no change"] = timed(tree, make("book"))
    ledger = tree / "renderer" / "ledger.py"
    text = ledger.read_text(encoding="utf-8")
    ledger.write_text(text + "# edited\n", encoding="utf-8")
    try:
        out["book ledger.py edited"] = timed(tree, make("book"))
    finally:
        ledger.write_text(text, encoding="utf-8")
    if with_test:     # a base whose tests need what this checkout no longer installs may fail some
        timed(tree, make("book"))           # the edit reverted: make test then finds the book current
        out["test"] = timed(tree, make("test"), must_pass=False)
    print(f"{tree.name}: " + ", ".join(f"{k} {v:.1f} s" for k, v in out.items()), file=sys.stderr, flush=True)
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--base", required=True, help="the revision to compare against")
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--test", action="store_true", help="time make test too")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="symrender-loop-") as tmp:
        base, head = Path(tmp, "base"), Path(tmp, "head")
        subprocess.run(["git", "worktree", "add", "--detach", str(base), args.base], cwd=ROOT, check=True,
                       capture_output=True)
        try:
            head.mkdir()
            scratch_copy(head)
            for tree in (base, head):
                where = subprocess.run([str(BIN / "python"), "-c", "import renderer; print(renderer.__file__)"],
                                       cwd=tree, env=env_for(tree), capture_output=True, text=True).stdout
                assert where.startswith(str(tree)), (tree, where)
                timed(tree, [str(BIN / "python"), "-c", "import renderer; renderer.render(renderer.Scene(), 8, 8)"])
            times = {"base": [], "head": []}
            for _ in range(args.repeats):
                for name, tree in (("base", base), ("head", head)):
                    times[name].append(rounds(tree, args.test))
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(base)], cwd=ROOT, capture_output=True)
    print(f"| what | base {args.base} (s) | head (s) | base / head |\n|---|---:|---:|---:|")
    for key in times["head"][0]:
        b = statistics.median(t[key] for t in times["base"])
        h = statistics.median(t[key] for t in times["head"])
        print(f"| {key} | {b:.1f} | {h:.1f} | {b / h:.1f}x |")


if __name__ == "__main__":
    main()
