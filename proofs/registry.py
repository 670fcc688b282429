"""All theorems of the chapter, by id, and the verdict each must reach."""

from . import blinn, core, displacement, finite_difference, frame, gradients, kink_loci, kinks, no_boundary, normal

#: id -> Theorem, in the order the chapter uses them.
THEOREMS = {t.id: t for mod in (frame, gradients, kinks, kink_loci, no_boundary, normal,
                                        finite_difference, displacement, blinn)
            for t in mod.THEOREMS}

#: id -> title of every theorem a statement or a step may cite (``⟪id⟫``, rule 8 of proofs.core):
#: proofs.core.CITABLE, filled here (the engine imports no theorem).
CITABLE = core.CITABLE
CITABLE.update({theorem_id: t.title for theorem_id, t in THEOREMS.items()})

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


def pin(theorem_id):
    """(status, bound) of the theorem's `PINNED` verdict: ("proved", None), or ("verified", bound)
    with bound a finite float >= 0 (0.0 included: then no residual but 0 passes).

    Raises
    ------
    KeyError
        If the theorem has no pinned verdict.
    ValueError
        If its pin is neither "proved" nor ("verified", bound) with a finite bound >= 0.
    """
    p = PINNED[theorem_id]
    if p == "proved":
        return "proved", None
    if isinstance(p, tuple) and len(p) == 2 and p[0] == "verified" and isinstance(p[1], (int, float)) \
            and not isinstance(p[1], bool) and 0 <= p[1] < float("inf"):
        return "verified", float(p[1])
    raise ValueError(f"PINNED[{theorem_id!r}] is {p!r}: a pin is \"proved\" or (\"verified\", bound), "
                     "bound a finite number >= 0")


def pinned_failure(theorem_id, status, residual, rendered):
    """Why the verdict (``status``, ``residual``, ``rendered``) differs from `PINNED` and
    `RENDERED`, or None if it does not: the status must be the pin's, a verified one's
    residual a number at most the pin's bound (a missing or NaN residual never passes),
    and at least `RENDERED` renderer outputs compared.

    Raises
    ------
    KeyError
        If the theorem has no pinned verdict.
    ValueError
        If its pin is malformed (`pin`).
    """
    want, bound = pin(theorem_id)
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
