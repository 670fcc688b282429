"""renderer.workers: tiles rendered in worker processes are the same bits as on
one thread; a failing worker costs no pixel; workers start only when a
process renders more than once, and die with their parent.
"""

from __future__ import annotations

import importlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from renderer import Scene, render
from renderer import workers as W

R = importlib.import_module("renderer.render")
ROOT = Path(__file__).resolve().parents[1]
BIG = (300, 240)                # above MIN_SPLIT_PIXELS: split into tiles


def _same(a, b):
    return all(
        (x is None and y is None) or np.array_equal(x, y)
        for x, y in ((a.image, b.image), (a.chamber, b.chamber), (a.kink, b.kink), (a.grad, b.grad)))


@pytest.fixture
def ready():
    """One ready worker, and a fresh start afterwards."""
    W.shutdown()
    if W.wait_ready(1) != 1:
        pytest.fail(f"no render worker started: {W.stats()}")
    yield
    W.shutdown()


SCENES = {
    "default": Scene(),
    "sine, phong": Scene(height_field="sine", model="phong", eps=1e-6),
    "rings, no floor": Scene(height_field="rings", floor=False),
    "surface bump": Scene(height_field="sine", bump="surface", beta=0.5, sphere_b=False),
}


@pytest.mark.parametrize("name", sorted(SCENES))
@pytest.mark.parametrize("gradient", ["exact", "central"])
def test_worker_tiles_are_the_same_bits(ready, name, gradient):
    scene = SCENES[name]
    before = W.stats()["tiles"]
    for size in (BIG, (256, 256), (640, 300)):
        one = render(scene, *size, gradient=gradient, workers=1)
        two = render(scene, *size, gradient=gradient, workers=2)
        assert _same(one, two), size
    lean = render(scene, *BIG, gradient=gradient, workers=2, kink=False, grad=False)
    ref = render(scene, *BIG, gradient=gradient, workers=1)
    assert lean.kink is None and lean.grad is None
    assert np.array_equal(lean.image, ref.image) and np.array_equal(lean.chamber, ref.chamber)
    assert W.stats()["tiles"] > before            # the workers rendered some of them


def test_a_slot_keeps_no_pixel_of_the_previous_tile(ready):
    # The default scene's floor fills the frame; without the floor the same
    # tiles show background, which a tile does not write: the worker must
    # clear its slot first.
    render(Scene(), *BIG, workers=2)
    bare = Scene(floor=False)
    assert _same(render(bare, *BIG, workers=2), render(bare, *BIG, workers=1))
    assert not _same(render(Scene(), *BIG, workers=1), render(bare, *BIG, workers=1))


def test_the_check_sees_a_tile_copied_to_the_wrong_rows(ready, monkeypatch):
    copy = W._copy_out

    def shifted(worker, slot, bounds, outputs, width):
        j0, j1 = bounds
        copy(worker, slot, (j0 - 1, j1 - 1), outputs, width)

    monkeypatch.setattr(W, "_copy_out", shifted)
    assert not _same(render(Scene(), *BIG, workers=2), render(Scene(), *BIG, workers=1))


def test_a_worker_error_is_rendered_here_with_one_warning(ready):
    # A tile too big for the worker's slot: the worker raises, the caller
    # renders the tile itself and turns the workers off.
    scene = Scene()
    width, height = 400, 330
    ref = render(scene, width, height, workers=1)
    out = [np.zeros((width * height, 3)), np.zeros(width * height, np.uint8),
           np.zeros(width * height, bool), np.zeros((width * height, 2))]
    x, y = R.image_plane(scene.radius_a, scene.camera_z, width, height, 1.0)

    def local(j0, j1):
        sl = slice(j0 * width, j1 * width)
        R._render_tile(scene, "exact", np.tile(x, j1 - j0), np.repeat(y[j0:j1], width),
                       out[0][sl], out[1][sl], out[2][sl], out[3][sl], True, (x, y[j0:j1]))

    job = (scene, "exact", width, height, 1.0, True, True, True)
    with pytest.warns(RuntimeWarning, match="a worker failed: ValueError: a tile of 124000 pixels"):
        assert W.run_tiles([(0, 20), (20, 330)], local, job, out, width, 1, 1 << 16)
    assert W.stats()["disabled"] and W.stats()["fallbacks"] == 1 and W.stats()["workers"] == 0
    assert np.array_equal(out[0].reshape(ref.image.shape), ref.image)
    assert np.array_equal(out[3].reshape(ref.grad.shape), ref.grad)
    # Off for the rest of the process (until shutdown): threads, same bits.
    assert not W.run_tiles([(0, 10), (10, 20)], local, job, out, width, 1, 1 << 16)
    assert _same(render(scene, *BIG, workers=2), render(scene, *BIG, workers=1))


