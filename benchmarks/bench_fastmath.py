"""The price of fast math: each backend's ulps and speed side by side, and the U-curve's floor.

Prints (and writes as Markdown and JSON) three tables from `lab.fastmath`: the ulp error
of sin, cos, atan2, acos and pow per backend (largest and 99.9 % quantile over the seeded
sample, largest over the hard points) beside the median time per call on 2^20 points of
the same ranges; and the U-curve's floor per backend beside the error model's optimum.
A backend this machine lacks (Dr.Jit without the system's libLLVM) is listed as missing.
Times: medians of interleaved runs (backends and functions in turn, so load hits all
alike), with the machine's load average printed beside them.

Usage: python benchmarks/bench_fastmath.py [--runs N] [--count N] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT)]

from lab import fastmath as fm  # noqa: E402

POINTS = 2**20


def timers(name, args):
    """{function: a callable running it once on ``args[function]``, synchronised} for backend ``name``."""
    if name in ("numba", "numpy"):                  # ufuncs both
        ufuncs, out = (fm._numba if name == "numba" else fm._numpy)(), np.empty(POINTS)
        return {f: (lambda f=f: ufuncs[f](*args[f], out=out)) for f in fm.FUNCTIONS}
    if name == "drjit":
        import drjit as dr
        from renderer.backends import drjit_llvm
        llvm = drjit_llvm()
        ops = {"sin": dr.sin, "cos": dr.cos, "atan2": dr.atan2, "acos": dr.acos, "pow": dr.power}
        native = {f: [llvm.Float64(a) for a in args[f]] for f in fm.FUNCTIONS}
        dr.eval(*[a for f in native for a in native[f]])

        def run(f):
            dr.eval(ops[f](*native[f]))
            dr.sync_thread()
        return {f: (lambda f=f: run(f)) for f in fm.FUNCTIONS}
    import jax
    import jax.numpy as jnp
    ops = {"sin": jnp.sin, "cos": jnp.cos, "atan2": jnp.arctan2, "acos": jnp.arccos, "pow": jnp.power}
    with jax.enable_x64(True):
        native = {f: [jnp.asarray(a) for a in args[f]] for f in fm.FUNCTIONS}
        jitted = {f: jax.jit(ops[f]) for f in fm.FUNCTIONS}

    def run(f):
        with jax.enable_x64(True):
            jitted[f](*native[f]).block_until_ready()
    return {f: (lambda f=f: run(f)) for f in fm.FUNCTIONS}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=15, help="timed runs per backend and function (default 15)")
    ap.add_argument("--count", type=int, default=fm.SAMPLES, help=f"ulp sample per function (default {fm.SAMPLES})")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results",
                    help="directory for fastmath.md and fastmath.json (default benchmarks/results)")
    a = ap.parse_args(argv)
    if a.runs < 1 or a.count < 1:
        ap.error(f"--runs and --count must be >= 1, got {a.runs} and {a.count}")

    ulp, floors = fm.ulp_table(a.count), fm.floors()
    args = {f: [x[:POINTS] for x in fm.arguments(f, POINTS)[0]] for f in fm.FUNCTIONS}
    run = {name: timers(name, args) for name in ulp["backends"]}
    for name in run:                                   # compile (numba, XLA, Dr.Jit) before timing
        for f in fm.FUNCTIONS:
            run[name][f]()
    times = {name: {f: [] for f in fm.FUNCTIONS} for name in run}
    load = [os.getloadavg()[0]]
    for _ in range(a.runs):
        for name in run:
            for f in fm.FUNCTIONS:
                t0 = time.perf_counter()
                run[name][f]()
                times[name][f].append(time.perf_counter() - t0)
    load.append(os.getloadavg()[0])
    median = {name: {f: statistics.median(t) for f, t in d.items()} for name, d in times.items()}

    q = f"{100 * fm.QUANTILE:g} %"
    lines = [f"# The price of fast math ({POINTS:,} points per call, median of {a.runs} interleaved runs; "
             f"load average {load[0]:.2f} -> {load[1]:.2f} on {os.cpu_count()} cores)", "",
             f"| function | backend | max ulp | {q} ulp | hard points, max ulp | ms per call | ns per value |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for f in fm.FUNCTIONS:
        for name in ulp["backends"]:
            e, t = ulp["errors"][name][f], median[name][f]
            lines.append(f"| {f} | {name} | {e['max']:.3g} | {e['quantile']:.3g} | {e['hard_max']:.3g} | "
                         f"{1e3 * t:.2f} | {1e9 * t / POINTS:.2f} |")
    lines += ["", "Flushes subnormal results to zero: " + ", ".join(
        f"{name} {'yes' if ulp['flushes'][name] else 'no'}" for name in ulp["backends"]),
        "Missing on this machine: " + (", ".join(ulp["missing"]) or "none"), "",
        f"## The U-curve's floor (sine field, h_u at (u, v) = ({floors['u']}, {floors['v']}), "
        f"{floors['steps']} steps)", "",
        "| backend | floor (least error) | at step | fitted optimal step | fitted error there | "
        "fitted roundoff B | steps with other bits than libm |", "|---|---:|---:|---:|---:|---:|---:|",
        f"| error model | {floors['model']['error']:.3g} | {floors['model']['step']:.3g} | | | "
        f"{floors['model']['roundoff']:.3g} | |"]
    for name in floors["backends"]:
        b = floors["floors"][name]
        lines.append(f"| {name} | {b['error']:.3g} | {b['step']:.3g} | {b['fitted_step']:.3g} | "
                     f"{b['fitted_error']:.3g} | {b['fitted_roundoff']:.3g} | {b['differ']} |")
    text = "\n".join(lines) + "\n"
    print(text)
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "fastmath.md").write_text(text, encoding="utf-8")
    (a.out / "fastmath.json").write_text(json.dumps({"ulps": ulp, "floors": floors, "points": POINTS,
                                                     "load": load, "seconds": times}, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
