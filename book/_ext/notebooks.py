"""Sphinx extension: each notebook page of the book can be downloaded as a notebook that stands alone.

An HTML build puts into the site, beside the pages:

* ``_downloads/<wheel>``: the project's wheel, built when the build starts by
  the setuptools of the build's own environment (its PEP 517 hook: offline,
  no build isolation), from a copy of the files it packages (so nothing is
  written into the source tree); ``_downloads/constraints.txt``, the
  versions the book was built with; and ``_downloads/README.html``, the README
  rendered with markdown-it (the parser the book itself uses; the README has no
  relative links to break), beside the files it describes and not among the
  pages that the build's checks read;
* ``_notebooks/<page>.ipynb`` for each page that is a MyST notebook, written by
  jupytext when the build finishes: the page's code cells as they are, with
  their tags and no outputs, and its prose as plain Markdown any Jupyter
  renders (`chapter.page.plain_markdown`, which `chapter.page.markdown` also
  applies to what a page shows when it runs outside the book, with
  `PageMarkdown` resolving against this build): each glue role becomes the value this build
  computed (myst-nb's glue data of the page), each cross-reference its text
  ("§3 · The mathematics", "Fig. 2"), a ``glue:figure`` its numbered caption
  (the figure is drawn by the code cell that calls `chapter.page.show`), a
  ``literalinclude`` the code it includes (Sphinx's own reader), a margin note a quoted
  aside, an exercise its numbered heading with its solution folded below it, a citation
  its author-year text and the bibliography its list (sphinxcontrib-bibtex's entries,
  formatted by pybtex), and so on.
  A first cell says how to install the project to run the notebook.

Each notebook page gets a line under its title linking its notebook, the wheel
and the README.  Every file is written to a temporary name and renamed into
place, so the site never holds a half-written one.  A role or directive with no
plain-Markdown form, a glued name without a value or a failed wheel build fails
the build, and the message names the page and the markup, or the build backend's output; a
page that failed to execute gets no notebook (a warning says so).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

from docutils import nodes

from lab.store import source_digest
from renderer import files
from chapter.page import (TITLED, escape, fenced, minus_signs, plain_directive, plain_exercise,
                          plain_markdown)

#: The site folder that holds the notebooks, and the one that holds the wheel and constraints.txt.
FOLDER, DOWNLOADS = "_notebooks", "_downloads"
#: The README, rendered into the site.
README = f"{DOWNLOADS}/README.html"
#: The project's root (pyproject.toml, README.md, constraints.txt).
ROOT = Path(__file__).resolve().parents[2]


class NotebookError(Exception):
    """Something the site's notebooks or the files beside them need could not be made."""


def _names(entry):
    """The author part of an author-year citation: "Blinn", "Squire and Trapp", "Martins et al."."""
    last = [" ".join(person.last_names).replace("{", "").replace("}", "") for person in entry.persons["author"]]
    return last[0] if len(last) == 1 else " and ".join(last) if len(last) == 2 else f"{last[0]} et al."


def _author_year(entry):
    return _names(entry), entry.fields.get("year", "")


def cite_text(kind, entries):
    """A citation as the site writes it: sphinxcontrib-bibtex's author-year style, with its brackets
    and separators, the works in the bibliography's (author) order.

    Parameters
    ----------
    kind : {"t", "p"}
        Textual (``{cite:t}``: "Blinn [1978]") or parenthetical (``{cite:p}``:
        "[Martins et al., 2003, Squire and Trapp, 1998]").
    entries : list of pybtex.database.Entry
        The works cited, each with an ``author`` and a ``year``.

    Returns
    -------
    str
        Plain text (not yet Markdown-escaped).
    """
    pairs = sorted(_author_year(entry) for entry in entries)
    if kind == "t":
        return ", ".join(f"{names} [{year}]" for names, year in pairs)
    return "[" + ", ".join(f"{names}, {year}" for names, year in pairs) + "]"


# --- files of the site -------------------------------------------------------------------------

def write_atomic(target, data: bytes):
    """Write ``data`` to ``target`` (its directory made first) atomically, by `renderer.files.write_bytes`."""
    Path(target).parent.mkdir(parents=True, exist_ok=True)
    files.write_bytes(target, data)


