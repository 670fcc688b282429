"""The proof checker's engine (proofs/core.py): what it calls proved, verified
and refuted, on identities and small proofs whose truth is known without it; and
how it prints them; and the soundness rules of its docstring, each refusing a planted violation.

Fast on purpose (seconds): mutmut (pyproject.toml's [tool.mutmut]) runs the tests of this
file that reach a function once per mutant of it in proofs/core.py.
"""

import dataclasses
import itertools
import re

import pytest
import sympy as sp

from proofs import core
from chapter.latex import statement, tex
from proofs.core import Cross, Dot, Identity, Jacobian, Step, Theorem, Verdict, calc, check_identities, written

x = sp.Symbol("x", positive=True)
y = sp.Symbol("y")
h = sp.Function("h")


@pytest.fixture(autouse=True)
def _fresh_cache(monkeypatch):
    """Each test decides its equations itself: no verdict of another test (or of a process this one
    was forked from, as mutmut's) is reused from core's cache."""
    monkeypatch.setattr(core, "_DECIDED", {})


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
    assert v.residual == pytest.approx(float(sp.pi), rel=1e-12, abs=0)       # -pi/2 against pi/2
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


# ------------------------------------------------------------------------------------ proofs
a_, b_ = sp.symbols("a b", positive=True)
SQUARE = (a_ + b_) ** 2


def square_theorem(*steps, claims=None, **fields):
    """(a + b)^2 = a^2 + 2ab + b^2, by the steps given."""
    return Theorem("square", "A square", " ".join(f"$⟦{key}⟧$" for key in claims) if claims else "$⟦square⟧$"
                   if claims is None else "", steps,
                   {"square": (SQUARE, a_**2 + 2 * a_ * b_ + b_**2)} if claims is None else claims,
                   domain={a_: (0.5, 2.0), b_: (0.5, 2.0)}, **fields)


CHAIN = calc(SQUARE, ("multiply out", (a_ + b_) * a_ + (a_ + b_) * b_),
             ("and again", a_**2 + 2 * a_ * b_ + b_**2))


def test_a_correct_chain_is_proved_step_by_step():
    t = square_theorem(*CHAIN)
    assert [s.link for s in t.steps] == [False, True] and t.steps[1].lhs is t.steps[0].rhs
    v = t.check()
    assert (v.status, v.evidence, v.rendered) == ("proved", "2 steps, each reduced to 0 by sympy", 0)


def test_a_wrong_step_is_refuted_and_named_by_number_and_sentence():
    wrong = (CHAIN[0], Step("and again", CHAIN[1].lhs, a_**2 + a_ * b_ + b_**2, link=True))
    v = square_theorem(*wrong).check()
    assert v.status == "refuted"
    assert re.fullmatch(r"square, step 2 \(and again\): residual \S+ at a=\S+, b=\S+", v.evidence), v.evidence


def test_a_chain_whose_links_do_not_connect_is_refuted_at_the_link():
    # Step 2 claims to continue step 1 but starts from another expression (each step true on its own).
    broken = (CHAIN[0], Step("and again", (a_ + b_) * a_ + b_**2 + a_ * b_ + 1, a_**2 + 2 * a_ * b_ + b_**2 + 1,
                             link=True))
    v = square_theorem(*broken, claims={}).check()
    assert v.status == "refuted" and v.evidence.startswith(
        "square, step 2 (and again) does not continue step 1: its left side differs from step 1's right side")
    # The same left side written differently is a link: it is decided equal to step 1's right side.
    rewritten = (CHAIN[0], Step("and again", a_ * (a_ + b_) + b_ * (a_ + b_), a_**2 + 2 * a_ * b_ + b_**2, link=True))
    assert square_theorem(*rewritten).check().status == "proved"
    assert square_theorem(Step("first", SQUARE, SQUARE, link=True), claims={}).check().evidence == \
        "square, step 1 (first): continues a step that does not exist"


def test_steps_that_hold_but_do_not_reach_the_statement_are_refuted():
    # Every step true, but no chain runs from the claim's left side to its right side.
    v = square_theorem(CHAIN[0], Step("and again", a_**2, a_ * a_)).check()
    assert v.status == "refuted" and v.evidence == (
        "square: no chain of steps runs from the left side of the claim 'square' to its right side: the proof "
        "does not reach the statement")
    # A claim may be any run of one chain: the first step alone reaches (a + b)^2 = (a + b) a + (a + b) b.
    assert square_theorem(*CHAIN, claims={"first": (SQUARE, CHAIN[0].rhs)}).check().status == "proved"


def test_a_step_undecided_by_sympy_makes_the_theorem_verified_with_its_residual():
    x_ = sp.Symbol("x", positive=True)
    t = Theorem("arc", "Arctangents", "$⟦arc⟧$",
                (Step("complementary angles", sp.atan(x_) + sp.atan(1 / x_), sp.pi / 2),),
                {"arc": (sp.atan(x_) + sp.atan(1 / x_), sp.pi / 2)}, domain={x_: (0.1, 10)})
    v = t.check()
    assert v.status == "verified" and v.residual < 1e-25 and (v.digits, v.points) == (core.DIGITS, core.POINTS)
    assert v.evidence.startswith("1 steps, reduced to 0 by sympy but for step 1, which holds numerically (worst "
                                 "residual") and "; " not in v.evidence       # the ledger shows it up to a "; "
    assert v.numeric == (1,)                     # the steps sympy left, for the book's box to name
    proved = dataclasses.replace(t, steps=(Step("complementary angles", sp.atan(x_) + sp.atan(1 / x_),
                                                sp.atan(x_) + sp.atan(1 / x_)),),
                                 claims={"arc": (sp.atan(x_) + sp.atan(1 / x_), sp.atan(x_) + sp.atan(1 / x_))})
    assert (proved.check().status, proved.check().numeric) == ("proved", ())


def test_named_symbols_are_printed_and_substituted_when_checked():
    e = sp.Symbol("e")
    t = square_theorem(Step("by definition", e, a_**2 + 2 * a_ * b_ + b_**2),
                       claims={"square": (e, a_**2 + 2 * a_ * b_ + b_**2)}, where={e: SQUARE})
    assert t.check().status == "proved" and statement(t) == "$e = a^{2} + 2 a b + b^{2}$"
    wrong = square_theorem(Step("by definition", e, a_**2 + b_**2), claims={}, where={e: SQUARE})
    assert wrong.check().evidence.startswith("square, step 1 (by definition): residual")
    unknown = dataclasses.replace(square_theorem(*CHAIN), statement="⟦cube⟧")
    with pytest.raises(KeyError, match=r"⟦cube⟧, neither a claim \['square'\], a named symbol"):
        statement(unknown)
    assert unknown.check().status == "refuted" and "⟦cube⟧" in unknown.check().evidence
    named = dataclasses.replace(t, statement="⟦cube⟧").check().evidence
    assert "shows ⟦cube⟧, which is neither a claim ['square'], a named symbol ['e'] nor a shown object []" in named
    shown = dataclasses.replace(square_theorem(*CHAIN), statement="$⟦cube⟧$", shown={"cube": a_**3})
    assert shown.check().status == "proved" and statement(shown) == "$a^{3}$"


