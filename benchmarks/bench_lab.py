"""Time the computations of §5's lab cells: every code cell of book/s5_lab.md,
run in order in one IPython shell (figures drawn with the Agg backend, not
encoded), several times in fresh subprocesses; median and min-max per cell and
in total, against a target of 3 s for the eight lab cells together.

Usage: python benchmarks/bench_lab.py [--runs N] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "book" / "s5_lab.md"

_CHILD = r'''
import json, re, sys, time
import matplotlib
matplotlib.use("Agg")
from IPython.core.interactiveshell import InteractiveShell
text = open(sys.argv[1], encoding="utf-8").read()
cells = re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", text, re.S)
shell = InteractiveShell.instance()
out = []
for cell in cells:
    body = "\n".join(l for l in cell.splitlines() if not l.startswith(":"))
    t0 = time.perf_counter()
    result = shell.run_cell(body, silent=True)
    out.append(time.perf_counter() - t0)
    if not result.success:
        raise SystemExit(f"cell {len(out) - 1} failed")
print(json.dumps(out))
'''


def _label(cell_text):
    lines = [l for l in cell_text.splitlines() if l.strip() and not l.startswith((":", "#"))]
    return (lines[0][:60] if lines else "").replace("|", "\\|")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args(argv)
    if args.runs < 1:
        ap.error(f"--runs must be >= 1, got {args.runs}")
    cells = re.findall(r"```\{code-cell\}[^\n]*\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.S)
    runs = []
    for _ in range(args.runs):
        proc = subprocess.run([sys.executable, "-c", _CHILD, str(PAGE)], capture_output=True, text=True,
                              cwd=ROOT, check=True)
        runs.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    per_cell = list(zip(*runs))
    totals = [sum(r) for r in runs]
    lines = ["# §5 lab cells: computation time", "",
             f"{args.runs} runs, each a fresh process running every code cell of book/s5_lab.md in order "
             "(imports included; figures drawn with Agg, not encoded to PNG).", "",
             "| cell | first line | median s | min-max s |", "|---|---|---|---|"]
    for i, (text, times) in enumerate(zip(cells, per_cell)):
        lines.append(f"| {i} | `{_label(text)}` | {statistics.median(times):.3f} | "
                     f"{min(times):.3f}-{max(times):.3f} |")
    lines += ["", f"**Total: median {statistics.median(totals):.2f} s (min-max {min(totals):.2f}-"
              f"{max(totals):.2f} s); target 3 s.**"]
    text = "\n".join(lines) + "\n"
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "lab.md").write_text(text, encoding="utf-8")
    (args.out / "lab.json").write_text(json.dumps({"runs": runs, "totals": totals}, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
