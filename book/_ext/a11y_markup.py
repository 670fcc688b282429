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
* A negative number.  Python writes it with a hyphen-minus, which a screen reader reads as a dash
  or skips; in the prose (not in code or maths) it becomes the minus sign, "−0.651"
  (`chapter.page.minus_signs`; book/check_glue.py fails a page with one left).
"""

from __future__ import annotations

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
    app.add_node(HideCodeCellNode, override=True, html=(visit_hidden_cell, depart_HideCellInput))
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
