"""The register's decision rules (lab/claims.py: `Bound`, `Criterion`,
`rule`, `Claim.measure`): how a measured number becomes a verdict, and how the
rule is printed in the book's table.

Fast on purpose: benchmarks/mutation_audit.py --mutmut runs this file once per
mutant of lab/claims.py (its measurements are checked by pytest verify).
"""

import pytest

from lab.claims import (CLAIMS, CORRECTED, FAILS, HOLDS, UNMEASURED, Bound, Claim, ClaimChanged, Criterion,
                        Unmeasured, checked, rule)


@pytest.mark.parametrize("bound, x, inside", [
    (Bound("q", 1, 2), 1, True), (Bound("q", 1, 2), 2, True), (Bound("q", 1, 2), 0.999, False),
    (Bound("q", 1, 2), 2.001, False), (Bound("q", 1, 2, strict=True), 1, False),
    (Bound("q", 1, 2, strict=True), 2, False), (Bound("q", 1, 2, strict=True), 1.5, True),
    (Bound("q", lo=3), 1e300, True), (Bound("q", lo=3), 2.9, False), (Bound("q", hi=3), -1e300, True),
    (Bound("q", hi=3), 3.1, False), (Bound("q", 0, 0), 0.0, True), (Bound("q", 0, 0), 1e-300, False),
    (Bound("q"), float("nan"), True),
])
def test_a_bound_holds_inside_its_interval(bound, x, inside):
    assert bound.holds({"q": x, "other": -7}) is inside


def test_a_bound_reads_only_its_own_quantity_and_names_a_missing_one():
    assert Bound("a", hi=1).holds({"a": 0, "b": 5})
    with pytest.raises(KeyError, match="'a'"):
        Bound("a", hi=1).holds({"b": 0})


def test_nan_is_outside_every_closed_side():
    assert not Bound("q", lo=0).holds({"q": float("nan")}) and not Bound("q", hi=0).holds({"q": float("nan")})


@pytest.mark.parametrize("bound, text", [
    (Bound("ratio", 1, 2), "1 ≤ ratio ≤ 2"), (Bound("ratio", 1, 2, strict=True), "1 < ratio < 2"),
    (Bound("flips", 0, 0), "flips = 0"), (Bound("error", hi=1e-9), "error ≤ 1e-09"),
    (Bound("error", hi=2.5e-7, strict=True), "error < 2.5e-07"), (Bound("count", lo=15875), "count ≥ 15,875"),
    (Bound("count", lo=2e6), "count ≥ 2e+06"), (Bound("slope", lo=1.23456), "slope ≥ 1.23"),
    (Bound("slope", lo=0.5, strict=True), "slope > 0.5"),
])
def test_a_bound_prints_as_the_book_shows_it(bound, text):
    assert str(bound) == text


def test_a_criterion_takes_the_first_case_whose_bounds_all_hold():
    c = Criterion(((HOLDS, (Bound("a", hi=1), Bound("b", hi=1))), (CORRECTED, (Bound("a", hi=10),))))
    assert c.decide({"a": 0.5, "b": 0.5}) == HOLDS
    assert c.decide({"a": 0.5, "b": 2}) == CORRECTED      # one bound of the first case fails
    assert c.decide({"a": 11, "b": 0}) == FAILS
    assert Criterion(((HOLDS, (Bound("a", hi=1),)),), otherwise=CORRECTED).decide({"a": 2}) == CORRECTED
    assert Criterion(((FAILS, (Bound("a", hi=1),)), (HOLDS, (Bound("a", hi=1),)))).decide({"a": 0}) == FAILS


def test_a_criterion_prints_its_cases_in_order_and_its_default():
    c = Criterion(((HOLDS, (Bound("a", hi=1), Bound("b", lo=2))), (CORRECTED, (Bound("a", hi=10),))))
    assert str(c) == "holds if a ≤ 1 and b ≥ 2; holds with a correction if a ≤ 10; otherwise does not hold"


def test_rule_pairs_verdicts_with_a_bound_or_a_tuple_of_them():
    b1, b2, b3 = Bound("a", hi=1), Bound("b", hi=2), Bound("c", hi=3)
    assert rule(HOLDS, b1, CORRECTED, (b2, b3)) == Criterion(((HOLDS, (b1,)), (CORRECTED, (b2, b3))), FAILS)
    assert rule(FAILS, b1, otherwise=HOLDS) == Criterion(((FAILS, (b1,)),), HOLDS)


