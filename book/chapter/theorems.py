"""Render theorems for the book: MyST markdown with sphinx-proof directives.

A code cell displays ``Markdown(theorem_block("frame-orthonormal"))``; myst-nb
parses the output as MyST (``nb_render_markdown_format: myst``), so the
statement and the argument shown are the proof object's, and the badge is the
verdict its check returned during this build.  A theorem that does not hold
raises, and the cell error fails the build.  Each theorem's check runs once
per build: its entry is a measurement of `lab.store`, which later pages
(§6's ledger) read.
"""

from __future__ import annotations

import html
import math
import re
from collections import Counter

from lab import store
from proofs.core import MATH

from . import latex
from .page import minus_signs

__all__ = ["theorem_block", "ledger_table", "ledger", "findings", "TheoremFailed", "tex_number", "glue_math",
           "badge", "code_words"]

BADGES = {"proved": "PROVED", "verified": "VERIFIED numerically", "refuted": "REFUTED"}
#: The badge of a verified theorem whose steps sympy all proved: what is numeric is its evidence.
BADGE_STEPS_PROVED = "STEPS PROVED · VERIFIED on renders"


def badge(status, numeric=()):
    """The badge a verdict earns: `BADGES` by ``status``, but for a ``"verified"`` verdict
    with no step left to mpmath (``numeric``, `Verdict.numeric`, empty) `BADGE_STEPS_PROVED`:
    sympy proved every step, and what was checked numerically is the renderer evidence.

    Raises
    ------
    KeyError
        If ``status`` is not proved, verified or refuted.
    """
    if status not in BADGES:
        raise KeyError(f"status must be one of {sorted(BADGES)}, got {status!r}")
    return BADGE_STEPS_PROVED if status == "verified" and not numeric else BADGES[status]


#: What reader-facing text must not contain (`code_words`): a name from the code, constant-shaped
#: (KINK_BAND, STENCIL_POINTS) or a dotted path (renderer.formulas, kernel.reach), a constant
#: set as code (`GRADIENT`), or "seed" (the book calls the source document "the draft").
_CODE_WORD = re.compile(r"\b[A-Z][A-Z0-9]*_[A-Z0-9_]*\b|\b[A-Za-z_]\w+\.[A-Za-z_]\w+|`[^`]*\b[A-Z]{2,}\b[^`]*`|"
                        r"\b(?!(?:RMS|LLVM|SIMD|CPU)\b)[A-Z]{3,}\b")
_SEED = re.compile(r"\bseed\b", re.IGNORECASE)
#: ... and, in mathematics too, a constant's name set upright (\mathrm{CENTRAL}).
_UPRIGHT_CONSTANT = re.compile(r"\\mathrm\{[A-Z][A-Z0-9_]+\}")


def code_words(text):
    """The tokens of ``text`` (a theorem's title, statement, step sentence or evidence) that
    read as code or audit vocabulary: outside its ``$...$`` mathematics, constant-shaped
    names (``KINK_BAND``; ``CIRCLES``, three capitals or more that are not an acronym the book uses:
    RMS, LLVM, SIMD, CPU), dotted paths (``renderer.formulas``), code spans holding a
    constant (```GRADIENT```) and the word "seed"; anywhere, a constant's name set upright
    (``\\mathrm{CENTRAL}``).  An empty list is text a reader can read.

    Parameters
    ----------
    text : str

    Returns
    -------
    list of str
        The offending tokens, in order.
    """
    prose = MATH.sub(" ", text)
    return ([m.group(0) for m in _CODE_WORD.finditer(prose)] + [m.group(0) for m in _SEED.finditer(prose)]
            + _UPRIGHT_CONSTANT.findall(text))


def tex_number(x) -> str:
    """A number as the prose's LaTeX writes it: a power of ten as ``10^{-6}``,
    another number below 0.01 as ``5\\cdot 10^{-4}`` (three significant
    digits at most), the rest as ``%g`` (``0.47``, ``1.5``, ``256``).

    Raises
    ------
    ValueError
        If ``x`` is not a finite real number.
    """
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"x must be a finite number, got {x!r}")
    if x == 0 or abs(x) >= 0.01:
        return f"{x:g}"
    mantissa, exponent = f"{x:.2e}".split("e")
    mantissa = mantissa.rstrip("0").rstrip(".")
    power = f"10^{{{int(exponent)}}}"
    if mantissa in ("1", "-1"):
        return power if mantissa == "1" else f"-{power}"
    return f"{mantissa}\\cdot {power}"


def glue_math(name, x):
    """Glue ``x`` under ``name`` as inline math (`tex_number`), for prose that
    shows it with ``{glue:md}`name:myst```: ``$10^{-6}$`` where a plain glue
    would print ``1e-06``.  Raises ValueError, as `tex_number`, for a
    non-finite ``x``."""
    from IPython.display import Markdown
    from myst_nb import glue
    glue(name, Markdown(f"${tex_number(x)}$"), display=False)


