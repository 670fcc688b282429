"""The book's words for the draft's claims (book/chapter/claim_words.py): each claim's sentence is
formatted from its own values, and each rule is shown with its cases in order.  Checked by the
numbers and the structure they show, not by their wording."""

import dataclasses
import math
import re

import pytest

from chapter.claim_words import SENTENCES, WORDS, bound_text, measured_text, rule_text
from chapter.labels import frame_label
from lab.claims import CLAIMS, CORRECTED, FAILS, HOLDS, Bound, Criterion


@pytest.mark.parametrize("bound, text", [
    (Bound("ratio", 1, 2), "1 ≤ ratio ≤ 2"), (Bound("ratio", 1, 2, strict=True), "1 < ratio < 2"),
    (Bound("flips", 0, 0), "flips = 0"), (Bound("error", hi=1e-9), "error ≤ 1e-09"),
    (Bound("error", hi=2.5e-7, strict=True), "error < 2.5e-07"), (Bound("count", lo=15875), "count ≥ 15,875"),
    (Bound("count", lo=2e6), "count ≥ 2e+06"), (Bound("slope", lo=1.23456), "slope ≥ 1.23"),
    (Bound("slope", lo=0.5, strict=True), "slope > 0.5"), (Bound("count", lo=1e6), "count ≥ 1e+06"),
    (Bound("count", lo=999_999), "count ≥ 999,999"), (Bound("q", lo=99.5), "q ≥ 99.5"),
    (Bound("q", 2000 / 10**0.5, 2000 * 10**0.5), "632 ≤ q ≤ 6,325"),
])
def test_a_bound_is_shown_as_its_inequality(bound, text):
    assert bound_text(bound) == text


def test_a_rule_shows_its_cases_in_order_then_its_default_unless_it_does_not_hold():
    """The register states once that a claim no case of its rule decides does not hold, so a rule
    shows its default only when that is another verdict."""
    a, b, c = Bound("a", hi=1), Bound("b", lo=2), Bound("a", hi=10)
    cases = rule_text(Criterion(((HOLDS, (a, b)), (CORRECTED, (c,))))).split("; ")
    assert len(cases) == 2
    assert cases[0].startswith(WORDS[HOLDS].lower()) and cases[0].endswith(f"{bound_text(a)} and {bound_text(b)}")
    assert cases[1].startswith(WORDS[CORRECTED].lower()) and cases[1].endswith(bound_text(c))
    other = rule_text(Criterion(((FAILS, (a,)),), otherwise=HOLDS)).split("; ")
    assert other == [f"{WORDS[FAILS].lower()} if {bound_text(a)}", f"otherwise {WORDS[HOLDS].lower()}"]


def test_every_claim_has_one_sentence_and_every_sentence_a_claim():
    ids = {c.id for c in CLAIMS}
    assert {k.split("/")[0] for k in SENTENCES} == ids


#: Counts a rule decides on that a sentence shows otherwise, and how.
SHOWN_AS = {"rows computed": "the crash or the row (cell3-runs's two sentences)",
            "sin/cos calls, exact minus central": "the two counts it is the difference of"}


@pytest.fixture(scope="module")
def register():
    from chapter.verdicts import _results
    return _results()


@pytest.mark.parametrize("claim", CLAIMS, ids=[c.id for c in CLAIMS])
def test_each_sentence_shows_its_claims_numbers_and_frame(claim, register):
    """Formatted from the claim's measured values: no field left unfilled (a role's braces are markup), the frame's label where
    the values carry a frame, and each count the rule decides on, as a number in the sentence."""
    _, values, _ = register[claim.id]
    text = measured_text(claim.id, values)
    assert "{" not in re.sub(r"\{[a-z:]+\}`", "`", text).replace("{-", "")     # a MyST role ({term}`...`) is no field
    if "scene" in values:
        assert frame_label(values["scene"], *values["size"]) in text
    shown = {float(n.replace(",", "")) for n in re.findall(r"-?\d[\d,]*(?:\.\d+)?(?:e[-+]?\d+)?", text)}
    for b in {b.quantity for _, bounds in claim.criterion.cases for b in bounds}:
        if isinstance(values[b], int) and b not in SHOWN_AS:
            assert float(values[b]) in shown, (b, values[b], text)


