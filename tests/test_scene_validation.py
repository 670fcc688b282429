"""`Scene`, `PointLight` and the entry points are wired to their validators: the seed's
defaults, one accepted and one refused value per field and per argument, the rules that
tie fields together, and a property test over valid scenes.

What each kind of value accepts is tests/test_validate.py's subject, tested once there.
Here every field of `Scene` and `PointLight` (read from the dataclasses, so that a new field
cannot be missed) keeps its default and refuses, naming itself, the float just past the
range its own refusal states (a real number or a vector's component); a flag refuses 1, a
choice another case, the lights a non-light, the height field an unknown name and an
expression that is not finite on the chart (a reader's expression is accepted).  Each
argument of `render`, `gbuffer`, `sweep` and `compare` (read from their signatures) has one
accepted and one refused value.  Messages are matched on the parameter's name and the
essential phrase only.
"""

from __future__ import annotations

import dataclasses
import inspect
import re

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from renderer import BUMPS, DRAFT_NAMES, DRAFT_SCENE, GRADIENTS, MODELS, PointLight, Scene, compare, gbuffer, render, sweep
from renderer import formulas as F
from renderer.validate import InputError, InvalidType, InvalidValue

# The seed's SC9 dictionary (seed Cell 1), typed from the seed: it is the spec.
SC9 = dict(R=1.0, e=4.0, Cb=(0.5, 0.5, 1.3), R2=0.32, b_on=True, floor_on=True,
           lights=(((5., 5., 10.), (1., 1., 1.)),
                   ((-6., 2., 8.), (0.9, 0.65, 0.25))),
           ambient=(0.15, 0.15, 0.16), matA=(0.63, 0.19, 0.16), matB=(0.33, 0.44, 0.62),
           ka=0.1, kd=0.7, ks=0.5, shin=32.0, model='blinn',
           alpha=0.25, hf='ridges', ku=8.0, kv=4.0, beta=0.35, eps=1e-3)
# Scene field <- seed name: `DRAFT_NAMES`, each other field under its own name (lights are compared apart).
SEED_NAMES = {f: DRAFT_NAMES.get(f, f) for f in Scene.__dataclass_fields__ if f not in ("lights", "bump")}


def refusal(call):
    """(type, message) of the InputError ``call()`` raises (a ValueError or a TypeError)."""
    with pytest.raises(InputError) as info:
        call()
    return type(info.value), str(info.value)


# --- defaults --------------------------------------------------------------------------

def seed_mismatches(scene):
    """Fields of ``scene`` that differ from SC9 in value or type (sorted)."""
    bad = [f for f, seed in SEED_NAMES.items()
           if not (getattr(scene, f) == SC9[seed] and type(getattr(scene, f)) is type(SC9[seed]))]
    lights = tuple((light.position, light.color) for light in scene.lights)
    if lights != SC9["lights"]:
        bad.append("lights")
    return sorted(bad)


def test_defaults_are_the_seeds():
    assert sorted([*SEED_NAMES.values(), "lights"]) == sorted(SC9)       # every draft key named, once
    assert seed_mismatches(Scene()) == []
    assert all(isinstance(light, PointLight) for light in Scene().lights)
    # The project's addition: the default perturbed normal is the displaced sphere's; the
    # draft's own scene, with its chart formula, is DRAFT_SCENE and differs in nothing else.
    assert Scene().bump == "surface"
    assert DRAFT_SCENE.bump == "chart" and DRAFT_SCENE.replace(bump="surface") == Scene()


def test_defaults_check_has_teeth():
    drifted = Scene(k_v=4.000001, lights=(PointLight(),), floor=False)
    assert seed_mismatches(drifted) == ["floor", "k_v", "lights"]
    assert seed_mismatches(Scene(k_u=8)) == []          # int 8 is stored as the float 8.0


# --- each field wired to its validator ---------------------------------------------------

_STATED = re.compile(r"must be (?:in [\[(][^,]+, (?P<high>[^\])]+)[\])]|<= (?P<le>[^\s,]+))")


