"""`renderer.validate`: one function per kind of value, the same acceptance wherever it is used.

Each kind's messages are matched whole (the parameter, what is accepted, the
value).  The same values are then offered to every place that takes a real
scalar (`Scene`, `PointLight`, `renderer.pointwise`, `renderer.ucurve.measure`):
numpy scalars and 0-d arrays pass everywhere, bools, strings and complex numbers
fail everywhere, naming the parameter.  Every documented range of
`renderer.pointwise` is tried at its limit (finite outputs) and one float past
it (refused, with the range).
"""

from __future__ import annotations

import itertools
import math
from fractions import Fraction

import numpy as np
import pytest

from renderer import PointLight, Scene, pointwise
from renderer.scene import COORDINATE, MAX_LENGTH, MIN_RADIUS
from renderer.ucurve import measure
from renderer.validate import (InputError, InvalidType, InvalidValue, choice, flag, positive_int, real,
                               real_array, steps, vector3)

UP, DOWN = math.inf, -math.inf


def past(x, direction):
    """The float next to ``x`` towards ``direction``: one past a limit."""
    return float(np.nextafter(x, direction))


# ------------------------------------------------------------------ the kinds, message by message


@pytest.mark.parametrize("call, error, message", [
    (lambda: real("x", 2.0, low=0.0, high=1.0), InvalidValue, "x must be in [0, 1], got 2.0"),
    (lambda: real("x", 0.0, low=0.0, low_open=True, high=5.0), InvalidValue, "x must be in (0, 5], got 0.0"),
    (lambda: real("x", 1.0, low=0.0, high=1.0, high_open=True), InvalidValue, "x must be in [0, 1), got 1.0"),
    (lambda: real("x", -1.0, low=0.0), InvalidValue, "x must be >= 0, got -1.0"),
    (lambda: real("x", 2.0, high=1.0), InvalidValue, "x must be <= 1, got 2.0"),
    (lambda: real("x", math.inf), InvalidValue, "x must be finite, got inf"),
    (lambda: real("x", np.float32("nan")), InvalidValue, "x must be finite, got np.float32(nan)"),
    (lambda: real("x", -(10**400)), InvalidValue, "x must be finite, got an integer of 401 digits"),
    (lambda: real("x", 10**5000), InvalidValue, "x must be finite, got an integer of more than 4300 digits"),
    (lambda: real("x", True), InvalidType, "x must be a real number, got bool True"),
    (lambda: real("x", "1"), InvalidType, "x must be a real number, got str '1'"),
    (lambda: real("x", 1j), InvalidType, "x must be a real number, got complex 1j"),
    (lambda: real("x", np.array([1.0, 2.0])), InvalidType, "x must be a real number, got ndarray array([1., 2.])"),
    (lambda: real_array("a", [[0.5, 2.0]], low=0.0, high=1.0), InvalidValue,
     "a must be in [0, 1], got 2.0 at flat index 1"),
    (lambda: real_array("a", [0.5, 10**400]), InvalidValue, "a must be finite, got an integer too large for a float"),
    (lambda: real_array("a", np.array([True])), InvalidType,
     "a must be real numbers (a scalar or an array), got ndarray array([ True])"),
    (lambda: real_array("a", "0.5"), InvalidType, "a must be real numbers (a scalar or an array), got str '0.5'"),
    (lambda: real_array("a", [1, [2, 3]]), InvalidType, "a must be real numbers (a scalar or an array), got list [1, [2, 3]]"),
    (lambda: vector3("p", (1.0, 2.0)), InvalidValue, "p must have exactly 3 components, got 2: (1.0, 2.0)"),
    (lambda: vector3("p", (1.0, 2.0, "3")), InvalidType, "p[2] must be a real number, got str '3'"),
    (lambda: vector3("p", (0.0, 2.0, 0.0), low=0.0, high=1.0), InvalidValue, "p[1] must be in [0, 1], got 2.0"),
    (lambda: vector3("p", np.array(0.5)), InvalidType,
     "p must be a sequence of 3 real numbers (a tuple, list or 1-D array), got ndarray array(0.5)"),
    (lambda: vector3("p", "abc"), InvalidType,
     "p must be a sequence of 3 real numbers (a tuple, list or 1-D array), got str 'abc'"),
    (lambda: flag("f", 1), InvalidType, "f must be True or False, got int 1"),
    (lambda: flag("f", "no"), InvalidType, "f must be True or False, got str 'no'"),
    (lambda: choice("c", "Sine", ("sine", "rings")), InvalidValue, "c must be one of ('sine', 'rings'), got 'Sine'"),
    (lambda: choice("c", 1, ("sine",)), InvalidType, "c must be one of ('sine',), got int 1"),
    (lambda: positive_int("n", 0), InvalidValue, "n must be a positive integer, got 0"),
    (lambda: positive_int("n", 9, high=8), InvalidValue, "n must be an integer in [1, 8], got 9"),
    (lambda: positive_int("n", 2.0), InvalidType, "n must be a positive integer, got float 2.0"),
    (lambda: positive_int("n", np.True_), InvalidType, "n must be a positive integer, got bool np.True_"),
    (lambda: steps("e", [], low=0.1, high=1.0), InvalidValue, "e must hold at least one step, got 0"),
    (lambda: steps("e", [0.5] * 3, low=0.1, high=1.0, max_count=2), InvalidValue, "e must hold 1 to 2 steps, got 3"),
    (lambda: steps("e", [0.5, 2.0], low=0.1, high=1.0), InvalidValue, "e must be in [0.1, 1], got 2.0 at flat index 1"),
    (lambda: steps("e", {0.5: 1}, low=0.1, high=1.0), InvalidType,
     "e must be ordered steps (a list, tuple or array), got dict {0.5: 1}"),
])
def test_each_kind_names_the_parameter_the_value_and_what_is_accepted(call, error, message):
    with pytest.raises(InputError) as info:
        call()
    assert (type(info.value), str(info.value)) == (error, message)
    assert isinstance(info.value, ValueError if error is InvalidValue else TypeError)


