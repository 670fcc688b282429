"""The draft's claims: every verdict computed from its measurement equals the
verdict the register (lab/claims.py) records, and rests on a finite measurement.
If a change to the code moves a measurement across its verdict, this fails
until the register is edited with it.  The decision rules themselves are tested
in tests/test_claim_rules.py.
"""

import pytest

from lab.claims import CENSUS_SIZE, CLAIMS, CORRECTED, FAILS, HOLDS


@pytest.mark.parametrize("claim", CLAIMS, ids=[c.id for c in CLAIMS])
def test_computed_verdict_matches_register(claim, claim_results):
    measured, verdict = claim_results[claim.id]
    assert verdict in (HOLDS, FAILS, CORRECTED)
    assert verdict == claim.registered, f"{claim.id}: measured {measured} -> {verdict}"


def test_cell3_runs_tells_the_drafts_code_from_this_renderers_frame(claim_results):
    """The draft's code's sphere-A count and this renderer's, on the same scene and size, each named
    as whose it is: the draft's map has no sphere-A pixel, this renderer's frame has them all."""
    import numpy as np

    from renderer import DRAFT_SCENE, gbuffer
    from renderer.render import SPHERE_A

    measured, _ = claim_results["cell3-runs"]
    code, pixels, ours = measured["code_pixels_a"], measured["pixels"], measured["pixels_a"]
    chamber = gbuffer(DRAFT_SCENE, CENSUS_SIZE, CENSUS_SIZE).chamber
    assert (code, pixels, ours) == (0, chamber.size, int(np.count_nonzero(chamber == SPHERE_A)))