def refused_value(cls, name):
    """(a value refused for field ``name`` of ``cls``, the field named in the message, the
    essential phrase), by the kind of its default: a number (or a vector's first component)
    one float past the upper end of the range its own refusal of 1e300 states; a flag 1; a
    choice its default in capitals; the lights a light that is not a PointLight; the height
    field an expression with an unknown name."""
    default = getattr(cls(), name)
    label = f"{cls.__name__}.{name}"
    if isinstance(default, bool):
        return 1, label, "True or False"
    if name == "height_field":
        return "u + w", label, "'w' is not one of its names"
    if isinstance(default, str):
        return default.upper(), label, "must be one of"
    if name == "lights":
        return ("a light",), f"{label}[0]", "must be a PointLight"
    vector = isinstance(default, tuple)
    probe = (1e300, *default[1:]) if vector else 1e300
    _, message = refusal(lambda: cls(**{name: probe}))
    stated = _STATED.search(message)
    high = float(stated["high"] or stated["le"])
    beyond = float(np.nextafter(high, np.inf))
    return ((beyond, *default[1:]) if vector else beyond), label + ("[0]" if vector else ""), stated[0]


FIELDS = [(cls, f.name) for cls in (Scene, PointLight) for f in dataclasses.fields(cls)]


@pytest.mark.parametrize("cls, name", FIELDS, ids=[f"{c.__name__}.{n}" for c, n in FIELDS])
def test_each_field_keeps_its_default_and_refuses_a_value_past_its_range_by_name(cls, name):
    default = getattr(cls(), name)
    assert getattr(cls(**{name: default}), name) == default
    value, label, phrase = refused_value(cls, name)
    error, message = refusal(lambda: cls(**{name: value}))
    assert message.startswith(f"{label} ") and phrase in message, message
    assert error in (InvalidType, InvalidValue)


def test_the_field_check_rejects_a_refusal_that_names_another_field():
    _, message = refusal(lambda: Scene(k_u=1e300))
    value, label, phrase = refused_value(Scene, "k_v")
    assert not message.startswith(f"{label} ") and label == "Scene.k_v" and phrase in message


def test_a_readers_expression_is_accepted_and_a_non_finite_one_refused():
    scene = Scene(height_field="sin(pi*k_u*u)^2 * sin(pi*k_v*v)^2", beta=0.5)
    assert scene.field.expr == (F.FIELDS["sine"].expr ** 2) and scene.height_field not in F.FIELDS
    # Symbols are taken by name: a reader's sympy.symbols("u v k_u k_v") carry no assumptions (the
    # project's are real), and were refused as "must use only u, v, k_u, k_v; it uses u, v".
    pu, pv, pk = sp.symbols("u v k_u")
    assert Scene(height_field=sp.sin(sp.pi * pk * pu) * pv).field.expr == sp.sin(sp.pi * F.k_u * F.u) * F.v
    # A number is a constant field (TOML reads height_field = 0 as one); a bool is not a number here.
    assert [Scene(height_field=c).field.gradient for c in (0, 0.5)] == [(0, 0)] * 2
    _, message = refusal(lambda: Scene(height_field=True))
    assert message.startswith("Scene.height_field must be") and message.endswith("got bool"), message
    # 12**4096 overflows; (0.5 - pi)**pi is a complex number sympy does not evaluate.  (1e400 is refused as a
    # number beyond float64: test_an_expression_beyond_the_grammar_or_float64_is_refused_in_one_line.)
    for text in ("1/u", "log(v)", "u*(k_u + k_v)**(k_u**k_v)", "u*(0.5 - pi)**pi", "(0.5 - pi)**pi"):
        _, message = refusal(lambda: Scene(height_field=text))
        assert message.startswith("Scene.height_field ") and "not finite and real" in message, message
    # The point named is one where the field has no value: on its singular line.
    for text, on_line in (("1/(v - 0.5)", lambda u, v: v == 0.5), ("log(u)*v", lambda u, v: u == 0),
                          ("1/(u - v)", lambda u, v: u == v), ("sqrt(0.25 - v)", lambda u, v: v >= 0.25)):
        _, message = refusal(lambda: Scene(height_field=text))
        u, v = map(float, re.search(r"at \(u, v\) = \(([^,]+), ([^)]+)\)", message).groups())
        assert on_line(u, v), message
    # A displaced radius at or below 0 is named where h is least.
    for text, least in (("u - 2*v", (0.0, 1.0)), ("2*(u - 0.25)**2 - 6*(v - 0.5)**2", (0.25, 0.0))):
        _, message = refusal(lambda: Scene(height_field=text, beta=0.9))
        assert f"at (u, v) = ({least[0]:g}, {least[1]:g})" in message, message


