"""The book's prose types no number: every value it shows is glued from the
code that computes or uses it (``{glue:text}``, ``{glue:md}`` with
`chapter.theorems.glue_math`).

The scan reads each page's Markdown outside code cells, drops glue roles,
inline code, cross-references and link targets, and looks for numeric
literals: powers of ten (``10^{-6}``), e-notation, decimals, and integers of
three or more digits.  What is left must be in `QUOTED`: the draft's own
claims quoted in order to check them (a cited work's year comes from
book/references.bib through a ``{cite:t}``/``{cite:p}`` role, whose keys have no
digits).  Wrong variant: a typed step added to a page is found.
"""

from __future__ import annotations

import ast
import re
from collections import Counter
from pathlib import Path

import pytest

from .pages import code_cells, parse_cell

BOOK = Path(__file__).resolve().parents[1] / "book"

NUMBER = re.compile(r"10\^\{-?\d+\}|\d+(?:\.\d+)?e-?\d+|\d+\.\d+|\d{1,3}(?:,\d{3})+|\d{1,3}(?:\{,\}\d{3})+|\d{3,}")

#: Literals that stay typed, per page, with how often they occur and why.  (The draft's
#: claims are quoted from the register, `lab.claims`, not typed into the pages.)
QUOTED: dict[str, dict[str, tuple[int, str]]] = {}


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
    assert typed_numbers(page) == Counter()
    for typed, literal in (("at $\\varepsilon = 10^{-5}$", "10^{-5}"), ("at 512 × 512", "512"),
                           ("with $\\beta = 0.35$", "0.35"), ("step 1e-4 here", "1e-4")):
        assert typed_numbers(page + "\n\nThe frame " + typed + ".\n")[literal] >= 1, typed
    # Glued, the same values are not typed.
    assert typed_numbers(page + "\n\nAt {glue:md}`c1_eps_tex:myst`, {glue:text}`s4_size`.\n") == \
        Counter()



#: A number in a code comment: a decimal, e-notation, or an integer other than a lone 0 or 1 (the
#: 1 of "1/k_u" is a formula's, not a value's).
COMMENT_NUMBER = re.compile(r"(?<![\w.])(?:\d+\.\d+|\d+e-?\d+|\d{2,}|[2-9])(?![\w.])")


def commented_numbers(text):
    """The numbers typed in the comments of ``text``'s code cells (a page that is no notebook has none)."""
    import io
    import tokenize
    found = []
    for source in code_cells(text) or []:
        for token in tokenize.generate_tokens(io.StringIO(source).readline):
            if token.type == tokenize.COMMENT:
                found += COMMENT_NUMBER.findall(token.string)
    return found


@pytest.mark.parametrize("page", sorted(p.name for p in BOOK.glob("*.md")))
def test_no_number_is_typed_into_a_code_comment(page):
    """A comment repeats no value: the code that holds it is beside it, or the page glues it."""
    assert commented_numbers((BOOK / page).read_text(encoding="utf-8")) == [], page


def test_a_number_typed_into_a_comment_is_found():
    """Wrong variants: a count, a size, a step and a decimal in a comment; a formula's 1 is none."""
    page = (BOOK / "s5_lab.md").read_text(encoding="utf-8")
    assert commented_numbers(page) == []
    cell = "\n```{code-cell} ipython3\nx = 1   # %s\n```\n"
    for typed, literal in (("197 steps", "197"), ("256 x 256", "256"), ("eps = 1e-3", "1e-3"),
                           ("beta = 0.35", "0.35"), ("a 50-digit reference", "50"), ("at 4 points", "4")):
        assert literal in commented_numbers(page + cell % typed), typed
    assert commented_numbers(page + cell % "the crease u = 1/k_u") == []


