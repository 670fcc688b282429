"""What a book page calls to put a number, a figure or a block of text on the page.

`glue`, `show` and `markdown` are the only ways a page hands what it computed
to the reader.  Inside a book build (a page kernel the build started, which it
marks with ``SYMRENDER_BOOK_BUILD=1``) `glue` and `show` glue the value with
myst-nb under a name, for the prose's ``{glue:text}`` roles and
``{glue:figure}`` directives, and `markdown` hands myst-nb MyST to render.
Anywhere else (a page downloaded as a notebook and run in Jupyter, whose prose
already holds the values the build computed) there is nothing to glue to:
`show` displays the figure where it was made, `glue` does nothing (neither
needs myst-nb), and `markdown` shows its text as the plain Markdown Jupyter
renders (`plain_markdown`: a cross-reference becomes its title, a directive
its body).  book/_ext/notebooks.py writes the downloaded notebooks' prose with
the same `plain_markdown`.

`show` refuses a figure whose text overlaps (`chapter.layout.text_overlaps`),
so the build fails on one instead of publishing it.
"""

from __future__ import annotations

import os
import re

__all__ = ["glue", "show", "markdown", "table", "plain_markdown", "plain_role", "plain_directive", "plain_exercise",
           "minus_signs", "HYPHEN_MINUS", "EXERCISE_FORMS", "BUILD_ENV",
           "in_book_build", "FigureLayoutError"]

#: Set (to "1") by the book build (book/_ext/measurement_store.py) for the kernels it starts.
BUILD_ENV = "SYMRENDER_BOOK_BUILD"

#: A glued name, as the prose's roles can spell it (``{glue:text}`name:fmt```).
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")


class FigureLayoutError(ValueError):
    """A figure's text artists overlap one another."""


#: A hyphen-minus that makes a number negative: before a digit, and not after a letter, a digit, a
#: point, a slash, a caret or another dash (an exponent's ``1e-12``, ``k-1``, a range ``3-5``, a path).
HYPHEN_MINUS = re.compile(r"(?<![\w.\-−/^])-(?=\d)")


def minus_signs(text: str) -> str:
    """``text`` with each negative number's hyphen-minus the minus sign U+2212: "−0.651", as
    typeset (a screen reader says "minus"; the hyphen is read as a dash or not at all).  An
    exponent keeps its hyphen, "1.3e-12", as the book writes it.  Python formats a negative
    number with a hyphen; the book build (book/_ext/a11y_markup.py) applies this to the prose
    of every page, and book/_ext/notebooks.py to the values it writes into the notebooks."""
    return HYPHEN_MINUS.sub("−", text)


def in_book_build() -> bool:
    """Whether this process is a page kernel of the book build."""
    return os.environ.get(BUILD_ENV) == "1"


def _check_name(name):
    if not isinstance(name, str):
        raise TypeError(f"name must be a str, got {type(name).__name__}")
    if not _NAME.fullmatch(name):
        raise ValueError("name must be letters, digits, '_', '.' or '-', not starting with '.' or '-' "
                         f"(a glue role's name), got {name!r}")


def glue(name, value):
    """Glue ``value`` under ``name`` for the page's prose (myst-nb), without displaying it.

    Parameters
    ----------
    name : str
        Letters, digits, ``_ . -``: the name the prose's ``{glue:text}`` (or
        ``{glue:md}``, ``{glue:figure}``) role or directive uses.
    value : object
        Anything IPython can display: a number or str (its ``repr`` is the
        text/plain a ``{glue:text}`name:fmt``` formats), an
        ``IPython.display.Markdown``, a matplotlib Figure.

    Outside a book build nothing is glued and myst-nb is not imported (a
    downloaded notebook needs neither).  Returns None, as myst-nb's ``glue``
    does, so a call ending a cell shows no output.

    Raises
    ------
    TypeError
        ``name`` is not a str.
    ValueError
        ``name`` is not of that form.
    ImportError
        Inside a book build, if myst-nb is not installed.
    """
    _check_name(name)
    if in_book_build():
        from myst_nb import glue as nb_glue
        nb_glue(name, value, display=False)