#: Fields singular between any grid's points: on a line u = P or v = Q, at a point (P, Q), or in their
#: gradient alone; each is named by the coordinates it is singular in.  Between them a pole or a jump
#: of tan, log, abs, atan, exp, sinh, tanh and a power.
SINGULAR = {"1/(u - P)": "u", "tan(pi*(v - Q + 0.5))": "v", "log(abs(u - P))": "u", "sqrt(abs(v - Q))": "v",
            "abs(u - P)**(1/3)*v": "u", "atan(1/(u - P))": "u", "exp(v)/(v - Q)": "v", "1/sinh(u - P)": "u",
            "1/tanh(v - Q)": "v", "1/((u - P)**2 + (v - Q)**2)": "uv"}
#: Fields bounded on the chart with their gradients, however near C puts them to a pole; together
#: they call every function of `renderer.formulas.ELEMENTARY`.
BOUNDED = ("1/((u - P)**2 + C)", "log((v - Q)**2 + C)*sqrt((u - P)**2 + C)", "exp(-((u - P)**2 + (v - Q)**2)/C)",
           "atan(u - P) + sinh(v)*cosh(u) + tanh((v - Q)/C)", "asin(0.9*u) - acos(0.9*v)",
           "abs(sin(pi*k_u*(u - P)))*tan(v/2) + cos(u)")


@settings(max_examples=30, deadline=None)
@given(p=st.floats(0.001, 0.999), q=st.floats(0.001, 0.999), c=st.floats(1e-6, 1.0),
       form=st.sampled_from(sorted(SINGULAR)), bounded=st.sampled_from(BOUNDED))
def test_a_singularity_between_the_grids_points_is_refused_where_it_is_and_a_near_one_accepted(
        p, q, c, form, bounded):
    """A reader's field is checked on a grid of the chart and between its points by interval arithmetic
    (`renderer.scene._unbounded_near`): a pole, a jump or a gradient without bound anywhere in the chart,
    wherever it falls, is refused naming a point within a millionth of it; a field bounded with its
    gradient, even a millionth from a pole, is accepted.  (Before the interval check, tan(pi*u) with
    bump="chart" was accepted: no grid point is a float whose tangent overflows.)"""
    text = lambda t: t.replace("P", repr(p)).replace("Q", repr(q)).replace("C", repr(c))       # noqa: E731
    _, message = refusal(lambda: Scene(height_field=text(form), bump="chart"))
    named = re.search(r"(?:at|near) \(u, v\) = \(([^,]+), ([^)]+)\)", message)
    assert message.startswith("Scene.height_field ") and "not finite and real" in message and named, message
    assert all(abs(float(named[i]) - x) <= 1e-6 for i, (x, axis) in enumerate(((p, "u"), (q, "v")), 1)
               if axis in SINGULAR[form]), (p, q, message)
    assert Scene(height_field=text(bounded), bump="chart").height_field not in F.FIELDS     # accepted, as typed


