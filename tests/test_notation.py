"""The theorems print as the book shows them: each theorem's statement, its steps' sentences, the display of
each of its calc chains and the definitions its steps introduce, in LaTeX from book/chapter/latex.py, are the
text the chapter was reviewed in.  A printer that drops a prime, a sign or a bracket states a theorem other than the one
checked; this fails, naming the theorem and printing its new text.

After an intended change of notation, review the new text and record its digest here:
``python tests/test_notation.py`` prints the text of each new or changed theorem, then the table.
"""

import hashlib
import re

import pytest
import sympy as sp

from chapter import latex
from chapter.latex import tex
from chapter.theorems import _chains
from proofs.core import written
from proofs.registry import THEOREMS

#: sha256 (first 16 hex digits) of `printed`, per theorem.
PRINTED = {
    "shading": "1fce5561cf3d311a",
    "displaced-normal": "29ad1e174333cdfb",
    "chart": "b0eb3cf5166d0cb0",
    "frame-orthonormal": "6f2e22487456f433",
    "frame-orientation": "159cdc15fdb9b096",
    "gradient-sine": "afdd4d313d68b6fe",
    "gradient-ridges": "c7e368c0325ff445",
    "gradient-rings": "ccd11d1bae25eafb",
    "ridges-kinks": "e05b59e321093ac4",
    "kink-loci-rays": "3f2bafdfa214747e",
    "kink-loci-circles": "3fd68e4230bb45e8",
    "no-boundary": "8bce22910d9e53d8",
    "normal-beta-derivative": "35beda755e35b086",
    "beta-zero-regression": "3fcdd884c05219d5",
    "central-difference-truncation": "1d7a38548a2d22ed",
    "optimal-step": "8ff24d3b64fdf31c",
    "bump-vs-displacement": "faba007091e2fccc",
    "blinn-perturbation": "0b31a92250fdbb7d",
}


#: What a failure tells the author to do.
RECORD = ("If the change is intended, review the text, then run .venv/bin/python tests/test_notation.py "
          "and paste the table it prints over PRINTED in tests/test_notation.py.")


def printed(t):
    """The theorem's text as the book prints it: statement, each step's sentence, each calc chain's display,
    each defined symbol."""
    return "\n".join([latex.statement(t)] + [s.why for s in t.steps]
                     + [latex.chain(t, [s for _, s in run], [k for k, _ in run]) for run in _chains(t.steps)]
                     + [latex.definition(t, d, inline=True) for s in t.steps for d in s.defines])


def _digest(text):
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@pytest.mark.parametrize("theorem_id", list(THEOREMS))
def test_the_theorem_prints_as_reviewed(theorem_id):
    text = printed(THEOREMS[theorem_id])
    assert _digest(text) == PRINTED.get(theorem_id), f"{theorem_id} now prints:\n{text}\n{RECORD}"


def test_every_theorem_has_a_recorded_print():
    assert set(PRINTED) == set(THEOREMS), (f"theorems without a recorded print: {sorted(set(THEOREMS) - set(PRINTED))}; "
                                           f"recorded, no longer a theorem: {sorted(set(PRINTED) - set(THEOREMS))}. {RECORD}")


if __name__ == "__main__":
    # The text of each theorem whose print is new or changed (to review), then the table to paste over
    # PRINTED: its order, new theorems last, removed ones gone.
    for theorem_id, t in THEOREMS.items():
        if _digest(printed(t)) != PRINTED.get(theorem_id):
            print(f"--- {theorem_id} now prints:\n{printed(t)}\n")
    for theorem_id in [*(k for k in PRINTED if k in THEOREMS), *(k for k in THEOREMS if k not in PRINTED)]:
        print(f'    "{theorem_id}": "{_digest(printed(THEOREMS[theorem_id]))}",')


# The printer's forms that no theorem prints today, as a person writes them.
x, y, theta = sp.symbols("x y theta")
h, H = sp.Function("h"), sp.Function("H")
A, B, C, M, N = (sp.MatrixSymbol(name, 3, 1) for name in "ABCMN")
NORM = sp.Symbol(r"\lVert M\rVert", positive=True)


