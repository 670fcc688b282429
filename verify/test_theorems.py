"""`pytest verify`: one test per theorem, and one per wrong variant.

A theorem passes when its check returns proved or verified; the ledger of
verdicts is printed at the end of the run (see conftest.py).  Each wrong
variant (a flipped sign, a dropped factor, a wrong exponent) must be refuted:
the checker has teeth.
"""

import dataclasses
import re
from pathlib import Path

import pytest

from proofs.registry import PINNED, RENDERED, THEOREMS, get, pinned_failure
from verify.conftest import LEDGER

BOOK = Path(__file__).resolve().parents[1] / "book"
VARIANTS = [(t.id, d, fn) for t in THEOREMS.values() for d, fn in t.wrong_variants]


@pytest.mark.parametrize("theorem_id", list(THEOREMS))
def test_theorem_holds(theorem_id):
    verdict = THEOREMS[theorem_id].check()
    LEDGER[theorem_id] = verdict
    assert verdict.holds, f"{theorem_id} {verdict.status}: {verdict.evidence}"
    assert isinstance(verdict.evidence, str) and verdict.evidence, "the ledger shows the evidence"
    assert pinned_failure(theorem_id, verdict.status, verdict.residual, verdict.rendered) is None
    if verdict.status == "verified":      # mpmath at >= 30 digits, or >= 100 renders without a difference
        assert (verdict.digits is not None and verdict.digits >= 30 and verdict.points >= 20) or \
            (verdict.digits is None and verdict.points >= 100 and verdict.residual == 0.0)


def test_every_theorem_has_a_pinned_verdict():
    assert set(PINNED) == set(THEOREMS)
    assert set(RENDERED) <= set(THEOREMS)


def test_a_check_that_skips_the_renderer_is_named():
    """A verdict reached without its renderer comparison (fewer outputs than pinned) is a change."""
    assert "compared 599 renderer outputs, pinned at least 600" in pinned_failure("chart", "verified", 1e-30, 599)
    assert pinned_failure("chart", "verified", 1e-30, 600) is None


@pytest.mark.parametrize("pin, status, residual, why", [
    ("proved", "verified", 1e-30, "is verified, pinned proved"),
    (("verified", 1e-25), "proved", None, "is proved, pinned verified"),
    (("verified", 1e-25), "verified", 1e-20, "residual 1e-20, pinned at most 1e-25"),
    (("verified", 1e-25), "verified", None, "residual None"),
])
def test_a_changed_verdict_is_named(monkeypatch, pin, status, residual, why):
    monkeypatch.setitem(PINNED, "chart", pin)
    assert why in pinned_failure("chart", status, residual, RENDERED["chart"])
    assert pinned_failure("chart", *((pin, None) if isinstance(pin, str) else ("verified", 1e-30)),
                          RENDERED["chart"]) is None


@pytest.mark.parametrize("theorem_id, description, variant", VARIANTS,
                         ids=[f"{i}: {d}" for i, d, _ in VARIANTS])
def test_wrong_variant_is_refuted(theorem_id, description, variant):
    verdict = variant()
    assert verdict.status == "refuted", f"{theorem_id}, {description}: {verdict.evidence}"
    assert isinstance(verdict.evidence, str) and verdict.evidence, "a refutation says why"


def test_every_theorem_has_a_variant_and_a_statement():
    for t in THEOREMS.values():
        assert t.wrong_variants, t.id
        assert t.statement and t.steps, t.id


def test_every_theorem_is_titled_and_used_on_pages_that_place_it():
    """The ledger's "used on" list names book pages, among them the page whose theorem block shows
    the theorem; the title is the block's heading."""
    pages = {p.name.split("_")[0]: p.read_text(encoding="utf-8") for p in BOOK.glob("s[0-9]_*.md")}
    for t in THEOREMS.values():
        assert isinstance(t.title, str) and t.title.strip() == t.title and len(t.title) > 3, t.id
        assert isinstance(t.pages, tuple) and set(t.pages) <= set(pages), (t.id, t.pages)
        placed = {name for name, text in pages.items() for line in text.splitlines()
                  if "theorem_block(" in line and re.search(rf"[\"']{re.escape(t.id)}[\"']", line)}
        assert placed and placed <= set(t.pages), (t.id, placed, t.pages)


def _step_residual(lhs, rhs, seed=0):
    """Worst |lhs - rhs| (derivatives evaluated) at 20 seeded points, every free symbol in
    (0.2, 2.5): inside the chart's range (theta in (-pi, pi), phi in (0, pi)) and the fields'."""
    import random

    import sympy as sp
    diff = sp.Matrix(lhs).doit() - sp.Matrix(rhs) if isinstance(lhs, sp.MatrixBase) else lhs.doit() - rhs
    free = sorted(diff.free_symbols, key=str)
    fn = sp.lambdify(free, diff, modules="mpmath")
    rng = random.Random(seed)
    return max(float(abs(sp.Matrix(fn(*at)).norm()) if isinstance(diff, sp.MatrixBase) else abs(fn(*at)))
               for at in ([rng.uniform(0.2, 2.5) for _ in free] for _ in range(20)))


