"""Interval arithmetic on the chart [0, 1]^2: where a field breaks a rule between the points of any grid.

`search_chart` bounds sympy expressions of (u, v) on boxes of the chart with mpmath's outward-rounded
intervals (mpmath.iv), halving a box it cannot bound, depth first.  `renderer.scene` uses it to refuse
a reader's field with a pole, a jump or a dip through the displaced radius between its grid's points,
and `lab.displaced` to hold |h| to the bound its bracketing assumes.
"""

from __future__ import annotations

from . import formulas

__all__ = ["search_chart", "CHART_CHECK_SIDE", "CHART_CHECK_BOXES"]

#: Between the points of a grid of the chart (`renderer.scene`'s), interval arithmetic (`search_chart`) bounds
#: a field on boxes, halving a box it cannot bound down to sides of `CHART_CHECK_SIDE`, and at most
#: `CHART_CHECK_BOXES` boxes: a pole is found in a few dozen (tan(pi*u): 48), and a bounded field whose bound
#: the intervals overestimate (u**2 - 2*u*v + v**2 + 1e-4, written out, is bounded only on boxes of side 1e-5
#: along u = v) stops the search there, and is accepted on the grid's evidence, after about 0.2 s.
CHART_CHECK_SIDE, CHART_CHECK_BOXES = 2.0 ** -24, 2_000


def _interval_functions():
    """The names lambdify prints for `formulas.ELEMENTARY`, sqrt and sign (an Abs's derivative) as functions
    of mpmath's intervals, each returning an interval that holds every value on its argument's; mpmath.iv
    lacks the inverse and hyperbolic ones, written here through those it has."""
    import mpmath
    from mpmath import iv

    def sign(x):
        if not isinstance(x, type(iv.mpf(0))):
            raise ValueError("sign of a complex interval")
        return iv.mpf(1) if x.a > 0 else iv.mpf(-1) if x.b < 0 else iv.mpf([-1, 1])
    return {"sin": iv.sin, "cos": iv.cos, "tan": iv.tan, "exp": iv.exp, "log": iv.log, "sqrt": iv.sqrt,
            "atan": lambda x: iv.atan2(x, 1), "asin": lambda x: iv.atan2(x, iv.sqrt(1 - x**2)),
            "acos": lambda x: iv.atan2(iv.sqrt(1 - x**2), x), "sinh": lambda x: (iv.exp(x) - iv.exp(-x)) / 2,
            "cosh": lambda x: (iv.exp(x) + iv.exp(-x)) / 2, "tanh": lambda x: 1 - 2 / (iv.exp(2 * x) + 1),
            "sign": sign, "mpf": lambda x: iv.mpf(mpmath.mpf(x)), "pi": iv.pi, "e": iv.e}


def search_chart(exprs, k_u, k_v, holds, *, broken=None):
    """The first point (u, v) of the chart [0, 1]^2 found to break a rule of ``exprs``, between the points
    of any grid: interval arithmetic (mpmath.iv) on boxes, depth first.

    Each box is given to ``holds`` as the intervals enclosing ``exprs`` on it, or None where mpmath found
    none real (a root or a log of a negative).  A box that holds is done.  One that does not is tested at
    its centre by ``broken`` if given (True: the rule is broken there, and that point is returned), then
    halved along u and v where the expressions depend on each, down to sides of `CHART_CHECK_SIDE`.  A box
    that small still not holding is returned without ``broken`` (nothing bounds there: a pole, a jump, a
    point where an expression is not real) and dropped with it (the intervals overestimate, and no point
    has broken the rule).

    Parameters
    ----------
    exprs : sequence of sympy expressions
        In `renderer.formulas.FIELD_SYMBOLS`, built from `formulas.ELEMENTARY`, sqrt and sign.
    k_u, k_v : float
        The frequencies.
    holds : callable(list of mpmath.iv.mpf or None) -> bool
    broken : callable(u, v) -> bool, optional

    Returns
    -------
    (u, v) floats, or None when no box is left or after `CHART_CHECK_BOXES` boxes (the rule
    holds, or the intervals could not show where it does not).

    Raises
    ------
    Nothing of its own: mpmath's arithmetic errors on a box (a root or a log of a negative) count as
    no bound there.  An expression calling a function outside those above fails in lambdify or mpmath.

    Source: interval arithmetic's enclosure of a function's range by its natural extension, refined
    by bisection (R. E. Moore, *Interval Analysis*, 1966), on mpmath's outward-rounded intervals.
    """
    import itertools

    import sympy as sp
    from mpmath import iv

    fn = sp.lambdify(formulas.FIELD_SYMBOLS, list(exprs), modules=[_interval_functions(), "mpmath"])
    used = set().union(*(sp.sympify(e).free_symbols for e in exprs))
    split = [x in used for x in (formulas.u, formulas.v)]
    real = type(iv.mpf(0))

    def enclosures(box):
        try:
            values = fn(*(iv.mpf(list(side)) for side in box), iv.mpf(k_u), iv.mpf(k_v))
        except (ArithmeticError, ValueError):     # mpmath's ComplexResult: a root or log of a negative
            return None
        values = [iv.mpf(x) if isinstance(x, (int, float)) else x for x in values]
        return values if all(isinstance(x, real) for x in values) else None

    boxes = [((0.0, 1.0), (0.0, 1.0))] if any(split) else []      # constants: the grid has checked them
    for _ in range(CHART_CHECK_BOXES):
        if not boxes:
            return None
        box = boxes.pop()
        if holds(enclosures(box)):
            continue
        centre = tuple((lo + hi) / 2 for lo, hi in box)
        if broken is not None and broken(*centre):
            return centre
        if max(hi - lo for (lo, hi), s in zip(box, split) if s) <= CHART_CHECK_SIDE:
            if broken is None:
                return centre
            continue
        boxes.extend(itertools.product(*(((lo, (lo + hi) / 2), ((lo + hi) / 2, hi)) if s else ((lo, hi),)
                                         for (lo, hi), s in zip(box, split))))
    return None
