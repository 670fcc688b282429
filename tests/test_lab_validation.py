"""Every public function of lab/ refuses bad input as `renderer.validate` refuses the renderer's.

One table, `FUNCTIONS`: per function, a cheap valid call and the kind of each parameter.
Each kind (`BAD`) lists values it must refuse (a bool where a number is meant, a string, NaN,
inf, an integer too large for a float, a negative count, ...) with the error and how the
message shows the value; a parameter adds values outside its own range.  The cases are
generated from the table: each is one call with one argument replaced, which must raise the
error named, with a message whose subject (before "must", where it says what is accepted) is
the parameter's name, and which shows the value.  `test_a_valid_call_is_not_refused` makes each function's valid call.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from lab import accuracy, claims, displaced, fastmath, inverse, seed_errata
from lab import gradient_benchmark as gb
from lab import gradient_methods as gm
from renderer import Scene
from renderer import formulas as F
from renderer.validate import InvalidType, InvalidValue

T, V = InvalidType, InvalidValue

#: Values each kind of parameter refuses: (value, error, how the message shows the value).
BAD = {
    "real": [(True, T, "bool True"), ("0.5", T, "str '0.5'"), (1j, T, "complex"), (math.nan, V, "got nan"),
             (-math.inf, V, "got -inf"), (10**400, V, "integer of 401 digits")],
    "array": [([True], T, "list [True]"), ("0.5", T, "str '0.5'"), ([0.5, math.nan], V, "nan at flat index 1"),
              ([0.5, 10**400], V, "too large for a float")],
    "int": [(True, T, "bool True"), (2.0, T, "float 2.0"), ("3", T, "str '3'"), (-1, V, "got -1"),
            (10**400, V, "int 1000000000")],
    "seed": [(True, T, "bool True"), (1.5, T, "float 1.5"), (-1, V, "got -1"), (2**64, V, "18446744073709551616")],
    "steps": [(True, T, "bool True"), ({1e-3}, T, "set {0.001}"), ([], V, "got 0"),
              ([1e-3, math.nan], V, "at flat index 1")],
    "field": [(3j, T, "got complex"), ("no_such_field", V, "'no_such_field'")],
    "name": [(1, T, "int 1"), ("nope", V, "'nope'")],
    "flag": [(1, T, "int 1"), ("yes", T, "str 'yes'")],
    "fields": [("rings", T, "str 'rings'"), ((), V, "got ()"), (("rings", "waves"), V, "'waves'")],
    "own": [],                               # only the parameter's own values
}


def p(kind, *extra, named=None):
    """A parameter of ``kind``, refusing also ``extra`` (value, error, shown), named ``named`` in messages."""
    return kind, extra, named


U8, V8 = np.linspace(0.1, 0.9, 8), np.linspace(0.2, 0.8, 8)
CHART = dict(field="sine", uu=[0.31, 0.32], vv=[0.47, 0.48], ku=8.0, kv=4.0)
CHART_KINDS = dict(field=p("field", named="field"), uu=p("array", ([1.5], V, "1.5 at flat index 0")),
                   vv=p("array", ([0.5, 0.5, 0.5], V, "broadcast")), ku=p("real", (0.0, V, "got 0.0")),
                   kv=p("real", (1e4, V, "got 10000.0")))
EPS = p("real", (0.0, V, "got 0.0"), (1.0, V, "got 1.0"))
RESULT = gb.MethodResult("sine", "exact", None, (1.0,), 0.0, 0.0, 1.0, 1e-15, 1e-16)
CONFIG = dict(name="tiny", central_steps=(1e-3,), forward_steps=(1e-8,), complex_steps=(1e-20,), repeats=1,
              richardson_repeats=1, reference_pixels=5, digits=34, size=16, seed=6)
#: A measurement of the errata in which every defect is there (`seed_errata.reproduced` checks that).
ERRATA = {"sphere-b-quadratic": dict(off_surface_relative=2.0, seed_pixels_b=6, true_pixels_b=1),
          "terminator-leak": dict(leak_pixels_default=1, leak_diffuse_max_default=1.0),
          "specular-ungated": dict(pixels=1, max_specular_added=1.0),
          "v-border-branch": {"fraction_interior": [0.1, 0.2]},
          "acos-pole": dict(max_rel_error_acos=1.0, max_rel_error_atan2=0.0),
          "fallback-orientation": dict(orientation_fallback=1.0, orientation_regular_min=-1.0,
                                       orientation_regular_max=-1.0)}
GEOMETRY = tuple([x] for x in (0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.1, 0.2, 0.5, 1.0, 1.0))
UP = np.tile([0.0, 0.0, 1.0], (8, 8, 1))

#: Function: (call, its valid arguments, {parameter: p(kind, ...)}).  The call takes them as keywords.
FUNCTIONS = {
    # lab.accuracy
    "accuracy.gradient_accuracy": (accuracy.gradient_accuracy, dict(field="sine", count=3, size=16, seed=4,
                                                                    steps=(1e-3,), k_u=8.0, k_v=4.0),
                                   dict(field=p("field"), count=p("int", (2**24 + 1, V, "16777217")),
                                        size=p("int", (4097, V, "4097")), seed=p("seed"), steps=p("steps"),
                                        k_u=p("real"), k_v=p("real", (0.0, V, "got 0.0")))),
    "accuracy.normal_beta_derivative_residual": (accuracy.normal_beta_derivative_residual, dict(trials=2, seed=5),
                                                 dict(trials=p("int", (0, V, "got 0")), seed=p("seed"))),
    "accuracy.image_beta_order": (accuracy.image_beta_order, dict(size=16, beta=0.35, steps=(0.1, 0.05)),
                                  dict(size=p("int"), beta=p("real", (101.0, V, "got 101.0")),
                                       steps=p("steps", ((0.1,), V, "2 or more"), ((0.5, 0.1), V, "beta +- db")))),
    "accuracy.crease_distance": (accuracy.crease_distance, dict(u=0.3, v=[0.4, 0.6], k_u=8.0, k_v=4.0, field="ridges"),
                                 dict(u=p("array", ([0.3, 0.4, 0.5], V, "broadcast"), ([1.5], V, "1.5 at flat index 0")),
                                      v=p("array", ([-0.1], V, "-0.1 at flat index 0")),
                                      k_u=p("real", (0.0, V, "got 0.0")), k_v=p("real", (1e4, V, "got 10000.0")),
                                      field=p("field"), along=p("own", ("w", V, "'w'"), (1, T, "int 1")))),
    "accuracy.measure_optimum": (accuracy.measure_optimum, dict(field="rings", u=0.31, v=0.47, component="v"),
                                 dict(field=p("field"), u=p("real", (1.5, V, "got 1.5")), v=p("real", (-0.1, V, "got -0.1")),
                                      component=p("own", ("w", V, "'w'"), (1, T, "int 1"),
                                                  ("u", V, "rings field's h''' along u at (0.31, 0.47) is 0")))),
    "accuracy.image_best_step": (accuracy.image_best_step, dict(field="sine", size=4),
                                 dict(field=p("field"), size=p("int", (0, V, "got 0")))),
    "accuracy.frame_model_step": (accuracy.frame_model_step, dict(field="sine", k_u=8.0, k_v=4.0, samples=8),
                                  dict(field=p("field"), k_u=p("real", (0.0, V, "got 0.0")), k_v=p("real"),
                                       samples=p("int", (4097, V, "4097")))),
    "accuracy.footprint_steps": (accuracy.footprint_steps, dict(scene=Scene(), size=8),
                                 dict(scene=p("own", (3, T, "got int")), size=p("int", (0, V, "got 0")))),
    "accuracy.footprint_median": (accuracy.footprint_median, dict(size=8), dict(size=p("int", (0, V, "got 0")))),
    # lab.gradient_methods
    "gradient_benchmark.Config": (gb.Config, CONFIG, {
        **{k: p("steps", ([1.0], V, "1.0 at flat index 0"), named=f"Config.{k}")
           for k in ("central_steps", "forward_steps", "complex_steps")},
        **{k: p("int", (1001, V, "1001"), named=f"Config.{k}") for k in ("repeats", "richardson_repeats")},
        "name": p("own", (None, T, "NoneType None"), named="Config.name"),
        "reference_pixels": p("int", named="Config.reference_pixels"),
        "digits": p("int", (31, V, "got 31"), named="Config.digits"),
        "size": p("int", (4097, V, "4097"), named="Config.size"), "seed": p("seed", named="Config.seed")}),
    "gradient_benchmark.chart_points": (gb.chart_points, dict(field="sine", size=16),
                                      dict(field=p("field"), size=p("int"))),
    "gradient_methods.forward_gradient": (gm.forward_gradient, dict(CHART, eps=1e-3), dict(CHART_KINDS, eps=EPS)),
    "gradient_methods.complex_step_gradient": (gm.complex_step_gradient, dict(CHART, eps=1e-20, continued=False),
                                               dict(CHART_KINDS, eps=EPS, continued=p("flag"))),
    "gradient_methods.richardson_gradient": (gm.richardson_gradient, dict(CHART, info={}),
                                             dict(CHART_KINDS, info=p("own", ([], T, "list []")))),
    "gradient_methods.ad_gradient": (gm.ad_gradient, dict(CHART, height=F.FIELDS["sine"].expr),
                                     dict(CHART_KINDS, height=p("own", ("u", T, "str 'u'"),
                                                                (sp.Symbol("w"), V, "it uses w"),
                                                                (sp.zoo * F.u, V, "must be real")))),
    "gradient_methods.xla_exact_gradient": (gm.xla_exact_gradient, CHART, CHART_KINDS),
    "gradient_methods.reference_gradient": (gm.reference_gradient, dict(CHART, digits=34),
                                            dict(CHART_KINDS, digits=p("int", (31, V, "got 31"), (1001, V, "1001")))),
    "gradient_methods.trig_calls": (gm.trig_calls, dict(exprs=(F.FIELDS["sine"].expr, 0)),
                                    dict(exprs=p("own", ("sin(u)", T, "str 'sin(u)'"),
                                                 (["sin(u)"], T, "str 'sin(u)'")))),
    "gradient_methods.stencil_values": (gm.stencil_values, dict(field="sine"), dict(field=p("field"))),
    "gradient_methods.height_work": (gm.height_work, dict(field="sine"), dict(field=p("field"))),
    "gradient_methods.ad_trig_calls": (gm.ad_trig_calls, dict(field="rings"),
                                       dict(field=p("field", ([], T, "got list")))),
    "gradient_methods.method": (gm.method, dict(name="exact"), dict(name=p("name", named="method"))),
    "gradient_methods.evaluations": (gm.evaluations, dict(field="sine", name="exact", info=None),
                                     dict(field=p("field"), name=p("name", named="method"),
                                          info=p("own", ("h", T, "str 'h'")))),
    "gradient_benchmark.measure": (gb.measure, dict(config="fast", fields_=("rings",), uv=(U8, V8)),
                                 dict(config=p("name", ((), T, "tuple ()")), fields_=p("fields"),
                                      uv=p("own", ("uv", T, "str 'uv'"), ((U8,), T, "tuple"),
                                           ((U8, [True] * 8), T, "list [True"), ((U8, V8[:4]), V, "(8,) and (4,)"),
                                           ((U8 + 1, V8), V, "1.1 at flat index 0")))),
    "gradient_benchmark.pareto_front": (gb.pareto_front, dict(results=[RESULT], error="max"),
                                      dict(results=p("own", ("r", T, "str 'r'"), ([RESULT, 1], T, "int 1")),
                                           error=p("name"))),
    "gradient_benchmark.to_json": (gb.to_json, dict(measurement=gb.Measurement(gb.FAST, (RESULT,), 1, {}, {}, {},
                                                                           1.0, 8.0, 4.0)),
                                 dict(measurement=p("own", ("m", T, "str 'm'"), (RESULT, T, "MethodResult")))),
    "gradient_methods.crease_values": (gm.crease_values, dict(v=0.47, eps=1e-3, ku=8.0, kv=4.0),
                                       dict(v=p("real", (1.5, V, "got 1.5")), eps=EPS, kv=p("real"),
                                            # u = 1/k_u, the second crease, must be on the chart
                                            ku=p("real", (0.5, V, "ku must be in [1, 1000], got 0.5")))),
    "gradient_methods.same_compiler_times": (gm.same_compiler_times, dict(uu=U8, vv=V8, ku=8.0, kv=4.0, rounds=1,
                                                                          fields_=("rings",)),
                                             dict(uu=p("array"), vv=p("array"), ku=p("real"), kv=p("real"),
                                                  rounds=p("int", (10**4 + 1, V, "10001")), fields_=p("fields"))),
    "gradient_benchmark.univariate_errors": (gb.univariate_errors, dict(function="exp(x)", x=0.5, steps=(1e-3,)),
                                           dict(function=p("field"), x=p("real"), steps=p("steps"))),
    # lab.fastmath
    "fastmath.backend": (fastmath.backend, dict(name="numpy"), dict(name=p("name", named="backend"))),
    "fastmath.flushes": (fastmath.flushes, dict(name="numpy"), dict(name=p("name", named="backend"))),
    "fastmath.arguments": (fastmath.arguments, dict(function="sin", count=4, seed=9),
                           dict(function=p("name"), count=p("int", (2**24 + 1, V, "16777217")), seed=p("seed"))),
    "fastmath.reference": (lambda function, args: fastmath.reference(function, *args),
                           dict(function="sin", args=([0.5],)),
                           dict(function=p("name"), args=p("own", (([True],), T, "list [True]"),
                                                           (([math.nan],), V, "nan at flat index 0"),
                                                           (([0.5], [0.5]), V, "1 array(s) for sin, got 2"),
                                                           (([0.5], [0.5, 0.6]), V, "shapes"), named="args"))),
    "fastmath.ulps": (fastmath.ulps, dict(values=[0.5, math.nan], hi=[0.5, 0.5], exponent=[-53], rest=[0.0]),
                      dict(values=p("own", ([True], T, "list [True]"), ("x", T, "str 'x'"),
                                    ([1.0] * 3, V, "broadcast")),
                           hi=p("array"), exponent=p("own", ([True], T, "list [True]"), ([0.5], T, "list [0.5]"),
                                                     ([-2000], V, "got -2000 at flat index 0")),
                           rest=p("array", ([0.6], V, "0.6 at flat index 0")))),
    "fastmath.ulp_table": (fastmath.ulp_table, dict(count=1, seed=9), dict(count=p("int"), seed=p("seed"))),
    "fastmath.central_differences": (fastmath.central_differences,
                                     dict(name="numpy", eps=[1e-3, 0.7], u=0.31, v=0.47, k_u=8.0, k_v=4.0),
                                     dict(name=p("name", named="backend"),
                                          eps=p("array", ([0.0], V, "0.0 at flat index 0")), u=p("real"),
                                          v=p("real", (-0.1, V, "got -0.1")), k_u=p("real"), k_v=p("real"))),
    # lab.inverse
    "inverse.jacobian": (inverse.jacobian, dict(mode="chart"), dict(mode=p("name", ([], T, "list []")))),
    "inverse.normal_and_jacobian": (inverse.normal_and_jacobian, dict(mode="surface", geometry=GEOMETRY, beta=0.35),
                                    dict(mode=p("name"),
                                         geometry=p("own", ("g", T, "str"), (GEOMETRY[1:], T, "tuple"),
                                                    (([math.nan],) + GEOMETRY[1:], V, "nan at flat index 0"),
                                                    (([0.0, 0.0],) + GEOMETRY[1:], V, "shapes")),
                                         beta=p("array", ([0.1, 0.2], V, "shape (2,)")))),
    "inverse.geometry": (inverse.geometry, dict(scene=Scene(), width=8, height=8),
                         dict(scene=p("own", ("scene", T, "got str")), width=p("int"), height=p("int"))),
    "inverse.fit_beta": (inverse.fit_beta, dict(target=UP, scene=Scene(), beta0=0.1, steps=2, tol=1e-12),
                         dict(target=p("own", ("x", T, "str 'x'"), (UP != 0, T, "array([[[False"),
                                       (UP * 1e308, V, "(0.0, 0.0, 1e+308)"), (UP[..., :2], V, "shape (8, 8, 2)")),
                              scene=p("own", ("scene", T, "got str")), beta0=p("real", (-0.1, V, "got -0.1")),
                              steps=p("int", (101, V, "101")), tol=p("real", (0.0, V, "got 0.0")))),
    # lab.displaced
    "displaced.surface_function": (displaced.surface_function, dict(field="sine"),
                                   dict(field=p("field", ([], T, "got list")))),
    "displaced.render_displaced": (displaced.render_displaced, dict(scene=Scene(), width=4, height=4, samples=2),
                                   dict(scene=p("own", ("scene", T, "got str")), width=p("int"), height=p("int"),
                                        samples=p("int", (4097, V, "4097")))),
    # lab.seed_errata
    "seed_errata.seed_chamber": (seed_errata.seed_chamber, dict(size=4), dict(size=p("int", (4097, V, "4097")))),
    "seed_errata.reproduced": (seed_errata.reproduced, dict(measured=ERRATA),
                               dict(measured=p("own", ("m", T, "str 'm'"), ({}, V, "missing sphere-b-quadratic"),
                                               (dict(ERRATA, **{"acos-pole": 1}), T, "int 1"), named="measured"))),
    # lab.claims
    "claims.relative_error_at": (claims.relative_error_at, dict(eps=1e-9), dict(eps=p("real", (1.0, V, "got 1.0")))),
    "claims.checked": (claims.checked, dict(results=[(claims.CLAIMS[0], {}, claims.CLAIMS[0].registered)]),
                       dict(results=p("own", ("r", T, "str 'r'"), ([(1, 2, 3)], T, "tuple (1, 2, 3)")))),
    "claims.rule": (lambda cases, otherwise: claims.rule(*cases, otherwise=otherwise),
                    dict(cases=(claims.HOLDS, claims.Bound("a", hi=1)), otherwise=claims.FAILS),
                    dict(cases=p("own", ((claims.HOLDS,), V, "got 1"), named="cases"),
                         otherwise=p("name", named="Criterion.otherwise"))),
    "claims.about": (claims.about, dict(quantity="q", x=2.0, lo=True, hi=True),
                     dict(quantity=p("own", (3, T, "int 3"), named="Bound.quantity"),
                          x=p("real", (-1.0, V, "got -1.0")), lo=p("flag"), hi=p("flag"))),
    "claims.Bound": (claims.Bound, dict(quantity="q", lo=1.0, hi=1.0, strict=False),     # lo = hi: a point
                     dict(quantity=p("own", (3, T, "int 3"), named="Bound.quantity"),
                          lo=p("real", (3.0, V, "lo = 3.0, hi = 1.0"), named="Bound.lo"),
                          hi=p("real", named="Bound.hi"), strict=p("flag", named="Bound.strict"))),
    "claims.Criterion": (claims.Criterion, dict(cases=((claims.HOLDS, (claims.Bound("a"),)),), otherwise=claims.FAILS),
                         dict(cases=p("own", ("c", T, "str 'c'"), (((claims.HOLDS, claims.Bound("a")),), T, "Bound("),
                                      ((("yes", ()),), V, "'yes'"), named="Criterion.cases"),
                              otherwise=p("name", named="Criterion.otherwise"))),
}


def cases():
    """(function, parameter, bad value, error, the name it gives, what it shows) for every parameter
    of every function of `FUNCTIONS`: its kind's bad values and its own."""
    for name, (_, _, kinds) in FUNCTIONS.items():
        for param, (kind, extra, named) in kinds.items():
            for k, (value, error, shown) in enumerate(BAD[kind] + list(extra)):
                yield pytest.param(name, param, value, error, named or param, shown, id=f"{name}-{param}-{k}")


