"""Each notebook page of the built site can be downloaded as a notebook, and that notebook runs.

book/_ext/notebooks.py writes ``_notebooks/<page>.ipynb`` with jupytext and
links it under the page's title.  Checked against the site `book_html` names:
every page that is a notebook has one, linked from its page, with the page's
code cells (as myst-nb reads them) in order; and one of them, copied to a
directory outside the repository, runs top to bottom in a fresh kernel and
draws its figures with the same bytes as the build did.
"""

from __future__ import annotations

import base64
import hashlib
import json
import shutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]
sys.path.insert(0, str(ROOT / "book" / "_ext"))
import nb_deps  # noqa: E402  (book/_ext is not a package)

sys.path.remove(str(ROOT / "book" / "_ext"))

PAGES = sorted(p for p in (ROOT / "book").glob("*.md")
               if nb_deps.code_cells(p.read_text(encoding="utf-8"), path=p) is not None)


def test_the_book_has_notebook_pages():
    assert len(PAGES) >= 7


@pytest.mark.parametrize("page", PAGES, ids=[p.stem for p in PAGES])
def test_each_notebook_page_links_its_notebook_with_its_code_cells(book_html, page):
    nb_file = book_html / "_notebooks" / f"{page.stem}.ipynb"
    assert nb_file.is_file(), f"{nb_file} is missing"
    notebook = json.loads(nb_file.read_text(encoding="utf-8"))
    code = ["".join(c["source"]) for c in notebook["cells"] if c["cell_type"] == "code"]
    assert code == nb_deps.code_cells(page.read_text(encoding="utf-8"), path=page)
    assert notebook["metadata"]["kernelspec"]["name"] == "python3"
    assert all(not c.get("outputs") for c in notebook["cells"] if c["cell_type"] == "code")
    html = (book_html / f"{page.stem}.html").read_text(encoding="utf-8")
    assert f'href="_notebooks/{page.stem}.ipynb"' in html


def test_a_downloaded_notebook_runs_outside_the_repository(book_html, tmp_path):
    from nbclient import NotebookClient
    import nbformat
    copy = tmp_path / "s2_scene.ipynb"
    shutil.copy(book_html / "_notebooks" / "s2_scene.ipynb", copy)
    notebook = nbformat.read(copy, as_version=4)
    NotebookClient(notebook, timeout=600, resources={"metadata": {"path": str(tmp_path)}}).execute()
    assert any(o.get("output_type") in ("display_data", "execute_result")
               for c in notebook.cells if c.cell_type == "code" for o in c.get("outputs", []))
    # Its figures, drawn again in another process, are byte for byte the site's images.
    drawn = [base64.b64decode(v) for c in notebook.cells if c.cell_type == "code" for o in c.get("outputs", [])
             for k, v in o.get("data", {}).items() if k.endswith("image/png")]
    site = {hashlib.sha256(p.read_bytes()).hexdigest() for p in (book_html / "_images").glob("*.png")}
    assert len(drawn) >= 2
    assert [hashlib.sha256(b).hexdigest() in site for b in drawn] == [True] * len(drawn)
    assert all(b"tIME" not in b[:4096] for b in drawn)      # no timestamp chunk
