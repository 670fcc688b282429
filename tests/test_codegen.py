"""renderer/codegen.py: the generated formulas are fresh, faithful to the sympy
objects of `renderer.formulas`, and the bits the renderer uses.

(a) Freshness: `codegen.targets()` equals renderer/generated.py,
    renderer/generated_array.py and renderer/kernel.py (what
    ``python -m renderer.codegen --check`` checks),
    and a tampered generated.py or digest line is caught; the generator runs
    where the kernel's import guard refuses a hand-edited generated.py.
(b) The JavaScript `codegen.js_source()` runs under node and computes the
    same functions (checked like (d)); its signatures are the Python ones.
    That the bundle uses it is tests/test_jsgen.py's subject.
(c) `renderer.pointwise` at a frame's own chart points gives the frame's
    gradient, crease flag and shading normal on sphere A bit for bit, for
    each gradient method.
(d) Every generated function agrees with an independent evaluation of its
    sympy object: mpmath at 60 digits walks the expression tree and carries
    a first-order forward error bound of float64 evaluation alongside
    (`evaluate`).  The printed code is the same tree after ``sympy.cse`` and
    the printers' regrouping, which changes the order of the roundings but
    not their number much, so a generated value must lie within twice that
    bound plus 8 units of roundoff of the exact value.  Points where a
    branch or sign is decided closer than its error bound are left out
    ("ambiguous"), and at most a tenth of them may be.  Verified
    numerically at seeded random points (`sample`), not proved.
(e) Wrong variants (a sign flipped in a formula, a changed cut-off, a
    tampered line of the printed source) printed through the same
    `codegen.python_source` are rejected by the checks of (d).

The height-field tests follow: the seed's closed forms, the central
difference's order and its border rules.
"""

from __future__ import annotations

import inspect
import json
import math
import os
import re
import shutil
import subprocess
import sys

import mpmath
import numpy as np
import pytest
import sympy as sp

from renderer import GRADIENTS, Scene, backends, codegen, fieldcode, gbuffer, pointwise, render
from renderer import formulas as F
from renderer.univariate import univariate
from renderer import generated as G
from renderer import generated_array as GA

from . import scalar_reference
from .jsnode import node_command
from .test_parity import field_bounds, require_backend

#: Unit roundoff of float64.
U = 2.0**-53
#: 60 digits: inputs are exact binary numbers and the worst cancellation in
#: these formulas (a central quotient at a step of 1e-12 of a point of size 1,
#: or a ray differential of a grazing ray) loses fewer than 20 of them, so
#: the reference keeps more than 40, far below the float64 error it bounds.
MP_DPS = 60
#: At most this fraction of a function's points may be left out as ambiguous.
MAX_AMBIGUOUS = 0.1


# ---- (d) an independent evaluator with a forward error bound ----------------------------

class Ambiguous(Exception):
    """A sign, branch or comparison is decided within its own error bound."""


def _number(e):
    v = mpmath.mpf(e.p) / e.q if e.is_Rational else mpmath.mpf(e._mpf_)
    exact = mpmath.mpf(float(v)) == v
    return v, (mpmath.mpf(0) if exact else U * abs(v))


def evaluate(expr, env):
    """(value, bound) of a sympy expression at ``env`` {Symbol: (value, bound)}.

    value is exact to ``MP_DPS`` digits; bound is a first-order bound on the
    error of evaluating the same tree in float64 with inputs carrying the
    given bounds: a sum adds its terms' bounds and (n - 1) u times the sum of
    their magnitudes; a product prod (|a| + b) - prod |a| (its factors' relative
    bounds, and their products, which alone remain where factors vanish) and
    (n - 1) u, a positive integer power likewise;
    1/x, sqrt, sin, cos, atan2, hypot and pow their derivative times the argument's
    bound and one rounding (two for the libm functions, which are within an
    ulp); pi and decimal constants one rounding.  A branch (Piecewise, sign,
    a comparison) decided within its bound raises `Ambiguous`.

    Each subexpression's result is kept in ``env`` and found there again: a tree
    evaluates its shared subtrees once (the generated code too: it is printed after
    common-subexpression elimination).
    """
    if expr not in env:
        env[expr] = _evaluate(expr, env)
    return env[expr]


def _evaluate(expr, env):
    if expr.is_Symbol:
        return env[expr]
    if expr is sp.pi:
        return +mpmath.pi, U * mpmath.pi
    if expr.is_Number:
        return _number(expr)
    args = [evaluate(a, env) for a in expr.args] if not isinstance(expr, sp.Piecewise) else None
    if isinstance(expr, sp.Add):
        vals = [a for a, _ in args]
        return mpmath.fsum(vals), sum(b for _, b in args) + (len(args) - 1) * U * sum(abs(a) for a in vals)
    if isinstance(expr, sp.Mul):
        vals = [a for a, _ in args]
        value = mpmath.fprod(vals)
        # prod (|a| + b) - prod |a|: first order, and the products of the errors (a product of
        # two factors near their zeros, sin^2 at a multiple of pi, has only those).
        bound = mpmath.fprod(abs(a) + b for a, b in args) - abs(value)
        return value, bound + (len(args) - 1) * U * abs(value)
    if isinstance(expr, sp.Pow):
        (x, bx), n = args[0], expr.exp
        if not n.is_Rational:
            raise NotImplementedError(f"power {expr}")
        n = mpmath.mpf(n.p) / n.q
        if x == 0:
            if bx == 0 and n > 0:
                return mpmath.mpf(0), mpmath.mpf(0)
            raise Ambiguous(f"{expr} at 0")
        value = x ** n if mpmath.isint(n) or x > 0 else mpmath.nan
        if mpmath.isint(n) and n > 0:            # (|x| + b)^n - |x|^n: every order, as for a product
            return value, (abs(x) + bx) ** n - abs(x) ** n + 2 * U * abs(value)
        return value, abs(n) * abs(x) ** (n - 1) * bx + 2 * U * abs(value)
    if isinstance(expr, (sp.sin, sp.cos)):
        (x, bx), = args
        value, slope = (mpmath.sin(x), mpmath.cos(x)) if isinstance(expr, sp.sin) else (mpmath.cos(x), mpmath.sin(x))
        return value, abs(slope) * bx + 2 * U * abs(value)
    if isinstance(expr, sp.atan2):
        (y, by), (x, bx) = args
        r2 = x * x + y * y
        if r2 == 0 or (x < 0 and abs(y) <= by):        # at the origin or on the branch cut
            raise Ambiguous(f"atan2 at ({y}, {x})")
        value = mpmath.atan2(y, x)
        return value, (abs(x) * by + abs(y) * bx) / r2 + 2 * U * abs(value)
    if isinstance(expr, sp.Abs):
        (x, bx), = args
        return abs(x), bx
    if isinstance(expr, F.hypot):                  # 1-Lipschitz in each argument; libm's within an ulp
        (x, bx), (y, by) = args
        value = mpmath.hypot(x, y)
        slope = (abs(x) * bx + abs(y) * by) / value if value > 0 else bx + by
        return value, slope + 2 * U * value
    if isinstance(expr, sp.sign):
        (x, bx), = args
        if x == 0 and bx == 0:
            return mpmath.mpf(0), mpmath.mpf(0)
        if abs(x) <= bx:
            raise Ambiguous(f"sign of {x} +- {bx}")
        return mpmath.sign(x), mpmath.mpf(0)
    if isinstance(expr, (sp.Min, sp.Max)):
        pick = min if isinstance(expr, sp.Min) else max
        return pick(a for a, _ in args), max(b for _, b in args)
    if isinstance(expr, sp.Piecewise):
        for piece, condition in expr.args:
            decided = decide(condition, env)
            if decided is None:
                raise Ambiguous(f"branch {condition}")
            if decided:
                return evaluate(piece, env)
        raise ValueError(f"no branch of {expr} holds")
    raise NotImplementedError(f"{type(expr).__name__}: {expr}")


