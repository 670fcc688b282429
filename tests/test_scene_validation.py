"""Input validation of `Scene`, `PointLight` and `render`, the seed's defaults, and a
property test over valid scenes.

The contract: invalid input raises ValueError (TypeError for a wrong type) naming
the field, the value and what is accepted.  Each case below matches the
field's name at the start of the message ("Scene.<field>" or
"PointLight.<field>"), so an error that names another field does not pass.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from renderer import DRAFT_SCENE, GRADIENTS, PointLight, Scene, compare, gbuffer, render, sweep

NAN, INF = float("nan"), float("inf")

# The seed's SC9 dictionary (seed Cell 1), typed from the seed: it is the spec.
SC9 = dict(R=1.0, e=4.0, Cb=(0.5, 0.5, 1.3), R2=0.32, b_on=True, floor_on=True,
           lights=(((5., 5., 10.), (1., 1., 1.)),
                   ((-6., 2., 8.), (0.9, 0.65, 0.25))),
           ambient=(0.15, 0.15, 0.16), matA=(0.63, 0.19, 0.16), matB=(0.33, 0.44, 0.62),
           ka=0.1, kd=0.7, ks=0.5, shin=32.0, model='blinn',
           alpha=0.25, hf='ridges', ku=8.0, kv=4.0, beta=0.35, eps=1e-3)
# Scene field <- seed name (the `Scene` docstring gives both).
SEED_NAMES = dict(radius_a="R", camera_z="e", center_b="Cb", radius_b="R2", sphere_b="b_on",
                  floor="floor_on", ambient="ambient", albedo_a="matA", albedo_b="matB",
                  ka="ka", kd="kd", ks="ks", shininess="shin", model="model",
                  floor_tint="alpha", height_field="hf", k_u="ku", k_v="kv", beta="beta",
                  eps="eps")


def names(field):
    """Regex for a message that starts by naming ``field`` (optionally indexed)."""
    owner, _, name = field.rpartition(".")
    return rf"^{owner or 'Scene'}\.{re.escape(name)}(\[\d\])?\b"


# --- defaults --------------------------------------------------------------------------

def seed_mismatches(scene):
    """Fields of ``scene`` that differ from SC9 in value or type (sorted)."""
    bad = [f for f, seed in SEED_NAMES.items()
           if not (getattr(scene, f) == SC9[seed] and type(getattr(scene, f)) is type(SC9[seed]))]
    lights = tuple((light.position, light.color) for light in scene.lights)
    if lights != SC9["lights"]:
        bad.append("lights")
    return sorted(bad)


def test_defaults_are_the_seeds():
    assert seed_mismatches(Scene()) == []
    assert all(isinstance(light, PointLight) for light in Scene().lights)
    # The project's addition: the default perturbed normal is the displaced sphere's; the
    # draft's own scene, with its chart formula, is DRAFT_SCENE and differs in nothing else.
    assert Scene().bump == "surface"
    assert DRAFT_SCENE.bump == "chart" and DRAFT_SCENE.replace(bump="surface") == Scene()


def test_defaults_check_has_teeth():
    drifted = Scene(k_v=4.000001, lights=(PointLight(),), floor=False)
    assert seed_mismatches(drifted) == ["floor", "k_v", "lights"]
    assert seed_mismatches(Scene(k_u=8)) == []          # int 8 is stored as the float 8.0


# --- bad Scene fields -------------------------------------------------------------------

REAL_FIELDS = ("radius_a", "camera_z", "radius_b", "ka", "kd", "ks", "shininess",
               "floor_tint", "k_u", "k_v", "beta", "eps")
VECTOR_FIELDS = ("center_b", "ambient", "albedo_a", "albedo_b")

BAD = []
for f in REAL_FIELDS:
    BAD += [(f, NAN, ValueError), (f, INF, ValueError), (f, -INF, ValueError),
            (f, True, TypeError), (f, False, TypeError), (f, "1.0", TypeError),
            (f, None, TypeError), (f, 1j, TypeError), (f, (1.0,), TypeError),
            (f, np.float64(NAN), ValueError), (f, np.True_, TypeError), (f, np.array([1.0]), TypeError),
            (f, np.array(True), TypeError), (f, 10**400, ValueError)]
for f in VECTOR_FIELDS:
    BAD += [(f, (0.1, 0.2), ValueError), (f, (0.1, 0.2, 0.3, 0.4), ValueError),
            (f, (), ValueError), (f, "abc", TypeError), (f, 0.5, TypeError), (f, None, TypeError),
            (f, (0.1, NAN, 0.3), ValueError), (f, (0.1, 0.2, INF), ValueError),
            (f, (0.1, True, 0.3), TypeError), (f, (0.1, "0.2", 0.3), TypeError),
            (f, np.array([0.1, 0.2]), ValueError), (f, np.array(0.5), TypeError),
            (f, np.zeros((3, 1)), TypeError), (f, (0.1, np.True_, 0.3), TypeError)]
for f in ("sphere_b", "floor"):
    BAD += [(f, 1, TypeError), (f, 0, TypeError), (f, "yes", TypeError), (f, None, TypeError),
            (f, 1.0, TypeError)]
BAD += [
    # radii
    ("radius_a", 0.0, ValueError), ("radius_a", -1.0, ValueError),
    ("radius_b", 0.0, ValueError), ("radius_b", -0.32, ValueError),
    # camera inside or on sphere A
    ("camera_z", 1.0, ValueError), ("camera_z", 0.5, ValueError), ("camera_z", -4.0, ValueError),
    ("camera_z", 0.0, ValueError),
    # steps and amplitudes
    ("eps", 0.0, ValueError), ("eps", -1e-3, ValueError), ("eps", -0.0, ValueError),
    ("beta", -0.1, ValueError), ("beta", -5e-324, ValueError),
    ("ka", -0.1, ValueError), ("kd", -1e-9, ValueError), ("ks", -1.0, ValueError),
    ("shininess", 0.0, ValueError), ("shininess", -32.0, ValueError),
    ("k_u", 0.0, ValueError), ("k_u", -8.0, ValueError), ("k_v", 0.0, ValueError),
    # above the meaningful ranges (each stated in the message)
    ("eps", 1e300, ValueError), ("eps", 5e-324, ValueError), ("eps", 0.26, ValueError),
    ("eps", 9e-17, ValueError), ("kd", 1e308, ValueError), ("ks", 1e308, ValueError),
    ("ka", 1.01, ValueError), ("shininess", 1e20, ValueError), ("shininess", 0.5, ValueError),
    ("beta", 100.5, ValueError), ("k_u", 1001.0, ValueError), ("k_v", 1e6, ValueError),
    ("ambient", (1e308, 0.0, 0.0), ValueError),
    # colours and albedos
    ("ambient", (0.15, -0.01, 0.16), ValueError),
    ("albedo_a", (0.63, 1.01, 0.16), ValueError), ("albedo_a", (-0.1, 0.19, 0.16), ValueError),
    ("albedo_b", (0.33, 0.44, 1.5), ValueError), ("albedo_b", (0.33, -0.44, 0.62), ValueError),
    ("floor_tint", -0.01, ValueError), ("floor_tint", 1.01, ValueError),
    # names
    ("model", "Blinn", ValueError), ("model", "lambert", ValueError), ("model", "", ValueError),
    ("model", 3, TypeError), ("model", None, TypeError), ("model", ("blinn",), TypeError),
    ("height_field", "Sine", ValueError), ("height_field", "bumps", ValueError),
    ("height_field", "ridges ", ValueError), ("height_field", 1, TypeError),
    ("bump", "displacement", ValueError), ("bump", True, TypeError),
    # lights
    ("lights", PointLight(), TypeError), ("lights", "abc", TypeError), ("lights", None, TypeError),
    ("lights", (((5.0, 5.0, 10.0), (1.0, 1.0, 1.0)),), TypeError),
    ("lights", (PointLight(), "light"), TypeError), ("lights", [PointLight(), None], TypeError),
]


@pytest.mark.parametrize("field, value, error", BAD,
                         ids=[f"{f}={v!r}" for f, v, _ in BAD])
def test_bad_field_is_rejected_naming_it(field, value, error):
    with pytest.raises(error, match=names(field)):
        Scene(**{field: value})


@pytest.mark.parametrize("field, value, accepted", [
    ("eps", 1e300, "in [1e-16, 0.25]"), ("kd", 1e308, "in [0, 1]"),
    ("shininess", 1e20, "in [1, 10000]"), ("beta", 1e3, "in [0, 100]"), ("k_u", 0.0, "in (0, 1000]"),
])
def test_range_errors_state_the_accepted_range(field, value, accepted):
    with pytest.raises(ValueError, match=re.escape(f"Scene.{field} must be {accepted}, got {value!r}")):
        Scene(**{field: value})


@pytest.mark.parametrize("kwargs, error, field", [
    # camera inside or on sphere B: the message names radius_b and says "sphere B"
    (dict(radius_b=3.0), ValueError, "radius_b"),
    (dict(center_b=(0.0, 0.0, 3.5), radius_b=0.5), ValueError, "radius_b"),   # on: d = r
    (dict(center_b=(0.0, 0.0, 4.0)), ValueError, "radius_b"),                 # at the centre
    (dict(camera_z=1.5, center_b=(0.0, 0.0, 1.4)), ValueError, "radius_b"),
    # the displaced surface needs beta < radius_a
    (dict(bump="surface", beta=1.0), ValueError, "beta"),
    (dict(bump="surface", beta=2.0, radius_a=1.5, camera_z=4.0), ValueError, "beta"),
])
def test_bad_combination_is_rejected_naming_a_field(kwargs, error, field):
    with pytest.raises(error, match=names(field)) as info:
        Scene(**kwargs)
    if field == "radius_b":
        assert "sphere B" in str(info.value)


@pytest.mark.parametrize("field, value, error", [
    ("position", (1.0, 2.0), ValueError), ("position", (1.0, 2.0, 3.0, 4.0), ValueError),
    ("position", (NAN, 0.0, 1.0), ValueError), ("position", (0.0, INF, 1.0), ValueError),
    ("position", "abc", TypeError), ("position", 5.0, TypeError),
    ("position", (0.0, False, 1.0), TypeError),
    ("color", (1.0, -0.1, 1.0), ValueError), ("color", (1.0, 1.0, -INF), ValueError),
    ("color", (NAN, 1.0, 1.0), ValueError), ("color", "white", TypeError),
    ("color", (1.0, 1.0), ValueError), ("color", (1.0, True, 1.0), TypeError),
])
def test_bad_point_light_is_rejected_naming_the_field(field, value, error):
    with pytest.raises(error, match=names(f"PointLight.{field}")):
        PointLight(**{field: value})


# --- values at the edges of the accepted ranges are accepted (the checks are not too wide) ---

@pytest.mark.parametrize("kwargs", [
    dict(beta=0.0), dict(floor_tint=0.0), dict(floor_tint=1.0), dict(ka=0.0, kd=0.0, ks=0.0),
    dict(albedo_a=(1.0, 1.0, 1.0)), dict(albedo_b=(0.0, 0.0, 0.0)), dict(ambient=(0.0, 0.0, 0.0)),
    dict(eps=1e-16), dict(eps=0.25), dict(shininess=1.0), dict(shininess=1e4), dict(k_u=5e-324),
    dict(k_v=1e3), dict(beta=100.0, bump="chart"), dict(ka=1.0, kd=1.0, ks=1.0), dict(ambient=(1e3, 0.0, 1e3)),
    dict(lights=(PointLight((1e6, -1e6, 0.0), (1e3, 1e3, 0.0)),)),
    dict(camera_z=1.0 + 2**-52), dict(radius_a=1e-3, bump="chart"), dict(radius_b=1e-3),
    dict(center_b=np.array([0.5, 0.5, 1.3])), dict(center_b=[0.5, 0.5, 1.3]),
    dict(beta=np.float64(0.5)), dict(k_u=np.int64(3)), dict(k_v=7), dict(beta=np.float32(0.5)),
    dict(kd=np.array(0.5)), dict(floor=np.False_), dict(albedo_a=np.array([1, 0, 0])),
    dict(lights=()), dict(lights=[PointLight()]), dict(model="phong"),
    dict(height_field="sine"), dict(height_field="rings"), dict(bump="surface", beta=0.99),
    dict(sphere_b=False, floor=False),
])
def test_valid_edge_values_are_accepted(kwargs):
    scene = Scene(**kwargs)
    for key, value in kwargs.items():
        got = getattr(scene, key)
        if key == "lights":
            assert got == tuple(value)
        elif isinstance(value, (tuple, list)) or (isinstance(value, np.ndarray) and value.ndim):
            assert got == tuple(float(c) for c in value)
        else:
            assert got == value and not isinstance(got, np.generic)


# --- vectors: any other container is a wrong type -------------------------------------------

@pytest.mark.parametrize("value", [
    {0: 0.5, 1: 0.5, 2: 1.3},        # iterating a dict yields its keys 0, 1, 2
    {0.5, 1.3, 2.0},                 # a set has no order
])
def test_vector_field_rejects_unordered_containers(value):
    """A dict or set of three numbers is not a vector.  (Currently accepted: the dict
    {0: 0.5, 1: 0.5, 2: 1.3} becomes center_b = (0.0, 1.0, 2.0), silently.)"""
    with pytest.raises(TypeError, match=names("center_b")):
        Scene(center_b=value)


# --- finite inputs that validate must not raise something else ----------------------------

def scene_or_rejection(kwargs, field):
    """The Scene, or None if validation rejects it with a ValueError naming ``field``.

    Any other exception propagates (and fails the calling test)."""
    try:
        return Scene(**kwargs)
    except ValueError as exc:
        assert re.match(names(field), str(exc)), f"ValueError names another field: {exc}"
        return None


@pytest.mark.parametrize("kwargs, field", [
    (dict(camera_z=1e155), "camera_z"),
    (dict(radius_b=1e160), "radius_b"),
    (dict(center_b=(1e160, 0.0, 0.0)), "center_b"),
])
def test_huge_finite_values_raise_value_error_not_overflow(kwargs, field):
    """Invalid input raises ValueError naming the field.  (A finite value
    whose square overflows made Scene() raise OverflowError from `x ** 2`.)"""
    try:
        scene_or_rejection(kwargs, field)
    except ArithmeticError as exc:
        pytest.fail(f"Scene({kwargs}) raised {type(exc).__name__}: {exc}")


@pytest.mark.parametrize("kwargs, field", [
    (dict(radius_a=1e-300, camera_z=2e-300, sphere_b=False), "radius_a"),  # e^2 - R^2 underflows
    (dict(k_u=1e308), "k_u"),                                # pi k_u u overflows: sin(inf)
    (dict(beta=1e308), "beta"),
])
def test_a_scene_that_validates_renders_finite_outputs(kwargs, field):
    """Nothing returns NaN silently: a Scene is either rejected by
    validation, naming the field, or renders without an exception and with a
    finite image and gradient."""
    scene = scene_or_rejection(kwargs, field)
    if scene is None:
        return
    with np.errstate(all="ignore"):
        for gradient in GRADIENTS:
            frame = render(scene, 8, 8, gradient=gradient)
            bad = {name: int(np.count_nonzero(~np.isfinite(a)))
                   for name, a in (("image", frame.image), ("grad", frame.grad))}
            assert bad == {"image": 0, "grad": 0}, f"{gradient}: non-finite entries {bad}"


def test_contract_helper_has_teeth():
    """The helper lets a rejection pass only when it names the field."""
    assert scene_or_rejection(dict(beta=0.5), "beta").beta == 0.5
    assert scene_or_rejection(dict(beta=-1.0), "beta") is None
    with pytest.raises(AssertionError, match="names another field"):
        scene_or_rejection(dict(beta=-1.0), "k_u")


# --- render arguments and Scene.replace ----------------------------------------------------

@pytest.mark.parametrize("width, height, error, name", [
    (16.0, 16, TypeError, "width"), (16, 16.0, TypeError, "height"),
    ("16", 16, TypeError, "width"), (None, 16, TypeError, "width"),
    (True, 16, TypeError, "width"), (16, False, TypeError, "height"),
    (np.True_, 16, TypeError, "width"),
    (0, 16, ValueError, "width"), (16, 0, ValueError, "height"),
    (-1, 16, ValueError, "width"), (16, -16, ValueError, "height"),
    (8193, 1, ValueError, "width"), (1, 8193, ValueError, "height"),
    (10**20, 1, ValueError, "width"),
])
def test_render_rejects_bad_sizes(width, height, error, name):
    with pytest.raises(error, match=rf"^{name}\b"):
        render(Scene(), width, height)


@pytest.mark.parametrize("gradient", ["Exact", "symbolic", "numeric", "Footprint", "pbrt", ""])
def test_render_rejects_unknown_gradient(gradient):
    with pytest.raises(ValueError, match=r"^gradient must be one of \('exact', 'central', 'footprint'\)"):
        render(Scene(), 4, 4, gradient=gradient)
    with pytest.raises(ValueError, match=r"^gradient\b"):
        gbuffer(Scene(), 4, 4, gradient=gradient)


@pytest.mark.parametrize("gradient", [None, 1, ("exact",)])
def test_render_rejects_a_gradient_that_is_not_a_string(gradient):
    with pytest.raises(TypeError, match=r"^gradient must be one of \('exact', 'central', 'footprint'\), got "):
        render(Scene(), 4, 4, gradient=gradient)
    with pytest.raises(TypeError, match=r"^gradient\b"):
        gbuffer(Scene(), 4, 4, gradient=gradient)


@pytest.mark.parametrize("gradient", GRADIENTS)
def test_render_accepts_every_gradient_and_records_it(gradient):
    frame = render(Scene(), 4, 4, gradient=gradient)
    assert frame.gradient == gradient and gbuffer(Scene(), 4, 4, gradient=gradient).grad.shape == (4, 4, 2)


@pytest.mark.parametrize("workers", [0, -1, 65])
def test_render_rejects_a_thread_count_out_of_range_naming_it(workers):
    with pytest.raises(ValueError, match=r"^workers must be an integer in \[1, 64\], got -?[0-9]+$"):
        render(Scene(), 4, 4, workers=workers)


@pytest.mark.parametrize("workers", [1.5, True, "2", np.float64(2.0)])
def test_render_rejects_a_thread_count_that_is_not_an_integer(workers):
    with pytest.raises(TypeError, match=r"^workers must be a positive integer, got (float|bool|str|float64) "):
        render(Scene(), 4, 4, workers=workers)


@pytest.mark.parametrize("workers", [1, 64, np.int64(2), None])
def test_render_accepts_thread_counts_in_range(workers):
    assert render(Scene(), 4, 4, workers=workers).image.shape == (4, 4, 3)


def test_render_rejects_a_non_scene():
    with pytest.raises(TypeError, match=r"^scene\b"):
        render(dict(beta=0.35), 4, 4)


@pytest.mark.parametrize("width, height", [(1, 1), (8192, 1), (1, 8192), (np.int64(3), 2)])
def test_render_accepts_sizes_at_the_limits(width, height):
    frame = render(Scene(), width, height)
    assert frame.image.shape == (int(height), int(width), 3)


@pytest.mark.parametrize("changes, bad", [
    (dict(betaa=1.0), "betaa"), (dict(R=1.0), "R"), (dict(hf="sine"), "hf"),
    (dict(beta=0.5, light=()), "light"),
])
def test_replace_rejects_unknown_fields(changes, bad):
    with pytest.raises(TypeError, match=rf"no field\(s\) \[[^\]]*'{bad}'"):
        Scene().replace(**changes)


def test_replace_validates_and_keeps_the_rest():
    scene = Scene(bump="chart").replace(beta=1.5, height_field="sine")
    assert (scene.beta, scene.height_field, scene.k_u) == (1.5, "sine", 8.0)
    with pytest.raises(ValueError, match=names("beta")):
        Scene().replace(beta=-1.0)


# --- property: valid scenes render in [0, 1], and bump moves no boundary ---------------------

@st.composite
def valid_scenes(draw):
    bump = draw(st.sampled_from(("chart", "surface")))
    beta_max = 5.0 if bump == "chart" else 0.99          # the displaced surface needs beta < R
    return Scene(
        height_field=draw(st.sampled_from(("sine", "ridges", "rings"))),
        model=draw(st.sampled_from(("blinn", "phong"))),
        k_u=draw(st.floats(0.5, 20.0, exclude_min=True, exclude_max=True)),
        k_v=draw(st.floats(0.5, 20.0, exclude_min=True, exclude_max=True)),
        beta=draw(st.floats(0.0, beta_max)),
        eps=draw(st.floats(1e-8, 0.25)),
        sphere_b=draw(st.booleans()),
        floor=draw(st.booleans()),
        bump=bump,
    )


def geometry_only(scene):
    """The same scene with every shading-side field at its default."""
    return scene.replace(beta=0.35, eps=1e-3, height_field="ridges", k_u=8.0, k_v=4.0,
                         bump="chart")


def boundary_violations(frame, other):
    """Pixels whose chamber code differs between two frames."""
    return int(np.count_nonzero(frame.chamber != other.chamber))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=valid_scenes(), gradient=st.sampled_from(GRADIENTS))
def test_valid_scenes_render_in_unit_interval_and_bump_moves_no_boundary(scene, gradient):
    frame = render(scene, 16, 16, gradient=gradient)
    assert np.all(np.isfinite(frame.image)) and np.all(np.isfinite(frame.grad))
    assert frame.image.min() >= 0.0 and frame.image.max() <= 1.0
    reference = render(geometry_only(scene), 16, 16, gradient="exact")
    assert boundary_violations(frame, reference) == 0


def test_boundary_check_has_teeth():
    """A geometric change (sphere B's radius) is caught by the same comparison."""
    scene = Scene()
    moved = render(scene.replace(radius_b=0.33), 16, 16)
    assert boundary_violations(moved, render(geometry_only(scene), 16, 16)) > 0


def test_an_integer_beyond_float_range_names_the_field():
    with pytest.raises(ValueError, match=r"^Scene\.beta must be in \[0, 100\], got an integer of 401 digits$"):
        Scene(beta=10**400)


def test_a_0d_array_where_a_vector_belongs_names_the_field():
    """``Scene(center_b=np.array(0.5))`` raised ``TypeError: len() of unsized object``."""
    with pytest.raises(TypeError, match=r"^Scene\.center_b must be a sequence of 3 real numbers \(a tuple, list or "
                                        r"1-D array\), got ndarray array\(0\.5\)$"):
        Scene(center_b=np.array(0.5))


# --- every range at its limit and one float past it ----------------------------------------

def _past(x, direction):
    return float(np.nextafter(x, direction))


#: (field, the limit, one past it, the range as the message states it, other fields the limit needs).
#: The camera must stay outside both spheres, which is what the extra fields arrange.
FAR_B = dict(center_b=(1e6, 1e6, 0.0))
LIMITS = [
    ("radius_a", 1e-6, _past(1e-6, 0), "in [1e-06, 1e+06]", {"bump": "chart"}),
    ("radius_b", 1e-6, _past(1e-6, 0), "in [1e-06, 1e+06]", {}),
    ("radius_b", 1e6, _past(1e6, INF), "in [1e-06, 1e+06]", FAR_B),
    ("camera_z", 1e6, _past(1e6, INF), "<= 1e+06", {}),
    ("center_b", (-1e6, 0.5, 1.3), (_past(-1e6, -INF), 0.5, 1.3), "in [-1e+06, 1e+06]", {}),
    ("center_b", (0.5, 1e6, 1.3), (0.5, _past(1e6, INF), 1.3), "in [-1e+06, 1e+06]", {}),
    ("ambient", (0.0, 0.0, 1e3), (0.0, 0.0, _past(1e3, INF)), "in [0, 1000]", {}),
    ("ambient", (0.0, 0.0, 0.0), (0.0, -5e-324, 0.0), "in [0, 1000]", {}),
    ("albedo_a", (1.0, 0.5, 0.5), (_past(1.0, INF), 0.5, 0.5), "in [0, 1]", {}),
    ("albedo_b", (0.0, 0.5, 0.5), (-5e-324, 0.5, 0.5), "in [0, 1]", {}),
    *[(f, lim, p, "in [0, 1]", {}) for f in ("ka", "kd", "ks", "floor_tint") for lim, p in ((0.0, -5e-324),
                                                                                        (1.0, _past(1.0, INF)))],
    ("shininess", 1.0, _past(1.0, 0), "in [1, 10000]", {}),
    ("shininess", 1e4, _past(1e4, INF), "in [1, 10000]", {}),
    *[(f, lim, p, "in (0, 1000]", {}) for f in ("k_u", "k_v") for lim, p in ((5e-324, 0.0), (1e3, _past(1e3, INF)))],
    ("beta", 0.0, -5e-324, "in [0, 100]", {}),
    ("beta", 100.0, _past(100.0, INF), "in [0, 100]", {"bump": "chart"}),
    ("eps", 1e-16, _past(1e-16, 0), "in [1e-16, 0.25]", {}),
    ("eps", 0.25, _past(0.25, INF), "in [1e-16, 0.25]", {}),
]


@pytest.mark.parametrize("field, limit, beyond, accepted, extra", LIMITS,
                         ids=[f"{f}-{lim}" for f, lim, *_ in LIMITS])
def test_every_range_at_its_limit_and_one_past(field, limit, beyond, accepted, extra):
    scene = Scene(**extra, **{field: limit})
    assert getattr(scene, field) == limit
    with pytest.raises(ValueError) as info:
        Scene(**extra, **{field: beyond})
    bad = [i for i in range(3) if beyond[i] != limit[i]] if isinstance(beyond, tuple) else []
    name, value = (f"{field}[{bad[0]}]", beyond[bad[0]]) if bad else (field, beyond)
    assert str(info.value) == f"Scene.{name} must be {accepted}, got {value!r}"


@pytest.mark.parametrize("field, limit, beyond, accepted", [
    ("position", (-1e6, 0.0, 1e6), (-1e6, 0.0, _past(1e6, INF)), "[-1e+06, 1e+06]"),
    ("color", (1e3, 0.0, 1.0), (1e3, -5e-324, 1.0), "[0, 1000]"),
])
def test_point_light_ranges_at_the_limit_and_one_past(field, limit, beyond, accepted):
    assert getattr(PointLight(**{field: limit}), field) == limit
    i = next(i for i in range(3) if beyond[i] != limit[i])
    with pytest.raises(ValueError, match=rf"^PointLight\.{field}\[{i}\] must be in {re.escape(accepted)}, "
                                         rf"got {re.escape(repr(beyond[i]))}$"):
        PointLight(**{field: beyond})


# --- flags, sweep steps and compare's inputs -----------------------------------------------

@pytest.mark.parametrize("flag", ["kink", "grad", "skip"])
@pytest.mark.parametrize("value", ["no", 0, 1, None, 1.0, [True]])
def test_boolean_flags_are_type_checked(flag, value):
    with pytest.raises(TypeError, match=rf"^{flag} must be True or False, got "):
        render(Scene(), 4, 4, **{flag: value})


def test_numpy_bools_are_accepted_as_flags():
    frame = render(Scene(), 4, 4, kink=np.bool_(False), grad=np.True_)
    assert frame.kink is None and frame.grad is not None


def test_sweep_reads_an_endless_iterator_only_one_step_past_the_limit():
    from renderer.sweep import MAX_STEPS
    taken = []

    def endless():
        while True:
            taken.append(1)
            yield 1e-3

    with pytest.raises(ValueError, match=f"must hold 1 to {MAX_STEPS} steps, got more than {MAX_STEPS}"):
        sweep(Scene(), endless(), 4, 4)
    assert len(taken) == MAX_STEPS + 1
    # An iterator within the limit is read whole and used in order.
    sw = sweep(Scene(), iter([1e-2, 1e-3]), 4, 4)
    assert [f.scene.eps for f in sw.numeric] == [1e-2, 1e-3]


@pytest.mark.parametrize("steps", [{1e-3, 1e-4}, frozenset({1e-3}), {1e-3: "a"}, {1e-3: 1}.keys()])
def test_sweep_refuses_unordered_steps(steps):
    with pytest.raises(TypeError, match=rf"^eps_values must be ordered \(a list, tuple, array or iterator\), got a "
                                        rf"{type(steps).__name__}: the census follows the order of the steps$"):
        sweep(Scene(), steps, 4, 4)


@pytest.mark.parametrize("step", [0.0, 5e-324, np.nextafter(1e-16, 0), np.nextafter(0.25, 1), 1e300, 0.3, np.nan])
def test_sweep_steps_outside_the_scene_range_are_refused_by_index(step):
    with pytest.raises(ValueError, match=r"^eps_values\[1\] must be in \[1e-16, 0.25\], got "):
        sweep(Scene(), [1e-3, step], 4, 4)


@pytest.mark.parametrize("step", [True, np.True_, "1e-3", None])
def test_sweep_steps_that_are_not_numbers_are_refused_by_index(step):
    with pytest.raises(TypeError, match=r"^eps_values\[1\] must be a real number, got "):
        sweep(Scene(), [1e-3, step], 4, 4)


@pytest.mark.parametrize("step", [1e-16, 0.25, np.float32(0.125), np.array(1e-3)])
def test_sweep_steps_at_the_limits_and_numpy_scalars_are_accepted(step):
    assert sweep(Scene(), [step], 2, 2).eps == (float(step),)


def test_compare_without_a_crease_band_says_what_to_pass():
    numeric = render(Scene(), 8, 8, gradient="central")
    symbolic = render(Scene(), 8, 8, kink=False)
    with pytest.raises(ValueError, match="render the symbolic frame with kink=True"):
        compare(numeric, symbolic)
    # With the band, the same frames compare.
    assert compare(numeric, render(Scene(), 8, 8)).pixels_a > 0
    with pytest.raises(TypeError, match="numeric must be a renderer Frame"):
        compare(numeric.image, symbolic)


@pytest.mark.parametrize("call", ["render", "gbuffer", "sweep"])
def test_the_library_refuses_a_frame_over_its_pixel_cap_before_allocating(call):
    """Sides up to 8192 are accepted, but not 8192 x 8192 (67 M pixels, 2.7 GB for one frame)."""
    from renderer import cli, gbuffer, sweep
    from renderer.render import MAX_PIXELS
    assert cli.MAX_PIXELS == MAX_PIXELS
    run = {"render": lambda w, h: render(Scene(), w, h), "gbuffer": lambda w, h: gbuffer(Scene(), w, h),
           "sweep": lambda w, h: sweep(Scene(), (1e-3,), w, h)}[call]
    with pytest.raises(ValueError, match=r"^width \* height must be at most 16,777,216 pixels \(4096 x 4096\), "
                                         r"got 8192 x 8192 = 67,108,864$"):
        run(8192, 8192)
    with pytest.raises(ValueError, match="got 4097 x 4096"):
        run(4097, 4096)
