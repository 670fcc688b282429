"""Render speed and scaling, measured side by side in one run.

* time (median, min-max) of both pipelines from 64^2 to 4096^2, and peak
  memory (tracemalloc) at each size, with the part beyond the returned frame;
* the speed-up over the scalar per-pixel reference of tests/ at 64^2;
* an 8-step eps sweep at 256^2 (both pipelines and the census), against the
  same frames rendered independently;
* the gradient stage alone over sphere A's pixels: exact against one central
  difference at the same pixels;
* the steady state: each target case (and 256^2 on one thread) repeated back
  to back in child processes of three kinds, alternating: the defaults (tiles
  on the calling thread and worker processes, renderer.workers; the
  allocator settings of renderer.heap), threads only
  (SYMRENDER_WORKER_PROCESSES=0), and the heap left alone
  (SYMRENDER_KEEP_HEAP=0), with the minor page faults per run; the issue-6
  targets are judged on the defaults.

These machines are noisy: every median is printed with its min-max, and the
things compared are interleaved in one loop.  Results go to
benchmarks/results/render.md (and .json).

Usage: python benchmarks/bench_render.py [--repeats N] [--max-size S] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from renderer import Scene, compare, fields, gbuffer, render, sweep  # noqa: E402
from renderer import workers as worker_processes  # noqa: E402
from renderer.render import TILE_PIXELS, WORKERS, central_gradient  # noqa: E402
from tests.scalar_reference import render_reference  # noqa: E402

SIZES = (64, 128, 256, 512, 1024, 2048, 4096)
PIPELINES = ("exact", "central")
STEPS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10)


def _stats(samples):
    return dict(median=statistics.median(samples), min=min(samples), max=max(samples), runs=len(samples))


def _interleaved(fns, repeats):
    """{name: stats} of the callables in ``fns``, run round-robin ``repeats`` times after a warm-up."""
    for fn in fns.values():
        fn()
    samples = {k: [] for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            samples[k].append(time.perf_counter() - t0)
    return {k: _stats(v) for k, v in samples.items()}


def _peak_working_bytes(fn):
    tracemalloc.start()
    out = fn()
    current, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    del out
    return peak, current


# Cases measured in child processes, each repeated back to back (a user's
# steady state): the issue-6 targets, and the heap settings on and off.
# name: (size, render keywords or "sweep", repeats as a fraction of --repeats)
STEADY_CASES = {
    "exact 256², 1 thread": (256, dict(workers=1), 1.0),
    "exact 256²": (256, {}, 1.0),
    "central 256²": (256, dict(gradient="central"), 1.0),
    "exact 1024²": (1024, {}, 1 / 3),
    "central 1024²": (1024, dict(gradient="central"), 1 / 3),
    "8-step ε sweep 256²": (256, "sweep", 1 / 2),
}


def _steady_child(repeats):
    """Run in a child process: per case, the median of its warm runs, one case
    after the other (s), and the minor page faults per run; printed as JSON."""
    from renderer.heap import keep_heap
    scene = Scene()
    out = {"worker processes": worker_processes.wait_ready()}
    for name, (size, kw, share) in STEADY_CASES.items():
        if kw == "sweep":
            fn = lambda size=size: sweep(scene, STEPS, size, size)   # noqa: E731
        else:
            fn = lambda size=size, kw=kw: render(scene, size, size, **kw)   # noqa: E731
        fn()
        fn()
        runs = max(3, round(repeats * share))
        before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        times = []
        for _ in range(runs):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        faults = (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / runs
        out[name] = dict(median=statistics.median(times), faults=faults)
    out["applied"] = keep_heap()
    print(json.dumps(out))


#: Children of each kind.
STEADY_ROUNDS = 5
#: The kinds of steady-state child: name -> environment variable set to "0".
STEADY_SETTINGS = {"defaults": None, "threads only": worker_processes.ENV_VAR,
                   "heap left alone": "SYMRENDER_KEEP_HEAP"}


def _steady_rounds(rounds, repeats):
    """Children of each kind in `STEADY_SETTINGS`, alternating:
    {setting: {case: stats of the children's medians, with faults per run}}."""
    samples = {k: [] for k in STEADY_SETTINGS}
    for _ in range(rounds):
        for setting, var in STEADY_SETTINGS.items():
            env = {k: v for k, v in os.environ.items() if k not in STEADY_SETTINGS.values()}
            if var is not None:
                env[var] = "0"
            run = subprocess.run([sys.executable, __file__, "--steady-child", str(repeats)], env=env,
                                 check=True, capture_output=True, text=True)
            samples[setting].append(json.loads(run.stdout.strip().splitlines()[-1]))
    res = {}
    for setting, runs in samples.items():
        res[setting] = {"applied": all(r["applied"] for r in runs),
                        "worker processes": min(r["worker processes"] for r in runs)}
        for name in STEADY_CASES:
            res[setting][name] = _stats([r[name]["median"] for r in runs]) | {
                "faults": statistics.median(r[name]["faults"] for r in runs)}
    return res


def main(argv=None):
    if argv is None and sys.argv[1:2] == ["--steady-child"]:
        return _steady_child(int(sys.argv[2]))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=15, help="timed runs per cell at <= 256^2 (default 15)")
    ap.add_argument("--max-size", type=int, default=4096, help="largest side (default 4096)")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error(f"--repeats must be >= 1, got {args.repeats}")
    scene = Scene()
    res = {"scaling": {}, "memory": {}, "worker processes": worker_processes.wait_ready()}

    for size in [s for s in SIZES if s <= args.max_size]:
        reps = args.repeats if size <= 256 else max(3, args.repeats // 3) if size <= 1024 else 3
        fns = {p: (lambda p=p: render(scene, size, size, gradient=p)) for p in PIPELINES}
        fns["exact, image only"] = lambda: render(scene, size, size, kink=False, grad=False)
        if size <= 1024:
            fns["exact, 1 thread"] = lambda: render(scene, size, size, workers=1)
        for k, st in _interleaved(fns, reps).items():
            res["scaling"][f"{k}@{size}"] = st
        peak, held = _peak_working_bytes(lambda: render(scene, size, size, kink=False, grad=False))
        res["memory"][size] = dict(peak=peak, output=held, per_pixel=peak / size**2)

    ref = _interleaved({"reference exact": lambda: render_reference(scene, 64, 64, gradient="exact"),
                        "numpy exact": lambda: render(scene, 64, 64),
                        "reference central": lambda: render_reference(scene, 64, 64, gradient="central"),
                        "numpy central": lambda: render(scene, 64, 64, gradient="central")}, 3)
    res["reference"] = ref

    def independent():
        frames = [render(scene.replace(eps=e), 256, 256, gradient="central") for e in STEPS]
        sym = render(scene, 256, 256)
        return [compare(f, sym) for f in frames]

    res["sweep"] = _interleaved({"sweep()": lambda: sweep(scene, STEPS, 256, 256),
                                 "sweep(), 1 thread": lambda: sweep(scene, STEPS, 256, 256, workers=1),
                                 "independent renders": independent}, 7)

    gb = gbuffer(scene, 256, 256)
    on_a = gb.chamber == 1
    uu, vv = gb.uv[on_a, 0].copy(), gb.uv[on_a, 1].copy()
    stage = {}
    for field in ("sine", "ridges", "rings"):
        st = _interleaved({
            "exact": lambda f=field: fields.exact_gradient(f, uu, vv, 8.0, 4.0),
            "central": lambda f=field: central_gradient(f, uu, vv, 8.0, 4.0, 1e-3)}, 25)
        stage[field] = st | {"pixels": int(uu.size)}
    res["gradient_stage"] = stage
    res["steady"] = steady = _steady_rounds(STEADY_ROUNDS, args.repeats)

    lines = ["## Scaling (default scene; ms, median and min-max)", "",
             f"Tiles render on the calling thread and {res['worker processes']} worker process(es) "
             f"(`renderer.workers`; {WORKERS} workers, the default here) unless stated.  Peak memory is "
             "this process's (tracemalloc); a worker process holds one tile's temporaries and "
             f"{worker_processes.SLOTS} tile slots of {worker_processes.PIXEL_BYTES} bytes per pixel "
             f"({worker_processes.SLOTS * TILE_PIXELS * worker_processes.PIXEL_BYTES / 2**20:.2f} MiB).", "",
             "| size | exact | central | exact, image only | exact, 1 thread | output MiB | peak MiB | "
             "peak beyond the output, MiB |",
             "|---|---|---|---|---|---|---|---|"]
    for size in [s for s in SIZES if s <= args.max_size]:
        cells = []
        for k in ("exact", "central", "exact, image only", "exact, 1 thread"):
            r = res["scaling"].get(f"{k}@{size}")
            cells.append("—" if r is None else
                         f"{1e3 * r['median']:.1f} ({1e3 * r['min']:.1f}-{1e3 * r['max']:.1f})")
        m = res["memory"][size]
        lines.append(f"| {size}² | " + " | ".join(cells) + f" | {m['output'] / 2**20:.1f} | "
                     f"{m['peak'] / 2**20:.1f} | {(m['peak'] - m['output']) / 2**20:.1f} |")
    lines += ["", "## Scalar per-pixel reference at 64² (same run)", "", "| pipeline | reference ms | numpy ms | speed-up |",
              "|---|---|---|---|"]
    for p in PIPELINES:
        a, b = ref[f"reference {p}"]["median"], ref[f"numpy {p}"]["median"]
        lines.append(f"| {p} | {1e3 * a:.0f} | {1e3 * b:.2f} | ×{a / b:.0f} |")
    sw = res["sweep"]
    lines += ["", "## 8-step ε sweep at 256², both pipelines and the census", "",
              "| path | median ms | min-max ms |", "|---|---|---|"]
    for k, r in sw.items():
        lines.append(f"| {k} | {1e3 * r['median']:.0f} | {1e3 * r['min']:.0f}-{1e3 * r['max']:.0f} |")
    lines += ["", "## Gradient stage over sphere A's pixels at 256² (µs)", "",
              "| field | pixels | exact | one central difference | exact / central |", "|---|---|---|---|---|"]
    for field, st in stage.items():
        e, c = st["exact"]["median"], st["central"]["median"]
        lines.append(f"| {field} | {st['pixels']} | {1e6 * e:.0f} ({1e6 * st['exact']['min']:.0f}-"
                     f"{1e6 * st['exact']['max']:.0f}) | {1e6 * c:.0f} ({1e6 * st['central']['min']:.0f}-"
                     f"{1e6 * st['central']['max']:.0f}) | {e / c:.2f} |")
    def cell(st):
        return f"{1e3 * st['median']:.1f} ({1e3 * st['min']:.1f}-{1e3 * st['max']:.1f})"

    d, t, h = (steady[k] for k in STEADY_SETTINGS)
    lines += ["", "## Steady state: worker processes, threads, and the allocator settings", "",
              "Each case repeated back to back in a child process (the tables above "
              "alternate their cases in one process, which here runs each 15-30 % slower). "
              f"{len(STEADY_SETTINGS)} kinds of child, {STEADY_ROUNDS} of each, alternating: the defaults (the calling thread and "
              f"{d['worker processes']} worker process(es), `renderer.workers`; the heap kept, "
              "`renderer.heap`), threads only (SYMRENDER_WORKER_PROCESSES=0) and the heap left alone "
              "(SYMRENDER_KEEP_HEAP=0).  Shown: the median of the children's medians (min-max), "
              "and the minor page faults per run of this process (a worker's are its own).", "",
              "| case | defaults, ms | faults/run | threads only, ms | threads / defaults | "
              "heap left alone, ms | faults/run | left alone / defaults |",
              "|---|---|---|---|---|---|---|---|"]
    for name in STEADY_CASES:
        lines.append(f"| {name} | {cell(d[name])} | {d[name]['faults']:.0f} | {cell(t[name])} | "
                     f"{t[name]['median'] / d[name]['median']:.2f} | {cell(h[name])} | "
                     f"{h[name]['faults']:.0f} | {h[name]['median'] / d[name]['median']:.2f} |")
    lines += ["", "## Issue 6 targets (steady state, defaults: the table above)", "",
              "| target | measured, median (min-max of the children) | met |", "|---|---|---|"]
    kept = d
    checks = [(f"{p} 256², ≤ 15 ms", kept[f"{p} 256²"], 0.015) for p in PIPELINES]
    checks += [(f"{p} 1024², ≤ 250 ms", kept[f"{p} 1024²"], 0.25) for p in PIPELINES]
    checks.append(("8-step ε sweep at 256², both pipelines and the census, ≤ 80 ms",
                   kept["8-step ε sweep 256²"], 0.08))
    for name, st, limit in checks:
        lines.append(f"| {name} | {1e3 * st['median']:.1f} ({1e3 * st['min']:.1f}-{1e3 * st['max']:.1f}) ms | "
                     f"{'yes' if st['median'] <= limit else 'no'} |")
    text = "\n".join(lines) + "\n"
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "render.md").write_text(text, encoding="utf-8")
    (args.out / "render.json").write_text(json.dumps(res, indent=1, default=float), encoding="utf-8")


if __name__ == "__main__":
    main()
