"""The draft's claims: every verdict computed from its measurement equals the
verdict the register (lab/claims.py) records, and rests on a finite measurement.
If a change to the code moves a measurement across its verdict, this fails
until the register is edited with it.  The decision rules themselves are tested
in tests/test_claim_rules.py.
"""

import pytest

from lab.claims import CLAIMS, CORRECTED, FAILS, HOLDS


@pytest.mark.parametrize("claim", CLAIMS, ids=[c.id for c in CLAIMS])
def test_computed_verdict_matches_register(claim, claim_results):
    measured, verdict = claim_results[claim.id]
    assert verdict in (HOLDS, FAILS, CORRECTED)
    assert verdict == claim.registered, f"{claim.id}: measured {measured} -> {verdict}"


def test_register_records_false_claims_too():
    verdicts = [c.registered for c in CLAIMS]
    assert verdicts.count(FAILS) >= 5 and verdicts.count(HOLDS) >= 5
