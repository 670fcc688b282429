"""All theorems of the chapter, by id, and the verdict each must reach."""

from . import blinn, displacement, finite_difference, frame, gradients, kink_loci, kinks, no_boundary, normal

#: id -> Theorem, in the order the chapter uses them.
THEOREMS = {t.id: t for mod in (frame, gradients, kinks, kink_loci, no_boundary, normal,
                                        finite_difference, displacement, blinn)
            for t in mod.THEOREMS}

#: The verdict each theorem must reach: "proved" (sympy decided every step
#: of its proof, and its evidence holds) or ("verified", bound): sympy left a
#: step undecided and mpmath found no residual above ``bound`` at the check's
#: seeded points and digits, or the theorem rests on its renderer evidence
#: (no-boundary: ``bound`` is then the number of differing outputs).
#: `pinned_failure` compares a verdict with it; `pytest verify` and the book
#: build fail on any difference, so a verdict cannot change unnoticed.
PINNED = {
    "chart": ("verified", 1e-25), "frame-orthonormal": "proved", "frame-orientation": "proved",
    "gradient-sine": "proved", "gradient-ridges": "proved", "gradient-rings": "proved",
    "ridges-kinks": "proved", "kink-loci-rays": "proved", "kink-loci-circles": "proved",
    "no-boundary": ("verified", 0.0), "normal-beta-derivative": "proved", "beta-zero-regression": "proved",
    "central-difference-truncation": "proved", "optimal-step": "proved", "bump-vs-displacement": "proved",
    "blinn-perturbation": "proved",
}


#: Theorems whose check must evaluate the renderer's own outputs, and how many at least:
#: sphere-A pixels (200 per field, per bump mode where both are compared), or whole
#: G-buffers and renders.  A check that skips its renderer comparison reports fewer
#: (`Verdict.rendered`), and `pinned_failure` names it.
RENDERED = {
    "chart": 3 * 200, "frame-orthonormal": 3 * 2 * 200, "gradient-sine": 200, "gradient-ridges": 200,
    "gradient-rings": 200, "kink-loci-rays": 200, "kink-loci-circles": 200, "no-boundary": 100,
    "beta-zero-regression": 12, "central-difference-truncation": 200, "bump-vs-displacement": 3 * 200,
}


def pinned_failure(theorem_id, status, residual, rendered):
    """Why the verdict (``status``, ``residual``, ``rendered``) differs from `PINNED` and
    `RENDERED`, or None if it does not.

    Raises
    ------
    KeyError
        If the theorem has no pinned verdict.
    """
    pin = PINNED[theorem_id]
    want, bound = (pin, None) if isinstance(pin, str) else pin
    if status != want:
        return f"{theorem_id} is {status}, pinned {want}"
    if bound is not None and not (residual is not None and residual <= bound):
        return f"{theorem_id} is verified with residual {residual}, pinned at most {bound:g}"
    if rendered < RENDERED.get(theorem_id, 0):
        return f"{theorem_id} compared {rendered} renderer outputs, pinned at least {RENDERED[theorem_id]}"
    return None


def get(theorem_id):
    """The theorem with this id.

    Raises
    ------
    KeyError
        Naming the unknown id and the known ones.
    """
    try:
        return THEOREMS[theorem_id]
    except KeyError:
        raise KeyError(f"no theorem {theorem_id!r}; known: {sorted(THEOREMS)}") from None
