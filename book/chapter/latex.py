"""The theorems' mathematics in LaTeX, as the book prints it, laid out for the narrow column.

The proofs (proofs/) hold sympy objects, step sentences and the checking; this module prints
them: `tex` writes an object as a person writes it, `statement` fills a statement's ``⟦key⟧``
placeholders, and `chain` lays out one calc chain of a proof as a single ``aligned`` display,
one relation a line, each "=" marked with the number of the step that proves it.  MathJax 3
does not break lines, so the layout breaks them: a tuple claim one component a line, a line
wider than the proof's column at a top-level ``+``, ``-``, ``\\times`` or ``\\cdot`` (inside one
pair of brackets if that is where the sum is).  Widths are estimated from the LaTeX (`width`),
in pixels of MathJax's output at the book's font size, calibrated on the built book.
"""

from __future__ import annotations

import contextlib
import re

import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.printing.conventions import requires_partial
from sympy.printing.latex import LatexPrinter
from sympy.printing.precedence import PRECEDENCE

from proofs.core import PLACEHOLDER, Cross, Dot, placeholder_key

__all__ = ["tex", "definition", "statement", "chain", "width", "COLUMN_PX", "PROOF_COLUMN_PX", "NAMES_BY_NAME"]

#: LaTeX of symbols by name, wherever they appear: the book writes the colatitude varphi.
NAMES_BY_NAME = {"phi": r"\varphi", "sin_phi": r"\sin\varphi", "varepsilon": r"\varepsilon",
                 "eps_u": r"\varepsilon_u", "eps_v": r"\varepsilon_v"}

#: A proof's column in a 390-px viewport, in CSS px (the 358-px column less the dropdown's and the
#: proof box's padding; measured in the built book).
PROOF_COLUMN_PX = 278
#: The width a line of a proof's display may take, in CSS px: `PROOF_COLUMN_PX` less a margin,
#: `width` underestimating by up to a fifth.
COLUMN_PX = 240


