"""The theorems print as the book shows them: each theorem's statement, its steps (lhs = rhs) and the
definitions its steps introduce, in LaTeX from proofs/core.py's printer, are the text the chapter was
reviewed in.  A printer that drops a prime, a sign or a bracket states a theorem other than the one
checked; this fails, naming the theorem and printing its new text.

After an intended change of notation, review the new text (it is printed) and record its digest here:
``python tests/test_notation.py`` prints the table.
"""

import hashlib

import pytest
import sympy as sp

from proofs.core import tex, written
from proofs.registry import THEOREMS

#: sha256 (first 16 hex digits) of `printed`, per theorem.
PRINTED = {
    "chart": "281377454e137b4f",
    "frame-orthonormal": "5e2d3ba9660f0dfc",
    "frame-orientation": "ecd7762812643c2c",
    "gradient-sine": "a0d32e32db0c87fd",
    "gradient-ridges": "568dc8dac31dd110",
    "gradient-rings": "c57d5ee6dc25cc0d",
    "ridges-kinks": "95eeaf03b0543a5d",
    "kink-loci-rays": "846041ddbb4c7b7a",
    "kink-loci-circles": "2ee79e7e99261d40",
    "no-boundary": "23e06e379e02c039",
    "normal-beta-derivative": "bfde89e2e383c5c0",
    "beta-zero-regression": "b47aea0df169fda4",
    "central-difference-truncation": "15fa36211b297057",
    "optimal-step": "729b6a1ff9f9973f",
    "bump-vs-displacement": "312f40d2df1d5e05",
    "blinn-perturbation": "df041990cdcbf0d2",
}


def printed(t):
    """The theorem's text as the book prints it: statement, each step's equation, each defined symbol."""
    return "\n".join([t.statement_tex()] + [f"{t.tex(s.lhs)} = {t.tex(s.rhs)}" for s in t.steps]
                     + [t.definition_tex(d) for s in t.steps for d in s.defines])


def _digest(text):
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@pytest.mark.parametrize("theorem_id", list(THEOREMS))
def test_the_theorem_prints_as_reviewed(theorem_id):
    text = printed(THEOREMS[theorem_id])
    assert _digest(text) == PRINTED[theorem_id], f"{theorem_id} now prints:\n{text}"


def test_every_theorem_has_a_recorded_print():
    assert set(PRINTED) == set(THEOREMS)


if __name__ == "__main__":
    for theorem_id, t in THEOREMS.items():
        print(f'    "{theorem_id}": "{_digest(printed(t))}",')


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
     r"\left( y + x, \  x + y\right)"),
    (M, {M: r"\mathbf{M}"}, r"\mathbf{M}"),
    (x ** sp.Rational(3, 2), None, "x^{3/2}"),
    (sp.MatAdd(B, A, evaluate=False), None, "A + B"),
], ids=["d2", "mixed", "named-function", "minus-named", "times-named", "minus-fraction", "nested-product",
        "named-power", "function-power", "root-of-power", "written-then-sorted", "named-matrix", "half-power",
        "sum-order"])
def test_the_printer_writes_each_form_as_a_person_does(expr, names, latex):
    assert tex(expr, names) == latex
