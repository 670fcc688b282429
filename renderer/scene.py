"""The Chapter-9 scene: a frozen, validated description of what is rendered.

Every field is checked once, here, when the scene is built; the render code
downstream can then trust its inputs.  Seed names are given in brackets in the
`Scene` docstring (seed §2 and Cell 1, the ``SC9`` dictionary).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from functools import lru_cache

from . import formulas
from .intervals import CHART_CHECK_SIDE, search_chart
from .validate import InvalidType, InvalidValue, _shown, choice, flag, real, vector3

__all__ = ["PointLight", "Scene", "DRAFT_SCENE", "DRAFT_NAMES", "MODELS", "BUMPS"]

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

#: Names accepted for ``Scene.model`` (seed Cell 1, ``shade1``).
MODELS = ("blinn", "phong")
#: Names accepted for ``Scene.bump``: the seed's chart formula, or the normal
#: of the displaced surface P = (R + beta h) N (theorem bump-vs-displacement).
BUMPS = ("chart", "surface")


#: The accepted ranges, as keyword arguments of `renderer.validate.real` (and of
#: `real_array`, `vector3`): one range per kind of quantity, shared by `Scene`,
#: `renderer.pointwise` and `renderer.ucurve`, so that they accept the same values.
COORDINATE = dict(low=-MAX_LENGTH, high=MAX_LENGTH)          # scene units
RADIUS = dict(low=MIN_RADIUS, high=MAX_LENGTH)               # scene units
FREQUENCY = dict(low=0.0, low_open=True, high=MAX_FREQUENCY)  # periods over the chart
UNIT = dict(low=0.0, high=1.0)                               # weights, albedos, chart coordinates
INTENSITY = dict(low=0.0, high=MAX_INTENSITY)                # linear RGB


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
        object.__setattr__(self, "position", vector3("PointLight.position", self.position, **COORDINATE))
        object.__setattr__(self, "color", vector3("PointLight.color", self.color, **INTENSITY))


_DEFAULT_LIGHTS = (
    PointLight((5.0, 5.0, 10.0), (1.0, 1.0, 1.0)),
    PointLight((-6.0, 2.0, 8.0), (0.9, 0.65, 0.25)),
)


@dataclass(frozen=True)
class Scene:
    """The Chapter-9 scene; the defaults are the seed's (Cell 1, ``SC9``) but for the normal.

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

    Bump.  ``height_field`` [hf] is the name of a registered field (one of
    `renderer.formulas.FIELDS`, the seed's "sine", "ridges" and "rings" of §2 among them), a
    `renderer.formulas.HeightField`, or a reader's own field: a sympy expression, or its
    text (``"sin(pi*k_u*u)**2 * sin(pi*k_v*v)**2"``), in u, v and the frequencies
    ``k_u`` [ku] and ``k_v`` [kv] (kept as its printed text); a field other than the
    built-in ones must be finite, with its gradient, on the chart [0, 1]^2 (checked on a grid,
    and between its points by interval arithmetic, `_check_on_chart`).  The chart's edges u = 0
    and u = 1 meet on the sphere (the seam): a field is smooth across it only if it and h_u agree
    there, as sine does for an even ``k_u`` (an odd one creases it there, and a non-integer one
    breaks it).  ``beta`` [beta] >= 0 is the bump amplitude; ``eps`` [eps] > 0 is the central-difference step of the
    numeric pipeline, in chart units (u and v both run over [0, 1]).
    ``bump`` selects the perturbed normal: "surface" (default) is the exact
    normal of the displaced sphere P = (R + beta h) N,
    N' = normalize(N - beta / (R + beta h) (h_u / (2 pi sin phi) e_theta + h_v / pi e_phi)),
    which needs beta < radius_a (|h| <= 1 keeps R + beta h > 0); "chart" is the
    seed's N' = normalize(N + beta (h_u e_theta + h_v e_phi)), the normal of the
    draft's scene `DRAFT_SCENE`.  Every other default is the seed's.

    Raises
    ------
    TypeError
        A field has the wrong type (a string or a bool for a number, a number
        for a flag).  Numbers are accepted as `renderer.validate` says: Python
        or numpy scalars (``np.float32(0.5)``, ``np.int64(3)``) or 0-d arrays;
        vectors as tuples, lists or 1-D arrays of three.
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
        is accepted.  Both are `renderer.validate.InputError`.

    Examples
    --------
    >>> Scene(height_field="sine", beta=0.5).bump
    'surface'
    >>> DRAFT_SCENE.replace(height_field="sine", beta=1.5).bump
    'chart'
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
    bump: str = "surface"

    def __post_init__(self):
        set_ = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        set_("radius_a", real("Scene.radius_a", self.radius_a, **RADIUS))
        set_("camera_z", real("Scene.camera_z", self.camera_z, high=MAX_LENGTH))
        if not self.camera_z > self.radius_a:
            raise InvalidValue(f"Scene.camera_z must be > radius_a = {self.radius_a} (camera outside "
                               f"sphere A), got {self.camera_z!r}")
        set_("center_b", vector3("Scene.center_b", self.center_b, **COORDINATE))
        set_("radius_b", real("Scene.radius_b", self.radius_b, **RADIUS))
        # Camera outside sphere B: the nearest hit is then always a front face.
        d2 = self.center_b[0] ** 2 + self.center_b[1] ** 2 + (self.camera_z - self.center_b[2]) ** 2
        if not d2 > self.radius_b**2:
            raise InvalidValue(f"Scene.radius_b = {self.radius_b!r} puts the camera (0, 0, {self.camera_z}) "
                               f"inside or on sphere B centred at {self.center_b}; the camera must be outside")
        set_("sphere_b", flag("Scene.sphere_b", self.sphere_b))
        set_("floor", flag("Scene.floor", self.floor))
        lights = self.lights
        if isinstance(lights, PointLight):
            raise InvalidType("Scene.lights must be a sequence of PointLight, got a single PointLight")
        if not isinstance(lights, (tuple, list)):
            raise InvalidType(f"Scene.lights must be a tuple of PointLight, got {_shown(lights)}")
        if len(lights) > MAX_LIGHTS:     # each light costs a shadow ray per pixel
            raise InvalidValue(f"Scene.lights holds at most {MAX_LIGHTS} lights, got {len(lights):,}")
        for i, light in enumerate(lights):
            if not isinstance(light, PointLight):
                raise InvalidType(f"Scene.lights[{i}] must be a PointLight, got {_shown(light)}")
        set_("lights", tuple(lights))
        set_("ambient", vector3("Scene.ambient", self.ambient, **INTENSITY))
        set_("albedo_a", vector3("Scene.albedo_a", self.albedo_a, **UNIT))
        set_("albedo_b", vector3("Scene.albedo_b", self.albedo_b, **UNIT))
        for name in ("ka", "kd", "ks", "floor_tint"):
            set_(name, real(f"Scene.{name}", getattr(self, name), **UNIT))
        set_("shininess", real("Scene.shininess", self.shininess, low=MIN_SHININESS, high=MAX_SHININESS))
        set_("model", choice("Scene.model", self.model, MODELS))
        set_("height_field", formulas.field(self.height_field, "Scene.height_field").name)
        set_("k_u", real("Scene.k_u", self.k_u, **FREQUENCY))
        set_("k_v", real("Scene.k_v", self.k_v, **FREQUENCY))
        set_("beta", real("Scene.beta", self.beta, low=0.0, high=MAX_BETA))
        set_("eps", real("Scene.eps", self.eps, low=MIN_EPS, high=MAX_EPS))
        set_("bump", choice("Scene.bump", self.bump, BUMPS))
        if self.height_field not in formulas.BUILTIN:
            _check_on_chart(self)
        if self.bump == "surface" and not self.beta < self.radius_a:
            raise InvalidValue(f"Scene.beta must be < radius_a = {self.radius_a} when bump='surface' (the "
                               f"default; the displaced radius R + beta h must stay positive), got "
                               f"{self.beta!r}; bump='chart' (the draft's normal) accepts beta up to {MAX_BETA:g}")

    @property
    def field(self):
        """The `renderer.formulas.HeightField` record of ``height_field``."""
        return formulas.field(self.height_field)

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
            raise InvalidType(f"Scene has no field(s) {unknown}; fields are {sorted(names)}")
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        values.update(changes)
        return Scene(**values)

    def changes(self) -> dict:
        """The fields that differ from `Scene`'s defaults: the keyword arguments that build
        this scene, so a stored measurement can say which scene it used.

        Returns
        -------
        dict
            {field name: value}; ``Scene(**scene.changes()) == scene``.  JSON-safe (str,
            float, bool, tuples of floats) unless ``lights`` differ (a tuple of `PointLight`).
        """
        default = Scene()
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) != getattr(default, f.name)}


