"""The kernel's skips change no bit, and the sweep's frames are `render`'s.

`renderer.kernel` skips work the outputs do not need (its docstring lists
the skips): an object that is off is not intersected; a shadow ray is traced
only where Ns . w > 0; at beta = 0 no gradient unless grad is an output, and
no crease flag unless kink is; `kernel.params` drops lights of zero colour.
``render(..., skip=False)`` is the reference path that does all of it.
Checked here, each against a wrong variant:

* over a grid of scenes x gradient methods x output flags, the two paths
  give the same bytes (image, chamber, kink, grad);
* the grid does exercise every skip: the kernel's own Python source
  (numba's ``py_func``), run interpreted with its steps and the field's code counted, skips on
  the grid's scenes and does the work with ``skip=False``;
* every frame of `sweep` is the bytes of a separate `render` call, and its
  census is `compare` of those renders;
* the number of threads changes no bit.
"""

from __future__ import annotations

import collections
import concurrent.futures
import dataclasses
import os
import subprocess
import sys

import numba
import numpy as np
import pytest

from renderer import GRADIENTS, PointLight, Scene, compare, fieldcode, kernel, render, sweep

SIZE = (40, 32)
LIGHT_1, LIGHT_2 = Scene().lights
DARK = PointLight((-2.0, 6.0, 9.0), (0.0, 0.0, 0.0))
SCENES = {
    "default": Scene(),
    "sphere B off": Scene(sphere_b=False),
    "floor off": Scene(floor=False),
    "B and floor off": Scene(sphere_b=False, floor=False, height_field="sine"),
    "zero-colour light": Scene(lights=(LIGHT_1, DARK, LIGHT_2)),
    "beta 0": Scene(beta=0.0),
    # The gradient skipped only at beta = 0 exactly: a skip at beta <= 1e-10 changed 1e-12's image by 2e-11.
    "beta 1e-12": Scene(beta=1e-12, height_field="sine"),
    "beta 0, sine, phong": Scene(beta=0.0, height_field="sine", model="phong"),
    # Lights behind sphere A and below the floor: attached shadows and the floor plane.
    "lights behind": Scene(lights=(PointLight((0.5, -1.0, -6.0)), PointLight((3.0, -2.0, -4.0), (0.5, 0.6, 0.7)))),
    # A strong bump turns many N' away from lights the geometric normal faces.
    "strong bump": Scene(height_field="sine", beta=1.5, bump="chart"),
    "surface bump, phong": Scene(height_field="sine", bump="surface", beta=0.6, model="phong"),
    "rings, eps 0.05": Scene(height_field="rings", eps=0.05),
}
FLAGS = ((True, True), (False, False), (True, False), (False, True))


def differences(a, b):
    """Names of the outputs of two frames that differ in any byte (None must match None)."""
    out = []
    for name in ("image", "chamber", "kink", "grad"):
        x, y = getattr(a, name), getattr(b, name)
        if (x is None) != (y is None):
            out.append(name)
        elif x is not None and (x.dtype, x.shape, x.tobytes()) != (y.dtype, y.shape, y.tobytes()):
            out.append(name)
    return out


@pytest.mark.parametrize("gradient", GRADIENTS)
@pytest.mark.parametrize("name", sorted(SCENES))
def test_skipping_path_gives_the_reference_paths_bytes(name, gradient):
    scene = SCENES[name]
    images = []
    for kink, grad in FLAGS:
        fast = render(scene, *SIZE, gradient=gradient, kink=kink, grad=grad)
        full = render(scene, *SIZE, gradient=gradient, kink=kink, grad=grad, skip=False)
        assert differences(fast, full) == [], (kink, grad)
        assert (fast.kink is None, fast.grad is None) == (not kink, not grad)
        images.append(fast.image.tobytes())
    assert len(set(images)) == 1                           # the flags change no pixel


def _dropping_a_lit_light(real):
    """A wrong `kernel.params`: with skip, it drops the first light, which has colour."""
    def params(scene, skip=True):
        return real(scene.replace(lights=scene.lights[1:]) if skip else scene, skip)
    return params


