"""The Chapter-9 scene: a frozen, validated description of what is rendered.

Every field is checked once, here, when the scene is built; the render code
downstream can then trust its inputs.  Seed names are given in brackets in the
`Scene` docstring (seed §2 and Cell 1, the ``SC9`` dictionary).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, fields

import numpy as np

__all__ = ["PointLight", "Scene", "HEIGHT_FIELDS", "MODELS", "BUMPS", "frame_label"]

#: Largest accepted magnitude of a length or coordinate (scene units): squares of
#: lengths are formed everywhere, and 1e6 keeps them far from overflow.
MAX_LENGTH = 1e6
#: Smallest accepted radius (scene units), far from underflow of R^2.
MIN_RADIUS = 1e-6
#: Largest accepted frequency k_u, k_v (periods over the chart): 1000 periods
#: over u are more than a pixel each even at 8192 pixels across, and keep the
#: phase pi k u small enough that a sine's argument reduction loses nothing.
MAX_FREQUENCY = 1e3
#: Largest accepted bump amplitude beta: at 100 the chart bump tilts every
#: normal with |grad h| >= 0.01 by 45 degrees or more; beyond it the image no
#: longer changes in any way that means something.
MAX_BETA = 100.0
#: Accepted central-difference steps eps (chart units).  Below 1e-16 the step
#: no longer moves every chart point (half an ulp of u just below 1 is 2^-54,
#: about 5.6e-17, so u + 1e-16 != u still holds on all of [0, 1)); at 0.5 the
#: two samples u +- eps wrap onto the same point of the periodic u, and 0.25
#: keeps them at least a quarter period apart.
MIN_EPS, MAX_EPS = 1e-16, 0.25
#: Largest accepted light colour or ambient component (linear RGB): 1000
#: times the default white light already saturates every lit pixel.
MAX_INTENSITY = 1e3
#: Most lights a scene may hold (the draft's has two; each is a shadow ray per pixel).
MAX_LIGHTS = 16
#: Accepted Blinn/Phong exponents: n >= 1 keeps the lobe inside the cosine
#: lobe (n < 1 widens it towards a step at the horizon); at 1e4 the Blinn
#: highlight's half-width, acos(2^(-1/n)) between N and the half vector, is
#: about 0.7 degrees, already close to a mirror's.
MIN_SHININESS, MAX_SHININESS = 1.0, 1e4

#: Names accepted for ``Scene.height_field`` (seed §2).
HEIGHT_FIELDS = ("sine", "ridges", "rings")
#: Names accepted for ``Scene.model`` (seed Cell 1, ``shade1``).
MODELS = ("blinn", "phong")
#: Names accepted for ``Scene.bump``: the seed's chart formula, or the normal
#: of the displaced surface P = (R + beta h) N (theorem bump-vs-displacement).
BUMPS = ("chart", "surface")


def _real(owner: str, name: str, value, *, low=None, low_open=False, high=None):
    """Return ``value`` as a finite float, or raise naming ``owner.name``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(
            f"{owner}.{name} must be a real number, got {type(value).__name__} {value!r}"
        )
    try:
        x = float(value)
    except OverflowError:                      # an integer beyond float64's range
        raise ValueError(f"{owner}.{name} must be finite, got an integer of "
                         f"{len(str(abs(int(value))))} digits") from None
    if not math.isfinite(x):
        raise ValueError(f"{owner}.{name} must be finite, got {value!r}")
    below = low is not None and (x <= low if low_open else x < low)
    if below or (high is not None and x > high):
        if low is not None and high is not None:
            accepted = f"in {'(' if low_open else '['}{low:g}, {high:g}]"
        elif low is not None:
            accepted = f"{'>' if low_open else '>='} {low:g}"
        else:
            accepted = f"<= {high:g}"
        raise ValueError(f"{owner}.{name} must be {accepted}, got {value!r}")
    return x


