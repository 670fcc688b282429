"""The draft's claims: every verdict computed from its measurement equals the
verdict the register (lab/claims.py) records, and rests on a finite measurement.
If a change to the code moves a measurement across its verdict, this fails
until the register is edited with it.  The decision rules themselves are tested
in tests/test_claim_rules.py.
"""

import math

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


#: The draft's height fields as its own code computes them (seed §2, ``height1``), transcribed by hand in
#: scalar math: the spec the renderer's built-in fields (`renderer.formulas.FIELDS`) are held to.  The
#: proofs are about whatever expression a field's record holds; this says the records are the draft's.
DRAFT_HEIGHT = {
    "sine": lambda u, v, ku, kv: math.sin(math.pi * ku * u) * math.sin(math.pi * kv * v),
    "ridges": lambda u, v, ku, kv: abs(math.sin(math.pi * ku * u) * math.sin(math.pi * kv * v)),
    "rings": lambda u, v, ku, kv: math.sin(2 * math.pi * kv * v),
}


def _off_the_draft(name, draft, points=200):
    """Largest |h - the draft's h| of the renderer's compiled field ``name`` at seeded random chart points
    and frequencies."""
    import numpy as np

    from renderer import pointwise
    rng = np.random.default_rng(20261129)
    u, v = rng.random(points), rng.random(points)
    ku, kv = rng.uniform(0.5, 12.0, points), rng.uniform(0.5, 12.0, points)
    have = pointwise.height(name, u, v, ku, kv)
    return max(abs(h - draft(*p)) for h, p in zip(have, zip(u, v, ku, kv)))


@pytest.mark.parametrize("name", DRAFT_HEIGHT)
def test_the_builtin_fields_are_the_drafts(name):
    """Each of the draft's fields as the renderer compiles it equals the draft's own formula to a few ulps
    (|h| <= 1), at random points and frequencies."""
    assert _off_the_draft(name, DRAFT_HEIGHT[name]) < 1e-13


def test_the_comparison_with_the_draft_tells_a_wrong_field_apart():
    """Rings at half its frequency, and sine with its two frequencies swapped: each far from the renderer's."""
    half = lambda u, v, ku, kv: math.sin(math.pi * kv * v)                      # noqa: E731
    swapped = lambda u, v, ku, kv: DRAFT_HEIGHT["sine"](u, v, kv, ku)            # noqa: E731
    assert _off_the_draft("rings", half) > 0.1 and _off_the_draft("sine", swapped) > 0.1
