"""Sphinx extension: each notebook page of the book can be downloaded as a Jupyter notebook.

The pages are MyST markdown notebooks.  At the end of an HTML build, jupytext
(the well-kept converter between the two formats) turns each page's source into
``_notebooks/<page>.ipynb`` in the site: its code cells with their tags, its
markdown, its kernelspec, no outputs.  Each such page gets a line under its
title linking to the file.  The notebooks import the project's packages
(``renderer``, ``proofs``) and myst-nb's ``glue``, so they run wherever the
project is installed with its book extra (``pip install -e '.[book]'``, as
``make book`` does), from any directory.

A file is written to a temporary name and renamed into place, so the site
never holds a half-written notebook.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from docutils import nodes

#: The site folder that holds the notebooks.
FOLDER = "_notebooks"


def is_notebook(app, docname):
    """Whether the page is a MyST notebook (its front matter names a kernelspec)."""
    return bool(app.env.metadata.get(docname, {}).get("kernelspec"))


def notebook_uri(docname):
    """The notebook's address relative to the page's HTML file."""
    return "../" * docname.count("/") + f"{FOLDER}/{docname}.ipynb"


def _link(app, doctree, docname):
    if app.builder.format != "html" or not is_notebook(app, docname):
        return
    sections = list(doctree.findall(nodes.section))
    if not sections:
        return
    name = f"{Path(docname).name}.ipynb"
    para = nodes.paragraph("", "", nodes.Text("This page as a Jupyter notebook: "),
                           nodes.reference("", name, refuri=notebook_uri(docname)),
                           nodes.Text(" (runs wherever the project is installed; see the README)."),
                           classes=["notebook-download"])
    title = sections[0].next_node(nodes.title)
    sections[0].insert(sections[0].index(title) + 1 if title is not None else 0, para)


def write_notebook(source, target):
    """Convert the MyST notebook ``source`` to ``target`` (.ipynb) with jupytext, atomically."""
    import jupytext
    notebook = jupytext.read(source, fmt="md:myst")
    notebook.metadata.pop("jupytext", None)          # the pairing describes the source, not this file
    target.parent.mkdir(parents=True, exist_ok=True)
    text = jupytext.writes(notebook, fmt="ipynb")
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".part")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.chmod(tmp, 0o644)                          # mkstemp's 0600 would hide it from a web server
        os.replace(tmp, target)
    except BaseException:
        os.unlink(tmp)
        raise


def _write_all(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    for docname in sorted(app.env.found_docs):
        if is_notebook(app, docname):
            write_notebook(app.env.doc2path(docname), Path(app.outdir, FOLDER, f"{docname}.ipynb"))


def setup(app):
    app.connect("doctree-resolved", _link)
    app.connect("build-finished", _write_all)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
