"""A reader's function f(x) of one real variable, as a sympy record, for the U-curves
(`renderer.ucurve.measure_function`) and the gradient methods (`lab.gradient_benchmark.univariate_errors`)
at any real point where it is defined: Squire and Trapp (1998)'s test function
e^x / sqrt(sin^3 x + cos^3 x), say.

What lives here: the record (`Univariate`, made by `univariate` from an expression or its text),
and what the generator prints for one (`FUNCTIONS`: f, its central and forward differences at the
float64 abscissae x +- step, with `PRELUDE`'s assignments); `renderer.codegen` prints them and
`renderer.fieldcode` compiles them, as it does a height field's (`renderer.formulas`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import sympy as sp

from .formulas import ELEMENTARY, check_expression, refusal

__all__ = ["x_var", "step", "Univariate", "univariate", "FUNCTIONS", "PRELUDE"]

#: The variable of a reader's function of one variable, and the step.
x_var, step = sp.Symbol("x", real=True), sp.Symbol("step", positive=True)
x_p, x_m = sp.symbols("x_p x_m", real=True)


@dataclass(frozen=True, eq=False)
class Univariate:
    """A reader's function f(x) of one real variable, for U-curves and the gradient methods
    at any real point where it is defined (Squire and Trapp 1998's test function, say).

    Parameters
    ----------
    name : str
        Its printed form.
    expr : sympy expression
        f in `x_var` alone, built from `renderer.formulas.ELEMENTARY` functions, real.

    Raises
    ------
    TypeError, ValueError
        An expression outside the above.
    """

    name: str
    expr: sp.Expr

    def __post_init__(self):
        check_expression(f"function {self.name!r}", self.expr, (x_var,))

    @cached_property
    def derivative(self):
        """f' (sympy's derivative)."""
        return sp.diff(self.expr, x_var)

    @cached_property
    def analytic(self):
        """As `renderer.formulas.HeightField.analytic`."""
        return not self.expr.has(sp.Abs)


#: What the generator prints for a `Univariate`: f, and its central and forward differences
#: at the float64 abscissae x +- step.
FUNCTIONS = {
    "value": ((x_var,), lambda f: (f.expr,)),
    "central": ((x_var, step), lambda f: ((f.expr.subs(x_var, x_p) - f.expr.subs(x_var, x_m)) / (2 * step),)),
    "forward": ((x_var, step), lambda f: ((f.expr.subs(x_var, x_p) - f.expr) / step,)),
}
PRELUDE = {"central": ((x_p, x_var + step), (x_m, x_var - step)), "forward": ((x_p, x_var + step),)}


def univariate(spec, name="function"):
    """The `Univariate` ``spec`` is: one, a sympy expression of one symbol (renamed `x_var`), or
    its text in ``x`` (parsed by `renderer.validate.expression`).

    Raises
    ------
    renderer.validate.InvalidType, renderer.validate.InvalidValue
        Naming ``name``.
    """
    from .validate import InvalidType, InvalidValue, expression
    if isinstance(spec, Univariate):
        return spec
    typed = spec
    if isinstance(spec, str):
        spec = expression(name, spec, (x_var,), ELEMENTARY)
    if not isinstance(spec, sp.Expr):
        raise InvalidType(f"{name} must be a sympy expression of one variable or its text in x, "
                          f"got {type(spec).__name__}")
    free = spec.free_symbols
    if len(free) != 1:
        raise InvalidValue(f"{name} must depend on exactly one variable, got {len(free)}: {spec}")
    expr = spec.xreplace({free.pop(): x_var})
    try:
        record = Univariate(str(expr), expr)
    except (TypeError, ValueError) as exc:
        raise refusal(name, typed, expr, exc) from None
    return _UNIVARIATES.setdefault(record.name, record)


_UNIVARIATES = {}
