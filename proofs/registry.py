"""All theorems of the chapter, by id, and the verdict each must reach.

Importing this module builds nothing (nor does it import sympy): `THEOREMS` lists the ids of
each theorem module's ``titles()``, in the chapter's order, and a theorem is built by its
module's ``build(id)`` when it is first asked for (`get`, ``THEOREMS[id]``), then kept by that
module.  A module's theorems per height field follow `renderer.formulas.FIELDS` as it stands
when they are asked for: a field registered later has its theorems too.

A new theorem (proofs/finite_difference.py's are a short model to copy):

1. a builder in one of `MODULES`: a function returning a `proofs.core.Theorem` (its steps a
   ``calc`` chain, each checked by sympy; its statement's relations shown through ⟦key⟧, rule 10
   of proofs.core), at least one wrong variant (tests/test_checker.py refutes each), and its id and
   title in the module's ``TITLES`` and ``catalogue``;
2. its verdict in `PINNED` (``pytest verify`` fails on any other, and on a theorem without a pin);
3. a place on a book page: its id in a ``theorem_block``, ``theorems`` or ``folded`` call of a
   page's code cell (book/s*.md; verify/test_theorems.py finds it there);
4. its printed text reviewed: ``python tests/test_notation.py`` prints it and its digest for
   ``PRINTED``, and a theorem that renders adds its minimum to `RENDERED`.
"""

import importlib
from collections.abc import Mapping

#: The theorem modules of proofs/, in the chapter's order.  Each has ``titles()`` ({id: title}, in
#: order, without building a theorem) and ``build(id)`` (the Theorem, built once, until
#: ``build.cache_clear()``).
MODULES = ("shading", "surface", "frame", "displacement", "gradients", "kinks", "kink_loci", "no_boundary", "finite_difference",
           "normal", "blinn")


def _catalogue():
    """{id: (module, title)} of every theorem, in the chapter's order."""
    out = {}
    for name in MODULES:
        module = importlib.import_module(f"{__package__}.{name}")
        out.update((theorem_id, (module, title)) for theorem_id, title in module.titles().items())
    return out


class _Theorems(Mapping):
    """A read-only mapping over the theorem ids of `_catalogue`, in its order: ``value(module, id,
    title)`` of each (iterating, ``in`` and ``len`` build nothing)."""

    def __init__(self, value):
        self._value = value

    def __getitem__(self, theorem_id):
        module, title = _catalogue()[theorem_id]
        return self._value(module, theorem_id, title)

    def __contains__(self, theorem_id):
        return theorem_id in _catalogue()

    def __iter__(self):
        return iter(_catalogue())

    def __len__(self):
        return len(_catalogue())


#: id -> Theorem, in the order the chapter uses them, each built when first asked for.
THEOREMS = _Theorems(lambda module, theorem_id, title: module.build(theorem_id))

#: id -> title of every theorem a statement or a step may cite (``⟪id⟫``, rule 8 of proofs.core,
#: whose CITABLE reads this one: the engine imports no theorem).
CITABLE = _Theorems(lambda module, theorem_id, title: title)

#: The verdict each theorem must reach: "proved" (sympy decided every step
#: of its proof, and its evidence holds) or ("verified", bound): sympy left a
#: step undecided and mpmath found no residual above ``bound`` at the check's
#: seeded points and digits, or the theorem rests on its renderer evidence
#: (no-boundary: ``bound`` is then the number of differing outputs).  A key with
#: ``{field}`` pins the theorem of each registered height field (gradient-sine, ...).
#: `pinned_failure` compares a verdict with it; `pytest verify` and the book
#: build fail on any difference, so a verdict cannot change unnoticed.
PINNED = {
    "displaced-normal": "proved", "chart": ("verified", 1e-30), "frame-orthonormal": "proved", "frame-orientation": "proved",
    "gradient-{field}": "proved", "{field}-kinks": "proved", "kink-loci-rays": "proved",
    "kink-loci-circles": "proved", "no-boundary": ("verified", 0.0), "normal-beta-derivative": "proved",
    "beta-zero-regression": "proved", "central-difference-truncation": "proved", "optimal-step": "proved",
    "bump-vs-displacement": "proved", "blinn-perturbation": "proved", "shading": "proved",
}


#: Theorems whose check must evaluate the renderer's own outputs, and how many at least:
#: sphere-A pixels (200 per field, per bump mode where both are compared, for the theorems
#: about every field: times the number of registered fields), or whole G-buffers and renders.
#: A check that skips its renderer comparison reports fewer (`Verdict.rendered`), and
#: `pinned_failure` names it.  Keys as in `PINNED`.
RENDERED = {
    "chart": 200, "frame-orthonormal": 2 * 200, "gradient-{field}": 200, "kink-loci-rays": 20_000,
    "kink-loci-circles": 20_000, "no-boundary": 100, "beta-zero-regression": 4, "central-difference-truncation": 10_000,
    "bump-vs-displacement": 200, "shading": 2 * 450,
}
#: A theorem's evidence compares at most this many times its `RENDERED` minimum: a minimum far below what
#: the evidence compares would let most of it be cut unseen.
RENDERED_SHARE = 10
#: The entries of `RENDERED` that count per registered field: the theorems about every field, whose
#: evidence names the fields it compared (`proofs.core.Verdict.covers`; `pinned_failure` holds the two together).
COUNTED_PER_FIELD = ("chart", "frame-orthonormal", "beta-zero-regression", "bump-vs-displacement")
#: A verified verdict rests on mpmath at `LEAST_DIGITS` digits and `LEAST_POINTS` seeded points at least, or,
#: when renderer evidence alone verifies it (no digits), on `LEAST_RENDERS` outputs without a difference.
LEAST_DIGITS, LEAST_POINTS, LEAST_RENDERS = 30, 20, 100


