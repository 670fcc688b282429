"""book/chapter/verdicts.py: every claim of the draft is shown once, where the book discusses it,
as a margin note, and the register's row and the note link to each other."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from chapter import verdicts
from lab.claims import CLAIMS, FAILS, HOLDS

BOOK = Path(__file__).parents[1] / "book"


def _placed(places):
    return [i for ids in places.values() for i in ids]


def test_every_claim_is_placed_exactly_once():
    placed = _placed(verdicts.PLACES)
    assert sorted(placed) == sorted(c.id for c in CLAIMS)


def test_a_claim_placed_twice_or_nowhere_is_caught():
    twice = {**verdicts.PLACES, "s9": ("h3-scale",)}
    assert sorted(_placed(twice)) != sorted(c.id for c in CLAIMS)
    nowhere = {k: tuple(i for i in v if i != "stacking") for k, v in verdicts.PLACES.items()}
    assert sorted(_placed(nowhere)) != sorted(c.id for c in CLAIMS)
    with pytest.raises(KeyError, match="placed in no section"):
        verdicts.place_of("no-such-claim")


def test_every_place_is_a_label_of_a_page_that_shows_its_margin_notes():
    """Each place is a MyST label of the book, and the page holding the label calls
    margin_notes(place): a claim cannot be placed where no page shows it."""
    pages = {p: p.read_text(encoding="utf-8") for p in BOOK.glob("*.md")}
    for place in verdicts.PLACES:
        holders = [p for p, text in pages.items() if re.search(rf"^\({re.escape(place)}\)=$", text, re.M)]
        assert len(holders) == 1, (place, holders)
        assert re.search(rf"margin_notes\([\"']{re.escape(place)}[\"']\)", pages[holders[0]]), (place, holders[0])


MARGIN = re.compile(r"```\{margin\}\n(.*?)\n```", re.S)


def test_a_margin_note_quotes_the_claim_links_its_verdict_term_and_its_register_row(monkeypatch):
    """One ``margin`` directive per claim of the place, in order, each with the draft's words, the
    verdict as a glossary ``{term}`` and a ``{ref}`` to the claim's row; the measurement stays in §6."""
    claims = [c for c in CLAIMS if c.id in ("h3-scale", "truncation-until-1e-6")]
    monkeypatch.setattr(verdicts, "_results", lambda ids=None: {c.id: (c, {"x": 1}, FAILS) for c in claims})
    monkeypatch.setitem(verdicts.PLACES, "s3-ucurve", tuple(c.id for c in claims))
    notes = MARGIN.findall(verdicts.margin_notes("s3-ucurve"))
    assert len(notes) == 2
    for claim, note in zip(claims, notes):
        assert f"“{claim.quote}”" in note and claim.where in note
        assert re.findall(r"\{term\}`([^`]+)`", note) == [verdicts.WORDS[FAILS]]
        assert re.findall(r"\{ref\}`[^`<]*<([^>]+)>`", note) == [f"claim-{claim.id}"]
    monkeypatch.setattr(verdicts, "_results", lambda ids=None: {c.id: (c, {}, HOLDS) for c in claims})
    assert re.findall(r"\{term\}`([^`]+)`", verdicts.margin_notes("s3-ucurve")) == [verdicts.WORDS[HOLDS]] * 2


def test_the_register_gives_each_claim_a_target_its_measurement_its_rule_and_a_link_back():
    """Each row: the target, the verdict term, the claim's own numbers (its sentence), and the link to
    its place; read from one evaluation of the register (the real one: the build's measurement)."""
    from chapter.claim_words import measured_text, rule_text
    results = verdicts._results()
    md = verdicts.register()
    rows = md.split("(claim-")[1:]
    assert [r.split(")=", 1)[0] for r in rows] == [c.id for c in CLAIMS]
    for c, row in zip(CLAIMS, rows):
        _, measured, verdict = results[c.id]
        assert f"{{term}}`{verdicts.WORDS[verdict]}`" in row
        assert measured_text(c.id, measured) in row and rule_text(c.criterion) in row
        assert f"{{ref}}`{verdicts.place_of(c.id)}`" in row
    assert md.count("{ref}`cell3`") == len(verdicts.PLACES["cell3"])


def test_an_unknown_place_is_refused():
    with pytest.raises(KeyError, match="place must be one of"):
        verdicts.margin_notes("cell9")


def test_outside_a_book_build_only_the_places_claims_are_measured(monkeypatch):
    """A downloaded notebook measures the two claims of its section, not the register (wrong variant: all)."""
    measured = []
    monkeypatch.setattr("lab.claims.Claim.measure", lambda self: measured.append(self.id) or ({}, self.registered))
    monkeypatch.delenv("SYMRENDER_BOOK_BUILD", raising=False)
    assert len(MARGIN.findall(verdicts.margin_notes("s3-boundary"))) == len(verdicts.PLACES["s3-boundary"])
    assert sorted(measured) == sorted(verdicts.PLACES["s3-boundary"])


def glossary_terms(text):
    """The terms of the book's glossary (each term line of its ``{glossary}`` block, as Sphinx reads it:
    a whole line, commas included), lower case: what a ``{term}`` role can link to."""
    block = re.search(r"```\{glossary\}\n(.*?)\n```", text, re.S).group(1)
    return {line.strip().lower() for line in block.splitlines() if line and not line[0].isspace()}


def test_the_glossary_defines_every_verdict_word():
    """Each verdict a claim or a theorem can be given, as the pages word it, is a glossary term
    (`verdicts.WORDS`, the checker's statuses); a glossary without one is caught (wrong variant)."""
    from chapter.theorems import BADGES
    text = (BOOK / "glossary.md").read_text(encoding="utf-8")
    words = {w.lower() for w in verdicts.WORDS.values()} | set(BADGES)
    assert words == {"holds", "holds with a correction", "does not hold", "proved", "verified", "refuted"}
    assert words <= glossary_terms(text)
    assert not words <= glossary_terms(text.replace("\nrefuted\n", "\nrebutted\n"))
    assert not words <= glossary_terms(text.replace("\nproved\n", "\nproved, shown\n"))   # one term, not two