def build_wheel(root, folder) -> Path:
    """Build the project at ``root`` into a wheel in ``folder`` (replacing older wheels of
    the project there) and return its path.

    The files the wheel packages (pyproject.toml, the README, the packages named
    by ``[tool.setuptools] packages``, without ``__pycache__``) are copied to a
    temporary directory, and the build backend that pyproject.toml names
    (``[build-system] build-backend``, setuptools) builds there through its PEP 517
    hook ``build_wheel``, in a child process with this environment's setuptools:
    no network, nothing written into ``root``.  (``pip wheel --no-build-isolation``
    gives the same files, after pip's own start-up.)  ``SOURCE_DATE_EPOCH``
    (1980-01-01) gives the zip entries fixed times, so the same sources give the
    same bytes.

    Raises
    ------
    NotebookError
        If the build fails (the message holds the end of its output).
    """
    root, folder = Path(root), Path(folder)
    pyproject = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))
    with tempfile.TemporaryDirectory(prefix="symrender-wheel-") as tmp:
        src, out = Path(tmp, "src"), Path(tmp, "out")
        src.mkdir()
        for name in ("pyproject.toml", pyproject["project"]["readme"]):
            shutil.copy2(root / name, src / name)
        where = pyproject["tool"].get("setuptools", {}).get("package-dir", {})
        for package in pyproject["tool"]["setuptools"]["packages"]:
            path = where.get(package, package)
            shutil.copytree(root / path, src / path, ignore=shutil.ignore_patterns("__pycache__"))
        backend = pyproject["build-system"]["build-backend"]
        hook = f"import importlib, sys; importlib.import_module({backend!r}).build_wheel(sys.argv[1])"
        run = subprocess.run([sys.executable, "-c", hook, str(out)], capture_output=True, text=True, cwd=src,
                             env={**os.environ, "SOURCE_DATE_EPOCH": "315532800"})
        wheels = sorted(out.glob("*.whl"))
        if run.returncode != 0 or len(wheels) != 1:
            raise NotebookError(f"building the project's wheel with {backend} failed (exit {run.returncode}):\n"
                                + (run.stdout + run.stderr)[-3000:])
        target = folder / wheels[0].name
        write_atomic(target, wheels[0].read_bytes())
    for old in folder.glob(f"{target.name.split('-')[0]}-*.whl"):
        if old != target:
            old.unlink()
    return target


def write_readme(root, target):
    """Render ``root``/README.md (CommonMark and tables) as a standalone HTML page at ``target``."""
    from html import escape as html_escape

    from markdown_it import MarkdownIt
    text = Path(root, "README.md").read_text(encoding="utf-8")
    title = text.lstrip("# ").partition("\n")[0]
    body = MarkdownIt("commonmark", {"html": False}).enable("table").render(text)
    style = ("body{max-width:46rem;margin:2rem auto;padding:0 1rem;font:16px/1.55 system-ui,sans-serif}"
             "pre{overflow-x:auto;background:#f5f5f5;padding:.6rem}code{font-size:.9em}"
             "table{border-collapse:collapse;display:block;overflow-x:auto}"
             "td,th{border:1px solid #ccc;padding:.3rem;vertical-align:top}")
    page = (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>README · {html_escape(title)}</title><style>{style}</style></head>\n<body>\n"
            f'<p><a href="../index.html">The book</a></p>\n{body}</body></html>\n')
    write_atomic(target, page.encode("utf-8"))


# --- MyST -> plain Markdown, with the build's values ----------------------------------------

