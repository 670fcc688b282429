"""The words that name what a number was measured on: a render's scene and resolution,
and the U-curve's point and steps.

`lab`, `proofs` and `renderer` return the scene (or its fields that differ from
`renderer.Scene`'s defaults, `Scene.changes`) and the size; the pages word them here.
"""

from __future__ import annotations

from renderer import DRAFT_SCENE, Scene
from renderer.validate import positive_int

__all__ = ["frame_label", "size_label", "ucurve_label"]

#: How `frame_label` words a field of `renderer.Scene` that differs from its reference scene.
#: An equation's and a size's spaces are no-break ones, so that a phone's line never parts "β =" from
#: its value or "256 ×" from "256".
_EQUALS, _TIMES = "\u00a0=\u00a0", "\u00a0×\u00a0"
_WORDS = {"height_field": "the {} field", "beta": f"β{_EQUALS}{{:g}}", "eps": f"ε{_EQUALS}{{:g}}",
          "k_u": f"kᵤ{_EQUALS}{{:g}}", "k_v": f"kᵥ{_EQUALS}{{:g}}", "radius_a": f"R{_EQUALS}{{:g}}",
          "model": "{} shading", "shininess": "shininess {:g}"}


def _field_words(name, value):
    if name == "bump":
        return {"surface": "the displaced sphere's normal", "chart": "the draft's normal"}[value]
    if name in ("sphere_b", "floor") and isinstance(value, bool):
        return f"{'with' if value else 'no'} {'sphere B' if name == 'sphere_b' else name}"
    return _WORDS.get(name, name.replace("_", " ") + " {}").format(value)


def frame_label(scene, width, height) -> str:
    """The label a number measured on a render carries: its scene and resolution, in words.

    ``"the chapter's scene, 256 × 256"`` (`renderer.Scene`'s defaults: the displaced
    sphere's normal), ``"the draft's scene, 256 × 256"`` (`renderer.DRAFT_SCENE`: the
    draft's chart normal), or either with the fields that differ from it: ``"the draft's
    scene with the sine field, β = 1.5, 64 × 64"``.

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
    draft = scene.bump == DRAFT_SCENE.bump
    reference = DRAFT_SCENE if draft else Scene()
    changed = [_field_words(name, getattr(scene, name)) for name in scene.changes()
               if getattr(scene, name) != getattr(reference, name)]
    return (("the draft's scene" if draft else "the chapter's scene") + (" with " + ", ".join(changed) if changed else "")
            + ", " + size_label(width, height))


def size_label(width, height):
    """A frame's size in pixels as the pages print it, ``"256 × 256"``, its spaces no-break ones.

    Raises
    ------
    TypeError, ValueError
        As `frame_label` does for ``width`` and ``height``.
    """
    return f"{positive_int('width', width)}{_TIMES}{positive_int('height', height)}"


def ucurve_label(field, curve) -> str:
    """Where a U-curve of `lab.accuracy.optima` is measured, in words: the field, the
    component and the point, the frequencies and the steps (each equation's spaces no-break ones).

    Parameters
    ----------
    field : str
        The height field's name (a key of `lab.accuracy.optima`'s dict).
    curve : dict
        Its entry: ``component`` ("u" or "v"), ``u``, ``v`` (chart coordinates), ``k_u``,
        ``k_v`` (periods over the chart), ``steps`` (int), ``largest_step``, ``smallest_step``
        (chart units).

    Raises
    ------
    KeyError
        If ``curve`` lacks one of those keys.
    """
    sub = {"u": "ᵤ", "v": "ᵥ"}[curve["component"]]
    return (f"{field} field, h{sub} at (u,\u00a0v){_EQUALS}({curve['u']},\u00a0{curve['v']}), "
            f"kᵤ{_EQUALS}{curve['k_u']:g}, kᵥ{_EQUALS}{curve['k_v']:g}, {curve['steps']} steps from "
            f"{curve['largest_step']:.0e} to {curve['smallest_step']:.0e}")
