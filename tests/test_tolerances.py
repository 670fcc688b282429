"""The suite's own tolerances: a relative tolerance must be only relative.

``pytest.approx(x, rel=r)`` also accepts anything within its default absolute tolerance, 1e-12, of x.
For the numbers this project checks (a roundoff coefficient of 2e-16, an error of 1e-10, a step of
1e-6) that default is larger than the relative tolerance meant, or larger than the number itself: a fit
whose roundoff coefficient was 50 % off passed ``== pytest.approx((3.0, 2e-16), rel=1e-12)``.  So every
``pytest.approx`` in tests/ and verify/ that gives ``rel`` also gives ``abs`` (``abs=0`` where only the
relative error is meant).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def approx_without_abs(source: str) -> list[int]:
    """Line numbers of the ``pytest.approx(...)`` calls in ``source`` that give ``rel`` and no ``abs``."""
    return [node.lineno for node in ast.walk(ast.parse(source))
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "approx"
            and isinstance(node.func.value, ast.Name) and node.func.value.id == "pytest"
            and {"rel"} <= {k.arg for k in node.keywords} and "abs" not in {k.arg for k in node.keywords}]


def test_every_relative_tolerance_states_its_absolute_one():
    found = {str(p.relative_to(ROOT)): lines for p in sorted([*ROOT.glob("tests/*.py"), *ROOT.glob("verify/*.py")])
             if (lines := approx_without_abs(p.read_text(encoding="utf-8")))}
    assert not found, f"pytest.approx with rel= and no abs= (its default abs=1e-12 then passes small numbers): {found}"


def test_the_check_finds_a_relative_tolerance_alone_and_what_it_let_pass():
    assert approx_without_abs("assert x == pytest.approx(2e-16, rel=1e-12)\n"
                              "assert y == pytest.approx(1.0, rel=1e-12, abs=0)\n"
                              "assert z == pytest.approx(1.0)\n") == [1]
    assert 3e-16 == pytest.approx(2e-16, rel=1e-12, abs=1e-12)       # the default's absolute 1e-12: passes
    assert 3e-16 != pytest.approx(2e-16, rel=1e-12, abs=0)