#: Steps the book shows as "lhs = rhs" between two sympy objects (the rest pair LaTeX with one).
SYMPY_STEPS = [(t.id, caption, lhs, rhs) for t in THEOREMS.values() for caption, lhs, rhs in t.steps
               if all(hasattr(x, "free_symbols") for x in (lhs, rhs))]


@pytest.mark.parametrize("theorem_id, caption, lhs, rhs", SYMPY_STEPS,
                         ids=[f"{s[0]}:{s[1]}" for s in SYMPY_STEPS])
def test_a_step_the_book_shows_holds(theorem_id, caption, lhs, rhs):
    assert _step_residual(lhs, rhs) < 1e-12, f"{theorem_id}, step {caption}: the two sides differ"


def test_a_step_check_refutes_a_wrong_step():
    import sympy as sp
    from renderer import formulas as F
    assert _step_residual(sp.Derivative(F.HEIGHT["sine"], F.u), F.GRADIENT["sine"][0]) < 1e-12
    assert _step_residual(sp.Derivative(F.HEIGHT["sine"], F.u), F.GRADIENT["sine"][1]) > 1e-3


def test_registry_names_unknown_ids():
    with pytest.raises(KeyError, match="no theorem 'no-such'"):
        get("no-such")


def test_book_block_refuses_a_failing_theorem(monkeypatch):
    """A theorem that does not hold fails the build (the cell raises)."""
    from proofs import book, registry
    from proofs.core import Verdict
    refuted = dataclasses.replace(get("optimal-step"), check=lambda: Verdict("refuted", "forced for the test"))
    monkeypatch.setattr(registry, "THEOREMS", {"optimal-step": refuted,
                                               "frame-orthonormal": get("frame-orthonormal")})
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    with pytest.raises(book.TheoremFailed, match="optimal-step is refuted"):
        book.theorem_block("optimal-step")
    assert "PROVED" in book.theorem_block("frame-orthonormal")
    with pytest.raises(book.TheoremFailed, match="optimal-step is refuted"):
        book.ledger_table()
    with pytest.raises(KeyError, match="no theorem 'no-such'"):
        book.theorem_block("no-such")


def test_book_block_refuses_a_changed_verdict(monkeypatch):
    """A theorem that holds but not with its pinned verdict also fails the build."""
    from proofs import book, registry
    monkeypatch.setattr(registry, "THEOREMS", {"frame-orthonormal": get("frame-orthonormal")})
    monkeypatch.setitem(registry.PINNED, "frame-orthonormal", ("verified", 1e-25))
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    for show in (lambda: book.theorem_block("frame-orthonormal"), book.ledger_table):
        with pytest.raises(book.TheoremFailed, match="frame-orthonormal is proved, pinned verified"):
            show()


def test_undecided_identity_is_verified_numerically(monkeypatch):
    """When sympy cannot decide, a true identity is 'verified' at >= 20 points and
    >= 30 digits with its worst residual stated, and a false one is still refuted."""
    import sympy as sp

    from proofs import core
    monkeypatch.setattr(core, "_exactly_zero", lambda expr: False)   # sympy "cannot decide"
    x = sp.Symbol("x", real=True)
    true = core.Identity("double angle", sp.sin(2 * x), 2 * sp.sin(x) * sp.cos(x), {x: (-3, 3)})
    verdict = core.check_identities([true])
    assert verdict.status == "verified"
    assert verdict.points >= 20 and verdict.digits >= 30 and verdict.residual < 1e-25
    false = core.Identity("wrong angle", sp.sin(2 * x), sp.sin(x) * sp.cos(x), {x: (-3, 3)})
    assert core.check_identities([false]).status == "refuted"


def test_book_block_refuses_a_check_without_its_renders(monkeypatch):
    """The chart's identities alone, its renderer comparison skipped: the build fails."""
    from proofs import book, registry
    from proofs.core import Verdict
    skipped = dataclasses.replace(get("chart"), check=lambda: Verdict("verified", "identities only", 1e-31, 30, 24))
    monkeypatch.setattr(registry, "THEOREMS", {"chart": skipped})
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    with pytest.raises(book.TheoremFailed, match="chart compared 0 renderer outputs, pinned at least 600"):
        book.theorem_block("chart")


def test_the_kink_loci_refuse_an_unknown_family():
    from renderer import Scene

    from proofs.kink_loci import locus_bands
    with pytest.raises(ValueError, match=r"kind must be one of \('rays', 'circles'\), got 'lines'"):
        locus_bands("lines", Scene(), 8, 8)
