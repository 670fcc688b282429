"""chapter.page: inside a book build `glue` and `show` glue for the prose and `markdown`
hands on MyST; anywhere else `show` displays the figure, `glue` does nothing (without
needing myst-nb) and `markdown` shows plain Markdown (`plain_markdown`).

The build's side is spied on (myst-nb's ``glue`` replaced by a recorder), and so is
IPython's ``display``; tests/test_notebooks.py runs a page for real, in Jupyter,
outside the repository.
"""

from __future__ import annotations

import re
import sys
import types

import matplotlib
import pytest
from hypothesis import given, settings, strategies as st

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from chapter import page  # noqa: E402


@pytest.fixture
def calls(monkeypatch):
    """Records myst-nb glue calls and IPython display calls, as ("glue"|"display", args, kwargs)."""
    record = []
    fake_myst_nb = types.ModuleType("myst_nb")
    fake_myst_nb.glue = lambda *a, **k: record.append(("glue", a, k))
    monkeypatch.setitem(sys.modules, "myst_nb", fake_myst_nb)
    import IPython.display
    monkeypatch.setattr(IPython.display, "display", lambda *a, **k: record.append(("display", a, k)))
    return record


def _figure(overlap=False):
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0, 1], [0, 1])
    ax.set_title("a title")
    if overlap:
        ax.text(0.5, 0.5, "one label", transform=ax.transAxes)
        ax.text(0.5, 0.5, "another label", transform=ax.transAxes)
    return fig


@pytest.mark.parametrize("building", [False, True], ids=["notebook", "book build"])
def test_show_displays_outside_a_build_and_glues_inside_and_always_closes(monkeypatch, calls, building):
    if building:
        monkeypatch.setenv(page.BUILD_ENV, "1")
    else:
        monkeypatch.delenv(page.BUILD_ENV, raising=False)
    fig = _figure()
    assert page.show("fig-x", fig) is None          # nothing for a cell's last line to show again
    if building:
        assert calls == [("glue", ("fig-x", fig), {"display": False})]
    else:
        assert calls == [("display", (fig,), {"metadata": {"symrender": {"figure": "fig-x"}}})]
    assert not plt.fignum_exists(fig.number)


@pytest.mark.parametrize("value", [0.35, "256 × 256"])
def test_glue_glues_only_inside_a_build(monkeypatch, calls, value):
    monkeypatch.setenv(page.BUILD_ENV, "1")
    assert page.glue("s1_beta", value) is None
    monkeypatch.setenv(page.BUILD_ENV, "0")          # anything but "1" is not a build
    page.glue("s1_beta", value)
    assert calls == [("glue", ("s1_beta", value), {"display": False})]


def test_outside_a_build_glue_and_show_need_no_myst_nb(monkeypatch, calls):
    monkeypatch.delenv(page.BUILD_ENV, raising=False)
    monkeypatch.setitem(sys.modules, "myst_nb", None)     # importing it now raises ImportError
    page.glue("s1_beta", 0.35)
    page.show("fig-x", _figure())
    assert [c[0] for c in calls] == ["display"]
    # The same calls inside a build do need it: the spy above is what the check could catch.
    monkeypatch.setenv(page.BUILD_ENV, "1")
    with pytest.raises(ImportError):
        page.glue("s1_beta", 0.35)


def test_show_without_ipython_says_what_to_install(monkeypatch):
    monkeypatch.delenv(page.BUILD_ENV, raising=False)
    monkeypatch.setitem(sys.modules, "IPython.display", None)
    fig = _figure()
    with pytest.raises(ImportError, match="notebook extra"):
        page.show("fig-x", fig)
    assert not plt.fignum_exists(fig.number)


def test_show_refuses_overlapping_text_and_closes_the_figure(calls):
    fig = _figure(overlap=True)
    with pytest.raises(page.FigureLayoutError, match="'one label' / 'another label'"):
        page.show("fig-x", fig)
    assert calls == [] and not plt.fignum_exists(fig.number)


@pytest.mark.parametrize("call, error, match", [
    (lambda: page.glue(3, 1.0), TypeError, "name must be a str, got int"),
    (lambda: page.glue("", 1.0), ValueError, "name must be letters.*got ''"),
    (lambda: page.glue("two words", 1.0), ValueError, "got 'two words'"),
    (lambda: page.glue("a:b", 1.0), ValueError, "got 'a:b'"),
    (lambda: page.show("fig-x", "not a figure"), TypeError, "fig must be a matplotlib.figure.Figure, got str"),
])
def test_bad_arguments_are_named(calls, call, error, match):
    with pytest.raises(error, match=match):
        call()
    assert calls == []


#: MyST a plain Jupyter would show as written: a role, a fenced directive, a target line.
MYST = re.compile(r"\{[A-Za-z][\w:.+-]*\}`|`{3,}\s*\{|:{3,}\s*\{|^\s*(?:[*+-]\s+)?\([^()\s]+\)=\s*$", re.M)

#: What the book's helpers hand `markdown`: a claim's margin note, a theorem box, a ledger item.
MYST_OUTPUT = ("```{margin}\n**§1** · “No pixel changes chamber” — {term}`Holds` "
               "({ref}`in the register <claim-flips-zero>`)\n```\n\n"
               ":::{prf:theorem} The bump moves no boundary\n:label: thm-no-boundary\n\n"
               "For every pixel, $c(\\beta) = c(0)$.\n\n**PROVED** · evidence: {ref}`§6 <ledger-no-boundary>`\n:::\n\n"
               ":::{prf:proof}\n**Step 1.** The chamber is computed first.\n:::\n\n"
               "* (ledger-no-boundary)=\n  {prf:ref}`The bump moves no boundary <thm-no-boundary>`: used on {ref}`s3`.\n\n"
               "::::{dropdown} Why\nBecause:\n\n```{math}\nc = c_0\n```\n::::\n")