@pytest.mark.parametrize("call, want", [
    (lambda: real("x", np.float32(0.5), low=0.0, high=1.0), 0.5),
    (lambda: real("x", np.array(3), low=0.0), 3.0),
    (lambda: real("x", Fraction(1, 4)), 0.25),
    (lambda: real("x", 1.0, low=0.0, high=1.0), 1.0),
    (lambda: flag("f", np.array(True)), True),
    (lambda: positive_int("n", np.int64(8), high=8), 8),
    (lambda: vector3("p", np.array([1, 2, 3])), (1.0, 2.0, 3.0)),
])
def test_numpy_scalars_and_0d_arrays_are_plain_values(call, want):
    got = call()
    assert got == want and type(got) is type(want)


# ------------------------------------------------------------------ the same acceptance everywhere


#: Each place that takes a real scalar: (parameter named in its messages, a call with the value).
SCALAR_SITES = {
    "Scene.beta": lambda x: Scene(beta=x),
    "Scene.floor_tint": lambda x: Scene(floor_tint=x),
    "Scene.center_b[0]": lambda x: Scene(center_b=(x, 0.5, 1.3)),
    "PointLight.color[1]": lambda x: PointLight(color=(1.0, x, 1.0)),
    "u": lambda x: measure(u=x, eps=[1e-3]),
    "k_v": lambda x: measure(k_v=x, eps=[1e-3]),
}
#: Places that take arrays (a scalar among them): the same scalars pass and fail.
ARRAY_SITES = {
    "v": lambda x: pointwise.height("sine", 0.3, x, 8, 4),
    "eps": lambda x: pointwise.central_gradient("sine", 0.3, 0.4, 8, 4, x),
    "sin_phi": lambda x: pointwise.tangent_frame(0.6, 0.0, 0.8, x),
}
ACCEPTED = [0.5, np.float32(0.5), np.float16(0.5), np.float64(0.5), np.array(0.5), Fraction(1, 2), np.int64(0) + 0.5]
REFUSED = [True, np.True_, np.array(True), "0.5", 0.5 + 0j, np.complex64(0.5), None]


