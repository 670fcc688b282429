"""Hypothesis strategies of what a reader types: an expression (a function of x, or a height field of
u, v, k_u, k_v) and the point where it is measured, ordinary or singular.

An ordinary case is an expression built at random from the functions and operators
`renderer.validate.expression` accepts, at a point drawn from the edges of float64 and of the chart
and at random.  A singular case puts the point on a singularity of a template: a pole, the branch
point of a log or a root, an essential singularity, or past acos's domain.
"""

from hypothesis import strategies as st

from renderer import formulas as F

UNARY = (*(f.__name__ for f in F.ELEMENTARY), "sqrt", "-")
BINARY = ("+", "-", "*", "/", "**")
#: Singular at x = c: a pole, two branch points, an essential singularity, outside acos's domain,
#: and tan's pole (exact in sympy, finite in mpmath and float64, whose pi is rounded).
SINGULAR = ("1/({x} - {c})", "log({x} - {c})", "sqrt({x} - {c})", "exp(1/({x} - {c}))", "acos({x} - {c} + 2)",
            "({x} - {c})**1.5", "tan(pi*({x} - {c}) + pi/2)")
#: Points at the edges of float64 (a subnormal, the overflow of exp) and a few ordinary ones.
POINTS = (0.0, -0.0, 1.0, -1.0, 0.5, 1.5, 2.0, 1e-320, 709.8, -778.8, 1e16, 1e300, -1e300)
#: Chart coordinates at its edges and seams, its seed point and a few ordinary ones.
CHART = (0.0, 1.0, 0.5, 0.25, 0.31, 0.47, 1e-300, 1 - 2.0**-53)


def expressions(variables, max_leaves=5):
    """Texts of random expressions in ``variables``."""
    leaves = st.sampled_from([*variables, "0", "1", "2", "3", "0.5", "pi"])

    def grow(children):
        return st.one_of(
            st.tuples(st.sampled_from(UNARY), children).map(lambda t: f"{t[0]}({t[1]})"),
            st.tuples(children, st.sampled_from(BINARY), children).map(lambda t: f"({t[0]}){t[1]}({t[2]})"))
    return st.recursive(leaves, grow, max_leaves=max_leaves)


def functions_at_points():
    """(text of f(x), x): random ones at edge or random points, or a template at its singularity."""
    ordinary = st.tuples(expressions(["x"]), st.one_of(st.sampled_from(POINTS), st.floats(-1e3, 1e3)))
    singular = st.tuples(st.sampled_from(SINGULAR), st.floats(-10.0, 10.0)).map(
        lambda t: (t[0].format(x="x", c=repr(t[1])), t[1]))
    return st.one_of(ordinary, singular)


def fields_at_points():
    """(text of h(u, v), u, v, component): random fields at chart points, or a template in u or v
    with the point on its singularity."""
    chart = st.one_of(st.sampled_from(CHART), st.floats(0.0, 1.0))
    ordinary = st.tuples(expressions(["u", "v", "k_u", "k_v"]), chart, chart, st.sampled_from("uv"))

    def at(t):
        template, var, c, other, component = t
        return template.format(x=var, c=repr(c)), *((c, other) if var == "u" else (other, c)), component
    singular = st.tuples(st.sampled_from(SINGULAR), st.sampled_from("uv"), chart, chart,
                         st.sampled_from("uv")).map(at)
    return st.one_of(ordinary, singular)


#: Singular where pi x is a multiple of pi (or of pi/2) exactly, which neither float64's pi nor a 50-digit
#: one is: f at such a point is finite in both (1/sin(pi x) at x = 1: 8e15 and 1e102), infinite exactly.
#: (template, its singular points as a strategy).
ROUNDED_PI = (("1/sin(pi*{x})", st.integers(-3, 3)), ("tan(pi*{x})", st.integers(-3, 2).map(lambda n: n + 0.5)),
              ("1/cos(pi*{x})", st.integers(-3, 2).map(lambda n: n + 0.5)), ("log(sin(pi*{x})**2)", st.integers(-3, 3)))


def singular_cases(var, lo, hi):
    """(text, the point on its singularity in [lo, hi]): a `SINGULAR` template at its ``c``, or a
    `ROUNDED_PI` one at one of its points, in the variable ``var``.  ``c`` is a multiple of 1/64, whose
    decimal text is the float exactly (sympy reads a float's repr, 3.73e-54, to more bits than 53: the
    pole of 1/(u - 3.73e-54) is not at the float 3.73e-54)."""
    at_c = st.tuples(st.sampled_from(SINGULAR), st.integers(int(lo * 64), int(hi * 64)).map(lambda n: n / 64)).map(
        lambda t: (t[0].format(x=var, c=repr(t[1])), t[1]))
    rounded = st.one_of(*(p.filter(lambda c: lo <= c <= hi).map(lambda c, t=t: (t.format(x=var), float(c)))
                          for t, p in ROUNDED_PI))
    return st.one_of(at_c, rounded)
