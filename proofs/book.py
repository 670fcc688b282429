"""Render theorems for the book: MyST markdown with sphinx-proof directives.

A code cell displays ``Markdown(theorem_block("frame-orthonormal"))``; myst-nb
parses the output as MyST (``nb_render_markdown_format: myst``), so the
statement and the argument shown are the proof object's, and the badge is the
verdict its check returned during this build.  A theorem that does not hold
raises, and the cell error fails the build.
"""

from __future__ import annotations

from .core import step_latex
from .registry import THEOREMS, get

__all__ = ["theorem_block", "ledger_table", "TheoremFailed"]

BADGES = {"proved": "PROVED", "verified": "VERIFIED numerically", "refuted": "REFUTED"}
_VERDICTS = {}


class TheoremFailed(AssertionError):
    """A theorem the book relies on did not hold during the build."""


def verdict(theorem_id):
    """The theorem's verdict, computed once per build (per kernel)."""
    if theorem_id not in _VERDICTS:
        _VERDICTS[theorem_id] = get(theorem_id).check()
    return _VERDICTS[theorem_id]


def theorem_block(theorem_id, *, label_prefix="thm-"):
    """MyST markdown: a prf:theorem with statement and badge, and a prf:proof with the steps.

    Raises
    ------
    TheoremFailed
        If the theorem's check does not return proved or verified.
    KeyError
        If the id is unknown.
    """
    t = get(theorem_id)
    v = verdict(theorem_id)
    if not v.holds:
        raise TheoremFailed(f"{theorem_id} is {v.status}: {v.evidence}")
    steps = "\n".join(f"- $\\displaystyle {step_latex(step)}$" for step in t.steps)
    evidence = v.evidence.replace("$", "")
    return (f":::{{prf:theorem}} {t.title}\n:label: {label_prefix}{theorem_id}\n\n{t.statement}\n\n"
            f"**{BADGES[v.status]}** (`{theorem_id}`): {evidence}\n:::\n\n"
            f":::{{prf:proof}}\n{steps}\n\nThe check: every identity above is decided by sympy "
            f"(or, failing that, evaluated with mpmath), and a wrong variant "
            f"({t.wrong_variants[0][0]}) is refuted by the same check.\n:::\n")


def ledger_table():
    """Markdown table of every theorem: id, verdict, evidence, the pages using it."""
    rows = ["| theorem | verdict | evidence | the draft says | used on |", "|---|---|---|---|---|"]
    for theorem_id, t in THEOREMS.items():
        v = verdict(theorem_id)
        pages = ", ".join(f"{{ref}}`{p}`" for p in t.pages)
        rows.append(f"| {{prf:ref}}`{t.title} <thm-{theorem_id}>` (`{theorem_id}`) | "
                    f"{BADGES[v.status]} | {v.evidence.replace('|', '/')} | "
                    f"{t.seed_says.replace('|', '/') or '—'} | {pages} |")
    return "\n".join(rows)