def test_a_sentence_follows_its_values_and_refuses_a_missing_one():
    values = {"(π kᵤ)³": 3375.0, "k_u": 4.0}
    text = measured_text("h3-scale", values)
    assert "3,375" in text and "4" in text
    with pytest.raises(KeyError, match="k_u"):
        measured_text("h3-scale", {"(π kᵤ)³": 1.0})
    with pytest.raises(KeyError, match="claim_id must be one of"):
        measured_text("no-such-claim", values)


def test_the_cell3_sentence_tells_a_crash_from_a_row():
    frame = {"scene": {}, "size": [8, 8]}
    crashed = measured_text("cell3-runs", {"rows computed": 0, "code_pixels_a": 0, "pixels": 64, "pixels_a": 21,
                                           "error": "ValueError", **frame})
    ran = measured_text("cell3-runs", {"rows computed": 1, **frame})
    assert "ValueError" in crashed and "21" in crashed and "ValueError" not in ran and ran != crashed


def test_the_cell5_sentence_shows_the_ratio_to_two_digits_and_the_drafts_powers():
    text = measured_text("cell5-fd-1e-9", {"worst component": 1.63e-5, "expected": 1e-9, "ratio": 16300.0,
                                           "step": 1e-7, "trials": 2000})
    assert "16,000" in text and "1e-9" in text and "1e-7" in text and "2,000" in text


#: A number written in a claim's words: not inside a field (braces), maths ($...$) or parentheses' first
#: place ("max(0, ·)"), and not a section's, cell's or chapter's number, a fraction's numerator ("1/kᵤ") or
#: a frame's side ("256²": its label is checked above).
TYPED = re.compile(r"(?<![\w.(])[-+]?\d[\d,]*(?:\.\d+)?(?:e[-+]?\d+)?(?![\w/])")


def typed_numbers(text):
    text = re.sub(r"\{[^{}]*\}|\$[^$]*\$|\b(?:Cell|Ch\.|§)\s?\d+[a-z]?", " ", text)
    return [float(n.replace(",", "")) for n in TYPED.findall(text)]


def unrun_numbers(claim, values, sentences=SENTENCES):
    """The numbers typed in ``claim``'s measurement and in its book sentences that are none of the
    numbers it was measured with (``values``, nested lists and dicts included): a step, a size or a
    digit count written beside the run rather than read from it."""
    def flat(v):
        if isinstance(v, dict):
            return [x for w in v.values() for x in flat(w)]
        if isinstance(v, (list, tuple)):
            return [x for w in v for x in flat(w)]
        return [float(v)] if isinstance(v, (int, float)) and not isinstance(v, bool) else []
    ran = flat(values)
    texts = [claim.measurement] + [t for k, t in sentences.items() if k.split("/")[0] == claim.id]
    return [(text[:40], n) for text in texts for n in typed_numbers(text)
            if not any(math.isclose(n, x, rel_tol=1e-12, abs_tol=0) for x in ran)]


@pytest.mark.parametrize("claim", CLAIMS, ids=[c.id for c in CLAIMS])
def test_every_number_a_claims_words_type_is_one_it_was_measured_with(claim, register):
    """The register's "measurement" column and the book's sentence name steps, β, trial counts, filter
    sizes and digits: each is a number the claim's run recorded, so that a parameter changed in the code
    cannot leave the words behind."""
    _, values, _ = register[claim.id]
    assert unrun_numbers(claim, values) == []


def test_a_claims_words_naming_a_step_or_a_digit_count_it_did_not_run_are_caught(register):
    by_id = {c.id: c for c in CLAIMS}
    _, values, _ = register["cell6-truncation"]
    drifted = dataclasses.replace(by_id["cell6-truncation"],
                                  measurement=by_id["cell6-truncation"].measurement.replace("0.0001", "0.0002"))
    assert unrun_numbers(drifted, values) == [(drifted.measurement[:40], 0.0002)]
    _, values, _ = register["dn-verified-1e-12"]
    sentences = {"dn-verified-1e-12": SENTENCES["dn-verified-1e-12"].replace("{digits}-digit", "40-digit")}
    assert [n for _, n in unrun_numbers(by_id["dn-verified-1e-12"], values, sentences)] == [40.0]
