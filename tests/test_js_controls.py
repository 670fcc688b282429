"""The simulator's controls against the Python scene, under node (no browser, no built book).

`tests/js/controls_driver.mjs` imports the generated simulator module and returns, for every
position of every control (each option of a menu, each end, default and decade tick of a slider,
both states of the checkbox, each applied alone to the opening state) and for each preset, the
scene `scene_of` hands the renderer.  Each must be a `renderer.Scene` Python accepts; a control
named like a Scene field moves that field and nothing else (the ε slider moves ``eps``, to the
printed value); a control of the view (scale, resolution, zoom, numeric pipeline) moves none; the
menus offer exactly Python's choices; the opening scene is `SIMULATOR_SCENE`; every field the menu offers, at
every pair of frequencies the sliders offer, is smooth across the seam u = 0 = 1 where the chart's edges meet,
or creased there with the crease band flagging it (`seam_problems`).  Wrong variants: a `scene_of` that swaps
the two frequencies, one that ignores the bump control, and a k_u slider of odd values (sine creased at the seam).
"""

import dataclasses
import json
import subprocess

import numpy as np
import pytest

from renderer import Scene, pointwise
from renderer.formulas import FIELDS
from renderer.ledger import SIMULATOR_SCENE
from renderer.render import GRADIENTS
from renderer.scene import BUMPS, MODELS, PointLight as Light

from .jsnode import DRIVERS, node_command, write_modules

#: The simulator's controls that set a Scene field (the ε slider sets eps from log10 eps) ...
SCENE_CONTROLS = {"height_field": "height_field", "beta": "beta", "bump": "bump", "k_u": "k_u", "k_v": "k_v",
                  "model": "model", "sphere_b": "sphere_b", "log_eps": "eps"}
#: ... and those that change only how the frames are drawn or sampled.
VIEW_CONTROLS = {"view", "scale", "numeric", "resolution", "zoom"}


