"""lab.displaced: the displaced sphere A against the renderer's own functions."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from renderer import Scene, gbuffer, generated, kernel, pointwise
from renderer.render import image_plane
from lab import displaced as D
from lab.displaced import H_MAX, render_displaced

SIZE = 48
SINE = Scene(height_field="sine", bump="surface", beta=0.2)


#: The displaced frames' scenes, by field.
SCENES = {"sine": SINE, "ridges": Scene(bump="surface")}


@pytest.fixture(scope="module")
def displaced():
    return {name: render_displaced(scene, SIZE, SIZE) for name, scene in SCENES.items()}


def test_beta_zero_reproduces_the_undisplaced_render():
    # Same kernel shading on the same sphere: the hit point differs from the kernel's by a
    # few ulps, so 1e-12 (about 4500 ulps of a channel) bounds the image difference.
    d = render_displaced(Scene(beta=0.0), SIZE, SIZE)
    assert np.array_equal(d.chamber, d.bumped.chamber)
    assert np.abs(d.image - d.bumped.image).max() <= 1e-12
    assert (d.silhouette_changed, d.shadow_changed, d.self_shadowed) == (0, 0, 0)
    assert d.shadow.sum() > 0                      # sphere B and A cast shadows in this scene


@pytest.mark.parametrize("name", ["sine", "ridges"])
def test_the_hit_lies_on_the_displaced_surface(displaced, name):
    d = displaced[name]
    s = d.bumped.scene
    P = d.P[d.covered]
    r = np.linalg.norm(P, axis=1)
    u, v, _ = pointwise.chart(*(P / r[:, None]).T)
    h = pointwise.height(s.height_field, u, v, s.k_u, s.k_v)
    assert np.abs(r - s.radius_a - s.beta * h).max() <= 1e-12 * s.radius_a
    # Coverage lies between the silhouettes of the spheres R -+ beta max|h|.
    x, y = image_plane(s.radius_a, s.camera_z, SIZE, SIZE)
    hits = {sign: np.array([[kernel.sphere_hit(xi, yj, s.camera_z, 0.0, 0.0, 0.0, s.radius_a + sign * s.beta * H_MAX)
                             < np.inf for xi in x] for yj in y]) for sign in (-1, 1)}
    assert not (d.covered & ~hits[1]).any()
    assert not (hits[-1] & ~d.covered & (d.chamber != 2)).any()
    assert hits[1].sum() > d.covered.sum() > hits[-1].sum()


def test_normals_agree_with_the_surface_mode_normal(displaced):
    d, s = displaced["sine"], SINE
    # Interior of the coverage (all 8 neighbours covered), away from the poles' cut-off.
    c = np.pad(d.covered, 1)
    interior = np.logical_and.reduce([c[1 + a:c.shape[0] - 1 + a, 1 + b:c.shape[1] - 1 + b]
                                      for a in (-1, 0, 1) for b in (-1, 0, 1)])
    P = d.P[interior]
    r = np.linalg.norm(P, axis=1)
    N = P / r[:, None]
    u, v, sin_phi = pointwise.chart(*N.T)
    keep = sin_phi > 0.1
    N, u, v, sin_phi, r = N[keep], u[keep], v[keep], sin_phi[keep], r[keep]
    et, ep = pointwise.tangent_frame(*N.T, sin_phi)
    hu, hv = pointwise.exact_gradient("sine", u, v, s.k_u, s.k_v)
    h = pointwise.height("sine", u, v, s.k_u, s.k_v)
    out = np.empty((3, N.shape[0]))
    full = lambda x: np.full(N.shape[0], x)        # noqa: E731
    generated.perturbed_normal_surface_array(*N.T, *et, *ep, hu, hv, full(s.beta), h, full(s.radius_a), sin_phi,
                                             out)
    assert N.shape[0] > 500
    assert np.abs(d.normal[interior][keep] - out.T).max() <= 1e-9
    # The bumps tilt the normal: the comparison is not of two radial directions.
    assert np.abs(out.T - N).max() > 0.1


def test_the_self_shadowed_pixels_are_those_the_bumped_frame_lights_and_the_displaced_sphere_blocks(displaced):
    """self_shadowed counts the pixels on A in both frames where some light is blocked by the displaced A and
    lights the bumped frame: reached by the kernel's predicate and facing the bumped normal, Ns . w > 0, the
    gate here taken by hand."""
    for name, d in displaced.items():
        scene = SCENES[name]
        geo = gbuffer(scene, *d.covered.shape[::-1], gradient="exact")
        w = np.stack([np.asarray(light.position) for light in scene.lights])[:, None, None, :] - geo.P
        facing = np.einsum("hwc,khwc->khw", geo.Ns, w) > 0
        lit = pointwise.reach(scene, geo) & facing
        both = d.covered & (d.bumped.chamber == 1)
        assert d.self_shadowed == int(((d.blocked & lit).any(axis=0) & both).sum()) > 0
        assert d.blocked.shape == lit.shape and not d.blocked[:, ~d.covered & (d.chamber == 0)].any()


def test_displacement_moves_silhouette_and_shadows(displaced):
    for d in displaced.values():
        assert d.silhouette_changed > 0 and d.shadow_changed > 0 and d.self_shadowed > 0
        assert d.silhouette_changed == int((d.covered != (d.bumped.chamber == 1)).sum())
        # Newton converges in a few steps (measured mean 3.7, most 9); bisection alone takes about 40.
        assert 1 <= d.newton_max <= 60 and d.newton_mean < 6 and d.seconds > 0 and d.render_seconds > 0


@pytest.mark.parametrize("kwargs, words", [
    (dict(samples=0), "samples"), (dict(samples="8"), "samples"), (dict(samples=5000), "samples"),
    (dict(scene=Scene(bump="chart", beta=1.0)), "beta"), (dict(scene=Scene(beta=0.35, camera_z=1.2)), "camera_z"),
    (dict(scene="scene"), "scene"), (dict(width=0), "width")])
def test_bad_input_is_refused(kwargs, words):
    args = dict(scene=Scene(), width=8, height=8) | kwargs
    scene, width, height = args.pop("scene"), args.pop("width"), args.pop("height")
    with pytest.raises((TypeError, ValueError), match=words):
        render_displaced(scene, width, height, **args)


@settings(max_examples=20, deadline=None)
@given(p=st.floats(0.01, 0.99), q=st.floats(0.01, 0.99), width=st.floats(1e-8, 1e-6), a=st.floats(0.6, 5.0))
def test_a_field_past_h_max_anywhere_on_the_chart_is_refused_where_it_is(p, q, width, a):
    """The bracketing shells hold |h| <= `H_MAX`: a spike of h past it, narrower than the check's grid
    and wherever it stands, is refused naming a point of the spike where |h| is past it; the same spike
    under `H_MAX` is accepted."""
    spike = lambda height: f"0.5 + {height!r}*exp(-((u - {p!r})**2 + (v - {q!r})**2)/{width!r})"   # noqa: E731
    with pytest.raises(ValueError) as info:
        D._check_bounded(Scene(height_field=spike(a), bump="chart"))
    said = re.search(r"reaches \|h\| = (\S+) at \(u, v\) = \(([^,]+), ([^)]+)\)", str(info.value))
    assert said and float(said[1]) > H_MAX, info.value
    assert np.hypot(float(said[2]) - p, float(said[3]) - q) <= 3 * np.sqrt(width), (p, q, info.value)
    D._check_bounded(Scene(height_field=spike(0.4), bump="chart"))      # |h| <= 0.9 everywhere: no error
