"""The seed-claims register: every computed verdict equals the registered one.

If a change to the code moves a measurement across its verdict, this fails
until the register (proofs/claims.py) is edited with it.
"""

import pytest

from proofs.claims import CLAIMS, CORRECTED, FAILS, HOLDS, Claim, evaluate

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


def test_register_records_false_claims_too():
    verdicts = [c.registered for c in CLAIMS]
    assert verdicts.count(FAILS) >= 5 and verdicts.count(HOLDS) >= 5
