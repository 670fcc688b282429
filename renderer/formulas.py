"""Every bump-mapping formula the render kernel evaluates, written once as sympy objects.

This module is the single source of sphere A's mathematics (height fields,
gradients, stencil, crease band, chart, frame, perturbed normals, footprint);
the ray-sphere hit, the shadow test and the shading are written by hand in
renderer/kernel.py and renderer/js/render.js, held together by tests (the
shading's formula is theorem ``shading``, proofs/shading.py, checked on rendered pixels).  Nothing
imports it at render time: `renderer.codegen` prints each entry of
`FUNCTIONS`, and of `FIELD_FUNCTIONS` for each height field, as scalar Python
functions that numba compiles (renderer/generated.py for the fields defined here,
`renderer.fieldcode` for the others), as branch-free array functions and as the
JavaScript of the §4 simulator; tests/test_codegen.py regenerates them and compares.
proofs/ proves its theorems about these same objects.

What lives here (seed §2, §3 and Cell 1, with the project's corrections):

* the height fields, one `HeightField` record each in `FIELDS` (sine, ridges
  and rings of seed §2, and any field registered later): the expression, and
  derived from it the exact gradient, the central difference, the creases and
  the seed's crease band about them; `field` also makes a record of a reader's
  own expression in u, v, k_u, k_v;
* the chart (u, v) of a unit normal N of sphere A, and sin(phi) (`hypot`);
* the tangent frame (e_theta, e_phi), a fixed basis only where sin(phi) is 0 or subnormal;
* the perturbed normal of both bump modes ("chart": the seed's formula;
  "surface": the normal of the displaced sphere P = (R + beta h) N);
* the central-difference stencil (u wraps, v clamps with a one-sided quotient);
* the pixel footprint in (u, v), the step of ``gradient="footprint"``
  (pbrt-v4's bump-mapping rule);
* the central difference's error model and its optimal step (`ERROR_MODEL`, `EPS_STAR`).

A reader's function of one variable, for U-curves at any real point, is `renderer.univariate`'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache

import sympy as sp

__all__ = [
    "u", "v", "k_u", "k_v", "FIELD_SYMBOLS", "ELEMENTARY", "KINK_BAND_HALF_WIDTH", "SEED_POINT", "HeightField",
    "FIELDS", "BUILTIN", "register", "field", "gradient_scale", "gradient_scale_text", "check_expression",
    "BUILDING_BLOCKS", "MAX_DEPTH",
    "N_x", "N_y", "N_z", "sin_phi", "hypot", "CHART", "POLE_SIN_PHI",
    "TANGENT_FRAME", "FALLBACK_FRAME", "beta", "R", "h", "h_u", "h_v", "BUMP", "PERTURBED_NORMAL",
    "eps_u", "eps_v", "u_p", "u_m", "v_p", "v_m", "STENCIL_POINTS", "CENTRAL_DENOMINATORS", "FOOTPRINT",
    "FOOTPRINT_FALLBACK", "FOOTPRINT_MAX", "FOOTPRINT_LIMIT", "FOOTPRINT_RULE", "FUNCTIONS", "FIELD_FUNCTIONS",
    "eps", "H3", "H", "HX", "u_round", "ERROR_MODEL", "EPS_STAR",
]

# ---------------------------------------------------------------- height fields
#: Chart coordinates and frequencies.  Real, so that d|f|/du = sign(f) f'.
u, v, k_u, k_v = sp.symbols("u v k_u k_v", real=True)
#: The symbols a height field may use.
FIELD_SYMBOLS = (u, v, k_u, k_v)
#: The functions a height field (or a function of one variable) may be built from: the ones
#: every printer of `renderer.codegen` (numba, array namespaces, JavaScript) has.  Powers and
#: roots are ``Pow``; ``sign`` arises only in derivatives of ``Abs``.
ELEMENTARY = (sp.sin, sp.cos, sp.tan, sp.asin, sp.acos, sp.atan, sp.sinh, sp.cosh, sp.tanh,
              sp.exp, sp.log, sp.Abs)
#: Half-width of the seed's crease band (seed Cell 1, ``height1``).
KINK_BAND_HALF_WIDTH = sp.Float(0.03)
#: The seed's chart point (u, v) of Cell 2's U-curve, where a field's optimal step is measured.
SEED_POINT = (0.31, 0.47)

# ------------------------------------------------------ central-difference stencil
eps_u, eps_v = sp.symbols("eps_u eps_v", positive=True)
u_p, u_m, v_p, v_m = sp.symbols("u_p u_m v_p v_m", real=True)
#: The stencil's sample points for u, v in [0, 1] and steps in (0, 1): u wraps
#: (one exact subtraction or addition: the chart is periodic in u), v clamps
#: to [0, 1] (seed Cell 1, ``grad_numeric``).
STENCIL_POINTS = (
    (u_p, sp.Piecewise((u + eps_u - 1, u + eps_u >= 1), (u + eps_u, True))),
    (u_m, sp.Piecewise((u - eps_u + 1, u - eps_u < 0), (u - eps_u, True))),
    (v_p, sp.Min(1, v + eps_v)),
    (v_m, sp.Max(0, v - eps_v)),
)
#: The central quotients' denominators (u, v): where v clamps the quotient is one-sided,
#: divided by the clamped distance.
CENTRAL_DENOMINATORS = (2 * eps_u, sp.Piecewise((v_p - v_m, sp.Or(v + eps_v > 1, v - eps_v < 0)), (2 * eps_v, True)))


#: What an expression may be built from: numbers, pi and E, symbols, + * ** and `ELEMENTARY`.
BUILDING_BLOCKS = (sp.Number, sp.NumberSymbol, sp.Symbol, sp.Add, sp.Mul, sp.Pow, *ELEMENTARY)
#: The deepest an expression's tree may be: sympy and its printers recurse along it.
MAX_DEPTH = 100
#: The largest float64.
_FLOAT_MAX = sp.Float(1.7976931348623157e308)


def _depth(expr):
    """The depth of ``expr``'s tree, found without recursion."""
    deepest, stack = 0, [(expr, 1)]
    while stack:
        e, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend((a, d + 1) for a in e.args)
    return deepest


