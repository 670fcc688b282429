"""book/chapter/verdicts.py: every claim of the draft is shown once, where the book discusses it,
and the register's row and the place link to each other."""

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


def test_every_place_is_a_label_of_a_page_that_shows_its_verdicts():
    """Each place is a MyST label of the book, and the page holding the label calls
    verdicts(place): a claim cannot be placed where no page shows it."""
    pages = {p: p.read_text(encoding="utf-8") for p in BOOK.glob("*.md")}
    for place in verdicts.PLACES:
        holders = [p for p, text in pages.items() if re.search(rf"^\({re.escape(place)}\)=$", text, re.M)]
        assert len(holders) == 1, (place, holders)
        assert re.search(rf"verdicts\([\"']{re.escape(place)}[\"']\)", pages[holders[0]]), (place, holders[0])


def test_a_verdict_sentence_names_the_claim_the_verdict_and_links_its_register_row(monkeypatch):
    claim = next(c for c in CLAIMS if c.id == "h3-scale")
    monkeypatch.setattr(verdicts, "_results", lambda ids=None: {"h3-scale": (claim, "measured text", FAILS)})
    monkeypatch.setitem(verdicts.PLACES, "s3-ucurve", ("h3-scale",))
    md = verdicts.verdicts("s3-ucurve")
    assert md.startswith(":::{container} verdicts") and f"“{claim.quote}”" in md
    assert "**Does not hold:** measured text." in md and "{ref}`Register <claim-h3-scale>`" in md
    monkeypatch.setattr(verdicts, "_results", lambda ids=None: {"h3-scale": (claim, "measured text", HOLDS)})
    assert "**Holds:**" in verdicts.verdicts("s3-ucurve")


def test_the_register_gives_each_claim_a_target_and_a_link_back(monkeypatch):
    monkeypatch.setattr(verdicts, "_results", lambda ids=None: {c.id: (c, f"m-{c.id}", c.registered) for c in CLAIMS})
    md = verdicts.register()
    for c in CLAIMS:
        assert f"(claim-{c.id})=\n" in md
    assert md.count("Measured in {ref}`cell3`") == len(verdicts.PLACES["cell3"])


def test_an_unknown_place_is_refused():
    with pytest.raises(KeyError, match="place must be one of"):
        verdicts.verdicts("cell9")


def test_outside_a_book_build_only_the_places_claims_are_measured(monkeypatch):
    """A downloaded notebook measures the two claims of its section, not the register (wrong variant: all)."""
    measured = []
    monkeypatch.setattr("lab.claims.Claim.measure", lambda self: measured.append(self.id) or ("m", self.registered))
    monkeypatch.delenv("SYMRENDER_BOOK_BUILD", raising=False)
    assert "**Holds" in verdicts.verdicts("s3-boundary")
    assert sorted(measured) == sorted(verdicts.PLACES["s3-boundary"])


def glossary_terms(text):
    """The terms of the book's glossary (each term line of its ``{glossary}`` block, split at commas), lower case."""
    block = re.search(r"```\{glossary\}\n(.*?)\n```", text, re.S).group(1)
    return {t.strip().lower() for line in block.splitlines() if line and not line[0].isspace()
            for t in line.split(",")}


def test_the_glossary_defines_every_verdict_word():
    """Each verdict a claim or a theorem can be given, as the pages word it, is a glossary term
    (`verdicts.WORDS`, the checker's statuses); a glossary without one is caught (wrong variant)."""
    from chapter.theorems import BADGES
    text = (BOOK / "glossary.md").read_text(encoding="utf-8")
    words = {w.lower() for w in verdicts.WORDS.values()} | set(BADGES)
    assert words == {"holds", "holds with a correction", "does not hold", "proved", "verified", "refuted"}
    assert words <= glossary_terms(text)
    assert not words <= glossary_terms(text.replace("\nrefuted\n", "\nrebutted\n"))