class TheoremFailed(AssertionError):
    """A theorem the book relies on did not hold during the build."""


def _prose(text):
    """A step's sentence as MyST: ``*`` and ``_`` escaped outside code and math spans (not emphasis)."""
    parts = re.split(r"(`[^`]*`|\$[^$]*\$)", text)
    return "".join(p if p[:1] in "`$" and p else re.sub(r"([*_])", r"\\\1", p) for p in parts)


def _cited(text):
    """``text`` with each citation ``⟪id⟫`` (`proofs.core.CITATION`) as MyST: a bare
    ``{prf:ref}`thm-<id>``` (sphinx-proof prints it "Theorem n", linked to the box) and the
    theorem's title in parentheses.

    Raises
    ------
    KeyError
        A cited id that is no theorem of the registry (the check refutes it first).
    """
    from proofs.core import CITATION
    from proofs.registry import CITABLE

    def ref(m):
        if m.group(1) not in CITABLE:
            raise KeyError(f"no theorem {m.group(1)!r} to cite")
        return f"{{prf:ref}}`thm-{m.group(1)}` ({CITABLE[m.group(1)]})"
    return CITATION.sub(ref, text)


def _chains(steps):
    """The proof's calc chains (`proofs.core.chains`): lists of (step number, step)."""
    from proofs.core import chains
    return [[(k + 1, steps[k]) for k in range(first, last + 1)] for first, last in chains(steps)]


def _proof(t, numeric=(), note=None):
    """``t``'s proof as MyST: ``note`` (what was checked numerically, `_numeric_note`) first, then each
    step "**Step k.** Sentence" with the definitions it introduces (``where ...``), a step of ``numeric``
    followed by why sympy left it (`Step.why_numeric`), and after the steps of each calc chain one display
    of the chain (`chapter.latex.chain`): one relation a line, each "=" of a chain of several steps marked
    "(k)" with the step that proves it; no display starts with "="."""
    out = [note] if note else []
    for run in _chains(t.steps):
        numbers = [k for k, _ in run]
        for k, step in run:
            why = _prose(_cited(step.why.rstrip(".:")))
            where = ", ".join(f"${latex.definition(t, s, inline=True)}$" for s in step.defines)     # in the sentence
            aside = (f" (Checked numerically: {_prose(_cited(step.why_numeric))}.)" if k in numeric else "")
            out.append(f"**Step {k}.** {why}" + (f", where {where}" if where else "")
                       + ("." if k != run[-1][0] else ":") + aside)
        out.append(f"$$\n{latex.chain(t, [s for _, s in run], numbers)}\n$$")
    return "\n\n".join(out)


def _numeric_note(t, v):
    """The proof's opening sentence for the steps sympy left to mpmath (`Verdict.numeric`): which,
    at how many points, to how many digits and the worst residual (each step then says why,
    `Step.why_numeric`; `_proof`), as MyST, or None; and why the box cannot be shown (or None):
    a numeric step without a reason, or a reason on a step sympy proved.  The renderer evidence
    is §6's (`ledger_table`), not the box's."""
    numeric = v.numeric
    stale = [k for k, s in enumerate(t.steps, 1) if s.why_numeric and k not in numeric]
    unexplained = [k for k in numeric if not t.steps[k - 1].why_numeric]
    if unexplained or (stale and v.status in ("proved", "verified")):
        k = (unexplained or stale)[0]
        return None, (f"{t.id}: step {k} was verified numerically but its proof does not say why "
                      "(Step.why_numeric)" if unexplained else
                      f"{t.id}: step {k} says why sympy cannot decide it (Step.why_numeric), but sympy proved it")
    if v.status != "verified" or not numeric:
        return None, None
    many = len(numeric) > 1
    return (f"*Step{'s' if many else ''} {', '.join(map(str, numeric))} {'are' if many else 'is'} checked "
            f"numerically, not proved:* sympy cannot decide {'them' if many else 'it'} (each says why), so "
            f"{'they were' if many else 'it was'} evaluated at {v.points} random points to {v.digits} digits, "
            f"with worst residual {v.residual:.1e}."), None


def _entry(t):
    from proofs.registry import verdict_failure
    v = t.check()
    note, unexplained = _numeric_note(t, v)
    steps = _proof(t, v.numeric if v.status == "verified" else (), note)
    block = (f":::{{prf:theorem}} {t.title}\n:label: thm-{t.id}\n\n{_cited(latex.statement(t))}\n\n"
             f"**{badge(v.status, v.numeric)}** · evidence: {{ref}}`§6 <ledger-{t.id}>`\n:::\n\n"
             f"::::{{dropdown}} Proof\n:::{{prf:proof}}\n{steps}\n:::\n::::\n")   # folded: the statement reads first
    return dict(title=t.title, status=v.status, badge=badge(v.status, v.numeric), evidence=v.evidence,
                block=block, unexplained=unexplained,
                changed=verdict_failure(t.id, v))