def decide(condition, env):
    """True, False, or None where float64 rounding could decide either way."""
    if condition is sp.true or condition is sp.false:
        return bool(condition)
    if isinstance(condition, (sp.Or, sp.And)):
        parts = [decide(c, env) for c in condition.args]
        want = isinstance(condition, sp.Or)
        if want in parts:
            return want
        return None if None in parts else not want
    (lhs, bl), (rhs, br) = evaluate(condition.lhs, env), evaluate(condition.rhs, env)
    if abs(lhs - rhs) <= bl + br and bl + br > 0:
        return None
    ops = {sp.StrictGreaterThan: lambda a, b: a > b, sp.GreaterThan: lambda a, b: a >= b,
           sp.StrictLessThan: lambda a, b: a < b, sp.LessThan: lambda a, b: a <= b}
    return ops[type(condition)](lhs, rhs)


def signature(name, field):
    """(arguments, outputs) of a generated function: the entry ``name`` of `formulas.FUNCTIONS`
    (``field`` ''), or of `formulas.FIELD_FUNCTIONS` for the registered field ``field``."""
    if not field:
        return F.FUNCTIONS[name]
    args, outputs = F.FIELD_FUNCTIONS[name]
    return args, outputs(F.FIELDS[field])


def reference(name, field, point):
    """[(value, bound) or None (ambiguous) or bool] per output of ``name`` at ``point``."""
    args, exprs = signature(name, field)
    with mpmath.workdps(MP_DPS):
        env = {s: (mpmath.mpf(x), mpmath.mpf(0)) for s, x in zip(args, point)}
        try:
            for symbol, expr in F.PRELUDE.get(name, ()):
                env[symbol] = evaluate(expr, env)
        except Ambiguous:
            return [None] * len(exprs)
        out = []
        for expr in exprs:
            try:
                out.append(decide(expr, env) if isinstance(expr, sp.logic.boolalg.Boolean)
                           else evaluate(sp.sympify(expr), env))
            except Ambiguous:
                out.append(None)
        return out


def excess(got, want):
    """How far ``got`` lies outside the allowance around ``want`` (<= 0: inside)."""
    if want is None or got is None:          # ambiguous, or an output not computed (JavaScript)
        return -1.0
    if isinstance(want, bool):
        is_flag = isinstance(got, (bool, np.bool_)) or got in (0.0, 1.0)
        return 0.0 if is_flag and bool(got) == want else 1.0
    value, bound = want
    if not math.isfinite(got):
        return math.inf
    return float(abs(mpmath.mpf(got) - value) - (2 * bound + 8 * U * abs(value)))


# ---- samples: the inputs of each generated function ------------------------------------

def _sin_phi(N):
    """sin(phi) of unit normals N (n, 3), by `renderer.pointwise.chart` (inputs only)."""
    return pointwise.chart(*N.T)[2]


def _frame(N):
    """(sin phi, e_theta, e_phi) rows for unit normals N (n, 3), with the pole
    fallback, by `renderer.pointwise` (inputs only)."""
    s = _sin_phi(N)
    et, ep = (np.stack(e, -1) for e in pointwise.tangent_frame(*N.T, s))
    return s, et, ep


def _normals(rng, n):
    N = rng.normal(size=(n, 3))
    # A tenth near the poles, sin(phi) from 1e-7 to 1e-2: on both sides of the draft's cut-off 1e-4.
    k = n // 10
    N[:k, :2] *= 10.0 ** rng.uniform(-7, -2, size=(k, 1))
    return N / np.linalg.norm(N, axis=-1, keepdims=True)


def _chart_points(rng, n):
    u, v = rng.random(n), rng.random(n)
    edges = [0.0, 1.0, 0.5, 0.25, 1 / 3, 2**-30, 1 - 2**-53, 0.125]
    u[:8], v[:8] = edges, edges[::-1]
    k = np.where(rng.random((n, 2)) < 0.25, rng.choice([8.0, 4.0, 300.0], (n, 2)), rng.uniform(0.3, 20, (n, 2)))
    return u, v, k[:, 0], k[:, 1]


def _steps(rng, n, low=-12):
    return 10.0 ** rng.uniform(low, math.log10(0.25), n)


def sample(name, rng, n=160):
    """Argument tuples for ``name`` (by its formulas.FUNCTIONS signature)."""
    if name in ("height", "exact", "kink"):
        return list(zip(*_chart_points(rng, n)))
    if name == "central":
        u, v, ku, kv = _chart_points(rng, n)
        eu, ev = _steps(rng, n), _steps(rng, n)
        # A quarter within a step of the border v = 0 or 1, where the quotient is one-sided.
        q = n // 4
        v[:q] = np.where(rng.random(q) < 0.5, ev[:q] * rng.random(q), 1 - ev[:q] * rng.random(q))
        return list(zip(u, v, ku, kv, eu, ev))
    if name == "chart":
        return [tuple(p) for p in _normals(rng, n)]
    if name == "tangent_frame":
        N = _normals(rng, n)
        return [tuple(p) + (s,) for p, s in zip(N, _sin_phi(N))]
    if name.startswith("perturbed_normal"):
        N = _normals(rng, n)
        s, et, ep = _frame(N)
        hu, hv, beta = rng.uniform(-60, 60, n), rng.uniform(-60, 60, n), rng.uniform(0, 2, n)
        head = np.column_stack([N, et, ep, hu, hv])
        if name.endswith("chart"):
            return [tuple(r) + (b,) for r, b in zip(head, beta)]
        R = rng.uniform(0.5, 2.0, n)
        return [tuple(r) + (0.99 * b * R_ / 2, h, R_, s_)
                for r, b, h, R_, s_ in zip(head, beta, rng.uniform(-1, 1, n), R, s)]
    if name == "footprint":
        return footprint_points(rng, n)
    raise KeyError(f"no sampler for generated function {name!r}: add one to tests/test_codegen.py")


