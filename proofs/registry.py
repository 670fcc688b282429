"""All theorems of the chapter, by id."""

from . import blinn, displacement, finite_difference, frame, gradients, kink_loci, kinks, no_boundary, normal

#: id -> Theorem, in the order the chapter uses them.
THEOREMS = {t.id: t for mod in (frame, gradients, kinks, kink_loci, no_boundary, normal,
                                        finite_difference, displacement, blinn)
            for t in mod.THEOREMS}


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
