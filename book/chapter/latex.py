"""The theorems' mathematics in LaTeX, as the book prints it.

The proofs (proofs/) hold sympy objects, step sentences and the checking; this module prints
them: `tex` writes an object as a person writes it, `statement` fills a statement's ``⟦key⟧``
placeholders, and `chain` lays out one calc chain of a proof as a single ``aligned`` display,
one relation a line, each "=" marked with the number of the step that proves it.  Where a line
is too wide for the reader's column, MathJax 4 breaks it (book/_config.yml).
"""

from __future__ import annotations

import re

import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.printing.conventions import requires_partial
from sympy.printing.latex import LatexPrinter
from sympy.printing.precedence import PRECEDENCE

from proofs.core import PLACEHOLDER, Cross, Dot, placeholder_key

__all__ = ["tex", "definition", "statement", "chain", "NAMES_BY_NAME"]

#: LaTeX of symbols by name, wherever they appear: the book writes the colatitude varphi.
NAMES_BY_NAME = {"phi": r"\varphi", "sin_phi": r"\sin\varphi", "varepsilon": r"\varepsilon",
                 "eps_u": r"\varepsilon_u", "eps_v": r"\varepsilon_v"}


class _Printer(LatexPrinter):
    """sympy's LaTeX as a person writes it: ``\\sin\\varphi`` (no brackets around a plain
    argument), round parentheses around vectors and tuples, 0 for a float zero, a `written` form
    in the order it was written, ``a \\cdot b`` for a
    dot product, ``(a)^{1/3}`` for a cube root, ``h'''(x)`` and ``H_\\theta`` for
    derivatives of a function, ``\\frac{dE}{d\\varepsilon}`` for the derivative of a name."""

    def __init__(self, names, inline=False):
        super().__init__({"fold_func_brackets": True, "mat_delim": "(", "fold_frac_powers": True})
        self.names, self.inline = names, inline

    # --- the proofs' own notation: dot and cross products, Jacobians
    def _print_Dot(self, expr):
        """``{a \\cdot b}``: a group, which MathJax does not break across lines (a break after the dot
        reads as a product of what stands on either line)."""
        return "{" + r" \cdot ".join(rf"\left({self._print(x)}\right)" if isinstance(x, (Cross, sp.MatAdd, sp.Add))
                                     else self._print(x) for x in expr.args) + "}"

    def _print_Cross(self, expr):
        return r" \times ".join(rf"\left({self._print(x)}\right)" if isinstance(x, sp.MatAdd) else self._print(x)
                                for x in expr.args)

    def _print_tuple(self, expr):
        """(a, b) in plain brackets, each component a group, a line allowed to break after each comma
        (unless every component is a number or a symbol) and nowhere else: MathJax breaks an in-line formula only between its top-level parts, and
        ``\\left( \\right)`` would make the tuple one box."""
        comma = r",\ " if all(x.is_Atom for x in expr) else r",\ \allowbreak "      # (x, y, 0) stays whole
        return "(" + comma.join(f"{{{self._print(x)}}}" for x in expr) + ("," if len(expr) == 1 else "") + ")"

    def _print_Jacobian(self, expr):
        fs, xs = (", ".join(self._print(a) for a in t) for t in expr.args)
        return rf"\frac{{\partial({fs})}}{{\partial({xs})}}"

    def _print_Symbol(self, expr, style="plain"):
        if expr in self.names:
            return self.names[expr]
        return NAMES_BY_NAME.get(expr.name) or super()._print_Symbol(expr, style)

    def _needs_function_brackets(self, expr):
        """Only a plain argument goes without brackets: sin φ, but sin(πk_u u)."""
        return not expr.is_Symbol

    def _print_MatrixSymbol(self, expr):
        return self.names.get(expr) or super()._print_MatrixSymbol(expr)

    def _print_Float(self, expr):
        return self._print(sp.Integer(int(expr))) if float(expr).is_integer() else super()._print_Float(expr)

    def _print_Pow(self, expr):
        if expr.exp.is_Rational and expr.exp.q > 2 and expr.exp.p == 1:
            return rf"{self.parenthesize(expr.base, PRECEDENCE['Pow'])}^{{1/{expr.exp.q}}}"
        return super()._print_Pow(expr)

    def _print_atan2(self, expr):
        return rf"\mathrm{{atan2}}\left({self._print(expr.args[0])}, {self._print(expr.args[1])}\right)"

    def _print_ZeroMatrix(self, expr):
        return "0"

    def _print_UnevaluatedExpr(self, expr):
        """A written form (`proofs.core.written`): its sums and products in the order written."""
        order, self._settings["order"] = self._settings["order"], "none"
        try:
            return self._print(expr.args[0])
        finally:
            self._settings["order"] = order

    def _print_Mul(self, expr):
        """A coefficient times the derivative of a name: ``\\frac{1}{\\sin\\varphi} \\frac{\\partial N}{\\partial\\theta}``.
        In running text (``inline``) a fraction is written with "/", not stacked (set at 70 %, small on a phone): over
        one symbol or number ``a / b`` (``m / k_u``), over anything else with its denominator in brackets,
        ``a / (2 \\pi)`` (``a / 2 \\pi`` could be read as ``(a / 2) \\pi``), a sum over it in brackets too."""
        named = [a for a in expr.args if isinstance(a, sp.Derivative) and isinstance(a.expr, (sp.Symbol, sp.MatrixSymbol))]
        if len(named) == 1 and len(expr.args) > 1:
            rest = sp.Mul(*[a for a in expr.args if a is not named[0]])
            coefficient = "-" if rest == -1 else self.parenthesize(rest, PRECEDENCE["Mul"])
            if self.inline and sp.fraction(rest)[1] != 1:          # (1 / sin phi) dN/dtheta
                coefficient = rf"\left({coefficient}\right)"
            return f"{coefficient} {self._print(named[0])}"
        numer, denom = sp.fraction(expr)
        if self.inline and denom != 1 and not denom.is_Atom:
            sign = "- " if numer.could_extract_minus_sign() else ""
            numer = -numer if sign else numer
            if self._settings["order"] == "none" and not sign:        # a written form: its factors as written
                numer = sp.Mul(*[a for a in expr.args if not (a.is_Pow and a.exp.is_negative)], evaluate=False)
            top = self._print(numer) if isinstance(numer, Dot) else self.parenthesize(numer, PRECEDENCE["Mul"], strict=True)
            return f"{sign}{top} / {self._over(denom)}"
        fold = self._settings["fold_short_frac"]
        self._settings["fold_short_frac"] = self.inline and denom.is_Atom
        try:
            return super()._print_Mul(expr)
        finally:
            self._settings["fold_short_frac"] = fold

    def _print_Rational(self, expr):
        """In running text ``3 / 100``, not stacked."""
        if self.inline and expr.q != 1:
            return f"{'- ' if expr.p < 0 else ''}{abs(expr.p)} / {expr.q}"
        return super()._print_Rational(expr)

    def _over(self, denom):
        """A denominator after "/" in running text: bare if one symbol, number, dot product (a group already) or
        function of one symbol (sin phi), else in brackets."""
        whole = (denom.is_Atom or isinstance(denom, Dot) or isinstance(denom, sp.Function) and all(a.is_Atom for a in denom.args)
                 or denom.is_Pow and denom.exp.is_Integer)                     # (e - R cos phi)^2
        return self._print(denom) if whole else rf"\left({self._print(denom)}\right)"

    def _print_MatAdd(self, expr):
        """Positive terms first (g - M(M.g)/|M|^3, not -M(M.g)/|M|^3 + g), a vector before a scaled one
        (p_u + beta h n_u), then by their vectors' names."""
        def negative(t):
            return isinstance(t, sp.MatMul) and t.as_coeff_matrices()[0].could_extract_minus_sign()
        out = []
        terms = sorted(expr.args, key=lambda t: (negative(t), isinstance(t, sp.MatMul), self._print(
            sp.MatMul(*t.as_coeff_matrices()[1])) if isinstance(t, sp.MatMul) else self._print(t)))
        for i, t in enumerate(terms):
            shown = self.parenthesize(-t if negative(t) else t, PRECEDENCE["Add"])
            out.append(("- " if i == 0 else " - ") + shown if negative(t) else (" + " if i else "") + shown)
        return "".join(out)

    def _print_Contains(self, expr):
        """x in an interval with finite ends as the chain ``a < x < b`` (``\\le`` at a closed end)."""
        x, where = expr.args
        if not isinstance(where, sp.Interval) or not (where.start.is_finite and where.end.is_finite):
            return super()._print_Contains(expr)
        left, right = (r"\le" if closed else "<" for closed in (not where.left_open, not where.right_open))
        return f"{self._print(where.start)} {left} {self._print(x)} {right} {self._print(where.end)}"

    def _print_Or(self, expr):
        return r"\ \text{or}\ ".join(self._print(a) for a in expr.args)

    def _print_And(self, expr):
        return r"\ \text{and}\ ".join(self._print(a) for a in expr.args)

    def _print_Identity(self, expr):
        return "I"

    def _print_MatMul(self, expr):
        """A scalar coefficient, then the matrices; a vector over a scalar as a fraction:
        ``\\frac{M}{\\lVert M\\rVert}``, ``\\frac{(I - N'N'^T) g}{\\lVert M\\rVert}``."""
        coeff, matrices = expr.as_coeff_matrices()
        coeff = sp.Mul(*coeff) if isinstance(coeff, (list, tuple)) else coeff
        numer, denom = sp.fraction(coeff)
        mats = " ".join(self.parenthesize(m, PRECEDENCE["Mul"], strict=False) if not isinstance(m, sp.MatAdd)
                        else rf"\left({self._print(m)}\right)" for m in matrices)
        if denom != 1 and abs(numer) == 1 and len(matrices) == 1 and not self.inline:   # a fraction bar groups a sum
            mats = self._print(matrices[0])
        if numer == -1:
            top = f"- {mats}"
        elif numer == 1:
            top = mats
        else:
            shown = self._print(numer)
            top = (rf"\left({shown}\right)" if numer.is_Add or isinstance(numer, Dot) else shown) + f" {mats}"
        if denom != 1 and self.inline:                 # in running text, as `_print_Mul`: M / |M|, g / (pi R)
            return f"{top} / {self._over(denom)}"
        return top if denom == 1 else (rf"- \frac{{{top[2:]}}}{{{self._print(denom)}}}" if top.startswith("- ")
                                       else rf"\frac{{{top}}}{{{self._print(denom)}}}")

    def _print_Function(self, expr, exp=None):
        if expr in self.names:                                     # H(theta, phi) written H
            return self.names[expr] + (f"^{{{exp}}}" if exp else "")
        if expr.func in self.names or isinstance(expr, AppliedUndef):     # h(x), always with its brackets
            name = self.names.get(expr.func) or self._print(sp.Symbol(expr.func.__name__))
            args = ", ".join(self._print(a) for a in expr.args)
            return rf"{name}\left({args}\right)" + (f"^{{{exp}}}" if exp else "")
        return super()._print_Function(expr, exp)

    def _print_Subs(self, expr):
        """E'(x) at x = a as E'(a)."""
        f, (var,), (point,) = expr.args
        if isinstance(f, sp.Derivative) and isinstance(f.expr, AppliedUndef) and f.expr.args == (var,):
            return self._print(f).replace(rf"\left({self._print(var)}\right)", rf"\left({self._print(point)}\right)")
        return super()._print_Subs(expr)

    def _print_Derivative(self, expr):
        f, counts = expr.expr, expr.variable_count
        n = sum(c for _, c in counts)
        if isinstance(f, AppliedUndef) and all(isinstance(a, sp.Symbol) for a in f.args):
            name = self.names.get(f.func) or self._print(sp.Symbol(f.func.__name__))
            if len(f.args) == 1:                              # h'(x), h'''(x), h^{(5)}(x)
                return name + ("'" * n if n <= 3 else f"^{{({n})}}") + rf"\left({self._print(f.args[0])}\right)"
            if all(c == 1 for _, c in counts):               # H_\theta, H_{\theta\varphi}
                return f"{name}_{{{' '.join(self._print(v) for v, _ in counts)}}}"
        named = isinstance(f, (sp.Symbol, sp.MatrixSymbol))       # dE/d(eps), dN/d(theta): a named quantity
        d = r"\partial" if named or requires_partial(f) else "d"
        below = " ".join(f"{d} {self._print(v)}" + (f"^{{{c}}}" if c > 1 else "") for v, c in counts)
        top = d + ("" if n == 1 else f"^{{{n}}}")
        if named:                                                  # in running text: dN/dbeta, not stacked
            return rf"{top} {self._print(f)} / {below}" if self.inline else rf"\frac{{{top} {self._print(f)}}}{{{below}}}"
        if self.inline:                                            # d / du (expression)
            return rf"{top} / {below} \left({self._print(f)}\right)"
        return rf"\frac{{{top}}}{{{below}}} \left({self._print(f)}\right)"