def footprint_points(rng, n):
    """Pixels on sphere A of random cameras: (x, y), spacing, eye, hit, normal, frame."""
    R = rng.uniform(0.3, 2.0, n)
    e = R * rng.uniform(1.2, 8.0, n)
    rho = e * R / np.sqrt(e * e - R * R)                   # silhouette radius on z = 0
    r = rho * np.sqrt(rng.random(n)) * 0.97
    r[: n // 10] = rho[: n // 10] * 10.0 ** rng.uniform(-7, -3, n // 10)   # near the pole
    ang = rng.uniform(0, 2 * np.pi, n)
    x, y = r * np.cos(ang), r * np.sin(ang)
    a, c = x * x + y * y + e * e, e * e - R * R
    t = (e * e - np.sqrt(e**4 - a * c)) / a
    P = np.column_stack([t * x, t * y, e * (1 - t)])
    N = P / R[:, None]
    s, et, ep = _frame(N)
    dx = rho * 10.0 ** rng.uniform(-3, -0.3, n)          # the largest reach the 0.25 cap
    dy = dx * rng.uniform(0.5, 2.0, n)
    return [(x[i], y[i], dx[i], dy[i], e[i], *P[i], *N[i], *et[i], *ep[i], R[i], s[i]) for i in range(n)]


def _points(fields=None):
    """{(name, field): [args]}: field '' for the functions of no field (`formulas.FUNCTIONS`), and
    each entry of `formulas.FIELD_FUNCTIONS` per field of ``fields`` (every registered one); one
    seed each."""
    out = {(name, ""): sample(name, np.random.default_rng([2026, i])) for i, name in enumerate(F.FUNCTIONS)}
    for i, name in enumerate(F.FIELD_FUNCTIONS):
        for field in F.FIELDS if fields is None else fields:
            out[name, field] = sample(name, np.random.default_rng([2026, 100 + i, *map(ord, field)]))
    return out


@pytest.fixture(scope="module")
def points():
    return _points()


@pytest.fixture(scope="module")
def references(points):
    return {key: [reference(key[0], key[1], p) for p in pts] for key, pts in points.items()}


def function(namespace, name, field):
    """The generated ``name`` (of ``field``) in ``namespace``: a dict of printed functions (a field's
    named ``<field>_<name>``; a field the namespace lacks, one not built in, is `fieldcode`'s), or
    None for the compiled code the kernel runs (generated.py's, and `fieldcode.compiled`'s)."""
    if not field:
        return namespace[name] if namespace is not None else getattr(G, name)
    if namespace is not None and f"{field}_{name}" in namespace:
        return namespace[f"{field}_{name}"]
    return getattr(fieldcode.compiled(F.FIELDS[field]), name)


def call(namespace, name, field, point):
    """Outputs (a tuple) of the generated ``name`` from ``namespace`` (`function`)."""
    out = function(namespace, name, field)(*(float(a) for a in point))
    return out if isinstance(out, tuple) else (out,)


def outputs_of(namespace, points, names=None):
    return {key: [call(namespace, key[0], key[1], p) for p in pts]
            for key, pts in points.items() if names is None or key[0] in names}


def mismatches(results, references, points):
    """[(name, field, output index, point, got, exact value)] beyond the allowance,
    plus an entry for every function with too many ambiguous points."""
    bad = []
    for key, rows in results.items():
        refs = references[key]
        ambiguous = sum(r is None for ref in refs for r in ref)
        if ambiguous > MAX_AMBIGUOUS * sum(len(ref) for ref in refs):
            bad.append((*key, "ambiguous", ambiguous))
        for point, got, ref in zip(points[key], rows, refs):
            if len(got) != len(ref):
                bad.append((*key, "outputs", len(got), len(ref)))
                continue
            for k, (g, r) in enumerate(zip(got, ref)):
                if excess(g, r) > 0:
                    bad.append((*key, k, point, g, r if r is None or isinstance(r, bool) else float(r[0])))
    return bad


def test_every_generated_function_has_samples_of_each_field(points):
    assert set(points) == {(n, "") for n in F.FUNCTIONS} | {(n, f) for n in F.FIELD_FUNCTIONS for f in F.FIELDS}
    assert all(len(p) >= 100 for p in points.values())


def test_generated_functions_agree_with_the_sympy_objects(points, references):
    """The compiled code the kernel calls: generated.py's functions and each field's cfuncs."""
    bad = mismatches(outputs_of(None, points), references, points)
    assert bad == [], bad[:5]


def test_the_printed_source_run_as_python_agrees_too(points, references):
    """The route the wrong variants below take (the printed text, exec'd without
    numba) passes with the true formulas: a rejection there is the variant's."""
    bad = mismatches(outputs_of(plain_python(codegen.python_source()), points), references, points)
    assert bad == [], bad[:5]


def array_outputs(module, points, xp):
    """`outputs_of` for the branch-free array functions of ``module`` (generated_array.py
    or its printed text run): each function called once on all points of a key, as columns."""
    column = xp.Float64 if xp.name == "drjit" else np.asarray
    results = {}
    for (name, field), pts in points.items():
        if module is not None and (not field or f"{field}_{name}" in module):
            fn = module[f"{field}_{name}" if field else name]
        else:
            fn = getattr(fieldcode.array_code(F.FIELDS[field]), name) if field else getattr(GA, name)
        out = fn(xp, *(column(np.array(c, dtype=np.float64)) for c in zip(*pts)))
        out = out if isinstance(out, tuple) else (out,)
        arrays = [o for o in out if not isinstance(o, (bool, float))]     # a constant output is a Python value
        values = iter(xp.numpy([([a], np.float64) for a in arrays]))
        cols = [np.full(len(pts), o) if isinstance(o, (bool, float)) else next(values) for o in out]
        results[name, field] = [tuple(c[i].item() for c in cols) for i in range(len(pts))]
    return results


@pytest.mark.parametrize("backend", ["numpy", "drjit"])
def test_generated_array_functions_agree_with_the_sympy_objects(points, references, backend):
    """renderer/generated_array.py under each namespace: every Piecewise became a select
    that keeps the right side, and Dr.Jit's sin, cos and atan2 stay within the bound."""
    require_backend(backend)
    xp = backends.namespace(backend)
    with xp.scope():
        bad = mismatches(array_outputs(None, points, xp), references, points)
    assert bad == [], bad[:5]


@pytest.mark.parametrize("old, new", [
    ("xp.select(x2, -x1, 1.0)", "xp.select(x2, 1.0, -x1)"),        # a select's sides swapped
    ("xp.minimum(1, eps_v + v)", "xp.maximum(1, eps_v + v)"),      # the clamp of v inverted
    ("xp.select(x6 == 0, 0.0,", "xp.select(x6 != 0, 0.0,"),        # sign(0) taken as the other case
])
def test_the_array_check_rejects_a_tampered_line_of_the_printed_source(old, new, points, references):
    source = codegen.array_source()
    assert old in source
    namespace = {}
    exec(compile(source.replace(old, new), "<variant>", "exec"), namespace)
    with np.errstate(all="ignore"):
        assert mismatches(array_outputs(namespace, points, backends.namespace("numpy")), references, points)


# ---- (e) wrong variants, printed by the same generator -----------------------------------

def plain_python(source):
    """Namespace of a printed generated.py run as plain Python (no numba compile)."""
    namespace = {}
    exec(compile(re.sub(r"^@njit\(.*\)\n", "", source, flags=re.M), "<variant>", "exec"), namespace)
    return namespace


def _replace_output(name, field, index, new):
    """The entry ``name`` of `formulas.FUNCTIONS` (or of `FIELD_FUNCTIONS`, for ``field`` only)
    with its output ``index`` replaced by ``new(output)``."""
    def changed(outputs):
        outputs = list(outputs)
        outputs[index] = new(outputs[index])
        return tuple(outputs)
    if not field:
        args, outputs = F.FUNCTIONS[name]
        return args, changed(outputs)
    args, outputs = F.FIELD_FUNCTIONS[name]
    return args, lambda record: changed(outputs(record)) if record.name == field else outputs(record)


def _doubled_footprint(expr):
    cond = expr.args[0].cond                     # half > 0 (and below the limit)
    half = (cond.args[0] if isinstance(cond, sp.And) else cond).lhs
    return expr.xreplace({half: 2 * half})


def _two_sided(expr):
    """rings' h_v over 2 eps_v everywhere, also where v was clamped (the seed's slip)."""
    h = F.FIELDS["rings"].expr
    return (h.xreplace({F.v: F.v_p}) - h.xreplace({F.v: F.v_m})) / (2 * F.eps_v)


VARIANTS = {
    "h_u of sine with its sign flipped": ("exact", "sine", 1, lambda e: -e),
    "the chart's u from atan2(N_x, N_y)": ("chart", "", 0, lambda e: e.xreplace({F.N_x: F.N_y, F.N_y: F.N_x})),
    "the draft's pole cut-off 1e-4": ("tangent_frame", "", 3,
                                      lambda e: e.xreplace({F.POLE_SIN_PHI: sp.Float(1e-4)})),
    "the draft's floor of sin phi in the surface normal": (
        "perturbed_normal_surface", "", 0,
        lambda e: e.xreplace({F.sin_phi: sp.Max(F.sin_phi, sp.Float(1e-4))})),
    "the surface normal with pi halved": ("perturbed_normal_surface", "", 0,
                                            lambda e: e.xreplace({sp.pi: sp.pi / 2})),
    "the footprint without pbrt's half": ("footprint", "", 1, _doubled_footprint),
    "a two-sided v quotient at the border": ("central", "rings", 2, _two_sided),
    "the crease band twice as wide": ("kink", "ridges", 0,
                                      lambda e: e.xreplace({F.KINK_BAND_HALF_WIDTH: sp.Float(0.06)})),
}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_the_checks_reject_a_wrong_formula(variant, points, references, monkeypatch):
    name, field, index, change = VARIANTS[variant]
    table = F.FIELD_FUNCTIONS if field else F.FUNCTIONS
    original = table[name]
    monkeypatch.setitem(table, name, _replace_output(name, field, index, change))
    source = codegen.python_source()
    assert codegen.targets()[codegen.GENERATED] != codegen.GENERATED.read_text(encoding="utf-8")
    monkeypatch.setitem(table, name, original)
    bad = mismatches(outputs_of(plain_python(source), points, {name}), references, points)
    assert {(b[0], b[1]) for b in bad} == {(name, field)}, bad[:3]


@pytest.mark.parametrize("old, new", [
    ("math.atan2(N_y, N_x)", "math.atan2(N_x, N_y)"),     # arguments swapped
    ("(1/2)*", "(1//2)*"),                                 # integer division
    ("math.cos(", "math.sin("),                            # a derivative's cosine
])
def test_the_checks_reject_a_tampered_line_of_the_printed_source(old, new, points, references):
    source = codegen.python_source()
    assert old in source
    bad = mismatches(outputs_of(plain_python(source.replace(old, new)), points), references, points)
    assert bad


def test_excess_rejects_a_value_one_bound_away():
    value, bound = mpmath.mpf(1), mpmath.mpf(1e-15)
    assert excess(1.0, (value, bound)) <= 0
    assert excess(1.0 + 4e-15, (value, bound)) > 0
    assert excess(True, True) <= 0 and excess(False, True) > 0 and excess(math.nan, (value, bound)) > 0


# ---- (a) freshness ----------------------------------------------------------------------

@pytest.fixture
def copies(tmp_path, monkeypatch):
    """generated.py, generated_array.py and kernel.py copied to a temporary directory and made
    the generator's targets."""
    paths = {}
    for attr in ("GENERATED", "GENERATED_ARRAY", "KERNEL"):
        src = getattr(codegen, attr)
        paths[attr] = tmp_path / src.name
        paths[attr].write_bytes(src.read_bytes())
        monkeypatch.setattr(codegen, attr, paths[attr])
    return paths


@pytest.mark.parametrize("target, old, new", [
    ("GENERATED", "math.sin(", "math.cos("),
    ("GENERATED", "0.03", "0.031"),
    ("GENERATED_ARRAY", "xp.sin(", "xp.cos("),
    ("KERNEL", 'FORMULAS_DIGEST = "', 'FORMULAS_DIGEST = "0'),
])
def test_check_catches_a_tampered_file_and_the_generator_restores_it(copies, capsys, target, old, new):
    path = copies[target]
    fresh = path.read_text(encoding="utf-8")
    assert old in fresh
    path.write_text(fresh.replace(old, new, 1), encoding="utf-8")
    assert codegen.main(["--check"]) == 1
    assert f"{path} is stale" in capsys.readouterr().err
    assert codegen.main([]) == 0
    assert path.read_text(encoding="utf-8") == fresh
    assert codegen.main(["--check"]) == 0


@pytest.mark.parametrize("target", ["GENERATED", "GENERATED_ARRAY"])
def test_check_catches_a_missing_generated_file_and_the_generator_writes_it(copies, capsys, target):
    path = copies[target]
    fresh = path.read_text(encoding="utf-8")
    path.unlink()
    assert codegen.main(["--check"]) == 1 and f"{path} is stale" in capsys.readouterr().err
    assert codegen.main([]) == 0 and path.read_text(encoding="utf-8") == fresh


@pytest.mark.parametrize("code", [fieldcode.compiled, fieldcode.array_code])
def test_a_built_in_field_the_generator_has_not_printed_sends_the_author_to_it(code, monkeypatch):
    """A field registered among the built-in ones since the generator last ran (as a line added to
    formulas.py is) has no generated code: the error names the generator's command, not a KeyError."""
    late = F.HeightField("late", F.u * F.v)
    monkeypatch.setattr(F, "FIELDS", {**F.FIELDS, "late": late})
    monkeypatch.setattr(F, "BUILTIN", (*F.BUILTIN, "late"))
    with pytest.raises(RuntimeError, match=r"no code for the height field 'late'.*run python -m renderer\.codegen"):
        code(late)


@pytest.mark.parametrize("lines", [0, 2])
def test_a_kernel_without_exactly_one_digest_line_is_refused(lines):
    text = "x = 1\n" + 'FORMULAS_DIGEST = "abc"  # of generated.py\n' * lines
    with pytest.raises(ValueError, match="one line starting 'FORMULAS_DIGEST = '"):
        codegen.kernel_text(text)


def test_python_m_renderer_codegen_check_exits_0():
    """The generated files are fresh, as ``python -m renderer.codegen --check`` says, and the header says so."""
    result = subprocess.run([sys.executable, "-m", "renderer.codegen", "--check"], capture_output=True,
                            text=True, timeout=300, cwd=codegen.GENERATED.parents[1])
    assert (result.returncode, result.stderr) == (0, "")
    for module in (G, GA):
        assert module.__doc__.startswith("GENERATED by renderer/codegen.py from renderer/formulas.py; do not edit.")


def test_the_generator_runs_where_the_kernel_refuses_a_hand_edited_generated_file(tmp_path):
    """The kernel's import guard sends a reader to ``python -m renderer.codegen`` when
    generated.py does not match its digest; in a copy of the package with a line appended
    to generated.py, importing the kernel fails, and the generator runs and restores it."""
    shutil.copytree(codegen.GENERATED.parent, tmp_path / "renderer",
                    ignore=shutil.ignore_patterns("__pycache__"))
    generated = tmp_path / "renderer" / "generated.py"
    fresh = generated.read_text(encoding="utf-8")
    generated.write_text(fresh + "# edited by hand\n", encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    guard = subprocess.run([sys.executable, "-c", "import renderer.kernel"], capture_output=True, text=True,
                           cwd=tmp_path, env=env, timeout=300)
    assert guard.returncode == 1 and "run python -m renderer.codegen" in guard.stderr
    run = subprocess.run([sys.executable, "-m", "renderer.codegen"], capture_output=True, text=True,
                         cwd=tmp_path, env=env, timeout=300)
    assert run.returncode == 0, run.stderr
    assert generated.read_text(encoding="utf-8") == fresh


# ---- (b) the JavaScript printed from the same objects -------------------------------------

_NODE_DRIVER = """
import { readFileSync } from "node:fs";
const F = await import(process.argv[2]);
const jobs = JSON.parse(readFileSync(0, "utf-8"));
const out = {};
for (const [key, job] of Object.entries(jobs)) {
  const lead = job.field === "" ? [] : [F.FIELD_CODES[job.field]];
  out[key] = job.points.map((args) => {
    const buf = new Array(job.outputs).fill(NaN);
    const r = F[job.name](...lead, ...args, buf);
    return job.outputs > 1 ? Array.from(r) : [r];
  });
}
process.stdout.write(JSON.stringify(out));
"""


#: The JavaScript function of each entry of `formulas.FIELD_FUNCTIONS`, and the outputs it returns.
JS_OF_ENTRY = {entry: (name, keep) for name, (entry, keep) in codegen.JS_FIELD_FUNCTIONS.items()}


def run_js(source, points, tmp_path):
    """Outputs of the JavaScript ``source``'s functions at ``points``, run by node: a field's
    function gives the outputs its JavaScript twin returns (`codegen.JS_FIELD_FUNCTIONS`), None
    in the place of the others."""
    node = node_command("runs the generated JavaScript formulas")
    (tmp_path / "formulas.mjs").write_text(source, encoding="utf-8")
    (tmp_path / "driver.mjs").write_text(_NODE_DRIVER, encoding="utf-8")
    jobs, places = {}, {}
    for (name, field), pts in points.items():
        n = len(signature(name, field)[1])
        js, keep = JS_OF_ENTRY[name] if field else (name, tuple(range(n)))
        places[name, field] = (n, keep)
        jobs[f"{name}/{field}"] = dict(name=js, field=field, outputs=len(keep), points=[list(map(float, p)) for p in pts])
    result = subprocess.run([*node, str(tmp_path / "driver.mjs"), (tmp_path / "formulas.mjs").as_uri()],
                            input=json.dumps(jobs), capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    out = {}
    for key, rows in json.loads(result.stdout).items():
        n, keep = places[tuple(key.split("/"))]
        placed = [{i: math.nan if x is None else x for i, x in zip(keep, row)} for row in rows]
        out[tuple(key.split("/"))] = [tuple(row.get(i) for i in range(n)) for row in placed]
    return out


def test_javascript_formulas_agree_with_the_sympy_objects(points, references, tmp_path):
    bad = mismatches(run_js(codegen.js_source(), points, tmp_path), references, points)
    assert bad == [], bad[:5]


def test_javascript_check_rejects_a_flipped_sign(points, references, tmp_path):
    source = codegen.js_source()
    old = "return Math.sin(Math.PI*k_u*u)*Math.sin(Math.PI*k_v*v);"
    assert old in source
    wrong = {k: p for k, p in points.items() if k == ("height", "sine")}
    bad = mismatches(run_js(source.replace(old, "return -" + old[7:]), wrong, tmp_path), references, wrong)
    assert bad


def test_javascript_signatures_are_the_python_ones():
    source = codegen.js_source()
    for name, (args, outputs) in F.FUNCTIONS.items():
        params = list(inspect.signature(getattr(G, name).py_func).parameters)
        assert f"export function {name}({', '.join(params + (['out'] if len(outputs) > 1 else []))}) {{" in source, name
    for entry, (name, keep) in JS_OF_ENTRY.items():
        params = ["field", *map(str, F.FIELD_FUNCTIONS[entry][0]), *(["out"] if len(keep) > 1 else [])]
        assert f"export function {name}({', '.join(params)}) {{" in source, name
    assert codegen.js_source() == source                   # regenerated, the same text


def unread_names(source):
    """{function: names it assigns and never reads} of generated Python (ast) or JavaScript
    (``const NAME = ...;``, read where the name occurs again in its function)."""
    if "export function" in source:
        functions = {m.group(1): m.group(0) for m in re.finditer(r"export function (\w+)\(.*?\n}", source, re.S)}
        found = {f: {n for n in re.findall(r"const (\w+) =", body) if len(re.findall(rf"\b{n}\b", body)) == 1}
                 for f, body in functions.items()}
    else:
        import ast
        found = {}
        for fn in (n for n in ast.walk(ast.parse(source)) if isinstance(n, ast.FunctionDef)):
            names = [n for n in ast.walk(fn) if isinstance(n, ast.Name)]
            found[fn.name] = ({n.id for n in names if isinstance(n.ctx, ast.Store)}
                              - {n.id for n in names if isinstance(n.ctx, ast.Load)})
    return {f: names for f, names in found.items() if names}


def test_no_generated_function_assigns_a_name_it_never_reads():
    """The prelude (the central quotient's stencil points) is written only where read: rings' h does
    not depend on u, and its central functions once assigned u_p and u_m for nothing, in every
    backend's text.  Over the built-in fields, a reader's field, and a function of one variable;
    the check is shown finding such a line planted into each language."""
    sources = {"python": codegen.python_source(), "array": codegen.array_source(), "js": codegen.js_source(),
               "own field": codegen.field_source(F.field("sin(pi*k_v*v)**3")),
               "univariate": codegen.univariate_source(univariate("exp(x)/sqrt(sin(x)**3 + cos(x)**3)"))}
    assert {k: unread_names(s) for k, s in sources.items()} == {k: {} for k in sources}
    assert unread_names(sources["python"].replace("    return (math.sin(v*x0)", "    w_p = u + 1\n    return (math.sin(v*x0)", 1)) \
        == {"rings_central": {"w_p"}}
    js = sources["js"].replace("  if (field === ", "  if (field === 99) { const w_p = u + 1; return w_p; }\n"
                               "  const u_q = u;\n  if (field === ", 1)
    assert list(unread_names(js).values()) == [{"u_q"}]


# ---- (c) pointwise gives the renderer's bits ----------------------------------------------

def each(fn, *arrays):
    """A generated scalar function applied elementwise (a tuple of arrays out)."""
    rows = [fn(*map(float, args)) for args in zip(*arrays)]
    return tuple(np.array(c) for c in zip(*rows))


def pointwise_pixels(scene, g, gradient, *, dy_sign=1.0):
    """(grad, kink, Ns) on sphere A recomputed by `renderer.pointwise` from the
    GBuffer's normals and pixel centres: render's pixel spacing dx = x1 - x0,
    dy = y0 - y1 (the neighbouring row above), steps per gradient method."""
    a = g.chamber == 1
    N = g.N[a]
    u, v, sin_phi = pointwise.chart(*N.T)
    field, ku, kv = scene.height_field, scene.k_u, scene.k_v
    e_th, e_ph = pointwise.tangent_frame(*N.T, sin_phi)
    if gradient == "exact":
        hu, hv = pointwise.exact_gradient(field, u, v, ku, kv)
    elif gradient == "central":
        hu, hv = pointwise.central_gradient(field, u, v, ku, kv, scene.eps)
    else:
        X, Y = np.meshgrid(g.x, g.y)
        dx, dy = g.x[1] - g.x[0], dy_sign * (g.y[0] - g.y[1])
        eu, ev = pointwise.footprint(X[a], Y[a], dx, dy, scene.camera_z, tuple(g.P[a].T), tuple(N.T),
                                     e_th, e_ph, scene.radius_a, sin_phi)
        hu, hv = pointwise.central_gradient(field, u, v, ku, kv, eu, ev)
    kink = pointwise.kink_band(field, u, v, ku, kv)
    if scene.bump == "chart":
        Ns = np.column_stack(each(G.perturbed_normal_chart, *N.T, *e_th, *e_ph, hu, hv, np.full(u.shape, scene.beta)))
    else:
        h = pointwise.height(field, u, v, ku, kv)
        n = u.shape
        Ns = np.column_stack(each(G.perturbed_normal_surface, *N.T, *e_th, *e_ph, hu, hv, np.full(n, scene.beta), h,
                                  np.full(n, scene.radius_a), sin_phi))
    return (u, v), np.column_stack([hu, hv]), kink, Ns


def pixel_differences(scene, size, gradient, frame, g, **kw):
    """Names of the outputs of ``frame`` / ``g`` on sphere A that pointwise does not reproduce bit for bit."""
    a = g.chamber == 1
    uv, grad, kink, Ns = pointwise_pixels(scene, g, gradient, **kw)
    checks = {"uv": (g.uv[a], np.column_stack(uv)), "grad": (frame.grad[a], grad), "gbuffer grad": (g.grad[a], grad),
              "kink": (frame.kink[a], kink), "Ns": (g.Ns[a], Ns),
              "off A": (np.concatenate([frame.grad[~a].ravel(), frame.kink[~a].ravel()]), 0)}
    return [k for k, (x, y) in checks.items() if not np.array_equal(x, np.broadcast_to(y, np.shape(x)))]


POINTWISE_SCENES = {
    "ridges": Scene(beta=1.2, bump="chart"),
    "sine, surface bump": Scene(height_field="sine", bump="surface", beta=0.6, k_u=3.3, k_v=7.1),
    "rings, eps 0.05": Scene(height_field="rings", eps=0.05, camera_z=2.5),
    "ridges, beta 0": Scene(beta=0.0),
}


@pytest.mark.parametrize("gradient", GRADIENTS)
@pytest.mark.parametrize("name", sorted(POINTWISE_SCENES))
def test_pointwise_gives_the_renderers_bits(name, gradient):
    scene = POINTWISE_SCENES[name]
    for size in ((24, 20), (17, 20)):                        # 17 x 20 puts a pixel on the pole
        frame, g = render(scene, *size, gradient=gradient), gbuffer(scene, *size, gradient=gradient)
        assert np.count_nonzero(g.chamber == 1) > 100
        assert pixel_differences(scene, size, gradient, frame, g) == [], size


@pytest.mark.parametrize("gradient, wrong", [
    ("exact", dict(gradient="central")), ("central", dict(eps=1.001e-3)), ("footprint", dict(dy_sign=-1.0)),
    ("exact", dict(k_v=4.5)), ("exact", dict(beta=0.36)), ("exact", dict(bump="chart")),
])
def test_the_pointwise_check_rejects_another_pipeline(gradient, wrong):
    scene, size, wrong = Scene(), (24, 20), dict(wrong)
    frame, g = render(scene, *size, gradient=gradient), gbuffer(scene, *size, gradient=gradient)
    kw = {k: wrong.pop(k) for k in ("gradient", "dy_sign") if k in wrong}
    assert pixel_differences(scene.replace(**wrong), size, kw.pop("gradient", gradient), frame, g, **kw)


# ---- the height fields ------------------------------------

def closed_form_excess(exprs, field, points):
    """`excess` of the seed's closed forms (h, h_u, h_v), as tests/scalar_reference.py
    types them by hand (`seed_height`, `seed_gradient`, float64), over the mpmath value of
    ``exprs`` (sympy expressions in u, v, k_u, k_v; a shorter tuple compares its first
    components) at each chart point; an ambiguous sign is left out."""
    out = []
    for point in points:
        point = tuple(map(float, point))
        seed = (scalar_reference.seed_height(field, *point), *scalar_reference.seed_gradient(field, *point))
        with mpmath.workdps(MP_DPS):
            env = {s: (mpmath.mpf(x), mpmath.mpf(0)) for s, x in zip((F.u, F.v, F.k_u, F.k_v), point)}
            for expr, got in zip(exprs, seed):
                try:
                    out.append(excess(got, evaluate(sp.sympify(expr), env)))
                except Ambiguous:
                    pass
    return np.array(out)


def _closed_form_points(n=200, seed=102):
    return list(zip(*_chart_points(np.random.default_rng(seed), n)))


@pytest.mark.parametrize("field", scalar_reference.SEED_FIELDS)
def test_the_records_are_the_seeds_closed_forms(field):
    """The record of each of the seed's fields (its expression and sympy's derivative) agrees
    with seed §2 and §3's closed forms, written by hand in tests/scalar_reference.py, at seeded
    chart points: the float64 closed form lies within the forward error bound of the mpmath
    value (numerical, at points, not a proof)."""
    points = _closed_form_points()
    record = F.FIELDS[field]
    ex = closed_form_excess((record.expr, *record.gradient), field, points)
    assert len(ex) >= (1 - MAX_AMBIGUOUS) * 3 * len(points)
    assert ex.max() <= 0.0


def test_closed_form_check_rejects_swapped_frequencies():
    points = _closed_form_points()
    sine, ridges = F.FIELDS["sine"], F.FIELDS["ridges"]
    swapped = sine.gradient[0].xreplace({F.k_u: F.k_v, F.k_v: F.k_u})
    assert np.mean(closed_form_excess((sine.expr, swapped), "sine", points) > 0) > 0.25
    # ridges' h and h_u in place of sine's: wrong wherever the sign factor is -1.
    assert np.mean(closed_form_excess((ridges.expr, ridges.gradient[0]), "sine", points) > 0) > 0.2


EPS_SWEEP = np.logspace(-2, -4, 9)


def convergence_order(gradient_fn, field, component, v, ku=8.0, kv=4.0, n=400, seed=94):
    """Slope of log(RMS error) against log(eps), eps from 1e-2 to 1e-4.

    At eps = 1e-4 the truncation error (pi k)^3 eps^2 / 6 ~ 3e-6 dwarfs the
    roundoff ~ 1e-16 / eps = 1e-12, so the fit sees truncation alone.
    """
    u = np.random.default_rng(seed).random(n)
    exact = pointwise.exact_gradient(field, u, v, ku, kv)[component]
    errors = [np.sqrt(np.mean((gradient_fn(field, u, v, ku, kv, eps)[component] - exact) ** 2)) for eps in EPS_SWEEP]
    return np.polyfit(np.log(EPS_SWEEP), np.log(errors), 1)[0]


def _interior_v(n=400, seed=95):
    return np.random.default_rng(seed).uniform(0.05, 0.95, n)   # no clamp at eps <= 1e-2


@pytest.mark.parametrize("field, component", [(name, c) for name, record in F.FIELDS.items() if record.analytic
                                               for c in (0, 1) if record.gradient[c] != 0])
def test_central_difference_converges_at_second_order(field, component):
    assert abs(convergence_order(pointwise.central_gradient, field, component, _interior_v()) - 2.0) <= 0.2


def forward_gradient(field, u, v, ku, kv, eps):
    """A wrong variant: forward differences, first order."""
    h0 = pointwise.height(field, u, v, ku, kv)
    return ((pointwise.height(field, np.mod(u + eps, 1.0), v, ku, kv) - h0) / eps,
            (pointwise.height(field, u, np.minimum(v + eps, 1.0), ku, kv) - h0) / eps)


@pytest.mark.parametrize("component", (0, 1))
def test_order_check_rejects_forward_differences(component):
    order = convergence_order(forward_gradient, "sine", component, _interior_v())
    assert abs(order - 2.0) > 0.2 and abs(order - 1.0) <= 0.2


def test_one_sided_quotient_at_the_pole_converges_at_first_order():
    """At v = 1 the quotient is one-sided, so its error falls like eps.  k_v =
    3.3 so that h_vv(u, 1) != 0 (with integer k_v the sine is odd about v = 1
    and the one-sided quotient is second order by accident)."""
    order = convergence_order(pointwise.central_gradient, "sine", 1, np.ones(400), kv=3.3)
    assert abs(order - 1.0) <= 0.2


def reference_quotient(field, u, v, ku, kv, eps, component):
    """tests/scalar_reference.py's central quotient (its own heights and stencil,
    seed Cell 1) at each u (array) and v (array or scalar): the independent value."""
    v = np.broadcast_to(v, np.shape(u))
    return np.array([scalar_reference.grad_central(field, float(a), float(b), ku, kv, eps)[component]
                     for a, b in zip(u, v)])


def quotient_tolerance(field, ku, kv, eps):
    """Rounding allowance of a difference quotient of h: each of the two
    samples carries a few ulp of its argument times h's Lipschitz constant
    (tests/test_parity.py's `field_bounds`), plus an ulp of h (<= 1), over the step."""
    return 4 * (field_bounds(field, ku, kv)[0] + 1) * 2 * U / eps


@pytest.mark.parametrize("field", tuple(F.FIELDS))
def test_v_clamp_is_one_sided_at_the_poles(field):
    ku, kv, eps = 3.3, 7.1, float(np.random.default_rng(97).uniform(1e-3, 0.05))
    u = np.random.default_rng(98).random(50)
    at0 = pointwise.central_gradient(field, u, np.zeros_like(u), ku, kv, eps)[1]
    at1 = pointwise.central_gradient(field, u, np.ones_like(u), ku, kv, eps)[1]
    # The reference's stencil at the borders: (v+, v-, divisor), one-sided.
    assert scalar_reference.stencil_v(0.0, eps) == (eps, 0.0, eps)
    assert scalar_reference.stencil_v(1.0, eps) == (1.0, 1.0 - eps, 1.0 - (1.0 - eps))
    one_sided_0 = reference_quotient(field, u, 0.0, ku, kv, eps, 1)
    one_sided_1 = reference_quotient(field, u, 1.0, ku, kv, eps, 1)
    tol = quotient_tolerance(field, ku, kv, eps)
    assert np.all(np.abs(at0 - one_sided_0) <= tol) and np.all(np.abs(at1 - one_sided_1) <= tol)
    # The two-sided quotient over the clamped points (divided by 2 eps) is half that: rejected.
    nonzero = np.abs(one_sided_0) > 1e3 * tol
    assert nonzero.any() and np.all(np.abs(at0 - one_sided_0 / 2)[nonzero] > tol)


def test_v_clamp_just_inside_the_border():
    """0 < v < eps: v_- clamps to 0 and the quotient divides by v + eps."""
    eps, v0, ku, kv = 1e-2, 2.5e-3, 8.0, 4.0
    u = np.random.default_rng(99).random(50)
    got = pointwise.central_gradient("sine", u, v0, ku, kv, eps)[1]
    assert scalar_reference.stencil_v(v0, eps) == (v0 + eps, 0.0, v0 + eps)
    want = reference_quotient("sine", u, v0, ku, kv, eps, 1)
    tol = quotient_tolerance("sine", ku, kv, eps)
    assert np.all(np.abs(got - want) <= tol)
    assert np.all(np.abs(got - want * (v0 + eps) / (2 * eps)) > tol)


def test_u_wraps_at_the_seam(monkeypatch):
    """u near 0 and 1: the quotient reaches across the seam (u - eps + 1).  With
    k_u = 3.3 the field is not periodic in u, so a quotient that did not wrap
    (h(u - eps) at u - eps < 0) differs by O(1)."""
    eps, ku, kv = 1e-2, 3.3, 4.0
    rng = np.random.default_rng(101)
    v = rng.uniform(0.1, 0.9, 60)
    u = np.concatenate([rng.uniform(0, eps, 30), rng.uniform(1 - eps, 1, 30)])
    got = pointwise.central_gradient("sine", u, v, ku, kv, eps)[0]
    want = reference_quotient("sine", u, v, ku, kv, eps, 0)
    # The wrong variant: the reference's quotient with its u stencil not wrapped.
    monkeypatch.setattr(scalar_reference, "stencil_u", lambda uu, e: (uu + e, uu - e))
    unwrapped = reference_quotient("sine", u, v, ku, kv, eps, 0)
    tol = quotient_tolerance("sine", ku, kv, eps)
    assert np.all(np.abs(got - want) <= tol)
    assert np.all(np.abs(unwrapped - want) > 1e6 * tol)


def test_interior_v_difference_divides_by_two_eps(monkeypatch):
    """Erratum v-border-branch: away from the border the quotient is over 2 eps,
    even where rounding makes fl(v + eps) - fl(v - eps) differ from 2 eps (the
    seed's test `vp - vm < 2 eps` would switch to that distance there)."""
    u, v, eps = 0.31, 0.47, 1e-9
    assert (v + eps) - (v - eps) != 2 * eps                  # the seed's branch would fire
    _, hv = pointwise.central_gradient("sine", u, v, 8.0, 4.0, eps)
    # The reference's quotient over the renderer's own samples of h (`pointwise.height`),
    # so that only the stencil can differ: its divisor is 2 eps here.
    assert scalar_reference.stencil_v(v, eps)[2] == 2 * eps
    monkeypatch.setattr(scalar_reference, "height_value", lambda *a: float(pointwise.height(*a)))
    want = scalar_reference.grad_central("sine", u, v, 8.0, 4.0, eps)[1]
    tol = 4 * U * abs(want)                                  # the quotient's own roundings
    assert abs(hv - want) <= tol
    assert abs(hv - want * (2 * eps) / ((v + eps) - (v - eps))) > 1e3 * tol


@pytest.mark.parametrize("field, component", [(name, c) for name, record in F.FIELDS.items()
                                               for c in (0, 1) if record.gradient[c] == 0])
def test_a_component_that_is_identically_zero_is_exactly_zero(field, component):
    """A field without u (rings): its h_u is the literal 0 in both pipelines and in frames."""
    u, v, ku, kv = _chart_points(np.random.default_rng(96), 2000)
    assert np.all(pointwise.exact_gradient(field, u, v, ku, kv)[component] == 0.0)
    for eps in (1e-3, 0.37, 1e-16):
        assert np.all(pointwise.central_gradient(field, u, v, ku, kv, eps)[component] == 0.0)
    for gradient in GRADIENTS:
        frame = render(Scene(height_field=field), 48, 48, gradient=gradient)
        on_a = frame.chamber == 1
        assert np.all(frame.grad[on_a, component] == 0.0) and np.any(frame.grad[on_a, 1 - component] != 0.0)


def test_zero_check_rejects_sine():
    frame = render(Scene(height_field="sine"), 48, 48)
    assert np.count_nonzero(frame.grad[frame.chamber == 1, 0]) > 500


@pytest.mark.parametrize("field", tuple(F.FIELDS))
def test_central_gradient_is_finite_at_the_border_points(field):
    """Steps from the scene's smallest to just below 1, at the chart's borders."""
    grid = np.array([0.0, 5e-324, 1e-300, 2**-60, 0.5, 1 - 2**-53, 1.0, 0.999, 1e-3])
    u, v = (a.ravel() for a in np.meshgrid(grid, grid))
    for eps in (float(F.FOOTPRINT_FALLBACK), 1e-16, 1e-12, 0.25, 0.5, 1 - 2**-53):
        hu, hv = pointwise.central_gradient(field, u, v, 8.0, 4.0, eps)
        assert np.all(np.isfinite(hu)) and np.all(np.isfinite(hv)), eps


@pytest.mark.parametrize("field", tuple(F.FIELDS))
def test_a_field_has_a_crease_band_where_its_record_has_creases(field):
    assert np.any(render(Scene(height_field=field), 48, 48).kink) == bool(F.FIELDS[field].crease_factors)
