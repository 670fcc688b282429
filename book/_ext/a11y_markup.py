"""Sphinx extension: markup a screen reader reads as it looks (axe-core finds no serious or critical
violation on the built pages: tests/test_browser.py).

* The bibliography.  Docutils writes the works cited (sphinxcontrib-bibtex's list on §8) as a
  ``role="list"`` box of ``role="doc-biblioentry"`` entries; that role is deprecated (DPUB-ARIA 1.1)
  and is no list item, so the list has no items and the entries' back-links stand as its children
  (axe-core's ``aria-required-children``, critical, and ``aria-deprecated-role``).  Here each entry
  is a ``role="listitem"``.  The theme (pydata-sphinx-theme) adds its own HTML to this translator as
  it does to Sphinx's.
* A folded code cell's toggle.  myst-nb names its ``<summary>`` "Toggle hidden content" while it shows
  "Show code cell source": a speech-input user saying what they see misses it (axe-core's
  ``label-content-name-mismatch``).  Here the summary is named by the words it shows.
* A margin note.  sphinx-book-theme writes each as an ``<aside>``, which a screen reader lists
  among the page's landmarks, unnamed: §5 had 17 "complementary" landmarks.  Here each is a
  ``role="note"``, read where it stands and kept out of that list.
* A table's row labels.  A table whose head row begins with an empty cell (§3's table of optima) labels
  its rows in its first column; docutils writes those labels as data cells, so a screen reader reading
  across a row hears "0.367, 0.367, 0.685" with no quantity.  Here that column is a stub column, each
  of its cells a ``<th scope="row">``.
* Links that say the same and lead to different places.  Each margin note on a claim of the draft links
  to the claim's entry in §6 by the word "why", and many links to a section say only its number ("§3"):
  a screen reader's list of links had 17 "why" on §5, each to another claim, and five "§3" on the
  glossary, each to another part of §3.  Here each link whose words another link of its page shares,
  leading elsewhere, is named by those words and then where it leads: "why: claim 16" (the entry's
  number in §6), "§6: the evidence for “The gradient of the sine field”" (a theorem's entry in §6's ledger, by
  the theorem's title), or "§3: The finite-difference U-curve" (the section's title).  A target
  with none of these (a label on a paragraph) fails the build, naming it: a label's words ("s3 kinks")
  are no name.
* An id given twice.  sphinx-proof and sphinx-exercise give each proof, exercise and solution the same
  ids ("proof", "proof-content", "exercise-content", "solution-content": 14 of each on §3), and an id
  names one element of a page (a reference to it, ``aria-labelledby`` or ``#proof``, finds only the
  first).  Here the second and later get a number ("proof-content-2").
* A negative number.  Python writes it with a hyphen-minus, which a screen reader reads as a dash
  or skips; in the prose (not in code or maths) it becomes the minus sign, "−0.651"
  (`chapter.page.minus_signs`; book/check_glue.py fails a page with one left).
"""

from __future__ import annotations

from functools import cache
from html import escape

from docutils import nodes
from sphinx.transforms.post_transforms import SphinxPostTransform
from sphinx.writers.html5 import HTML5Translator

from chapter.page import minus_signs


class Translator(HTML5Translator):
    """Sphinx's HTML5 translator with each citation a list item of the list around it, and each
    margin note a note."""

    def visit_citation(self, node):
        if not isinstance(node.previous_sibling(), type(node)):
            self.body.append('<div role="list" class="citation-list">\n')
        self.body.append(self.starttag(node, "div", classes=[node.tagname], role="listitem"))

    def visit_entry(self, node):
        """A table cell; in the body, a stub column's cell is the header of its row."""
        super().visit_entry(node)
        if not isinstance(node.parent.parent, nodes.thead) and self.body[-1].startswith("<th "):
            self.body[-1] = self.body[-1].replace("<th ", '<th scope="row" ', 1)

    def visit_reference(self, node):
        """A link, named by its ``aria-label`` where `LinkNames` gave it one."""
        i = len(self.body)                      # where Sphinx's <a …> goes
        super().visit_reference(node)
        if node.get("aria-label"):
            self.body[i] = self.body[i].replace("<a ", f'<a aria-label="{escape(node["aria-label"])}" ', 1)

    def visit_sidebar(self, node):
        """A margin note as a note: Sphinx's ``<aside class="sidebar">`` with ``role="note"``."""
        note = {"role": "note"} if "margin" in node["classes"] else {}
        self.body.append(self.starttag(node, "aside", CLASS="sidebar", **note))
        self.in_sidebar = True