def tex(expr, names=None, inline=False) -> str:
    """LaTeX of a sympy object as the book prints it (see `_Printer`); a str is LaTeX already.

    Parameters
    ----------
    expr : sympy object or str
    names : dict, optional
        {symbol, MatrixSymbol or function: LaTeX}, for the symbols whose name is not their
        notation (``H_3`` printed ``\\lvert h'''\\rvert``): a theorem's ``names``.
    inline : bool
        In running text: a fraction over one symbol or number written ``a / b`` (a stacked one is set at 70 %,
        small on a phone).

    Returns
    -------
    str
    """
    if isinstance(expr, str):
        return expr
    return _Printer(names or {}, inline).doprint(sp.sympify(expr))


def definition(t, symbol, inline=False) -> str:
    """``name = definition`` of a named symbol of theorem ``t``'s ``where`` (``E(x) = ...`` for a
    function), in LaTeX (``inline`` as `tex`'s).  Raises KeyError for a symbol ``t.where`` does not define."""
    d = t.where[symbol]
    if isinstance(d, sp.Lambda):
        return f"{tex(symbol(*d.variables), t.names, inline)} = {tex(d.expr, t.names, inline)}"
    return f"{tex(symbol, t.names, inline)} = {tex(d, t.names, inline)}"


class _Relation:
    """One relation ``lhs = rhs``, as `chain` reads a step."""

    def __init__(self, lhs, rhs):
        self.lhs, self.rhs = lhs, rhs


