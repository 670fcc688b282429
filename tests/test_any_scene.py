"""Every scene `Scene` accepts renders finite outputs in range: a property
over the whole accepted range of every field (hypothesis draws the ends of
each range often), for the three gradient methods.

What is checked where: the compiled kernel (`renderer.kernel`, numba with
``error_model="numpy"``) computes in IEEE arithmetic and signals nothing (no
numpy error state, no ZeroDivisionError), so for the pixels the property
rests on the outputs: the image finite and in [0, 1] (a NaN in the shading
sum survives the kernel's clamp, so it shows), the gradient finite, the
chamber a known code, the crease flag only on sphere A.  The numpy code
around the kernel (the window, the parameters, a sweep's ledger) runs under
``np.errstate(all="raise")`` with warnings turned into errors, so an
overflow there is an error.  The checker is shown to reject a frame with a
NaN, an out-of-range chamber and a stray crease flag.

Every normal the documentation calls unit is unit to 1e-12 at every accepted
scene: the G-buffer's N and N' (either bump mode, as the scene draws it) and
sphere A's tangent frame, which the kernel computes from N with
`renderer.generated.tangent_frame` (`renderer.pointwise.tangent_frame` is the
same compiled function).
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from renderer import BUMPS, GRADIENTS, MODELS, PointLight, Scene, gbuffer, pointwise, render, sweep
from renderer import formulas as F
from renderer import scene as S
from renderer.render import MAX_ZOOM

def _length(low=-S.MAX_LENGTH, high=S.MAX_LENGTH):
    return st.floats(low, high, allow_nan=False)


def _vec(elements):
    return st.tuples(elements, elements, elements)


@st.composite
def accepted_scenes(draw):
    """Any combination of field values inside the stated ranges; combinations
    that `Scene` refuses (camera inside a sphere, surface bump with beta >= R)
    are discarded."""
    intensity = st.floats(0.0, S.MAX_INTENSITY)
    radius = st.floats(S.MIN_RADIUS, S.MAX_LENGTH)
    kw = dict(
        radius_a=draw(st.one_of(st.just(1.0), radius)),
        camera_z=draw(st.one_of(st.just(4.0), _length(0.0))),
        center_b=draw(st.one_of(st.just((0.5, 0.5, 1.3)), _vec(_length()))),
        radius_b=draw(st.one_of(st.just(0.32), radius)),
        sphere_b=draw(st.booleans()),
        floor=draw(st.booleans()),
        lights=tuple(draw(st.lists(st.builds(PointLight, _vec(_length()), _vec(intensity)), max_size=3))),
        ambient=draw(_vec(intensity)),
        albedo_a=draw(_vec(st.floats(0.0, 1.0))),
        albedo_b=draw(_vec(st.floats(0.0, 1.0))),
        ka=draw(st.floats(0.0, 1.0)), kd=draw(st.floats(0.0, 1.0)), ks=draw(st.floats(0.0, 1.0)),
        shininess=draw(st.floats(S.MIN_SHININESS, S.MAX_SHININESS)),
        model=draw(st.sampled_from(MODELS)),
        floor_tint=draw(st.floats(0.0, 1.0)),
        height_field=draw(st.sampled_from(tuple(F.FIELDS))),
        k_u=draw(st.floats(0.0, S.MAX_FREQUENCY, exclude_min=True)),
        k_v=draw(st.floats(0.0, S.MAX_FREQUENCY, exclude_min=True)),
        beta=draw(st.floats(0.0, S.MAX_BETA)),
        eps=draw(st.floats(S.MIN_EPS, S.MAX_EPS)),
        bump=draw(st.sampled_from(BUMPS)),
    )
    try:
        return Scene(**kw)
    except ValueError:
        assume(False)


def check_frame(render_fn, scene, width, height, gradient, zoom):
    """Render under errstate(all="raise") with warnings as errors; return the
    frame after checking its outputs (see the module docstring)."""
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        frame = render_fn(scene, width, height, gradient=gradient, zoom=zoom)
    assert np.all(np.isfinite(frame.image)), "non-finite pixels"
    assert frame.image.min() >= 0.0 and frame.image.max() <= 1.0, "pixels outside [0, 1]"
    assert np.all(np.isfinite(frame.grad)), "non-finite gradient"
    assert np.all(np.isin(frame.chamber, (0, 1, 2, 3))), "unknown chamber code"
    assert not np.any(frame.kink & (frame.chamber != 1)), "crease flag off sphere A"
    assert not np.any(frame.grad[frame.chamber != 1]), "gradient off sphere A"
    return frame


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                    HealthCheck.filter_too_much])
@given(scene=accepted_scenes(), size=st.tuples(st.integers(1, 12), st.integers(1, 12)),
       gradient=st.sampled_from(GRADIENTS),
       zoom=st.one_of(st.just(1.0), st.floats(1.0, MAX_ZOOM)))
def test_every_accepted_scene_renders_finite_without_floating_point_errors(scene, size, gradient, zoom):
    check_frame(render, scene, *size, gradient, zoom)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.filter_too_much])
@given(scene=accepted_scenes(), steps=st.lists(st.floats(S.MIN_EPS, S.MAX_EPS), min_size=1, max_size=3))
def test_every_accepted_scene_sweeps_and_buffers_finite(scene, steps):
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        sw = sweep(scene, steps, 8, 6)
        buffers = [gbuffer(scene, 8, 6, gradient=gradient) for gradient in GRADIENTS]
    for frame in (sw.symbolic, *sw.numeric):
        assert np.all(np.isfinite(frame.image)) and frame.image.min() >= 0.0 and frame.image.max() <= 1.0
        assert np.all(np.isfinite(frame.grad))
    for g in buffers:
        hit = g.chamber > 0
        assert np.all(np.isfinite(g.Ns[hit])) and np.all(np.isfinite(g.P[hit])) and np.all(np.isfinite(g.uv))


UNIT_TOL = 1e-12


def unit_errors(g):
    """| |V| - 1 | at worst, per kind of unit vector of a G-buffer: N and N' on
    every hit, and sphere A's e_theta and e_phi (the kernel's frame of N)."""
    hit, on_a = g.chamber > 0, g.chamber == 1
    N = g.N[on_a]
    with np.errstate(divide="ignore", invalid="ignore"):     # 1 / sin(phi) at the pole, discarded
        e_theta, e_phi = (np.stack(e, -1) for e in pointwise.tangent_frame(*N.T, pointwise.chart(*N.T)[2]))
    vectors = dict(N=g.N[hit], Ns=g.Ns[hit], e_theta=e_theta, e_phi=e_phi)
    return {name: float(np.abs(np.linalg.norm(v, axis=-1) - 1.0).max(initial=0.0)) for name, v in vectors.items()}


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                    HealthCheck.filter_too_much])
@given(scene=accepted_scenes(), gradient=st.sampled_from(GRADIENTS),
       zoom=st.one_of(st.just(1.0), st.floats(1.0, MAX_ZOOM)))
# The tester's scene (N was not unit there while P_z = e (1 - t) cancelled).
@example(scene=Scene(radius_a=S.MIN_RADIUS, camera_z=S.MAX_LENGTH, bump="chart"), gradient="exact", zoom=1.0)
@example(scene=Scene(radius_a=S.MIN_RADIUS, camera_z=S.MAX_LENGTH, beta=S.MIN_RADIUS / 2, bump="surface"),
         gradient="central", zoom=1.0)
@example(scene=Scene(radius_a=S.MIN_RADIUS, camera_z=S.MAX_LENGTH, center_b=(0.0, 0.0, 1e5),
                     radius_b=S.MIN_RADIUS, bump="chart"), gradient="footprint", zoom=1.0)        # sphere B as small, far
@example(scene=Scene(radius_a=1.0, camera_z=1.0 + 2.0**-52), gradient="exact", zoom=S.MAX_LENGTH)
def test_every_accepted_scene_has_unit_normals(scene, gradient, zoom):
    errors = unit_errors(gbuffer(scene, 9, 7, gradient=gradient, zoom=zoom))
    assert max(errors.values()) <= UNIT_TOL, errors


def test_the_unit_check_rejects_a_normal_off_by_1e_11():
    g = gbuffer(Scene(), 9, 7)
    assert max(unit_errors(g).values()) <= UNIT_TOL
    j, i = np.argwhere(g.chamber == 1)[0]
    for name, change, caught in (("N", 1.0 + 1e-11, ("N", "e_phi")), ("Ns", 1.0 - 1e-11, ("Ns",))):
        wrong = getattr(g, name).copy()
        wrong[j, i] *= change
        errors = unit_errors(dataclasses.replace(g, **{name: wrong}))
        assert all(errors[k] > UNIT_TOL for k in caught), errors
    # A frame not divided by sin(phi): e_theta = (-N_y, N_x, 0).
    N = g.N[g.chamber == 1]
    assert np.abs(np.linalg.norm(np.stack([-N[:, 1], N[:, 0]], -1), axis=-1) - 1.0).max() > UNIT_TOL


def _corrupting(name, index, value):
    """A wrong renderer: the frame with one entry of one output replaced."""
    def render_fn(scene, width, height, **kw):
        frame = render(scene, width, height, **kw)
        getattr(frame, name)[index] = value
        return frame
    return render_fn


@pytest.mark.parametrize("name, index, value, message", [
    ("image", (0, 0, 0), np.nan, "non-finite pixels"),
    ("image", (1, 1, 2), 1.0 + 2**-52, r"outside \[0, 1\]"),
    ("grad", (2, 2, 1), np.inf, "non-finite gradient"),
    ("chamber", (3, 0), 4, "unknown chamber"),
    ("kink", (3, 0), True, "crease flag off sphere A"),      # (3, 0) is the floor at 4 x 4
])
def test_the_checker_rejects_a_wrong_output(name, index, value, message):
    assert render(Scene(), 4, 4).chamber[3, 0] != 1
    with pytest.raises(AssertionError, match=message):
        check_frame(_corrupting(name, index, value), Scene(), 4, 4, "exact", 1.0)