def test_markdown_is_myst_in_a_build_and_plain_markdown_elsewhere(monkeypatch):
    assert len(MYST.findall(MYST_OUTPUT)) == 11             # the scan sees every piece of MyST in it
    monkeypatch.setenv(page.BUILD_ENV, "1")
    assert page.markdown(MYST_OUTPUT).data == MYST_OUTPUT
    monkeypatch.delenv(page.BUILD_ENV)
    shown = page.markdown(MYST_OUTPUT).data
    assert MYST.findall(shown) == []
    assert shown == ("> **Aside.** **§1** · “No pixel changes chamber” — Holds (in the register)\n\n"
                     "**Theorem (The bump moves no boundary).** For every pixel, $c(\\beta) = c(0)$.\n\n"
                     "**PROVED** · evidence: §6\n\n*Proof.* **Step 1.** The chamber is computed first.\n\n"
                     "*\n  The bump moves no boundary: used on s3.\n\n**Why**\n\nBecause:\n\n$$\nc = c_0\n$$")
    with pytest.raises(TypeError, match="text must be a str of MyST markdown, got int"):
        page.markdown(3)


def test_plain_markdown_keeps_code_and_hands_roles_and_directives_to_its_callbacks():
    def role(name, content):
        return f"<{name}:{content}>"

    def directive(name, arg, options, body):
        return f"[{name}|{arg}|{sorted(options.items())}|{body}]"

    source = ("(s1)=\n# Title\n\nSee {ref}`s3`, not ``{ref}`x` `` in code, and {numref}`Fig. %s <fig-a>`.\n\n"
              "```{glue:figure} fig-a\n:name: fig-a\n\nCaption.\n```\n\n```python\ny = '{ref}`z`'\n```\n\n"
              "::::{note}\nA note.\n::::\n")
    assert page.plain_markdown(source, role, directive) == (
        "# Title\n\nSee <ref:s3>, not ``{ref}`x` `` in code, and <numref:Fig. %s <fig-a>>.\n\n"
        "[glue:figure|fig-a|[('name', 'fig-a')]|Caption.]\n\n```python\ny = '{ref}`z`'\n```\n\n"
        "[note||[]|A note.]")


#: A page's learning aids: a margin note, an exercise with its folded solution, and the gated form whose
#: solution holds a code cell (here a fence standing for the cell between start and end).
AIDS = ("```{margin}\nA note on {ref}`u <s3>`.\n```\n\n"
        ":::{exercise} Find $\\varepsilon^\\ast$\n:label: ex-a\n\nMinimise $E$.\n:::\n\n"
        "::::{solution} ex-a\n:class: dropdown\n\nAt the root of $E'$.\n::::\n\n"
        "````{exercise-start}\n:label: ex-b\n````\n\nCount them.\n\n````{exercise-end}\n````\n\n"
        "````{solution-start} ex-b\n:class: dropdown\n````\n\n```python\nlen(x)\n```\n\n````{solution-end}\n````\n")


def test_margin_notes_and_exercises_become_plain_markdown():
    shown = page.plain_markdown(AIDS)
    assert MYST.findall(shown) == []
    blocks = shown.split("\n\n")
    assert blocks[0] == "> **Aside.** A note on u."                       # a quoted aside
    assert blocks[1:3] == ["**Exercise (Find $\\varepsilon^\\ast$).**", "Minimise $E$."]
    # The solution folded below its exercise, its Markdown rendered inside the <details>.
    assert blocks[3:6] == ["<details>\n<summary>Solution</summary>", "At the root of $E'$.", "</details>"]
    # The gated forms span cells: a heading where each starts, a closing line where the solution ends.
    assert blocks[6:] == ["**Exercise.**", "Count them.", "**Solution.**", "```python\nlen(x)\n```",
                          "*(End of the solution.)*"]


@pytest.mark.parametrize("body, shown", [
    ("Text.", "> **Note.** Text."),
    ("- one;\n- two.", "> **Note**\n>\n> - one;\n> - two."),        # a list stays a list
    ("$$\nx\n$$", "> **Note**\n>\n> $$\n> x\n> $$"),
])
def test_an_admonition_is_a_quotation_headed_by_its_title(body, shown):
    assert page.plain_markdown(f":::{{note}}\n{body}\n:::") == shown


@settings(max_examples=300, deadline=None)
@given(st.lists(st.sampled_from(["-", "−", "+", "e", "k", ".", "/", "^", " ", "(", ",", "0", "7", "1.5"]),
                max_size=12).map("".join))
def test_minus_signs_types_exactly_the_hyphens_that_begin_a_number(text):
    """Against a reading character by character: a hyphen becomes the minus sign when a digit follows
    and neither a letter, a digit, nor one of . - − / ^ precedes it; nothing else changes."""
    typeset = page.minus_signs(text)
    assert len(typeset) == len(text)
    for i, (a, b) in enumerate(zip(text, typeset)):
        begins = (a == "-" and text[i + 1:i + 2].isdigit()
                  and not (i and (text[i - 1].isalnum() or text[i - 1] == "_" or text[i - 1] in ".-−/^")))
        assert b == ("−" if begins else a), (text, typeset, i)