@pytest.mark.parametrize("function, param, value, error, named, shown", list(cases()))
def test_each_parameter_refuses_bad_values(function, param, value, error, named, shown):
    call, valid, _ = FUNCTIONS[function]
    with pytest.raises((TypeError, ValueError)) as info:
        call(**dict(valid, **{param: value}))
    message = str(info.value)
    assert type(info.value) is error, f"{type(info.value).__name__}: {message}"
    subject, must, _ = message.partition(" must ")        # "uu, vv must broadcast ..." names both
    assert must and any(s.startswith(named) for s in subject.split(", ")) and shown in message, message
    assert len(message) < 600, message


def test_the_table_covers_every_public_function_and_parameter():
    """Every function of the modules' ``__all__`` with parameters, and every parameter, is in the table."""
    import inspect
    listed = {}
    for module in (accuracy, gm, gb, fastmath, inverse, displaced, seed_errata, claims):
        for name in module.__all__:
            obj = getattr(module, name)
            if (inspect.isfunction(obj) or inspect.isclass(obj) and name in ("Config", "Bound", "Criterion")) \
                    and inspect.signature(obj).parameters:
                listed[f"{module.__name__.split('.')[-1]}.{name}"] = set(inspect.signature(obj).parameters)
    missing, stale = sorted(set(listed) - set(FUNCTIONS)), sorted(set(FUNCTIONS) - set(listed))
    assert not missing and not stale, (f"public functions without a row in this file's FUNCTIONS: {missing} (give each "
                                       f"its call with good arguments and a refused value per parameter); rows of no "
                                       f"public function: {stale}")
    for name, params in listed.items():
        assert params == set(FUNCTIONS[name][2]), (f"{name}'s row in FUNCTIONS covers {sorted(FUNCTIONS[name][2])}, "
                                                   f"its parameters are {sorted(params)}")


@pytest.mark.parametrize("function", FUNCTIONS)
def test_a_valid_call_is_not_refused(function):
    """The baseline of the refusal tests here: the call they break, with every argument valid, is
    answered (what it answers is each function's own tests')."""
    call, valid, _ = FUNCTIONS[function]
    assert call(**valid) is not None