@pytest.mark.parametrize("value", ACCEPTED, ids=repr)
@pytest.mark.parametrize("site", [*SCALAR_SITES, *ARRAY_SITES])
def test_every_place_accepts_numpy_scalars(site, value):
    {**SCALAR_SITES, **ARRAY_SITES}[site](value)


@pytest.mark.parametrize("value", REFUSED, ids=repr)
@pytest.mark.parametrize("site", [*SCALAR_SITES, *ARRAY_SITES])
def test_every_place_refuses_bools_strings_and_complex_numbers_by_name(site, value):
    with pytest.raises(TypeError) as info:
        {**SCALAR_SITES, **ARRAY_SITES}[site](value)
    kind = "a real number" if site in SCALAR_SITES else "real numbers (a scalar or an array)"
    assert str(info.value).startswith(f"{site} must be {kind}, got ") and isinstance(info.value, InputError)


@pytest.mark.parametrize("site", [*SCALAR_SITES, *ARRAY_SITES])
def test_every_place_refuses_an_integer_too_large_for_a_float_as_a_value_error(site):
    with pytest.raises(ValueError, match=rf"^{site.replace('[', '.').replace(']', '.')} must be .*, got an integer"):
        {**SCALAR_SITES, **ARRAY_SITES}[site](10**400)


# ------------------------------------------------------------------ pointwise: every range at its limit and one past


#: Each function with arguments inside every range.
CALLS = {
    "height": (pointwise.height, dict(name="sine", u=0.3, v=0.4, k_u=8.0, k_v=4.0)),
    "exact_gradient": (pointwise.exact_gradient, dict(name="ridges", u=0.3, v=0.4, k_u=8.0, k_v=4.0)),
    "kink_band": (pointwise.kink_band, dict(name="ridges", u=0.3, v=0.4, k_u=8.0, k_v=4.0)),
    "central_gradient": (pointwise.central_gradient,
                         dict(name="ridges", u=0.3, v=0.4, k_u=8.0, k_v=4.0, eps=1e-3, eps_v=1e-3)),
    "chart": (pointwise.chart, dict(N_x=0.6, N_y=0.0, N_z=0.8)),
    "tangent_frame": (pointwise.tangent_frame, dict(N_x=0.6, N_y=0.0, N_z=0.8, sin_phi=0.6)),
    "footprint": (pointwise.footprint, dict(x=0.1, y=0.1, dx=0.01, dy=0.01, camera_z=4.0, P=(0.1, 0.1, 0.99),
                                            N=(0.1, 0.1, 0.99), e_theta=(1.0, 0.0, 0.0), e_phi=(0.0, 1.0, 0.0),
                                            radius=1.0, sin_phi=0.14)),
}
STEP_LOW, STEP_HIGH = pointwise.MIN_STEP, past(1.0, DOWN)
#: (function, argument, the limit, one past it, the range as the message states it).
LIMITS = [
    *[(f, a, lim, past(lim, d), "[-1, 2]") for f in ("height", "exact_gradient", "kink_band")
      for a in ("u", "v") for lim, d in ((-1.0, DOWN), (2.0, UP))],
    *[(f, a, lim, p, "(0, 1000]") for f in ("height", "exact_gradient", "kink_band", "central_gradient")
      for a in ("k_u", "k_v") for lim, p in ((5e-324, 0.0), (1e3, past(1e3, UP)))],
    *[("central_gradient", a, lim, past(lim, d), "[0, 1]") for a in ("u", "v") for lim, d in ((0.0, DOWN), (1.0, UP))],
    *[("central_gradient", a, lim, p, "[1e-300, 1)") for a in ("eps", "eps_v")
      for lim, p in ((STEP_LOW, past(STEP_LOW, DOWN)), (STEP_HIGH, 1.0))],
    *[("chart", a, lim, past(lim, lim * UP), "[-1e+06, 1e+06]") for a in ("N_x", "N_z") for lim in (-1e6, 1e6)],
    *[("tangent_frame", a, lim, past(lim, lim * UP), "[-1e+06, 1e+06]") for a in ("N_y", "sin_phi")
      for lim in (-1e6, 1e6)],
    *[("footprint", a, lim, past(lim, lim * UP), "[-1e+06, 1e+06]") for a in ("x", "dy", "camera_z", "sin_phi")
      for lim in (-1e6, 1e6)],
    *[("footprint", "radius", lim, past(lim, d), "[1e-06, 1e+06]") for lim, d in ((MIN_RADIUS, DOWN), (MAX_LENGTH, UP))],
]


