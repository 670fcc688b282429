"""`renderer.validate`: one function per kind of value, each tested once here.

Each kind accepts what its docstring accepts (numpy scalars and 0-d arrays as plain
values) and refuses the rest, each refusal matched on the parameter's name and the
essential phrase only (the wording around them is free), and once per kind on how it
shows the value it got (`SHOWN`).  Who calls which kind is
wiring, tested once per caller: `Scene` and `PointLight` in tests/test_scene_validation.py,
`renderer.ucurve.measure` in tests/test_ucurve_args.py, `renderer.pointwise` below (each
function's arguments at their range's ends, and one float past them).
"""

from __future__ import annotations

import inspect
import itertools
import math
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from renderer import formulas as F
from renderer import pointwise
from renderer.scene import COORDINATE
from renderer.validate import (MAX_EXPRESSION_CHARS, MAX_THREADS, InputError, InvalidType, InvalidValue, choice,
                               expression, flag, positive_int, real, real_array, steps, thread_count, vector3)

UP, DOWN = math.inf, -math.inf


def past(x, direction):
    """The float next to ``x`` towards ``direction``: one past a limit."""
    return float(np.nextafter(x, direction))


def refusal(call):
    """(type, message) of the InputError ``call()`` raises."""
    with pytest.raises(InputError) as info:
        call()
    assert isinstance(info.value, ValueError if isinstance(info.value, InvalidValue) else TypeError)
    return type(info.value), str(info.value)