def test_the_check_rejects_a_skip_that_drops_a_lit_light(monkeypatch):
    monkeypatch.setattr(kernel, "params", _dropping_a_lit_light(kernel.params))
    fast, full = render(Scene(), *SIZE), render(Scene(), *SIZE, skip=False)
    assert "image" in differences(fast, full)


def _changed(frame, name, index, value):
    array = getattr(frame, name).copy()
    array[index] = value
    return dataclasses.replace(frame, **{name: array})


def test_the_check_rejects_one_changed_bit():
    frame = render(Scene(), *SIZE)
    j, i = np.argwhere(frame.chamber == 1)[0]
    (bj, bi), = np.argwhere(frame.chamber != 1)[:1]         # grad is +0 off sphere A
    assert differences(frame, frame) == []
    assert differences(frame, _changed(frame, "image", (j, i, 0), np.nextafter(frame.image[j, i, 0], 2))) == ["image"]
    assert differences(frame, _changed(frame, "grad", (bj, bi, 0), -0.0)) == ["grad"]    # -0 == 0, not the same bits
    assert differences(frame, _changed(frame, "kink", (j, i), not frame.kink[j, i])) == ["kink"]
    assert differences(frame, dataclasses.replace(frame, grad=None)) == ["grad"]


# --- the grid exercises every skip --------------------------------------------------------

@pytest.fixture
def interpreted(monkeypatch):
    """Run `renderer.kernel` as plain Python: every compiled function of the
    module (its steps and the generated formulas it calls) replaced by its
    ``py_func``, with the arguments of every call recorded by name."""
    calls = collections.defaultdict(list)

    def counted(name, fn):
        def step(*args):
            calls[name].append(args)
            return fn(*args)
        return step

    for name, obj in list(vars(kernel).items()):
        if isinstance(obj, numba.core.dispatcher.Dispatcher):
            monkeypatch.setattr(kernel, name, counted(name, obj.py_func))
    rows = kernel.render_rows

    def render_rows(*args):                    # the field's code (cfuncs the kernel calls) counted too
        field = fieldcode.FieldCode(*(counted(f"field.{n}", f) for n, f in args[-1]._asdict().items()))
        return rows(*args[:-1], field)
    monkeypatch.setattr(kernel, "render_rows", render_rows)
    assert {"render_rows", "sphere_hit", "segment_blocked", "gradient", "footprint"} <= set(vars(kernel)) \
        and calls == {}
    return calls


def _work(calls, scene):
    """Counts of the work each skip avoids, from the recorded calls."""
    b = (*scene.center_b, scene.radius_b)
    dark = {tuple(l.position) for l in scene.lights if not any(l.color)}
    return dict(
        b_rays=sum(tuple(a[-4:]) == b for a in calls["sphere_hit"]),
        b_blocks=sum(tuple(a[-4:]) == b for a in calls["segment_blocked"]),
        shadow_rays=len(calls["segment_blocked"]),
        dark_rays=sum(tuple(a[4]) in dark for a in calls["segment_blocked"]),
        gradients=len(calls["gradient"]),
        creases=len(calls["gradient"]) + len(calls["field.kink"]),
    )


def run(interpreted, scene, **kw):
    interpreted.clear()
    frame = render(scene, 16, 12, **kw)
    return _work(interpreted, scene), frame


@pytest.mark.parametrize("name, counter, flags", [
    ("sphere B off", "b_rays", {}), ("sphere B off", "b_blocks", {}),
    ("B and floor off", "b_rays", {}),
    ("zero-colour light", "dark_rays", {}),
    ("beta 0", "gradients", dict(grad=False)),
    ("beta 0", "creases", dict(grad=False, kink=False)),
    ("beta 0, sine, phong", "creases", dict(grad=False, kink=False, gradient="footprint")),
])
def test_the_skip_does_none_of_the_work_the_reference_path_does(interpreted, name, counter, flags):
    scene = SCENES[name]
    fast, _ = run(interpreted, scene, **flags)
    full, _ = run(interpreted, scene, skip=False, **flags)
    assert fast[counter] == 0 < full[counter]


@pytest.mark.parametrize("name", ["strong bump", "surface bump, phong"])
def test_shadow_rays_are_traced_only_where_the_light_can_add_light(interpreted, name):
    fast, _ = run(interpreted, SCENES[name])
    full, _ = run(interpreted, SCENES[name], skip=False)
    assert 0 < fast["shadow_rays"] < full["shadow_rays"]