def check_expression(name, expr, symbols):
    """``expr`` if it is a real sympy expression in ``symbols`` built from `BUILDING_BLOCKS`, with a real
    derivative in closed form in each of its variables (a `HeightField`'s, a `renderer.univariate.Univariate`'s).

    Raises
    ------
    TypeError
        ``expr`` is not a sympy expression.
    ValueError
        It is nested more than `MAX_DEPTH` deep, uses another symbol, calls another function or holds
        another of sympy's objects (Max, Piecewise, Integral, Sum, ...), holds a non-real or infinite
        number or one beyond float64's range, or its derivative holds re, im, arg or an unevaluated
        derivative; the message begins with ``name``.
    """
    if not isinstance(expr, sp.Expr):
        raise TypeError(f"{name} must be a sympy expression, got {type(expr).__name__}")
    if (depth := _depth(expr)) > MAX_DEPTH:
        raise ValueError(f"{name} must be nested at most {MAX_DEPTH} deep; its tree is {depth} deep")
    extra = expr.free_symbols - set(symbols)
    if extra:
        raise ValueError(f"{name} must use only {', '.join(map(str, symbols))}; it uses "
                         f"{', '.join(sorted(map(str, extra)))}")
    unknown = {type(f).__name__ for f in expr.atoms(sp.Function) if not isinstance(f, ELEMENTARY)}
    if unknown:
        raise ValueError(f"{name} must call only {', '.join(f.__name__ for f in ELEMENTARY)}; it calls "
                         f"{', '.join(sorted(unknown))}")
    # sympy's numbers oo, -oo and nan are not real; I and zoo are not numbers to it, nor an interval.
    held = [str(a) for a in (sp.I, sp.zoo) if expr.has(a)] + \
        sorted({str(a) for a in expr.atoms(sp.Number) if not a.is_real}) + \
        (["an interval, AccumBounds"] if expr.has(sp.AccumBounds) else [])
    if held:
        raise ValueError(f"{name} must be real and finite: it holds {', '.join(dict.fromkeys(held))}")
    # sympy's other objects are not functions to atoms(Function), and no printer of renderer.codegen has them.
    other, stack = set(), [expr]
    while stack:                        # the outermost objects of another kind (Integral, not its Tuple)
        e = stack.pop()
        if isinstance(e, BUILDING_BLOCKS):
            stack.extend(e.args)
        else:
            other.add(type(e).__name__)
    other = sorted(other)
    if other:
        raise ValueError(f"{name} must be built from numbers, its symbols, + - * / ** and "
                         f"{', '.join(f.__name__ for f in ELEMENTARY)}; it holds {', '.join(other)}")
    large = sorted((a for a in expr.atoms(sp.Number) if abs(a) > _FLOAT_MAX), key=abs)
    if large:
        raise ValueError(f"{name} must hold only numbers float64 can: it holds {sp.Float(large[-1], 3)}")
    for var in sorted(expr.free_symbols - {k_u, k_v}, key=str):      # the variables, not the frequencies
        # |g| of a g sympy cannot tell is real (g = u**u) differentiates into re, im and arg of g; a
        # negative base, c**u, into log(c) = log|c| + i pi.
        d = sp.diff(expr, var)
        held = {type(f).__name__ for f in d.atoms(sp.re, sp.im, sp.arg, sp.Derivative)} | \
            ({"the imaginary unit"} if d.has(sp.I) else set())
        if held:
            raise ValueError(f"{name} must have a real derivative in {var} in closed form; sympy's holds "
                             f"{', '.join(sorted(held))} (an abs of what sympy cannot tell is real, or a "
                             f"negative base to a power in {var}, say)")
    return expr