def _positions(tmp_path, transform=None):
    modules = write_modules(tmp_path / "modules", transform)
    out = subprocess.run([*node_command("the controls test runs the simulator's module under node"),
                          str(DRIVERS / "controls_driver.mjs"), str(modules)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def _scene(fields):
    """A Scene from the JSON of one (lists back to tuples, lights to Light records): raises as Scene does."""
    def value(name, x):
        if name == "lights":
            return tuple(Light(tuple(l["position"]), tuple(l["color"])) for l in x)
        return tuple(x) if isinstance(x, list) else x
    return Scene(**{name: value(name, x) for name, x in fields.items()})


def seam_problems(field, frequencies, v=np.linspace(0.01, 0.99, 99)):
    """Where ``field`` (a name of `renderer.formulas.FIELDS`) at one of ``frequencies`` [(k_u, k_v)] is, in the
    renderer's own compiled code (`renderer.pointwise`), neither smooth across the seam (h and h_u the same at
    u = 0 and u = 1, to 1e-9 of their scale) nor creased there with its crease band flagging both sides:
    [sentences].  At a smooth seam the shading is continuous, and the book calls a field without creases
    smooth; a crease the band does not flag would be truncation error by the captions and crease error on
    the canvas."""
    out, k = [], np.array(frequencies, float)[:, :, None, None]              # (frequencies, 2, 1, 1)
    at = (np.array([[0.0], [1.0]]), v, k[:, 0], k[:, 1])                      # each (frequencies, seam side, v)
    h, h_u, band = pointwise.height(field, *at), pointwise.exact_gradient(field, *at)[0], pointwise.kink_band(field, *at)
    for (k_u, k_v), (h0, h1), (d0, d1), flagged in zip(frequencies, h, h_u, band.all(axis=1)):
        scale = max(1.0, np.abs([d0, d1]).max())
        if np.abs(h0 - h1).max() > 1e-9 * scale:
            out.append(f"{field} at k_u = {k_u}, k_v = {k_v}: h breaks at the seam (u = 0 and u = 1 meet on the "
                       "sphere: h must agree there)")
        elif np.any((np.abs(d0 - d1) > 1e-9 * scale) & ~flagged):
            out.append(f"{field} at k_u = {k_u}, k_v = {k_v}: creased at the seam, and the crease band does not say "
                       "so (u = 0 and u = 1 meet on the sphere: h_u must agree there, or the seam be a zero of a crease "
                       "factor, under an Abs)")
    return out


def _problems(data):
    """What is wrong with the controls' scenes (an empty list when nothing is)."""
    bad = []
    default = _scene(data["default"])
    if default != SIMULATOR_SCENE:
        bad.append(f"opening scene {default} is not SIMULATOR_SCENE")
    seen = {}
    for p in data["positions"]:
        try:
            scene = _scene(p["scene"])
        except (TypeError, ValueError) as exc:
            bad.append(f"{p['control']}={p['value']!r} is a scene Python refuses: {exc}")
            continue
        moved = {f.name for f in dataclasses.fields(Scene) if getattr(scene, f.name) != getattr(default, f.name)}
        control, value = p["control"], p["value"]
        seen.setdefault(control, []).append(value)
        if control in VIEW_CONTROLS:
            if moved:
                bad.append(f"{control}={value!r} moves the scene's {sorted(moved)}")
            continue
        field = SCENE_CONTROLS[control]
        want = 10.0 ** value if control == "log_eps" else value
        if moved - {field}:
            bad.append(f"{control}={value!r} moves {sorted(moved - {field})} besides {field}")
        if control == "log_eps" and float(value).is_integer() and scene.eps != 10.0 ** value:
            bad.append(f"the ε slider at the decade {value} renders eps {scene.eps!r}, not 1e{int(value)}")
        got = getattr(scene, field)
        if not (got == pytest.approx(want, rel=0.05, abs=0) if isinstance(want, float) else got == want):
            bad.append(f"{control}={value!r} renders {field}={got!r}")
    for control, choices in (("height_field", tuple(FIELDS)), ("bump", BUMPS), ("model", MODELS),
                             ("numeric", tuple(g for g in GRADIENTS if g != "exact"))):
        if sorted(map(str, seen.get(control, ()))) != sorted(choices):
            bad.append(f"the {control} menu offers {seen.get(control)}, Python {choices}")
    if set(seen) != set(SCENE_CONTROLS) | VIEW_CONTROLS:
        bad.append(f"controls {sorted(set(seen) ^ (set(SCENE_CONTROLS) | VIEW_CONTROLS))} unaccounted for")
    frequencies = [(k_u, k_v) for k_u in seen.get("k_u", ()) for k_v in seen.get("k_v", ())]
    for name in seen.get("height_field", ()):
        bad += seam_problems(name, frequencies)
    for preset in data["presets"]:
        try:
            _scene(preset["scene"])
        except (TypeError, ValueError) as exc:                   # renderer.validate's errors are these
            bad.append(f"preset {preset['id']} is a scene Python refuses: {exc}")
    return bad


def test_every_control_position_is_a_python_scene_moving_its_own_field(tmp_path):
    assert _problems(_positions(tmp_path)) == []


@pytest.mark.parametrize("variant, transform", [
    ("k_u and k_v swapped", lambda name, text: text.replace("k_u: state.k_u, k_v: state.k_v",
                                                            "k_u: state.k_v, k_v: state.k_u")),
    ("the bump control ignored", lambda name, text: text.replace("bump: state.bump,", "")),
    ("a k_u slider of odd values", lambda name, text: text.replace('kind: "range", min: 2, max: 24, step: 2 }',
                                                                   'kind: "range", min: 1, max: 24, step: 1 }')),
])
def test_the_controls_check_catches_a_wrong_scene_of(tmp_path, variant, transform):
    data = _positions(tmp_path, lambda name, text: transform(name, text) if name == "simulator" else text)
    assert _problems(data), variant