def _vec3(owner: str, name: str, value, *, nonneg=False, high=None, low=None):
    """Return ``value`` as a tuple of three finite floats, or raise."""
    if not isinstance(value, (tuple, list, np.ndarray)):
        raise TypeError(
            f"{owner}.{name} must be a sequence of 3 real numbers, got {value!r}"
        )
    if len(value) != 3:
        raise ValueError(
            f"{owner}.{name} must have exactly 3 components, got {len(value)}: {value!r}"
        )
    low = 0.0 if nonneg else low
    return tuple(
        _real(owner, f"{name}[{i}]", c, low=low, high=high) for i, c in enumerate(value)
    )


def _flag(owner: str, name: str, value):
    if not isinstance(value, bool):
        raise TypeError(f"{owner}.{name} must be True or False, got {value!r}")
    return value


def _choice(owner: str, name: str, value, accepted):
    if not isinstance(value, str):
        raise TypeError(f"{owner}.{name} must be a string, one of {accepted}, got {value!r}")
    if value not in accepted:
        raise ValueError(f"{owner}.{name} must be one of {accepted}, got {value!r}")
    return value


@dataclass(frozen=True)
class PointLight:
    """A point light (seed Cell 1, ``SC9['lights']``).

    Parameters
    ----------
    position : sequence of 3 floats
        World position of the light (same units as the scene radii).
    color : sequence of 3 floats, each in [0, 1e3]
        Linear-RGB radiant intensity.  A light whose colour is (0, 0, 0)
        contributes nothing.

    Raises
    ------
    TypeError, ValueError
        If a component is not a finite real number, a position component is
        above 1e6 in magnitude, or a colour component is outside [0, 1e3].
    """

    position: tuple = (5.0, 5.0, 10.0)
    color: tuple = (1.0, 1.0, 1.0)

    def __post_init__(self):
        object.__setattr__(self, "position", _vec3("PointLight", "position", self.position,
                                                   low=-MAX_LENGTH, high=MAX_LENGTH))
        object.__setattr__(self, "color", _vec3("PointLight", "color", self.color, nonneg=True,
                                                high=MAX_INTENSITY))


_DEFAULT_LIGHTS = (
    PointLight((5.0, 5.0, 10.0), (1.0, 1.0, 1.0)),
    PointLight((-6.0, 2.0, 8.0), (0.9, 0.65, 0.25)),
)