@dataclass(frozen=True, eq=False)
class HeightField:
    """One height field h(u, v; k_u, k_v) of sphere A's chart (seed §2): the one record a field is.

    Everything other layers need of a field is its expression or derived from it here:
    the exact gradient (sympy's derivative), the central difference at the kernel's stencil,
    its creases (the zero lines of the factors under an ``Abs``) and the seed's crease band
    about them, whether the complex step applies, where its optimal step is measured.
    `renderer.codegen` prints the kernel's, the array backends' and the simulator's code
    from these objects; `FIELDS` holds the registered fields by name.

    Parameters
    ----------
    name : str
        How scenes, the command line and the book name it (a registered field's name is a
        Python identifier; a reader's expression is named by its printed form).
    expr : sympy expression
        h in `u`, `v` and optionally `k_u`, `k_v`, built from `ELEMENTARY` functions,
        real and finite on the chart [0, 1]^2.
    optimum : (u, v, component) or None
        Where its U-curve and optimal step are measured; None for `SEED_POINT` and the
        first component whose derivative is not identically 0.

    Raises
    ------
    TypeError, ValueError
        A name that is not a non-empty string, or an expression outside the above.
    """

    name: str
    expr: sp.Expr
    optimum: tuple | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.strip():
            raise TypeError(f"a height field's name must be a non-empty string, got {self.name!r}")
        check_expression(f"height field {self.name!r}", self.expr, FIELD_SYMBOLS)

    @cached_property
    def gradient(self):
        """(h_u, h_v): sympy's derivatives.  Where h = |f|, sign(f) f', which on a crease
        is one of the one-sided derivatives (or 0 where the float64 factor is exactly 0)."""
        return tuple(sp.diff(self.expr, x) for x in (u, v))

    @cached_property
    def crease_factors(self):
        """The factors under each ``Abs`` that vary on the chart: h has a crease (its slope
        jumps) where one of them changes sign.  () for a field without creases."""
        out = []
        for a in sorted(self.expr.atoms(sp.Abs), key=sp.default_sort_key):
            out.extend(f for f in sp.Mul.make_args(a.args[0]) if f.free_symbols & {u, v} and f not in out)
        return tuple(out)

    @cached_property
    def kink_band(self):
        """The crease flag: within `KINK_BAND_HALF_WIDTH` of a zero of a crease factor
        (seed Cell 1's band); false for a field without creases."""
        return sp.Or(*(sp.Abs(f) < KINK_BAND_HALF_WIDTH for f in self.crease_factors))

    @cached_property
    def central(self):
        """(h_u, h_v) by central differences at the stencil points `STENCIL_POINTS`."""
        return tuple((self.expr.subs(x, plus) - self.expr.subs(x, minus)) / den
                     for x, plus, minus, den in ((u, u_p, u_m, CENTRAL_DENOMINATORS[0]),
                                                 (v, v_p, v_m, CENTRAL_DENOMINATORS[1])))

    @cached_property
    def analytic(self):
        """Whether h is built from functions holomorphic in their argument (no ``Abs``), so
        that its complex evaluation is the continuation the complex step needs."""
        return not self.expr.has(sp.Abs)

    @cached_property
    def optimum_at(self):
        """(u, v, component): `optimum`, or `SEED_POINT` and the first component whose
        derivative is not identically 0 ("u" if both are)."""
        if self.optimum is not None:
            return tuple(self.optimum)
        component = next((c for c, d in zip("uv", self.gradient) if d != 0), "u")
        return (*SEED_POINT, component)