def test_a_killed_worker_costs_no_pixel(ready):
    W._state["workers"][0].proc.kill()
    W._state["workers"][0].proc.wait()
    with pytest.warns(RuntimeWarning, match="render worker processes are off"):
        frame = render(Scene(), *BIG, gradient="central", workers=2)
    assert _same(frame, render(Scene(), *BIG, gradient="central", workers=1))
    assert W.stats()["disabled"] is not None


def test_answers_to_an_interrupted_render_are_dropped(ready):
    scene = Scene()

    class Interrupt(Exception):
        pass

    def interrupted(j0, j1):
        raise Interrupt

    width, height = BIG
    out = [np.zeros((width * height, 3)), np.zeros(width * height, np.uint8), None, None]
    job = (scene, "central", width, height, 1.0, False, False, True)
    with pytest.raises(Interrupt):
        W.run_tiles([(0, 120), (120, 240)], interrupted, job, out, width, 1, 1 << 16)
    # The worker's answer to that job is still on its way; the next render
    # must not take it for its own.
    bare = scene.replace(floor=False, sphere_b=False)
    tiles = W.stats()["tiles"]
    assert _same(render(bare, *BIG, workers=2), render(bare, *BIG, workers=1))
    assert W.stats()["tiles"] > tiles and W.stats()["disabled"] is None


def test_the_environment_variable_turns_them_off(ready, monkeypatch):
    monkeypatch.setenv(W.ENV_VAR, "0")
    tiles = W.stats()["tiles"]
    render(Scene(), *BIG, workers=2)
    assert W.stats()["tiles"] == tiles