@dataclass(frozen=True)
class Scene:
    """The Chapter-9 scene; the defaults are the seed's (Cell 1, ``SC9``).

    Geometry.  Sphere A (radius ``radius_a`` [R]) is centred at the origin and
    carries the bump.  The pinhole camera sits at ``(0, 0, camera_z)`` [e] and
    looks down the -z axis at the image plane z = 0, which is also the floor
    plane.  Sphere B has centre ``center_b`` [Cb] and radius ``radius_b`` [R2]
    and is drawn when ``sphere_b`` [b_on]; the checker floor when ``floor``
    [floor_on].

    Shading.  ``lights`` [lights] is a tuple of `PointLight`.  ``ambient``
    [ambient] times ``ka`` is added everywhere; ``kd``, ``ks`` and
    ``shininess`` [shin] weight Lambert and ``model`` ("blinn" or "phong")
    terms.  ``albedo_a`` [matA] and ``albedo_b`` [matB] are the sphere
    albedos; ``floor_tint`` [alpha] in [0, 1] removes that fraction of red and
    green from the floor's checker squares.

    Bump.  ``height_field`` [hf] is one of "sine", "ridges", "rings" with
    frequencies ``k_u`` [ku] and ``k_v`` [kv] (seed §2); ``beta`` [beta] >= 0 is
    the bump amplitude; ``eps`` [eps] > 0 is the central-difference step of the
    numeric pipeline, in chart units (u and v both run over [0, 1]).
    ``bump`` selects the perturbed normal: "chart" (default) is the seed's
    N' = normalize(N + beta (h_u e_theta + h_v e_phi)); "surface" is the exact
    normal of the displaced sphere P = (R + beta h) N,
    N' = normalize(N - beta / (R + beta h) (h_u / (2 pi sin phi) e_theta + h_v / pi e_phi)),
    which needs beta < radius_a (|h| <= 1 keeps R + beta h > 0).

    Raises
    ------
    TypeError
        A field has the wrong type (a string for a number, a number for a flag).
    ValueError
        A field is out of its range, each chosen to mean something (see the
        module constants for why): every number finite; radii in [1e-6, 1e6]
        and coordinates in [-1e6, 1e6] (scene units); the camera outside
        sphere A and sphere B; ``ka``, ``kd``, ``ks``, ``floor_tint`` and
        albedos in [0, 1]; ``ambient`` and light colours in [0, 1e3];
        ``shininess`` in [1, 1e4]; ``k_u``, ``k_v`` in (0, 1e3]; ``beta`` in
        [0, 100] (and < ``radius_a`` for ``bump="surface"``); ``eps`` in
        [1e-16, 0.25] chart units; ``model``, ``height_field`` and ``bump``
        one of their names.  The message names the field, the value and what
        is accepted.

    Examples
    --------
    >>> Scene(height_field="sine", beta=1.5).beta
    1.5
    """

    radius_a: float = 1.0
    camera_z: float = 4.0
    center_b: tuple = (0.5, 0.5, 1.3)
    radius_b: float = 0.32
    sphere_b: bool = True
    floor: bool = True
    lights: tuple = field(default=_DEFAULT_LIGHTS)
    ambient: tuple = (0.15, 0.15, 0.16)
    albedo_a: tuple = (0.63, 0.19, 0.16)
    albedo_b: tuple = (0.33, 0.44, 0.62)
    ka: float = 0.1
    kd: float = 0.7
    ks: float = 0.5
    shininess: float = 32.0
    model: str = "blinn"
    floor_tint: float = 0.25
    height_field: str = "ridges"
    k_u: float = 8.0
    k_v: float = 4.0
    beta: float = 0.35
    eps: float = 1e-3
    bump: str = "chart"

    def __post_init__(self):
        set_ = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        S = "Scene"
        set_("radius_a", _real(S, "radius_a", self.radius_a, low=MIN_RADIUS, high=MAX_LENGTH))
        set_("camera_z", _real(S, "camera_z", self.camera_z, high=MAX_LENGTH))
        if not self.camera_z > self.radius_a:
            raise ValueError(
                f"Scene.camera_z must be > radius_a = {self.radius_a} (camera outside "
                f"sphere A), got {self.camera_z!r}"
            )
        set_("center_b", _vec3(S, "center_b", self.center_b, low=-MAX_LENGTH, high=MAX_LENGTH))
        set_("radius_b", _real(S, "radius_b", self.radius_b, low=MIN_RADIUS, high=MAX_LENGTH))
        # Camera outside sphere B: the nearest hit is then always a front face.
        d2 = self.center_b[0] ** 2 + self.center_b[1] ** 2 + (self.camera_z - self.center_b[2]) ** 2
        if not d2 > self.radius_b**2:
            raise ValueError(
                f"Scene.radius_b = {self.radius_b!r} puts the camera (0, 0, {self.camera_z}) "
                f"inside or on sphere B centred at {self.center_b}; the camera must be outside"
            )
        set_("sphere_b", _flag(S, "sphere_b", self.sphere_b))
        set_("floor", _flag(S, "floor", self.floor))
        lights = self.lights
        if isinstance(lights, PointLight):
            raise TypeError("Scene.lights must be a sequence of PointLight, got a single PointLight")
        if not isinstance(lights, (tuple, list)):
            raise TypeError(f"Scene.lights must be a tuple of PointLight, got {lights!r:.80}")
        if len(lights) > MAX_LIGHTS:     # each light costs a shadow ray per pixel
            raise ValueError(f"Scene.lights holds at most {MAX_LIGHTS} lights, got {len(lights):,}")
        for i, light in enumerate(lights):
            if not isinstance(light, PointLight):
                raise TypeError(f"Scene.lights[{i}] must be a PointLight, got {light!r}")
        set_("lights", tuple(lights))
        set_("ambient", _vec3(S, "ambient", self.ambient, nonneg=True, high=MAX_INTENSITY))
        set_("albedo_a", _vec3(S, "albedo_a", self.albedo_a, nonneg=True, high=1.0))
        set_("albedo_b", _vec3(S, "albedo_b", self.albedo_b, nonneg=True, high=1.0))
        for name in ("ka", "kd", "ks"):
            set_(name, _real(S, name, getattr(self, name), low=0.0, high=1.0))
        set_("shininess", _real(S, "shininess", self.shininess, low=MIN_SHININESS, high=MAX_SHININESS))
        set_("model", _choice(S, "model", self.model, MODELS))
        set_("floor_tint", _real(S, "floor_tint", self.floor_tint, low=0.0, high=1.0))
        set_("height_field", _choice(S, "height_field", self.height_field, HEIGHT_FIELDS))
        set_("k_u", _real(S, "k_u", self.k_u, low=0.0, low_open=True, high=MAX_FREQUENCY))
        set_("k_v", _real(S, "k_v", self.k_v, low=0.0, low_open=True, high=MAX_FREQUENCY))
        set_("beta", _real(S, "beta", self.beta, low=0.0, high=MAX_BETA))
        set_("eps", _real(S, "eps", self.eps, low=MIN_EPS, high=MAX_EPS))
        set_("bump", _choice(S, "bump", self.bump, BUMPS))
        if self.bump == "surface" and not self.beta < self.radius_a:
            raise ValueError(
                f"Scene.beta must be < radius_a = {self.radius_a} when bump='surface' (the "
                f"displaced radius R + beta h must stay positive), got {self.beta!r}"
            )

    def replace(self, **changes) -> "Scene":
        """Return a copy with ``changes`` applied (and validated).

        Raises
        ------
        TypeError
            If a keyword is not a Scene field.
        """
        names = {f.name for f in fields(self)}
        unknown = sorted(set(changes) - names)
        if unknown:
            raise TypeError(f"Scene has no field(s) {unknown}; fields are {sorted(names)}")
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        values.update(changes)
        return Scene(**values)


