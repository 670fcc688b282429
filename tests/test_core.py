"""The proof checker's engine (proofs/core.py): what it calls proved, verified
and refuted, on identities whose truth is known without it.

Fast on purpose (seconds): benchmarks/mutation_audit.py --mutmut runs this
file once per mutant of proofs/core.py.
"""

import re

import pytest
import sympy as sp

from proofs import core
from proofs.core import Identity, Verdict, check_identities, identities_theorem, step_parts

x = sp.Symbol("x", positive=True)
y = sp.Symbol("y")
h = sp.Function("h")


def test_an_identity_sympy_reduces_is_proved_without_numbers():
    v = check_identities([Identity("square", (x + 1) ** 2, x**2 + 2 * x + 1, {x: (0.1, 2)})])
    assert (v.status, v.residual, v.holds) == ("proved", None, True)
    assert v.evidence == "1 identities, lhs - rhs reduced to 0 by sympy"


@pytest.mark.parametrize("lhs, rhs", [(sp.sin(y) ** 2 + sp.cos(y) ** 2, 1), (sp.sin(2 * y), 2 * sp.sin(y) * sp.cos(y)),
                                      (sp.cos(y) ** 2 - sp.sin(y) ** 2, sp.cos(2 * y))])
def test_trigonometric_identities_are_proved(lhs, rhs):
    assert check_identities([Identity("trig", lhs, rhs, {y: (-3, 3)})]).status == "proved"


def test_what_sympy_cannot_reduce_is_verified_with_its_residual():
    # atan x + atan(1/x) = pi/2 for x > 0: true, and not reduced by sympy's simplifiers.
    assert not core._exactly_zero(sp.atan(x) + sp.atan(1 / x) - sp.pi / 2)
    v = check_identities([Identity("arctangents", sp.atan(x) + sp.atan(1 / x), sp.pi / 2, {x: (0.1, 10)})])
    assert v.status == "verified" and v.holds
    assert v.residual < 10.0 ** -core.TOLERANCE_DIGITS
    assert (v.digits, v.points) == (core.DIGITS, core.POINTS)
    assert v.evidence.startswith("1 of 1 identities not decided by sympy") and "arctangents" in v.evidence
    assert f"{core.POINTS} seeded points, {core.DIGITS} digits" in v.evidence


def test_the_same_identity_off_its_domain_is_refuted():
    v = check_identities([Identity("arctangents", sp.atan(y) + sp.atan(1 / y), sp.pi / 2, {y: (-10, -0.1)})])
    assert v.status == "refuted" and not v.holds
    assert v.residual == pytest.approx(float(sp.pi), rel=1e-12)       # -pi/2 against pi/2
    assert v.evidence.startswith("arctangents: residual 3.142e+00 at y=-")


def test_a_false_identity_is_refuted_with_its_counterexample():
    v = check_identities([Identity("not square", x**2, x, {x: (2, 3)})])
    assert v.status == "refuted" and 2 <= v.residual <= 6
    assert "not square: residual" in v.evidence and " at x=" in v.evidence


@pytest.mark.parametrize("scale, status", [(1e-25, "verified"), (5e-21, "verified"), (1e-18, "refuted"),
                                           (1e-12, "refuted")])
def test_residuals_count_as_zero_only_below_the_tolerance(scale, status):
    # x + s sin(x) = x: not zero for sympy; the residual is about s at 30 digits.
    v = check_identities([Identity("tiny", x + sp.Float(scale, 30) * sp.sin(x), x, {x: (1.0, 1.5)})])
    assert v.status == status
    if status == "refuted":
        assert scale * 0.8 <= v.residual <= scale


def test_the_tolerance_is_twenty_digits_at_thirty():
    assert (core.TOLERANCE_DIGITS, core.DIGITS, core.POINTS) == (20, 30, 24)


def test_numbers_are_evaluated_at_the_precision_asked_for():
    # float64-like precision cannot show a residual below 1e-20: the true
    # identity then fails the tolerance, so the working precision must be DIGITS.
    ident = Identity("arctangents", sp.atan(x) + sp.atan(1 / x), sp.pi / 2, {x: (0.1, 10)})
    assert check_identities([ident]).residual < 1e-25
    low = check_identities([ident], digits=15)
    assert low.status == "refuted" and 1e-20 < low.residual < 1e-13
    assert (low.digits, low.points) == (15, core.POINTS)


def test_a_counterexample_the_quick_probe_misses_is_found_by_the_full_sampling():
    # Wrong only for x > 0.9: the 3-point probe (seed 1000) draws no x above 0.78,
    # the 24 points (seed 0) three above 0.9.
    v = check_identities([Identity("edge", x + sp.Max(0, x - sp.Rational(9, 10)), x, {x: (0, 1)})])
    assert v.status == "refuted" and v.evidence.startswith("edge: residual 8.279e-02 at x=0.982785")
    assert (v.digits, v.points) == (core.DIGITS, core.POINTS)


def test_several_symbols_are_sampled_each_from_its_own_interval():
    w = sp.Symbol("w", positive=True)
    ident = Identity("two", sp.atan(x) + sp.atan(1 / x) + sp.atan(w) + sp.atan(1 / w), sp.pi,
                     {x: (0.1, 10), w: (0.5, 2)})
    assert check_identities([ident]).status == "verified"
    r, at = core._numeric_residual(Identity("two", x * w, 0, {x: (3, 4), w: (-2, -1)}), 0, 5, 30)
    assert 3 <= at[x] <= 4 and -2 <= at[w] <= -1 and 3 <= r <= 8
    # A counterexample in two symbols is named coordinate by coordinate, in the symbols' order.
    v = check_identities([Identity("product", x * w, 0, {x: (3, 4), w: (-2, -1)})])
    assert re.fullmatch(r"product: residual \S+ at w=-1\.\d+, x=3\.\d+", v.evidence), v.evidence


