"""The mutation audit's mutants (benchmarks/mutation_audit.py) apply to the code as it is: each
one's old text occurs once in its file.  An edit that moves the code a mutant plants its bug in
fails here, in `make test`, not at the next audit, which refuses to start on a stale mutant."""

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _audit():
    spec = importlib.util.spec_from_file_location("mutation_audit", ROOT / "benchmarks" / "mutation_audit.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_mutant_of_the_audit_applies_once():
    audit = _audit()
    # The audit leaves this test out of its runs: in a mutated copy it fails on the mutant's own edit.
    assert ROOT / audit.MUTATION_LIST_TEST == Path(__file__).resolve()
    audit.check(audit.MUTANTS + audit.SECOND)
    name, path, old, new, bug = audit.MUTANTS[0]
    with pytest.raises(SystemExit, match=f"mutant stale: its old text occurs 0 times in {path}"):
        audit.check([("stale", path, old + " and what follows no more", new, bug)])
    with pytest.raises(SystemExit, match=r"mutant twice: its old text occurs [1-9]\d+ times"):
        audit.check([("twice", path, "\n", "x", bug)])                  # a text of every line
    with pytest.raises(SystemExit, match="mutant same: its new text is its old text"):
        audit.check([("same", path, old, old, bug)])
