"""The draft's claims on the book's pages: a margin note where the reader meets each claim,
and the register of §6 that collects them.

Every claim of `lab.claims.CLAIMS` is *placed* on exactly one page section
(`PLACES`): there `margin_notes(place)` shows it in a margin note (the draft's words,
the verdict linked to its glossary term) linked to its row of the register; the row
holds the measurement in words (`chapter.claim_words`) and the rule, and links back.
Both read the same evaluation of the register (`lab.claims.checked`), so a verdict
cannot read one way in §5 and another in §6, and the build fails, as `pytest verify`
does, when a computed verdict is not the registered one.
"""

from __future__ import annotations

from lab.claims import CLAIMS, checked

from .claim_words import WORDS, measured_text, rule_text

__all__ = ["PLACES", "WORDS", "margin_notes", "register", "place_of", "section_of", "measurement", "NUMBERS"]

#: {claim id: its entry's number in §6's register} (`register`; the "why" links' names, book/_ext/a11y_markup.py).
NUMBERS = {c.id: n for n, c in enumerate(CLAIMS, start=1)}

#: Place -> the claims noted there, in the order the text meets them.  A place is a section label
#: of the book (``"cell3"``) or a paragraph within it (``"cell3/flips"``: the section label, a slash,
#: a name), and the page calls ``margin_notes(place)`` once, right before the paragraph that discusses
#: those claims: the theme floats a margin note beside what follows it.  Every claim is placed once.
PLACES = {
    "s3-frame": ("frame-aligned",),
    "s3-boundary": ("flips-zero",),
    "s3-boundary/gate": ("shadow-curves-unchanged",),
    "s3-ucurve": ("h3-scale", "truncation-until-1e-6"),
    "s3-ucurve/tiny": ("roundoff-drowns-1e-9",),
    "sim-try": ("try-sweep",),
    "sim-try/creases": ("try-creases",),
    "sim-try/pinch": ("try-pinch",),
    "sim-try/beta0": ("try-beta0",),
    "cell1": ("cell1-ripples",),
    "cell2": ("cell2-minimum",),
    "cell3/census": ("cell3-runs",),
    "cell3": ("census-slope", "kink-order-of-magnitude"),
    "cell3/flips": ("census-flips",),
    "cell4": ("four-evals-vs-one", "cell4-counter"),
    "cell4/trig": ("symbolic-not-slower",),
    "cell5": ("dn-verified-1e-12", "cell5-fd-1e-9"),
    "cell5/order": ("beta-quadratic",),
    "cell6": ("beta0-1e-16", "bump-nonzero"),
    "cell6/truncation": ("cell6-truncation",),
    "cell7": ("noise-below-1e-11",),
    "cell7/crease": ("crease-fd-zero",),
    "cell7/pole": ("pole-pixels",),
    "s6": ("stacking",),
    "s8": ("blinn-exact",),
}


def section_of(place):
    """The section label of ``place``: the place itself, or the part before its ``/``."""
    return place.split("/", 1)[0]


def place_of(claim_id):
    """The place (a key of `PLACES`) where ``claim_id``'s margin note is shown.

    Raises
    ------
    KeyError
        If ``claim_id`` is not the id of a claim of `lab.claims.CLAIMS` placed in `PLACES`.
    """
    place = next((place for place, ids in PLACES.items() if claim_id in ids), None)
    if place is None or claim_id not in NUMBERS:
        raise KeyError(f"claim_id must be the id of a claim of lab.claims.CLAIMS placed in PLACES, got {claim_id!r}")
    return place


def measurement(claim_id):
    """The measured values of the claim ``claim_id`` (its `lab.claims.Claim.measure` dict), from the
    evaluation its margin note shows, for a page to glue.

    Raises
    ------
    KeyError
        As `place_of`.
    lab.claims.ClaimChanged
        If a computed verdict is not the registered one.
    """
    return _results(PLACES[place_of(claim_id)])[claim_id][1]


def _results(ids=None):
    """{claim id: (claim, measured, verdict)}, checked against the register.  Inside a book
    build the whole register is one measurement shared by every page (`lab.claims.checked`);
    elsewhere (a downloaded notebook) only the claims ``ids`` are measured."""
    from .page import in_book_build
    if ids is None or in_book_build():
        return {c.id: (c, m, v) for c, m, v in checked()}
    return {c.id: (c, m, v) for c, m, v in checked([(c, *c.measure()) for c in CLAIMS if c.id in ids])}


def _note(claim, verdict):
    return (f"```{{margin}}\n**Draft {claim.where}:** “{claim.quote}” — {{term}}`{WORDS[verdict]}` "
            f"({{ref}}`why <claim-{claim.id}>`)\n```")


def margin_notes(place):
    """MyST markdown for the section labelled ``place``: one margin note (sphinx-book-theme's
    ``margin`` directive) per claim placed there (`PLACES`), in order: the draft's words
    (``where``, ``quote``), the verdict as a ``{term}`` link to the glossary, and a ``{ref}``
    link to the claim's row of the register (`register`).

    Raises
    ------
    KeyError
        If ``place`` is not a key of `PLACES`.
    lab.claims.ClaimChanged
        If a computed verdict is not the registered one.
    """
    if place not in PLACES:
        raise KeyError(f"place must be one of {sorted(PLACES)}, got {place!r}")
    results = _results(PLACES[place])
    return "\n\n".join(_note(claim, verdict) for claim, _, verdict in (results[i] for i in PLACES[place])) + "\n"


def register():
    """MyST markdown: the register of §6, one entry per claim in `lab.claims.CLAIMS`
    order, each with the target ``claim-<id>``, its verdict (a ``{term}`` link), the
    measurement in words (`chapter.claim_words.measured_text`), the rule that decided it
    (`chapter.claim_words.rule_text`), and a link to the section whose margin note shows it
    (`margin_notes`).

    Raises
    ------
    lab.claims.ClaimChanged
        If a computed verdict is not the registered one.
    """
    results = _results()
    entries = []
    for c in CLAIMS:
        n, (claim, measured, verdict) = NUMBERS[c.id], results[c.id]
        entries.append(
            f"(claim-{c.id})=\n"
            f"**{n}. {claim.where}:** “{claim.quote}” (noted in {{ref}}`{section_of(place_of(c.id))}`). "
            f"**{{term}}`{WORDS[verdict]}`**: {measured_text(c.id, measured)}; rule: "
            f"{rule_text(claim.criterion)}.\n")
    return "\n".join(entries)