#: The registered height fields by name, in the order menus and tables list them.  Every
#: list of fields anywhere is derived from it.
FIELDS = {}


def register(field):
    """Add ``field`` (a `HeightField` named by an identifier) to `FIELDS`, and return it.

    A new built-in field is one call here, after the built-in ones and before
    ``BUILTIN = tuple(FIELDS)`` (a field registered after that, or elsewhere, is printed and
    compiled when first used)::

        register(HeightField("bumps", _s1**2 * _s2**2, optimum=(0.15, 0.47, "u")))

    then ``python -m renderer.codegen``, which rewrites renderer/generated*.py and the kernel's
    digest.  Everything else takes the field from `FIELDS`: the kernel, the array backends, the
    simulator's JavaScript, `renderer.ucurve`, the gradient methods, the proofs (its gradient
    theorem and, if it has creases, its kinks theorem), the checker's pins, the book's maps,
    tables and theorem blocks, and the tests.  The scale the gradient checks hold errors to
    (`gradient_scale`) is the fastest-turning sine argument of any registered field, so a field
    of sin(2 pi k_u u) widens it for all.  The chart's edges u = 0 and u = 1 meet on the sphere
    (the seam): at every frequency the simulator offers (k_u even), h and h_u must agree there
    or the seam be a zero of a crease factor (tests/test_js_controls.py checks it).

    Four things stay the author's:

    * ``optimum=``, where §3 and §6 state the field's optimal step.  Without it the seed point
      is used; the checker holds a claim about the error there (measured within a factor 3 of
      the model at the fitted step), which one point's rounding can miss: ``pytest verify``
      says so, and `lab.accuracy.measure_optimum` measures a candidate point first (for the
      field above the ratio is 1.3 at the point shown, 0.39 at u = 0.2, and u = 0.25, where
      h''' = 0, is refused).
    * The theorems print as reviewed: a new field adds its gradient theorem and changes the one
      that lists the fields (bump-vs-displacement).  ``python tests/test_notation.py`` prints the
      text of each new or changed theorem, then the digests: read the text, then record the
      digests in its ``PRINTED``.
    * §2's prose (book/s2_scene.md: its list of the fields, its figure's alt text, its summary)
      describes them in words; tests/test_book_prose.py finds a field it leaves out.
    * The book's length limits (tests/test_book_pages.py: words on the reading path and in the
      asides, each page's height) count what a field adds: about 150 words of asides (its
      gradient theorem), some 230 px on each of §3 and §5, and the words you add to §2.  Only
      the audit of the built site checks them: ``make audit`` (which builds the book first)
      names each limit passed, and ``pytest -m audit tests/test_book_pages.py -k short_enough``
      checks them alone; make room, or raise a limit with the reason in its comment.

    Raises
    ------
    TypeError
        ``field`` is not a HeightField.
    ValueError
        Its name is not an identifier, or names another registered field.
    """
    if not isinstance(field, HeightField):
        raise TypeError(f"register takes a HeightField, got {type(field).__name__}")
    if not field.name.isidentifier():
        raise ValueError(f"a registered field's name must be an identifier, got {field.name!r}")
    if field.name in FIELDS and FIELDS[field.name] is not field:
        raise ValueError(f"a height field named {field.name!r} is registered already")
    FIELDS[field.name] = field
    return field


_s1, _s2 = sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_v * v)
register(HeightField("sine", _s1 * _s2))
register(HeightField("ridges", sp.Abs(_s1 * _s2)))
register(HeightField("rings", sp.sin(2 * sp.pi * k_v * v)))


#: The frequencies as positive symbols, so that |d a/du| and a Max of rates simplify.
_POSITIVE = {k_u: sp.Symbol("k_u", positive=True), k_v: sp.Symbol("k_v", positive=True)}


def _argument_rates(expr):
    """|d a/du| and |d a/dv| of each argument a of a sine or cosine in ``expr``: the nonzero ones, as
    sympy expressions in the positive frequencies `_POSITIVE`."""
    rates = {sp.Abs(sp.diff(f.args[0], x)).xreplace(_POSITIVE) for f in expr.atoms(sp.sin, sp.cos) for x in (u, v)}
    return rates - {0}