# ------------------------------------------------------------- scene and resolution labels
ROOT = BOOK.parent
#: A glue whose name ends so carries the scene or resolution of a render (e.g. "256 × 256",
#: `chapter.labels.frame_label`'s "the draft's scene with the sine field, 64 × 64").
#: A glue ``*_measured`` is a claim's measurement text, which ends with its frame (`lab.claims`).
LABEL = re.compile(r"(_size|_label|_measured)$")
CELL = re.compile(r"```\{code-cell\}[^\n]*\n(.*?)\n```", re.S)      # to drop cells from the prose
GLUE_DEF = re.compile(r"\bglue(?:_math)?\(\s*(f?)[\"']([^\"']+)[\"']")
GLUE_USE = re.compile(r"\{glue(?::\w+)?\}`([^`:]+)|```\{glue:figure\}\s*(\S+)")


#: Functions of proofs/ that render but whose numbers on the pages are not measured on a
#: frame of the scene, with why.
NOT_A_FRAME = {
    "theorem_block": "a theorem's verdict; its evidence names the pixels and renders it checked",
    "ledger_table": "the theorems' verdicts, as theorem_block",
    "findings": "counts of theorems and claims by verdict",
    "checked": "the claims register's verdicts; each row's method names its frame",
    "reproduced": "the errata's measurements, each reported with its own frame in its text",
}


def rendering_functions():
    """Names that render, as a page cell calls them: `renderer.render`, `renderer.gbuffer`,
    and every function of proofs/ and lab/ whose body names one of them (calls it, or hands it to
    `lab.store.measured`), to a fixed point, less `NOT_A_FRAME`.  Matched by name, so a
    homonym (ucurve.measure and gradient_benchmark.measure) asks for one label too many."""
    names = {}
    for path in sorted([*(ROOT / "proofs").glob("*.py"), *(ROOT / "lab").glob("*.py")]):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                names.setdefault(node.name, set()).update(
                    n.id if isinstance(n, ast.Name) else n.attr
                    for n in ast.walk(node) if isinstance(n, (ast.Name, ast.Attribute)))
    found = {"render", "gbuffer"}
    while True:
        more = {f for f, used in names.items() if used & found} - found
        if not more:
            return found - set(NOT_A_FRAME)
        found |= more


def blocks(text):
    """The page's prose in units that must carry a label: a glued figure with its caption, a
    paragraph, a table row.  Yields (glue names used, glue names of the labels in force): its
    own; for a table row, the paragraph before its table; and the section's, a label in the
    first paragraph under a heading, which holds for the section ("Frames: ...")."""
    text = CELL.sub("", text)
    section, first = [], False
    for chunk in re.split(r"(```\{glue:figure\}.*?\n```)", text, flags=re.S):
        if chunk.startswith("```{glue:figure}"):
            names = [a or b for a, b in GLUE_USE.findall(chunk)]
            yield names, names + section
            continue
        before = []
        for para in re.split(r"\n\s*\n", chunk):
            if re.search(r"^#{1,6} ", para, re.M):
                section, first = [], True
                continue
            rows = para.strip().splitlines()
            if rows and all(r.lstrip().startswith("|") for r in rows):
                for row in rows:
                    names = [a or b for a, b in GLUE_USE.findall(row)]
                    yield names, names + before + section
                continue
            before = [a or b for a, b in GLUE_USE.findall(para)]
            if first and para.strip():
                section, first = [n for n in before if LABEL.search(n)], False
            yield before, before + section


def _bound(target):
    """The variable names an assignment target binds: ``a``, ``a, b``, and ``a`` for ``a[k]`` or ``a.x``."""
    while isinstance(target, (ast.Subscript, ast.Attribute, ast.Starred)):
        target = target.value
    if isinstance(target, (ast.Tuple, ast.List)):
        return [name for t in target.elts for name in _bound(t)]
    return [target.id] if isinstance(target, ast.Name) else []


def _loaded(tree):
    """The variable names ``tree`` reads."""
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}