@pytest.mark.parametrize("typed", [
    "$a = b$", "$a=b$", "$⟦square⟧ > 0$", "$$a < b$$", "$a\\le b$", "$a \\leq b$", "$a \\geqslant b$",
    "$a \\ne 0$", "$a\\neq0$", "$\\beta \\to 0$", "$x \\in (0, 1)$", "$a ≤ b$", "$a ≠ b$", "$a \\approx b$",
    "$a \\lt b$", "$\\varphi \\rightarrow 0$", "$a\n= b$",
    *(f"$a {r} b$" for r in ("≥", "→", "∈", "≈", "≡", "\\ge", "\\geq", "\\gt", "\\leqslant", "\\sim", "\\simeq",
                           "\\equiv", "\\propto", "\\mapsto", "\\subset", "\\subseteq", "\\ni", "\\Rightarrow",
                           "\\leftarrow", "\\Leftarrow", "\\longrightarrow", "\\Leftrightarrow", "\\iff",
                           "\\implies", "\\gets", "\\notin", "\\cong", "\\supseteq", "\\ll", "\\gg", "⇒", "∉",
                           "≃", "⊆")),
    "\\(a = b\\)", "\\[a \\le b\\]", "{math}`a = b`"])
def test_a_relation_typed_in_a_statement_is_refused(typed):
    """Rule 10: a statement asserts only through ⟦key⟧; a relation typed by hand, in any spelling and any of
    MyST's math delimiters, refutes."""
    t = dataclasses.replace(square_theorem(*CHAIN), statement=f"Here $⟦square⟧$, and {typed}.")
    verdict = t.check()
    assert verdict.status == "refuted" and "types the relation" in verdict.evidence, verdict
    assert f"by hand in {typed!r}: show it through ⟦key⟧" in verdict.evidence, verdict


def test_typed_mathematics_that_asserts_nothing_passes():
    """Names and operations are not relations: \\left, \\infty, \\int, \\top, \\lvert, \\pm, a < outside math."""
    text = (r"For $⟦square⟧$, $\left(a + b\right)^2$, $\infty$, $\int f$, $x^\top$, $\lvert a\rvert$, "
            r"$h_v^\pm$, $\inf$, $\tone$, $\sin\gamma$, $\nabla\lambda$, $\neg\ell$, $\lim$, $\simple$, "
            r"\(\partial\), {math}`\theta`, and in words a < b = c.")
    assert dataclasses.replace(square_theorem(*CHAIN), statement=text).check().status == "proved"


def test_using_rewrites_with_an_earlier_step_and_only_an_earlier_named_one():
    e, f = sp.symbols("e f")
    lemma = Step("name the square", e, a_**2 + 2 * a_ * b_ + b_**2)
    # f is defined as e + 1; with step 1 it is the expansion plus 1 (where maps e back to the square too).
    ok = square_theorem(lemma, Step("add one", f, a_**2 + 2 * a_ * b_ + b_**2 + 1, using=(1,)), claims={},
                        where={e: SQUARE, f: e + 1})
    assert ok.check().status == "proved"
    later = square_theorem(Step("use a later step", f, e + 1, using=(2,)), lemma, claims={}, where={e: SQUARE, f: e + 1})
    assert later.check().evidence == "square, step 1 (use a later step) uses step 2, which does not come before it"
    unnamed = square_theorem(*CHAIN, Step("use an unnamed side", a_, a_, using=(1,)), claims={})
    assert unnamed.check().evidence == "square, step 3 (use an unnamed side) uses step 1, whose left side is not a name"
    # A citation the step never reaches is refused (it holds without it: b = b), named or through where.
    idle = square_theorem(lemma, Step("cite an idle step", b_, b_, using=(1,)), claims={}, where={e: SQUARE})
    assert idle.check().evidence == "square, step 2 (cite an idle step) uses step 1, whose left side e it does not contain"
    pair = square_theorem(Step("name both", sp.Tuple(e, f), sp.Tuple(SQUARE, a_)),
                          Step("use one of them", f + 1, a_ + 1, using=(1,)), claims={}, where={e: SQUARE, f: a_})
    assert pair.check().status == "proved"


def test_cases_must_each_hold_and_the_failing_one_is_named():
    h = sp.Function("h")
    step = Step("double it", 2 * h(a_), h(a_) + h(a_), cases=(("square", {h: sp.Lambda(a_, a_**2)}),
                                                             ("cube", {h: sp.Lambda(a_, a_**3)})))
    assert square_theorem(step, claims={}).check().status == "proved"
    wrong = Step("double it", 2 * h(a_), h(a_) + a_**2, cases=step.cases)
    assert square_theorem(wrong, claims={}).check().evidence.startswith(
        "square, step 1 (double it): in case cube, residual")


def test_a_side_up_to_an_order_term_is_compared_by_its_series():
    x_ = sp.Symbol("x")
    good = Step("Taylor", sp.exp(x_), 1 + x_ + x_**2 / 2 + sp.O(x_**3))
    bad = Step("Taylor", sp.exp(x_), 1 + x_ + x_**2 / 3 + sp.O(x_**3))
    t = lambda s: Theorem("exp", "exp", "", (s,), {}, domain={x_: (-1, 1)})  # noqa: E731
    assert t(good).check().status == "proved"
    assert t(bad).check().evidence.startswith("exp, step 1 (Taylor): residual")


def test_the_evidence_decides_last_and_sets_the_rendered_count():
    holds = square_theorem(*CHAIN, evidence=lambda: Verdict("proved", "12 renders agree", rendered=12))
    v = holds.check()
    assert (v.status, v.evidence, v.rendered) == ("proved", "2 steps, each reduced to 0 by sympy; 12 renders agree", 12)
    rests = square_theorem(*CHAIN, evidence=lambda: Verdict("verified", "no pixel differs", 0.0, None, 100, 100))
    assert (rests.check().status, rests.check().residual, rests.check().points) == ("verified", 0.0, 100)
    fails = square_theorem(*CHAIN, evidence=lambda: Verdict("refuted", "3 pixels differ"))
    assert fails.check() == Verdict("refuted", "3 pixels differ")
    called = []
    first = square_theorem(Step("wrong", SQUARE, a_**2), claims={}, evidence=lambda: called.append(1))
    assert first.check().status == "refuted" and not called          # a refuted step stops before the renders


