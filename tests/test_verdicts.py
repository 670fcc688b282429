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


def placement_faults(places):
    """What is wrong with a `verdicts.PLACES`: claims placed twice, ids that are no claim, and claims
    placed nowhere (the front page promises a margin note beside each)."""
    placed, ids = _placed(places), [c.id for c in CLAIMS]
    return (sorted({i for i in placed if placed.count(i) > 1}) + sorted(set(placed) - set(ids))
            + [f"{i} nowhere" for i in ids if i not in placed])


def test_every_claim_is_placed_once():
    assert placement_faults(verdicts.PLACES) == []


def test_a_claim_placed_twice_or_nowhere_or_no_claim_placed_is_caught():
    assert placement_faults({**verdicts.PLACES, "s9": ("h3-scale",)}) == ["h3-scale"]
    assert placement_faults({**verdicts.PLACES, "s9": ("no-such-claim",)}) == ["no-such-claim"]
    assert placement_faults({**verdicts.PLACES, "cell6/truncation": ()}) == ["cell6-truncation nowhere"]
    assert verdicts.place_of("h3-scale") == "s3-ucurve"
    for unplaced in ("no-such-claim", "cell6-truncation"):
        with pytest.MonkeyPatch.context() as m:
            m.setitem(verdicts.PLACES, "cell6/truncation", ())
            with pytest.raises(KeyError, match="claim_id must be"):
                verdicts.place_of(unplaced)


CALL = re.compile(r"margin_notes\([\"']([^\"']+)[\"']\)")


def place_faults(pages):
    """What is wrong with the pages' margin-note calls against `verdicts.PLACES`: {place: what}.
    Each place is called exactly once over the pages (none: "unused", more: "N calls"), on the page
    that holds its section's label ("section label on no page" / "not on the page of <label>"), and
    no page calls a place `PLACES` lacks ("not in PLACES")."""
    calls = [(p, m.group(1)) for p, text in pages.items() for m in CALL.finditer(text)]
    faults = {place: "not in PLACES" for _, place in calls if place not in verdicts.PLACES}
    for place in verdicts.PLACES:
        section = verdicts.section_of(place)
        holders = [p for p, text in pages.items() if re.search(rf"^\({re.escape(section)}\)=$", text, re.M)]
        where = [p for p, called in calls if called == place]
        if len(holders) != 1:
            faults[place] = "section label on no page" if not holders else "section label on several pages"
        elif len(where) != 1:
            faults[place] = "unused" if not where else f"{len(where)} calls"
        elif where != holders:
            faults[place] = f"not on the page of {section}"
    return faults


def test_every_place_is_used_exactly_once_on_the_page_of_its_section():
    """Each place is a section label (or a paragraph in one: ``cell3/flips``) of a page that calls
    margin_notes(place) once; no page calls a place that is not in PLACES."""
    pages = {p.name: p.read_text(encoding="utf-8") for p in BOOK.glob("*.md")}
    assert place_faults(pages) == {}


def test_a_missing_duplicated_or_unknown_place_is_caught():
    pages = {p.name: p.read_text(encoding="utf-8") for p in BOOK.glob("*.md")}
    s5 = pages["s5_lab.md"]
    call = 'markdown(margin_notes("cell3/flips"))'
    assert place_faults({**pages, "s5_lab.md": s5.replace(call, "")}) == {"cell3/flips": "unused"}
    assert place_faults({**pages, "s5_lab.md": s5 + call}) == {"cell3/flips": "2 calls"}
    assert place_faults({**pages, "s5_lab.md": s5 + 'margin_notes("cell9")'}) == {"cell9": "not in PLACES"}
    moved = {**pages, "s5_lab.md": s5.replace(call, ""), "s7_pitfalls.md": pages["s7_pitfalls.md"] + call}
    assert place_faults(moved) == {"cell3/flips": "not on the page of cell3"}


CELL = re.compile(r"\bCell (\d)")


def numbering_faults(places, claims=CLAIMS):
    """Margin notes that break the numbering the index states (the draft's Cell N is noted in the lab's
    Cell N; outside the lab only the draft's Cell 2, on the tangent frame, in §3): [(claim id, place)]."""
    where = {c.id: c.where for c in claims}
    faults = []
    for place, ids in places.items():
        for i in ids:
            cells = CELL.findall(where[i])
            lab = re.fullmatch(r"cell(\d)", verdicts.section_of(place))
            if cells and (cells != [lab.group(1)] if lab else (cells, place.split("-")[0]) != (["2"], "s3")):
                faults.append((i, place))
    return faults


def test_a_note_on_a_draft_cell_stands_in_the_labs_cell_of_that_number_as_the_index_says():
    index = " ".join((BOOK / "index.md").read_text(encoding="utf-8").split())
    lab_cells = re.findall(r"^\(cell(\d)\)=$", (BOOK / "s5_lab.md").read_text(encoding="utf-8"), re.M)
    assert lab_cells == [str(n) for n in range(1, 8)], lab_cells         # the sentence's "Cells 1–7"
    assert "Cells 1–7 are numbered as this book's sections and the lab's cells" in index
    assert "the draft's Cell 2 on the tangent frame is noted in {ref}`§3 <s3>`" in index
    assert numbering_faults(verdicts.PLACES) == []
    moved = {**verdicts.PLACES, "cell2": verdicts.PLACES["cell2"] + ("census-flips",), "cell3/flips": ()}
    assert numbering_faults(moved) == [("census-flips", "cell2")]
    assert numbering_faults({**verdicts.PLACES, "s7": ("cell1-ripples",), "cell1": ()}) == [("cell1-ripples", "s7")]
    assert numbering_faults({**verdicts.PLACES, "s4-x": ("frame-aligned",), "s3-frame": ()}) == [("frame-aligned", "s4-x")]


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
        assert f"(noted in {{ref}}`{verdicts.section_of(verdicts.place_of(c.id))}`)" in row
    in_cell3 = [i for p, ids in verdicts.PLACES.items() if verdicts.section_of(p) == "cell3" for i in ids]
    assert md.count("{ref}`cell3`") == len(in_cell3) == 4


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