def _assignments(tree):
    """(value, bound names) of each assignment and for loop in ``tree``."""
    for node in ast.walk(tree):
        if isinstance(node, ast.For):
            yield node.iter, _bound(node.target)
        elif isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)) and node.value is not None:
            yield node.value, [n for tg in getattr(node, "targets", [getattr(node, "target", None)])
                               for n in _bound(tg)]


def _rebound(tree, call, tainted):
    """Names ``tree`` binds from values that owe nothing to a render (a loop variable reused)."""
    return {n for value, names in _assignments(tree)
            if not (call.search(ast.unparse(value)) or _loaded(value) & tainted) for n in names}


def rendering_cells(text, renders):
    """The code cells of a page whose values come from a render: a cell that calls one of
    ``renders`` or names a variable holding a render's result, a variable assigned from
    such a call or such a variable (in that cell or an earlier one)."""
    call = re.compile(r"\b(" + "|".join(sorted(renders)) + r")\s*\(")
    tainted, out = set(), []
    for cell in code_cells(text) or []:
        tree = parse_cell(cell)
        if not (call.search(cell) or (_loaded(tree) - _rebound(tree, call, tainted)) & tainted):
            continue
        out.append(cell)
        for value, names in _assignments(tree):
            if call.search(ast.unparse(value)) or _loaded(value) & tainted:
                tainted |= set(names)
    return out


def unlabelled(text, renders):
    """[glue names] of ``text``'s blocks that show a number glued by a cell of
    `rendering_cells` without a scene/resolution label (a glue named ``*_size``, ``*_label``)."""
    derived = [re.compile((re.sub(r"\\\{[^}]*\\\}", ".+", re.escape(n)) if f else re.escape(n)) + "$")
               for cell in rendering_cells(text, renders) for f, n in GLUE_DEF.findall(cell)]
    return [names for names, label in blocks(text)
            if any(d.match(n) for n in names for d in derived if not LABEL.search(n))
            and not any(LABEL.search(n) for n in label)]


@pytest.mark.parametrize("page", sorted(p.name for p in BOOK.glob("*.md")))
def test_every_rendered_number_names_its_resolution(page):
    """A number measured on a render is shown beside its scene's resolution (or label)."""
    assert unlabelled((BOOK / page).read_text(encoding="utf-8"), rendering_functions()) == []


def test_an_unlabelled_rendered_number_is_found():
    """Wrong variants: a label dropped from a caption, from a table's intro, and a new cell
    that renders through a proofs/ function with a paragraph that does not say at what size."""
    renders = rendering_functions()
    assert {"render", "gbuffer", "image_beta_order", "census", "gradient_accuracy"} <= renders
    assert "tex_number" not in renders
    s4 = (BOOK / "s4_simulator.md").read_text(encoding="utf-8")
    assert unlabelled(s4.replace("The opening frame ({glue:text}`s4_label`):", "The opening frame:"), renders)
    assert unlabelled(s4.replace("({glue:text}`s4_label`):", "({glue:text}`s4_max`):"), renders)
    front = s4[:s4.index("---", 3) + 4]                  # a page's front matter: it is a notebook
    cell = (front + "```{code-cell} ipython3\nfrom lab.accuracy import image_beta_order\n"
            "glue(\"x_slope\", image_beta_order()[\"median_slope\"])\n```\n\n")
    assert unlabelled(cell + "The slope is {glue:text}`x_slope:.2f`.\n", renders) == [["x_slope"]]
    assert unlabelled(cell + "The slope is {glue:text}`x_slope:.2f` ({glue:text}`x_label`).\n", renders) == []
    # A frame rendered in one cell, its number glued in a later one; a name the frame tainted,
    # rebound by a loop over plain values, is not a frame's.
    two = (front + "```{code-cell} ipython3\nfr = render(Scene(), 8, 8)\nk = fr.chamber.sum()\n```\n\n"
           "```{code-cell} ipython3\nfor k in (1, 2):\n    glue(\"x_k\", k)\n```\n\n"
           "```{code-cell} ipython3\nglue(\"x_n\", int(fr.chamber.sum()))\n```\n\n")
    assert unlabelled(two + "It has {glue:text}`x_n`.\n\nAnd {glue:text}`x_k`.\n", renders) == [["x_n"]]