def statement(t) -> str:
    """Theorem ``t``'s statement with each ``⟦key⟧`` printed: a claim as ``lhs = rhs`` (laid out by
    `chain` when set apart, ``$$⟦key⟧$$``), a named symbol of ``where`` as ``name = definition``, an
    object of ``shown`` as itself; in running text as `tex` prints ``inline``, set apart at full size.

    Raises
    ------
    KeyError
        A ``⟦key⟧`` that is none of these (the check refutes such a theorem first).
    """
    named = {placeholder_key(s): s for s in t.where}

    def display(m):
        """A placeholder set apart, ``$$⟦key⟧$$``: a claim laid out as `chain` lays out a proof's display,
        anything else as `fill` prints it set apart; each fraction at full size (``\\dfrac``: one within another is
        otherwise set at 70 %)."""
        shown = chain(t, [_Relation(*t.claims[m.group(1)])]) if m.group(1) in t.claims else fill(m, inline=False)
        return "\n\n$$\n{}\n$$\n\n".format(shown.replace(r"\frac{", r"\dfrac{"))

    def fill(m, inline=True):
        key = m.group(1)
        if key in t.claims:
            return " = ".join(tex(x, t.names, inline=inline) for x in t.claims[key])
        if key in named:
            return definition(t, named[key], inline=inline)
        if key in t.shown:
            return tex(t.shown[key], t.names, inline=inline)
        raise KeyError(f"theorem {t.id!r}: the statement names ⟦{key}⟧, neither a claim {sorted(t.claims)}, "
                       f"a named symbol {sorted(named)} nor a shown object {sorted(t.shown)}")
    return PLACEHOLDER.sub(fill, re.sub(rf"\$\$\s*{PLACEHOLDER.pattern}\s*\$\$", display, t.statement))


