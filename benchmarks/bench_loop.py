"""The author's loop, timed side by side from fresh clones: a base revision against a head revision.

For each revision, and alternating base and head ``--repeats`` times, a new ``git clone`` of
this repository is checked out at the revision and the revision's own ``bash .ci/run`` runs in
it, as CI runs it: the venv installed from the package registries, the book built cold (no
bytecode, numba cache or jupyter cache yet), the tests, the audits where the revision has them.
Each step's seconds are read from the lines ``.ci/run`` prints; then, in the same clone,

* ``pytest verify``: the proof checker alone (numba's cache warm from the book);
* ``book no change``: ``make book`` again;
* ``book ledger.py edited``: a comment appended to renderer/ledger.py, ``make book``.

The table gives each row's median in seconds and head / base in per cent.  A revision's steps
are its own (a base without ``make audit`` runs its audits inside ``make test``), so compare the
totals, and steps only where both have them.  Commit what you measure: a clone sees commits only.
Run it on a machine doing nothing else; a repeat takes about 12 minutes on 2 cores.

Usage: python benchmarks/bench_loop.py --base REV [--head REV] [--repeats N]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: What .ci/run prints after each step.
STEP = re.compile(r"^\.ci/run: '(.+)' took (\d+) s$", re.M)


def timed(tree: Path, cmd: list[str]) -> tuple[float, str]:
    """Seconds ``cmd`` takes in ``tree`` (as CI's environment: CI=true, bytecode written), and its
    stderr; a failure stops the benchmark with the end of its output."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "VIRTUAL_ENV")}
    start = time.monotonic()
    run = subprocess.run(cmd, cwd=tree, env={**env, "CI": "true"}, capture_output=True, text=True)
    seconds = time.monotonic() - start
    if run.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed in {tree}:\n{(run.stdout + run.stderr)[-3000:]}")
    return seconds, run.stderr


def one_round(rev: str, tree: Path) -> dict[str, float]:
    """One fresh clone of ``rev`` at ``tree``, timed: each step of its .ci/run, the total, then the rest."""
    shutil.rmtree(tree, ignore_errors=True)
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(tree)], check=True)
    subprocess.run(["git", "checkout", "--quiet", "--detach", rev], cwd=tree, check=True)
    total, stderr = timed(tree, ["bash", ".ci/run"])
    out = {step.replace(" -o book", ""): float(s) for step, s in STEP.findall(stderr)}
    if not out:
        raise SystemExit(f"{rev}'s .ci/run printed no line like \".ci/run: 'make book' took 46 s\": no step to time")
    out[".ci/run in all"] = total
    out["pytest verify"] = timed(tree, [str(tree / ".venv" / "bin" / "python"), "-m", "pytest", "verify",
                                        "-q", "-p", "no:cacheprovider"])[0]
    out["book no change"] = timed(tree, ["make", "book"])[0]
    ledger = tree / "renderer" / "ledger.py"
    ledger.write_text(ledger.read_text(encoding="utf-8") + "# edited\n", encoding="utf-8")
    out["book ledger.py edited"] = timed(tree, ["make", "book"])[0]
    print(f"{rev}: " + ", ".join(f"{k} {v:.0f} s" for k, v in out.items()), file=sys.stderr, flush=True)
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--base", required=True, help="the revision to compare against")
    p.add_argument("--head", default="HEAD", help="the revision measured (default HEAD)")
    p.add_argument("--repeats", type=int, default=1)
    args = p.parse_args(argv)
    if args.repeats < 1:
        raise SystemExit(f"--repeats: {args.repeats} is not a positive number of rounds")
    revs = {}
    for name in ("base", "head"):
        rev = getattr(args, name)
        found = subprocess.run(["git", "rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"], cwd=ROOT,
                               capture_output=True, text=True)
        if found.returncode != 0:
            raise SystemExit(f"--{name}: {rev!r} is not a commit of {ROOT}")
        revs[name] = found.stdout.strip()[:12]
    times = {"base": [], "head": []}
    with tempfile.TemporaryDirectory(prefix="symrender-loop-") as tmp:
        for _ in range(args.repeats):
            for name in ("base", "head"):
                times[name].append(one_round(revs[name], Path(tmp, name)))
    rows = list(dict.fromkeys([*times["head"][0], *times["base"][0]]))      # head's steps in its order
    print(f"| what | base {revs['base']} (s) | head {revs['head']} (s) | head / base |\n|---|---:|---:|---:|")
    for key in rows:
        b = [t[key] for t in times["base"] if key in t]
        h = [t[key] for t in times["head"] if key in t]
        cell = lambda xs: f"{statistics.median(xs):.1f}" if xs else "—"      # noqa: E731
        ratio = f"{100 * statistics.median(h) / statistics.median(b):.0f} %" if b and h else "—"
        print(f"| {key} | {cell(b)} | {cell(h)} | {ratio} |")


if __name__ == "__main__":
    main()
