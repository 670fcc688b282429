"""`renderer.render` beside the speed peers, side by side in one process.

Per frame size (256², 1024²) and gradient (exact, central), the draft's scene
is rendered by every contender in interleaved rounds (one call of each per
round, after warm-up), so that the machine's load falls on all alike; the table
gives medians and each contender's ratio to the plain Dr.Jit program
(`benchmarks/peers.py`).  Contenders: `render` with each backend this machine
has ("numba" always, "drjit" with the system's LLVM), the plain Dr.Jit program,
and the plain JAX program (256² only: XLA CPU is an order of magnitude
slower).  Each peer's image is first checked against the project's (max |dI|).
The load average before and after is printed with the table.

Results: benchmarks/results/peers.md (table) and peers.json (raw samples).
A contender whose image differs from render's by more than `AGREEMENT` stops the run.
Usage: python benchmarks/bench_peers.py [--rounds N] [--out DIR]
"""

from __future__ import annotations

import argparse
import inspect
import json
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import peers  # noqa: E402
from renderer import DRAFT_SCENE, render  # noqa: E402
from renderer.backends import drjit_llvm  # noqa: E402

#: Largest |dI| from render (numba)'s image a contender may show: the same scene, rounded differently.
AGREEMENT = 1e-9
CASES = [(256, "exact"), (256, "central"), (1024, "exact"), (1024, "central")]


def contenders(side, gradient):
    """name -> function of no arguments returning an (H, W, 3) image, for this case."""
    scene = DRAFT_SCENE
    out = {"render (numba)": lambda: render(scene, side, side, gradient=gradient, kink=False, grad=False).image}
    if drjit_llvm() is not None:
        if "backend" in inspect.signature(render).parameters:
            out["render (drjit)"] = lambda: render(scene, side, side, gradient=gradient, kink=False, grad=False,
                                                   backend="drjit").image
        out["Dr.Jit peer"] = peers.renderer_for(peers.drjit_namespace(), scene, side, side, gradient)
    if side <= 256:
        out["JAX peer"] = peers.renderer_for(peers.jax_namespace(), scene, side, side, gradient)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args(argv)
    load0 = os.getloadavg()
    rows, raw = [], {}
    for side, gradient in CASES:
        fns = contenders(side, gradient)
        first = next(iter(fns.values()))()
        agree = {n: float(abs(f() - first).max()) for n, f in fns.items()}
        if max(agree.values()) > AGREEMENT:
            sys.exit(f"bench_peers: at {side}² {gradient} a contender's image differs from render's by "
                     f"{max(agree.values()):.1e} > {AGREEMENT:.0e}: {agree}; they would not be doing the same work")
        for _ in range(3):
            for f in fns.values():
                f()
        samples = {n: [] for n in fns}
        for _ in range(args.rounds):
            for n, f in fns.items():
                t0 = time.perf_counter()
                f()
                samples[n].append(time.perf_counter() - t0)
        med = {n: statistics.median(s) for n, s in samples.items()}
        peer = med.get("Dr.Jit peer")
        for n in fns:
            ratio = f"{med[n] / peer:.2f}" if peer else "—"
            rows.append(f"| {side}² {gradient} | {n} | {1e3 * med[n]:.1f} | {ratio} | {agree[n]:.1e} |")
        raw[f"{side} {gradient}"] = samples
    load1 = os.getloadavg()
    table = "\n".join([
        f"Medians of {args.rounds} interleaved rounds, scene DRAFT_SCENE; load average "
        f"{load0[0]:.2f} before, {load1[0]:.2f} after; {os.cpu_count()} CPUs.", "",
        "| frame | contender | median ms | ÷ Dr.Jit peer | max abs dI vs render (numba) |",
        "|---|---|---:|---:|---:|", *rows])
    print(table)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "peers.md").write_text(table + "\n")
    (args.out / "peers.json").write_text(json.dumps(raw))


if __name__ == "__main__":
    main()
