"""Scene and render reject bad input with an error naming the field."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from renderer import PointLight, Scene, render

# The seed's SC9 (Cell 1), typed from the seed: the spec of the defaults.
SC9 = dict(radius_a=1.0, camera_z=4.0, center_b=(0.5, 0.5, 1.3), radius_b=0.32, sphere_b=True,
           floor=True, ambient=(0.15, 0.15, 0.16), albedo_a=(0.63, 0.19, 0.16),
           albedo_b=(0.33, 0.44, 0.62), ka=0.1, kd=0.7, ks=0.5, shininess=32.0, model="blinn",
           floor_tint=0.25, height_field="ridges", k_u=8.0, k_v=4.0, beta=0.35, eps=1e-3)


def test_defaults_are_the_seeds():
    scene = Scene()
    for name, value in SC9.items():
        assert getattr(scene, name) == value, name
    assert [(l.position, l.color) for l in scene.lights] == [
        ((5.0, 5.0, 10.0), (1.0, 1.0, 1.0)), ((-6.0, 2.0, 8.0), (0.9, 0.65, 0.25))]


BAD_VALUES = [
    # (field, value, exception, message fragment)
    ("radius_a", 0.0, ValueError, "radius_a"), ("radius_a", -1.0, ValueError, "radius_a"),
    ("radius_a", math.nan, ValueError, "radius_a"), ("radius_a", "1", TypeError, "radius_a"),
    ("radius_a", True, TypeError, "radius_a"),
    ("camera_z", 1.0, ValueError, "camera_z"), ("camera_z", 0.5, ValueError, "camera_z"),
    ("camera_z", math.inf, ValueError, "camera_z"),
    ("center_b", (0.0, 0.0), ValueError, "center_b"), ("center_b", "abc", TypeError, "center_b"),
    ("center_b", (0, 0, math.nan), ValueError, r"center_b\[2\]"),
    ("center_b", (0.0, 0.0, 4.0), ValueError, "radius_b"),      # camera inside sphere B
    ("radius_b", 0.0, ValueError, "radius_b"), ("radius_b", None, TypeError, "radius_b"),
    ("sphere_b", 1, TypeError, "sphere_b"), ("floor", "yes", TypeError, "floor"),
    ("lights", PointLight(), TypeError, "lights"), ("lights", ((1, 2, 3),), TypeError, r"lights\[0\]"),
    ("lights", "light", TypeError, "lights"),
    ("ambient", (-0.1, 0, 0), ValueError, r"ambient\[0\]"),
    ("albedo_a", (1.5, 0, 0), ValueError, r"albedo_a\[0\]"),
    ("albedo_b", (0, 0, math.inf), ValueError, r"albedo_b\[2\]"),
    ("ka", -1.0, ValueError, "ka"), ("kd", math.nan, ValueError, "kd"), ("ks", "0.5", TypeError, "ks"),
    ("shininess", 0.0, ValueError, "shininess"),
    ("model", "lambert", ValueError, "model"), ("model", 1, TypeError, "model"),
    ("floor_tint", 1.5, ValueError, "floor_tint"), ("floor_tint", -0.1, ValueError, "floor_tint"),
    ("height_field", "bumps", ValueError, "height_field"), ("height_field", None, TypeError, "height_field"),
    ("k_u", 0.0, ValueError, "k_u"), ("k_v", -2.0, ValueError, "k_v"), ("k_u", math.inf, ValueError, "k_u"),
    ("beta", -0.1, ValueError, "beta"), ("beta", math.nan, ValueError, "beta"),
    ("bump", "displacement", ValueError, "bump"), ("bump", None, TypeError, "bump"),
    ("eps", 0.0, ValueError, "eps"), ("eps", -1e-3, ValueError, "eps"), ("eps", math.inf, ValueError, "eps"),
]


@pytest.mark.parametrize("field, value, exc, fragment", BAD_VALUES)
def test_scene_rejects_bad_field(field, value, exc, fragment):
    with pytest.raises(exc, match=fragment):
        Scene(**{field: value})


def test_surface_bump_needs_beta_below_radius():
    with pytest.raises(ValueError, match="beta must be < radius_a"):
        Scene(bump="surface", beta=1.0)
    assert Scene(bump="surface", beta=0.99).bump == "surface"


def test_message_names_value_and_accepted_range():
    with pytest.raises(ValueError, match=r"Scene\.eps must be > 0\.0, got -0\.001"):
        Scene(eps=-1e-3)
    with pytest.raises(ValueError, match=r"one of \('sine', 'ridges', 'rings'\), got 'bumps'"):
        Scene(height_field="bumps")


@pytest.mark.parametrize("kwargs, exc, fragment", [
    (dict(position=(0, 0)), ValueError, "position"), (dict(color=(1, -1, 1)), ValueError, r"color\[1\]"),
    (dict(position=(0, 0, math.nan)), ValueError, r"position\[2\]"), (dict(color="white"), TypeError, "color"),
])
def test_point_light_rejects_bad_field(kwargs, exc, fragment):
    with pytest.raises(exc, match=fragment):
        PointLight(**kwargs)


def test_replace_validates_and_rejects_unknown_fields():
    assert Scene().replace(beta=1.5).beta == 1.5
    with pytest.raises(TypeError, match="betta"):
        Scene().replace(betta=1.5)
    with pytest.raises(ValueError, match="beta"):
        Scene().replace(beta=-1.0)


@pytest.mark.parametrize("width, height, exc, fragment", [
    (0, 8, ValueError, "width"), (8, -1, ValueError, "height"), (8193, 8, ValueError, "width"),
    (8.0, 8, TypeError, "width"), (True, 8, TypeError, "width"), (8, "8", TypeError, "height"),
    (8, None, TypeError, "height"),
])
def test_render_rejects_bad_size(width, height, exc, fragment):
    with pytest.raises(exc, match=fragment):
        render(Scene(), width, height)


def test_render_rejects_bad_gradient_and_scene():
    with pytest.raises(ValueError, match="gradient"):
        render(Scene(), 8, 8, gradient="forward")
    with pytest.raises(TypeError, match="scene"):
        render({"beta": 0.35}, 8, 8)


def test_numpy_scalars_are_accepted():
    scene = Scene(beta=np.float64(0.5), k_u=np.int64(3))
    assert type(scene.beta) is float and scene.k_u == 3.0
    assert render(scene, np.int64(4), 4).image.shape == (4, 4, 3)


@settings(max_examples=40, deadline=None)
@given(field=st.sampled_from(["sine", "ridges", "rings"]), model=st.sampled_from(["blinn", "phong"]),
       k_u=st.floats(0.5, 20), k_v=st.floats(0.5, 20), beta=st.floats(0, 5),
       eps=st.floats(1e-8, 0.4), sphere_b=st.booleans(), floor=st.booleans(),
       gradient=st.sampled_from(["exact", "central"]))
def test_property_finite_image_and_geometry_only_chamber(field, model, k_u, k_v, beta, eps,
                                                        sphere_b, floor, gradient):
    scene = Scene(height_field=field, model=model, k_u=k_u, k_v=k_v, beta=beta, eps=eps,
                  sphere_b=sphere_b, floor=floor)
    frame = render(scene, 16, 16, gradient=gradient)
    assert np.isfinite(frame.image).all()
    assert frame.image.min() >= 0 and frame.image.max() <= 1
    plain = render(Scene(sphere_b=sphere_b, floor=floor, beta=0.0), 16, 16)
    assert np.array_equal(frame.chamber, plain.chamber)
