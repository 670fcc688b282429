"""Shared measurements of `pytest verify`, each computed once per run (and only when a
test asks for it: `lab.store`'s measurements once across the xdist workers, the others once
per worker), and the theorem ledger printed at the end of the run.

The ledger is collected from the test reports: test_theorem_holds records each verdict as
its report's user property ``ledger``, which pytest-xdist carries from the worker that ran
the test to the controller, where `pytest_runtest_logreport` files it and
`pytest_terminal_summary` prints it; without xdist both run in the one process."""

import os
import shutil
import tempfile

import pytest

#: {theorem id: (status, evidence)} of the verdicts reported to this process.
LEDGER = {}


#: The store this run made (`pytest_configure`), removed at its end.
STORE = pytest.StashKey[str]()
#: Tests that read one measurement, computed once per process: xdist sends each group to one worker.
SHARED = {"render-flips": ("test_theorem_holds[no-boundary]", "test_computed_verdict_matches_register[flips-zero]")}


def pytest_configure(config):
    """The run's measurements of `lab.store` go to a store of its own (a new temporary directory, unless
    ``SYMRENDER_STORE`` names one), which its xdist workers share: a measurement two tests read (a claim's
    and an accuracy test's) is computed once, by the first worker to ask.  Under xdist, `SHARED`'s groups
    each go to one worker (``--dist loadgroup`` for ``load``, the default of ``-n``), and a worker renders
    on one thread (``NUMBA_NUM_THREADS=1`` unless set, before numba is imported): the workers already fill
    the cores, and numba's threads on top of them oversubscribe them, as the book's page kernels would
    (book/_ext/execute_pages.py)."""
    from lab.store import ENV
    if not os.environ.get(ENV):
        os.environ[ENV] = config.stash[STORE] = tempfile.mkdtemp(prefix="verify-store-")
    if getattr(config.option, "dist", "no") == "load":
        config.option.dist = "loadgroup"
    if os.environ.get("PYTEST_XDIST_WORKER"):
        os.environ.setdefault("NUMBA_NUM_THREADS", "1")


def pytest_unconfigure(config):
    if STORE in config.stash:
        shutil.rmtree(config.stash[STORE], ignore_errors=True)


@pytest.hookimpl(tryfirst=True)          # before xdist's, which reads the groups
def pytest_collection_modifyitems(config, items):
    if not config.pluginmanager.hasplugin("xdist"):
        return
    for item in items:
        for group, names in SHARED.items():
            if item.name in names:
                item.add_marker(pytest.mark.xdist_group(group))


def pytest_runtest_logreport(report):
    if report.when == "call":
        for name, value in report.user_properties:
            if name == "ledger":
                theorem_id, status, evidence = value
                LEDGER[theorem_id] = (status, evidence)


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
    from proofs.registry import THEOREMS
    tr.section("theorem ledger")
    width = max(len(k) for k in LEDGER)
    for theorem_id in sorted(LEDGER, key=list(THEOREMS).index):      # in the chapter's order
        status, evidence = LEDGER[theorem_id]
        tr.write_line(f"{theorem_id:<{width}}  {status:<8}  {evidence}")
