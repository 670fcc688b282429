"""Run time against error of the gradient methods, release configuration.

Runs `lab.gradient_benchmark.measure` with the FULL configuration (all sphere-A
pixels of a 256^2 frame in the mpmath reference, twelve steps per difference
sweep, fifteen interleaved repeats; forward-mode AD with its compile time apart), prints the Pareto front of each height
field, the best step of every method and the full table (medians with the
min-max of the runs: these machines are noisy), and writes them as Markdown and
the raw results, every run kept, as JSON.

Usage: python benchmarks/bench_gradients.py [--out DIR] [--repeats N]
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "book")]          # book/ for the book's `chapter` (its table)

from chapter.benchmark import markdown_table, step_text  # noqa: E402
from lab import gradient_benchmark as gb  # noqa: E402
from lab import gradient_methods as gm  # noqa: E402
from renderer import DRAFT_SCENE  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results",
                    help="directory for gradients.md and gradients.json (default benchmarks/results)")
    ap.add_argument("--repeats", type=int, default=gb.FULL.repeats,
                    help=f"timed runs per method (default {gb.FULL.repeats})")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error(f"--repeats must be >= 1, got {args.repeats}")
    config = dataclasses.replace(gb.FULL, repeats=args.repeats, richardson_repeats=args.repeats)

    m = gb.measure(config)
    h_ms = {f: 1e3 * statistics.median(t) for f, t in m.h_times.items()}
    excluded = ", ".join(f"{f} {n:,}" for f, n in m.excluded_pixels.items() if n)
    draft = gb.MethodResult("", "central", DRAFT_SCENE.eps, (0.0,), 0, 0, 0, 0, 0).label    # its row's label
    head = [
        "# Gradient methods: run time against error (FULL configuration)",
        "",
        f"{m.pixels:,} sphere-A pixels of a {config.size}x{config.size} default-scene frame "
        f"(k_u = {m.k_u:g}, k_v = {m.k_v:g}); times are per frame, median (min–max) of "
        f"{config.repeats} interleaved runs; errors are max and RMS over both components against "
        f"an mpmath reference at {config.digits} digits at every pixel where the gradient exists "
        f"(pixels on the crease band left out: {excluded or 'none'}). "
        f"One evaluation of h at all pixels: "
        + ", ".join(f"{f} {ms:.2f} ms" for f, ms in h_ms.items()) + ". "
        f"{gm.AD} (jax.jvp, jit-compiled by XLA): its first call at the frame's size traces and compiles, "
        "timed apart and not in its times: "
        + ", ".join(f"{f} {1e3 * m.get(f, gm.AD).compile_seconds:.0f} ms" for f in m.h_times) + ". "
        f"Machine: {m.machine}. Wall time of the run: {m.seconds:.0f} s.",
        "",
    ]
    front = "\n".join(head + ["## Pareto front (max error)", "", markdown_table(m, rows="front"), ""])
    best = "\n".join([f"## The best step of each method, and the draft's step {step_text(DRAFT_SCENE.eps)}", "",
                      markdown_table(m, rows="best", include=(draft,)), ""])
    full = "\n".join(["## Every method", "", markdown_table(m, rows="all"), ""])
    print(front)
    print(best)
    print(full)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "gradients.md").write_text(front + "\n" + best + "\n" + full)
    (args.out / "gradients.json").write_text(gb.to_json(m) + "\n")
    print(f"wrote {args.out / 'gradients.md'} and {args.out / 'gradients.json'}")


if __name__ == "__main__":
    main()