def test_vectors_dot_cross_and_jacobians_evaluate_when_checked():
    u_, v_ = sp.MatrixSymbol("u", 3, 1), sp.MatrixSymbol("v", 3, 1)
    where = {u_: sp.ImmutableMatrix([1, a_, 0]), v_: sp.ImmutableMatrix([0, 1, b_])}
    steps = (Step("dot", Dot(u_, v_), a_), Step("cross", Cross(u_, v_), sp.Matrix([a_ * b_, -b_, 1])),
             Step("jacobian", Jacobian((a_ * b_, a_), (a_, b_)), sp.Matrix([[b_, a_], [1, 0]])))
    assert square_theorem(*steps, claims={}, where=where).check().status == "proved"
    assert tex(Dot(Cross(u_, v_), u_)) == r"{\left(u \times v\right) \cdot u}"   # a group: MathJax never breaks it
    assert tex(Jacobian((a_, b_), (a_,))) == r"\frac{\partial(a, b)}{\partial(a)}"


def test_printing_as_a_person_writes():
    phi = sp.Symbol("phi")
    H3, H, u_round = sp.symbols("H_3 H u", positive=True)
    names = {H: r"\lvert h\rvert", H3: r"\lvert h'''\rvert", u_round: r"u_{\mathrm{round}}"}
    star = written(sp.Pow(sp.Mul(3, u_round, H, 1 / H3, evaluate=False), sp.Rational(1, 3), evaluate=False))
    assert tex(star, names) == r"\left(\frac{3 u_{\mathrm{round}} \lvert h\rvert}{\lvert h'''\rvert}\right)^{1/3}"
    # In running text too, the numerator in the order written (sympy's R e sin phi read as "Re" sin phi), and a
    # power over which "/" needs no brackets of its own; evaluated, sympy's order (the wrong variant's).
    e, R = sp.symbols("e R", positive=True)
    over = sp.Pow(sp.Add(e, -R * sp.cos(phi), evaluate=False), -2)
    assert tex(written(sp.Mul(e, R, sp.sin(phi), over, evaluate=False)), inline=True) == \
        r"e R \sin {\varphi} / \left(e - R \cos {\varphi}\right)^{2}"
    assert tex(e * R * sp.sin(phi) * over, inline=True).startswith("R e")
    assert tex(sp.Symbol("sin_phi", nonnegative=True)) == r"\sin\varphi"
    assert tex(sp.sin(phi) * sp.cos(sp.pi * phi)) == r"\sin {\varphi} \cos{\left(\pi \varphi \right)}"
    assert tex(sp.Matrix([sp.Float(0.0), 1])) == r"\left(\begin{matrix}0\\1\end{matrix}\right)"
    x_, h = sp.Symbol("x"), sp.Function("h")
    assert tex(sp.Derivative(h(x_), (x_, 3))) == r"h'''\left(x\right)"
    assert tex(sp.Derivative(h(x_), (x_, 5))) == r"h^{(5)}\left(x\right)"
    assert tex("\\alpha") == "\\alpha"


def test_square_roots_are_reduced_whatever_way_their_radicand_is_written():
    # sqrt(S)^3 = S sqrt(S) with S written two ways: zero without simplify; a different radicand is not.
    S, T = (x + 1) ** 2 - 2 * x, x**2 + 1
    assert core._radicals_reduced(sp.sqrt(S) ** 3 - T * sp.sqrt(T)) == 0
    assert core._radicals_reduced(sp.sqrt(S) ** 3 - T * sp.sqrt(T + 1)) != 0
    assert core._radicals_reduced((x + 1) ** 2 - x**2 - 2 * x - 1) == 0          # no root: plain expansion


#: Angles spelt as `_circle_reduced` meets them: z, 2z three ways (the last one -2z) and y.
_z = sp.Symbol("z", real=True)
SPELLINGS = (_z, 2 * _z, (_z + 1) ** 2 - _z**2 - 1, _z**2 - (_z + 1) ** 2 + 1, y)
#: sin and cos of each two spellings: equal (2z spelt two ways; cos of 2z and -2z) or not.
SPELLING_PAIRS = [(f, a, b) for f in (sp.sin, sp.cos) for a, b in itertools.combinations(SPELLINGS, 2)]