def _entry(table, theorem_id):
    """``table``'s entry for the theorem: its own, or its family's (``gradient-{field}`` for
    gradient-sine) if it is a theorem of the registry.  KeyError if it has none."""
    if theorem_id in table:
        return table[theorem_id]
    if theorem_id in CITABLE:
        from renderer.formulas import FIELDS
        for key, value in table.items():
            if any(key.replace("{field}", name) == theorem_id for name in FIELDS):
                return value
    raise KeyError(f"{theorem_id!r} has no entry in proofs.registry's table: a new theorem needs its verdict "
                   "in PINNED (see the module's docstring)")


def least_rendered(theorem_id):
    """How many renderer outputs the theorem's check must compare at least (`RENDERED`; 0 if none)."""
    try:
        count = _entry(RENDERED, theorem_id)
    except KeyError:
        return 0
    if theorem_id in COUNTED_PER_FIELD:
        from renderer.formulas import FIELDS
        count *= len(FIELDS)
    return count


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
    p = _entry(PINNED, theorem_id)
    if p == "proved":
        return "proved", None
    if isinstance(p, tuple) and len(p) == 2 and p[0] == "verified" and isinstance(p[1], (int, float)) \
            and not isinstance(p[1], bool) and 0 <= p[1] < float("inf"):
        return "verified", float(p[1])
    raise ValueError(f"PINNED[{theorem_id!r}] is {p!r}: a pin is \"proved\" or (\"verified\", bound), "
                     "bound a finite number >= 0")


def pinned_failure(theorem_id, status, residual, rendered, covers):
    """Why the verdict (``status``, ``residual``, ``rendered``, ``covers``) differs from `PINNED` and
    `RENDERED`, or None if it does not: the status must be the pin's, a verified one's
    residual a number at most the pin's bound (a missing or NaN residual never passes) and
    the bound within `proofs.core.TIGHT` of it, at least `least_rendered` renderer outputs
    compared and at most `RENDERED_SHARE` times that many (a theorem with renderer evidence has a minimum), and for a theorem of `COUNTED_PER_FIELD` outputs of every registered field among
    them (``covers``: the field names the evidence compared, `proofs.core.Verdict.covers`); evidence
    that names the fields it compared belongs to a theorem of `COUNTED_PER_FIELD`.

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
    from .core import loose
    too_loose = loose(bound, residual)
    if too_loose:
        return f"{theorem_id}'s pin: {too_loose}"
    least = least_rendered(theorem_id)
    if rendered < least:
        return f"{theorem_id} compared {rendered} renderer outputs, pinned at least {least}"
    if rendered > RENDERED_SHARE * least:
        return (f"{theorem_id} compared {rendered} renderer outputs, more than {RENDERED_SHARE} times its pinned "
                f"minimum {least} (RENDERED): raise the minimum, so that evidence cut is seen")
    if theorem_id in COUNTED_PER_FIELD:
        from renderer.formulas import FIELDS
        missing = [name for name in FIELDS if name not in set(covers)]
        if missing:
            return (f"{theorem_id}'s evidence compared no renderer output of the {', '.join(missing)} "
                    f"field{'s' if len(missing) > 1 else ''}, which its statement is about")
    elif covers:
        return (f"{theorem_id}'s evidence compared outputs field by field ({', '.join(covers)}), but its "
                "least count is not per field (COUNTED_PER_FIELD)")
    return None


def verdict_failure(theorem_id, verdict):
    """Why ``verdict`` (a `proofs.core.Verdict` of the theorem) does not stand, or None: it does not
    hold; it is not its pin (`pinned_failure`); or it is verified on fewer than `LEAST_DIGITS` digits
    at `LEAST_POINTS` points, or, without digits, on fewer than `LEAST_RENDERS` outputs or a residual
    other than 0.  `pytest verify` and the book's theorem blocks refuse what this names.

    Raises
    ------
    KeyError, ValueError
        As `pin`.
    """
    v = verdict
    if not v.holds:
        return f"{theorem_id} is {v.status}: {v.evidence}"
    why = pinned_failure(theorem_id, v.status, v.residual, v.rendered, v.covers)
    if why or v.status != "verified":
        return why
    if v.digits is not None and v.digits >= LEAST_DIGITS and (v.points or 0) >= LEAST_POINTS:
        return None
    if v.digits is None and (v.points or 0) >= LEAST_RENDERS and v.residual == 0.0:
        return None
    return (f"{theorem_id} is verified at {v.digits} digits and {v.points} points (residual {v.residual}): "
            f"at least {LEAST_DIGITS} digits at {LEAST_POINTS} points, or {LEAST_RENDERS} outputs without a difference")


def unknown_keys():
    """The keys of `PINNED`, `RENDERED` and `COUNTED_PER_FIELD` that name no theorem (a ``{field}`` key: the
    theorem of no registered field), and the entries of `COUNTED_PER_FIELD` that `RENDERED` lacks."""
    from renderer.formulas import FIELDS
    known = set(CITABLE)
    out = [key for key in [*PINNED, *RENDERED, *COUNTED_PER_FIELD]
           if not any(key.replace("{field}", f) in known for f in FIELDS)]
    return out + [f"{key} (not in RENDERED)" for key in COUNTED_PER_FIELD if key not in RENDERED]


def get(theorem_id):
    """The theorem with this id, built when first asked for.

    Raises
    ------
    KeyError
        Naming the unknown id and the known ones.
    """
    if theorem_id not in CITABLE:
        raise KeyError(f"no theorem {theorem_id!r}; known: {sorted(CITABLE)}")
    return THEOREMS[theorem_id]