def visit_hidden_cell(self, node):
    """myst-nb's ``visit_HideCellInput`` without the summary's aria-label."""
    self.body.append(f'<details class="admonition hide {" ".join(node["classes"])}">\n<summary>\n'
                     f'<p class="collapsed admonition-title">{escape(node["prompt_show"])}</p>\n'
                     f'<p class="expanded admonition-title">{escape(node["prompt_hide"])}</p>\n</summary>\n')


class RowHeaders(SphinxPostTransform):
    """The first column of each table whose head row begins with an empty cell, as a stub column."""

    default_priority = 900

    def run(self, **kwargs):
        for tgroup in self.document.findall(nodes.tgroup):
            head = next(tgroup.findall(nodes.thead), None)
            first = next(head.findall(nodes.entry), None) if head is not None else None
            if first is not None and not first.astext().strip():
                next(tgroup.findall(nodes.colspec))["stub"] = 1


@cache
def untitled_targets():
    """{label: where it leads, in words} of §6's targets that have no title: a claim's entry in the register
    (``claim-<id>``) by its number there, a theorem's entry in the ledger (``ledger-<id>``) by the theorem's
    title."""
    from chapter.verdicts import NUMBERS    # imports lab.claims: only on a page that needs it
    from proofs.registry import CITABLE
    return {**{f"claim-{c}": f"claim {n}" for c, n in NUMBERS.items()},
            **{f"ledger-{t}": f"the evidence for “{title}”" for t, title in CITABLE.items()}}


class LinkNames(SphinxPostTransform):
    """Each link whose words another link of the page shares, leading elsewhere, named by those words and
    where it leads: a section (or another titled target) by its title, else by `untitled_targets`.  A link
    to a page's top (``s3_math.html#s3``) leads where the link to the page leads.

    Raises
    ------
    ValueError
        For such a link to a target with neither (a label on a paragraph), naming the page, the link's
        words and the target: give the target a heading, or the link words of its own.
    """

    default_priority = 900

    def run(self, **kwargs):
        titles = {(doc, anchor): str(title).split(" · ")[-1]
                  for doc, anchor, title in self.env.domaindata["std"]["labels"].values() if title}
        places = {}
        for r in self.document.findall(nodes.reference):
            page, _, anchor = (r.get("refuri") or "#" + r.get("refid", "")).partition("#")
            doc = page.removesuffix(".html") or self.env.docname
            if anchor == doc.split("_")[0]:
                anchor = ""
            places.setdefault(r.astext(), {}).setdefault((doc, anchor), []).append(r)
        for text, targets in places.items():
            for (doc, anchor), links in targets.items() if len(targets) > 1 else ():
                where = titles.get((doc, anchor)) or untitled_targets().get(anchor)
                if where is None:
                    raise ValueError(f"{self.env.docname}: the links {text!r} lead to different places, and "
                                     f"{doc}#{anchor} has no title to name its links by: give it a heading, "
                                     f"or its links words of their own")
                for r in links:
                    r["aria-label"] = f"{text}: {where}"


class UniqueIds(SphinxPostTransform):
    """Each id of the page once: an id already given is numbered by its place (``proof-content-2``), skipping
    a number another element has."""

    default_priority = 900

    def run(self, **kwargs):
        elements = list(self.document.findall(nodes.Element))
        taken, seen = {i for e in elements for i in e.get("ids", ())}, {}
        for element in elements:
            for k, name in enumerate(element.get("ids", ())):
                seen[name] = seen.get(name, 0) + 1
                if seen[name] > 1:
                    n = seen[name]
                    while f"{name}-{n}" in taken:
                        n += 1
                    element["ids"][k] = f"{name}-{n}"
                    taken.add(element["ids"][k])


class MinusSigns(SphinxPostTransform):
    """Each negative number of the prose with the minus sign: every text node outside code, maths
    and raw markup (glued numbers included: myst-nb pastes them as text)."""

    default_priority = 900
    KEEP = (nodes.FixedTextElement, nodes.literal, nodes.math, nodes.raw, nodes.comment)

    def run(self, **kwargs):
        for text in list(self.document.findall(nodes.Text)):
            parent = text.parent
            while parent is not None and not isinstance(parent, self.KEEP):
                parent = parent.parent
            typeset = minus_signs(str(text))
            if parent is None and typeset != str(text):
                text.parent.replace(text, nodes.Text(typeset))


def setup(app):
    from myst_nb.sphinx_ import HideCodeCellNode, depart_HideCellInput
    app.set_translator("html", Translator)
    app.add_post_transform(MinusSigns)
    app.add_post_transform(RowHeaders)
    app.add_post_transform(LinkNames)
    app.add_post_transform(UniqueIds)
    app.add_node(HideCodeCellNode, override=True, html=(visit_hidden_cell, depart_HideCellInput))
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
