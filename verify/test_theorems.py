"""`pytest verify`: each theorem of the chapter checked once, against the code that draws the
figures.  A theorem passes when its check returns proved or verified with its pinned verdict;
the ledger of verdicts is printed at the end of the run, with or without xdist (see conftest.py).  That the checker
refutes wrong variants and wrong steps is a property of the checker: tests/test_checker.py.
"""

import re
from pathlib import Path

import pytest

from chapter import latex
from chapter.theorems import code_words
from proofs.registry import THEOREMS, least_rendered, pin, unknown_keys, verdict_failure
from renderer.formulas import FIELDS

BOOK = Path(__file__).resolve().parents[1] / "book"


@pytest.mark.parametrize("theorem_id", [pytest.param(t, marks=pytest.mark.cpu_dependent if least_rendered(t) else ())
                                        for t in THEOREMS])
def test_theorem_holds(theorem_id, record_property):
    verdict = THEOREMS[theorem_id].check()
    # printed by conftest.py, in the chapter's order: the place, not the registry, travels with the report
    record_property("ledger", (list(THEOREMS).index(theorem_id), theorem_id, verdict.status, verdict.evidence))
    assert verdict_failure(theorem_id, verdict) is None, verdict_failure(theorem_id, verdict)
    assert isinstance(verdict.evidence, str) and verdict.evidence, "the ledger shows the evidence"
    assert not code_words(verdict.evidence), f"§6 shows the evidence to the reader: {code_words(verdict.evidence)}"


def test_every_theorem_has_a_pinned_verdict_and_every_pin_a_theorem():
    """Each theorem has a well-formed pin (`pin`), and each key of `PINNED` and `RENDERED` names a theorem, or
    (``{field}``) the theorem of a registered field."""
    for t in THEOREMS:
        pin(t)                            # raises for a theorem without a pin, or with a malformed one
    assert unknown_keys() == []


def _placed(text):
    """The theorem ids a page shows: string constants, and f-strings with one field placeholder (each
    registered field), in the statements of its code cells that call theorem_block, or a function of the
    page that calls it (as s3's ``theorems(*ids)``)."""
    import ast
    cells = [ast.parse(re.sub(r"\A(:\w+:[^\n]*\n)+", "", code))           # less the cell's :tags: lines
             for code in re.findall(r"```\{code-cell\}[^\n]*\n(.*?)\n```", text, re.S) if "theorem_block" in text]
    calls = lambda node, names: any(isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id in names  # noqa: E731
                                    for n in ast.walk(node))
    helpers = {"theorem_block"} | {n.name for tree in cells for n in tree.body
                                   if isinstance(n, ast.FunctionDef) and calls(n, {"theorem_block"})}
    def ids(node):                          # a string constant, or an f-string over the registered fields
        if isinstance(node, ast.JoinedStr):
            parts = [p.value if isinstance(p, ast.Constant) else "{}" for p in node.values]
            return {"".join(parts).replace("{}", f) for f in FIELDS} if parts.count("{}") == 1 else set()
        return {node.value} if isinstance(node, ast.Constant) and isinstance(node.value, str) else set()
    return {i for tree in cells for stmt in tree.body if not isinstance(stmt, ast.FunctionDef)
            and calls(stmt, helpers) for c in ast.walk(stmt) for i in ids(c)}


def test_every_theorem_is_titled_and_placed_on_a_page():
    """Some book page's theorem block shows the theorem (`_placed`); the title is the block's heading."""
    placed = set().union(*(_placed(p.read_text(encoding="utf-8")) for p in BOOK.glob("s[0-9]_*.md")))
    for t in THEOREMS.values():
        assert isinstance(t.title, str) and t.title.strip() == t.title and len(t.title) > 3, t.id
        assert t.id in placed, (f"{t.id} is placed on no page: name it in a theorem_block, theorems or folded call "
                                "of a page's code cell (book/s*.md)")


def test_every_claim_is_stated_and_every_statement_prints():
    """The statement prints each claim (``⟦key⟧``) from the objects the steps reach; nothing else is named."""
    for t in THEOREMS.values():
        assert t.claims, t.id
        for key in t.claims:
            assert f"⟦{key}⟧" in t.statement, (t.id, key)
        assert "⟦" not in latex.statement(t), t.id


def test_no_theorem_rests_on_itself_through_its_citations():
    """Rule 8: the citations among the registry's theorems form no cycle (`proofs.core.citation_cycle`)."""
    from proofs.core import citation_cycle
    assert citation_cycle(dict(THEOREMS)) is None