def _relation(k):
    """The "=" of a chain's line, marked with the number of the step that proves it."""
    return "=" if k is None else rf"\overset{{({k})}}{{=}}"


def chain(t, steps, numbers=None) -> str:
    """One calc chain of theorem ``t`` as one LaTeX ``aligned`` display: ``lhs = r_1 = r_2 ...`` one
    relation a line, aligned at "=", each "=" marked with its step's number (``numbers``; unmarked
    if None or the chain is one step); a chain of tuples one block of lines per component.  A step
    whose left side is not the right side of the one before (a link decided equal to it) adds that
    left side as a line, joined by an unmarked "=".

    Parameters
    ----------
    t : proofs.core.Theorem
    steps : sequence of proofs.core.Step
        A run of one chain: each after the first a link.
    numbers : sequence of int, optional
        The steps' numbers in the proof, one per step.

    Returns
    -------
    str
        ``\\begin{aligned} ... \\end{aligned}``, or a bare ``lhs = rhs`` for a single relation.
    """
    printer = _Printer(t.names)
    numbers = list(numbers) if numbers is not None and len(steps) > 1 else [None] * len(steps)
    # The relations of the chain: its sides, left sides shown only where they change, and the marks.
    sides = [steps[0].lhs]
    marks = []
    for k, step in zip(numbers, steps):
        if step.lhs != sides[-1]:
            sides.append(step.lhs)
            marks.append(None)
        sides.append(step.rhs)
        marks.append(k)
    split = all(isinstance(s, sp.Tuple) and len(s) == len(sides[0]) for s in sides) or all(
        isinstance(s, sp.MatrixBase) and s.shape == sides[0].shape and s.shape[1] == 1 for s in sides)
    blocks = [[s[i] for s in sides] for i in range(len(sides[0]))] if split else [sides]
    if len(blocks) == 1 and len(sides) == 2:
        return f"{printer._print(sides[0])} {_relation(marks[0])} {printer._print(sides[1])}"
    rows = []
    # A column vector's components whose left sides are expressions, not names: each left side on a line
    # of its own, its relations indented below it (beside its right side, a row was wider than a phone).
    apart = split and isinstance(sides[0], sp.MatrixBase) and not all(
        isinstance(b[0], (sp.Symbol, AppliedUndef, sp.Derivative)) for b in blocks)
    indent = r"&\qquad "
    for block in blocks:
        # The left side in a box of its own width (an mpadded, which MathJax does not break): in a row
        # too wide for the column MathJax narrows every column, and broke D_u(u, v) before its "(".
        head = rf"\raise 0em{{{printer._print(block[0])}}} &"
        if apart:
            rows.append("&" + head[:-2])
        for mark, rhs in zip(marks, block[1:]):
            rows.append(f"{indent if apart else head}{_relation(mark)} {printer._print(rhs)}")
            head = "&"
    return r"\begin{aligned}" + r"\\ ".join(rows) + r"\end{aligned}"
