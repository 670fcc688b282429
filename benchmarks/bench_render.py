"""Render time, start-up time and memory of the working tree's renderer against a baseline commit.

The baseline (``--baseline``, default a35b7d1) is checked out into a temporary
detached git worktree, removed at the end.  All measurements run in child
processes, new and baseline alternating, each with ``PYTHONPATH=<its tree>``
and the tree first on ``sys.path``; each child checks that ``renderer`` came
from its tree.  Only the public API is used (Scene, render, sweep).

* Steady state, default ``Scene()``: 256² and 1024², exact and central, and an
  8-step ε sweep at 256² (the census inside ``sweep``); per round, case and
  renderer one child, two warm-up calls, then timed calls; samples pooled.
* Fresh process: the parent's wall time around a child that imports renderer
  and renders 256² exact (and ``python -c pass``); the first run (numba cache
  as found) apart from the later ones (warm cache); the new renderer with an
  empty ``NUMBA_CACHE_DIR`` (cold compile); where numba put its cache files.
* Memory beyond the output at 4096² exact, a fresh child each time: growth of
  ``ru_maxrss`` over the render (after a 64² warm-up) less the Frame's arrays'
  resident pages (those never written, zeros, are found by writing them after);
  tracemalloc's peak beyond the output for reference (numpy's allocations).

Results: benchmarks/results/render.md (table) and render.json (raw samples).
Usage: python benchmarks/bench_render.py [--repeats N] [--baseline REV] [--out DIR] [--quick]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STEPS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8, 1e-10)
#: Steady-state cases: name -> (side, gradient or "sweep", target in seconds).
CASES = {"exact 256²": (256, "exact", 0.004), "central 256²": (256, "central", 0.004),
         "exact 1024²": (1024, "exact", 0.060), "central 1024²": (1024, "central", 0.060),
         "8-step ε sweep 256²": (256, "sweep", 0.020)}
FRESH_TARGET, MEMORY_TARGET = 1.5, 16 * 2**20
#: A fresh process: import the tree's renderer, render 256² once, say where renderer came from.
FRESH = ("import sys; sys.path.insert(0, sys.argv[1]); import renderer; from renderer import Scene, render; "
         "render(Scene(), 256, 256); print(renderer.__file__)")
TREES = ("new", "baseline")


def _child(mode, root, arg):
    """In a child process: one measurement of the renderer in ``root``, printed as JSON."""
    sys.path.insert(0, root)
    import renderer
    from renderer import Scene, render, sweep
    out = {"file": os.path.realpath(renderer.__file__)}
    if not out["file"].startswith(os.path.realpath(root) + os.sep):
        sys.exit(f"renderer was imported from {out['file']}, not from {root}")
    scene = Scene()
    nbytes = lambda f: sum(a.nbytes for a in (f.image, f.chamber, f.kink, f.grad) if a is not None)  # noqa: E731
    if mode == "steady":
        name, reps = arg.rsplit(":", 1)
        side, kind, _ = CASES[name]
        fn = ((lambda: sweep(scene, STEPS, side, side).census) if kind == "sweep"
              else lambda: render(scene, side, side, gradient=kind))
        t0 = time.perf_counter()  # warm-up: three calls and a third of a second, whichever is longer
        for k in range(1000):
            fn()
            if k >= 2 and time.perf_counter() - t0 > 0.33:
                break
        out["samples"] = []
        for _ in range(int(reps)):
            t0 = time.perf_counter()
            fn()
            out["samples"].append(time.perf_counter() - t0)
    elif mode == "maxrss":
        import resource
        rss = lambda: 1024 * sum(int(ln.split()[1]) for ln in open("/proc/self/status") if ln[:6] == "VmRSS:")  # noqa
        maxrss = lambda: 1024 * resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # noqa: E731
        render(scene, 64, 64)
        before, slack = maxrss(), max(0, maxrss() - rss())  # slack: growth the high-water mark cannot show
        frame = render(scene, 4096, 4096)
        after, held = maxrss(), rss()
        for a in (a for a in (frame.image, frame.chamber, frame.kink, frame.grad) if a is not None):
            if a.flags.c_contiguous:  # write one byte per page: the output's pages never touched (zeros)
                a.reshape(-1).view("u1")[::resource.getpagesize()] |= 0
        untouched = rss() - held
        out.update(raw=after - before - nbytes(frame), beyond=after - before - (nbytes(frame) - untouched),
                   output=nbytes(frame), untouched=untouched, slack=slack)
    elif mode == "tracemalloc":  # and the versions of what the renderer loaded
        import tracemalloc
        render(scene, 64, 64)
        tracemalloc.start()
        frame = render(scene, 4096, 4096)
        nb = sys.modules.get("numba")
        out.update(beyond=tracemalloc.get_traced_memory()[1] - nbytes(frame), python=platform.python_version(),
                   numpy=sys.modules["numpy"].__version__, numba=nb and nb.__version__,
                   numba_cache_dir=nb and (nb.config.CACHE_DIR or None))
    print(json.dumps(out))


def _process(root, argv, **env):
    """Wall time (s) of a child process run in ``root`` with PYTHONPATH=root, and its last line of output."""
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, *argv], env={**os.environ, "PYTHONPATH": str(root), **env}, cwd=root,
                         capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if run.returncode:
        raise SystemExit(f"failed in {root}: {argv[-3:]}\n{run.stderr[-4000:]}")
    return dt, (run.stdout.strip().splitlines() or [""])[-1]


def _stats(samples):
    return dict(median=statistics.median(samples), min=min(samples), max=max(samples), runs=len(samples),
                samples=samples)


def _git(*args, cwd=ROOT):
    return subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True, text=True).stdout.strip()


def _nb_files(tree):
    return sorted(str(p.relative_to(tree)) for ext in ("nbi", "nbc") for p in (tree / "renderer").rglob(f"*.{ext}"))


def measure(trees, repeats, quick):
    """All the measurements, new and baseline alternating: a dict for render.json."""
    res = {"numba cache files before": len(_nb_files(trees["new"]))}
    def child(tree, mode, arg=""):
        return json.loads(_process(trees[tree], [__file__, "--child", mode, str(trees[tree]), arg])[1])
    fresh_runs, cold_runs, mem_runs, rounds = (3, 1, 1, 2) if quick else (5, 3, 3, 3)
    # Fresh processes first, so that the first run meets the numba cache as it was found.
    fresh = {k: [] for k in (*TREES, "python -c pass")}
    for _ in range(fresh_runs):
        for tree in TREES:
            dt, where = _process(trees[tree], ["-c", FRESH, str(trees[tree])])
            if not os.path.realpath(where).startswith(str(trees[tree]) + os.sep):
                raise SystemExit(f"{tree}: renderer was imported from {where}")
            fresh[tree].append(dt)
        fresh["python -c pass"].append(_process(ROOT, ["-c", "pass"])[0])
    res["fresh"] = {k: {"first": _stats(s[:1]), "warm": _stats(s[1:])} for k, s in fresh.items()}
    cold, written = [], []
    for _ in range(cold_runs):
        with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache:
            cold.append(_process(trees["new"], ["-c", FRESH, str(trees["new"])], NUMBA_CACHE_DIR=cache)[0])
            written.append(sum(1 for p in Path(cache).rglob("*") if p.suffix in (".nbi", ".nbc")))
    res["cold"] = _stats(cold) | {"cache files written": written}
    samples = {t: {c: [] for c in CASES} for t in TREES}
    for _ in range(rounds):
        for case in CASES:
            for tree in TREES:
                samples[tree][case] += child(tree, "steady", f"{case}:{math.ceil(repeats / rounds)}")["samples"]
    res["steady"] = {t: {c: _stats(s) for c, s in cs.items()} for t, cs in samples.items()}
    mem = [{t: child(t, "maxrss") for t in TREES} for _ in range(mem_runs)]  # alternating
    res["memory"] = {t: _stats([m[t]["beyond"] for m in mem]) | {k: [m[t][k] for m in mem] for k in mem[0][t]}
                     for t in TREES}
    res["tracemalloc"] = {t: child(t, "tracemalloc") for t in TREES}
    res["numba cache files after"] = _nb_files(trees["new"])
    return res


def _cell(st, scale, fmt, unit):
    if st is None:
        return "—"
    spread = f" ({st['min'] * scale:{fmt}}–{st['max'] * scale:{fmt}})" if st["runs"] > 1 else ""
    return f"{st['median'] * scale:{fmt}}{spread}{unit}"


def report(res, info):
    """The Markdown page."""
    (new, base), fresh, mem = (res["steady"][t] for t in TREES), res["fresh"], res["memory"]
    rows = [(name, new[name], base[name], 1e3, ".1f", " ms", target) for name, (_, _, target) in CASES.items()]
    rows += [("fresh import + first 256² render, warm cache (runs 2–)", fresh["new"]["warm"],
              fresh["baseline"]["warm"], 1, ".2f", " s", FRESH_TARGET),
             ("the same, first run (cache as found)", fresh["new"]["first"], fresh["baseline"]["first"], 1, ".2f",
              " s", None),
             ("the same, empty NUMBA_CACHE_DIR (cold compile)", res["cold"], None, 1, ".2f", " s", None),
             ("bare interpreter, python -c pass", fresh["python -c pass"]["warm"], None, 1e3, ".0f", " ms", None),
             ("peak memory beyond the output, 4096² exact (ru_maxrss)", mem["new"], mem["baseline"], 2**-20, ".1f",
              " MiB", MEMORY_TARGET)]
    v = res["tracemalloc"]["new"]
    lines = ["## Render benchmark: the working tree against the baseline", "",
             f"* new: `{info['new']}`", f"* baseline: `{info['baseline']}`",
             f"* machine: {info['cpu']}, {info['cores']}; Python {v['python']}, numpy {v['numpy']}, "
             f"numba {v['numba'] or 'not loaded by the renderer'}", "",
             f"Median (min–max).  Steady state: {new['exact 256²']['runs']} timed calls per case and renderer, "
             "from alternating child processes, after a warm-up of at least three calls and 0.33 s.  Targets are judged on the new renderer's median.",
             "", "| case | new median (min–max) | baseline median (min–max) | ratio baseline/new | target |",
             "|---|---|---|---|---|"]
    for name, st_new, st_base, scale, fmt, unit, target in rows:
        ratio = f"{st_base['median'] / st_new['median']:.2f}" if st_base else "—"
        goal = "—" if target is None else f"≤ {target * scale:g}{unit}: " + (
            "met" if st_new["median"] <= target else "not met")
        lines.append(f"| {name} | {_cell(st_new, scale, fmt, unit)} | {_cell(st_base, scale, fmt, unit)} | "
                     f"{ratio} | {goal} |")
    files, mib = res["numba cache files after"], lambda t, k: f"{max(mem[t][k]) / 2**20:.1f} MiB ({t})"
    lines += ["", "* Fresh process: the parent's wall time around the child, interpreter start included.  "
              "Cold compile: a new empty NUMBA_CACHE_DIR per run "
              f"({', '.join(map(str, res['cold']['cache files written']))} *.nbi/*.nbc files written into it).",
              f"* numba cache: numba.config.CACHE_DIR is {v.get('numba_cache_dir') or 'not set'}; *.nbi/*.nbc "
              f"files under the new tree's renderer/: {res['numba cache files before']} before the first run, "
              f"{len(files)} after, in {', '.join(sorted({str(Path(f).parent) for f in files})) or '—'}.",
              f"* Memory: the 4096² Frame's arrays are {mem['new']['output'][0] / 2**20:.1f} MiB, of which pages "
              f"never written (zeros, not resident) at most {mib('new', 'untouched')} and "
              f"{mib('baseline', 'untouched')}; they are not subtracted (the ru_maxrss growth less all the output "
              f"would be, median, {statistics.median(mem['new']['raw']) / 2**20:.1f} MiB (new) and "
              f"{statistics.median(mem['baseline']['raw']) / 2**20:.1f} MiB (baseline)).  ru_maxrss counts the "
              "rendering process only, not worker processes it may start; before the render it stood at most "
              f"{mib('new', 'slack')} and {mib('baseline', 'slack')} above the resident set (growth it cannot "
              "show).  tracemalloc's peak beyond the output (numpy's allocations only): "
              + ", ".join(f"{t} {res['tracemalloc'][t]['beyond'] / 2**20:.1f} MiB" for t in TREES) + "."]
    return "\n".join(lines) + "\n"


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--child"]:
        return _child(*argv[1:4])
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=None, help="timed calls per steady-state case (default 15)")
    ap.add_argument("--baseline", default="a35b7d1", help="the baseline commit (default a35b7d1)")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results", help="benchmarks/results/")
    ap.add_argument("--quick", action="store_true", help="fewer repeats and runs, for a smoke run")
    ap.add_argument("--new-tree", type=Path, default=ROOT, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    repeats = args.repeats or (4 if args.quick else 15)
    if repeats < 1:
        ap.error(f"--repeats must be >= 1, got {repeats}")
    new = args.new_tree.resolve()
    dirty = " + uncommitted changes in renderer/" if _git("status", "--porcelain", "--", "renderer", cwd=new) else ""
    cpu = [ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")]
    info = {"new": f"{new} at {_git('rev-parse', 'HEAD', cwd=new)}{dirty}", "cpu": (cpu or ["unknown CPU"])[0],
            "cores": f"{os.cpu_count()} logical CPUs ({len(os.sched_getaffinity(0))} usable)"}
    base = (tmp := Path(os.path.realpath(tempfile.mkdtemp(prefix="bench-render-")))) / "baseline"
    _git("worktree", "add", "--detach", str(base), args.baseline)
    try:
        info["baseline"] = f"{args.baseline} = {_git('rev-parse', 'HEAD', cwd=base)}"
        res = measure({"new": new, "baseline": base}, repeats, args.quick)
    finally:
        _git("worktree", "remove", "--force", str(base))
        shutil.rmtree(tmp, ignore_errors=True)
    res["info"] = info
    text = report(res, info)
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "render.md").write_text(text, encoding="utf-8")
    (args.out / "render.json").write_text(json.dumps(res, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