#: kind: [(call, error, parameter named first, essential phrase)].
REFUSED = {
    "real": [
        (lambda: real("x", 2.0, low=0.0, high=1.0), InvalidValue, "x", "must be in [0, 1]"),
        (lambda: real("x", 0.0, low=0.0, low_open=True, high=5.0), InvalidValue, "x", "must be in (0, 5]"),
        (lambda: real("x", 1.0, low=0.0, high=1.0, high_open=True), InvalidValue, "x", "must be in [0, 1)"),
        (lambda: real("x", -1.0, low=0.0), InvalidValue, "x", "must be >= 0"),
        (lambda: real("x", np.float32("nan")), InvalidValue, "x", "must be finite"),
        (lambda: real("x", -(10**400)), InvalidValue, "x", "integer of 401 digits"),
        (lambda: real("x", True), InvalidType, "x", "must be a real number"),
        (lambda: real("x", "1"), InvalidType, "x", "must be a real number"),
        (lambda: real("x", 1j), InvalidType, "x", "must be a real number"),
        (lambda: real("x", np.array([1.0, 2.0])), InvalidType, "x", "must be a real number"),
    ],
    "real_array": [
        (lambda: real_array("a", [[0.5, 2.0]], low=0.0, high=1.0), InvalidValue, "a", "at flat index 1"),
        (lambda: real_array("a", [0.5, 10**400]), InvalidValue, "a", "too large for a float"),
        (lambda: real_array("a", np.array([True])), InvalidType, "a", "must be real numbers"),
        (lambda: real_array("a", "0.5"), InvalidType, "a", "must be real numbers"),
        (lambda: real_array("a", [1, [2, 3]]), InvalidType, "a", "must be real numbers"),
        (lambda: real_array("a", np.array([0.5, True], dtype=object)), InvalidType, "a", "must be real numbers"),
        (lambda: real_array("a", [True, 0.5]), InvalidType, "a", "not bools"),       # numpy reads [1.0, 0.5]
        (lambda: real_array("a", [np.array([True]), np.array([0.5])]), InvalidType, "a", "not bools"),
        (lambda: real_array("a", np.ma.masked_array([0.2, 0.5], mask=[True, False])), InvalidType, "a",
         "masked array"),                                                            # numpy drops the mask
    ],
    "vector3": [
        (lambda: vector3("p", (1.0, 2.0)), InvalidValue, "p", "exactly 3 components"),
        (lambda: vector3("p", (1.0, 2.0, "3")), InvalidType, "p[2]", "must be a real number"),
        (lambda: vector3("p", (0.0, 2.0, 0.0), low=0.0, high=1.0), InvalidValue, "p[1]", "must be in [0, 1]"),
        (lambda: vector3("p", np.array(0.5)), InvalidType, "p", "sequence of 3 real numbers"),
        (lambda: vector3("p", {0.5, 1.3, 2.0}), InvalidType, "p", "sequence of 3 real numbers"),
        (lambda: vector3("p", [10**5000, 0.0]), InvalidValue, "p", "integer of more than"),   # repr would raise
    ],
    "flag": [
        (lambda: flag("f", 1), InvalidType, "f", "must be True or False"),
        (lambda: flag("f", "no"), InvalidType, "f", "must be True or False"),
    ],
    "choice": [
        (lambda: choice("c", "Sine", ("sine", "rings")), InvalidValue, "c", "must be one of"),
        (lambda: choice("c", 1, ("sine",)), InvalidType, "c", "must be one of"),
    ],
    "positive_int": [
        (lambda: positive_int("n", 0), InvalidValue, "n", "positive integer"),
        (lambda: positive_int("n", 9, high=8), InvalidValue, "n", "integer in [1, 8]"),
        (lambda: positive_int("n", 2.0), InvalidType, "n", "positive integer"),
        (lambda: positive_int("n", np.True_), InvalidType, "n", "positive integer"),
    ],
    "steps": [
        (lambda: steps("e", [], low=0.1, high=1.0), InvalidValue, "e", "at least one step"),
        (lambda: steps("e", [0.5] * 3, low=0.1, high=1.0, max_count=2), InvalidValue, "e", "1 to 2 steps"),
        (lambda: steps("e", [0.5, 2.0], low=0.1, high=1.0), InvalidValue, "e", "at flat index 1"),
        (lambda: steps("e", [1.0], low=0.1, high=1.0, high_open=True), InvalidValue, "e", "must be in [0.1, 1)"),
        (lambda: steps("e", {0.5: 1}, low=0.1, high=1.0), InvalidType, "e", "ordered steps"),
    ],
    "thread_count": [
        (lambda: thread_count("T", "100000"), InvalidValue, "T", f"integer in [1, {MAX_THREADS}]"),   # segfaulted
        (lambda: thread_count("T", "0"), InvalidValue, "T", "integer in [1, "),
        (lambda: thread_count("T", "abc"), InvalidValue, "T", "integer in [1, "),
        (lambda: thread_count("T", True), InvalidValue, "T", "integer in [1, "),
        (lambda: thread_count("T", 10**5000), InvalidValue, "T", "integer of 16,610 bits"),
    ],
    "expression": [
        (lambda: expression("f", "u + w", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "'w' is not one of its names"),
        (lambda: expression("f", "u.__class__", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "'.' is not one of its operators"),
        (lambda: expression("f", "__import__('os')", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "is not one of its names"),
        (lambda: expression("f", "u // 2", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "'//' is not one of its operators"),
        (lambda: expression("f", "u < v", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "'<' is not one of its operators"),
        (lambda: expression("f", "2j*u", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "imaginary"),
        (lambda: expression("f", "I*u", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "'I' is not one of its names"),
        (lambda: expression("f", "u" + " " * MAX_EXPRESSION_CHARS, F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f",
         f"1 to {MAX_EXPRESSION_CHARS} characters, got {MAX_EXPRESSION_CHARS + 1}"),
        (lambda: expression("f", "u +", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "is not one"),
        (lambda: expression("f", "(u", F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidValue, "f", "does not parse"),
        (lambda: expression("f", 3, F.FIELD_SYMBOLS, F.ELEMENTARY), InvalidType, "f", "must be a string"),
    ],
}
#: kind: [(call, the value returned)], type included.
ACCEPTED = {
    "real": [(lambda: real("x", np.float32(0.5), low=0.0, high=1.0), 0.5), (lambda: real("x", np.array(3), low=0.0), 3.0),
             (lambda: real("x", Fraction(1, 4)), 0.25), (lambda: real("x", 1.0, low=0.0, high=1.0), 1.0)],
    "real_array": [(lambda: real_array("a", [[1, 2]]).tolist(), [[1.0, 2.0]]),
                   (lambda: real_array("a", np.array([Fraction(1, 2), 10**20], dtype=object)).tolist(), [0.5, 1e20]),
                   (lambda: str(real_array("a", np.arange(3, dtype=np.int8)).dtype), "float64")],
    "vector3": [(lambda: vector3("p", np.array([1, 2, 3])), (1.0, 2.0, 3.0)), (lambda: vector3("p", [0, 0, 1]), (0.0, 0.0, 1.0))],
    "flag": [(lambda: flag("f", np.array(True)), True), (lambda: flag("f", np.False_), False)],
    "choice": [(lambda: choice("c", "rings", ("sine", "rings")), "rings")],
    "positive_int": [(lambda: positive_int("n", np.int64(8), high=8), 8), (lambda: positive_int("n", np.array(3)), 3)],
    "thread_count": [(lambda: thread_count("T", " 4"), 4), (lambda: thread_count("T", MAX_THREADS), MAX_THREADS)],
    "steps": [(lambda: steps("e", np.float32(0.5), low=0.1, high=1.0).tolist(), [0.5]),
              (lambda: steps("e", [0.5, 1.0], low=0.1, high=1.0, max_count=2).tolist(), [0.5, 1.0])],
    "expression": [(lambda: expression("f", "sin(pi*k_u*u)^2 * sin(pi*k_v*v)**2", F.FIELD_SYMBOLS, F.ELEMENTARY),
                    sp.sin(sp.pi * F.k_u * F.u) ** 2 * sp.sin(sp.pi * F.k_v * F.v) ** 2),
                   (lambda: expression("f", "abs(u - 1/2) + sqrt(E*v)", F.FIELD_SYMBOLS, F.ELEMENTARY),
                    sp.Abs(F.u - sp.Rational(1, 2)) + sp.sqrt(sp.E * F.v)),
                   (lambda: expression("f", "u" + " " * (MAX_EXPRESSION_CHARS - 1), F.FIELD_SYMBOLS, F.ELEMENTARY), F.u)],
}
#: kind: a refusal and how its message ends: the value it got, with its type where the type is the fault.
SHOWN = {
    "real": (lambda: real("x", "1"), "got str '1'"),
    "real_array": (lambda: real_array("a", "0.5"), "got str '0.5'"),
    "vector3": (lambda: vector3("p", (1.0, 2.0, "3")), "got str '3'"),
    "flag": (lambda: flag("f", 1), "got int 1"),
    "choice": (lambda: choice("c", "Sine", ("sine", "rings")), "got 'Sine'"),
    "positive_int": (lambda: positive_int("n", 2.0), "got float 2.0"),
    "steps": (lambda: steps("e", {0.5: 1}, low=0.1, high=1.0), "got dict {0.5: 1}"),
    "expression": (lambda: expression("f", 3, F.FIELD_SYMBOLS, F.ELEMENTARY), "got int 3"),
    "thread_count": (lambda: thread_count("T", "100000"), "got '100000'"),
}


@pytest.mark.parametrize("kind", REFUSED)
def test_each_kind_refuses_naming_the_parameter(kind):
    assert {fn.__name__ for fn in (real, real_array, vector3, flag, choice, positive_int, steps, expression,
                                   thread_count)} \
        == set(REFUSED) == set(ACCEPTED)
    for call, error, name, phrase in REFUSED[kind]:
        got, message = refusal(call)
        assert got is error and message.startswith(f"{name} ") and phrase in message, message


@pytest.mark.parametrize("kind", ACCEPTED)
def test_each_kind_accepts_and_returns_plain_values(kind):
    for call, want in ACCEPTED[kind]:
        got = call()
        assert got == want and type(got) is type(want), (got, want)


@pytest.mark.parametrize("kind", SHOWN)
def test_each_kind_names_the_value_it_refused(kind):
    assert set(SHOWN) == set(REFUSED)
    call, tail = SHOWN[kind]
    assert refusal(call)[1].endswith(tail)


def test_a_long_value_is_shown_cut_short():
    """A refused value's text is cut at 80 characters and marked, whatever its size."""
    message = refusal(lambda: real("x", "a" * 1000))[1]
    assert message.endswith("got str '" + "a" * 79 + "..."), message          # the repr's first 80 characters


def test_the_refusal_check_rejects_another_name_or_phrase():
    _, message = refusal(lambda: real("x", 2.0, low=0.0, high=1.0))
    assert not message.startswith("y ") and "must be finite" not in message


# ------------------------------------------------------------------ pointwise: each argument wired to its range

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


def call(function, **change):
    fn, kwargs = CALLS[function]
    kwargs = {**kwargs, **change}
    return fn(kwargs.pop("name"), **kwargs) if "name" in kwargs else fn(**kwargs)


def all_finite(result):
    """Whether every array of a pointwise result (an array, or nested tuples of them) is finite."""
    if isinstance(result, tuple):
        return all(all_finite(item) for item in result)
    return bool(np.all(np.isfinite(np.asarray(result, dtype=float))))


def ranges(function):
    """The ranges ``function``'s arguments are checked with (`pointwise.RANGES_CENTRAL` for the
    central quotient, `pointwise.RANGES_FRAME` for the tangent frame, else `pointwise.RANGES`, and
    `COORDINATE` for a name neither lists)."""
    return {"central_gradient": pointwise.RANGES_CENTRAL, "tangent_frame": pointwise.RANGES_FRAME}.get(
        function, pointwise.RANGES)


def ends(name, ranges=pointwise.RANGES):
    """[(the extreme value ``name`` accepts, the float one past it)] at both ends of its range."""
    r = ranges.get(name, COORDINATE)
    low = (past(r["low"], UP), r["low"]) if r.get("low_open") else (r["low"], past(r["low"], DOWN))
    high = (past(r["high"], DOWN), r["high"]) if r.get("high_open") else (r["high"], past(r["high"], UP))
    return [low, high]


@pytest.mark.parametrize("function", CALLS)
def test_each_pointwise_argument_is_wired_to_its_range(function):
    """Every scalar argument of the function (from its signature) at each end of its range gives
    finite outputs, and one float past it is refused naming the argument."""
    fn, kwargs = CALLS[function]
    names = [a for a in inspect.signature(fn).parameters if a in kwargs and a != "name"
             and not isinstance(kwargs[a], tuple)]
    assert len(names) >= 3
    for argument in names:
        for limit, beyond in ends(argument, ranges(function)):
            assert all_finite(call(function, **{argument: limit})), (argument, limit)
            _, message = refusal(lambda: call(function, **{argument: beyond}))
            assert message.startswith(f"{argument} must be in ") and "flat index 0" in message, message


#: Values each kind of argument must refuse, written from the docstrings rather than read from the module's
#: ranges (which the test above reads): a step is in (0, 1), a frequency and a radius are positive, and the
#: central quotient's chart point lies in [0, 1].
KIND_REFUSALS = {"eps": (0.0, -1e-3, 1.0), "eps_v": (0.0, -1e-3, 1.0), "k_u": (0.0, -1.0), "k_v": (0.0, -1.0),
           "radius": (0.0, -1.0)}
KIND_REFUSALS_CENTRAL = {**KIND_REFUSALS, "u": (-0.1, 1.1), "v": (-0.1, 1.1)}


@pytest.mark.parametrize("function", CALLS)
def test_each_pointwise_argument_refuses_what_its_kind_cannot_be(function):
    refused = KIND_REFUSALS_CENTRAL if function == "central_gradient" else KIND_REFUSALS
    names = [a for a in inspect.signature(CALLS[function][0]).parameters if a in refused]
    assert names or function in ("chart", "tangent_frame")
    for argument in names:
        for value in refused[argument]:
            _, message = refusal(lambda: call(function, **{argument: value}))
            assert message.startswith(f"{argument} must be in "), (argument, value, message)


@pytest.mark.parametrize("argument", ["P", "N", "e_theta", "e_phi"])
@pytest.mark.parametrize("point, error", [(b"abc", InvalidType), ({0.1, 0.2, 0.3}, InvalidType),
                                          ((c for c in (0.1, 0.2, 0.3)), InvalidType), (0.5, InvalidType),
                                          (np.array(0.5), InvalidType), ((0.1, 0.2), InvalidValue),
                                          ([10**5000, 0.0], InvalidValue)])
def test_a_footprint_vector_is_a_tuple_list_or_array_of_three(argument, point, error):
    """Each of the four vectors: bytes, a set (no order) and a generator were read as three components;
    a huge integer's repr raised a ValueError that named nothing."""
    got, message = refusal(lambda: call("footprint", **{argument: point}))
    assert got is error and message.startswith(f"{argument} must ") and "three components" in message, message
    assert all_finite(call("footprint", **{argument: np.array([[0.1, 0.2], [0.1, 0.2], [0.99, 0.97]])}))


@pytest.mark.parametrize("argument", ["P", "N", "e_theta", "e_phi"])
def test_each_component_of_a_footprint_vector_is_refused_by_its_name_and_index(argument):
    for i in range(3):
        vector = list(CALLS["footprint"][1][argument])
        vector[i] = np.array([0.5, np.inf])
        _, message = refusal(lambda: call("footprint", **{argument: vector}))
        assert message.startswith(f"{argument}[{i}] must be in [") and message.endswith("got inf at flat index 1")


def test_a_footprint_vectors_refusal_shows_the_value_cut_at_60_characters():
    assert refusal(lambda: call("footprint", e_phi=(0.1, 0.2)))[1] == \
        "e_phi must have three components (x, y, z), got 2: tuple (0.1, 0.2)"
    assert refusal(lambda: call("footprint", e_theta=b"abc"))[1] == \
        "e_theta must be three components (x, y, z): a tuple, list or array, got bytes b'abc'"
    assert refusal(lambda: call("footprint", N=[0.0] * 40))[1] == \
        "N must have three components (x, y, z), got 40: list " + "[" + "0.0, " * 11 + "0.0,..."
    assert refusal(lambda: call("footprint", P=set(range(40))))[1] == \
        "P must be three components (x, y, z): a tuple, list or array, got set " + \
        "{" + ", ".join(map(str, range(17))) + ", 1..."


def test_pointwise_outputs_are_finite_at_every_corner_of_the_ranges():
    """All arguments at the ends of their ranges at once (and at the tangent frame's
    pole cut-off, float64's smallest normal number, and just above it, where its quotients by
    sin phi are largest), for every registered field: the ranges are read from the module, so a
    wider one is tried too."""
    central = pointwise.RANGES_CENTRAL
    edge = lambda name, r=pointwise.RANGES: [lim for lim, _ in ends(name, r)]  # noqa: E731
    for name in F.FIELDS:
        grid = itertools.product(*(edge(a) for a in ("u", "v", "k_u", "k_v")))
        u, v, ku, kv = (np.array(c) for c in zip(*grid))
        for fn in (pointwise.height, pointwise.exact_gradient):
            assert all_finite(fn(name, u, v, ku, kv))
        grid = itertools.product((*edge("u", central), 0.5), (*edge("v", central), past(1.0, DOWN), 0.5),
                                 edge("k_u"), edge("k_v"), (*edge("eps"), 1e-16), (*edge("eps_v", central), 1e-16))
        assert all_finite(pointwise.central_gradient(name, *(np.array(c) for c in zip(*grid))))
    low, high = edge("N_x")
    edges = np.array([low, -1.0, 0.0, 1.0, high])
    n = np.array(list(itertools.product(edges, repeat=3))).T
    assert all_finite(pointwise.chart(*n))
    frame = pointwise.RANGES_FRAME
    unit = np.array(list(itertools.product((*edge("N_x", frame), -1.0, 0.0, 1.0), repeat=3))).T
    pole = float(F.POLE_SIN_PHI)
    for s in (*edge("sin_phi", frame), 0.0, 2.0**-1074, pole, past(pole, UP), 1e-4):
        assert all_finite(pointwise.tangent_frame(*unit, s))
    rng = np.random.default_rng(7)
    pick = lambda: rng.choice(np.concatenate([edges, rng.uniform(low, high, 5)]), 4000)  # noqa: E731
    triple = lambda: (pick(), pick(), pick())  # noqa: E731
    got = pointwise.footprint(pick(), pick(), pick(), pick(), pick(), triple(), triple(), triple(), triple(),
                              rng.choice([*edge("radius"), 1.0], 4000), pick())
    assert all_finite(got)


def test_arguments_that_do_not_broadcast_are_refused_with_every_shape():
    _, message = refusal(lambda: pointwise.height("sine", [0.1, 0.2], [0.1, 0.2, 0.3], 8.0, 4.0))
    assert message == "the arguments must broadcast to one shape, got u (2,), v (3,), k_u (), k_v ()"