@pytest.mark.parametrize("name", ["strong bump", "surface bump, phong"])
def test_a_sweep_traces_each_shadow_ray_at_most_once_per_pixel(interpreted, name):
    """A sweep's frames share each pixel's shadow rays: six frames trace no more of them than
    one ungated render (which traces every light the normal faces, once), and more than none."""
    scene = SCENES[name]
    full, _ = run(interpreted, scene, skip=False)
    interpreted.clear()
    sweep(scene, (1e-1, 1e-2, 1e-3, 1e-5, 1e-8), 16, 12)
    swept = _work(interpreted, scene)
    assert 0 < swept["shadow_rays"] <= full["shadow_rays"]


def test_zero_colour_lights_are_dropped_from_the_kernels_lights():
    scene = SCENES["zero-colour light"]

    def lights(skip):
        return [(*light.position, *light.color) for light in kernel.params(scene, skip)[1]]

    assert lights(True) == [(*l.position, *l.color) for l in (LIGHT_1, LIGHT_2)]
    assert len(lights(False)) == 3


def test_gradient_and_crease_work_is_done_when_asked(interpreted):
    """The counters see work when the outputs need it, so a zero above means a skip."""
    scene = SCENES["beta 0"]
    asked, frame = run(interpreted, scene)
    a = int(np.count_nonzero(frame.chamber == 1))
    assert asked["gradients"] == a > 0
    only_kink, _ = run(interpreted, scene, grad=False)
    assert only_kink["creases"] == a and only_kink["gradients"] == 0


def test_the_counters_see_a_skip_that_is_not_taken(interpreted, monkeypatch):
    """The same counters reject a kernel told never to skip (every call gets skip=False)."""
    real = kernel.render_rows
    monkeypatch.setattr(kernel, "render_rows", lambda *a: real(*_never_skip(a)))
    work, _ = run(interpreted, SCENES["sphere B off"])
    assert work["b_rays"] > 0


def _never_skip(args):
    """render_rows' arguments with its job's ``skip`` False."""
    return [a._replace(skip=False) if isinstance(a, kernel.Job) else a for a in args]


# --- the sweep's frames are separate renders -----------------------------------------------

STEPS = (1e-1, 1e-3, 1e-6, 1e-10, 1e-16, 0.25)


def ledger_bytes(led):
    return np.array(dataclasses.astuple(led), dtype=np.float64).tobytes()


def sweep_differences(scene, sw, size=SIZE, zoom=1.0):
    """What differs between a sweep and separate renders of the same frames (at ``zoom``)."""
    bad = []
    exact = render(scene, *size, zoom=zoom)
    if differences(sw.symbolic, exact) or (sw.symbolic.scene, sw.symbolic.gradient) != (scene, "exact"):
        bad.append("symbolic")
    for i, (eps, frame, led) in enumerate(zip(sw.eps, sw.numeric, sw.census)):
        alone = render(scene.replace(eps=eps), *size, gradient="central", zoom=zoom)
        if differences(frame, alone) or (frame.scene, frame.gradient) != (alone.scene, "central"):
            bad.append(f"numeric[{i}]")
        if ledger_bytes(led) != ledger_bytes(compare(alone, exact)):
            bad.append(f"census[{i}]")
    return bad


@pytest.mark.parametrize("name", sorted(SCENES))
def test_sweep_frames_are_separate_renders(name):
    scene = SCENES[name]
    sw = sweep(scene, STEPS, *SIZE)
    assert sw.eps == STEPS and len(sw.numeric) == len(sw.census) == len(STEPS)
    assert sweep_differences(scene, sw) == []


def test_a_zoomed_sweep_is_separate_renders_at_that_zoom():
    """The sweep's image plane is the zoomed one (the pole at zoom 300, where the chart's frame
    changes branch): a sweep that drew the unzoomed plane differs from every zoomed render."""
    scene = Scene(beta=1.2, bump="chart")
    sw = sweep(scene, STEPS[:2], *SIZE, zoom=300.0)
    assert sweep_differences(scene, sw, zoom=300.0) == []
    assert sweep_differences(scene, sw) == ["symbolic", "numeric[0]", "census[0]", "numeric[1]", "census[1]"]


