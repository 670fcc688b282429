"""Shared measurements of `pytest verify`, each computed once per session (and only
when a test asks for it), and the theorem ledger printed at the end of the run."""

import pytest

LEDGER = {}


@pytest.fixture(scope="session")
def claim_results():
    """{claim id: (measured, verdict)} of the whole register (`lab.claims.evaluate`)."""
    from lab.claims import evaluate
    return {c.id: (measured, verdict) for c, measured, verdict in evaluate()}


@pytest.fixture(scope="session")
def errata():
    """{erratum id: measurement} of the draft's errata (`lab.seed_errata.measure_all`)."""
    from lab.seed_errata import measure_all
    return measure_all()


@pytest.fixture(scope="session")
def curve():
    """The default U-curve (`renderer.ucurve.measure`: sine, (0.31, 0.47), h_u, k = (8, 4))."""
    from renderer.ucurve import measure
    return measure()


def pytest_terminal_summary(terminalreporter):
    if not LEDGER:
        return
    tr = terminalreporter
    tr.section("theorem ledger")
    width = max(len(k) for k in LEDGER)
    for theorem_id, verdict in LEDGER.items():
        tr.write_line(f"{theorem_id:<{width}}  {verdict.status:<8}  {verdict.evidence}")
