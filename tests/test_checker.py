"""The proof checker has teeth: every wrong variant of every theorem is refuted, and so is
every theorem with a wrong step planted in its proof, at that step; a changed or skipped
verdict is named; the book's theorem blocks refuse a theorem that fails.  These are tests of
the checker (proofs/core.py, proofs/registry.py, chapter.theorems), run by ``make test``;
``pytest verify`` checks the theorems themselves.
"""

import dataclasses
import re
import sys

import numpy as np
import pytest
import sympy as sp

from chapter import latex
from proofs.core import CITATION, Verdict, plain
from renderer.formulas import FIELDS
from proofs.registry import CITABLE, PINNED, THEOREMS, get, least_rendered, pin, pinned_failure
from verify.test_theorems import _placed

#: Every registered field: what a theorem about every field must cover (rule 12).
ALL = tuple(FIELDS)

VARIANTS = [(t.id, d, fn) for t in THEOREMS.values() for d, fn in t.wrong_variants]

def test_a_check_that_skips_the_renderer_is_named():
    """A verdict reached without its renderer comparison (fewer outputs than pinned) is a change."""
    least = least_rendered("chart")
    assert f"compared {least - 1} renderer outputs, pinned at least {least}" in \
        pinned_failure("chart", "verified", 1e-30, least - 1, ALL)
    assert pinned_failure("chart", "verified", 1e-30, least, ALL) is None