@settings(max_examples=20, deadline=None)
@given(p=st.floats(0.01, 0.99), q=st.floats(0.01, 0.99), width=st.floats(1e-8, 1e-6), depth=st.floats(3.5, 50.0))
def test_a_dip_through_the_displaced_radius_anywhere_is_refused_where_it_is(p, q, width, depth):
    """bump="surface" needs radius_a + beta h > 0 on the whole chart: a dip of h below -radius_a / beta,
    narrower than the chart check's grid and wherever it stands, is refused naming a point of it where h
    is below; the same dip short of it is accepted."""
    dip = lambda d: f"1 - {d!r}*exp(-((u - {p!r})**2 + (v - {q!r})**2)/{width!r})"     # noqa: E731
    _, message = refusal(lambda: Scene(height_field=dip(depth), beta=0.5))
    said = re.search(r"\(h = (\S+) at \(u, v\) = \(([^,]+), ([^)]+)\)\)", message)
    assert said and 1.0 + 0.5 * float(said[1]) <= 0.0, message
    assert np.hypot(float(said[2]) - p, float(said[3]) - q) <= 3 * np.sqrt(width), (p, q, message)
    assert Scene(height_field=dip(2.5), beta=0.5).beta == 0.5           # 1 + 0.5 h >= 0.25: accepted


def test_a_bounded_field_the_intervals_overestimate_is_accepted_after_the_searchs_budget():
    """(u - v)**2 written out holds each variable twice, and interval arithmetic bounds
    1/(u**2 - 2*u*v + v**2 + 1e-4) about u = v only on boxes of side about 1e-5: the search stops at
    `renderer.intervals.CHART_CHECK_BOXES` boxes and the field, bounded, is accepted on the grid's evidence."""
    from renderer import scene as S
    scene = Scene(height_field="1/(u**2 - 2*u*v + v**2 + 1e-4)", bump="chart")
    assert S._unbounded_near(scene.field, scene.k_u, scene.k_v) is None


def _nested(depth):
    e = F.u
    for _ in range(depth - 1):
        e = sp.sin(e)
    return e


@pytest.mark.parametrize("field, said", [
    # sympy objects that are not functions to atoms(Function): they passed the check of the functions called.
    (sp.Max(F.u, 0.5), "it holds Max"), (sp.Integral(sp.sin(F.u), F.u), "it holds Integral"),
    (sp.Derivative(sp.sin(F.u), F.u), "it holds Derivative"), (F.u + sp.O(F.u**2), "it holds Order"),
    (sp.Sum(F.u**sp.Symbol("t"), (sp.Symbol("t"), 0, 3)), "it holds Sum"),
    (sp.Subs(sp.sin(sp.Symbol("t")), sp.Symbol("t"), F.u), "it holds Subs"), (sp.Lambda(F.u, F.u**2), "it holds Lambda"),
    (sp.MatrixSymbol("A", 1, 1)[0, 0] * F.u, "it uses A"),
    # Numbers beyond float64: 10**400 raised OverflowError from the chart's check; 9**9**9 took hours to parse.
    ("10**400*u", "must hold only numbers float64 can: it holds 1.00E+400"),
    (sp.Rational(10**400, 3) * F.u, "it holds 3.33E+399"), ("1e999*u", "it holds 1.00E+999"),
    ("9**9**9*u", "raises a number to the power 9**9"), ("u*2**(3**7)", "raises a number to the power 3**7"),
    (_nested(101), "must be nested at most 100 deep; its tree is 101 deep"),
    ("u**" * 166 + "u", "its tree is 167 deep"),
])
def test_an_expression_beyond_the_grammar_or_float64_is_refused_in_one_line(field, said):
    """What a field may be built from is a whitelist (`renderer.formulas.BUILDING_BLOCKS`), numbers float64
    holds, a tree at most `renderer.formulas.MAX_DEPTH` deep: anything else is one InputError naming
    ``Scene.height_field``, never an exception from inside sympy, numba or the chart's check, nor a hang."""
    kind, message = refusal(lambda: Scene(height_field=field))
    assert message.startswith("Scene.height_field") and said in message and "\n" not in message, message
    assert len(message) < 400, message


