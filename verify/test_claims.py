"""The seed-claims register: every computed verdict equals the registered one.

If a change to the code moves a measurement across its verdict, this fails
until the register (proofs/claims.py) is edited with it.
"""

import pytest

from proofs.claims import CLAIMS, CORRECTED, FAILS, HOLDS, Claim, ClaimChanged, checked, evaluate

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
    wrong = Claim("x", "§0", "q", "m", HOLDS, lambda: ("measured 2", FAILS))
    _, verdict = wrong.measure()
    assert verdict != wrong.registered


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
    from proofs.claims import CRITERIA
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