def test_the_sweep_check_rejects_a_frame_of_another_step_and_a_wrong_census():
    scene = Scene()
    sw = sweep(scene, (1e-3, 1e-1), *SIZE)
    other = render(scene.replace(eps=1.001e-3), *SIZE, gradient="central")
    wrong = dataclasses.replace(sw, numeric=(other, sw.numeric[1]))
    assert sweep_differences(scene, wrong) == ["numeric[0]"]
    swapped = dataclasses.replace(sw, census=sw.census[::-1])
    assert sweep_differences(scene, swapped) == ["census[0]", "census[1]"]
    moved = dataclasses.replace(sw, symbolic=_changed(sw.symbolic, "image", (20, 20, 1), 0.5))
    assert sweep_differences(scene, moved) == ["symbolic"]


@pytest.mark.parametrize("bad, match", [
    ((), "1 to 64"), ([1e-3, 0.0], r"eps_values\[1\]"), ([float("nan")], r"eps_values\[0\]"),
    ("1e-3", "sequence"), ([True], r"eps_values\[0\]"), ([1e-3] * 65, "1 to 64"),
    (np.array(1e-3), "^eps_values must be a sequence"),          # a 0-d array: numpy's "iteration over a 0-d array"
    pytest.param(10**5000, "^eps_values must be a sequence.* integer of", id="5001 digits"),  # its repr raised
])
def test_sweep_rejects_bad_steps(bad, match):
    with pytest.raises((TypeError, ValueError), match=match):
        sweep(Scene(), bad, 8, 8)


# --- threads ------------------------------------------------------------------------------