def call(function, **change):
    fn, kwargs = CALLS[function]
    kwargs = {**kwargs, **change}
    return fn(kwargs.pop("name"), **kwargs) if "name" in kwargs else fn(**kwargs)


def all_finite(result):
    """Whether every array of a pointwise result (an array, or nested tuples of them) is finite."""
    if isinstance(result, tuple):
        return all(all_finite(item) for item in result)
    return bool(np.all(np.isfinite(np.asarray(result, dtype=float))))


@pytest.mark.parametrize("function, argument, limit, beyond, accepted", LIMITS,
                         ids=[f"{f}-{a}-{lim:g}" for f, a, lim, _, _ in LIMITS])
def test_pointwise_ranges_at_the_limit_and_one_past(function, argument, limit, beyond, accepted):
    assert all_finite(call(function, **{argument: limit}))
    with pytest.raises(ValueError) as info:
        call(function, **{argument: beyond})
    assert str(info.value) == f"{argument} must be in {accepted}, got {beyond!r} at flat index 0"


def ends(name, ranges=pointwise.RANGES):
    """The extreme values ``name`` accepts, read from `renderer.pointwise.RANGES`
    (`renderer.scene.COORDINATE` for the names it does not list)."""
    r = ranges.get(name, COORDINATE)
    low = past(r["low"], UP) if r.get("low_open") else r["low"]
    high = past(r["high"], DOWN) if r.get("high_open") else r["high"]
    return low, high


def test_pointwise_outputs_are_finite_at_every_corner_of_the_ranges():
    """All arguments at the ends of their ranges at once (and at the tangent frame's
    pole cut-off): the ranges are read from the module, so a wider one is tried too."""
    central = pointwise.RANGES_CENTRAL
    for name in ("sine", "ridges", "rings"):
        grid = itertools.product(*(ends(a) for a in ("u", "v", "k_u", "k_v")))
        u, v, ku, kv = (np.array(c) for c in zip(*grid))
        for fn in (pointwise.height, pointwise.exact_gradient):
            assert all_finite(fn(name, u, v, ku, kv))
        grid = itertools.product((*ends("u", central), 0.5), (*ends("v", central), past(1.0, DOWN), 0.5),
                                 ends("k_u"), ends("k_v"), (*ends("eps"), 1e-16), (*ends("eps_v", central), 1e-16))
        assert all_finite(pointwise.central_gradient(name, *(np.array(c) for c in zip(*grid))))
    low, high = ends("N_x")
    edges = np.array([low, -1.0, 0.0, 1.0, high])
    n = np.array(list(itertools.product(edges, repeat=3))).T
    assert all_finite(pointwise.chart(*n))
    for s in (low, 0.0, 1e-4, past(1e-4, UP), high):
        assert all_finite(pointwise.tangent_frame(*n, s))
    rng = np.random.default_rng(7)
    pick = lambda: rng.choice(np.concatenate([edges, rng.uniform(low, high, 5)]), 4000)  # noqa: E731
    triple = lambda: (pick(), pick(), pick())  # noqa: E731
    got = pointwise.footprint(pick(), pick(), pick(), pick(), pick(), triple(), triple(), triple(), triple(),
                              rng.choice([*ends("radius"), 1.0], 4000), pick())
    assert all_finite(got)