def test_a_claim_is_decided_by_its_criterion_from_its_own_numbers():
    calls = []

    def quantify():
        calls.append(1)
        return "ratio 3.5", {"ratio": 3.5}
    claim = Claim("c", "§1", "it is fast", "timed", HOLDS, quantify, rule(HOLDS, Bound("ratio", lo=3)))
    assert claim.measure() == ("ratio 3.5", HOLDS) and calls == [1]
    slow = Claim("c", "§1", "it is fast", "timed", HOLDS, quantify, rule(HOLDS, Bound("ratio", lo=4)))
    assert slow.measure() == ("ratio 3.5", FAILS)


def test_the_register_names_each_claim_once_with_a_known_verdict():
    assert len(CLAIMS) == len({c.id for c in CLAIMS}) >= 30
    assert all(c.registered in (HOLDS, FAILS, CORRECTED) for c in CLAIMS)


def _inside(bound):
    if bound.lo is not None and bound.hi is not None:
        return (bound.lo + bound.hi) / 2
    return bound.lo + abs(bound.lo) + 1 if bound.lo is not None else bound.hi - abs(bound.hi) - 1


@pytest.mark.parametrize("claim", CLAIMS, ids=[c.id for c in CLAIMS])
def test_each_claims_first_case_is_reachable(claim):
    """Numbers inside the first case's bounds get that case's verdict: no claim's first case is dead."""
    verdict, bounds = claim.criterion.cases[0]
    others = {b.quantity: _inside(b) for _, bs in claim.criterion.cases[1:] for b in bs}
    assert claim.criterion.decide({**others, **{b.quantity: _inside(b) for b in bounds}}) == verdict


def test_the_books_table_refuses_a_flipped_verdict():
    """The book's register goes through `checked`: one flipped verdict fails the build, naming the claim."""
    results = [(c, {}, c.registered) for c in CLAIMS]
    assert checked(results) == results
    c = CLAIMS[3]
    flipped = results[:3] + [(c, {}, HOLDS if c.registered != HOLDS else FAILS)] + results[4:]
    with pytest.raises(ClaimChanged, match=f"{c.id}: registered"):
        checked(flipped)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), None, "3", 1j],
                         ids=["nan", "inf", "none", "text", "complex"])
def test_a_verdict_needs_a_finite_measurement_even_does_not_hold(value):
    """NaN fails every bound, so a criterion would fall to 'otherwise': for a claim registered
    as failing, any broken measurement would match.  It is refused instead, naming the quantity."""
    c = rule(HOLDS, Bound("on/off ratio", lo=10))          # otherwise FAILS
    with pytest.raises(Unmeasured, match=r"^on/off ratio measured .*: a verdict needs a finite number$"):
        c.decide({"on/off ratio": value})
    with pytest.raises(Unmeasured, match="^other measured None"):
        rule(HOLDS, Bound("a", lo=10), CORRECTED, Bound("other", lo=1)).decide({"a": 1.0})


def test_a_claim_that_cannot_be_measured_is_refused_and_hides_no_other():
    broken = Claim("broken", "§3", "a crease band", "ratio", FAILS,
                   lambda: ("ratio nan", {"ratio": float("nan")}), rule(HOLDS, Bound("ratio", lo=10)))
    crashing = Claim("crashing", "§3", "an integer", "int()", HOLDS,
                     lambda: ("", {"n": int(__import__("sympy").Symbol("x"))}), rule(HOLDS, Bound("n", lo=0)))
    fine = Claim("fine", "§3", "ok", "ratio", HOLDS, lambda: ("ratio 20", {"ratio": 20}), rule(HOLDS, Bound("ratio", lo=10)))
    results = [(c, *c.measure()) for c in (broken, crashing, fine)]
    assert [v for _, _, v in results] == [UNMEASURED, UNMEASURED, HOLDS]
    assert results[1][1].startswith("not measured: TypeError: ")
    with pytest.raises(ClaimChanged, match=r"^broken: registered 'does not hold', computed 'not measured' "
                                           r"\(not measured: Unmeasured: ratio measured nan.*; crashing: "):
        checked(results)


def test_a_claim_whose_sympy_value_does_not_reduce_to_an_integer_is_not_measured(monkeypatch):
    """The frame's orientation claim takes int() of a sympy value: one that does not reduce
    (a symbol left in it) makes that claim 'not measured', not an error of the whole register."""
    import sympy as sp

    import proofs.frame
    claim = next(c for c in CLAIMS if c.quantify.__name__ == "_orientation")
    monkeypatch.setattr(proofs.frame, "_orientation_value", lambda: sp.Symbol("s") - 1)
    measured, verdict = claim.measure()
    assert verdict == UNMEASURED and measured.startswith("not measured: TypeError"), measured