def test_every_component_of_a_matrix_identity_is_checked_and_named():
    ok = Identity("pair", sp.Matrix([x, x**2]), sp.Matrix([x, x * x]), {x: (0, 1)})
    assert check_identities([ok]).status == "proved"
    v = check_identities([Identity("pair", sp.Matrix([x, 1]), sp.Matrix([x, 2]), {x: (0, 1)})])
    assert v.status == "refuted" and v.evidence.startswith("pair[1]: residual 1.000e+00")


def test_matrices_of_different_shapes_are_refuted_by_shape():
    v = check_identities([Identity("shape", sp.Matrix([x, 1]), sp.Matrix([[x, 1]]), {x: (0, 1)})])
    assert v == Verdict("refuted", "shape: shapes (2, 1) and (1, 2) differ")


def test_one_false_identity_refutes_a_list_of_true_ones():
    ids = [Identity("a", (x + 1) ** 2, x**2 + 2 * x + 1, {x: (0, 1)}), Identity("b", 2 * x, x, {x: (1, 2)}),
           Identity("c", sp.atan(x) + sp.atan(1 / x), sp.pi / 2, {x: (0.1, 10)})]
    v = check_identities(ids)
    assert v.status == "refuted" and v.evidence.startswith("b: ")
    assert check_identities([ids[0], ids[2]]).evidence.startswith("1 of 2 identities")


def test_a_symbol_without_a_sampling_interval_is_an_error_naming_it():
    with pytest.raises(ValueError, match=r"identity 'no domain': no sampling interval for \[y\]"):
        check_identities([Identity("no domain", sp.atan(y) + sp.atan(1 / y), sp.pi / 2, {})])


def test_an_undefined_function_is_sampled_through_its_instances():
    ident = Identity("derivative", sp.Derivative(h(x), x), 2 * x, {x: (0.5, 2)}, {h: sp.Lambda(x, x**2)})
    assert check_identities([ident]).status == "verified"
    wrong = Identity("derivative", sp.Derivative(h(x), x), 3 * x, {x: (0.5, 2)}, {h: sp.Lambda(x, x**2)})
    assert check_identities([wrong]).status == "refuted"


def test_a_residual_that_is_not_a_number_refutes():
    # Sides that evaluate to NaN (0/0 in a broken formula) must not pass as a residual of 0.
    nan = Identity("nan", h(x), 0, {x: (0.5, 2)}, {h: sp.Lambda(x, sp.nan)})
    assert check_identities([nan]).status == "refuted"
    assert check_identities([Identity("true", sp.sin(x) ** 2 + sp.cos(x) ** 2, 1, {x: (0, 1)}), nan]).status == "refuted"


def test_the_numbers_are_seeded():
    ident = Identity("arctangents", sp.atan(x) + sp.atan(1 / x), sp.pi / 2 + sp.Float(1e-3) * x, {x: (0.1, 10)})
    a, b = core._numeric_residual(ident, 7, 5, 30), core._numeric_residual(ident, 7, 5, 30)
    assert a == b and a[0] > 1e-4
    assert core._numeric_residual(ident, 8, 5, 30)[1] != a[1]
    # the worst of the points: more points find a larger residual than the first alone
    assert core._numeric_residual(ident, 7, 50, 30)[0] > core._numeric_residual(ident, 7, 1, 30)[0]


def test_a_verdict_holds_only_when_proved_or_verified():
    assert [Verdict(s, "").holds for s in ("proved", "verified", "refuted", "")] == [True, True, False, False]


def test_identities_theorem_checks_its_identities_and_refutes_its_variants():
    ids = [Identity("double angle", sp.sin(2 * y), 2 * sp.sin(y) * sp.cos(y), {y: (-1, 1)})]
    t = identities_theorem("t", "Title", "statement", ids, [("factor dropped", [
        Identity("double angle", sp.sin(2 * y), sp.sin(y) * sp.cos(y), {y: (-1, 1)})])], pages=["s3"],
        seed_says="so")
    assert (t.id, t.title, t.statement, t.seed_says) == ("t", "Title", "statement", "so")
    assert identities_theorem("t", "Title", "statement", ids, []).seed_says == ""
    assert t.check().status == "proved"
    assert [(d, f().status) for d, f in t.wrong_variants] == [("factor dropped", "refuted")]
    assert t.steps == (("double angle", sp.sin(2 * y), 2 * sp.sin(y) * sp.cos(y)),) and t.pages == ("s3",)


def test_step_parts_prints_sympy_and_passes_latex_through():
    phi = sp.Symbol("phi")
    assert step_parts(("c", sp.sin(phi), None)) == (r"\sin{\left(\varphi \right)}", None)
    assert step_parts(("c", r"\alpha", sp.Integer(2))) == (r"\alpha", "2")
    assert step_parts(("c", sp.Symbol("theta") + 1, "x")) == (r"\theta + 1", "x")
    # A plain Python number (no free_symbols) is printed too.
    assert step_parts(("c", 0, 0.5)) == ("0", "0.5")
