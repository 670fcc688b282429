"""The book's prose types no number: every value it shows is glued from the
code that computes or uses it (``{glue:text}``, ``{glue:md}`` with
`proofs.book.glue_math`).

The scan reads each page's Markdown outside code cells, drops glue roles,
inline code, cross-references and link targets, and looks for numeric
literals: powers of ten (``10^{-6}``), e-notation, decimals, and integers of
three or more digits.  What is left must be in `QUOTED`: the draft's own
claims quoted in order to check them, and a year.  Wrong variant: a typed step
added to a page is found.
"""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest

BOOK = Path(__file__).resolve().parents[1] / "book"

NUMBER = re.compile(r"10\^\{-?\d+\}|\d+(?:\.\d+)?e-?\d+|\d+\.\d+|\d{1,3}(?:,\d{3})+|\d{1,3}(?:\{,\}\d{3})+|\d{3,}")

#: Literals that stay typed, per page, with how often they occur and why.
QUOTED = {
    "index.md": {"1978": (1, "Blinn's paper's year")},
    "s8_history.md": {"1978": (1, "Blinn's paper's year")},
    "s3_math.md": {"2,000": (1, "the draft's \"about 2,000\", quoted")},
    "s4_simulator.md": {"10^{-6}": (1, "the draft's \"near 1e-6\", quoted")},
    "s5_lab.md": {"10^{-6}": (2, "the draft's expected minimum, quoted and answered"),
                  "2,000": (1, "the draft's (pi k_u)^3, answered"),
                  "10^{-8}": (1, "the draft's cliff, quoted"),
                  "2{,}000": (1, "the draft's (pi k_u)^3, quoted"),
                  "2000": (1, "the draft's number of random cases, quoted"),
                  "10^{-9}": (1, "the draft's expected worst error, quoted"),
                  "10^{-12}": (2, "the draft's \"verified to 1e-12\", quoted and answered"),
                  "10^{-7}": (1, "the draft's own forward step, quoted"),
                  "10^{-16}": (2, "the draft's expected agreement at beta = 0, quoted and answered"),
                  "10^{-11}": (1, "the draft's \"noise\" threshold, quoted")},
    "s6_ledger.md": {"10^{-12}": (1, "the draft's \"verified to 1e-12\", quoted")},
}


def prose(text):
    """The page's prose: Markdown outside code cells, fenced code and display math, without
    glue roles, inline code, references, section numbers and link targets."""
    out, fence, directives = [], None, []
    for line in text.splitlines():
        s = line.strip()
        if fence is None and s.startswith("```"):
            head = s.lstrip("`")
            if directives and s == directives[-1]:
                directives.pop()                      # a directive's closing fence
            elif head.startswith(("{code-cell}", "{math}")) or not head.startswith("{"):
                fence = s[:len(s) - len(head)]        # a code cell or a code block: skipped
            else:
                directives.append(s[:len(s) - len(head)])   # a directive: its body is prose
            continue
        if fence is not None:
            if s == fence:
                fence = None
            continue
        if s.startswith(":") and ":" in s[1:]:        # a directive option (:name:, :alt:, :tags:)
            continue
        out.append(line)
    text = re.sub(r"\$\$.*?\$\$", " ", "\n".join(out), flags=re.S)   # display math: formulas
    text = re.sub(r"\{glue[:\w]*\}`[^`]*`|\{(?:ref|numref|doc|prf:ref)\}`[^`]*`|`[^`]*`|§[\d.]+", " ", text)
    text = re.sub(r"\]\([^)]*\)|^\(\w[\w-]*\)=$|^---$.*?^---$", " ", text, flags=re.M | re.S)
    return text


def typed_numbers(text):
    """Counter of the numeric literals in ``text``'s prose (`prose`)."""
    return Counter(m.group(0) for m in NUMBER.finditer(prose(text)))


@pytest.mark.parametrize("page", sorted(p.name for p in BOOK.glob("*.md")))
def test_no_number_is_typed_into_the_prose(page):
    found = typed_numbers((BOOK / page).read_text(encoding="utf-8"))
    allowed = Counter({k: n for k, (n, _) in QUOTED.get(page, {}).items()})
    assert found == allowed, (f"{page}: typed {sorted((found - allowed).elements())}, "
                              f"quoted but gone {sorted((allowed - found).elements())}")


def test_a_typed_step_is_found():
    """Wrong variants: a step, a size and a decimal typed into prose."""
    page = (BOOK / "s4_simulator.md").read_text(encoding="utf-8")
    assert typed_numbers(page) == Counter({"10^{-6}": 1})
    for typed, literal in (("at $\\varepsilon = 10^{-5}$", "10^{-5}"), ("at 512 × 512", "512"),
                           ("with $\\beta = 0.35$", "0.35"), ("step 1e-4 here", "1e-4")):
        assert typed_numbers(page + "\n\nThe frame " + typed + ".\n")[literal] >= 1, typed
    # Glued, the same values are not typed.
    assert typed_numbers(page + "\n\nAt {glue:md}`c1_eps_tex:myst`, {glue:text}`s4_size`.\n") == \
        Counter({"10^{-6}": 1})
