"""Render speed: medians for both pipelines at 128^2 ... 1024^2, peak memory at
1024^2, and the speed-up over the scalar per-pixel reference of tests/ at 128^2,
all measured side by side in one run (these machines are noisy: the spread
min-max is printed with every median).

Usage: python benchmarks/bench_render.py [--repeats N] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from renderer import Scene, render  # noqa: E402
from tests.scalar_reference import render_reference  # noqa: E402

SIZES = (128, 256, 512, 1024)
PIPELINES = ("exact", "central")


def _times(fn, repeats):
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=15, help="timed runs per cell (default 15)")
    ap.add_argument("--json", type=Path, help="also write the results to this JSON file")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error(f"--repeats must be >= 1, got {args.repeats}")

    scene = Scene()
    results = {}
    for size in SIZES:
        for pipe in PIPELINES:
            render(scene, size, size, gradient=pipe)          # warm-up
        reps = max(3, args.repeats // (1 if size <= 256 else 3))
        samples = {p: [] for p in PIPELINES}
        for _ in range(reps):                                  # interleave the pipelines
            for pipe in PIPELINES:
                samples[pipe] += _times(lambda: render(scene, size, size, gradient=pipe), 1)
        for pipe in PIPELINES:
            s = samples[pipe]
            results[f"{pipe}@{size}"] = dict(median=statistics.median(s), min=min(s), max=max(s),
                                             runs=len(s))

    peak = {}
    for pipe in PIPELINES:
        tracemalloc.start()
        frame = render(scene, 1024, 1024, gradient=pipe)
        _, peak_bytes = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        del frame
        peak[pipe] = peak_bytes

    # Scalar reference against the vectorized renderer at 128^2, same run.
    ref = {}
    for pipe in PIPELINES:
        s = _times(lambda: render_reference(scene, 128, 128, gradient=pipe), 3)
        ref[pipe] = dict(median=statistics.median(s), min=min(s), max=max(s), runs=len(s))

    print(f"{'pipeline':>8} {'size':>6} {'median ms':>10} {'min-max ms':>16} {'runs':>5}")
    for size in SIZES:
        for pipe in PIPELINES:
            r = results[f"{pipe}@{size}"]
            print(f"{pipe:>8} {size:>4}^2 {1e3 * r['median']:>10.2f} "
                  f"{1e3 * r['min']:>7.2f}-{1e3 * r['max']:<8.2f} {r['runs']:>5}")
    print()
    for pipe in PIPELINES:
        print(f"peak traced memory, {pipe} 1024^2: {peak[pipe] / 2**20:.1f} MiB "
              f"(outputs alone: {1024 * 1024 * (3 * 8 + 1 + 1 + 2 * 8) / 2**20:.1f} MiB)")
    print()
    for pipe in PIPELINES:
        vec = results[f"{pipe}@128"]["median"]
        print(f"scalar reference {pipe} 128^2: median {ref[pipe]['median']:.2f} s "
              f"({ref[pipe]['min']:.2f}-{ref[pipe]['max']:.2f}); vectorized {1e3 * vec:.2f} ms; "
              f"speed-up x{ref[pipe]['median'] / vec:.0f}")
    if args.json:
        args.json.write_text(json.dumps(dict(render=results, peak_bytes=peak, reference=ref),
                                        indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
