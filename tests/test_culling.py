"""The renderer's culling boxes (`renderer.geometry.projected_bounds`).

A sphere is intersected only by the rays whose image-plane point lies in the
box of its projection from the eye, and a floor point is tested against a
blocker only if it lies in the box of the blocker's shadow from the light.
Both are sound only if no ray or shadow ray outside the box meets the sphere
*in floating point*: checked here on random spheres, apexes and points, and
on random scenes rendered with and without the culling (bit for bit).  A box
shrunk by 2 % fails the same check, so the check can fail.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from renderer import PointLight, Scene, render
from renderer.geometry import projected_bounds, segment_hits_sphere, sphere_hit

R = importlib.import_module("renderer.render")

coord = st.floats(-3.0, 3.0, allow_nan=False)
radius = st.floats(0.05, 1.5, allow_nan=False)
apex_z = st.floats(0.5, 12.0, allow_nan=False)
seed = st.integers(0, 2**32 - 1)


def inside(box, x, y):
    return (x >= box[0]) & (x <= box[1]) & (y >= box[2]) & (y <= box[3])


def shrunk(box, f=0.02):
    cx, cy = (box[0] + box[1]) / 2, (box[2] + box[3]) / 2
    hx, hy = (box[1] - box[0]) / 2 * (1 - f), (box[3] - box[2]) / 2 * (1 - f)
    return cx - hx, cx + hx, cy - hy, cy + hy


def plane_points(box, rng, n=20000):
    """Points around the box and close to its edges, where a wrong box fails."""
    w, h = box[1] - box[0], box[3] - box[2]
    x = rng.uniform(box[0] - 0.3 * w, box[1] + 0.3 * w, n)
    y = rng.uniform(box[2] - 0.3 * h, box[3] + 0.3 * h, n)
    return x, y


def eye_hits(e, center, r, x, y):
    return np.isfinite(sphere_hit(x, y, e, center, r))


def light_blocks(L, center, r, x, y):
    wx, wy, wz = L[0] - x, L[1] - y, L[2] - np.zeros_like(x)
    return segment_hits_sphere(wx, wy, wz, wx * wx + wy * wy + wz * wz, L, center, r)


@settings(max_examples=150, deadline=None)
@given(cx=coord, cy=coord, cz=st.floats(-2.0, 3.0), r=radius, e=apex_z, s=seed)
def test_every_ray_that_meets_a_sphere_is_in_its_box(cx, cy, cz, r, e, s):
    center = (cx, cy, cz)
    box = projected_bounds((0.0, 0.0, e), center, r)
    if box is None:
        assert e - cz <= r * (1 + 1e-12)
        return
    x, y = plane_points(box, np.random.default_rng(s))
    hit = eye_hits(e, center, r, x, y)
    assert not (hit & ~inside(box, x, y)).any()


@settings(max_examples=150, deadline=None)
@given(lx=coord, ly=coord, cx=coord, cy=coord, cz=st.floats(0.0, 3.0), r=radius, lz=apex_z, s=seed)
def test_every_floor_point_a_sphere_shadows_is_in_its_shadow_box(lx, ly, cx, cy, cz, r, lz, s):
    L, center = (lx, ly, lz), (cx, cy, cz)
    box = projected_bounds(L, center, r)
    if box is None:
        return
    x, y = plane_points(box, np.random.default_rng(s))
    blocked = light_blocks(L, center, r, x, y)
    assert not (blocked & ~inside(box, x, y)).any()


def test_the_check_rejects_a_box_two_percent_too_small():
    rng = np.random.default_rng(0)
    e, center, r = 4.0, (0.5, 0.5, 1.3), 0.32
    box = shrunk(projected_bounds((0.0, 0.0, e), center, r))
    x, y = plane_points(box, rng)
    assert (eye_hits(e, center, r, x, y) & ~inside(box, x, y)).any()
    L = (5.0, 5.0, 10.0)
    box = shrunk(projected_bounds(L, center, r))
    x, y = plane_points(box, rng)
    assert (light_blocks(L, center, r, x, y) & ~inside(box, x, y)).any()


@pytest.mark.parametrize("radius", [0.0, -0.5, float("nan"), float("inf")])
def test_bad_radius_is_refused(radius):
    with pytest.raises(ValueError, match="radius"):
        projected_bounds((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), radius)


def test_no_box_when_the_sphere_reaches_the_apex_plane():
    assert projected_bounds((0.0, 0.0, 4.0), (0.0, 0.0, 3.5), 0.5) is None   # touches z = 4
    assert projected_bounds((0.0, 0.0, 4.0), (0.0, 0.0, 5.0), 0.5) is None   # above the apex
    assert projected_bounds((0.0, 0.0, 4.0), (0.0, 0.0, 3.0), 0.5) is not None


@st.composite
def scenes(draw):
    rb = draw(st.floats(0.05, 0.8))
    cb = (draw(st.floats(-2.0, 2.0)), draw(st.floats(-2.0, 2.0)), draw(st.floats(-0.5, 2.5)))
    lights = tuple(PointLight((draw(st.floats(-8, 8)), draw(st.floats(-8, 8)), draw(st.floats(-3, 12))),
                              (1.0, draw(st.floats(0, 1)), 0.5))
                   for _ in range(draw(st.integers(1, 3))))
    kw = dict(center_b=cb, radius_b=rb, lights=lights, camera_z=draw(st.floats(2.5, 8.0)),
              height_field=draw(st.sampled_from(["sine", "ridges", "rings"])),
              beta=draw(st.sampled_from([0.0, 0.35, 1.5])), model=draw(st.sampled_from(["blinn", "phong"])))
    try:
        return Scene(**kw)
    except ValueError:               # e.g. the camera inside sphere B
        return Scene()


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=scenes(), gradient=st.sampled_from(["exact", "central"]))
def test_random_scenes_render_the_same_bits_with_and_without_culling(scene, gradient):
    fast = render(scene, 41, 33, gradient=gradient)
    ref = render(scene, 41, 33, gradient=gradient, skip=False)
    assert np.array_equal(fast.image, ref.image) and np.array_equal(fast.chamber, ref.chamber)


def test_culling_really_skips_rays_and_shadow_rays(monkeypatch):
    hits = {"n": 0}
    shadows = {"n": 0}
    real_hit, real_seg = R.sphere_hit, R.segment_hits_sphere

    def counting_hit(x, y, *a):
        hits["n"] += np.broadcast(x, y).size
        return real_hit(x, y, *a)

    def counting_seg(wx, *a):
        shadows["n"] += wx.size
        return real_seg(wx, *a)

    monkeypatch.setattr(R, "sphere_hit", counting_hit)
    monkeypatch.setattr(R, "segment_hits_sphere", counting_seg)
    scene, size = Scene(), (96, 80)
    fast = render(scene, *size)
    culled = hits["n"], shadows["n"]
    hits["n"] = shadows["n"] = 0
    monkeypatch.setattr(R, "projected_bounds", lambda *a: None)       # culling off
    full = render(scene, *size)
    assert np.array_equal(fast.image, full.image)
    pixels = size[0] * size[1]
    assert hits["n"] == 2 * pixels and culled[0] < 0.75 * hits["n"]
    assert culled[1] < 0.75 * shadows["n"]