@lru_cache(maxsize=None)
def _scale(records):
    """(the largest rate of `_argument_rates` over ``records`` (1 if none turns), and it as a float64
    function of (k_u, k_v))."""
    rates = set().union(*(_argument_rates(r.expr) for r in records))
    largest = sp.Max(*rates) if rates else sp.Integer(1)
    return largest, sp.lambdify(tuple(_POSITIVE.values()), largest, "math")


def gradient_scale(ku, kv, field=None):
    """The gradient's natural scale: the largest rate at which the argument of a sine or cosine turns in
    any registered field (and in ``field``, a `HeightField`, if given), pi max(k_u, 2 k_v) for the
    built-in fields (rings' 2 pi k_v v; seed §2's fields), 1 where no argument turns.  It bounds |h_u|
    and |h_v| of a product of sines of unit amplitude.  The gradient checks' tolerances
    (proofs/pixels.py, proofs/gradients.py) and `lab.accuracy`'s ulps are in its units, so a field
    that turns faster widens them for every field.

    ``ku``, ``kv``: positive floats, the frequencies (periods over the chart; not validated, the
    callers' scenes are).  Returns a float, in radians per chart unit; it raises nothing of its own
    (a non-number fails in `math`)."""
    return float(_scale(_scale_records(field))[1](ku, kv))


def gradient_scale_text(field=None):
    """`gradient_scale` as evidence prints it: ``"pi max(k_u, 2 k_v)"`` for the built-in fields."""
    largest = _scale(_scale_records(field))[0]
    terms = largest.args if isinstance(largest, sp.Max) else (largest,)
    printed = [str(t / sp.pi).replace("*", " ") for t in terms]
    return "pi " + (f"max({', '.join(printed)})" if len(printed) > 1 else printed[0])


def _scale_records(field):
    return tuple(FIELDS.values()) + ((field,) if field is not None and field not in FIELDS.values() else ())


#: The fields defined here, which renderer/generated.py holds compiled; others (registered later,
#: or a reader's expression) are printed and compiled when first used (`renderer.fieldcode`).
BUILTIN = tuple(FIELDS)

#: A reader's fields by their printed expression, so that a name finds the same record again.
_EXPRESSIONS = {}


def field(spec, name="height_field"):
    """The `HeightField` ``spec`` names: a registered name, a `HeightField`, a reader's
    sympy expression (or its text, parsed by `renderer.validate.expression`) in u, v, k_u, k_v,
    or a real number (a constant field, flat: no β moves its normal).  An expression's symbols are
    taken by their names: ``sympy.symbols("u v")`` are `u` and `v`, whatever their assumptions.

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming ``name``: not one of those, or an expression refused by `HeightField`.
    """
    from .validate import InvalidType, InvalidValue, expression
    if isinstance(spec, HeightField):
        known = FIELDS.get(spec.name, _EXPRESSIONS.get(spec.name))
        if known is not None and known is not spec:
            raise InvalidValue(f"{name}: another height field is named {spec.name!r}")
        return spec if known is not None else _EXPRESSIONS.setdefault(spec.name, spec)
    if isinstance(spec, str) and spec in FIELDS:
        return FIELDS[spec]
    if isinstance(spec, str) and spec in _EXPRESSIONS:
        return _EXPRESSIONS[spec]
    if isinstance(spec, (int, float)) and not isinstance(spec, bool):     # a constant (TOML's height_field = 0)
        spec = sp.sympify(spec)
    if not isinstance(spec, (str, sp.Expr)):
        raise InvalidType(f"{name} must be one of {tuple(FIELDS)}, a HeightField, a sympy expression in "
                          f"u, v, k_u, k_v or a real number, got {type(spec).__name__}")
    expr = expression(name, spec, FIELD_SYMBOLS, ELEMENTARY, fields=tuple(FIELDS)) if isinstance(spec, str) else spec
    by_name = {str(s): s for s in FIELD_SYMBOLS}
    alike = {s: by_name[s.name] for s in expr.free_symbols if getattr(s, "name", None) in by_name and s != by_name[s.name]}
    if alike:                           # only then: xreplace evaluates what was built unevaluated
        expr = expr.xreplace(alike)
    try:
        record = HeightField(str(expr), expr)
    except (TypeError, ValueError) as exc:
        raise refusal(name, spec, expr, exc) from None
    return _EXPRESSIONS.setdefault(record.name, record)


