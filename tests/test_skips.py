"""Each skip of the renderer is output-identical, bit for bit, to the path that
does not skip, and each skip really skips: instrumentation
counts the work, and the same counters show the reference path doing it.
"""

from __future__ import annotations

import numpy as np
import pytest

import importlib
import threading

from renderer import PointLight, Scene, fields, render, sweep

#: The module renderer.render (the package re-exports the function under that name).
R = importlib.import_module("renderer.render")

SIZE = (48, 40)
SCENES = {
    "default": Scene(),
    "sine-phong": Scene(height_field="sine", model="phong", eps=1e-6),
    "rings-noB": Scene(height_field="rings", sphere_b=False),
    "nofloor": Scene(floor=False),
    "noB-nofloor-beta0": Scene(sphere_b=False, floor=False, beta=0.0),
    "zero-light": Scene(lights=(PointLight((5.0, 5.0, 10.0), (1.0, 1.0, 1.0)),
                                PointLight((-6.0, 2.0, 8.0), (0.0, 0.0, 0.0)),
                                PointLight((0.0, 3.0, -2.0), (0.4, 0.4, 0.4)))),
    "surface-bump": Scene(height_field="sine", bump="surface", beta=0.5),
}


def _same(a, b):
    for name in ("image", "chamber", "kink", "grad"):
        x, y = getattr(a, name), getattr(b, name)
        if x is None or y is None:
            continue
        if not np.array_equal(x, y):
            return False
    return True


@pytest.mark.parametrize("name", sorted(SCENES))
@pytest.mark.parametrize("gradient", ["exact", "central"])
def test_skipping_path_equals_reference_path(name, gradient):
    scene = SCENES[name]
    fast = render(scene, *SIZE, gradient=gradient)
    ref = render(scene, *SIZE, gradient=gradient, skip=False)
    assert _same(fast, ref)
    lean = render(scene, *SIZE, gradient=gradient, kink=False, grad=False)
    assert lean.kink is None and lean.grad is None
    assert np.array_equal(lean.image, ref.image) and np.array_equal(lean.chamber, ref.chamber)


def test_the_identity_check_rejects_a_different_image():
    a = render(SCENES["default"], *SIZE)
    b = render(SCENES["default"].replace(eps=2e-3), *SIZE, gradient="central")
    c = render(SCENES["default"], *SIZE, gradient="central")
    assert _same(a, a) and not _same(a, c) and not _same(b, c)


class Counter:
    """Wrap a function; record the arguments' sizes and the positions/centres passed."""

    def __init__(self, fn, key=None, points_arg=0):
        self.fn, self.key, self.calls, self.points, self.keys = fn, key, 0, 0, []
        self.points_arg = points_arg
        self.lock = threading.Lock()          # tiles render on several threads

    def __call__(self, *args, **kwargs):
        with self.lock:
            self.calls += 1
            self.points += int(np.size(args[self.points_arg]))
            if self.key is not None:
                self.keys.append(self.key(*args))
        return self.fn(*args, **kwargs)


@pytest.fixture
def count(monkeypatch):
    def install(module, name, key=None, points_arg=0):
        c = Counter(getattr(module, name), key, points_arg)
        monkeypatch.setattr(module, name, c)
        return c
    return install


def test_objects_that_are_off_are_neither_intersected_nor_blockers(count):
    scene = SCENES["noB-nofloor-beta0"].replace(beta=0.35)
    hits = count(R, "sphere_hit", key=lambda x, y, e, center, r: tuple(center))
    shadows = count(R, "segment_hits_sphere", key=lambda *a: tuple(a[5]))
    render(scene, *SIZE)
    assert tuple(scene.center_b) not in hits.keys + shadows.keys
    render(scene, *SIZE, skip=False)              # the reference path does the work
    assert tuple(scene.center_b) in hits.keys and tuple(scene.center_b) in shadows.keys


def test_zero_colour_lights_are_skipped(count):
    scene = SCENES["zero-light"]
    dark = scene.lights[1].position
    shadows = count(R, "segment_hits_sphere", key=lambda *a: tuple(a[4]))
    render(scene, *SIZE)
    assert dark not in shadows.keys
    render(scene, *SIZE, skip=False)
    assert dark in shadows.keys


def test_shadow_rays_only_where_they_can_change_the_pixel(count):
    scene = Scene(height_field="sine", beta=1.5)       # strong bump: many N' facing away
    shadows = count(R, "segment_hits_sphere")
    fast = render(scene, *SIZE)
    traced_fast = shadows.points
    shadows.points = 0
    ref = render(scene, *SIZE, skip=False)
    assert traced_fast < shadows.points and _same(fast, ref)


def test_beta_zero_computes_no_gradient(count):
    scene = SCENES["default"].replace(beta=0.0)
    exact = count(fields, "exact_gradient")
    central = count(R, "central_gradient")
    frame_ = count(R, "tangent_frame")
    a = render(scene, *SIZE, grad=False, kink=False)
    b = render(scene, *SIZE, gradient="central", grad=False, kink=False)
    assert exact.calls == central.calls == frame_.calls == 0
    assert np.array_equal(a.image, render(scene, *SIZE, skip=False).image)
    assert np.array_equal(b.image, render(scene, *SIZE, gradient="central", skip=False).image)
    render(scene, *SIZE)                              # asked for grad: computed
    assert exact.calls > 0


def test_kink_and_grad_only_when_asked(count):
    kinks = count(fields, "kink_band")
    render(SCENES["default"], *SIZE, kink=False)
    assert kinks.calls == 0
    render(SCENES["default"], *SIZE)
    assert kinks.calls > 0