def test_the_deepest_and_largest_accepted_expressions_render():
    """The limits' other side: a tree exactly `renderer.formulas.MAX_DEPTH` deep and a power of numbers
    within float64 are accepted and render finite."""
    for field in (_nested(100), "u*2**(2**10)*1e-300"):
        out = render(Scene(height_field=field), 8, 8)
        assert np.isfinite(out.image).all()


def _off_contract(fields, k_u, k_v):
    """The fields of ``fields`` a built-in may not be (`Scene` skips the chart check for them and
    checks only beta < radius_a): not finite and real with its gradient on the chart's grid or
    between its points, or with h < -1 there, where R + beta h would reach 0 under beta < R."""
    from renderer.scene import _on_chart, _unbounded_near
    off = []
    for field in fields:
        low, _, bad = _on_chart(field, k_u, k_v)
        if not (bad is None and low >= -1.0 and _unbounded_near(field, k_u, k_v) is None):
            off.append(field.name)
    return off


@settings(max_examples=25, deadline=None)
@given(k_u=st.floats(1e-3, 1e3), k_v=st.floats(1e-3, 1e3))
def test_every_builtin_field_is_finite_and_at_least_minus_one_on_the_chart(k_u, k_v):
    """What lets `Scene` trust a field of `formulas.BUILTIN` without the chart check, held for
    whatever field is registered there, at random frequencies; a field twice the sine is refused."""
    assert _off_contract([F.FIELDS[name] for name in F.BUILTIN], k_u, k_v) == []
    twice = F.HeightField("twice", 2 * F.FIELDS["sine"].expr)
    assert _off_contract([twice], 1.5, 1.5) == ["twice"]

@pytest.mark.parametrize("text, held", [("abs(u**u)", "arg, im, re"), ("cos(3)**v", "the imaginary unit")])
def test_a_field_whose_derivative_sympy_cannot_write_real_is_refused(text, held):
    """|g| of a g sympy cannot tell is real, and a negative base to a power in v: their derivatives
    hold complex parts, which no printer of the kernels has.  A real abs is a field like any other."""
    _, message = refusal(lambda: Scene(height_field=text))
    assert message.startswith(f"Scene.height_field {text!r} ") and f"sympy's holds {held}" in message, message
    assert Scene(height_field="abs(sin(pi*k_u*u))*v").field.crease_factors
    _, message = refusal(lambda: Scene(height_field="u*atan(tan(pi/2))"))    # sympy: an interval, not a number
    assert message.startswith("Scene.height_field 'u*atan(tan(pi/2))' (read as u*AccumBounds(-pi/2, pi/2)) must be "
                              "real"), message
    _, message = refusal(lambda: Scene(height_field="sqrt(-1)*u"))           # as typed, and as sympy reads it
    assert message.startswith("Scene.height_field 'sqrt(-1)*u' (read as I*u) must be real and finite: it holds I")


@pytest.mark.parametrize("expr, held", [(sp.I * F.u, "I"), (sp.zoo * F.u, "zoo"), (F.u + sp.oo, "oo"),
                                        (F.u - sp.oo, "-oo"), (sp.nan * F.u, "nan"),
                                        (F.u * sp.AccumBounds(0, 1), "an interval")])
def test_a_sympy_field_holding_a_constant_that_is_not_a_real_number_is_refused_naming_it(expr, held):
    _, message = refusal(lambda: Scene(height_field=expr))
    assert message.startswith(f"Scene.height_field {str(expr)!r} must be real and finite: it holds {held}"), message


@pytest.mark.parametrize("kwargs, field, phrase", [
    (dict(radius_b=3.0), "radius_b", "sphere B"),                        # the camera inside sphere B
    (dict(camera_z=1.0), "camera_z", "radius_a"),                        # the camera on sphere A
    (dict(bump="surface", beta=1.0), "beta", "radius_a"),                # the displaced surface needs beta < R
    (dict(height_field="u - 3", beta=0.5), "beta", "displaced radius"),  # and R + beta h > 0 for any field
])
def test_each_rule_between_fields_names_a_field(kwargs, field, phrase):
    _, message = refusal(lambda: Scene(**kwargs))
    assert re.match(rf"^Scene\.{field}\b", message) and phrase in message, message