def test_a_minimum_lowered_far_below_what_the_evidence_compares_is_named(monkeypatch):
    """A `RENDERED` minimum cut to a tenth or less of what the evidence compares (an adversarial review: nothing
    stopped it), or removed while the theorem compares renderer outputs, is named; the registry's hold."""
    from proofs import registry
    least = least_rendered("kink-loci-rays")
    assert pinned_failure("kink-loci-rays", "proved", None, registry.RENDERED_SHARE * least, ()) is None
    monkeypatch.setitem(registry.RENDERED, "kink-loci-rays", least // 20)
    assert "more than 10 times its pinned minimum" in pinned_failure("kink-loci-rays", "proved", None, least, ())
    monkeypatch.delitem(registry.RENDERED, "kink-loci-rays")
    assert "pinned minimum 0" in pinned_failure("kink-loci-rays", "proved", None, least, ())


@pytest.mark.parametrize("pin, status, residual, why", [
    ("proved", "verified", 1e-30, "is verified, pinned proved"),
    (("verified", 1e-25), "proved", None, "is proved, pinned verified"),
    (("verified", 1e-25), "verified", 1e-20, "residual 1e-20, pinned at most 1e-25"),
    (("verified", 1e-25), "verified", None, "residual None"),
])


def test_a_changed_verdict_is_named(monkeypatch, pin, status, residual, why):
    monkeypatch.setitem(PINNED, "chart", pin)
    assert why in pinned_failure("chart", status, residual, least_rendered("chart"), ALL)
    assert pinned_failure("chart", *((pin, None) if isinstance(pin, str) else ("verified", 1e-27)),
                          least_rendered("chart"), ALL) is None


@pytest.mark.parametrize("residual, passes", [(0.0, True), (1e-30, False), (5e-324, False), (None, False),
                                              (float("nan"), False), (-0.0, True)])
def test_rule_7_a_pin_of_zero_admits_only_a_zero_residual(monkeypatch, residual, passes):
    """("verified", 0.0), as no-boundary's (its residual counts differing renderer outputs): a bound read
    by truthiness (0.0 is false) would never be enforced."""
    monkeypatch.setitem(PINNED, "no-boundary", ("verified", 0.0))
    why = pinned_failure("no-boundary", "verified", residual, least_rendered("no-boundary"), ())
    assert (why is None) is passes, why
    if not passes:
        assert why == f"no-boundary is verified with residual {residual}, pinned at most 0", why


@pytest.mark.parametrize("bound", [1e-25, 1.0, 7])
def test_rule_7_a_pin_bounds_the_residual_from_above_inclusively(monkeypatch, bound):
    monkeypatch.setitem(PINNED, "chart", ("verified", bound))
    least = least_rendered("chart")
    assert pinned_failure("chart", "verified", bound, least, ALL) is None
    assert pinned_failure("chart", "verified", bound * (1 + 1e-9), least, ALL) is not None
    assert pinned_failure("chart", "verified", float("nan"), least, ALL) is not None
    assert "is proved, pinned verified" in pinned_failure("chart", "proved", None, least, ALL)


@pytest.mark.parametrize("bad", ["verified", ("verified",), ["verified", 1e-30], ("verified", 1e-30, "x"),
                                 ("verified", -1e-30), ("verified", float("inf")),
                                 ("verified", float("nan")), ("verified", None), ("verified", True), ("proved", 0.0),
                                 ("refuted", 0.0), "refuted", "Proved", None])
def test_rule_7_a_malformed_pin_is_an_error_naming_it(monkeypatch, bad):
    """Every pin kind is "proved" or ("verified", bound >= 0, finite): anything else names the theorem,
    the pin and what is accepted, whatever verdict it is asked about."""
    monkeypatch.setitem(PINNED, "chart", bad)
    for status, residual in (("proved", None), ("verified", 0.0), ("refuted", None)):
        with pytest.raises(ValueError, match=r"^PINNED\['chart'\] is .*: a pin is \"proved\" or \(\"verified\", bound\), "
                                             r"bound a finite number >= 0$"):
            pinned_failure("chart", status, residual, least_rendered("chart"), ALL)


def test_a_theorem_without_renders_is_pinned_by_its_verdict_alone():
    assert least_rendered("optimal-step") == 0
    assert pinned_failure("optimal-step", "proved", None, 0, ()) is None
    assert pinned_failure("optimal-step", "verified", 1e-30, 0, ()) == "optimal-step is verified, pinned proved"


def test_every_registered_pin_is_well_formed():
    assert {pin(t)[0] for t in THEOREMS} == {"proved", "verified"}
    assert pin("no-boundary") == ("verified", 0.0) and pin("optimal-step") == ("proved", None)


@pytest.mark.parametrize("theorem_id, description, variant", VARIANTS,
                         ids=[f"{i}: {d}" for i, d, _ in VARIANTS])


def test_wrong_variant_is_refuted(theorem_id, description, variant):
    verdict = variant()
    assert verdict.status == "refuted", f"{theorem_id}, {description}: {verdict.evidence}"
    assert isinstance(verdict.evidence, str) and verdict.evidence, "a refutation says why"


def test_every_theorem_has_a_variant_and_a_statement():
    for t in THEOREMS.values():
        assert t.wrong_variants, f"{t.id} has no wrong variant: give its Theorem one that the checker must refute"
        assert t.statement and t.steps, t.id
        assert 1 <= len(t.steps) <= 6, (t.id, len(t.steps))


def test_placed_finds_the_ids_a_page_shows_and_no_other_string():
    page = ('```{code-cell} ipython3\n:tags: [remove-cell]\nfrom chapter.theorems import theorem_block\n'
            'def theorems(*ids):\n    return "".join(theorem_block(t) for t in ids)\n```\n\ntext\n\n'
            '```{code-cell} ipython3\ntheorems("chart", "frame-orientation")\n```\n\n'
            '```{code-cell} ipython3\nx = render(Scene(bump="chart"))\ntheorem_block("optimal-step")\n```\n')
    assert _placed(page) == {"chart", "frame-orientation", "optimal-step"}
    assert _placed(page.replace('theorems("chart", "frame-orientation")', 'print("chart")')) == {"optimal-step"}


def _wrong(rhs):
    """``rhs`` made wrong: 1 added to a scalar, to every entry of a matrix, to the first entry of a tuple."""
    if isinstance(rhs, sp.Tuple):
        return sp.Tuple(_wrong(rhs[0]), *rhs[1:])
    if isinstance(rhs, (sp.MatrixBase, sp.MatrixExpr)):
        return rhs + sp.ImmutableMatrix(sp.ones(*rhs.shape))
    return rhs + 1


STEPS = [(t.id, k) for t in THEOREMS.values() for k in range(1, len(t.steps) + 1)]


@pytest.mark.parametrize("theorem_id, k", STEPS, ids=[f"{i}: step {k}" for i, k in STEPS])
def test_a_wrong_step_is_refuted_and_named(theorem_id, k):
    """Every step is checked on its own: plant a wrong right side in step k of any theorem, and the
    check refutes the theorem at step k, naming it (the steps before it still hold)."""
    t = THEOREMS[theorem_id]
    steps = list(t.steps)
    steps[k - 1] = dataclasses.replace(steps[k - 1], rhs=_wrong(steps[k - 1].rhs))
    verdict = dataclasses.replace(t, steps=tuple(steps)).check()
    assert verdict.status == "refuted", verdict.evidence
    assert verdict.evidence.startswith(f"{theorem_id}, step {k} ({plain(t.steps[k - 1].why).rstrip('.:')})"), \
        verdict.evidence


def _family(theorem_id):
    """A theorem's id with the registered field it is about written ``{field}`` (``gradient-{field}``):
    the theorems one template makes, one per field."""
    return next((theorem_id.replace(f, "{field}") for f in FIELDS if f in theorem_id.split("-")), theorem_id)


def test_no_sentence_is_shared_between_theorems():
    """Each step says why it holds in its own words: no boilerplate repeated across theorems (the
    theorems one template makes per field, `_family`, say it in the template's words)."""
    seen = {}
    for t in THEOREMS.values():
        for step in t.steps:
            assert seen.setdefault(step.why, _family(t.id)) == _family(t.id), (step.why, seen[step.why], t.id)
            assert step.why and len(step.why.split(". ")) <= 2, (t.id, step.why)


def test_registry_names_unknown_ids():
    with pytest.raises(KeyError, match=r"no theorem 'no-such'; known: \[.*'chart'"):
        get("no-such")


def test_the_registry_builds_nothing_until_a_theorem_is_asked_for(monkeypatch):
    """Importing the registry loads none of numpy, sympy, matplotlib or numba (each test worker and page
    kernel imports it); listing, counting, testing and titling the theorems build none; asking for one
    builds that one."""
    import importlib

    from proofs import registry

    from .test_interrupts import heavy_modules_after
    assert heavy_modules_after("import proofs.registry") == "[]"
    assert "'sympy'" in heavy_modules_after("import proofs.registry as r; r.get('chart')")
    built = []
    for name in registry.MODULES:
        module = importlib.import_module(f"proofs.{name}")
        monkeypatch.setattr(module, "build", lambda theorem_id, real=module.build: built.append(theorem_id) or real(theorem_id))
    ids, n, known, title = list(registry.THEOREMS), len(registry.CITABLE), "chart" in registry.THEOREMS, \
        registry.CITABLE["chart"]
    assert (len(ids), n, known, isinstance(title, str), built) == (n, len(ids), True, True, [])
    registry.get("chart")
    assert built == ["chart"]


def test_a_family_pin_serves_only_a_theorem_of_the_registry_and_yields_to_its_own(monkeypatch):
    """``{field}-kinks`` pins the kinks theorem of each field that has creases: sine has none, so
    "sine-kinks" is no theorem and has no pin; a theorem's own entry comes before its family's."""
    assert "sine-kinks" not in CITABLE and "ridges-kinks" in CITABLE
    with pytest.raises(KeyError, match="'sine-kinks' has no entry .* needs its verdict in PINNED"):
        pin("sine-kinks")
    assert pin("ridges-kinks") == ("proved", None)
    monkeypatch.setitem(PINNED, "gradient-sine", ("verified", 1e-20))
    assert (pin("gradient-sine"), pin("gradient-rings")) == (("verified", 1e-20), ("proved", None))


def test_a_key_of_the_pins_that_names_no_theorem_is_named(monkeypatch):
    """A misspelt key would pin nothing and leave its theorem to the family's pin, or to none."""
    from proofs import registry
    assert registry.unknown_keys() == []
    monkeypatch.setitem(PINNED, "no-such", "proved")
    monkeypatch.setitem(registry.RENDERED, "kink-loci-ray", 200)
    monkeypatch.setattr(registry, "COUNTED_PER_FIELD", (*registry.COUNTED_PER_FIELD, "optimal-step"))
    assert registry.unknown_keys() == ["no-such", "kink-loci-ray", "optimal-step (not in RENDERED)"]


def test_evidence_compared_field_by_field_belongs_to_a_theorem_counted_per_field(monkeypatch):
    """A theorem whose evidence names the fields it compared is one about every field: its least count
    grows with the fields and every field must be among them.  Left out of COUNTED_PER_FIELD, it is
    named; so is a per-field theorem whose evidence reports fields."""
    from proofs import registry
    assert pinned_failure("beta-zero-regression", "proved", None, least_rendered("beta-zero-regression"), ALL) is None
    monkeypatch.setattr(registry, "COUNTED_PER_FIELD", tuple(t for t in registry.COUNTED_PER_FIELD
                                                             if t != "beta-zero-regression"))
    assert "least count is not per field" in pinned_failure("beta-zero-regression", "proved", None, least_rendered("beta-zero-regression"), ALL)
    assert "(sine)" in pinned_failure("gradient-sine", "proved", None, least_rendered("gradient-sine"), ("sine",))


@pytest.mark.parametrize("theorem_id, verdict, why", [
    ("chart", Verdict("verified", "e", 1e-31, 20, 24, 1000, covers=ALL), "at 20 digits and 24 points"),
    ("chart", Verdict("verified", "e", 1e-31, 30, 19, 1000, covers=ALL), "at 30 digits and 19 points"),
    ("chart", Verdict("verified", "e", 1e-31, 30, 24, 1000, covers=ALL), None),
    ("no-boundary", Verdict("verified", "e", 0.0, None, 99, 1000), "at None digits and 99 points"),
    ("no-boundary", Verdict("verified", "e", 0.0, None, 100, 1000), None),
    ("chart", Verdict("refuted", "forced"), "chart is refuted: forced"),
])
def test_a_verified_verdict_rests_on_enough_digits_and_points_or_renders(theorem_id, verdict, why):
    """`pytest verify` and the book refuse what `verdict_failure` names: besides the pin, a verified verdict
    rests on mpmath at 30 digits and 20 points, or on 100 renders without a difference."""
    from proofs.registry import verdict_failure
    found = verdict_failure(theorem_id, verdict)
    assert found == why if why is None else why in found, found


def test_book_block_refuses_a_failing_theorem(monkeypatch):
    """A theorem that does not hold fails the build (the cell raises)."""
    from chapter import theorems as book
    from proofs import registry
    from proofs.core import Verdict
    refuted = dataclasses.replace(get("optimal-step"), evidence=lambda: Verdict("refuted", "forced for the test"))
    monkeypatch.setattr(registry, "THEOREMS", {"optimal-step": refuted,
                                               "frame-orientation": get("frame-orientation")})
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    with pytest.raises(book.TheoremFailed, match="optimal-step is refuted"):
        book.theorem_block("optimal-step")
    assert "PROVED" in book.theorem_block("frame-orientation")
    with pytest.raises(book.TheoremFailed, match="optimal-step is refuted"):
        book.ledger_table()
    with pytest.raises(KeyError, match="no theorem 'no-such'"):
        book.theorem_block("no-such")


def test_book_block_refuses_a_changed_verdict(monkeypatch):
    """A theorem that holds but not with its pinned verdict also fails the build."""
    from chapter import theorems as book
    from proofs import registry
    monkeypatch.setattr(registry, "THEOREMS", {"frame-orientation": get("frame-orientation")})
    monkeypatch.setitem(registry.PINNED, "frame-orientation", ("verified", 1e-25))
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    for show in (lambda: book.theorem_block("frame-orientation"), book.ledger_table):
        with pytest.raises(book.TheoremFailed, match="frame-orientation is proved, pinned verified"):
            show()


def test_the_box_shows_statement_badge_and_steps_and_links_its_ledger_row(monkeypatch):
    """The theorem's box: the statement, the badge with a link to the ledger row (``ledger-<id>``), then the
    proof, one "Step k." per step with its equation; the evidence (what the check compared) is in the
    ledger row, which links back to the box."""
    from chapter import theorems as book
    from proofs import registry
    t = get("optimal-step")
    monkeypatch.setattr(registry, "THEOREMS", {t.id: t})
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    block, row = book.theorem_block(t.id), book.ledger_table()
    places = [block.index(latex.statement(t)), block.index("**PROVED** · evidence: {ref}`§6 <ledger-optimal-step>`"),
              block.index(":::{prf:proof}")] + [block.index(f"**Step {k}.** ") for k in range(1, len(t.steps) + 1)]
    assert places == sorted(places)
    assert (r"\varepsilon^\ast = \left(3 u_{\mathrm{round}} \left(\lvert h\rvert + \lvert u\,h'\rvert\right) / "
            r"\lvert h'''\rvert\right)^{1/3}") in block
    assert "reduced to 0" not in block and "reduced to 0 by sympy" in row
    assert row.startswith("* (ledger-optimal-step)=\n  {prf:ref}`thm-optimal-step` (The optimal central-difference "
                          "step), `optimal-step`: **PROVED**")


def test_undecided_identity_is_verified_numerically(monkeypatch):
    """When sympy cannot decide, a true identity is 'verified' at >= 20 points and
    >= 30 digits with its worst residual stated, and a false one is still refuted."""
    import sympy as sp

    from proofs import core
    monkeypatch.setattr(core, "_exactly_zero", lambda expr: False)   # sympy "cannot decide"
    x = sp.Symbol("x", real=True)
    true = core.Identity("double angle", sp.sin(2 * x), 2 * sp.sin(x) * sp.cos(x), {x: (-3, 3)})
    verdict = core.check_identities([true])
    assert verdict.status == "verified"
    assert verdict.points >= 20 and verdict.digits >= 30 and verdict.residual < 1e-25
    false = core.Identity("wrong angle", sp.sin(2 * x), sp.sin(x) * sp.cos(x), {x: (-3, 3)})
    assert core.check_identities([false]).status == "refuted"


def test_book_block_refuses_a_check_without_its_renders(monkeypatch):
    """The chart's identities alone, its renderer comparison skipped: the build fails."""
    from chapter import theorems as book
    from proofs import registry
    from proofs.core import Verdict
    skipped = dataclasses.replace(get("chart"), evidence=lambda: Verdict("proved", "renders skipped"))
    monkeypatch.setattr(registry, "THEOREMS", {"chart": skipped})
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    with pytest.raises(book.TheoremFailed,
                       match=f"chart compared 0 renderer outputs, pinned at least {least_rendered('chart')}"):
        book.theorem_block("chart")


def test_a_calc_chain_is_one_display_a_relation_a_line_and_no_display_starts_with_equals(monkeypatch):
    """In the theorem's box each calc chain is one display after its steps' sentences: its left side once,
    then one line per step, each "=" marked with the step's number; a single step is "lhs = rhs"; no
    display starts with "=" (optimal-step has a chain of two steps and two single steps)."""
    from chapter import theorems as book
    from proofs import registry
    t = get("optimal-step")
    monkeypatch.setattr(registry, "THEOREMS", {t.id: t})
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    shown = re.findall(r"\$\$\n(.*?)\n\$\$", book.theorem_block(t.id), re.S)
    runs = book._chains(t.steps)
    assert [len(r) for r in runs] == [2, 1, 1] and len(shown) == len(runs)
    lines = shown[0].removeprefix(r"\begin{aligned}").removesuffix(r"\end{aligned}").split(r"\\ ")
    # A long side may continue on an indented line of its own (&\qquad ...); it carries no relation.
    relations = [line for line in lines if not line.startswith(r"&\qquad")]
    assert [re.findall(r"\\overset\{\((\d+)\)\}\{=\}", line) for line in relations] == [["1"], ["2"]]
    assert not any(re.findall(r"\\overset", line) for line in lines if line not in relations)
    assert latex.tex(t.steps[0].lhs, t.names) in lines[0].split("&")[0]            # the left side, in the first column
    assert relations[1].endswith(latex.tex(t.steps[1].rhs, t.names))
    assert shown[1:] == [f"{latex.tex(s.lhs, t.names)} = {latex.tex(s.rhs, t.names)}" for s in t.steps[2:]]
    assert not any(d.lstrip().startswith("=") for d in shown)


def test_the_kink_loci_refuse_an_unknown_family():
    from renderer import Scene

    from proofs.kink_loci import locus_bands
    with pytest.raises(ValueError, match=r"kind must be one of \('rays', 'circles'\), got 'lines'"):
        locus_bands("lines", Scene(), 8, 8)


@pytest.mark.parametrize("k_v", [0.9, 1.0, 4.0])
def test_the_kink_loci_circles_are_every_zero_line_of_v(k_v):
    """circle_angles lists phi = pi v for every zero line v = m / k_v of the chart [0, 1], the poles' included
    (at k_v < 1 the north pole's is the only one, and its band is rendered): the theorem's check holds at these
    frequencies, not only at the scene's."""
    from renderer import Scene

    from proofs.kink_loci import _loci, circle_angles
    lines = np.arange(0.0, 1.0 + 1e-12, 1.0 / k_v)               # v = 0, 1/k_v, 2/k_v, ... <= 1
    np.testing.assert_allclose(circle_angles(k_v) / np.pi, lines, rtol=0, atol=1e-15)
    v = _loci("circles", scene=Scene(k_v=k_v))
    assert v.status == "proved", v.evidence


@pytest.mark.parametrize("k", [8.0, 4.0, 2.5])
def test_the_predicted_crease_band_ends_where_the_renderers_flag_does(k):
    """The kink loci's band half-width about a zero line of sin(pi k t) (_half_width) is where the kernel's
    crease flag (pointwise.kink_band) switches: set a millionth inside it, clear a millionth outside, in u and
    in v (the other factor 1)."""
    from renderer import pointwise

    from proofs.kink_loci import _half_width
    edge = _half_width(k) * np.array([1 - 1e-6, 1 + 1e-6])
    across_u = pointwise.kink_band("ridges", edge, 1 / (2 * 3.0), k, 3.0)
    across_v = pointwise.kink_band("ridges", 1 / (2 * 3.0), edge, 3.0, k)
    assert across_u.tolist() == across_v.tolist() == [True, False]


@pytest.mark.parametrize("field", list(FIELDS))
def test_the_generated_gradients_error_is_relative_to_the_gradients_largest_size(field):
    """generated_code_residual measures the kernel's error against pi max(k_u, 2 k_v), the largest |h_u| or
    |h_v| any field reaches (rings' h_v = 2 pi k_v cos(2 pi k_v v)): a kernel whose gradient is half as large
    again is off by at most half of it, and by nearly half at some of the seeded points."""
    from proofs.gradients import generated_code_residual, printed
    r = generated_code_residual(FIELDS[field], printed(FIELDS[field]), compiled=lambda g: [1.5 * g[0], 1.5 * g[1]])
    assert 0.4 < r <= 0.5, r


@pytest.mark.parametrize("rhs, low", [(0, 0.1), (1, 0.5)], ids=["everywhere", "where-it-holds-elsewhere"])
def test_an_identity_that_cannot_be_evaluated_is_refuted_naming_the_point(rhs, low):
    """A sampled point where lhs - rhs raises must not be skipped (worst residual 0, 'verified'),
    even where the identity holds at the other points (1/floor(x) = 1 on [1, 1.5)): the verdict
    is refuted and says where and why."""
    from proofs.core import Identity, check_identities
    x = sp.Symbol("x")
    v = check_identities([Identity("inverse floor", 1 / sp.floor(x), sp.Integer(rhs), {x: (low, low + 1)})])
    assert v.status == "refuted", v
    assert re.fullmatch(r"inverse floor: cannot be evaluated at x=0\.\d+ \(\w+Error: .*\)", v.evidence), v.evidence


def test_a_theorem_step_that_cannot_be_evaluated_refutes_the_theorem():
    from proofs.core import Step
    t = get("optimal-step")
    x = sp.Symbol("x")
    step = Step("A step whose sides raise at every sampled point", 1 / sp.floor(x), sp.Integer(0),
                domain={x: (0.1, 0.9)})
    v = dataclasses.replace(t, steps=(*t.steps, step), claims={}).check()
    assert v.status == "refuted" and "cannot be evaluated at x=" in v.evidence, v


def _cite_in(t, k, text):
    """``t`` with ``text`` appended to step k's sentence (k = 0: to the statement)."""
    if k == 0:
        return dataclasses.replace(t, statement=t.statement + " " + text)
    steps = list(t.steps)
    steps[k - 1] = dataclasses.replace(steps[k - 1], why=steps[k - 1].why + " " + text)
    return dataclasses.replace(t, steps=tuple(steps))


@pytest.mark.parametrize("k", [0, 1])
def test_rule_8_a_citation_of_an_unknown_id_is_refuted(k):
    """A statement or step citing ⟪id⟫ of no registered theorem is refuted, naming the id; the same
    citation of a registered id holds."""
    t = get("frame-orientation")
    verdict = _cite_in(t, k, "by ⟪frame-orthonormals⟫").check()
    assert verdict.status == "refuted" and "⟪frame-orthonormals⟫" in verdict.evidence, verdict.evidence
    assert _cite_in(t, k, "by ⟪frame-orthonormal⟫").check().status == "proved"


@pytest.mark.parametrize("words", ["theorem frame-orthonormal", "theorems `chart`", "Theorem chart", "THEOREMS chart",
                                   "theorem  chart", "theorem\nchart", "theorem “chart”", "theorem 'chart'",
                                   "Theorem \"frame-orthonormal\""])
def test_rule_8_a_theorem_named_by_its_id_in_words_is_refuted(words):
    verdict = _cite_in(get("frame-orientation"), 1, f"(by {words})").check()
    assert verdict.status == "refuted" and "by its id in words" in verdict.evidence, verdict.evidence


def test_rule_8_a_cycle_of_citations_is_found_whatever_its_length():
    """`citation_cycle`: none among the registry's theorems; frame-orthonormal citing bump-vs-displacement,
    which cites it through frame-orientation (an adversarial review's plant), and chart citing
    kink-loci-circles, which cites chart through kink-loci-rays: each a cycle, named in citing order (each
    id cites the next), through the planted citation."""
    from proofs.core import citation_cycle, citations
    theorems = dict(THEOREMS)
    assert citation_cycle(theorems) is None

    def cites(t):
        return {c for text in [t.statement] + [s.why for s in t.steps] for c in citations(text)}
    for planted, k, cited in (("frame-orthonormal", 1, "bump-vs-displacement"), ("chart", 0, "kink-loci-circles")):
        changed = {**theorems, planted: _cite_in(get(planted), k, f"(⟪{cited}⟫)")}
        cycle = citation_cycle(changed)
        assert cycle[0] == cycle[-1] and all(b in cites(changed[a]) for a, b in zip(cycle, cycle[1:])), cycle
        assert (planted, cited) in set(zip(cycle, cycle[1:])), cycle



def test_no_text_names_a_theorem_by_its_id_and_every_citation_is_known():
    cited = set()
    for t in THEOREMS.values():
        for text in [t.statement] + [s.why for s in t.steps]:
            cited |= set(CITATION.findall(text))
            assert not re.search(r"\btheorems? `?(" + "|".join(map(re.escape, THEOREMS)) + r")\b", text), (t.id, text)
    assert cited and cited <= set(THEOREMS)
    assert set(CITABLE) == set(THEOREMS)


def test_the_checkers_citable_titles_are_the_registrys_once_it_is_imported_and_none_before(monkeypatch):
    """`proofs.core.CITABLE` reads proofs/registry.py's titles when asked: every one while the registry
    is imported; none (a citation is then unknown) while it is not."""
    from proofs import core
    assert dict(core.CITABLE) == CITABLE and len(core.CITABLE) == len(CITABLE) and "chart" in core.CITABLE
    monkeypatch.delitem(sys.modules, "proofs.registry")
    assert dict(core.CITABLE) == {} and len(core.CITABLE) == 0 and "chart" not in core.CITABLE


def test_a_citation_prints_as_the_theorems_number_and_title_in_the_book_and_its_title_in_plain_text():
    from chapter.theorems import _cited
    assert _cited("by ⟪chart⟫, so") == f"by {{prf:ref}}`thm-chart` ({CITABLE['chart']}), so"
    assert plain("by ⟪chart⟫, so") == f"by theorem “{CITABLE['chart']}”, so"
    with pytest.raises(KeyError, match="no-such"):
        _cited("by ⟪no-such⟫")
    assert "⟪" not in plain("⟪chart⟫ and ⟪frame-orientation⟫")
    assert plain("by ⟪no-such⟫ and ⟪chart⟫") == f"by ⟪no-such⟫ and theorem “{CITABLE['chart']}”"   # no title: left as written
    from chapter.page import plain_markdown       # a box outside the book (a notebook run by a reader)
    assert plain_markdown(_cited("by ⟪chart⟫, so")) == f"by Theorem ({CITABLE['chart']}), so"


def _floats_shown(t):
    """[(step number, Float)] of the float literals a step of ``t`` shows: in its two sides, or in the
    definitions of the symbols it defines (`Step.defines`)."""
    def floats(x):
        x = sp.sympify(x)
        return x.atoms(sp.Float) if isinstance(x, sp.Basic) else set()
    return [(k, f) for k, s in enumerate(t.steps, 1)
            for f in floats(s.lhs) | floats(s.rhs) | set().union(*[floats(t.where[d]) for d in s.defines])]


def test_no_step_shows_a_float_literal_and_the_kink_margin_is_decided():
    """A step states its numbers with symbols whose values its definitions give (ridges-kinks: the seed's
    half-width w and the margin eta); the scan finds the float literal the step once showed, and the
    margin's value is checked: eta = 0 puts u_- on the band's edge, where the flag is not set."""
    from proofs.kinks import ETA, U_IN, W, k_u
    assert {t.id: _floats_shown(t) for t in THEOREMS.values() if _floats_shown(t)} == {}
    t = get("ridges-kinks")
    k = next(k for k, s in enumerate(t.steps, 1) if U_IN in s.defines)
    assert {W, ETA} <= set(t.steps[k - 1].defines)
    old = sp.asin(sp.Float(0.03 * (1 - 1e-6), 8), evaluate=False) / (sp.pi * k_u)
    planted = dataclasses.replace(t, where={**t.where, U_IN: old})
    assert [j for j, _ in _floats_shown(planted)] == [k]
    assert t.check().status == "proved"
    verdict = dataclasses.replace(t, where={**t.where, ETA: sp.Integer(0)}).check()
    assert verdict.status == "refuted" and verdict.evidence.startswith(f"ridges-kinks, step {k} "), verdict.evidence


def _chart_box(monkeypatch, t):
    from chapter import theorems as book
    from proofs import registry
    monkeypatch.setattr(registry, "THEOREMS", {"chart": t})
    monkeypatch.setattr(book.store, "_MEMORY", {})
    monkeypatch.delenv(book.store.ENV, raising=False)
    return book, (lambda: book.theorem_block("chart"))


def test_a_verified_box_shows_its_badge_and_its_proof_each_numeric_step_its_points_digits_and_why(monkeypatch):
    """chart is VERIFIED: its box holds the statement and the badge line only; the folded proof opens with the
    steps sympy left (the verdict's ``numeric``), the points and digits of their check, and each such step
    carries its reason (``Step.why_numeric``); a proved theorem's proof has none of it."""
    from chapter.theorems import _cited, _numeric_note, _prose
    from proofs.core import POINTS, DIGITS
    t, proved = get("chart"), get("optimal-step")
    v = t.check()
    assert v.status == "verified" and v.numeric and all(t.steps[k - 1].why_numeric for k in v.numeric)
    book, show = _chart_box(monkeypatch, t)
    box, _, proof = show().partition(":::{prf:proof}")
    assert box.split("**VERIFIED numerically**", 1)[1].split("\n")[1:] == [":::", "", "::::{dropdown} Proof", ""]
    opening, _, steps = proof.partition("**Step 1.**")
    assert f"{', '.join(map(str, v.numeric))} " in opening and f"at {POINTS} random points to {DIGITS} digits" in opening
    by_step = steps.split("**Step ")
    assert [bool(s.why_numeric) and _prose(_cited(s.why_numeric)) in by_step[k] for k, s in enumerate(t.steps)] == \
        [k in v.numeric for k in range(1, len(t.steps) + 1)]
    assert _numeric_note(proved, proved.check()) == (None, None)


@pytest.mark.parametrize("plant", ["no reason on a numeric step", "a reason on a proved step"])
def test_a_box_refuses_a_numeric_step_without_its_reason_or_a_reason_on_a_proved_step(monkeypatch, plant):
    t = get("chart")
    numeric, steps = t.check().numeric, list(t.steps)
    k = numeric[-1] if plant.startswith("no") else next(j for j in range(1, len(steps) + 1) if j not in numeric)
    steps[k - 1] = dataclasses.replace(steps[k - 1], why_numeric="" if plant.startswith("no") else "sympy cannot")
    book, show = _chart_box(monkeypatch, dataclasses.replace(t, steps=tuple(steps)))
    with pytest.raises(book.TheoremFailed, match=f"chart: step {k} "):
        show()


# ----------------------------------------------------------------- rule 11: thresholds held to residuals
@pytest.mark.parametrize("module, constant, theorem_id", [
    ("displacement", "NORMAL_TOLERANCE", "bump-vs-displacement"),
    ("gradients", "GENERATED_TOLERANCE", "gradient-sine"),
    ("finite_difference", "FOOTPRINT_TOLERANCE", "central-difference-truncation"),
])
def test_an_evidence_threshold_loosened_by_orders_of_magnitude_is_refused(monkeypatch, module, constant, theorem_id):
    """Each threshold an evidence holds its residual to, raised ten orders of magnitude (a change that
    lets a defect pass and changes no verdict by itself), refutes the theorem, naming the factor."""
    import importlib

    from proofs.registry import get
    mod = importlib.import_module(f"proofs.{module}")
    monkeypatch.setattr(mod, constant, getattr(mod, constant) * 1e10)
    v = get(theorem_id).check()
    assert v.status == "refuted" and "its threshold" in v.evidence and "tighten it" in v.evidence, v.evidence


@pytest.mark.parametrize("output, theorem_id", [("chart", "chart"), ("normal", "frame-orthonormal"),
                                                ("gradient", "gradient-ridges")])
def test_a_pixel_tolerance_loosened_by_orders_of_magnitude_is_refused(monkeypatch, output, theorem_id):
    """The same for the tolerances the renderer's pixels are held to (proofs/pixels.py's TOLERANCE)."""
    from proofs import pixels
    from proofs.registry import get
    monkeypatch.setitem(pixels.TOLERANCE, output, pixels.TOLERANCE[output] * 1e10)
    v = get(theorem_id).check()
    assert v.status == "refuted" and "its threshold" in v.evidence and "tighten it" in v.evidence, v.evidence


def test_the_rendered_rate_is_held_to_its_claimed_order_within_a_tenth(monkeypatch):
    """Theorem beta-zero-regression's evidence fits the order at which renders approach the beta = 0 render
    (1.00): claimed at 1 it holds; claimed 0.15 or more away, and at 2, it is refuted (accepting within 1
    instead of 0.1 let the mutation audit's loosened fit through)."""
    from proofs import normal
    measured = normal._render_rate()
    monkeypatch.setattr(normal, "_render_rate", lambda **kw: measured)
    assert normal._rate_evidence().status == "proved"
    for order in (0.85, 1.15, 2.0):
        v = normal._rate_evidence(order=order)
        assert v.status == "refuted" and "fitted order" in v.evidence, (order, v.evidence)


def test_a_verified_pin_loosened_is_refused_and_the_rule_spares_an_exact_zero(monkeypatch):
    from proofs import core, registry
    residual = registry.get("chart").check().residual
    assert registry.pinned_failure("chart", "verified", residual, least_rendered("chart"), ALL) is None
    monkeypatch.setitem(registry.PINNED, "chart", ("verified", 1e-20))
    assert "chart's pin: its threshold 1e-20 is" in registry.pinned_failure("chart", "verified", residual, least_rendered("chart"), ALL)
    assert core.loose(1e-20, 0.0) is None and core.loose(1e-20, 1e-23) is None
    assert "threshold 1e-20 is 4e+03 times the residual it measured (2.5e-24)" in core.loose(1e-20, 2.5e-24)


def test_rule_12_evidence_that_leaves_out_a_field_is_named(monkeypatch):
    """A theorem about every field whose evidence compared outputs of only some, enough of them in all,
    is named (rule 12); each of the four per-field theorems, its evidence narrowed to the first field,
    is refused: three by rule 12 alone (their outputs counted enough), β → 0's by its own evidence."""
    from proofs import displacement, normal, pixels
    assert pinned_failure("chart", "verified", 1e-30, least_rendered("chart"), ALL[:-1]).endswith(
        f"compared no renderer output of the {ALL[-1]} field, which its statement is about")
    real = pixels.worst_of
    monkeypatch.setattr(pixels, "worst_of", lambda check, cases: real(check, [c for c in cases if c[0] == ALL[0]]))
    real_surface = displacement.surface_normal_residual
    monkeypatch.setattr(displacement, "surface_normal_residual",
                        lambda bump, gradient, fields=None: real_surface(bump, gradient, fields=ALL[:1]))
    real_rate = normal._render_rate
    monkeypatch.setattr(normal, "_render_rate", lambda **kw: real_rate(**{**kw, "fields": ALL[:1] * len(ALL)}))
    for theorem_id in ("chart", "frame-orthonormal", "bump-vs-displacement"):
        v = get(theorem_id).check()
        assert v.holds and v.covers == ALL[:1], (theorem_id, v)
        # Outputs enough in number (its least count): only rule 12 is left to refuse it.
        assert f"compared no renderer output of the {', '.join(ALL[1:])} field" in pinned_failure(
            theorem_id, v.status, v.residual, least_rendered(theorem_id), v.covers), theorem_id
    v = get("beta-zero-regression").check()          # its own evidence counts the configurations it rendered
    assert v.status == "refuted" and "not every configuration was rendered" in v.evidence, v.evidence


def test_a_theorem_about_every_field_names_each_field_its_evidence_left_out():
    """Rule 12's refusal, read whole: the fields left out, in the registry's order, with the noun's number
    following their count; and a theorem the registry does not know is named in the KeyError."""
    least = least_rendered("chart")
    for covers in (ALL[1:], ALL[2:], ()):
        missing = [f for f in ALL if f not in covers]
        noun = "field" if len(missing) == 1 else "fields"
        assert pinned_failure("chart", "verified", 1e-30, least, covers) == (
            f"chart's evidence compared no renderer output of the {', '.join(missing)} {noun}, "
            "which its statement is about")
    with pytest.raises(KeyError, match="no-such-theorem"):
        pin("no-such-theorem")


def test_the_shadow_predicates_leave_a_root_at_the_light_undecided():
    """no-boundary's predicates (`predicate_masks`) compare the kernel's reach only where float64 decides:
    with the light on sphere B's near side, B's segment quadratic has the root s = 1 at every point of A,
    so no point of A that the other predicates light is decided (a root within the margin of 1, not only
    of 0, is undecided)."""
    from proofs.no_boundary import predicate_masks
    from renderer import Scene, gbuffer
    from renderer.scene import PointLight
    centre, radius = np.asarray(Scene().center_b, float), Scene().radius_b
    scene = Scene(lights=(PointLight(tuple(centre - radius * centre / np.linalg.norm(centre))),))
    g = gbuffer(scene, 48, 48)
    masks, decided = predicate_masks(scene, g)
    lit_on_a = masks[0] & (g.chamber == 1)
    assert lit_on_a.sum() > 50 and not (lit_on_a & decided[0]).any()


@pytest.mark.parametrize("miss", [0.5, 10.0])
def test_the_shadow_predicates_leave_a_grazing_segment_undecided(miss):
    """A segment that misses sphere B by a hair (its quadratic's discriminant -8 a r delta, within the margin
    of b^2, though far above the margin itself) is neither lit nor shadowed in float64: undecided.  A point
    and a light in B's tangent plane, moved off it by delta."""
    from types import SimpleNamespace
    from proofs.no_boundary import predicate_masks
    from renderer import Scene
    from renderer.scene import PointLight
    scene = Scene()
    centre, radius = np.asarray(scene.center_b, float), scene.radius_b
    out, along = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    delta = miss * 1e-9 * 400 / (8 * 25 * radius)                 # |disc| = miss * 1e-9 * b^2, b^2 = 400, a = 25
    P, L = (centre + (radius + delta) * out + t * along for t in (-2.0, 3.0))
    g = SimpleNamespace(P=P[None, None], N=along[None, None], chamber=np.ones((1, 1), np.uint8))
    masks, decided = predicate_masks(scene.replace(lights=(PointLight(tuple(L)),)), g)
    assert masks[0, 0, 0] and decided[0, 0, 0] == (miss > 1.0)


@pytest.mark.parametrize("wrong", ["a millionth off", "v's one-sided quotient over 2 eps at the poles"])
def test_the_stencils_evidence_reads_the_compiled_kernel(monkeypatch, wrong):
    """central-difference-truncation's evidence holds the compiled kernel's central differences
    (`renderer.pointwise.central_gradient`) to the border rule as well as the formulas: a kernel a
    millionth off, or one whose v-quotient at the poles divides by 2 eps, is refuted; the formulas
    unchanged."""
    from proofs import finite_difference as fd
    from renderer import pointwise
    real = pointwise.central_gradient
    if wrong == "a millionth off":
        planted = lambda *a: tuple(g * (1 + 1e-6) for g in real(*a))            # noqa: E731
    else:
        def planted(name, u, v, k_u, k_v, eps):
            hu, hv = real(name, u, v, k_u, k_v, eps)
            clamped = (v + eps > 1) | (v - eps < 0)
            width = np.minimum(1.0, v + eps) - np.maximum(0.0, v - eps)
            return hu, np.where(clamped, hv * width / (2 * eps), hv)
    assert fd.border_mismatches() == 0
    monkeypatch.setattr(pointwise, "central_gradient", planted)
    assert fd.border_mismatches() > 100
    assert fd._stencil_evidence().status == "refuted"
