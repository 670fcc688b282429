"""What a theorem shows the reader reads as mathematics and English: no names from the code and
no audit vocabulary in its title, statement or step sentences (`chapter.theorems.code_words`;
the evidence is checked where it is computed, verify/test_theorems.py), and its badge says what
was proved and what was checked numerically."""

import pytest

from chapter import latex
from chapter.theorems import BADGE_STEPS_PROVED, BADGES, _chains, badge, code_words
from proofs.registry import THEOREMS


def _texts(t):
    """Each text the book prints of ``t``, with where it stands."""
    yield "title", t.title
    yield "statement", latex.statement(t)
    for k, step in enumerate(t.steps, 1):
        yield f"step {k}", step.why
        yield f"step {k} (why numeric)", step.why_numeric or ""
    for run in _chains(t.steps):
        yield (f"display of steps {run[0][0]}-{run[-1][0]}",
               "$$" + latex.chain(t, [s for _, s in run], [k for k, _ in run]) + "$$")


@pytest.mark.parametrize("theorem_id", list(THEOREMS))
def test_theorem_text_names_no_code(theorem_id):
    bad = {where: code_words(text) for where, text in _texts(THEOREMS[theorem_id]) if code_words(text)}
    assert not bad, f"{theorem_id}: {bad}"


@pytest.mark.parametrize("text, found", [
    ("the crease flag (`KINK_BAND`)", ["KINK_BAND"]),
    ("the interior branches of STENCIL_POINTS", ["STENCIL_POINTS"]),
    ("the renderer's bump (renderer.formulas.BUMP['surface'])", ["renderer.formulas", "BUMP"]),
    ("kernel.reach gives each light the same mask", ["kernel.reach"]),
    ("against `GRADIENT`", ["`GRADIENT`"]),
    ("$(\\mathrm{CENTRAL}_u, \\mathrm{crease}, t_{\\mathrm{floor}})$", ["\\mathrm{CENTRAL}"]),
    ("the seed's half-width", ["seed"]),
    ("CIRCLES phi=0.1 and the RMS error, CPU time", ["CIRCLES"]),
    ("at 24 seeded points, $s_1 = \\sin\\pi k_u u$, $N_x$, width 0.03, the draft's `bump=\"surface\"`", []),
])
def test_code_words_finds_code_and_spares_mathematics(text, found):
    assert code_words(text) == found


def test_a_verified_theorem_whose_steps_sympy_proved_says_so():
    """Only a step left to mpmath earns "VERIFIED numerically"; renderer evidence alone does not."""
    assert badge("verified", ()) == BADGE_STEPS_PROVED
    assert badge("verified", (2,)) == BADGES["verified"]
    assert badge("proved", ()) == BADGES["proved"]
    assert "PROVED" in BADGE_STEPS_PROVED and "numerically" not in BADGE_STEPS_PROVED
    with pytest.raises(KeyError, match="status"):
        badge("checked")
