"""The code cells of a book page, as myst-nb executes them (for the tests of pages and notebooks)."""

from __future__ import annotations

import ast


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
