"""The §4 simulator's update time, this tree against a baseline commit, in headless Chromium.

    .venv/bin/python tests/js/bench_update.py BASELINE [--rounds 3] [--moves 16] [--out FILE]

The baseline's bundle is generated in a detached git worktree (removed at the
end) by its own renderer/jsgen.py; this tree's by ours.  Each bundle runs in a
bare page (file://, no network) at 256 x 256, and the two alternate, round by
round, so that a busy machine slows both alike.  Per round and bundle: the eps
slider moved `--moves` times between two steps, then the beta slider as often;
the simulator's own timing of each update (``sim.timings``, performance.now()
around the whole update) is kept, the first of each series dropped (JIT warm-up).
Prints, and writes as JSON to ``--out`` (default test-artifacts/update_bench.json),
the median, quartiles and extremes per bundle and slider, with the machine's
load average.  Not a test: nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).parents[2]
sys.path.insert(0, str(ROOT))
from tests.jsnode import CHROMIUM, CHROMIUM_ARGS  # noqa: E402

MOVES = {"eps": ("log_eps", [-3.1, -3]), "beta": ("beta", [0.3, 0.4])}
PAGE = ('<!doctype html><html><head><meta charset="utf-8"></head><body style="max-width:900px">'
        '<div data-symrender-sim></div><script src="simulator.js"></script></body></html>')


def bundle(tree, out):
    """Generate tree's simulator bundle into out/simulator.js with tree's own Python; return the page."""
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=str(tree))
    subprocess.run([sys.executable, "-m", "renderer.jsgen", "--bundle", str(out / "simulator.js")], cwd=tree,
                   env=env, check=True, capture_output=True)
    (out / "index.html").write_text(PAGE, encoding="utf-8")
    return (out / "index.html").as_uri()


def series(browser, url, control, values, moves):
    """Update times (ms) of `moves` moves of one slider, the first dropped."""
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    context.route("**/*", lambda r: r.continue_() if r.request.url.startswith("file://") else r.abort())
    page = context.new_page()
    page.goto(url)
    page.wait_for_selector("[data-symrender-sim][data-updates]", state="attached", timeout=60_000)
    count = "Number(document.querySelector('[data-symrender-sim]').dataset.updates)"
    for k in range(moves):
        before = page.evaluate(count)
        page.fill(f"#sim-{control}", str(values[k % 2]))
        page.wait_for_function(f"{count} > {before}", timeout=60_000)
    timings = page.evaluate("document.querySelector('[data-symrender-sim]').symrender.timings")
    context.close()
    return [t["ms"] for t in timings[-moves:]][1:]


def summary(ms):
    q = statistics.quantiles(ms, n=4)
    return {"n": len(ms), "median_ms": statistics.median(ms), "q1_ms": q[0], "q3_ms": q[2], "min_ms": min(ms),
            "max_ms": max(ms)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("baseline", help="a commit of this repository")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--moves", type=int, default=16)
    parser.add_argument("--out", type=Path, default=ROOT / "test-artifacts" / "update_bench.json")
    args = parser.parse_args(argv)
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory(prefix="bench-update-") as tmp:
        tmp = Path(tmp)
        subprocess.run(["git", "worktree", "add", "--detach", str(tmp / "base"), args.baseline], cwd=ROOT,
                       check=True, capture_output=True)
        try:
            urls = {"baseline": bundle(tmp / "base", tmp / "baseline"), "this tree": bundle(ROOT, tmp / "tree")}
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(tmp / "base")], cwd=ROOT, check=True)
        times = {(name, kind): [] for name in urls for kind in MOVES}
        load = [os.getloadavg()[0]]
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=list(CHROMIUM_ARGS))
            for _ in range(args.rounds):
                for name, url in urls.items():
                    for kind, (control, values) in MOVES.items():
                        times[name, kind] += series(browser, url, control, values, args.moves)
                load.append(os.getloadavg()[0])
            browser.close()
    report = {"baseline": args.baseline, "size": 256, "load_average_1min": load,
              "results": {f"{name}, {kind}": summary(ms) for (name, kind), ms in times.items()}}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=1), encoding="utf-8")
    for key, r in report["results"].items():
        print(f"{key:18s} median {r['median_ms']:6.1f} ms  (quartiles {r['q1_ms']:.1f}-{r['q3_ms']:.1f}, "
              f"min {r['min_ms']:.1f}, max {r['max_ms']:.1f}, n = {r['n']})")
    print("load average (1 min) per round:", " ".join(f"{x:.1f}" for x in load))


if __name__ == "__main__":
    main()