def show(name, fig):
    """Put the matplotlib Figure ``fig`` on the page, then close it.

    Inside a book build it is glued under ``name`` (for the page's
    ``{glue:figure}`` directive, which numbers and captions it); anywhere else
    it is displayed here, as the cell's output (``IPython.display.display``:
    a PNG in Jupyter, with the settings `chapter.figures.style` made), its
    output metadata ``{"symrender": {"figure": name}}`` naming it.  Either
    way the figure is closed, so Jupyter's inline backend does not draw it a
    second time.  Returns None.

    Raises
    ------
    TypeError
        ``name`` is not a str, or ``fig`` is not a ``matplotlib.figure.Figure``.
    ValueError
        ``name`` is not of the form `glue` accepts.
    FigureLayoutError
        If two of the figure's text artists overlap (the message names them);
        the figure is closed.
    ImportError
        Outside a book build, if IPython is not installed (the project's
        ``notebook`` extra brings it).
    """
    _check_name(name)
    from matplotlib.figure import Figure
    if not isinstance(fig, Figure):
        raise TypeError(f"fig must be a matplotlib.figure.Figure, got {type(fig).__name__}")
    import matplotlib.pyplot as plt

    from .layout import text_overlaps
    try:
        clashes = text_overlaps(fig)
        if clashes:
            raise FigureLayoutError(f"figure {name!r}: text overlaps: " + "; ".join(clashes))
        if in_book_build():
            glue(name, fig)
        else:
            try:
                from IPython.display import display
            except ImportError as error:
                raise ImportError("chapter.page.show displays a figure with IPython outside a book build; "
                                  "install it (the project's notebook extra: ipykernel)") from error
            display(fig, metadata={"symrender": {"figure": name}})
    finally:
        plt.close(fig)


def markdown(text):
    """The MyST markdown ``text`` as an ``IPython.display.Markdown`` (a cell ending with
    it shows it): as it is inside a book build, where myst-nb renders MyST; as
    `plain_markdown` anywhere else, where Jupyter renders CommonMark and would show
    MyST's roles and directives as they are written.

    Raises
    ------
    TypeError
        ``text`` is not a str.
    """
    if not isinstance(text, str):
        raise TypeError(f"text must be a str of MyST markdown, got {type(text).__name__}")
    from IPython.display import Markdown
    return Markdown(text if in_book_build() else plain_markdown(text))


def table(header, rows):
    """A Markdown table (`markdown`) of a header and rows of formatted cells, each a sequence of str
    as long as the header."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return markdown("\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows]))


# --- MyST -> plain Markdown ----------------------------------------------------------------------

#: A role (``{name}`content```) or, so that its text is left alone, an inline code span.
_ROLE_OR_CODE = re.compile(r"\{(?P<name>[\w:.+-]+)\}(?P<tick>`+)(?!`)(?P<body>.+?)(?<!`)(?P=tick)(?!`)"
                           r"|(?P<code>(?<!`)(?P<ct>`+)(?!`).+?(?<!`)(?P=ct)(?!`))", re.S)
_FENCE = re.compile(r"^ {0,3}(?P<fence>`{3,}|:{3,})(?P<info>.*)$")
_DIRECTIVE = re.compile(r"\s*\{(?P<name>[\w:.+-]+)\}\s*(?P<arg>.*)$")
_TARGET = re.compile(r"^(?P<bullet>\s*[*+-]\s)?\s*\([^()\s]+\)=\s*$")   # (label)=, alone or opening a list item
_OPTION = re.compile(r"^:(?P<key>[\w-]+):\s*(?P<value>.*)$")
#: A role's ``title <target>``.
TITLED = re.compile(r"(?P<title>.+?)\s*<(?P<target>[^<>]+)>$", re.S)
_ADMONITIONS = {"note", "tip", "hint", "important", "warning", "caution", "attention", "danger", "error",
                "seealso", "admonition"}


def _options(lines):
    """(options, body) of a directive's content lines: ``:key: value`` lines or a YAML block first."""
    if lines and lines[0].strip() == "---":
        import yaml
        end = next((i for i, line in enumerate(lines[1:], 1) if line.strip() == "---"), len(lines))
        return (yaml.safe_load("\n".join(lines[1:end])) or {}), "\n".join(lines[end + 1:]).strip("\n")
    options = {}
    while lines and (m := _OPTION.match(lines[0])):
        options[m["key"]] = m["value"]
        lines = lines[1:]
    return options, "\n".join(lines).strip("\n")