def refusal(name, spec, expr, exc):
    """The `renderer.validate.InvalidValue` naming ``name`` for a reader's expression ``expr`` (typed as
    ``spec``) that its record refused with ``exc``: "height_field 'sqrt(-1)*u' (read as I*u) must be real
    and finite: it holds I", the text as typed and sympy's reading of it where the two differ."""
    from .validate import InvalidValue
    said, shown = str(exc), repr(str(expr))
    same = lambda a: a.replace(" ", "").replace("^", "**").lower()       # noqa: E731
    def short(text):                                            # 10**400 has 401 digits
        return text if len(text) <= 80 else text[:77] + "..."
    typed = repr(short(str(spec))) if not isinstance(spec, str) or same(spec) == same(str(expr)) else \
        f"{short(spec)!r} (read as {short(str(expr))})"
    return InvalidValue(f"{name} {typed}{said.split(shown, 1)[1]}" if shown in said else f"{name}: {said}")


# ------------------------------------------------------------------------ chart
#: Components of sphere A's unit normal N = P / R, and sin(phi) = |(N_x, N_y)|.
N_x, N_y, N_z = sp.symbols("N_x N_y N_z", real=True)
sin_phi = sp.Symbol("sin_phi", nonnegative=True)


class hypot(sp.Function):
    """hypot(x, y) = sqrt(x^2 + y^2), without the underflow of the squares: below about
    1.5e-154 x^2 + y^2 loses its digits (or is 0), hypot keeps them.  Printed as the libraries'
    hypot (``math.hypot``, ``xp.hypot`` of `renderer.backends`, ``Math.hypot``); sympy reads it
    as the square root (`rewrite` with ``sp.sqrt``, ``evalf``, its derivative)."""

    nargs = 2

    def fdiff(self, argindex=1):
        return self.args[argindex - 1] / self

    def _eval_rewrite_as_sqrt(self, x, y, **hints):
        return sp.sqrt(x**2 + y**2)

    def _eval_evalf(self, prec):
        return self.rewrite(sp.sqrt)._eval_evalf(prec)

    def _eval_is_nonnegative(self):
        if all(a.is_real for a in self.args):
            return True
        return None

    def _latex(self, printer):
        return r"\operatorname{hypot}\left(%s, %s\right)" % tuple(printer._print(a) for a in self.args)


#: (u, v, sin phi) of a unit normal (seed Cell 1, ``chartA1``): u = (theta + pi)
#: / 2 pi with theta = atan2(N_y, N_x), v = phi / pi.  phi = atan2(sin phi, N_z),
#: not the seed's acos(N_z), which loses half the digits near the poles; sin phi =
#: hypot(N_x, N_y), whose relative error is an ulp or so at every sin phi > 0.
CHART = ((sp.atan2(N_y, N_x) + sp.pi) / (2 * sp.pi),
         sp.atan2(hypot(N_x, N_y), N_z) / sp.pi,
         hypot(N_x, N_y))

# ---------------------------------------------------------------- tangent frame
#: At and below this sin(phi) the frame is the fixed basis: float64's smallest normal number,
#: 2^-1022.  Above it 1/sin phi is finite (at most 2^1022) and sin phi carries its full 53 bits,
#: so the chart frame below is evaluated as written; at or below it sin phi is 0 (the pole
#: itself, where the chart has no theta) or subnormal (1/sin phi overflows from 2^-1024 on).
#: The seed cut the frame off at sin phi = 1e-4 (its Cell 1, ``tangent_frame``), a disc of
#: radius 1e-4 R where its fixed basis turned the displaced sphere's normal by up to 175 degrees
#: (tests/test_pole.py).
POLE_SIN_PHI = sp.Float(2.0**-1022, 17)
#: The fixed basis used at the poles: e_theta = (1, 0, 0), e_phi = (0, 1, 0).
FALLBACK_FRAME = (1, 0, 0, 0, 1, 0)
_frame = (-N_y / sin_phi, N_x / sin_phi, sp.Float(0),
          N_z * N_x / sin_phi, N_z * N_y / sin_phi, -sin_phi)