@pytest.mark.parametrize("expr, names, latex", [
    (sp.Derivative(x * y * sp.sin(x), (x, 2)), None, r"\frac{\partial^{2}}{\partial x^{2}} \left(x y \sin {x}\right)"),
    (sp.Derivative(sp.sin(x * y), x, y), None,
     r"\frac{\partial^{2}}{\partial x \partial y} \left(\sin{\left(x y \right)}\right)"),
    (sp.Derivative(h(x), x), {h: "H"}, r"H'\left(x\right)"),
    (-sp.Derivative(N, theta), None, r"- \frac{\partial N}{\partial \theta}"),
    (2 * sp.Derivative(N, theta), None, r"2 \frac{\partial N}{\partial \theta}"),
    (-M / NORM, None, r"- \frac{M}{\lVert M\rVert}"),
    (sp.MatMul(2, A.T, sp.MatMul(B, C.T, evaluate=False), evaluate=False), None, r"2 A^{T} \left(B C^{T}\right)"),
    (H(x, theta) ** 2, {H(x, theta): "H"}, "H^{2}"),
    (sp.sin(x + 1) ** 2, None, r"\sin^{2}{\left(x + 1 \right)}"),
    (sp.Pow(x**2, sp.Rational(1, 3), evaluate=False), None, r"\left(x^{2}\right)^{1/3}"),
    (sp.Tuple(written(sp.Add(y, x, evaluate=False)), sp.Add(y, x, evaluate=False)), None,
     r"({y + x},\ \allowbreak {x + y})"),
    (M, {M: r"\mathbf{M}"}, r"\mathbf{M}"),
    (x ** sp.Rational(3, 2), None, "x^{3/2}"),
    (sp.MatAdd(B, A, evaluate=False), None, "A + B"),
    (sp.Contains(x, sp.Interval.open(-sp.pi, sp.pi), evaluate=False), None, r"- \pi < x < \pi"),
    (sp.Contains(x, sp.Interval.Lopen(0, 1), evaluate=False), None, r"0 < x \le 1"),
    (sp.Contains(x, sp.Interval(0, sp.oo), evaluate=False), None, r"x \in \left[0, \infty\right)"),
    (sp.Or(x < 1, y > 2), None, r"y > 2\ \text{or}\ x < 1"),
], ids=["d2", "mixed", "named-function", "minus-named", "times-named", "minus-fraction", "nested-product",
        "named-power", "function-power", "root-of-power", "written-then-sorted", "named-matrix", "half-power",
        "sum-order", "open-interval", "half-open", "unbounded-interval", "or"])
def test_the_printer_writes_each_form_as_a_person_does(expr, names, latex):
    assert tex(expr, names) == latex


@pytest.mark.parametrize("expr, latex", [
    (-sp.Derivative(N, theta), r"- \partial N / \partial \theta"),
    (sp.Derivative(N, theta, 2), r"\partial^{2} N / \partial \theta^{2}"),
    (M / NORM, r"M / \lVert M\rVert"),
    ((A + B) / NORM, r"\left(A + B\right) / \lVert M\rVert"),
    (-2 * M / NORM, r"-2 M / \lVert M\rVert"),
    (x / (2 * sp.pi), r"x / \left(2 \pi\right)"),
    ((x + 1) / (2 * sp.pi), r"\left(x + 1\right) / \left(2 \pi\right)"),
    (-x / (x + 1), r"- x / \left(x + 1\right)"),
    (x / sp.sin(theta), r"x / \sin {\theta}"),
    (sp.Rational(-3, 100), "- 3 / 100"),
    (sp.Derivative(x / sp.pi, x, evaluate=False), r"d / d x \left(x / \pi\right)"),
], ids=["minus-named", "second-named", "over-a-norm", "sum-over-a-norm", "scaled-over-a-norm", "over-a-product",
        "sum-over-a-product", "over-a-sum", "over-a-function", "rational", "derivative-of-an-expression"])
def test_in_running_text_a_fraction_is_a_quotient(expr, latex):
    """In a line of text a stacked fraction is set at 70 % (small on a phone): a fraction, the derivative of a name
    and a vector over a scalar are written with "/", a denominator that is not one symbol, number or function of
    one in brackets, and a sum over it too; set apart, they stay stacked."""
    assert tex(expr, inline=True) == latex
    assert r"\frac" in tex(expr) and "/" not in tex(expr)