#: Points per side of the grid of the chart [0, 1]^2 on which a field other than the built-in
#: ones is checked when a scene is made (`_check_on_chart`).
CHART_CHECK_POINTS = 65
@lru_cache(maxsize=64)
def _on_chart(field, k_u, k_v):
    """(least h, the grid point (u, v) where it is, the first grid point where h or its gradient is not
    finite and real, or None) on a grid of the chart, numpy float64."""
    import numpy as np
    import sympy as sp
    fn = sp.lambdify(formulas.FIELD_SYMBOLS, [field.expr, *field.gradient], modules="numpy")
    t = np.linspace(0.0, 1.0, CHART_CHECK_POINTS)
    uu, vv = np.meshgrid(t, t)
    with np.errstate(all="ignore"):
        # numpy's frequencies: a term of them alone overflows to inf, where Python's floats raise.
        # A constant sympy cannot tell is complex, (0.5 - pi)**pi, comes out a Python complex.
        values = [np.broadcast_to(a, uu.shape) for a in fn(uu, vv, np.float64(k_u), np.float64(k_v))]
    if any(np.iscomplexobj(a) for a in values):       # a constant: every point alike
        return float("nan"), None, (0.0, 0.0)
    bad = np.argwhere(~np.all([np.isfinite(a) for a in values], axis=0))
    low = np.unravel_index(np.argmin(values[0]), uu.shape)
    where = lambda ij: (float(uu[tuple(ij)]), float(vv[tuple(ij)]))       # noqa: E731
    return float(values[0][low]), where(low), (where(bad[0]) if len(bad) else None)


