"""The suite's own tolerances: a relative tolerance must be only relative.

``pytest.approx(x, rel=r)`` also accepts anything within its default absolute tolerance, 1e-12, of x, and
``numpy.allclose`` / ``numpy.isclose`` within theirs, 1e-8.  For the numbers this project checks (a
roundoff coefficient of 2e-16, an error of 1e-10, a step of 1e-6) a default is larger than the relative
tolerance meant, or larger than the number itself: a fit whose roundoff coefficient was 50 % off passed
``== pytest.approx((3.0, 2e-16), rel=1e-12)``.  So every ``pytest.approx`` in tests/ and verify/ that
gives ``rel`` also gives ``abs``, and every ``np.allclose`` and ``np.isclose`` gives ``atol`` (0 where only
the relative error is meant).  (``math.isclose`` and ``numpy.testing.assert_allclose`` default to an
absolute tolerance of 0.)
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


#: (module, function): the keyword that gives the absolute tolerance, and the keyword whose presence makes a
#: call relative (None: every call is).
CALLS = {("pytest", "approx"): ("abs", "rel"), ("np", "allclose"): ("atol", None), ("np", "isclose"): ("atol", None),
         ("numpy", "allclose"): ("atol", None), ("numpy", "isclose"): ("atol", None)}


def unstated_absolute_tolerance(source: str) -> list[int]:
    """Line numbers of the calls in ``source`` that leave their absolute tolerance to its default (`CALLS`):
    ``pytest.approx`` with ``rel`` and no ``abs``, ``np.allclose`` or ``np.isclose`` without ``atol``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and isinstance(node.func.value, ast.Name):
            rule = CALLS.get((node.func.value.id, node.func.attr))
            given = {k.arg for k in node.keywords}
            if rule and (rule[1] is None or rule[1] in given) and rule[0] not in given:
                found.append(node.lineno)
    return sorted(found)


def test_every_relative_tolerance_states_its_absolute_one():
    found = {str(p.relative_to(ROOT)): lines for p in sorted([*ROOT.glob("tests/*.py"), *ROOT.glob("verify/*.py")])
             if (lines := unstated_absolute_tolerance(p.read_text(encoding="utf-8")))}
    assert not found, f"a tolerance left to its default absolute one, which passes small numbers: {found}"


def test_the_check_finds_a_relative_tolerance_alone_and_what_it_let_pass():
    assert unstated_absolute_tolerance("assert x == pytest.approx(2e-16, rel=1e-12)\n"
                                       "assert y == pytest.approx(1.0, rel=1e-12, abs=0)\n"
                                       "assert z == pytest.approx(1.0)\n"
                                       "assert np.allclose(a, b, rtol=1e-9)\n"
                                       "assert np.isclose(a, b, rtol=1e-9, atol=0)\n") == [1, 4]
    assert 3e-16 == pytest.approx(2e-16, rel=1e-12, abs=1e-12)       # the default's absolute 1e-12: passes
    assert 3e-16 != pytest.approx(2e-16, rel=1e-12, abs=0)
    assert np.allclose(3e-10, 2e-10, rtol=1e-9, atol=1e-8) and not np.allclose(3e-10, 2e-10, rtol=1e-9, atol=0)
