"""`pytest verify` prints the theorem ledger (README), also when xdist runs the theorems in a worker
processes, as `make test` does: each verdict travels in its test report to the process that prints."""

import os
import re
import subprocess
import sys
from pathlib import Path

import hypothesis  # noqa: F401  (imported at collection: this module's run keeps hypothesis's plugin)
import pytest

from proofs.registry import THEOREMS

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("workers", [["-n", "1"], ["-p", "no:xdist"]], ids=["xdist", "one-process"])
def test_the_ledger_is_printed_with_each_verdict(workers):
    run = subprocess.run([sys.executable, "-m", "pytest", "verify/test_theorems.py", "-k", "frame-orientation",
                          "-p", "no:cacheprovider", *workers], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    ledger = run.stdout.split(" theorem ledger ", 1)
    assert len(ledger) == 2, run.stdout[-2000:]
    rows = [line for line in ledger[1].splitlines() if re.match(r"^[a-z]", line)]
    assert len(rows) == 1, rows
    theorem_id, status, evidence = rows[0].split(maxsplit=2)
    steps = len(THEOREMS["frame-orientation"].steps)
    assert (theorem_id, status) == ("frame-orientation", "proved"), rows
    assert re.match(rf"{steps} steps\b", evidence), rows      # the verdict's evidence, which counts the steps


def test_the_ledger_is_in_the_chapters_order_whatever_order_the_verdicts_arrive_in(monkeypatch):
    """The controller sorts the rows by the place each report carries (it imports no theorem to sort
    them): verdicts arriving last to first are printed first to last.  The wrong variant, rows in the
    order of arrival, prints them reversed."""
    from types import SimpleNamespace

    from verify import conftest
    monkeypatch.setattr(conftest, "LEDGER", {})
    ids = list(THEOREMS)
    for place, theorem_id in reversed(list(enumerate(ids))):
        conftest.pytest_runtest_logreport(SimpleNamespace(
            when="call", user_properties=[("ledger", (place, theorem_id, "proved", "evidence"))]))
    lines = []
    conftest.pytest_terminal_summary(SimpleNamespace(section=lambda title: None, write_line=lines.append))
    assert [line.split()[0] for line in lines] == ids, lines


def test_a_run_that_imported_no_hypothesis_drops_its_plugin(monkeypatch, pytestconfig):
    """verify/conftest.py unregisters hypothesis's pytest plugin, by the name it is registered under,
    when the run's collection imported no hypothesis, and leaves it otherwise.  The wrong variants: the
    hook gone, a wrong name (nothing found to drop), the condition turned round."""
    from types import SimpleNamespace

    from verify import conftest
    assert pytestconfig.pluginmanager.get_plugin(conftest.HYPOTHESIS_PLUGIN) is not None
    dropped = []
    session = SimpleNamespace(config=SimpleNamespace(pluginmanager=SimpleNamespace(
        unregister=lambda name: dropped.append(name))))
    conftest.pytest_collection_finish(session)
    assert dropped == []
    monkeypatch.delitem(sys.modules, "hypothesis")
    conftest.pytest_collection_finish(session)
    assert dropped == [conftest.HYPOTHESIS_PLUGIN]


def test_verify_fails_a_theorem_that_holds_but_not_with_its_pin(tmp_path):
    """`pytest verify` applies the pins: frame-orientation, proved, pinned ("verified", 1e-25) by a plugin
    loaded into the run, fails naming the difference (a verify that only asked whether the verdict holds
    would pass it)."""
    (tmp_path / "planted_pin.py").write_text(
        "def pytest_configure(config):\n    from proofs import registry\n"
        "    registry.PINNED['frame-orientation'] = ('verified', 1e-25)\n", encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    run = subprocess.run([sys.executable, "-m", "pytest", "verify/test_theorems.py", "-k", "frame-orientation",
                          "-p", "no:cacheprovider", "-p", "no:xdist", "-p", "planted_pin"], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 1, run.stdout[-2000:] + run.stderr[-2000:]
    assert "frame-orientation is proved, pinned verified" in run.stdout, run.stdout[-2000:]