@pytest.mark.parametrize("seed", range(2 * len(SPELLING_PAIRS)))
def test_the_circle_reduction_is_zero_exactly_when_the_expression_vanishes(seed):
    """`_circle_reduced` against an independent reference, mpmath at 50 digits at five random points.  The
    expression: a random polynomial in sin and cos of `SPELLINGS` times sin(a)**2 + cos(b)**2 - 1, a and b
    spellings of one angle (an identity), plus for odd seeds a random term times f(a) - f(b) for the next
    pair of `SPELLING_PAIRS` (an identity only where the two are equal), over a denominator that does not
    vanish.  The reduction is 0 when, and only when, the expression vanishes.  Wrong variants it catches:
    an angle's spellings kept apart, different angles taken for one, sin(-a) taken for sin(a), the circle's
    relation with a wrong sign, the numerator left unreduced."""
    import random

    import mpmath
    rng = random.Random(seed)
    terms = [f(a) for a in SPELLINGS for f in (sp.sin, sp.cos)]

    def poly(n):
        return sum(rng.randint(-3, 3) * sp.Mul(*rng.sample(terms, rng.randint(0, 3))) for _ in range(n))
    angle = rng.choice(((SPELLINGS[0],), SPELLINGS[1:4], (y,)))
    expr = poly(3) * (sp.sin(rng.choice(angle)) ** 2 + sp.cos(rng.choice(angle)) ** 2 - 1)
    if seed % 2:
        f, a, b = SPELLING_PAIRS[seed // 2]
        expr += rng.choice(terms) * (f(a) - f(b))
    expr /= 3 + rng.choice(terms)
    fn = sp.lambdify((_z, y), expr, modules="mpmath")
    with mpmath.workdps(50):
        vanishes = all(abs(fn(mpmath.mpf(rng.uniform(-3, 3)), mpmath.mpf(rng.uniform(-3, 3)))) < mpmath.mpf(10) ** -40
                       for _ in range(5))
    assert (core._circle_reduced(expr) == 0) == vanishes, (expr, core._circle_reduced(expr))


def test_a_sine_inside_a_root_or_an_abs_is_left_to_the_other_simplifiers():
    """sin and cos under a square root or an Abs are not a polynomial in s and c: the circle reduction
    refuses them (PolynomialError), and `_exactly_zero` goes on to the others, which prove the identity and
    leave the non-identity undecided.  The wrong variant, the refusal not caught, raises here."""
    root_identity, not_identity = sp.sqrt(sp.sin(_z) ** 2 + sp.cos(_z) ** 2) - 1, sp.Abs(sp.sin(_z)) - sp.sin(_z)
    for expr in (root_identity, not_identity):
        with pytest.raises(sp.PolynomialError):
            core._circle_reduced(expr)
    assert core._exactly_zero(root_identity) and not core._exactly_zero(not_identity)


# ------------------------------------------------------------------------- the soundness rules
# Each test plants a violation of one rule of proofs/core.py's docstring and requires a refusal: no
# correct theorem breaks a rule, so only a planted violation shows that the checker enforces it.

@pytest.mark.parametrize("lemma, j", [(False, 1), (True, 2), (True, 0), (True, -1), (True, 3), (True, 1.0),
                                      (True, True)],
                         ids=["itself-as-step-1", "itself", "zero", "negative", "later", "float", "bool"])
def test_rule_1_a_step_cites_earlier_steps_only(lemma, j):
    """A step citing itself rewrites its name with its own false right side, and so "proves" anything
    (f = a + 7 here, f being (a + b)^2 + 1); step 0 and negative numbers would index the steps from the end."""
    e, f = sp.symbols("e f")
    steps = [Step("name the square", e, a_**2 + 2 * a_ * b_ + b_**2)] * lemma + [Step("circular", f, a_ + 7, using=(j,))]
    v = square_theorem(*steps, claims={}, where={e: SQUARE, f: e + 1}).check()
    assert v.status == "refuted"
    assert v.evidence == f"square, step {len(steps)} (circular) uses step {j}, which does not come before it"


def test_rule_2_a_claim_is_reached_only_through_linked_steps():
    """Two true steps, not linked: (a + b)^2 = (a + b) a + (a + b) b, and the expansion equals itself
    written in another order.  Their ends are the claim's, but no chain runs between them."""
    apart = (CHAIN[0], Step("the expansion, reordered", b_**2 + 2 * a_ * b_ + a_**2, a_**2 + 2 * a_ * b_ + b_**2))
    assert [s.link for s in apart] == [False, False]
    v = square_theorem(*apart).check()
    assert v.status == "refuted" and "no chain of steps runs from the left side of the claim 'square'" in v.evidence
    backwards = square_theorem(*apart, claims={"backwards": (apart[1].lhs, apart[0].rhs)}).check()
    assert backwards.status == "refuted" and "the claim 'backwards'" in backwards.evidence
    assert square_theorem(*CHAIN).check().status == "proved"      # the same ends, linked


def _arctangents(domain, functions=None, where=None):
    """A one-step theorem, atan(x) + atan(1/x) = pi/2 (true for x > 0 only, undecided by sympy)."""
    step = Step("complementary angles", sp.atan(x) + sp.atan(1 / x), sp.pi / 2)
    return Theorem("arc", "Arctangents", "", (step,), {}, domain=domain, functions=functions or {}, where=where or {})


def _derivative_of_h(instance):
    """A one-step theorem, d/dx h(x) = 2x, sampled through ``instance`` of h (true for x^2 only)."""
    return Theorem("dh", "Derivative", "", (Step("differentiate", sp.Derivative(h(x), x), 2 * x),), {},
                   domain={x: (0.5, 2.0)}, functions={h: sp.Lambda(x, instance)})


def _maximum(cut):
    """A one-step theorem, x + max(0, x - cut) = x on (0, 1): false, but only a sampled x above ``cut`` shows it."""
    step = Step("no excess", x + sp.Max(0, x - cut), x)
    return Theorem("max", "Maximum", "", (step,), {}, domain={x: (0, 1)})


def _tiny_gap():
    """A one-step theorem, x = x + 10^-25: numerically zero at the default tolerance, not at 10^-26."""
    return Theorem("gap", "Gap", "", (Step("a tiny gap", x, x + sp.Rational(1, 10**25)),), {}, domain={x: (0, 1)})


def _with(name, value, theorem):
    """``theorem.check`` with core's ``name`` set to ``value`` for the check."""
    def check():
        with pytest.MonkeyPatch.context() as m:
            m.setattr(core, name, value)
            return theorem.check().status
    return check


CACHE_PAIRS = {
    # Two checks with the same sides, one true and one false, differing in one part of the key only.
    "functions": (_derivative_of_h(x**2).check, _derivative_of_h(x**3).check),
    "domain": (_arctangents({x: (0.1, 10)}).check, _arctangents({x: (-10, -0.1)}).check),
    "definitions": (lambda: square_theorem(Step("define", sp.Symbol("e"), SQUARE), claims={},
                                           where={sp.Symbol("e"): a_**2 + 2 * a_ * b_ + b_**2}).check(),
                    lambda: square_theorem(Step("define", sp.Symbol("e"), SQUARE), claims={},
                                           where={sp.Symbol("e"): a_**2 + b_**2}).check()),
    "cases": (lambda: square_theorem(Step("double", 2 * h(a_), h(a_) + a_**2, cases=(("square", {h: sp.Lambda(a_, a_**2)}),)),
                                     claims={}).check(),
              lambda: square_theorem(Step("double", 2 * h(a_), h(a_) + a_**2, cases=(("cube", {h: sp.Lambda(a_, a_**3)}),)),
                                     claims={}).check()),
    "seed": (_with("SEED", 6, _maximum(sp.Rational(96, 100))), _with("SEED", 0, _maximum(sp.Rational(96, 100)))),
    "points": (_with("POINTS", 1, _maximum(sp.Rational(9, 10))), _with("POINTS", 24, _maximum(sp.Rational(9, 10)))),
    "digits": (_with("DIGITS", 30, _arctangents({x: (0.1, 10)})), _with("DIGITS", 15, _arctangents({x: (0.1, 10)}))),
    # x = x + 1e-25: a residual that counts as zero below 1e-20 and not below 1e-26.
    "tolerance": (_with("TOLERANCE_DIGITS", 20, _tiny_gap()), _with("TOLERANCE_DIGITS", 26, _tiny_gap())),
}


@pytest.mark.parametrize("first", [0, 1], ids=["holds-first", "fails-first"])
@pytest.mark.parametrize("part", CACHE_PAIRS)
def test_rule_3_the_cache_reuses_a_verdict_only_for_its_whole_key(monkeypatch, part, first):
    """Checked in one process in either order (one cache), each check reaches the verdict it reaches alone:
    the one that holds, and the one that does not, though their sides are the same."""
    monkeypatch.setattr(core, "_DECIDED", {})
    checks = CACHE_PAIRS[part]
    status = {}
    for i in (first, 1 - first):
        v = checks[i]()
        status[i] = v if isinstance(v, str) else v.status
    assert status[0] in ("proved", "verified") and status[1] == "refuted", (part, status)


@pytest.mark.parametrize("n", [2, 3, 4, 6])
def test_rule_4_a_series_step_is_checked_through_the_power_below_its_order(n):
    """exp(x) = sum x^k/k! + O(x^n): true; with the x^(n-1) coefficient 1/(n-1)! + 1, refuted (it lies
    below the O-term, so a check to order n - 1 alone would pass it)."""
    x_ = sp.Symbol("x")
    series = lambda last: sum(x_**k / sp.factorial(k) for k in range(n - 1)) + last * x_**(n - 1) + sp.O(x_**n)  # noqa: E731
    t = lambda rhs: Theorem("exp", "exp", "", (Step("Taylor", sp.exp(x_), rhs),), {}, domain={x_: (-1, 1)})  # noqa: E731
    assert t(series(1 / sp.factorial(n - 1))).check().status == "proved"
    v = t(series(1 / sp.factorial(n - 1) + 1)).check()
    assert v.status == "refuted" and v.evidence.startswith("exp, step 1 (Taylor): residual"), v.evidence


@pytest.mark.parametrize("term", ["c*x**4", "x**4", "c*x**5", "x**4*sin(x)"])
def test_rule_4_a_written_term_inside_the_order_is_refused_not_absorbed(term):
    """sympy's O(x^4) absorbs c x^4 (and anything it contains): written unevaluated, the checker refuses it
    rather than proving a statement the reader reads with the term."""
    x_, c = sp.symbols("x c")
    written_term = sp.sympify(term, locals={"x": x_, "c": c})
    rhs = written(sp.Add(1, x_, x_**2 / 2, x_**3 / 6, written_term, sp.O(x_**4), evaluate=False))
    t = Theorem("exp", "exp", "", (Step("Taylor", sp.exp(x_), rhs),), {}, domain={x_: (-1, 1), c: (1, 2)})
    v = t.check()
    assert v.status == "refuted", v.evidence
    assert v.evidence == (f"exp, step 1 (Taylor): it writes {written_term} inside O(x**4), which would absorb it: "
                          "state the series to a higher order or drop the term")
    below = written(sp.Add(1, x_, x_**2 / 2, x_**3 / 6, sp.O(x_**4), evaluate=False))     # the same, without it
    assert dataclasses.replace(t, steps=(Step("Taylor", sp.exp(x_), below),)).check().status == "proved"


def test_rule_4_an_order_term_anywhere_but_ending_the_right_side_is_refused():
    x_, y_ = sp.symbols("x y")
    cases = {"its left side carries an O-term": (sp.O(x_**2), sp.O(x_**3)),
             "must end in one O-term, a term of its sum": (sp.exp(x_), 1 + x_ * (1 + sp.O(x_))),
             "is not O((x - x0)**n) in one variable": (sp.exp(x_ * y_), 1 + sp.O(x_ * y_)),
             "about a finite point": (sp.exp(1 / x_), 1 + sp.O(1 / x_, (x_, sp.oo))),
             "x0, n >= 1": (x_**3, x_**3 + sp.O(x_**2, (x_, sp.oo)))}         # a power, about infinity
    for why, (lhs, rhs) in cases.items():
        t = Theorem("o", "o", "", (Step("series", lhs, rhs),), {}, domain={x_: (0.1, 1), y_: (0.1, 1)})
        v = t.check()
        assert v.status == "refuted" and why in v.evidence, (why, v.evidence)


@pytest.mark.parametrize("returned, why", [
    (None, "its evidence returned None, not a Verdict"),
    (True, "its evidence returned True, not a Verdict"),
    (Verdict("skipped", "renders skipped"), "renders skipped"),
    (Verdict("verified", "no residual", None, None, 100), "states no finite residual and points"),
    (Verdict("verified", "nan residual", float("nan"), 30, 24), "states no finite residual and points"),
    (Verdict("verified", "no points", 0.0, 30, 0), "states no finite residual and points"),
])
def test_rule_5_evidence_is_a_verdict_that_holds_and_states_what_it_measured(returned, why):
    v = square_theorem(*CHAIN, evidence=lambda: returned).check()
    assert v.status == "refuted" and why in v.evidence, v


# ----------------------------------------------------------- details the mutation run found untested
def test_a_verdict_names_the_steps_and_points_it_rests_on():
    """Refuted at a step or a link: the residual, digits and points of the check; the sentence less its final
    "." or ":" (a sentence ending "X." keeps its X)."""
    v = square_theorem(Step("Sum over X.", SQUARE, a_**2 + b_**2), claims={}).check()
    assert v.evidence.startswith("square, step 1 (Sum over X): residual") and v.residual > 0.5
    assert (v.status, v.digits, v.points) == ("refuted", core.DIGITS, core.POINTS)
    broken = (CHAIN[0], Step("and again:", (a_ + b_) * a_ + b_**2 + a_ * b_ + 1, a_**2 + 2 * a_ * b_ + b_**2 + 1,
                             link=True))
    v = square_theorem(*broken, claims={}).check()
    assert v.evidence.startswith("square, step 2 (and again) does not continue step 1") and v.residual == 1.0
    assert (v.status, v.digits, v.points) == ("refuted", core.DIGITS, core.POINTS)
    assert square_theorem(Step("first", SQUARE, SQUARE, link=True), claims={}).check().status == "refuted"
    proved = square_theorem(*CHAIN).check()
    assert (proved.residual, proved.digits, proved.points) == (None, None, None)


def _complementary(*steps, **fields):
    """A theorem about e = atan(a) + atan(1/a), which sympy does not reduce to pi/2 (so a step about e holds
    numerically, and one about pi/2 is proved)."""
    e = sp.Symbol("e")
    return Theorem("arc", "Arctangents", "", steps, {}, domain={a_: (0.1, 10)},
                   **{"where": {e: sp.atan(a_) + sp.atan(1 / a_)}, **fields})


def test_a_cited_step_rewrites_the_step_and_its_link():
    """With step 1's e = pi/2 substituted, step 2 and its link (whose left side e differs from step 1's right
    side) are proved; without it each would hold only numerically.  A tuple of names takes a tuple of values."""
    e = sp.Symbol("e")
    v = _complementary(Step("complementary", e, sp.pi / 2),
                       Step("the same, once more", e, sp.pi / 2, link=True, using=(1,))).check()
    assert v.evidence.startswith("2 steps, reduced to 0 by sympy but for step 1, which holds numerically (worst "
                                 "residual "), v.evidence
    pair = sp.symbols("p q")
    tuple_step = Step("two names at once", sp.Tuple(*pair), sp.Tuple(a_, b_))
    uses = square_theorem(tuple_step, Step("use both", pair[0] * pair[1], a_ * b_, using=(1,)), claims={},
                          where={pair[0]: a_, pair[1]: b_})
    assert uses.check().status == "proved"
    matrix_step = Step("two names, one vector", sp.Tuple(*pair), sp.ImmutableMatrix([a_, b_]))
    refused = square_theorem(matrix_step, Step("use both", pair[0] * pair[1], a_ * b_, using=(1,)), claims={},
                             where={pair[0]: a_, pair[1]: b_}).check()
    assert refused.evidence == "square, step 2 (use both) uses step 1, whose left side is not a name"


def test_two_steps_that_hold_numerically_are_both_named_with_the_worst_residual():
    e, f = sp.symbols("e f")
    t = _complementary(Step("complementary", e, sp.pi / 2), Step("doubled", 2 * f, sp.pi),
                       where={e: sp.atan(a_) + sp.atan(1 / a_), f: sp.atan(a_ + 1) + sp.atan(1 / (a_ + 1))})
    v = t.check()
    assert v.evidence.startswith("2 steps, reduced to 0 by sympy but for steps 1, 2, which hold numerically (worst "
                                 "residual "), v.evidence
    assert (v.status, v.digits, v.points) == ("verified", core.DIGITS, core.POINTS) and 0 < v.residual < 1e-25
    with_evidence = dataclasses.replace(t, evidence=lambda: Verdict("proved", "12 renders agree", rendered=12)).check()
    assert (with_evidence.status, with_evidence.residual, with_evidence.digits, with_evidence.points,
            with_evidence.rendered) == ("verified", v.residual, core.DIGITS, core.POINTS, 12)
    renders = dataclasses.replace(t, evidence=lambda: Verdict("verified", "no pixel differs", 0.0, None, 100, 100)).check()
    assert (renders.residual, renders.digits, renders.points) == (v.residual, core.DIGITS, core.POINTS), renders


def test_a_theorem_reports_its_worst_numerically_verified_step():
    """Of two steps that hold numerically, the theorem's residual (which its pin bounds and the ledger
    shows) is the larger one's, whichever step it is."""
    e, f = sp.symbols("e f")
    near = {e: sp.atan(a_) + sp.atan(1 / a_) + sp.Float(1e-24, 40), f: sp.atan(a_) + sp.atan(1 / a_)
            + sp.Float(1e-27, 40)}
    for first, second in ((e, f), (f, e)):
        v = _complementary(Step("one", first, sp.pi / 2), Step("other", second, sp.pi / 2), where=near).check()
        assert v.status == "verified" and 0.9e-24 < v.residual < 1.1e-24, v
        assert "worst residual 1.0e-24" in v.evidence, v.evidence


def test_a_step_in_several_cases_reports_its_weakest_case():
    """A step proved in one case and verified in two reports the verified case with the larger residual."""
    e = sp.Symbol("e")
    step = Step("complementary, three ways", e, sp.pi / 2,
                cases=(("exact", {e: sp.pi / 2}), ("small", {e: sp.atan(a_) + sp.atan(1 / a_) + sp.Float(1e-27, 40)}),
                       ("larger", {e: sp.atan(a_) + sp.atan(1 / a_) + sp.Float(1e-24, 40)})))
    v = _complementary(step).check()
    assert v.status == "verified" and 0.9e-24 < v.residual < 1.1e-24, v


def test_a_step_samples_its_own_domain_and_functions():
    """A step's ``domain`` and ``functions`` replace the theorem's for that step."""
    x_ = sp.Symbol("x")
    arc = Step("complementary", sp.atan(x_) + sp.atan(1 / x_), sp.pi / 2, domain={x_: (0.1, 10)})
    t = Theorem("arc", "Arctangents", "", (arc,), {}, domain={x_: (-10, -0.1)})
    assert t.check().status == "verified"
    square = Step("differentiate", sp.Derivative(h(x_), x_), 2 * x_, functions={h: sp.Lambda(x_, x_**2)})
    t = Theorem("dh", "Derivative", "", (square,), {}, domain={x_: (0.5, 2)}, functions={h: sp.Lambda(x_, x_**3)})
    assert t.check().status == "verified"


@pytest.mark.parametrize("residual", [float("inf"), -1e-30])
def test_rule_5_verified_evidence_with_an_impossible_residual_refutes(residual):
    v = square_theorem(*CHAIN, evidence=lambda: Verdict("verified", "odd", residual, 30, 24)).check()
    assert v.status == "refuted" and "states no finite residual and points" in v.evidence


def test_the_probe_and_the_full_sampling_draw_from_their_documented_seeds():
    """Component i's quick probe draws 3 points from Random(SEED + 1000 + i); the j-th undecided component's
    full sampling POINTS points from Random(SEED + j): the counterexamples named are theirs."""
    import random
    def drawn(seed, n):
        rng = random.Random(seed)
        return [rng.uniform(0, 1) for _ in range(n)]
    true = Identity("a", x, x, {x: (0, 1)})
    probed = Identity("b", x + sp.Max(0, x - sp.Rational(7, 10)), x, {x: (0, 1)})
    v = check_identities([true, probed])
    point = max(drawn(1001, 3))
    assert v.evidence == f"b: residual {point - 0.7:.3e} at x={point:.6g}", v.evidence
    undecided = Identity("a", sp.atan(x) + sp.atan(1 / x), sp.pi / 2, {x: (0, 1)})
    sampled = Identity("b", x + sp.Max(0, x - sp.Rational(9, 10)), x, {x: (0, 1)})
    v = check_identities([undecided, sampled])
    point = max(drawn(1, core.POINTS))
    assert max(drawn(1001, 3)) < 0.9 < point              # the probe misses it, the full sampling finds it
    assert v.evidence == f"b: residual {point - 0.9:.3e} at x={point:.6g}", v.evidence


def test_a_point_that_cannot_be_evaluated_is_named_with_its_error():
    import random
    v = check_identities([Identity("inverse floor", 1 / sp.floor(x), 1, {x: (0.1, 0.9)})])
    assert (v.status, v.digits, v.points) == ("refuted", core.DIGITS, core.POINTS)
    first = random.Random(1000).uniform(0.1, 0.9)                 # the probe's first point
    assert v.evidence == f"inverse floor: cannot be evaluated at x={first:.6g} (ZeroDivisionError: )", v


def test_equal_worst_residuals_name_the_last_component():
    ids = [Identity(k, sp.atan(x) + sp.atan(1 / x) + 1, sp.pi / 2, {x: (0.1, 10)}) for k in ("first", "second")]
    with pytest.MonkeyPatch.context() as m:
        m.setattr(core, "_exactly_zero", lambda expr: False)
        m.setattr(core, "_numeric_residual", lambda ident, seed, points, digits: (1.0 if points > 3 else 0.0, {x: 1}))
        assert check_identities(ids).evidence == "second: residual 1.000e+00 at x=1"


def test_calc_links_each_step_to_the_one_before_and_applies_the_options():
    d = {a_: (0, 1)}
    steps = calc(a_, ("one", b_), ("two", a_ * b_, {"using": (1,)}), ("three", b_ + 1), domain=d)
    assert steps == (Step("one", a_, b_, link=False, domain=d), Step("two", b_, a_ * b_, link=True, using=(1,), domain=d),
                     Step("three", a_ * b_, b_ + 1, link=True, domain=d))


def test_values_are_compared_as_columns_or_scalars():
    assert core._value(sp.Tuple(sp.ImmutableMatrix([1, 2]), 3)) == sp.Matrix([1, 2, 3])
    assert core._value(sp.Tuple(4)) == 4 and core._value(sp.ImmutableMatrix([[5]])) == 5
    assert core._value(sp.ImmutableMatrix([[1, 2]])) == sp.Matrix([[1, 2]])
    assert core._value(written(sp.Add(x, x, evaluate=False))) == 2 * x


def test_dot_and_cross_evaluate_matrix_expressions_and_keep_names():
    u_, v_ = sp.MatrixSymbol("u", 3, 1), sp.MatrixSymbol("v", 3, 1)
    assert Dot(u_, v_).doit() == Dot(u_, v_) and Cross(u_, v_).doit() == Cross(u_, v_)
    A, B = sp.ImmutableMatrix([1, 2, 3]), sp.ImmutableMatrix([0, 1, 0])
    assert Dot(Cross(u_, A), B).doit() == Dot(Cross(u_, A), B)
    assert Dot(u_, A).doit() == Dot(u_, A) and Cross(A, v_).doit() == Cross(A, v_)
    assert Dot(sp.MatMul(2, A, evaluate=False), B).doit() == 4 and Dot(sp.MatMul(a_, A, evaluate=False), B).doit() == 2 * a_
    assert Cross(sp.MatAdd(A, A, evaluate=False), B).doit() == sp.ImmutableMatrix([-6, 0, 2])
    assert core._dense(sp.MatAdd(A, B, evaluate=False)) == sp.ImmutableMatrix([1, 3, 3])
    assert core._dense(sp.MatMul(sp.ImmutableMatrix([[1, 2, 3]]), A, evaluate=False)) == sp.ImmutableMatrix([[14]])


def test_named_symbols_print_their_definitions_in_the_statement():
    E, f = sp.Function("E"), sp.Function("f")
    M = sp.MatrixSymbol("M", 2, 1)
    t = Theorem("t", "T", "$⟦E⟧$, $⟦f⟧$, $⟦M⟧$", (), {}, names={x: r"\chi"},
                where={E(x): x**2, f: sp.Lambda(x, x**3), M: sp.Matrix([x, 1])})
    assert statement(t) == (r"$E\left(\chi\right) = \chi^{2}$, $f\left(\chi\right) = \chi^{3}$, "
                                 r"$M = \left(\begin{matrix}\chi\\1\end{matrix}\right)$")
    assert tex(x + 1, t.names) == r"\chi + 1"


def test_a_variant_is_the_theorem_with_its_changes_checked_when_called():
    called = []
    wrong = core.variant(square_theorem(*CHAIN), steps=(Step("wrong", SQUARE, a_**2),), claims={},
                         evidence=lambda: called.append(1))
    assert not called and wrong().status == "refuted" and not called
    assert core.variant(square_theorem(*CHAIN))().status == "proved"


@pytest.mark.parametrize("rhs, status", [
    ("log(x) = (x - 1) - (x - 1)**2/2 + O((x - 1)**3, (x, 1))", "proved"),
    ("exp(x) = 1 + O(x)", "proved"),
    ("exp(c*x) = 1 + c*x + c**2*x**2/2 + O(x**3)", "proved"),
    ("exp(c*x) = 1 + c*x + c**2*x**2/3 + O(x**3)", "refuted"),
])
def test_rule_4_series_about_any_point_of_any_order_with_parameters(rhs, status):
    x_, c = sp.symbols("x c")
    lhs, rhs = (sp.sympify(s, locals={"x": x_, "c": c, "O": sp.O}) for s in rhs.split(" = "))
    t = Theorem("s", "s", "", (Step("series", lhs, rhs),), {}, domain={x_: (0.5, 1.5), c: (1, 2)})
    assert t.check().status == status


def test_rule_4_refusals_say_exactly_why():
    x_, y_ = sp.symbols("x y")
    t = lambda lhs, rhs: Theorem("o", "o", "", (Step("series", lhs, rhs),), {}, domain={x_: (0.1, 1), y_: (0.1, 1)})  # noqa: E731,E501
    assert t(sp.O(x_**2), sp.O(x_**3)).check().evidence == (
        "o, step 1 (series): its left side carries an O-term; only a right side may end in + O(x**n)")
    assert t(sp.exp(x_), sp.Add(1, sp.O(x_), sp.O(y_), evaluate=False)).check().evidence == (
        "o, step 1 (series): its right side must end in one O-term, a term of its sum: it has ['O(x)', 'O(y)']")
    two = written(sp.Add(1, x_, x_**3, x_**4, sp.O(x_**3), evaluate=False))
    assert t(sp.exp(x_), two).check().evidence == (
        "o, step 1 (series): it writes x**3, x**4 inside O(x**3), which would absorb them: state the series to a "
        "higher order or drop the term")


def test_each_root_of_a_radicand_however_written_becomes_one_symbol_to_the_first_power():
    """S^(k/2) is r^k, reduced to r^(k mod 2) S^(k div 2), for S written either way: what is left equals the
    expression with r = sqrt(S), and holds r to the first power only."""
    w = sp.Symbol("w", real=True)
    S = x**2 + w**2
    expr = (((x + w) ** 2 - 2 * x * w) ** sp.Rational(5, 2) + x * S ** sp.Rational(3, 2) + sp.sqrt(S)
            + w / S ** sp.Rational(3, 2) + sp.sqrt(x + 1) + x * sp.sqrt((x + w) ** 2 - 2 * x * w) * sp.sqrt(S)
            + S ** sp.Rational(1, 3))
    reduced = core._radicals_reduced(expr)
    roots = {s for s in reduced.free_symbols if isinstance(s, sp.Dummy)}
    assert len(roots) == 2 and not any(p.base in roots for p in reduced.atoms(sp.Pow)), reduced
    first, second = roots
    assert any(sp.simplify(reduced.subs({first: p, second: q}) - expr) == 0
               for p, q in ((sp.sqrt(S), sp.sqrt(x + 1)), (sp.sqrt(x + 1), sp.sqrt(S))))
    assert core._radicals_reduced(S ** sp.Rational(3, 2) - S * sp.sqrt(S)) == 0


def test_an_identity_only_expanded_trigonometry_reduces_is_proved():
    tangent = (3 * sp.tan(y) - sp.tan(y) ** 3) / (1 - 3 * sp.tan(y) ** 2)
    assert sp.simplify(sp.tan(3 * y) - tangent) != 0 and sp.trigsimp(sp.tan(3 * y) - tangent) != 0
    assert check_identities([Identity("triple tangent", sp.tan(3 * y), tangent, {y: (-0.3, 0.3)})]).status == "proved"


def test_a_vector_step_names_its_failing_component_and_sides_may_be_plain_numbers():
    v = square_theorem(Step("a vector", sp.Matrix([a_, b_]), sp.Matrix([a_, 2 * b_])), claims={}).check()
    assert re.fullmatch(r"square, step 1 \(a vector\): component 1: residual \S+ at b=\S+", v.evidence), v
    assert square_theorem(Step("plain numbers", 2, 1 + sp.Integer(1)), claims={}).check().status == "proved"


def test_a_zero_matrix_is_compared_as_its_entries():
    assert core._value(sp.ZeroMatrix(2, 3)) == sp.zeros(2, 3) and core._dense(sp.ZeroMatrix(2, 2)) == sp.zeros(2, 2)
    assert core._value(1 + written(sp.Add(x, x, evaluate=False))) == 2 * x + 1


def test_a_step_reports_a_verified_case_over_a_proved_one_and_the_larger_residual(monkeypatch):
    """Two verdicts from a step's cases: the verified one (the step holds numerically there), and of two
    verified ones the larger residual, a residual of 0.0 included."""
    e = sp.Symbol("e")
    cases = (("one", {e: a_}), ("two", {e: b_}))
    for given, want in (((Verdict("proved", "p"), Verdict("verified", "v", 0.0, 30, 24)), ("verified", 0.0)),
                        ((Verdict("verified", "v", 1e-30, 30, 24), Verdict("verified", "v", 0.0, 30, 24)),
                         ("verified", 1e-30))):
        verdicts = dict(zip((a_, b_), given))
        monkeypatch.setattr(core, "_DECIDED", {})
        monkeypatch.setattr(core, "check_identities", lambda ids, **k: verdicts[ids[0].lhs])
        v = square_theorem(Step("cases", e, e, cases=cases), claims={}).check()
        assert (v.status, v.residual) == want, v


def test_another_seed_draws_other_points_for_each_component():
    import random
    undecided = Identity("a", sp.atan(x) + sp.atan(1 / x), sp.pi / 2, {x: (0, 1)})
    sampled = Identity("b", x + sp.Max(0, x - sp.Rational(8, 10)), x, {x: (0, 1)})
    rng = random.Random(5 + 1)                                  # seed 5, the second undecided component
    point = max(rng.uniform(0, 1) for _ in range(core.POINTS))
    v = check_identities([undecided, sampled], seed=5)
    assert v.evidence == f"b: residual {point - 0.8:.3e} at x={point:.6g}", v.evidence


def test_a_point_in_several_symbols_is_named_coordinate_by_coordinate():
    import random
    w = sp.Symbol("w")
    v = check_identities([Identity("two", 1 / sp.floor(x) + w, 1, {x: (0.1, 0.9), w: (0, 1)})])
    rng = random.Random(1000)
    first = {"w": rng.uniform(0, 1), "x": rng.uniform(0.1, 0.9)}          # drawn in the symbols' order
    assert v.evidence == f"two: cannot be evaluated at w={first['w']:.6g}, x={first['x']:.6g} (ZeroDivisionError: )"


def test_a_nan_instance_refutes_even_where_sympy_reduces_the_symbols():
    """(h + 1)^2 = h^2 + 2h + 1 for any h, so sympy proves it; sampled through an h that is NaN (a broken
    formula's 0/0) it must be refuted: the quick probe runs before sympy is asked."""
    ident = Identity("nan instance", (h(x) + 1) ** 2, h(x) ** 2 + 2 * h(x) + 1, {x: (0.5, 2)}, {h: sp.Lambda(x, sp.nan)})
    assert core._exactly_zero(ident.lhs - ident.rhs)
    v = check_identities([ident])
    assert (v.status, v.evidence, v.digits) == ("refuted", "nan instance: residual nan, a constant", core.DIGITS), v


def test_a_residual_at_the_tolerance_is_not_below_it():
    v = check_identities([Identity("at the tolerance", x + sp.Float(10.0 ** -core.TOLERANCE_DIGITS, 30), x, {x: (1, 2)})])
    assert (v.status, v.evidence) == ("refuted", "at the tolerance: residual 1.000e-20, a constant")
    with pytest.MonkeyPatch.context() as m:
        m.setattr(core, "_exactly_zero", lambda expr: False)            # past the probe, in the full sampling
        m.setattr(core, "_numeric_residual", lambda ident, seed, points, digits: (
            10.0 ** -core.TOLERANCE_DIGITS if points > 3 else 0.0, {x: 1}))
        assert check_identities([Identity("full", x, x, {x: (1, 2)})]).status == "refuted"


def test_a_count_is_spelled_in_words_below_ten_in_digits_from_ten():
    from proofs.core import spelled
    assert [spelled(n) for n in range(13)] == ["no", "one", "two", "three", "four", "five", "six", "seven", "eight",
                                               "nine", "10", "11", "12"]


def test_words_are_listed_as_a_sentence_lists_them():
    from proofs.core import listed
    assert [listed(w) for w in ([], ["red"], ("red", "green"), iter(["red", "green", "blue"]), "abcd")] == [
        "", "red", "red and green", "red, green and blue", "a, b, c and d"]


# ----------------------------------------------------------- rules a review found no planted violation of
def test_a_nan_that_only_the_full_sampling_meets_refutes():
    """Sides NaN only above x = 9/10 (a formula that breaks near one end of its interval): the 3-point
    probe misses it (checked here), so the verdict rests on the full sampling keeping a NaN as the worst
    residual, after finite ones, and refuting with it."""
    nan_above = sp.Lambda(x, sp.Piecewise((sp.nan, x > sp.Rational(9, 10)), (0, True)))
    edge = Identity("nan edge", x + h(x), x, {x: (0, 1)}, {h: nan_above})
    probe, _ = core._numeric_residual(edge, 1000, 3, core.DIGITS)          # the probe's seed and size
    assert probe == 0.0
    v = check_identities([edge])
    assert v.status == "refuted" and "residual nan" in v.evidence, v
    r, at = core._numeric_residual(Identity("n", h(x), 0, {x: (0, 1)}, {h: nan_above}), 0, core.POINTS, 30)
    assert r != r and at[x] > 0.9                                            # NaN, where it was met


def test_rule_4_an_order_term_of_order_zero_is_refused():
    """O(1) as the whole series of exp x: it claims nothing about any power of x, so a check through
    power n - 1 = -1 would pass anything."""
    v = Theorem("o", "o", "", (Step("series", sp.exp(x), sp.O(1, x)),), {}, domain={x: (0.1, 1)}).check()
    assert v.status == "refuted" and "n >= 1" in v.evidence, v


@pytest.mark.parametrize("bound, status", [(1e-19, "refuted"), (1e-22, "proved")])
def test_rule_11_a_theorems_own_evidence_held_to_a_loose_threshold_is_refused(bound, status):
    """Evidence that measured 1e-24 and held it to 1e-19 (10^5 times: loose enough to pass a defect) refutes
    the theorem whose steps all hold; held to 1e-22 (100 times) it does not."""
    v = square_theorem(*CHAIN, evidence=lambda: Verdict("verified", "e", 1e-24, 30, 24, bound=bound)).check()
    assert v.status == ("refuted" if status == "refuted" else "verified"), v
    assert ("tighten it" in v.evidence) == (status == "refuted")


def test_the_evidence_is_not_asked_for_a_theorem_its_steps_or_statement_already_refute():
    """Evidence renders frames (seconds): a theorem whose claim no chain reaches, or whose statement shows
    an unknown placeholder, is refuted without it."""
    asked = []

    def evidence():
        asked.append(1)
        return Verdict("proved", "asked")
    unreached = square_theorem(CHAIN[0], evidence=evidence).check()
    unknown = dataclasses.replace(square_theorem(*CHAIN, evidence=evidence), statement="⟦cube⟧").check()
    assert (unreached.status, unknown.status, asked) == ("refuted", "refuted", [])
    assert square_theorem(*CHAIN, evidence=evidence).check().status == "proved" and asked == [1]