#: (e_theta, e_phi) = (dN/dtheta / sin phi, dN/dphi), six components, with the
#: pole fallback (seed §3).
TANGENT_FRAME = tuple(sp.Piecewise((c, sin_phi > POLE_SIN_PHI), (sp.Float(f), True))
                      for c, f in zip(_frame, FALLBACK_FRAME))

# ------------------------------------------------------------- perturbed normal
beta, R, h, h_u, h_v = sp.symbols("beta R h h_u h_v", real=True)
e_theta = sp.symbols("et_x et_y et_z", real=True)
e_phi = sp.symbols("ep_x ep_y ep_z", real=True)
_w = -beta / (R + beta * h)
#: Coefficients (t_u, t_v) of M = N + t_u e_theta + t_v e_phi, per bump mode.
#: "chart": the seed's N' formula.  "surface": the normal of P = (R + beta h) N,
#: with h_theta = h_u / 2 pi and h_phi = h_v / pi (theorem bump-vs-displacement),
#: 1/sin(phi) as it is wherever the frame is the chart's; at the pole (the fixed frame,
#: sin phi <= POLE_SIN_PHI), where the chart has no theta and h_u / sin phi no value (its
#: limit depends on the direction of approach), the e_theta term is 0.
BUMP = {
    "chart": (beta * h_u, beta * h_v),
    "surface": (sp.Piecewise((_w * h_u / (2 * sp.pi * sin_phi), sin_phi > POLE_SIN_PHI), (sp.Float(0), True)),
                _w * h_v / sp.pi),
}
#: N' = M / |M| per bump mode, a function of N, the frame, the gradient and
#: (surface) h, R and sin(phi).
PERTURBED_NORMAL = {}
for _mode, (_bu, _bv) in BUMP.items():
    _M = [n + _bu * a + _bv * b for n, a, b in zip((N_x, N_y, N_z), e_theta, e_phi)]
    _norm = sp.sqrt(sum(m * m for m in _M))
    PERTURBED_NORMAL[_mode] = tuple(m / _norm for m in _M)

# ------------------------------------------------------------------- footprint
x, y, dx, dy, camera_z = sp.symbols("x y dx dy camera_z", real=True)
P = sp.symbols("P_x P_y P_z", real=True)
#: pbrt-v4's fallback step where the footprint is 0 (or undefined), and the
#: largest step the stencil accepts (u +- eps stays a quarter period apart).
FOOTPRINT_FALLBACK, FOOTPRINT_MAX = sp.Float(0.0005), sp.Float(0.25)
#: pbrt-v4 clamps |du/dx| to 1e8 and zeroes a non-finite one (at the pole
#: sin phi = 0, or a ray grazing the tangent plane); here a footprint that is
#: not below 1e8 (or is NaN) takes the fallback step.
FOOTPRINT_LIMIT = sp.Float(1e8)
#: pbrt-v4's rule for a step from a pixel's two chart differentials (du/dx, du/dy): half the sum of their sizes.
_a, _b = sp.symbols("a b", real=True)
FOOTPRINT_RULE = sp.Lambda((_a, _b), sp.Mul(sp.S.Half, sp.Abs(_a) + sp.Abs(_b), evaluate=False))


def _ray_differential(sx, sy):
    """dp: where the ray through the neighbouring pixel (x + sx, y + sy) meets
    the tangent plane at P, minus P (pbrt-v4, ``ComputeDifferentials``)."""
    d = (x + sx, y + sy, -camera_z)
    E = (0, 0, camera_z)
    t = sum(n * (p - e) for n, p, e in zip((N_x, N_y, N_z), P, E)) / \
        sum(n * c for n, c in zip((N_x, N_y, N_z), d))
    return [e + t * c - p for e, c, p in zip(E, d, P)]


def _footprint():
    # dP/du = 2 pi R sin(phi) e_theta and dP/dv = pi R e_phi are orthogonal, so
    # pbrt's least-squares solve for du/dx reduces to one projection each.
    steps = []
    for axis, scale in ((e_theta, 2 * sp.pi * R * sin_phi), (e_phi, sp.pi * R)):
        d = [sum(a * c for a, c in zip(axis, _ray_differential(*s))) / scale
             for s in ((dx, 0), (0, dy))]
        half = FOOTPRINT_RULE(*d)
        # Min left unevaluated: sympy would try to order its arguments (0.2 s at every import), and
        # the printed code is the same.
        steps.append(sp.Piecewise((sp.Min(half, FOOTPRINT_MAX, evaluate=False),
                                   sp.And(half > 0, half < FOOTPRINT_LIMIT)), (FOOTPRINT_FALLBACK, True)))
    return tuple(steps)


