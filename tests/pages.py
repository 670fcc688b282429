"""The code cells of a book page, as myst-nb executes them (for the tests of pages and notebooks)."""

from __future__ import annotations

import ast

#: The front matter that makes a MyST page a notebook myst-nb executes (for miniature books).
NOTEBOOK_FRONT_MATTER = """---
jupytext:
  text_representation:
    extension: .md
    format_name: myst
kernelspec:
  display_name: Python 3
  language: python
  name: python3
---
"""


def code_cells(text: str) -> list[str] | None:
    """The code cells of a MyST notebook page, in order; None for a page that is not a notebook."""
    from myst_nb.core.read import is_myst_markdown_notebook, read_myst_markdown_notebook
    if not is_myst_markdown_notebook(text):
        return None
    return [cell.source for cell in read_myst_markdown_notebook(text).cells if cell.cell_type == "code"]


def parse_cell(source: str) -> ast.AST | None:
    """A cell as Python; IPython magics are translated first if plain Python fails; None if neither parses."""
    try:
        return ast.parse(source)
    except SyntaxError:
        pass
    from IPython.core.inputtransformer2 import TransformerManager
    try:
        return ast.parse(TransformerManager().transform_cell(source))
    except SyntaxError:
        return None


def run_page(path):
    """Run a book page's code cells in order in one namespace, as the build's kernel runs them, with
    `chapter.page.glue` and `chapter.page.show` recording what the page glues and publishes instead.

    The draft's claims are not measured (`chapter.verdicts.margin_notes` returns an empty string: the
    register has its own tests).  A measurement the page asks `lab.store` for is read from the
    store SYMRENDER_STORE names, if it holds a current one.  Returns (the namespace, {figure
    name: matplotlib Figure, closed}, {glue name: value}), in the order the page made them.
    """
    from pathlib import Path
    from unittest import mock

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from IPython.core.inputtransformer2 import TransformerManager

    figures, glued = {}, {}

    def show(name, fig):
        figures[name] = fig
        plt.close(fig)

    namespace = {"__name__": "__main__"}
    with mock.patch("chapter.page.glue", glued.__setitem__), mock.patch("chapter.page.show", show), \
            mock.patch("chapter.verdicts.margin_notes", lambda place: ""):
        for k, source in enumerate(code_cells(Path(path).read_text(encoding="utf-8"))):
            exec(compile(TransformerManager().transform_cell(source), f"{Path(path).name}, cell {k + 1}", "exec"),
                 namespace)
    return namespace, figures, glued
