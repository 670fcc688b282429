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
"""

from __future__ import annotations

from html import escape

from sphinx.writers.html5 import HTML5Translator


class Translator(HTML5Translator):
    """Sphinx's HTML5 translator with each citation a list item of the list around it."""

    def visit_citation(self, node):
        if not isinstance(node.previous_sibling(), type(node)):
            self.body.append('<div role="list" class="citation-list">\n')
        self.body.append(self.starttag(node, "div", classes=[node.tagname], role="listitem"))


def visit_hidden_cell(self, node):
    """myst-nb's ``visit_HideCellInput`` without the summary's aria-label."""
    self.body.append(f'<details class="admonition hide {" ".join(node["classes"])}">\n<summary>\n'
                     f'<p class="collapsed admonition-title">{escape(node["prompt_show"])}</p>\n'
                     f'<p class="expanded admonition-title">{escape(node["prompt_hide"])}</p>\n</summary>\n')


def setup(app):
    from myst_nb.sphinx_ import HideCodeCellNode, depart_HideCellInput
    app.set_translator("html", Translator)
    app.add_node(HideCodeCellNode, override=True, html=(visit_hidden_cell, depart_HideCellInput))
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