def test_replace_validates_and_refuses_unknown_fields():
    scene = Scene(bump="chart").replace(beta=1.5, height_field="sine")
    assert (scene.beta, scene.height_field, scene.k_u) == (1.5, "sine", 8.0)
    _, message = refusal(lambda: Scene().replace(beta=-1.0))
    assert message.startswith("Scene.beta ")
    _, message = refusal(lambda: Scene().replace(hf="sine"))
    assert "no field(s)" in message and "'hf'" in message


def test_huge_finite_values_are_refused_not_overflowed():
    """A finite value whose square overflows is refused by name (it once raised OverflowError)."""
    for kwargs, field in ((dict(camera_z=1e155), "camera_z"), (dict(radius_b=1e160), "radius_b"),
                          (dict(center_b=(1e160, 0.0, 0.0)), "center_b")):
        _, message = refusal(lambda: Scene(**kwargs))
        assert message.startswith(f"Scene.{field}"), message


def test_an_integer_too_long_to_print_is_described_by_name():
    """Python refuses to print an int of more than 4300 digits: the message describes it, naming
    the field (the repr once raised a ValueError that named nothing)."""
    for kwargs, field in ((dict(lights=10**5000), "lights"), (dict(lights=[10**5000]), "lights[0]"),
                          (dict(center_b=[10**5000, 0.0]), "center_b")):
        _, message = refusal(lambda: Scene(**kwargs))
        assert message.startswith(f"Scene.{field} ") and "integer of" in message, message


# --- each argument of the entry points ----------------------------------------------------

_SCENE = Scene()
#: entry point: {argument: (an accepted value, a refused value, the essential phrase)}; the scene,
#: sizes and steps of a call are small ones.
ARGUMENTS = {
    render: dict(scene=(_SCENE, dict(beta=0.35), "renderer.Scene"), width=(3, 0, "integer"),
                 height=(np.int64(2), 2.0, "positive integer"), gradient=("footprint", "numeric", "must be one of"),
                 zoom=(1e6, 0.5, "must be in [1, 1e+06]"), kink=(np.False_, 1, "True or False"),
                 grad=(False, "no", "True or False"), skip=(False, None, "True or False"),
                 workers=(1, 65, "integer in [1, 64]"), backend=("numpy", "cuda", "must be one of")),
    gbuffer: dict(scene=(_SCENE, None, "renderer.Scene"), width=(1, 8193, "integer in [1, 8192]"),
                  height=(3, True, "positive integer"), gradient=("central", "", "must be one of"),
                  zoom=(2.0, float("nan"), "must be in [1, 1e+06]")),
    sweep: dict(scene=(_SCENE, "scene", "renderer.Scene"), eps_values=((0.25, 1e-16), [1e-3, 0.0], "eps_values[1]"),
                width=(2, -1, "integer"), height=(2, "2", "positive integer"), zoom=(1.0, 1e7, "must be in"),
                workers=(None, 0, "integer in [1, 64]")),
}
_BASE = {"scene": _SCENE, "width": 3, "height": 2, "eps_values": (1e-3,)}


@pytest.mark.parametrize("entry", ARGUMENTS, ids=lambda f: f.__name__)
def test_each_argument_of_an_entry_point_is_wired(entry):
    parameters = list(inspect.signature(entry).parameters)
    assert set(ARGUMENTS[entry]) == set(parameters)
    for name, (accepted, refused, phrase) in ARGUMENTS[entry].items():
        base = {k: v for k, v in _BASE.items() if k in parameters}
        entry(**{**base, name: accepted})
        _, message = refusal(lambda: entry(**{**base, name: refused}))
        assert message.startswith(name) and phrase in message, (name, message)


