"""The seed-claims register: every computed verdict equals the registered one.

If a change to the code moves a measurement across its verdict, this fails
until the register (proofs/claims.py) is edited with it.
"""

import pytest

from proofs.claims import CLAIMS, CORRECTED, CRITERIA, FAILS, HOLDS, Bound, Claim, ClaimChanged, checked, evaluate, rule

RESULTS = {c.id: (measured, verdict) for c, measured, verdict in evaluate()}


def test_register_has_at_least_twenty_claims_with_unique_ids():
    assert len(CLAIMS) >= 20
    assert len({c.id for c in CLAIMS}) == len(CLAIMS)


@pytest.mark.parametrize("claim", CLAIMS, ids=[c.id for c in CLAIMS])
def test_computed_verdict_matches_register(claim):
    measured, verdict = RESULTS[claim.id]
    assert verdict in (HOLDS, FAILS, CORRECTED)
    assert verdict == claim.registered, f"{claim.id}: measured {measured} -> {verdict}"


def test_register_mismatch_is_detected():
    wrong = Claim("x", "§0", "q", "m", HOLDS, lambda: ("measured 2", {"x": 2}), rule(HOLDS, Bound("x", hi=1)))
    _, verdict = wrong.measure()
    assert verdict != wrong.registered


def test_criteria_decide_at_their_edges_as_written():
    """A bound is inclusive unless strict; cases are tried in order; the table's text is the data's."""
    r = rule(HOLDS, Bound("x", 1, 2), CORRECTED, (Bound("x", lo=0, strict=True), Bound("y", hi=0)))
    assert [r.decide({"x": x, "y": 0}) for x in (1, 2, 0.5, 0, 3)] == [HOLDS, HOLDS, CORRECTED, FAILS, CORRECTED]
    assert r.decide({"x": 0.5, "y": 1}) == FAILS
    assert str(r) == "holds if 1 ≤ x ≤ 2; holds with a correction if x > 0 and y ≤ 0; otherwise does not hold"
    assert not Bound("x", 1, 2, strict=True).holds({"x": 2}) and Bound("x", 1, 1).holds({"x": 1})
    assert str(Bound("x", 1e-10, 1e-8, strict=True)) == "1e-10 < x < 1e-08"


def _inside(bound):
    if bound.lo is not None and bound.hi is not None:
        return (bound.lo + bound.hi) / 2
    return bound.lo + abs(bound.lo) + 1 if bound.lo is not None else bound.hi - abs(bound.hi) - 1


@pytest.mark.parametrize("claim", CLAIMS, ids=[c.id for c in CLAIMS])
def test_each_criterion_is_the_table_text_and_its_first_case_decides(claim):
    """Numbers inside the first case's bounds get that case's verdict; the text the book's
    table shows is the criterion's own."""
    verdict, bounds = claim.criterion.cases[0]
    assert claim.criterion.decide({b.quantity: _inside(b) for b in bounds}) == verdict
    assert CRITERIA[claim.id] == str(claim.criterion)


def test_the_books_table_refuses_a_flipped_verdict():
    """The book's register goes through `checked`: one flipped verdict fails the build."""
    results = [(c, RESULTS[c.id][0], RESULTS[c.id][1]) for c in CLAIMS]
    assert checked(results) == results
    flipped = list(results)
    c, m, v = flipped[3]
    flipped[3] = (c, m, HOLDS if v != HOLDS else FAILS)
    with pytest.raises(ClaimChanged, match=f"{c.id}: registered"):
        checked(flipped)


def test_every_claim_states_its_decision_rule():
    assert set(CRITERIA) == {c.id for c in CLAIMS} and all(CRITERIA.values())


def test_register_records_false_claims_too():
    verdicts = [c.registered for c in CLAIMS]
    assert verdicts.count(FAILS) >= 5 and verdicts.count(HOLDS) >= 5


def test_the_ledger_the_claims_read_sums_over_sphere_a_only():
    """`renderer.compare` (the census, the crease ratio) against numpy over the pixels
    both frames put on sphere A; a sum over every pixel would differ."""
    import numpy as np

    from renderer import Scene, compare, render
    num, sym = render(Scene(), 96, 96, gradient="central"), render(Scene(), 96, 96)
    led = compare(num, sym)
    on_a = (num.chamber == 1) & (sym.chamber == 1)
    d = np.abs(num.image - sym.image)
    assert led.max_abs == d[on_a].max() and led.rms == pytest.approx(np.sqrt(np.mean(d[on_a] ** 2)), rel=1e-12)
    assert led.rms != pytest.approx(np.sqrt(np.mean(d ** 2)), rel=1e-3)