#: (eps_u, eps_v): half the sum of |du/dx| and |du/dy| (likewise v), the
#: pixel's footprint in the chart (pbrt-v4, ``BumpMap``: du = 0.5 (|dudx| +
#: |dudy|), 0.0005 where that is 0), the fallback also where it is not below
#: `FOOTPRINT_LIMIT`, and at most 0.25.  The neighbours are the next column
#: (x + dx) and, dy being the row spacing, the row above (y + dy); pbrt takes
#: the row below, the same footprint to first order.  Built when first read (`__getattr__`):
#: a fifth of this module's import time, and only the generator and the checks read it.
FOOTPRINT: tuple

#: What the generator prints once: name -> (arguments, outputs), each a scalar function.
_UV = (u, v, k_u, k_v)
_N = (N_x, N_y, N_z)
FUNCTIONS: dict            # built with FOOTPRINT, when first read (`__getattr__`)


def _functions():
    footprint = globals().get("FOOTPRINT") or __getattr__("FOOTPRINT")
    return {
        "chart": (_N, CHART),
        "tangent_frame": (_N + (sin_phi,), TANGENT_FRAME),
        "perturbed_normal_chart": (_N + e_theta + e_phi + (h_u, h_v, beta), PERTURBED_NORMAL["chart"]),
        "perturbed_normal_surface": (_N + e_theta + e_phi + (h_u, h_v, beta, h, R, sin_phi),
                                     PERTURBED_NORMAL["surface"]),
        "footprint": ((x, y, dx, dy, camera_z) + P + _N + e_theta + e_phi + (R, sin_phi), footprint),
    }


_LAZY = {"FOOTPRINT": _footprint, "FUNCTIONS": _functions}


def __getattr__(name):
    """`FOOTPRINT` and `FUNCTIONS`, built on first read and kept (PEP 562)."""
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value = _LAZY[name]()
    return value
#: What the generator prints per height field: name -> (arguments, outputs of a `HeightField`).
#: ``exact`` and ``central`` return (h, h_u, h_v, crease flag) together, so that one call per
#: pixel shares their sines (the kernel calls a field's functions through pointers).
FIELD_FUNCTIONS = {
    "height": (_UV, lambda f: (f.expr,)),
    "exact": (_UV, lambda f: (f.expr, *f.gradient, f.kink_band)),
    "central": (_UV + (eps_u, eps_v), lambda f: (f.expr, *f.central, f.kink_band)),
    "kink": (_UV, lambda f: (f.kink_band,)),
}
#: Assignments printed before a function's outputs (the stencil's points).
PRELUDE = {"central": STENCIL_POINTS}


# ------------------------------------------- the central difference's error model
#: The step, |h'''|, |h| and |x h'| at the point, and the unit roundoff u_round (named as the
#: optimal-step theorem prints them).
eps, H3, H, HX, u_round = sp.Symbol("varepsilon", positive=True), *sp.symbols("H_3 H H_x u", positive=True)
#: The error model of the central quotient at x, truncation plus roundoff, as written:
#: eps^2 |h'''| / 6 + u_round (|h| + |x h'|) / eps.  Roundoff has two sources: the rounded values
#: h(x +- eps) (each off by at most about u_round |h|, so u_round |h| / eps in the quotient) and the
#: rounded abscissae fl(x +- eps) (each off by at most u_round |x|, which moves h by |h'| u_round |x|,
#: so u_round |x h'| / eps); the trade-off as in Higham, *Accuracy and Stability of Numerical Algorithms*.
#: `renderer.ucurve` draws it and proofs/finite_difference.py proves where it is least.
ERROR_MODEL = sp.Add(sp.Mul(sp.Rational(1, 6), eps**2, H3, evaluate=False),
                     sp.Mul(u_round, sp.Add(H, HX, evaluate=False), 1 / eps, evaluate=False), evaluate=False)
#: Its minimiser over eps > 0 where |h'''| > 0, as written: (3 u_round (|h| + |x h'|) / |h'''|)^(1/3).
EPS_STAR = sp.Pow(sp.Mul(3, u_round, sp.Add(H, HX, evaluate=False), 1 / H3, evaluate=False), sp.Rational(1, 3),
                  evaluate=False)