@pytest.mark.parametrize("gradient", GRADIENTS)
def test_the_number_of_threads_changes_no_bit(gradient):
    from renderer.render import THREAD_PIXELS
    scene, size = Scene(beta=1.2, bump="chart"), (96, 3 * THREAD_PIXELS // 96 + 1)     # room for 3 threads
    one = render(scene, *size, gradient=gradient, workers=1)
    for workers in (None, 2, 3):
        assert differences(one, render(scene, *size, gradient=gradient, workers=workers)) == [], workers
    a, b = sweep(scene, (1e-2, 1e-6), *size, workers=1), sweep(scene, (1e-2, 1e-6), *size)
    assert all(differences(x, y) == [] for x, y in zip(a.numeric + (a.symbolic,), b.numeric + (b.symbolic,)))
    assert [ledger_bytes(x) for x in a.census] == [ledger_bytes(x) for x in b.census]


@pytest.mark.parametrize("bad, error", [(0, ValueError), (-1, ValueError), (65, ValueError),
                                        (1.5, TypeError), (True, TypeError), ("2", TypeError)])
def test_bad_workers_are_refused(bad, error):
    with pytest.raises(error, match="workers"):
        render(Scene(), 8, 8, workers=bad)
    with pytest.raises(error, match="workers"):
        sweep(Scene(), (1e-3,), 8, 8, workers=bad)


@pytest.mark.parametrize("value", ["100000", "0", "abc"])
def test_a_thread_count_numba_cannot_launch_is_refused_in_one_line(tmp_path, value):
    """NUMBA_NUM_THREADS=100000 segfaulted numba's thread pool, 0 failed numba's import (exit 1,
    "internal error") and "abc" printed numba's warning with a traceback: the command line says
    in one line the variable, the value and the range, exit 2, nothing written; the library's
    render refuses the count numba read before any thread is launched.  In child processes."""
    from renderer.validate import MAX_THREADS
    env, out = {**os.environ, "NUMBA_NUM_THREADS": value}, tmp_path / "x.png"
    cli = subprocess.run([sys.executable, "-m", "renderer.cli", "render", "--size", "4x4", "-o", str(out)],
                         env=env, capture_output=True, text=True, timeout=300)
    assert (cli.returncode, len(cli.stderr.splitlines())) == (2, 1), cli
    assert f"NUMBA_NUM_THREADS must be an integer in [1, {MAX_THREADS}]" in cli.stderr and repr(value) in cli.stderr
    assert not out.exists()
    if value == "100000":
        code = "from renderer import Scene, render\nrender(Scene(), 4, 4)"
        library = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
        assert library.returncode == 1 and library.stderr.splitlines()[-1].startswith(
            "renderer.validate.InvalidValue: NUMBA_NUM_THREADS must be an integer in [1, "), library


def test_renders_from_several_threads_at_once_give_the_serial_bits():
    """Four Python threads render at once (each call runs its own pool of threads in the
    kernel, which releases the GIL); each frame is the serial frame, bit for bit."""
    scenes = [Scene(beta=b, bump="chart") for b in (0.0, 0.35, 1.2, 3.0)]
    serial = [render(s, 40, 32) for s in scenes]
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        for _ in range(3):
            frames = list(pool.map(lambda s: render(s, 40, 32), scenes))
            assert all(differences(a, b) == [] for a, b in zip(serial, frames))


_FORK = r"""
import os, sys
from renderer import Scene, render
from renderer.render import THREAD_PIXELS
assert 128 * 128 >= 2 * THREAD_PIXELS   # two threads render it
parent = render(Scene(), 128, 128, workers=2).image.tobytes()
pid = os.fork()
if pid == 0:                            # the child renders too, after the parent's threads ran
    os._exit(0 if render(Scene(), 128, 128, workers=2).image.tobytes() == parent else 3)
_, status = os.waitpid(pid, 0)
sys.exit(os.waitstatus_to_exitcode(status))
"""


def test_a_forked_child_renders_after_its_parent():
    """A child forked after a render renders too: it makes its own rendering threads (the
    parent's pool would leave it waiting on threads it does not have; numba's GNU OpenMP
    layer, used by an earlier kernel, killed such a child)."""
    run = subprocess.run([sys.executable, "-c", _FORK], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr[-2000:]


@pytest.mark.parametrize("workers", [1, 2])
@pytest.mark.parametrize("call", ["render", "sweep"])
def test_a_ctrl_c_stops_a_large_frame_within_one_band(monkeypatch, call, workers):
    """The compiled kernel cannot be interrupted: a frame is rendered in bands of rows, and a
    Ctrl-C raised during one band stops every thread before its next (17k lights at 512^2 ran
    for minutes before; the lights are capped too).  Each band here lasts at least 0.3 s, so
    the interrupt is seen before any thread finishes its band."""
    import signal
    import threading
    import time

    from renderer.render import bands
    real, calls, lock = kernel.render_rows, [], threading.Lock()
    n = min(workers, numba.config.NUMBA_NUM_THREADS)       # threads: at most numba's count
    signal_at = 2 if n == 1 else n          # serial: in the second band; else in each thread's first

    def band(*args):
        with lock:
            calls.append(args[4:7])
            last = len(calls) == signal_at
        real(*args)
        if last:
            os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.3)
    monkeypatch.setattr(kernel, "render_rows", band)

    def interrupt(signum, frame):
        raise KeyboardInterrupt
    previous = signal.signal(signal.SIGINT, interrupt)
    try:
        with pytest.raises(KeyboardInterrupt):
            render(Scene(), 512, 512, workers=workers) if call == "render" else \
                sweep(Scene(), (1e-3,), 512, 512, workers=workers)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert bands(512, 512) == [(0, 128), (128, 256), (256, 384), (384, 512)]
    first = [(0, 128, 1), (128, 256, 1)] if n == 1 else [(t, 128, n) for t in range(n)]
    assert sorted(calls) == first


def test_bands_cover_every_row_once():
    from renderer.render import BAND_PIXELS, bands
    for height, width in [(1, 1), (7, 8192), (8192, 7), (300, 256), (4096, 4096)]:
        b = bands(height, width)
        assert [r for first, last in b for r in range(first, last)] == list(range(height))
        assert all(last - first == max(1, BAND_PIXELS // width) for first, last in b[:-1])


def test_a_scene_holds_at_most_sixteen_lights():
    light = PointLight(position=(1.0, 2.0, 3.0))
    assert len(Scene(lights=(light,) * 16).lights) == 16
    with pytest.raises(ValueError, match=r"^Scene.lights holds at most 16 lights, got 17,000$"):
        Scene(lights=[light] * 17_000)