def escape(text):
    """Plain text with the characters Markdown would read as markup backslash-escaped."""
    return re.sub(r"([\\`*_\[\]<>$|])", r"\\\1", text)


def fenced(code, language=""):
    """``code`` as a fenced block, its fence longer than any run of backticks inside."""
    ticks = "`" * max(3, 1 + max((len(m) for m in re.findall(r"`+", code)), default=0))
    return f"{ticks}{language}\n{code.rstrip()}\n{ticks}"


def plain_markdown(text, role=None, directive=None):
    """MyST markdown ``text`` (a str) as plain CommonMark, which any Jupyter renders.

    ``role(name, content)`` returns the Markdown for a role ``{name}`content```
    (default `plain_role`); ``directive(name, argument, options, body)`` the
    Markdown for a fenced directive, ```` ```{name} argument ```` or
    ``:::{name} argument``, its options a dict and its body a str (default
    `plain_directive`, or the body converted where that has no form for it);
    either may raise.  Targets ``(label)=`` are dropped; code fences and inline
    code are kept as they are.  Returns a str.
    """
    role = role or plain_role
    directive = directive or (lambda *a: plain_directive(*a) or plain_markdown(a[3]))
    out, para, lines, i = [], [], text.split("\n"), 0

    def flush():
        out.append(_ROLE_OR_CODE.sub(lambda m: m["code"] or role(m["name"], m["body"]), "\n".join(para)))
        para.clear()

    while i < len(lines):
        fence = _FENCE.match(lines[i])
        if fence:
            flush()
            mark = fence["fence"]
            close = re.compile(rf"^ {{0,3}}{re.escape(mark[0])}{{{len(mark)},}}\s*$")
            end = next((j for j in range(i + 1, len(lines)) if close.match(lines[j])), len(lines))
            found = _DIRECTIVE.match(fence["info"])
            if found:
                out.append(directive(found["name"], found["arg"].strip(), *_options(lines[i + 1:end])))
            else:
                out.append("\n".join(lines[i:end + 1]))
            i = end + 1
            continue
        target = _TARGET.match(lines[i])
        if not target:
            para.append(lines[i])
        elif target["bullet"]:
            para.append(target["bullet"].rstrip())        # the item stays, without its target
        i += 1
    flush()
    return re.sub(r"\n{3,}", "\n\n", "\n".join(out)).strip("\n")


def plain_role(name, content):
    """A role as plain Markdown without a book to resolve it in: ``{ref}`Title <target>```
    shows its title, ``{math}`` its math, a bare ``{prf:ref}`thm-<id>``` "Theorem" (unnumbered, as
    a theorem's box is outside the book; `chapter.theorems` follows it with the title), any other
    its content (a bare target's name)."""
    if name == "math":
        return f"${content}$"
    if name == "prf:ref" and content.startswith("thm-") and not TITLED.match(content):
        return "Theorem"
    titled = TITLED.match(content)
    return escape(titled["title"] if titled else content)


