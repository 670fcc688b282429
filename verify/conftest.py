"""Shared measurements of `pytest verify`, each computed once per session (and only
when a test asks for it), and the theorem ledger printed at the end of the run.

The ledger is collected from the test reports: test_theorem_holds records each verdict as
its report's user property ``ledger``, which pytest-xdist carries from the worker that ran
the test to the controller, where `pytest_runtest_logreport` files it and
`pytest_terminal_summary` prints it, in the chapter's order (the theorem's place, which the report
carries: the controller does not import the theorems to sort them); without xdist both run in the one
process.  A run of the checker alone leaves out hypothesis's pytest plugin (`pytest_collection_finish`)."""

import sys

import pytest

#: The name hypothesis's pytest plugin registers under (its ``pytest11`` entry point).
HYPOTHESIS_PLUGIN = "hypothesispytest"

#: {theorem id: (place in the chapter, status, evidence)} of the verdicts reported to this process.
LEDGER = {}


def pytest_collection_finish(session):
    """Drops hypothesis's pytest plugin from a run whose tests never imported hypothesis (`pytest verify`'s
    do not): the plugin would import all of it at the terminal summary to report on no test, 1.4-1.6 s
    of a new clone's `pytest verify` (``-X importtime``).  A run that collects a hypothesis test keeps it."""
    if "hypothesis" not in sys.modules:
        session.config.pluginmanager.unregister(name=HYPOTHESIS_PLUGIN)


def pytest_runtest_logreport(report):
    if report.when == "call":
        for name, value in report.user_properties:
            if name == "ledger":
                place, theorem_id, status, evidence = value
                LEDGER[theorem_id] = (place, status, evidence)


class _Claims(dict):
    """{claim id: (measured, verdict)}, each claim measured when it is first read (`lab.claims.Claim.measure`):
    a worker measures only the claims of its tests."""

    def __missing__(self, claim_id):
        from lab.claims import CLAIMS
        self[claim_id] = result = next(c for c in CLAIMS if c.id == claim_id).measure()
        return result


@pytest.fixture(scope="session")
def claim_results():
    """{claim id: (measured, verdict)} of the register, each measured when a test reads it (`_Claims`)."""
    return _Claims()


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
    for theorem_id, (_, status, evidence) in sorted(LEDGER.items(), key=lambda item: item[1][0]):
        tr.write_line(f"{theorem_id:<{width}}  {status:<8}  {evidence}")