class PageMarkdown:
    """The role and directive callbacks of `plain_markdown` for one page of a built book:
    glue values from myst-nb's glue data, reference texts from the Sphinx environment."""

    def __init__(self, app, docname):
        self.app, self.env, self.docname = app, app.env, docname
        self._glue = {}

    def __call__(self, text):
        return plain_markdown(text, self.role, self.directive)

    def fail(self, what, why):
        raise NotebookError(f"{self.env.doc2path(self.docname)}: {what}: {why}")

    # glue ---------------------------------------------------------------------------------------
    def glued(self, key, what):
        """The mime bundle glued under ``key`` (``name`` or ``page::name``)."""
        doc, _, name = key.rpartition("::")
        docname = self.env.path2doc(self.env.relfn2path(doc, self.docname)[1]) if doc else self.docname
        if docname not in self._glue:
            path = Path(self.env.mystnb_config.output_folder, *f"{docname}.glue.json".split("/"))
            self._glue[docname] = json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}
        if name not in self._glue[docname]:
            self.fail(what, f"no value is glued under {name!r} on page {docname}")
        return self._glue[docname][name]["data"]

    def glue_markdown(self, key, what):
        data = self.glued(key, what)
        if "text/markdown" in data:
            return self(data["text/markdown"])
        if "text/plain" in data:
            from myst_nb.core.variables import format_plain_text
            return escape(minus_signs(format_plain_text(data["text/plain"], "")))
        self.fail(what, f"the value glued under {key!r} is not text ({', '.join(data)})")

    # references ---------------------------------------------------------------------------------
    def label(self, target, what):
        """(docname, id, title) of a label of the std domain."""
        std = self.env.get_domain("std")
        if target in std.labels:
            return std.labels[target]
        if target in std.anonlabels:
            return (*std.anonlabels[target], "")
        self.fail(what, f"no label {target!r}")

    def number(self, docname, node_id):
        """(figtype, "1.2") of a numbered node, or None."""
        for figtype, numbers in self.env.toc_fignumbers.get(docname, {}).items():
            if node_id in numbers:
                return figtype, ".".join(map(str, numbers[node_id]))
        return None

    def role(self, name, content):
        what = f"{{{name}}}`{content}`"
        titled = TITLED.match(content)
        title, target = (titled["title"], titled["target"]) if titled else (None, content)
        if name == "glue:text":                      # name:format, split as myst-nb splits it
            key, fmt = content.rsplit(":", 1) if ":" in content else (content, "s")
            from myst_nb.core.variables import format_plain_text
            data = self.glued(key, what)
            if "text/plain" not in data:
                self.fail(what, "the value has no text/plain")
            return escape(minus_signs(format_plain_text(data["text/plain"], fmt)))   # as the page shows it
        if name == "glue:md":                        # name:myst or name:commonmark
            return self.glue_markdown(content.rsplit(":", 1)[0] if ":" in content else content, what)
        if name in ("glue", "glue:any"):
            return self.glue_markdown(content, what)
        if name == "ref":
            title = title or self.label(target, what)[2]
            return escape(title) if title else self.fail(what, "the label has no title")
        if name == "numref":
            docname, node_id, caption = self.label(target, what)
            numbered = self.number(docname, node_id) or self.fail(what, "the target is not numbered")
            figtype, number = numbered
            text = title or self.app.config.numfig_format[figtype]
            return escape(text.replace("%s", number).replace("{number}", number).replace("{name}", caption))
        if name == "prf:ref":
            return escape(title or self.proof_title(target, what))
        if name == "doc":
            if title:
                return escape(title)
            from sphinx.util import docname_join
            docname = docname_join(self.docname, target)
            if docname not in self.env.titles:
                self.fail(what, "no such page")
            return escape(self.env.titles[docname].astext())
        if name == "term":
            return escape(title or target)
        if name == "math":
            return f"${content}$"
        if name in ("cite:p", "cite:t"):
            return escape(cite_text(name[5:], [self.bib_entry(k.strip(), what) for k in content.split(",")]))
        self.fail(what, "this role has no plain-Markdown form in the notebook")

    # citations (sphinxcontrib-bibtex's data: the entries of the build's .bib files) -------------
    def bib_entry(self, key, what):
        entries = self.env.get_domain("cite").bibdata.data.entries
        return entries[key] if key in entries else self.fail(what, f"no entry {key!r} in the bibliography")

    def bibliography(self, options, what):
        """The entries a ``bibliography`` lists (all with ``:all:``, else those cited in the book),
        formatted by pybtex's plain style, as a Markdown list."""
        from pybtex.plugin import find_plugin
        if set(options) - {"all"}:
            self.fail(what, f"options {sorted(set(options) - {'all'})} have no notebook form (only :all:)")
        domain = self.env.get_domain("cite")
        data = domain.bibdata.data
        cited = {target.key for ref in domain.citation_refs for target in ref.targets}
        keys = [key for key in data.entries if "all" in options or key in cited]
        style = find_plugin("pybtex.style.formatting", "plain")()
        formatted = style.format_entries(sorted((data.entries[k] for k in keys), key=_author_year))
        return "\n".join(f"- {entry.text.render_as('markdown')}" for entry in formatted)

    def proof_title(self, label, what):
        """'Theorem 3' for a sphinx-proof label, as sphinx-proof's own references write it."""
        entry = getattr(self.env, "proof_list", {}).get(label) or self.fail(what, f"no proof label {label!r}")
        number = "" if entry.get("nonumber") else ".".join(
            map(str, self.env.toc_fignumbers.get(entry["docname"], {}).get(entry["countertype"], {}).get(label, ())))
        return f"{entry['realtype'].title()} {number}".strip()

    # directives ---------------------------------------------------------------------------------
    def directive(self, name, arg, options, body):
        what = f"{{{name}}} {arg}".strip()
        if name == "glue:figure":
            caption = self(body)
            node = self.number(*self.label(options["name"], what)[:2]) if "name" in options else None
            lead = f"**{self.app.config.numfig_format[node[0]] % node[1]}.** " if node else ""
            return f"{lead}{caption}" if caption else lead.strip()
        if name in ("glue", "glue:any", "glue:md"):
            return self.glue_markdown(arg, what)
        if name == "literalinclude":
            from sphinx.directives.code import LiteralIncludeReader
            path = self.env.relfn2path(arg, self.docname)[1]
            try:
                code, _ = LiteralIncludeReader(path, options, self.app.config).read(location=(self.docname, None))
            except Exception as error:          # the reader's own errors (a missing file or pyobject)
                self.fail(what, str(error))
            caption = f"*{self(options['caption'])}*\n\n" if options.get("caption") else ""
            return caption + fenced(code, options.get("language", ""))
        if name.startswith("prf:") and options.get("label") in getattr(self.env, "proof_list", {}):
            kind = self.proof_title(options["label"], what)           # numbered, as the page numbers it
            return f"**{kind}{f' ({self(arg)})' if arg else ''}.** {self(body)}"
        if name == "raw":
            return "*(Here the page on the site shows interactive content that a notebook cannot.)*"
        if name == "bibliography":
            return self.bibliography(options, what)
        if name in ("exercise", "exercise-start", "solution", "solution-start"):
            return plain_exercise(name, self.exercise_heading(name, arg, options, what), body, self)
        if name == "tableofcontents":
            docs = self.env.toctree_includes.get(self.docname, [])
            return "\n".join(f"- {escape(self.env.titles[d].astext())}" for d in docs if d in self.env.titles)
        plain = plain_directive(name, arg, options, body, self)
        return plain if plain is not None else self.fail(
            what, "this directive has no plain-Markdown form in the notebook")

    def exercise_heading(self, name, arg, options, what):
        """'Exercise 2 (Title)', or 'Solution to Exercise 2', numbered as sphinx-exercise numbers them."""
        label = options.get("label", "") if name.startswith("exercise") else arg
        entry = getattr(self.env, "sphinx_exercise_registry", {}).get(label)
        if name.startswith("solution") and entry is None:
            self.fail(what, f"no exercise labelled {label!r}")
        number = self.number(entry["docname"], label) if entry else None      # None: :nonumber:
        exercise = "Exercise" + (f" {number[1]}" if number else "")
        if name.startswith("solution"):
            return f"Solution to {exercise}"
        return exercise + (f" ({self(arg)})" if arg else "")