class _Printer(LatexPrinter):
    """sympy's LaTeX as a person writes it: ``\\sin\\varphi`` (no brackets around a plain
    argument), round parentheses around vectors, 0 for a float zero, a `written` form
    in the order it was written, ``a \\cdot b`` for a
    dot product, ``(a)^{1/3}`` for a cube root, ``h'''(x)`` and ``H_\\theta`` for
    derivatives of a function, ``\\frac{dE}{d\\varepsilon}`` for the derivative of a name."""

    def __init__(self, names):
        super().__init__({"fold_func_brackets": True, "mat_delim": "(", "fold_frac_powers": True})
        self.names = names

    # --- the proofs' own notation: dot and cross products, Jacobians
    def _print_Dot(self, expr):
        return r" \cdot ".join(rf"\left({self._print(x)}\right)" if isinstance(x, (Cross, sp.MatAdd, sp.Add))
                               else self._print(x) for x in expr.args)

    def _print_Cross(self, expr):
        return r" \times ".join(rf"\left({self._print(x)}\right)" if isinstance(x, sp.MatAdd) else self._print(x)
                                for x in expr.args)

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
        with self._written():
            return self._print(expr.args[0])

    def _print_Mul(self, expr):
        """A coefficient times the derivative of a name: ``\\frac{1}{\\sin\\varphi} \\frac{\\partial N}{\\partial\\theta}``."""
        named = [a for a in expr.args if isinstance(a, sp.Derivative) and isinstance(a.expr, (sp.Symbol, sp.MatrixSymbol))]
        if len(named) == 1 and len(expr.args) > 1:
            rest = sp.Mul(*[a for a in expr.args if a is not named[0]])
            coefficient = "-" if rest == -1 else self.parenthesize(rest, PRECEDENCE["Mul"])
            return f"{coefficient} {self._print(named[0])}"
        return super()._print_Mul(expr)

    def _print_Add(self, expr, order=None):
        return "".join(self.terms(expr, order))

    def terms(self, expr, order=None):
        """The printed terms of a sum, the first bare and the others with their sign (" + t", " - t"):
        where a long sum may be broken.  (sympy's `LatexPrinter._print_Add`, in pieces.)"""
        if isinstance(expr, sp.MatAdd):
            return self._matadd_terms(expr)
        out = []
        for i, term in enumerate(self._as_ordered_terms(expr, order=order)):
            sign = "" if i == 0 else " + "
            if i and term.could_extract_minus_sign():
                sign, term = " - ", -term
            shown = self._print(term)
            out.append(sign + (rf"\left({shown}\right)" if self._needs_add_brackets(term) else shown))
        return out

    def _matadd_terms(self, expr):
        """Positive terms first (g - M(M.g)/|M|^3, not -M(M.g)/|M|^3 + g), then by their vectors' names."""
        def negative(t):
            return isinstance(t, sp.MatMul) and t.as_coeff_matrices()[0].could_extract_minus_sign()
        out = []
        for i, t in enumerate(sorted(expr.args, key=lambda t: (negative(t), self._print(sp.MatMul(
                *t.as_coeff_matrices()[1])) if isinstance(t, sp.MatMul) else self._print(t)))):
            shown = self.parenthesize(-t if negative(t) else t, PRECEDENCE["Add"])
            out.append(("- " if i == 0 else " - ") + shown if negative(t) else (" + " if i else "") + shown)
        return out

    def _print_MatAdd(self, expr):
        return "".join(self._matadd_terms(expr))

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
        if numer == -1:
            top = f"- {mats}"
        elif numer == 1:
            top = mats
        else:
            shown = self._print(numer)
            top = (rf"\left({shown}\right)" if numer.is_Add or isinstance(numer, Dot) else shown) + f" {mats}"
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
        if named:
            return rf"\frac{{{top} {self._print(f)}}}{{{below}}}"
        return rf"\frac{{{top}}}{{{below}}} \left({self._print(f)}\right)"         # d/du (expression)

    # --- where a line too wide may break
    def pieces(self, expr):
        """``expr`` printed in pieces a line may break before (each but the first): the terms of a
        sum, the factors of a cross or dot product, or the terms of the sum a product ends in
        (its brackets then ``\\bigl( \\bigr)``, which may span lines); one piece if none."""
        if isinstance(expr, sp.UnevaluatedExpr):
            with self._written():
                return self.pieces(expr.args[0])
        whole = self._print(expr)
        if isinstance(expr, (sp.Add, sp.MatAdd)):
            return self.terms(expr)
        if isinstance(expr, (Cross, Dot)):
            op = r" \times " if isinstance(expr, Cross) else r" \cdot "
            parts = whole.split(op)
            if len(parts) == len(expr.args):
                return [parts[0]] + [op + p for p in parts[1:]]
        if isinstance(expr, (sp.Mul, sp.MatMul)):
            for arg in expr.args:
                written = isinstance(arg, sp.UnevaluatedExpr)
                if isinstance(arg.args[0] if written else arg, (sp.Add, sp.MatAdd)):
                    with self._written(written):
                        inner = self.terms(arg.args[0] if written else arg)
                    bracketed = r"\left(" + "".join(inner) + r"\right)"
                    if whole.endswith(bracketed) and len(inner) > 1:
                        size = "Big" if r"\frac" in bracketed else "big"
                        head = whole[:-len(bracketed)] + rf"\{size}l(" + inner[0]
                        return [head, *inner[1:-1], inner[-1] + rf"\{size}r)"]
        return [whole]

    @contextlib.contextmanager
    def _written(self, written=True):
        """Print sums and products in the order written (a `proofs.core.written` form) meanwhile."""
        order = self._settings["order"]
        self._settings["order"] = "none" if written else order
        try:
            yield
        finally:
            self._settings["order"] = order


def tex(expr, names=None) -> str:
    """LaTeX of a sympy object as the book prints it (see `_Printer`); a str is LaTeX already.

    Parameters
    ----------
    expr : sympy object or str
    names : dict, optional
        {symbol, MatrixSymbol or function: LaTeX}, for the symbols whose name is not their
        notation (``H_3`` printed ``\\lvert h'''\\rvert``): a theorem's ``names``.

    Returns
    -------
    str
    """
    if isinstance(expr, str):
        return expr
    return _Printer(names or {}).doprint(sp.sympify(expr))


def definition(t, symbol) -> str:
    """``name = definition`` of a named symbol of theorem ``t``'s ``where`` (``E(x) = ...`` for a
    function), in LaTeX.  Raises KeyError for a symbol ``t.where`` does not define."""
    d = t.where[symbol]
    if isinstance(d, sp.Lambda):
        return f"{tex(symbol(*d.variables), t.names)} = {tex(d.expr, t.names)}"
    return f"{tex(symbol, t.names)} = {tex(d, t.names)}"


class _Relation:
    """One relation ``lhs = rhs``, as `chain` reads a step."""

    def __init__(self, lhs, rhs):
        self.lhs, self.rhs = lhs, rhs


