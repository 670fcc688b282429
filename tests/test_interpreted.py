"""The kernel interpreted (NUMBA_DISABLE_JIT=1) gives the compiled outputs, bit for bit.

numba compiles the kernel with ``error_model="numpy"``: a float division by
zero is inf there, and the kernel may discard it (the tangent frame and the
footprint divide by sin(phi) in the branch their pole fallback replaces).
Interpreted, Python's float division by zero raises ZeroDivisionError.  The
kernel divides by no zero now (`renderer.kernel.chart_of`, and
`renderer.kernel.unit_vector` for a light so close to a point that |w|^2
underflows); every other operation is an IEEE operation or a call of the
same libm function in both modes, and the integral power is numba's own
repeated squaring written out (`renderer.kernel.int_power`; Python's ``**``
calls libm's pow), so the outputs must be equal, not close.

A grid of scenes at the accepted extremes (renderer/scene.py's limits) runs
in a child process with NUMBA_DISABLE_JIT=1, at 8 x 8, and at 9 x 20 the
frame whose pixel (4, 8) lies on the optical axis, on sphere A's pole
(sin(phi) = 0: the ZeroDivisionError found); each through `render` (the three
gradients, and without skips), `gbuffer` and `sweep`.  The same calls here,
compiled, must give the same bytes.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from renderer import PointLight, Scene, gbuffer, kernel, render, sweep
from renderer import scene as S
from renderer.render import image_plane

ROOT = Path(__file__).parents[1]
_X, _Y = image_plane(1.0, 4.0, 8, 8)

#: name: (scene, width, height).  8 x 8 has no pixel centre on the optical axis
#: (an even width); the pole needs an odd width and a row at y = 0 exactly.
SCENES = {
    "default": (Scene(), 8, 8),
    "sphere A's pole on a pixel": (Scene(radius_a=2.0, camera_z=3.0, height_field="sine", k_u=7.0), 9, 20),
    "no ambient, a black light": (Scene(ambient=(0.0, 0.0, 0.0),
                                        lights=(PointLight((5.0, 5.0, 10.0), (0.0, 0.0, 0.0)),)), 8, 8),
    "no lights": (Scene(lights=()), 8, 8),
    "a light at the eye": (Scene(lights=(PointLight((0.0, 0.0, 4.0)),), model="phong"), 8, 8),
    "a light inside sphere A": (Scene(lights=(PointLight((0.0, 0.0, 0.0)),)), 8, 8),
    # |L - P|^2 underflows to 0 at the floor pixel (7, 0): 1 / sqrt(0) in the light's direction.
    "a light 1e-170 above a floor pixel": (Scene(lights=(PointLight((_X[0], _Y[7], 1e-170)),)), 8, 8),
    "beta 0, floor and sphere B off": (Scene(beta=0.0, floor=False, sphere_b=False), 8, 8),
    "frequencies at their limits": (Scene(k_u=S.MAX_FREQUENCY, k_v=5e-324, height_field="sine"), 8, 8),
    "the largest beta, shininess and intensities": (
        Scene(beta=S.MAX_BETA, bump="chart", shininess=S.MAX_SHININESS, ambient=(S.MAX_INTENSITY,) * 3,
              lights=(PointLight((5.0, 5.0, 10.0), (S.MAX_INTENSITY,) * 3),)), 8, 8),
    "a shininess that is not an integer": (Scene(shininess=1.5, model="phong", kd=0.0), 8, 8),
    "the least eps, the surface bump": (Scene(eps=S.MIN_EPS, bump="surface", beta=0.99), 8, 8),
    "the least sphere from the farthest camera": (Scene(radius_a=S.MIN_RADIUS, camera_z=S.MAX_LENGTH, bump="chart"),
                                                  8, 8),
    "the camera one ulp outside sphere A": (Scene(radius_a=1.0, camera_z=1.0 + 2.0**-52), 8, 8),
    "the least sphere B, far from all": (Scene(radius_a=S.MIN_RADIUS, camera_z=S.MAX_LENGTH,
                                              center_b=(0.0, 0.0, 1e5), radius_b=S.MIN_RADIUS, bump="chart"), 8, 8),
}
STEPS = (S.MIN_EPS, 1e-3, S.MAX_EPS)


def outputs():
    """{key: array} of every call on every scene of `SCENES`."""
    out = {}
    for name, (scene, width, height) in SCENES.items():
        calls = {f"render {g}": lambda g=g: render(scene, width, height, gradient=g)
                 for g in ("exact", "central", "footprint")}
        calls["render central, no skips"] = lambda: render(scene, width, height, gradient="central", skip=False)
        calls["gbuffer footprint"] = lambda: gbuffer(scene, width, height, gradient="footprint")
        calls["sweep"] = lambda: sweep(scene, STEPS, width, height)
        for call, run in calls.items():
            result = run()
            if call == "sweep":
                fields = {f"frame {k} {f}": getattr(frame, f) for k, frame in enumerate((result.symbolic,) + result.numeric)
                          for f in ("image", "grad", "chamber", "kink")}
            else:
                fields = {f: getattr(result, f) for f in ("image", "grad", "chamber", "kink", "t", "P", "N", "Ns", "uv")
                          if getattr(result, f, None) is not None}
            out.update({f"{name} | {call} | {f}": np.asarray(a) for f, a in fields.items()})
    return out


def interpreted_outputs(tmp_path, env=None):
    """`outputs` computed in a child process with NUMBA_DISABLE_JIT=1."""
    path = tmp_path / "interpreted.npz"
    code = ("import sys, numpy as np\n"
            "from renderer import kernel\n"
            "assert not hasattr(kernel.render_rows, 'py_func'), 'the kernel is compiled'\n"
            "from tests.test_interpreted import outputs\n"
            "np.savez(sys.argv[1], **outputs())\n")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONWARNINGS="ignore", **(env or {}))
    done = subprocess.run([sys.executable, "-c", code, str(path)], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=900)
    if done.returncode:
        return done.stderr.strip().splitlines()[-1]
    with np.load(path) as data:
        return {key: data[key] for key in data.files}


def differences(interpreted, compiled):
    """Keys whose arrays differ in dtype, shape or any byte."""
    return [key for key, a in compiled.items()
            if key not in interpreted or interpreted[key].dtype != a.dtype or interpreted[key].shape != a.shape
            or interpreted[key].tobytes() != a.tobytes()]


def test_the_pole_frame_puts_a_pixel_centre_on_the_optical_axis():
    scene, width, height = SCENES["sphere A's pole on a pixel"]
    x, y = image_plane(scene.radius_a, scene.camera_z, width, height)
    assert x[4] == 0.0 and y[8] == 0.0
    assert gbuffer(scene, width, height).chamber[8, 4] == 1


@pytest.fixture(scope="module")
def compiled():
    assert hasattr(kernel.render_rows, "py_func")          # compiled here
    return outputs()


def test_interpreted_kernel_gives_the_compiled_outputs(compiled, tmp_path):
    interpreted = interpreted_outputs(tmp_path)
    assert isinstance(interpreted, dict), f"the interpreted run failed: {interpreted}"
    assert differences(interpreted, compiled) == []
    assert len(compiled) > 400


def test_a_light_next_to_a_floor_point_lights_it():
    """The light 1e-170 above the floor pixel lights it as one 1e-100 above does
    (w = (0, 0, 1) both), not the NaN direction 1 / sqrt(0) gave (unlit)."""
    scene = SCENES["a light 1e-170 above a floor pixel"][0]
    near = scene.replace(lights=(PointLight((_X[0], _Y[7], 1e-100)),))
    a, b = render(scene, 8, 8).image[7, 0], render(near, 8, 8).image[7, 0]
    assert np.array_equal(a, b) and a.min() > render(scene.replace(lights=()), 8, 8).image[7, 0].max()


def test_the_comparison_rejects_a_changed_bit(compiled):
    key = "default | render exact | image"
    changed = dict(compiled, **{key: compiled[key].copy()})
    changed[key][3, 3, 0] = math.nextafter(changed[key][3, 3, 0], 2.0)
    assert differences(changed, compiled) == [key]
    assert differences({k: v for k, v in compiled.items() if k != key}, compiled) == [key]
