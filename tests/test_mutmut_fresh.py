"""tests/mutmut_fresh.py, the plugin mutmut's runs load: after `forget`, a theorem, a verdict and a
measurement are computed again, not served from memory (else mutmut credits only the first test that
read them, and runs a mutant of their code against that test alone)."""

from lab import store
from proofs import core
from proofs.registry import THEOREMS

from . import mutmut_fresh


def test_the_mutated_modules_are_pyprojects_source_paths_as_modules():
    assert {"lab", "proofs", "renderer.ucurve", "renderer.pointwise"} <= set(mutmut_fresh.MUTATED)
    assert all("/" not in m and not m.endswith(".py") for m in mutmut_fresh.MUTATED)


def test_after_forget_a_theorem_its_verdicts_and_a_measurement_are_computed_again():
    theorem = THEOREMS["chart"]
    theorem.check()
    calls = []
    store.measured("mutmut-fresh-probe", lambda: calls.append(1) or 1)
    assert THEOREMS["chart"] is theorem and core._DECIDED                      # memoised: the same object
    store.measured("mutmut-fresh-probe", lambda: calls.append(1) or 1)
    assert calls == [1]
    mutmut_fresh.forget()
    assert THEOREMS["chart"] is not theorem and not core._DECIDED
    store.measured("mutmut-fresh-probe", lambda: calls.append(1) or 1)
    assert calls == [1, 1]