def frame_label(scene, width, height) -> str:
    """The label a number measured on a render carries: its scene and resolution, in words.

    ``"the draft's scene, 256 × 256"``, or with the fields that differ from
    `renderer.Scene`'s defaults (the draft's scene): ``"the draft's scene with the
    sine field, β = 1.5, 64 × 64"``.  ``scene`` is a `renderer.Scene`; ``width``,
    ``height`` in pixels.

    Raises
    ------
    TypeError
        ``scene`` is not a `renderer.Scene`.
    ValueError
        ``width`` or ``height`` is not a positive integer.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a renderer.Scene, got {type(scene).__name__}")
    for name, n in (("width", width), ("height", height)):
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"{name} must be a positive integer number of pixels, got {n!r}")
    default = Scene()
    changed = [_field_words(f.name, getattr(scene, f.name)) for f in fields(Scene)
               if getattr(scene, f.name) != getattr(default, f.name)]
    return "the draft's scene" + (" with " + ", ".join(changed) if changed else "") + f", {width} × {height}"


#: How `frame_label` words a field of `renderer.Scene` that differs from the draft's.
_WORDS = {"height_field": "the {} field", "beta": "β = {:g}", "eps": "ε = {:g}", "k_u": "kᵤ = {:g}",
          "k_v": "kᵥ = {:g}", "radius_a": "R = {:g}", "model": "{} shading", "shininess": "shininess {:g}"}


def _field_words(name, value):
    if name == "bump":
        return {"surface": "the displaced sphere's normal", "chart": "the draft's normal"}[value]
    if name in ("sphere_b", "floor") and isinstance(value, bool):
        return f"{'with' if value else 'no'} {'sphere B' if name == 'sphere_b' else name}"
    return _WORDS.get(name, name.replace("_", " ") + " {}").format(value)