def test_a_tuple_chain_prints_a_component_a_line():
    """A chain of tuples is one block per component, its left side once, one relation a line; MathJax
    breaks a line too wide for the reader's column (tests/test_browser.py measures the typeset pages)."""
    u, v, w = sp.symbols("u v w")
    from proofs.core import Theorem, calc
    t = Theorem("t", "T", "", calc(sp.Tuple(u, v), ("why", sp.Tuple(w, 2 * w)), ("then", sp.Tuple(1, 2))), {})
    assert latex.chain(t, t.steps, [1, 2]) == (r"\begin{aligned}\raise 0em{u} &\overset{(1)}{=} w\\ &\overset{(2)}{=} 1\\ "
                                               r"\raise 0em{v} &\overset{(1)}{=} 2 w\\ &\overset{(2)}{=} 2\end{aligned}")


def test_a_column_vector_chain_prints_a_component_a_line_its_expressions_above_their_relations():
    """A column vector's equation is a block per component, as a tuple's (as one matrix beside another, MathJax
    broke it at "=" on a phone); a component whose left side is an expression, not a name, has that side on a
    line of its own and its relation indented below it."""
    u, v, w = sp.symbols("u v w")
    from proofs.core import Theorem, calc
    named = Theorem("t", "T", "", calc(sp.Matrix([u, v]), ("why", sp.Matrix([w, 2 * w]))), {})
    assert latex.chain(named, named.steps) == r"\begin{aligned}\raise 0em{u} &= w\\ \raise 0em{v} &= 2 w\end{aligned}"
    formulas = Theorem("t", "T", "", calc(sp.Matrix([u + v, v]), ("why", sp.Matrix([w, 2 * w]))), {})
    assert latex.chain(formulas, formulas.steps) == (r"\begin{aligned}&\raise 0em{u + v}\\ &\qquad = w\\ "
                                                     r"&\raise 0em{v}\\ &\qquad = 2 w\end{aligned}")


def test_a_link_whose_left_side_is_rewritten_shows_that_side_on_an_unmarked_line():
    """A link's left side may differ in form from the step before's right side (decided equal with
    the link's rewrites): the chain then shows it, joined by an "=" no step number marks, so the
    display never asserts that a step proved the rewrite."""
    from proofs.core import Step
    x = sp.Symbol("x")
    t = THEOREMS["optimal-step"]
    steps = [Step("expand", x * (x + 2) + 1, x**2 + 2 * x + 1),
             Step("factor", sp.Pow(x + 1, 2, evaluate=False), sp.Symbol("y"), link=True)]
    shown = latex.chain(t, steps, [1, 2])
    lines = shown.removeprefix(r"\begin{aligned}").removesuffix(r"\end{aligned}").split(r"\\ ")
    assert len(lines) == 3, shown
    assert r"\overset{(1)}{=}" in lines[0] and r"\overset{(2)}{=}" in lines[2]
    assert r"\left(x + 1\right)^{2}" in lines[1] and r"\overset" not in lines[1]


def _fraction_in_fraction(math):
    """Whether ``math`` has a ``\\frac`` within the numerator or denominator of another."""
    for start in (m.end() for m in re.finditer(r"\\frac(?=\{)", math)):
        depth, i = 0, start
        for arg in range(2):
            begin = i
            while True:
                depth += {"{": 1, "}": -1}.get(math[i], 0)
                i += 1
                if depth == 0:
                    break
            if r"\frac" in math[begin:i]:
                return True
    return False


def test_no_statement_sets_a_fraction_in_a_fraction_inline():
    """A fraction within a fraction in running text is set at half size (unreadable on a phone): a statement
    sets such a claim apart (``$$⟦key⟧$$``), its fractions at full size."""
    assert _fraction_in_fraction(r"\frac{\beta \left(\frac{H}{s}\right)}{R}") and not _fraction_in_fraction(r"\frac{a}{b} \frac{c}{d}")
    for t in THEOREMS.values():
        text = latex.statement(t)
        inline = re.findall(r"\$([^$]+)\$", re.sub(r"\$\$.*?\$\$", " ", text, flags=re.S))
        assert not [m for m in inline if _fraction_in_fraction(m)], t.id
    shown = latex.statement(THEOREMS["bump-vs-displacement"])
    assert re.search(r"\$\$\s*\\dfrac\{\\partial P\}", shown) and r"\dfrac{H_{\theta} e_\theta}" in shown
