"""Collects each theorem's verdict and prints the ledger after `pytest verify`."""

LEDGER = {}


def pytest_terminal_summary(terminalreporter):
    if not LEDGER:
        return
    tr = terminalreporter
    tr.section("theorem ledger")
    width = max(len(k) for k in LEDGER)
    for theorem_id, verdict in LEDGER.items():
        tr.write_line(f"{theorem_id:<{width}}  {verdict.status:<8}  {verdict.evidence}")