# ------------------------------------------------------------------- code a reader is shown
#: The longest code cell a reader may be shown, in lines.
SHOWN_LINES = 25
#: Calls that are bookkeeping (handing values and figures to the prose), never shown to a reader.
BOOKKEEPING = re.compile(r"\b(glue|glue_math|show)\s*\(")


def shown_cells(text):
    """The code cells of a page whose source a reader can see (not tagged remove-input or
    remove-cell; hide-input folds the source but shows it on a click), as source strings."""
    out = []
    for head, body in re.findall(r"```\{code-cell\}[^\n]*\n((?::[^\n]*\n)*)(.*?)\n```", text, re.S):
        tags = re.search(r":tags:\s*\[([^\]]*)\]", head)
        if not (tags and {"remove-input", "remove-cell"} & {t.strip() for t in tags.group(1).split(",")}):
            out.append(body)
    return out


def shown_defects(text):
    """What a reader would be shown that they should not: cells over `SHOWN_LINES` lines, and
    bookkeeping calls (`BOOKKEEPING`)."""
    bad = []
    for cell in shown_cells(text):
        lines = cell.strip("\n").splitlines()
        if len(lines) > SHOWN_LINES:
            bad.append(f"{len(lines)} lines: {lines[0]!r}")
        bad += [f"bookkeeping: {line.strip()!r}" for line in lines if BOOKKEEPING.search(line)]
    return bad


@pytest.mark.parametrize("page", sorted(p.name for p in BOOK.glob("*.md")))
def test_a_reader_is_shown_short_cells_and_no_bookkeeping(page):
    assert shown_defects((BOOK / page).read_text(encoding="utf-8")) == []


def test_a_long_cell_or_a_shown_glue_is_found():
    """Wrong variants: a 26-line cell, a glue in a folded (hide-input) cell, a show() in a plain one;
    the same in a removed cell passes."""
    front = "---\njupytext: {}\n---\n"
    long = "```{code-cell} ipython3\n" + "x = 1\n" * (SHOWN_LINES + 1) + "```\n"
    folded = "```{code-cell} ipython3\n:tags: [hide-input]\nglue('a', 1)\n```\n"
    plain = "```{code-cell} ipython3\nshow('fig-a', fig)\n```\n"
    assert len(shown_defects(front + long)) == 1
    assert shown_defects(front + folded) == ["bookkeeping: \"glue('a', 1)\""]
    assert len(shown_defects(front + plain)) == 1
    removed = "```{code-cell} ipython3\n:tags: [remove-cell]\n" + "glue('a', 1)\n" * 30 + "```\n"
    assert shown_defects(front + removed) == []


#: A page's reference to a theorem's box, and the parenthesis after it: {prf:ref}`thm-id` (Title, ...).
#: Sphinx-proof prints a bare reference as the theorem's number ("Theorem 4").
THEOREM_REF = re.compile(r"\{prf:ref\}`([^`]*)`(?:\s*\(([^)]*)\))?")


def theorem_ref_problems(text):
    """What is wrong with the theorem references in ``text``: each must be bare (so that it shows the
    theorem's number), name a registered theorem, and be followed by a parenthesis that opens with
    the title its box shows.  Returns ([(theorem id, title)] found, [problems])."""
    from proofs.registry import THEOREMS
    found, problems = [], []
    for m in THEOREM_REF.finditer(text):
        target, after = m.group(1), " ".join((m.group(2) or "").split())
        theorem_id = target.removeprefix("thm-")
        if not target.startswith("thm-") or theorem_id not in THEOREMS:
            problems.append(f"{m.group(0)!r}: not a bare reference to a registered theorem")
            continue
        title = THEOREMS[theorem_id].title
        if not (after == title or after.startswith(title + ",")):
            problems.append(f"{m.group(0)!r}: not followed by its title ({title!r})")
        found.append((theorem_id, title))
    return found, problems