def plain_directive(name, argument, options, body, convert=None):
    """A directive as plain Markdown, or None for one this knows no form for: code
    (``code-block``, ``code``) as a fence, ``math`` as a display, ``prf:proof`` as
    *Proof.*, another ``prf:`` kind as **Kind (argument).**, an admonition as a
    quotation, a ``dropdown`` as its title in bold and its body, a
    ``container`` or ``div`` as its body, a ``margin`` note as a quoted aside, and
    sphinx-exercise's forms (`EXERCISE_FORMS`) unnumbered as `plain_exercise` writes them.
    ``convert`` turns the body's MyST into Markdown (default `plain_markdown`)."""
    convert = convert or plain_markdown
    if name in ("code-block", "code", "sourcecode"):
        return fenced(body, argument)
    if name == "math":
        return f"$$\n{body}\n$$"
    if name == "prf:proof":
        return f"*Proof.* {convert(body)}"
    if name.startswith("prf:"):
        return f"**{name[4:].title()}{f' ({convert(argument)})' if argument else ''}.** {convert(body)}"
    if name in _ADMONITIONS:
        head = convert(argument) if name == "admonition" else name.title()
        return _quoted(_headed(head, convert(body)))
    if name in ("dropdown", "toggle"):                    # folded on the page, open in a notebook
        return f"**{convert(argument)}**\n\n{convert(body)}" if argument else convert(body)
    if name in ("container", "div"):
        return convert(body)
    if name == "margin":                                  # sphinx-book-theme's margin note: an aside
        return _quoted(_headed(convert(argument) if argument else "Aside", convert(body)))
    if name in EXERCISE_FORMS:
        title = f" ({convert(argument)})" if argument and name.startswith("exercise") else ""
        return plain_exercise(name, ("Exercise" if name.startswith("exercise") else "Solution") + title, body,
                              convert)
    return None


#: sphinx-exercise's directives: an exercise and its solution, and the gated forms whose content is the
#: cells between a ``*-start`` and its ``*-end`` (a solution with a code cell).
EXERCISE_FORMS = ("exercise", "solution", "exercise-start", "exercise-end", "solution-start", "solution-end")


def _quoted(text):
    return "\n".join(f"> {line}".rstrip() for line in text.split("\n"))


#: Markdown that opens a block of its own (a list item, a quotation, a display, a fence, a heading).
_BLOCK = re.compile(r"\s*(?:[-*+]\s|\d+[.)]\s|>|\$\$|`{3,}|#)")


def _headed(head, body):
    """``body`` under a bold ``head``: run in ("**Note.** Text") before a paragraph, a line of its own
    before a block (a list would otherwise start inside the heading's paragraph)."""
    return f"**{head}**\n\n{body}" if _BLOCK.match(body) else f"**{head}.** {body}"


def plain_exercise(name, heading, body, convert):
    """One of sphinx-exercise's directives as plain Markdown.

    Parameters
    ----------
    name : str
        One of `EXERCISE_FORMS`.
    heading : str
        Markdown: "Exercise 2 (Title)", "Solution to Exercise 2" (a solution's is shown as text).
    body : str
        The directive's MyST body ("" for the gated forms, whose content is the cells that follow).
    convert : callable
        MyST str -> Markdown str, for the body.

    Returns
    -------
    str
        An exercise: its heading in bold, then its body.  A solution: folded in an HTML ``<details>``
        under its heading (Jupyter renders the Markdown inside).  A gated solution spans cells, which
        no ``<details>`` can: its start is a heading, its end a closing line; an ``exercise-end`` is "".
    """
    from html import escape as html_escape
    if name == "exercise-end":
        return ""
    if name == "solution-end":
        return "*(End of the solution.)*"
    if name == "solution":
        return f"<details>\n<summary>{html_escape(heading)}</summary>\n\n{convert(body)}\n\n</details>"
    return f"**{heading}.**" + (f"\n\n{convert(body)}" if body.strip() else "")
