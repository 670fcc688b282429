"""The labels a measured number carries on a page (book/chapter/labels.py): which scene and
resolution, or which U-curve.  Checked by structure (the size, each changed field's value,
nothing of an unchanged field), not by wording."""

import re

import numpy as np
import pytest

from chapter import labels
from renderer import DRAFT_SCENE, Scene


def _unbroken(label):
    """``label`` with its no-break spaces as spaces, once no line can part an "=" or a "×" from a side."""
    assert re.search(r"\s[=×]|[=×]\s", label.replace("\u00a0", "")) is None, label
    return label.replace("\u00a0", " ")


def frame_label(*args):
    return _unbroken(labels.frame_label(*args))


def ucurve_label(*args):
    return _unbroken(labels.ucurve_label(*args))


def test_a_frame_label_names_the_size_and_exactly_the_fields_that_differ():
    plain = frame_label(Scene(), 256, 128)
    assert plain.endswith("256 × 128") and "β" not in plain and "field" not in plain
    sine = frame_label(Scene(height_field="sine", beta=0.5), 64, 64)
    assert "sine" in sine and "β = 0.5" in sine and sine.endswith("64 × 64")
    assert "ridges" not in sine and "ε" not in sine and "kᵥ" not in sine      # unchanged fields unnamed
    other = frame_label(Scene(bump="chart", sphere_b=False, k_v=2.0), 8, 8)
    assert "kᵥ = 2" in other and "sphere B" in other and "draft" in other and "kᵤ" not in other
    assert "draft" not in plain and "draft" in frame_label(DRAFT_SCENE, 8, 8) != frame_label(Scene(), 8, 8)
    assert "normal" not in frame_label(DRAFT_SCENE.replace(beta=0.5), 8, 8)   # the draft's own normal is not a change
    assert frame_label(Scene(), np.int64(8), 8).endswith("8 × 8")          # numpy integers count


def test_a_frame_label_reads_the_scene_a_measurement_stores():
    """A `lab` measurement stores `Scene.changes()` (JSON); the label of that dict is the scene's."""
    scene = Scene(height_field="sine", beta=0.5, eps=1e-4)
    assert Scene(**scene.changes()) == scene and set(scene.changes()) <= {"height_field", "beta", "eps"}
    assert frame_label(scene.changes(), 32, 16) == frame_label(scene, 32, 16)
    assert frame_label({}, 4, 4) == frame_label(Scene(), 4, 4)


def test_a_frame_label_refuses_what_is_not_a_scene_or_a_size():
    with pytest.raises(TypeError, match="scene must be a renderer.Scene or a dict of its fields, got list"):
        frame_label([], 64, 64)
    with pytest.raises(TypeError, match=r"Scene has no field\(s\) \[.colour.\]; fields are "):
        frame_label({"colour": 1}, 64, 64)
    with pytest.raises(ValueError, match=r"^width must be a positive integer, got 0$"):
        frame_label(Scene(), 0, 64)
    for bad in (2.0, True):                    # a float or a bool is not a count of pixels
        with pytest.raises(TypeError, match=rf"^height must be a positive integer, got {type(bad).__name__} {bad!r}$"):
            frame_label(Scene(), 64, bad)


def test_the_ucurve_label_shows_the_point_the_frequencies_and_the_steps():
    label = ucurve_label("sine", dict(component="u", u=0.31, v=0.47, k_u=8.0, k_v=4.0, steps=97, largest_step=0.1,
                                      smallest_step=1e-16))
    for shown in ("sine", "hᵤ", "0.31", "0.47", "kᵤ = 8", "kᵥ = 4", "97", "1e-01", "1e-16"):
        assert shown in label, shown
    assert "hᵥ" in ucurve_label("rings", dict(component="v", u=0.31, v=0.47, k_u=8.0, k_v=4.0, steps=97,
                                              largest_step=0.1, smallest_step=1e-16))