def _ledger():
    from proofs.registry import THEOREMS
    return {theorem_id: _entry(t) for theorem_id, t in THEOREMS.items()}


def ledger():
    """{theorem id: entry} for every theorem, in the registry's order; an entry
    holds the title, the verdict (``status``, ``evidence``), what the draft
    says, the pages and the MyST ``block``.  One measurement of the build
    (`lab.store`): every check runs once, in the first page that needs
    any, and the later pages read the verdicts it reached."""
    return store.measured("theorem-ledger", _ledger)


def theorem_block(theorem_id):
    """MyST markdown: a prf:theorem (label ``thm-<id>``) with the statement and the
    badge line, which links to the theorem's ledger row (``ledger-<id>``, `ledger_table`),
    and a folded prf:proof with the steps, each a sentence and an equation (a VERIFIED
    theorem's opening with what was checked numerically, each such step saying why).

    Raises
    ------
    TheoremFailed
        If the theorem's check does not return proved or verified, or not
        the verdict `proofs.registry.PINNED` holds for it, or a step verified
        numerically does not say why (`Step.why_numeric`; `_numeric_note`).
    KeyError
        If the id is unknown.
    """
    entries = ledger()
    if theorem_id not in entries:
        raise KeyError(f"no theorem {theorem_id!r}")
    _refuse(theorem_id, entries[theorem_id])
    return entries[theorem_id]["block"]


def _refuse(theorem_id, entry):
    if entry["status"] not in ("proved", "verified"):
        raise TheoremFailed(f"{theorem_id} is {entry['status']}: {entry['evidence']}")
    if entry.get("unexplained"):
        raise TheoremFailed(entry["unexplained"])
    if entry["changed"]:
        raise TheoremFailed(f"{entry['changed']} (proofs.registry.PINNED, RENDERED): {entry['evidence']}")


#: A name from the code in a checker's text (``TANGENT_FRAME``, ``t_A``, ``PERTURBED_NORMAL['surface']``).
_CODE_NAME = re.compile(r"(?<![\w>])([A-Za-z][\w.]*_[\w.]*(?:\['\w+'\])?)")


def _folded(label, text):
    """Raw HTML: ``label`` and ``text`` up to its first semicolon, the rest folded
    into a <details> the reader opens; the code's names in it set as code, its negative numbers with
    the minus sign (`chapter.page.minus_signs`: raw HTML escapes the build's own typesetting)."""
    head, _, rest = (_CODE_NAME.sub(r"<code>\1</code>", html.escape(minus_signs(t), quote=False))
                     for t in text.partition("; "))
    return f"<details><summary>{label}: {head}</summary>{rest}</details>" if rest else f"<p>{label}: {head}</p>"


def ledger_table():
    """MyST markdown, one list item per theorem, labelled ``ledger-<id>`` (the theorem's box
    links here with ``{ref}`§6 <ledger-<id>>```): "Theorem n" (linked to the box), its title, id,
    verdict; then its evidence (what its steps took, and the
    renderer's outputs compared), the first clause shown and the rest folded.  (What the
    draft says about a theorem is in the claims register, `chapter.verdicts.register`.)  (A list, not a table: the evidence is a
    paragraph, which a table column of a 700-pixel page squeezes to a word a line.)

    Raises
    ------
    TheoremFailed
        As `theorem_block`, for the first theorem whose verdict fails or changed.
    """
    items = []
    for theorem_id, e in ledger().items():
        _refuse(theorem_id, e)
        items.append(f"* (ledger-{theorem_id})=\n  {{prf:ref}}`thm-{theorem_id}` ({e['title']}), `{theorem_id}`: "
                     f"**{e['badge']}**.\n\n"
                     f"  {_folded('Evidence', e['evidence'])}")
    return "\n".join(items)


def findings():
    """What the build found, for the book's front page: a dict of counts.

    ``theorems``: {status: count} over the theorem ledger; ``claims``: {verdict:
    count} over the draft's claims register (`lab.claims.checked`);
    ``errata``: the number of defects of the draft's code the book records
    (§6 re-measures each with `lab.seed_errata.reproduced`, and its build
    fails if one vanished).  Reads the build's measurements (`ledger`, the
    register), computing what is missing.

    Raises
    ------
    TheoremFailed, lab.claims.ClaimChanged
        As the pages that show the ledger and the register.
    """
    from lab.claims import checked
    from lab.seed_errata import ERRATA
    entries = ledger()
    for theorem_id, entry in entries.items():
        _refuse(theorem_id, entry)
    return {"theorems": dict(Counter(e["status"] for e in entries.values())),
            "claims": dict(Counter(verdict for _, _, verdict in checked())), "errata": len(ERRATA)}