def statement(t) -> str:
    """Theorem ``t``'s statement with each ``⟦key⟧`` printed: a claim as ``lhs = rhs`` (one set
    apart, ``$$⟦key⟧$$``, as a display laid out for a phone's column by `chain`), a named
    symbol of ``where`` as ``name = definition``, an object of ``shown`` as itself.

    Raises
    ------
    KeyError
        A ``⟦key⟧`` that is none of these (the check refutes such a theorem first).
    """
    named = {placeholder_key(s): s for s in t.where}

    def display(m):
        """A claim set apart, ``$$⟦key⟧$$``: laid out as `chain` lays out a proof's display, each
        fraction at full size (``\\dfrac``: one within another is otherwise set at 70 %)."""
        if m.group(1) not in t.claims:
            return m.group(0)
        lhs, rhs = t.claims[m.group(1)]
        shown = chain(t, [_Relation(lhs, rhs)]).replace(r"\frac{", r"\dfrac{")
        return f"\n\n$$\n{shown}\n$$\n\n"

    def fill(m):
        key = m.group(1)
        if key in t.claims:
            return " = ".join(tex(x, t.names) for x in t.claims[key])
        if key in named:
            return definition(t, named[key])
        if key in t.shown:
            return tex(t.shown[key], t.names)
        raise KeyError(f"theorem {t.id!r}: the statement names ⟦{key}⟧, neither a claim {sorted(t.claims)}, "
                       f"a named symbol {sorted(named)} nor a shown object {sorted(t.shown)}")
    return PLACEHOLDER.sub(fill, re.sub(rf"\$\$\s*{PLACEHOLDER.pattern}\s*\$\$", display, t.statement))


# ------------------------------------------------------------------------------- widths
#: Estimated width, in em, of a command's glyph (one not listed is one letter wide).
_GLYPH = {r"\cdot": 0.72, r"\times": 1.22, r"\to": 1.55, r"\ ": 0.25, r"\,": 0.17, r"\quad": 1.0,
          r"\qquad": 2.0, r"\left": 0.0, r"\right": 0.0, r"\lvert": 0.28, r"\rvert": 0.28,
          r"\lVert": 0.5, r"\rVert": 0.5, r"\partial": 0.57, r"\pi": 0.57, r"\ast": 0.5}
_TOKEN = re.compile(r"\\[A-Za-z]+|\\.|[{}^_&]|[^\\{}^_&]")
_TEXT = {r"\operatorname", r"\mathrm", r"\text"}
#: px of MathJax's output per em of the estimate (least squares over the book's displays).
_PX_PER_EM = 16.1


def width(latex) -> float:
    """Estimated width of ``latex`` as MathJax typesets it in a display, in CSS px: glyphs,
    fractions as their wider part, scripts at 70 %, a ``matrix`` as its widest row.  An
    estimate (within about 20 % on the book's displays), for deciding where a line breaks."""
    tokens = _TOKEN.findall(latex)
    return _PX_PER_EM * _em(tokens, 0, len(tokens), 1.0)[0]


def _group(tokens, i, end):
    """The end of the brace group (or single token) that starts at ``tokens[i]``."""
    if i >= end or tokens[i] != "{":
        return min(i + 1, end)
    depth = 0
    for j in range(i, end):
        depth += {"{": 1, "}": -1}.get(tokens[j], 0)
        if depth == 0:
            return j + 1
    return end


def _em(tokens, i, end, size):
    """(width in em of tokens[i:end] at font ``size``, end)."""
    total = line = 0.0
    while i < end:
        t = tokens[i]
        if t in "^_":
            j = _group(tokens, i + 1, end)
            w = _em(tokens, i + 1, j, size * 0.7)[0]
            if j < end and tokens[j] in "^_" and tokens[j] != t:          # x_a^b: the wider script
                k = _group(tokens, j + 1, end)
                w, j = max(w, _em(tokens, j + 1, k, size * 0.7)[0]), k
            line, i = line + w, j
        elif t in (r"\frac", r"\overset", r"\dfrac"):
            j = _group(tokens, i + 1, end)
            k = _group(tokens, j, end)
            inner = size * (0.7 if t == r"\overset" else 1.0 if size >= 1.0 and t == r"\frac" else 0.75)
            top, bottom = _em(tokens, i + 1, j, inner)[0], _em(tokens, j, k, size if t == r"\overset" else inner)[0]
            line, i = line + max(top, bottom) + 0.2 * size, k
        elif t == r"\begin":
            j = _group(tokens, i + 1, end)
            depth, k = 1, j
            while k < end and depth:
                depth += {r"\begin": 1, r"\end": -1}.get(tokens[k], 0)
                k += 1
            body, rows, start = tokens[j:k - 1], [], 0
            for n, tok in enumerate(body + [r"\\"]):
                if tok == r"\\":
                    rows.append(_em(body, start, n, size)[0] + 1.0 * size * body[start:n].count("&"))
                    start = n + 1
            line, i = line + max(rows) + 0.6 * size, _group(tokens, k, end)
        elif t in _TEXT:
            j = _group(tokens, i + 1, end)
            line, i = line + 0.5 * sum(len(x) for x in tokens[i + 1:j] if x not in "{}") * size, j
        elif t in (r"\sin", r"\cos", r"\tan", r"\log", r"\exp", r"\lim", r"\operatorname"):
            line, i = line + (0.5 * (len(t) - 1) + 0.17) * size, i + 1
        elif t == r"\\":
            total, line, i = max(total, line), 0.0, i + 1
        elif t in "{}&" or t.isspace():
            i += 1
        else:
            glyph = _GLYPH.get(t, 0.39 if t in "()[]|'" else 0.45 if t == "," else 1.33 if t in "=<>" else 1.22
                               if t in "+-" else 0.6
                               if t.startswith("\\") else 0.5 if t.isdigit() else 0.55)
            line, i = line + glyph * size, i + 1
    return max(total, line), end


