"""The words that name what a number was measured on: a render's scene and resolution,
and the U-curve's point and steps.

`lab`, `proofs` and `renderer` return the scene (or its fields that differ from
`renderer.Scene`'s defaults, `Scene.changes`) and the size; the pages word them here.
"""

from __future__ import annotations

from renderer import Scene
from renderer.validate import positive_int

__all__ = ["frame_label", "ucurve_label"]

#: How `frame_label` words a field of `renderer.Scene` that differs from the draft's.
_WORDS = {"height_field": "the {} field", "beta": "β = {:g}", "eps": "ε = {:g}", "k_u": "kᵤ = {:g}",
          "k_v": "kᵥ = {:g}", "radius_a": "R = {:g}", "model": "{} shading", "shininess": "shininess {:g}"}


def _field_words(name, value):
    if name == "bump":
        return {"surface": "the displaced sphere's normal", "chart": "the draft's normal"}[value]
    if name in ("sphere_b", "floor") and isinstance(value, bool):
        return f"{'with' if value else 'no'} {'sphere B' if name == 'sphere_b' else name}"
    return _WORDS.get(name, name.replace("_", " ") + " {}").format(value)


def frame_label(scene, width, height) -> str:
    """The label a number measured on a render carries: its scene and resolution, in words.

    ``"the draft's scene, 256 × 256"``, or with the fields that differ from
    `renderer.Scene`'s defaults (the draft's scene): ``"the draft's scene with the
    sine field, β = 1.5, 64 × 64"``.

    Parameters
    ----------
    scene : renderer.Scene or dict
        The scene, or the keyword arguments of `renderer.Scene` that build it (the
        `renderer.Scene.changes` a `lab` measurement returns, e.g. ``census()["scene"]``).
    width, height : int
        The frame's size in pixels.

    Raises
    ------
    TypeError
        ``scene`` is neither a `renderer.Scene` nor a dict, or ``width`` or ``height``
        is not an integer (`renderer.validate.positive_int`); a dict key that is not a
        Scene field (`renderer.Scene.replace`).
    ValueError
        ``width`` or ``height`` is below 1, or a dict value `renderer.Scene` refuses.
    """
    if isinstance(scene, dict):
        scene = Scene().replace(**scene)
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a renderer.Scene or a dict of its fields, got {type(scene).__name__}")
    width, height = positive_int("width", width), positive_int("height", height)
    changed = [_field_words(name, value) for name, value in scene.changes().items()]
    return "the draft's scene" + (" with " + ", ".join(changed) if changed else "") + f", {width} × {height}"


def ucurve_label(curve) -> str:
    """Where the U-curve of `lab.accuracy.default_optimum` is measured, in words: the field,
    the point, the frequencies and the steps.

    Parameters
    ----------
    curve : dict
        `lab.accuracy.default_optimum`'s dict: ``field`` (str), ``u``, ``v`` (chart
        coordinates), ``k_u``, ``k_v`` (periods over the chart), ``steps`` (int), ``eps_max``,
        ``eps_min`` (chart units).

    Raises
    ------
    KeyError
        If ``curve`` lacks one of those keys.
    """
    return (f"{curve['field']} field, hᵤ at (u, v) = ({curve['u']}, {curve['v']}), kᵤ = {curve['k_u']:g}, "
            f"kᵥ = {curve['k_v']:g}, {curve['steps']} steps from {curve['eps_max']:.0e} to {curve['eps_min']:.0e}")