def test_compare_is_wired():
    numeric = render(_SCENE, 8, 8, gradient="central")
    assert compare(numeric, render(_SCENE, 8, 8)).pixels_a > 0
    with pytest.raises(ValueError, match="kink=True"):
        compare(numeric, render(_SCENE, 8, 8, kink=False))
    with pytest.raises(TypeError, match="numeric must be a renderer Frame"):
        compare(numeric.image, render(_SCENE, 8, 8))


def test_the_library_refuses_a_frame_over_its_pixel_cap_before_allocating():
    """Sides up to 8192 are accepted, but not 8192 x 8192 (67 M pixels, 2.7 GB for one frame)."""
    from renderer import cli
    from renderer.render import MAX_PIXELS
    assert cli.MAX_PIXELS == MAX_PIXELS
    for run in (lambda w, h: render(_SCENE, w, h), lambda w, h: gbuffer(_SCENE, w, h),
                lambda w, h: sweep(_SCENE, (1e-3,), w, h)):
        _, message = refusal(lambda: run(4097, 4096))
        assert message.startswith("width * height must be at most") and "4097 x 4096" in message


def test_sweep_reads_an_endless_iterator_only_one_step_past_the_limit():
    from renderer.sweep import MAX_STEPS
    taken = []

    def endless():
        while True:
            taken.append(1)
            yield 1e-3

    with pytest.raises(ValueError, match=f"got more than {MAX_STEPS}"):
        sweep(_SCENE, endless(), 4, 4)
    assert len(taken) == MAX_STEPS + 1
    # An iterator within the limit is read whole and used in order.
    assert [f.scene.eps for f in sweep(_SCENE, iter([1e-2, 1e-3]), 4, 4).numeric] == [1e-2, 1e-3]
    with pytest.raises(TypeError, match=r"^eps_values must be ordered"):
        sweep(_SCENE, {1e-3, 1e-4}, 4, 4)


# --- property: valid scenes render in [0, 1], and bump moves no boundary ---------------------

@st.composite
def valid_scenes(draw):
    bump = draw(st.sampled_from(BUMPS))
    beta_max = 5.0 if bump == "chart" else 0.99          # the displaced surface needs beta < R
    return Scene(
        height_field=draw(st.sampled_from(tuple(F.FIELDS))),
        model=draw(st.sampled_from(MODELS)),
        k_u=draw(st.floats(0.5, 20.0, exclude_min=True, exclude_max=True)),
        k_v=draw(st.floats(0.5, 20.0, exclude_min=True, exclude_max=True)),
        beta=draw(st.floats(0.0, beta_max)),
        eps=draw(st.floats(1e-8, 0.25)),
        sphere_b=draw(st.booleans()),
        floor=draw(st.booleans()),
        bump=bump,
    )


#: The fields that move only sphere A's shading (the bump): `geometry_only` resets them.
BUMP_FIELDS = ("beta", "eps", "height_field", "k_u", "k_v", "bump")


def geometry_only(scene):
    """The same scene with every bump field at its default."""
    return scene.replace(**{f: getattr(Scene(), f) for f in BUMP_FIELDS})


def boundary_violations(frame, other):
    """Pixels whose chamber code differs between two frames."""
    return int(np.count_nonzero(frame.chamber != other.chamber))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=valid_scenes(), gradient=st.sampled_from(GRADIENTS))
def test_valid_scenes_render_in_unit_interval_and_bump_moves_no_boundary(scene, gradient):
    frame = render(scene, 16, 16, gradient=gradient)
    assert np.all(np.isfinite(frame.image)) and np.all(np.isfinite(frame.grad))
    assert frame.image.min() >= 0.0 and frame.image.max() <= 1.0
    reference = render(geometry_only(scene), 16, 16, gradient="exact")
    assert boundary_violations(frame, reference) == 0


def test_boundary_check_has_teeth():
    """A geometric change (sphere B's radius) is caught by the same comparison."""
    scene = Scene()
    moved = render(scene.replace(radius_b=0.33), 16, 16)
    assert boundary_violations(moved, render(geometry_only(scene), 16, 16)) > 0
