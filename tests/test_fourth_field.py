"""A fourth height field, registered at run time (`renderer.formulas.register`), gets what the
fields defined in renderer/formulas.py have, with no edit elsewhere: its theorems (proofs/),
built, pinned and proved, with wrong variants its check refutes.

The field is sin²(pi k_u u) sin²(pi k_v v), smooth, without creases, and not integrable in the
sense of theorem bump-vs-displacement (it depends on u).  The `squares` fixture registers it for
one test and removes it after.
"""

import pytest
import sympy as sp

from renderer import formulas as F


@pytest.fixture
def squares():
    """The field "squares", registered for the test and removed after it."""
    field = F.register(F.HeightField("squares", sp.sin(sp.pi * F.k_u * F.u) ** 2 * sp.sin(sp.pi * F.k_v * F.v) ** 2))
    try:
        yield field
    finally:
        F.FIELDS.pop("squares", None)


@pytest.fixture
def built_before():
    """bump-vs-displacement's statement, built before the `squares` fixture registers its field."""
    from proofs import registry
    return registry.get("bump-vs-displacement").statement


def test_a_theorem_built_from_the_fields_is_built_again_when_they_change(built_before, squares):
    """`proofs.core.catalogue`'s key: bump-vs-displacement, built before the field was registered, is built
    again for it, and states the built-in fields alone again once it is removed."""
    from proofs import registry
    assert "squares" not in built_before and "squares" in registry.get("bump-vs-displacement").statement
    F.FIELDS.pop("squares")
    assert registry.get("bump-vs-displacement").statement == built_before


@pytest.fixture
def listed_before():
    """The registry's ids, listed before the `squares` fixture registers its field."""
    from proofs import registry
    return list(registry.THEOREMS)


def test_the_registry_lists_a_field_registered_after_it_was_listed(listed_before, squares):
    """The catalogue is read again at each call, so a field registered after a first listing (in one test
    worker, any earlier test) has its theorem, and loses it when removed."""
    from proofs import registry
    assert "gradient-squares" not in listed_before and "gradient-squares" in registry.THEOREMS
    F.FIELDS.pop("squares")
    assert list(registry.THEOREMS) == listed_before
    with pytest.raises(KeyError, match="gradient-squares"):
        registry.pin("gradient-squares")


def test_the_fourth_field_has_its_theorems_and_pins(squares):
    """The registry lists gradient-squares after the other fields' (and no crease theorem: it has no crease),
    pinned proved with 200 pixels; the theorems about every field cover it: the stencil step has its case,
    the renderer comparisons count it, and bump-vs-displacement derives that its obstruction is not 0."""
    from proofs import displacement, registry
    ids = list(registry.THEOREMS)
    assert ids[ids.index(f"gradient-{F.BUILTIN[-1]}") + 1] == "gradient-squares"
    assert registry.CITABLE["gradient-squares"] == "The gradient of the squares field"
    assert "squares-kinks" not in registry.CITABLE
    assert registry.pin("gradient-squares") == ("proved", None) and registry.least_rendered("gradient-squares") == 200
    assert registry.least_rendered("chart") == len(F.FIELDS) * 200
    stencil = registry.get("central-difference-truncation").steps[-1]
    assert [label for label, _ in stencil.cases] == [*F.BUILTIN, "squares"]
    assert "rings" in displacement.integrable() and "squares" not in displacement.integrable()
    assert " and squares fields" in registry.get("bump-vs-displacement").statement.partition("it does not for")[2]


def test_the_fourth_fields_gradient_is_proved_as_printed(squares):
    """gradient-squares names its factors s_1, s_2 and reaches h_u = 2 pi k_u s_1 cos(pi k_u u) s_2^2 (derived
    from the expression, as the other fields' closed forms are), and its check proves it with the renderer's
    outputs of the new field (the kernel's cfuncs compiled for it)."""
    from proofs import gradients, registry
    t = registry.get("gradient-squares")
    s_1, s_2 = gradients.S1, gradients.S2
    assert t.shown["h"] == sp.Eq(F.h, s_1**2 * s_2**2, evaluate=False)
    h_u = t.claims["gradient"][1][0].doit()
    assert sp.simplify(h_u - 2 * sp.pi * F.k_u * s_1 * sp.cos(sp.pi * F.k_u * F.u) * s_2**2) == 0
    verdict = t.check()
    assert verdict.status == "proved", verdict.evidence
    assert registry.pinned_failure(t.id, verdict.status, verdict.residual, verdict.rendered, verdict.covers) is None


def test_the_fourth_fields_wrong_gradients_are_refuted(squares):
    """Each wrong closed form of gradient-squares (a factor dropped, k_u and k_v swapped) is refuted at the
    proof's last step, which the right one passes."""
    from proofs import registry
    t = registry.get("gradient-squares")
    wrong = [(d, check) for d, check in t.wrong_variants if d.startswith("h_u ")]
    assert len(wrong) >= 4 and any("swapped" in d for d, _ in wrong)
    for description, check in wrong:
        verdict = check()
        assert verdict.status == "refuted", description
        assert verdict.evidence.startswith(f"gradient-squares, step {len(t.steps)} "), (description, verdict.evidence)


def test_a_field_that_turns_faster_widens_the_gradient_scale_and_its_gradient_is_proved(monkeypatch):
    """The scale the gradient checks hold errors to (`formulas.gradient_scale`) is derived from the registered
    fields' sines: pi max(k_u, 2 k_v) for the built-in ones at any frequencies; a field of sin(2 pi k_u u)
    sin(2 pi k_v v) widens it to pi max(2 k_u, 2 k_v), and its gradient theorem is proved.  With the scale
    typed as pi max(k_u, 2 k_v), as it was in six places, the renderer's exact gradient of that field left its
    tolerance and the theorem was refuted: shown here."""
    import math

    import numpy as np

    from proofs import registry
    for ku, kv in np.random.default_rng(7).uniform(0.5, 24.0, (20, 2)):
        assert F.gradient_scale(ku, kv) == pytest.approx(math.pi * max(ku, 2 * kv), rel=1e-15, abs=0)
    assert F.gradient_scale_text() == "pi max(k_u, 2 k_v)"
    F.register(F.HeightField("checker", sp.sin(2 * sp.pi * F.k_u * F.u) * sp.sin(2 * sp.pi * F.k_v * F.v)))
    try:
        assert F.gradient_scale_text() == "pi max(2 k_u, 2 k_v)"
        verdict = registry.get("gradient-checker").check()
        assert verdict.status == "proved" and "relative to pi max(2 k_u, 2 k_v)" in verdict.evidence, verdict.evidence
        monkeypatch.setattr(F, "gradient_scale", lambda ku, kv, field=None: math.pi * max(ku, 2 * kv))
        assert registry.get("gradient-checker").check().status == "refuted"
    finally:
        F.FIELDS.pop("checker", None)