def test_a_page_refers_to_a_theorem_by_its_number_and_its_title():
    """Each {prf:ref} to a theorem on a page is bare (sphinx-proof shows its number) and followed by
    the title its box shows; a wrong id, a wrong title, a missing title or a reference shown by a
    title instead of the number is found (wrong variants)."""
    found = []
    for path in sorted(BOOK.glob("*.md")):
        refs, problems = theorem_ref_problems(path.read_text(encoding="utf-8"))
        assert problems == [], (path.name, problems)
        found += refs
    assert ("bump-vs-displacement", "Bump versus displacement") in found           # §7, pitfall 7
    for wrong in ("{prf:ref}`thm-bump-vs-displace` (Bump versus displacement)",
                  "{prf:ref}`thm-bump-vs-displacement` (Bump against displacement)",
                  "{prf:ref}`thm-bump-vs-displacement` proves",
                  "{prf:ref}`Bump versus displacement <thm-bump-vs-displacement>` (Bump versus displacement)"):
        assert len(theorem_ref_problems(wrong)[1]) == 1, wrong


EXERCISES_SENTENCE = re.compile(r"Exercises with folded solutions sit in (.+?);", re.S)


def pages_with_exercises(book=BOOK):
    """The labels (``s3``) of the pages holding an ``{exercise}`` directive."""
    return {p.stem.split("_")[0] for p in book.glob("s*.md") if re.search(r"^:::+\{exercise\}", p.read_text(), re.M)}


def exercises_named_by_the_index(text):
    """The page labels the index's sentence on exercises refers to, or None without that sentence."""
    m = EXERCISES_SENTENCE.search(text)
    return None if m is None else set(re.findall(r"\{ref\}`(s\d)`", m.group(1)))


def test_the_index_names_every_page_with_exercises():
    assert exercises_named_by_the_index((BOOK / "index.md").read_text()) == pages_with_exercises()


def test_a_page_with_exercises_left_out_of_the_index_is_found(tmp_path):
    for p in BOOK.glob("s*.md"):
        (tmp_path / p.name).write_text(p.read_text())
    (tmp_path / "s8_history.md").write_text("::::{exercise} New\n:label: ex-new\n::::\n")
    assert exercises_named_by_the_index((BOOK / "index.md").read_text()) != pages_with_exercises(tmp_path)


def fields_left_unsaid(text):
    """The registered height fields (`renderer.formulas.FIELDS`) §2's words leave out: its list (an item
    ``* **name**``), its map's alt text and its summary (the "In short" box)."""
    from renderer.formulas import FIELDS
    alt = re.search(r"^:alt: (.*)$", text.split("```{glue:figure} fig-s2-fields", 1)[-1], re.M)
    summary = re.search(r"^:::\{admonition\} In short\n(.*?)^:::$", text, re.M | re.S)
    where = {"list": lambda name: f"* **{name}**" in text,
             "the map's alt text": lambda name: alt is not None and name.lower() in alt.group(1).lower(),
             "the summary": lambda name: summary is not None and name.lower() in summary.group(1).lower()}
    return [f"{name} not in {part}" for name in FIELDS for part, said in where.items() if not said(name)]


def test_the_scene_page_describes_every_registered_field():
    """The one part of a new field written by hand, §2's words about it (`renderer.formulas.register` says so),
    is there for each field; a field unsaid is found (wrong variant: rings dropped from each place)."""
    text = (BOOK / "s2_scene.md").read_text(encoding="utf-8")
    assert fields_left_unsaid(text) == []
    unsaid = text.replace("* **rings**", "* **circles**").replace("rings is a set", "the last is a set")
    unsaid = unsaid.replace("rings varies in $v$ only", "the last varies in $v$ only")
    assert fields_left_unsaid(unsaid) == ["rings not in list", "rings not in the map's alt text", "rings not in the summary"]