# --- the notebook ------------------------------------------------------------------------------

def _prefix(docname):
    """The path from a page's HTML file, or from its notebook, up to the site's root."""
    return "../" * docname.count("/")


def notebook_uri(docname):
    """The notebook's address relative to the page's HTML file."""
    return _prefix(docname) + f"{FOLDER}/{docname}.ipynb"


def install_cell(title, book, docname, wheel):
    """The notebook's first cell (Markdown): what it is and how to install the project to run it."""
    up = "../" + _prefix(docname)                 # from _notebooks/<docname>.ipynb to the site's root
    return (f"*{escape(title)}*, a page of *{escape(book)}*, as a notebook: its text holds the values "
            f"the book's build computed; its code computes them again and draws the figures.\n\n"
            f"**To run it**, install the project into the Python (3.11 or newer) of your Jupyter kernel, "
            f"from the wheel served with the book, [{wheel}]({up}{DOWNLOADS}/{wheel}):\n\n"
            f'```sh\npip install "{wheel}[notebook]"\n```\n\n'
            f"Then the notebook runs top to bottom in any Jupyter, from any directory, or headless: "
            f"`jupyter-execute {Path(docname).name}.ipynb`. The `notebook` extra adds a kernel and "
            f"`jupyter-execute`; adding `-c constraints.txt` ([constraints.txt]({up}{DOWNLOADS}/constraints.txt)) "
            f"installs the exact versions the book was built with. More in the project's [README]({up}{README}).")