def test_one_worker_render_at_a_time_the_other_on_threads(ready):
    import threading
    scene = Scene()
    ref = render(scene, *BIG, gradient="central", workers=1)
    frames = [None] * 4

    def go(i):
        frames[i] = render(scene, *BIG, gradient="central", workers=2)

    threads = [threading.Thread(target=go, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(_same(f, ref) for f in frames)


# A fresh process: how many workers after each of three renders, and the pid
# of the worker; then it waits to be killed.
_PROBE = r"""
import json, sys, time
sys.path.insert(0, sys.argv[1])
from renderer import Scene, render, workers as W
counts = []
for _ in range(3):
    render(Scene(), 300, 240)
    counts.append(W.stats()["workers"])
W.wait_ready()
print(json.dumps({"counts": counts, "pids": [w.proc.pid for w in W._state["workers"]]}), flush=True)
time.sleep(60)
"""


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie (exited, not yet reaped by its dead parent's reaper) counts as gone.
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(") ")[-1][0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(sys.platform != "linux", reason="reads /proc")
def test_workers_start_on_the_second_render_and_die_with_their_parent():
    if R.WORKERS < 2:
        pytest.fail("this test needs a machine with two cores (as CI has)")
    env = {k: v for k, v in os.environ.items() if k != W.ENV_VAR}
    parent = subprocess.Popen([sys.executable, "-c", _PROBE, str(ROOT)], stdout=subprocess.PIPE,
                              text=True, env=env)
    try:
        info = json.loads(parent.stdout.readline())
        assert info["counts"] == [0, R.WORKERS - 1, R.WORKERS - 1]
        assert len(info["pids"]) == R.WORKERS - 1 and all(_alive(p) for p in info["pids"])
    finally:
        parent.send_signal(signal.SIGKILL)      # no atexit: only the closed socket tells them
        parent.wait()
    deadline = time.monotonic() + 20
    while any(_alive(p) for p in info["pids"]) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(_alive(p) for p in info["pids"])


@pytest.mark.parametrize("size", [(256, 256), BIG, (8192, 9), (640, 300), (1024, 1024), (100, 8192)])
@pytest.mark.parametrize("workers", [2, 3])
def test_tile_bounds_cover_the_frame_within_the_memory_bound(size, workers):
    scene = Scene()
    bounds = R._tile_bounds(scene, *size, 1.0, workers, R.SPHERE_A_COST["central"])
    cuts = [j0 for j0, _ in bounds] + [bounds[-1][1]]
    assert cuts[0] == 0 and cuts[-1] == size[1] and all(a < b for a, b in zip(cuts, cuts[1:]))
    assert all((j1 - j0) * size[0] <= R.TILE_PIXELS for j0, j1 in bounds)
    assert len(bounds) >= min(workers, size[1])


def _tile_costs(scene, bounds, size, a_cost):
    """Each tile's cost by the weights of render.PIXEL_COST, counted on every
    pixel of the rendered chamber map (not on the coarse grid of the estimate)."""
    chamber = render(scene, *size, workers=1, kink=False, grad=False).chamber
    weight = np.array([R.PIXEL_COST[R.BACKGROUND], a_cost, R.PIXEL_COST[R.SPHERE_B],
                       R.PIXEL_COST[R.FLOOR]])[chamber] + R.RAY_COST
    return [weight[j0:j1].sum() for j0, j1 in bounds]


@pytest.mark.parametrize("scene", [Scene(), Scene(sphere_b=False), Scene(floor=False),
                                   Scene(center_b=(-0.6, -0.7, 1.2))])
@pytest.mark.parametrize("gradient", ["exact", "central"])
def test_one_tile_per_worker_splits_the_cost_not_the_rows(scene, gradient):
    size = (256, 256)
    a_cost = R.SPHERE_A_COST[gradient]
    bounds = R._tile_bounds(scene, *size, 1.0, 2, a_cost)
    top, bottom = _tile_costs(scene, bounds, size, a_cost)
    assert abs(top - bottom) < 0.03 * (top + bottom)
    # The even split of the rows is what the balance replaces: off by more.
    top, bottom = _tile_costs(scene, [(0, 128), (128, 256)], size, a_cost)
    assert abs(top - bottom) > 0.03 * (top + bottom)


def test_more_tiles_than_workers_are_equal_bands():
    assert R._tile_bounds(Scene(), 512, 512, 1.0, 2, 4.4) == [(0, 128), (128, 256), (256, 384), (384, 512)]


def test_row_cost_estimate_is_cached_by_geometry_and_read_only():
    R._ROW_COSTS.clear()
    scene = Scene()
    first = R._row_costs(scene, 256, 256, 1.0, 4.4)
    # Lights, field and eps are not read by the estimate: the same entry.
    assert R._row_costs(scene.replace(eps=1e-6, height_field="sine"), 256, 256, 1.0, 4.4) is first
    # Geometry, size, zoom and pipeline are: new entries, with other costs.
    for other in [(scene.replace(center_b=(-0.6, -0.7, 1.2)), 256, 256, 1.0, 4.4),
                  (scene.replace(sphere_b=False), 256, 256, 1.0, 4.4),
                  (scene, 256, 256, 2.0, 4.4), (scene, 256, 256, 1.0, 2.7)]:
        cum = R._row_costs(*other)
        assert cum is not first and not np.array_equal(cum, first)
    with pytest.raises(ValueError):
        first[0] = 0.0
    with pytest.raises(ValueError):
        first.flags.writeable = True
    R._ROW_COSTS.clear()
    assert np.array_equal(R._row_costs(scene, 256, 256, 1.0, 4.4), first)