def test_gradient_frame_and_normal_only_on_sphere_a(count):
    scene = SCENES["default"]
    exact = count(fields, "exact_gradient", points_arg=1)
    frame_ = count(R, "tangent_frame")
    f = render(scene, *SIZE)
    on_a = int(np.count_nonzero(f.chamber == R.SPHERE_A))
    assert exact.points == on_a and frame_.points == on_a


@pytest.mark.parametrize("name", ["default", "sine-phong", "rings-noB", "noB-nofloor-beta0", "zero-light"])
def test_sweep_equals_independent_renders(name):
    scene = SCENES[name]
    steps = (1e-1, 1e-3, 1e-6, 1e-10)
    sw = sweep(scene, steps, *SIZE)
    assert _same(sw.symbolic, render(scene, *SIZE))
    for eps, frame in zip(steps, sw.numeric):
        assert _same(frame, render(scene.replace(eps=eps), *SIZE, gradient="central"))
    assert all(led.flips == 0 for led in sw.census)


def test_sweep_shades_geometry_once(count):
    hits = count(R, "sphere_hit")
    sweep(SCENES["default"], (1e-1, 1e-2, 1e-3, 1e-4), *SIZE)
    once = hits.calls
    hits.calls = 0
    render(SCENES["default"], *SIZE, gradient="central")
    assert once == hits.calls                       # one render's worth, not four


@pytest.mark.parametrize("bad, match", [
    ((), "1 to 64"), ([1e-3, 0.0], r"eps_values\[1\]"), ([float("nan")], r"eps_values\[0\]"),
    ("1e-3", "sequence"), ([True], r"eps_values\[0\]"), ([1e-3] * 65, "1 to 64"),
])
def test_sweep_rejects_bad_steps(bad, match):
    with pytest.raises((TypeError, ValueError), match=match):
        sweep(Scene(), bad, 8, 8)


@pytest.mark.parametrize("workers", [2, 3])
def test_threads_give_the_same_bits(workers, monkeypatch):
    monkeypatch.setenv("SYMRENDER_WORKER_PROCESSES", "0")     # threads only (tests/test_workers.py)
    scene = SCENES["default"]
    big = (300, 240)                        # above MIN_SPLIT_PIXELS: one tile per thread
    assert big[0] * big[1] >= R.MIN_SPLIT_PIXELS
    assert _same(render(scene, *big, workers=1), render(scene, *big, workers=workers))
    a = sweep(scene, (1e-2, 1e-6), *big, workers=1)
    b = sweep(scene, (1e-2, 1e-6), *big, workers=workers)
    assert all(_same(x, y) for x, y in zip(a.numeric + (a.symbolic,), b.numeric + (b.symbolic,)))


@pytest.mark.parametrize("bad", [0, -1, 65, 1.5, True, "2"])
def test_bad_workers_are_refused(bad):
    with pytest.raises(ValueError, match="workers"):
        render(Scene(), 8, 8, workers=bad)


def test_sweep_reports_progress_per_tile_and_gives_the_same_bits():
    calls = []
    scene = SCENES["default"]
    a = sweep(scene, (1e-3, 1e-6), 300, 240, progress=lambda done, total: calls.append((done, total)))
    b = sweep(scene, (1e-3, 1e-6), 300, 240)
    assert len(calls) > 1 and calls[-1] == (300 * 240, 300 * 240)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
    assert all(_same(x, y) for x, y in zip(a.numeric, b.numeric))


def _power_bases():
    """Bases for the specular power check: random values in [0, 1], the
    specular range, with +0 and -0 scattered among them, every special value
    (+-inf, NaN of either sign, subnormals, huge, negative), shuffled."""
    rng = np.random.default_rng(7)
    special = [np.nan, -np.nan, np.inf, -np.inf, 5e-324, -5e-324, 1e-300, 1e300, 1.0, -1.0, -2.5]
    base = np.concatenate([rng.random(1000), np.zeros(300), -np.zeros(30), special,
                           rng.random(100) * 1e-12])
    return rng.permutation(base)


_POWER_BASES = _power_bases()


def _bits(x):
    return np.asarray(x, dtype=np.float64).view(np.uint64)


@pytest.mark.parametrize("exponent", [32.0, 0.5, 1.0, 2.0, 3.0, 7.5, 1e-3, 200.0])
def test_specular_power_skips_zero_bases_with_the_same_bits(exponent):
    # render._power calls pow only where the base is not +0 (libm's slow
    # path); -0, NaN, inf, subnormals and the rest give the bits of **.
    with np.errstate(all="ignore"):
        expected = _POWER_BASES ** exponent
        got = R._power(_POWER_BASES.copy(), exponent)
        strided = R._power(_POWER_BASES[::3], exponent)
    assert np.array_equal(_bits(got), _bits(expected))
    assert np.array_equal(_bits(strided), _bits(expected[::3]))


def test_the_power_check_sees_a_lost_negative_zero():
    # A variant that also skips -0 writes +0 where pow(-0, 3) is -0.
    def variant(base, exponent):
        out = np.zeros_like(base)
        np.power(base, exponent, out=out, where=base != 0.0)
        return out
    with np.errstate(all="ignore"):
        assert not np.array_equal(_bits(variant(_POWER_BASES, 3.0)), _bits(_POWER_BASES ** 3.0))
        assert np.array_equal(_bits(variant(_POWER_BASES, 32.0)), _bits(_POWER_BASES ** 32.0))