def write_notebook(source, target, *, markdown=lambda text: text, first_cell=None):
    """Convert the MyST notebook ``source`` to ``target`` (.ipynb) with jupytext, atomically.

    ``markdown`` turns each Markdown cell's MyST into what the notebook shows
    (cells it leaves empty are dropped); ``first_cell``, if given, is a
    Markdown cell put before all others.
    """
    import jupytext
    from nbformat.v4 import new_markdown_cell
    notebook = jupytext.read(source, fmt="md:myst")
    notebook.metadata.pop("jupytext", None)          # the pairing describes the source, not this file
    cells = [new_markdown_cell(first_cell)] if first_cell else []
    for cell in notebook.cells:
        if cell.cell_type == "markdown":
            cell.source = markdown(cell.source)
            if not cell.source.strip():
                continue
        cells.append(cell)
    notebook.cells = cells
    write_atomic(target, jupytext.writes(notebook, fmt="ipynb").encode("utf-8"))


# --- Sphinx ------------------------------------------------------------------------------------

def is_notebook(app, docname):
    """Whether the page is a MyST notebook (its front matter names a kernelspec)."""
    return bool(app.env.metadata.get(docname, {}).get("kernelspec"))


def _project_files(app):
    """The wheel (its name kept for the links), constraints.txt and the README, into the site."""
    if app.builder.format != "html":
        return
    site = Path(app.outdir)
    # The wheel is built again only when what it packages changed.
    key = source_digest() + hashlib.sha256((ROOT / "pyproject.toml").read_bytes()
                                           + (ROOT / "README.md").read_bytes()).hexdigest()
    stamp, wheels = site.parent / ".wheel-source", sorted((site / DOWNLOADS).glob("*.whl"))
    if len(wheels) == 1 and stamp.is_file() and stamp.read_text(encoding="utf-8") == key:
        app.notebook_wheel = wheels[0].name
    else:
        app.notebook_wheel = build_wheel(ROOT, site / DOWNLOADS).name
        stamp.write_text(key, encoding="utf-8")
    write_atomic(site / DOWNLOADS / "constraints.txt", (ROOT / "constraints.txt").read_bytes())
    write_readme(ROOT, site / README)


def _outdated(app, env, added, changed, removed):
    """The notebook pages to write again because the wheel they link has a new name."""
    wheel = getattr(app, "notebook_wheel", None)
    if getattr(env, "notebook_wheel", None) == wheel:
        return []
    env.notebook_wheel = wheel
    return sorted(d for d in env.found_docs - added - changed - removed if is_notebook(app, d))


def _link(app, doctree, docname):
    if app.builder.format != "html" or not is_notebook(app, docname):
        return
    sections = list(doctree.findall(nodes.section))
    if not sections:
        return
    up = _prefix(docname)
    para = nodes.paragraph("", "", nodes.Text("This page as a Jupyter notebook: "),
                           nodes.reference("", f"{Path(docname).name}.ipynb", refuri=notebook_uri(docname)),
                           nodes.Text("; it runs in any Jupyter where "),
                           nodes.reference("", "the project's wheel",
                                           refuri=f"{up}{DOWNLOADS}/{app.notebook_wheel}"),
                           nodes.Text(" is installed (see the "),
                           nodes.reference("", "README", refuri=up + README), nodes.Text(")."),
                           classes=["notebook-download"])
    title = sections[0].next_node(nodes.title)
    sections[0].insert(sections[0].index(title) + 1 if title is not None else 0, para)


def _write_all(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    from myst_nb.sphinx_ import NbMetadataCollector
    from sphinx.util import logging
    for docname in sorted(app.env.found_docs):
        if is_notebook(app, docname):
            target = Path(app.outdir, FOLDER, f"{docname}.ipynb")
            if (NbMetadataCollector.get_exec_data(app.env, docname) or {}).get("succeeded") is False:
                # Its glue is incomplete; myst-nb has reported the cell that failed.
                logging.getLogger(__name__).warning(f"{docname}: no notebook written: the page failed to execute")
                target.unlink(missing_ok=True)           # nor an earlier build's left in its place
                continue
            first = install_cell(app.env.titles[docname].astext(), app.env.titles[app.config.root_doc].astext(),
                                 docname, app.notebook_wheel)
            write_notebook(app.env.doc2path(docname), target, markdown=PageMarkdown(app, docname), first_cell=first)


def setup(app):
    app.connect("builder-inited", _project_files)
    app.connect("env-get-outdated", _outdated)
    app.connect("doctree-resolved", _link)
    app.connect("build-finished", _write_all)
    # env_version: a new version makes Sphinx read every page again (the line under each title changed).
    return {"version": "2", "env_version": 2, "parallel_read_safe": True, "parallel_write_safe": True}