# ------------------------------------------------------------------------------- layout
def _lines(printer, expr, room):
    """``expr`` printed as lines within ``room`` px where it can break (`_Printer.pieces`), greedily."""
    lines = []
    for piece in printer.pieces(expr):
        if lines and width(lines[-1] + piece) > room:
            lines.append(piece.lstrip())
        else:
            lines.append((lines.pop() if lines else "") + piece)
    return lines


def _relation(k):
    """The "=" of a chain's line, marked with the number of the step that proves it."""
    return "=" if k is None else rf"\overset{{({k})}}{{=}}"


def _rows(printer, blocks, marks, column, left):
    """The lines of `chain`'s display, and by how many px the widest overflows ``column`` (<= 0: none):
    each block's left side,
    then its relations; aligned at "=" after a left side ``left`` px wide, or (``left`` None) each left
    side on a line of its own."""
    rows, excess = [], -column
    for block in blocks:
        if left is not None:
            head, indent, room = printer._print(block[0]) + " &", r"&\qquad ", column - left - 30
        else:
            lines = _lines(printer, block[0], column)
            rows += [r"&" + line for line in lines]
            excess = max(excess, max(map(width, lines)) - column)
            head, indent, room = r"&\quad ", r"&\qquad\quad ", column - 48
        for mark, rhs in zip(marks, block[1:]):
            first, *rest = lines = _lines(printer, rhs, room)
            excess = max(excess, max(map(width, lines)) - room)
            rows.append(f"{head}{_relation(mark)} {first}")
            rows += [indent + line for line in rest]
            head = "&" if left is not None else r"&\quad "
    return rows, excess


def chain(t, steps, numbers=None, column=COLUMN_PX) -> str:
    """One calc chain of theorem ``t`` as one LaTeX ``aligned`` display: ``lhs = r_1 = r_2 ...`` one
    relation a line, each "=" marked with its step's number (``numbers``; unmarked if None or
    the chain is one step);
    a chain of tuples one block of lines per component; a line wider than ``column`` px
    broken (`_Printer.pieces`), continued indented.  A step whose left side is not the right
    side of the one before (a link decided equal to it) adds that left side as a line.

    Parameters
    ----------
    t : proofs.core.Theorem
    steps : sequence of proofs.core.Step
        A run of one chain: each after the first a link.
    numbers : sequence of int, optional
        The steps' numbers in the proof, one per step.
    column : float
        The width a line may take, in CSS px.

    Returns
    -------
    str
        ``\\begin{aligned} ... \\end{aligned}``, or a bare ``lhs = rhs`` where it fits one line.
    """
    printer = _Printer(t.names)
    numbers = list(numbers) if numbers is not None and len(steps) > 1 else [None] * len(steps)
    # (lhs, [(number, rhs), ...]): the relations of the chain, left sides shown only where they change.
    sides = [steps[0].lhs]
    marks = []
    for k, step in zip(numbers, steps):
        if step.lhs != sides[-1]:
            sides.append(step.lhs)
            marks.append(None)
        sides.append(step.rhs)
        marks.append(k)
    split = all(isinstance(s, sp.Tuple) and len(s) == len(sides[0]) for s in sides)
    blocks = [[s[i] for s in sides] for i in range(len(sides[0]))] if split else [sides]
    if len(blocks) == 1 and len(sides) == 2 and width(printer._print(sides[0]) + " = " + printer._print(sides[1])) <= column:
        return f"{printer._print(sides[0])} {_relation(marks[0])} {printer._print(sides[1])}"
    left = max(width(printer._print(b[0])) for b in blocks)
    rows, excess = _rows(printer, blocks, marks, column, left)    # aligned at "=" if every line fits,
    if excess > 0:                                                  # else under the left side if that
        under, less = _rows(printer, blocks, marks, column, None)   # overflows less
        rows = under if less < excess else rows
    return r"\begin{aligned}" + r"\\ ".join(rows) + r"\end{aligned}"