@lru_cache(maxsize=64)
def _unbounded_near(field, k_u, k_v):
    """The centre (u, v) of a box of the chart (`search_chart`) on which no interval bounds h or its
    gradient within float64's range however small the box: a pole, a jump, an overflow or a point where h
    is not real, between the points of `_on_chart`'s grid too; or None."""
    import math

    def finite(values):
        return values is not None and all(math.isfinite(x.a) and math.isfinite(x.b) for x in values)
    return search_chart([field.expr, *field.gradient], k_u, k_v, finite)


@lru_cache(maxsize=64)
def _dip(field, k_u, k_v, radius_a, beta):
    """(h, (u, v)) at a point of the chart where the displaced radius radius_a + beta h is at or below 0
    (`search_chart`, h evaluated in float64 at box centres), between the points of `_on_chart`'s grid
    too; or None."""
    import sympy as sp
    h = sp.lambdify(formulas.FIELD_SYMBOLS, field.expr, modules="math")
    at = search_chart([field.expr], k_u, k_v, lambda values: values is not None and radius_a + beta * values[0].a > 0,
                      broken=lambda u, v: not radius_a + beta * h(u, v, k_u, k_v) > 0.0)
    return None if at is None else (h(*at, k_u, k_v), at)


def _check_on_chart(scene):
    """A field other than the built-in ones: h and its gradient finite at every point of a
    `CHART_CHECK_POINTS`-square grid of the chart and bounded between them (`_unbounded_near`), and
    with ``bump="surface"`` the displaced radius radius_a + beta h positive on the grid and between
    its points (`_dip_below`)."""
    low, at, bad = _on_chart(scene.field, scene.k_u, scene.k_v)
    where = f"of the chart [0, 1]^2 (k_u = {scene.k_u:g}, k_v = {scene.k_v:g}); it must be at every point"
    if bad is not None:
        raise InvalidValue(f"Scene.height_field {scene.height_field!r} or its gradient is not finite and real at "
                           f"(u, v) = ({bad[0]:.6g}, {bad[1]:.6g}) {where}")
    near = _unbounded_near(scene.field, scene.k_u, scene.k_v)
    if near is not None:
        raise InvalidValue(f"Scene.height_field {scene.height_field!r} or its gradient is not finite and real near "
                           f"(u, v) = ({near[0]:.6g}, {near[1]:.6g}) (no bound on a box of side "
                           f"{CHART_CHECK_SIDE:.2g} there) {where}")
    if scene.bump != "surface":
        return
    if scene.radius_a + scene.beta * low > 0.0:      # on the grid; and between its points:
        low, at = _dip(scene.field, scene.k_u, scene.k_v, scene.radius_a, scene.beta) or (low, at)
    if not scene.radius_a + scene.beta * low > 0.0:
        raise InvalidValue(f"Scene.beta = {scene.beta!r} with height_field {scene.height_field!r} (h = {low:.3g} at "
                           f"(u, v) = ({at[0]:.6g}, {at[1]:.6g})) puts the displaced radius radius_a + beta h at "
                           f"or below 0; bump='surface' needs radius_a + beta h > 0")


#: The draft's scene (seed Cell 1, ``SC9``): its field, frequencies, amplitude and step spelled
#: here, and its own perturbed normal, the chart formula (``bump="chart"``).  Every measurement of
#: a claim or erratum of the draft reads the draft's values from it, never from `Scene`'s defaults
#: (the book's, which may change).
DRAFT_SCENE = Scene(height_field="ridges", k_u=8.0, k_v=4.0, beta=0.35, eps=1e-3, bump="chart")
#: The draft's name (its ``SC9`` keys) of each `Scene` field it has, where the two differ (``bump`` is the
#: renderer's own; the fields not listed keep the draft's names).
DRAFT_NAMES = dict(radius_a="R", camera_z="e", center_b="Cb", radius_b="R2", sphere_b="b_on", floor="floor_on",
                   albedo_a="matA", albedo_b="matB", shininess="shin", floor_tint="alpha", height_field="hf",
                   k_u="ku", k_v="kv")
