"""Each notebook page of the built site can be downloaded as a notebook that stands alone.

book/_ext/notebooks.py writes ``_notebooks/<page>.ipynb`` (jupytext), links it under
the page's title, and serves the project's wheel and README beside the pages.
Checked against the site `book_html` names:

* every page that is a notebook has one, linked from its page with the wheel and
  the README, with the page's code cells (as myst-nb reads them) in order and a
  first cell that says how to install the wheel the site serves;
* no notebook carries MyST markup a plain Jupyter shows raw (a role, a fenced
  directive, a target), and every value the page pastes from glue is in its text
  (the scan is shown catching planted markup);
* the wheel holds the project's packages and declares the ``notebook`` extra;
* what a reader does: a new virtual environment in a temporary directory, the
  site's wheel installed there with its ``notebook`` extra (versions pinned by
  constraints.txt), and §1's notebook, copied outside the repository, run top to
  bottom by that environment's ``jupyter-execute``; its figures must be the
  page's, by name and byte for byte, and what it shows as Markdown plain Markdown.
"""

from __future__ import annotations

import base64
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import time
import zipfile
from collections import Counter
from html import unescape
from pathlib import Path
from types import SimpleNamespace

import pytest

from .pages import code_cells

ROOT = Path(__file__).parents[1]
sys.path.insert(0, str(ROOT / "book" / "_ext"))
import notebooks  # noqa: E402

sys.path.remove(str(ROOT / "book" / "_ext"))

PAGES = sorted(p for p in (ROOT / "book").glob("*.md")
               if code_cells(p.read_text(encoding="utf-8")) is not None)

#: MyST markup a plain Jupyter would show as it is: a role, a fenced directive, a target line.
LEFTOVER = re.compile(r"\{[A-Za-z][\w:.+-]*\}`|`{3,}\s*\{|:{3,}\s*\{|^\s*\([^()\s]+\)=\s*$", re.M)


def leftovers(notebook):
    """[(cell index, markup)] of every MyST role or directive left in a notebook's Markdown cells."""
    return [(i, m.group()) for i, cell in enumerate(notebook["cells"]) if cell["cell_type"] == "markdown"
            for m in LEFTOVER.finditer("".join(cell["source"]))]


def _notebook(book_html, stem):
    return json.loads((book_html / "_notebooks" / f"{stem}.ipynb").read_text(encoding="utf-8"))


def _wheel(book_html):
    wheels = sorted((book_html / notebooks.DOWNLOADS).glob("*.whl"))
    assert len(wheels) == 1, f"{book_html / notebooks.DOWNLOADS} holds {len(wheels)} wheels"
    return wheels[0]


def test_the_book_has_notebook_pages():
    assert len(PAGES) >= 7


@pytest.mark.parametrize("page", PAGES, ids=[p.stem for p in PAGES])
def test_each_notebook_page_links_its_notebook_with_its_code_cells(book_html, page):
    nb_file = book_html / "_notebooks" / f"{page.stem}.ipynb"
    assert nb_file.is_file(), f"{nb_file} is missing"
    notebook = json.loads(nb_file.read_text(encoding="utf-8"))
    code = ["".join(c["source"]) for c in notebook["cells"] if c["cell_type"] == "code"]
    assert code == code_cells(page.read_text(encoding="utf-8"))
    assert notebook["metadata"]["kernelspec"]["name"] == "python3"
    assert all(not c.get("outputs") for c in notebook["cells"] if c["cell_type"] == "code")
    # The first cell: how to install the wheel the site serves, linked from where the notebook lies.
    wheel = _wheel(book_html).name
    first = notebook["cells"][0]
    assert first["cell_type"] == "markdown"
    text = "".join(first["source"])
    assert f'pip install "{wheel}[notebook]"' in text
    for link in re.findall(r"\]\(([^)]+)\)", text):
        assert (nb_file.parent / link).resolve().is_file(), f"{page.stem}: the first cell's link {link} is broken"
    assert f"../{notebooks.DOWNLOADS}/{wheel}" in text and f"../{notebooks.README}" in text
    # The page links its notebook, the wheel and the README under its title.
    html = (book_html / f"{page.stem}.html").read_text(encoding="utf-8")
    for href in (f"_notebooks/{page.stem}.ipynb", f"{notebooks.DOWNLOADS}/{wheel}", notebooks.README):
        assert f'href="{href}"' in html, f"{page.stem}.html does not link {href}"


@pytest.mark.parametrize("page", PAGES, ids=[p.stem for p in PAGES])
def test_no_notebook_carries_myst_markup_and_each_shows_the_values_its_page_pasted(book_html, page):
    notebook = _notebook(book_html, page.stem)
    assert leftovers(notebook) == []
    # Every value the page shows from glue (myst-nb's pasted text) is in the notebook's text.
    html = (book_html / f"{page.stem}.html").read_text(encoding="utf-8")
    pasted = [_plain(unescape(v)) for v in re.findall(r'<span class="pasted-text">([^<]*)</span>', html)]
    prose = re.sub(r"\\(.)", r"\1", "".join("".join(c["source"]) for c in notebook["cells"]
                                            if c["cell_type"] == "markdown"))
    assert [v for v in pasted if v not in prose] == []


def _plain(text):
    """Text with Sphinx's smart quotes turned back into plain ones."""
    return text.translate(str.maketrans("‘’“”", "''\"\""))


def test_the_markup_scan_finds_planted_roles_and_directives(book_html):
    clean = _notebook(book_html, "s1_what_changes")
    assert leftovers(clean) == []
    at = next(i for i, c in enumerate(clean["cells"]) if c["cell_type"] == "markdown" and i > 0)
    for planted in ("see {numref}`fig-s1-bump`", "{glue:text}`s1_size`", "```{glue:figure} fig-s1-bump",
                    ":::{prf:theorem} A title", "(s1)="):
        notebook = json.loads(json.dumps(clean))
        notebook["cells"][at]["source"] = "".join(notebook["cells"][at]["source"]) + "\n\n" + planted + "\n"
        assert [i for i, _ in leftovers(notebook)] == [at], planted


def test_the_writer_refuses_a_role_or_directive_it_cannot_write_naming_the_page():
    # (chapter.page.plain_markdown, the converter, is tested in tests/test_page.py.)
    app = SimpleNamespace(env=SimpleNamespace(doc2path=lambda d: f"book/{d}.md"))
    page = notebooks.PageMarkdown(app, "s9_x")
    with pytest.raises(notebooks.NotebookError, match=r"book/s9_x.md: \{kbd\}`C-c`: this role has no"):
        page("Press {kbd}`C-c`.")
    with pytest.raises(notebooks.NotebookError, match=r"book/s9_x.md: \{figure\} a.png: this directive has no"):
        page("```{figure} a.png\n```")


def test_the_site_serves_a_wheel_of_the_project_and_the_readme(book_html):
    with zipfile.ZipFile(_wheel(book_html)) as wheel:
        names = set(wheel.namelist())
        metadata = wheel.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    packaged = {n for n in names if ".dist-info/" not in n}
    where = {"renderer": ROOT / "renderer", "proofs": ROOT / "proofs", "lab": ROOT / "lab",
             "chapter": ROOT / "book" / "chapter"}
    on_disk = {f"{package}/{p.relative_to(root).as_posix()}" for package, root in where.items()
               for p in root.rglob("*") if p.is_file() and "__pycache__" not in p.parts}
    assert packaged == on_disk
    assert {"renderer/generated.py", "renderer/js/render.js", "chapter/page.py"} <= packaged
    assert "Provides-Extra: notebook" in metadata
    assert re.search(r'^Requires-Dist: ipykernel\S* ?;\s*extra == "notebook"', metadata, re.M)
    readme = (book_html / notebooks.README).read_text(encoding="utf-8")
    headings = re.findall(r"^#+ (.+)$", (ROOT / "README.md").read_text(encoding="utf-8"), re.M)
    shown = [unescape(re.sub(r"<[^>]+>", "", h)) for h in re.findall(r"<h\d>(.*?)</h\d>", readme)]
    assert shown == [h.replace("`", "") for h in headings]
    assert (book_html / notebooks.DOWNLOADS / "constraints.txt").read_bytes() == (ROOT / "constraints.txt").read_bytes()


def test_a_new_wheel_name_makes_every_notebook_page_written_again():
    # The line under each title links the wheel by name; a new version must not leave it dangling.
    env = SimpleNamespace(found_docs={"s1", "s9", "new"}, notebook_wheel="p-0.1.0-py3-none-any.whl",
                          metadata={"s1": {"kernelspec": {"name": "python3"}}, "s9": {}, "new": {"kernelspec": {}}})
    app = SimpleNamespace(env=env, notebook_wheel="p-0.1.0-py3-none-any.whl")
    assert notebooks._outdated(app, env, set(), set(), set()) == []
    app.notebook_wheel = "p-0.2.0-py3-none-any.whl"
    assert notebooks._outdated(app, env, {"new"}, set(), set()) == ["s1"]
    assert env.notebook_wheel == app.notebook_wheel and notebooks._outdated(app, env, set(), set(), set()) == []


def test_the_wheel_is_built_again_when_what_it_packages_changed(tmp_path, monkeypatch):
    """The site's wheel is reused only under the same key (the source digest, pyproject.toml and the README)
    and as the one wheel there: a change of any part, or a second wheel, builds it again."""
    root, site = tmp_path / "root", tmp_path / "build" / "html"
    root.mkdir()
    for name in ("pyproject.toml", "README.md", "constraints.txt"):
        (root / name).write_text(name)
    built, digest = [], ["d0"]

    def build_wheel(_, folder):
        folder.mkdir(parents=True, exist_ok=True)
        for old in folder.glob("*.whl"):
            old.unlink()
        built.append(folder / f"p-{len(built)}-py3-none-any.whl")
        built[-1].write_bytes(b"wheel")
        return built[-1]
    monkeypatch.setattr(notebooks, "ROOT", root)
    monkeypatch.setattr(notebooks, "build_wheel", build_wheel)
    monkeypatch.setattr(notebooks, "write_readme", lambda *a: None)
    monkeypatch.setattr(notebooks, "source_digest", lambda: digest[0])
    app = SimpleNamespace(builder=SimpleNamespace(format="html"), outdir=str(site))

    def builds(change):
        before = len(built)
        change()
        notebooks._project_files(app)
        assert app.notebook_wheel == built[-1].name
        return len(built) - before
    assert builds(lambda: None) == 1 and builds(lambda: None) == 0
    for change in (lambda: (root / "pyproject.toml").write_text("version 2"),
                   lambda: (root / "README.md").write_text("new"), lambda: digest.__setitem__(0, "d1"),
                   lambda: (site / notebooks.DOWNLOADS / "other.whl").write_bytes(b"")):
        assert builds(change) == 1 and builds(lambda: None) == 0


def test_a_failed_wheel_build_names_what_failed(tmp_path):
    # The project as it is, but with a version no packaging tool accepts.
    root = tmp_path / "project"
    root.mkdir()
    (root / "pyproject.toml").write_text((ROOT / "pyproject.toml").read_text(encoding="utf-8").replace(
        'version = "', 'version = "not a version ', 1), encoding="utf-8")
    shutil.copy(ROOT / "README.md", root)
    for package in ("renderer", "proofs", "lab", "book/chapter"):
        (root / package).mkdir(parents=True)
        (root / package / "__init__.py").write_text("")
    with pytest.raises(notebooks.NotebookError,
                       match=r"(?s)building the project's wheel with setuptools\.build_meta failed.*version"):
        notebooks.build_wheel(root, tmp_path / "site")
    assert not list((tmp_path / "site").glob("*"))


def _clean_env(tmp, venv):
    """The environment of a reader's shell: the new venv first on PATH, nothing pointing into
    the repository, and Jupyter's and IPython's settings in temporary directories."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME", "MPLBACKEND") and not k.startswith("SYMRENDER_")}
    path = [p for p in env.get("PATH", "").split(os.pathsep) if p and not Path(p).resolve().is_relative_to(ROOT)]
    env.update(PATH=os.pathsep.join([str(venv / "bin"), *path]), JUPYTER_DATA_DIR=str(tmp / "jupyter-data"),
               JUPYTER_CONFIG_DIR=str(tmp / "jupyter-config"), IPYTHONDIR=str(tmp / "ipython"))
    return env


RUN = ["s1_what_changes"]


@pytest.mark.slow
@pytest.mark.parametrize("stem", RUN)
def test_a_downloaded_notebook_runs_in_a_new_environment_with_the_wheel(book_html, tmp_path, stem):
    assert not tmp_path.resolve().is_relative_to(ROOT)
    venv, work = tmp_path / "venv", tmp_path / "reader"
    work.mkdir()
    env = _clean_env(tmp_path, venv)
    seconds = {}

    def run(step, *command, timeout):
        t0 = time.perf_counter()
        done = subprocess.run(command, cwd=work, env=env, capture_output=True, text=True, timeout=timeout)
        seconds[step] = round(time.perf_counter() - t0, 1)
        assert done.returncode == 0, f"{step} failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
        return done.stdout

    wheel = Path(shutil.copy(_wheel(book_html), work)).name
    # The first cell's command, pinned, with uv's pip (a test dependency) in place of pip: the same
    # wheel, extra and versions, installed in a fraction of pip's time.
    uv = shutil.which("uv", path=str(Path(sys.executable).parent)) or pytest.fail("uv is not installed in this venv")
    run("venv", uv, "venv", "--quiet", "--python", sys.executable, str(venv), timeout=300)
    run("install", uv, "pip", "install", "--quiet", "--python", str(venv / "bin" / "python"),
        "-c", str(ROOT / "constraints.txt"), f"{wheel}[notebook]", timeout=1800)
    python = str(venv / "bin" / "python")
    where = run("import", python, "-c", "import proofs, renderer; print(proofs.__file__, renderer.__file__)", timeout=300)
    assert all(Path(p).is_relative_to(venv) for p in where.split()), where
    copy = Path(shutil.copy(book_html / "_notebooks" / f"{stem}.ipynb", work))
    run("run", str(venv / "bin" / "jupyter-execute"), "--inplace", "--timeout=900", copy.name, timeout=1800)
    print(f"\n{stem}: seconds {seconds}")

    notebook = json.loads(copy.read_text(encoding="utf-8"))
    code = [c for c in notebook["cells"] if c["cell_type"] == "code"]
    assert all(c["execution_count"] for c in code), "a code cell did not run"
    assert not [o for c in code for o in c["outputs"] if o["output_type"] == "error"]
    # What it shows as Markdown (chapter.page.markdown) is plain Markdown too.
    shown_md = ["".join(o["data"]["text/markdown"]) for c in code for o in c["outputs"]
                if "text/markdown" in o.get("data", {})]
    assert [m for text in shown_md for m in LEFTOVER.findall(text)] == []
    assert bool(shown_md) == ("markdown(" in (ROOT / "book" / f"{stem}.md").read_text(encoding="utf-8"))
    # The kernel ran the installed renderer: numba cached its compiled functions beside it.
    assert list((Path(where.split()[1]).parent / "__pycache__").glob("*.nbi"))
    # Its figures are the page's: the names its glue:figure directives show, in order, and the same PNGs.
    shown = [(o["metadata"].get("symrender", {}).get("figure"), o["data"]["image/png"]) for c in code
             for o in c["outputs"] if "image/png" in o.get("data", {})]
    page = (ROOT / "book" / f"{stem}.md").read_text(encoding="utf-8")
    assert [name for name, _ in shown] == re.findall(r"^`{3,}\{glue:figure\}\s*(\S+)", page, re.M)
    html = (book_html / f"{stem}.html").read_text(encoding="utf-8")
    site = Counter(hashlib.sha256((book_html / src).read_bytes()).hexdigest()
                   for src in re.findall(r'<img[^>]* src="(_images/[^"]+\.png)"', html))
    drawn = Counter(hashlib.sha256(base64.b64decode(png)).hexdigest() for _, png in shown)
    assert drawn == site




def test_a_citation_reads_as_the_theorems_number_and_title_on_the_page(book_html):
    """A proof's citation ⟪id⟫ (proofs/core.py, rule 8) on the site: a link to the theorem's box reading
    "Theorem n", n the number the box's heading shows, then its title in parentheses, as the heading reads.
    (A notebook shows the box when its cell runs, outside the book: "Theorem (title)", unnumbered like the
    box's heading there; tests/test_checker.py.)"""
    from proofs.core import CITATION
    from proofs.registry import CITABLE, THEOREMS
    pages = {p.name: unescape(p.read_text(encoding="utf-8")) for p in book_html.glob("s[0-9]_*.html")}
    cited = {i for t in THEOREMS.values() for text in [t.statement] + [s.why for s in t.steps]
             for i in CITATION.findall(text)}
    assert cited
    for theorem_id in cited:
        links = [(page or name, n, title) for name, html in pages.items() for page, n, title in
                 re.findall(rf'href="([\w.]*)#thm-{re.escape(theorem_id)}">Theorem (\d+)</a> \(([^)]*)\)', html)]
        assert links and {title for *_, title in links} == {CITABLE[theorem_id]}, (theorem_id, links)
        home = {name for name, html in pages.items() if f'id="thm-{theorem_id}"' in html}
        assert len(home) == 1 and {page for page, *_ in links} <= home, (theorem_id, links, home)
        heading = re.search(rf'id="thm-{re.escape(theorem_id)}">\s*<p[^>]*><span[^>]*>Theorem (\d+) </span> '
                            rf'\(([^)]*)\)', pages[home.pop()])
        assert heading and heading[2] == CITABLE[theorem_id] and {n for _, n, _ in links} == {heading[1]}, theorem_id


def test_the_ledger_lists_every_theorem_once_as_theorem_n_in_the_books_order(book_html):
    """§6's theorem ledger names each theorem as its box's heading does ("Theorem n (title)", linked
    to the box) and lists them in the order the book numbers them, 1, 2, 3, ...: a reader who meets
    Theorem 5 in §3 finds it fifth (the registry's order is the chapter's)."""
    from proofs.registry import CITABLE, THEOREMS
    pages = {p.name: unescape(p.read_text(encoding="utf-8")) for p in book_html.glob("s[0-9]_*.html")}
    number = {i: int(n) for html in pages.values()
              for i, n in re.findall(r'id="thm-([\w-]+)">\s*<p[^>]*><span[^>]*>Theorem (\d+) </span>', html)}
    ledger = re.findall(r'id="ledger-([\w-]+)">(?:</span>)?<a[^>]*href="[\w.]*#thm-([\w-]+)">Theorem (\d+)</a> \(([^)]*)\)',
                        pages["s6_ledger.html"])
    assert [i for i, *_ in ledger] == list(THEOREMS) == sorted(number, key=number.get), (ledger, number)
    shown = [(target, int(n), title.replace("’", "'")) for _, target, n, title in ledger]     # the site's quotes curl
    assert shown == [(i, number[i], CITABLE[i]) for i in THEOREMS]
    assert sorted(number.values()) == list(range(1, len(THEOREMS) + 1))


# --- the learning aids: exercises, margin notes, citations, the bibliography ----------------------

def _bib():
    from pybtex.database import parse_file
    return parse_file(ROOT / "book" / "references.bib").entries


def test_a_citation_reads_as_the_site_writes_it_author_year():
    bib = _bib()
    one, two, three = (next(e for e in bib.values() if len(e.persons["author"]) == n) for n in (1, 2, 3))
    last = [[" ".join(p.last_names) for p in e.persons["author"]] for e in (one, two, three)]
    year = [e.fields["year"] for e in (one, two, three)]
    assert notebooks.cite_text("t", [one]) == f"{last[0][0]} [{year[0]}]"
    assert notebooks.cite_text("p", [two]) == f"[{last[1][0]} and {last[1][1]}, {year[1]}]"
    # Several works: in the bibliography's (author) order whatever the order cited, "et al." past two.
    both = sorted([(f"{last[1][0]} and {last[1][1]}", year[1]), (f"{last[2][0]} et al.", year[2])])
    assert notebooks.cite_text("p", [two, three]) == notebooks.cite_text("p", [three, two]) == \
        "[" + ", ".join(f"{n}, {y}" for n, y in both) + "]"


def test_every_work_in_the_bibliography_has_what_a_reader_needs_to_find_it():
    required = {"article": {"journal", "volume", "pages"}, "book": {"publisher", "edition"},
                "inproceedings": {"booktitle", "pages"}}
    for key, entry in _bib().items():
        fields = {f.lower() for f in entry.fields}
        assert entry.persons.get("author") and {"title", "year"} <= fields, key
        assert required[entry.type] <= fields and fields & {"doi", "isbn"}, (key, required[entry.type] - fields)
        assert not re.search(r"\d", key), f"{key}: a key with a digit reads as a typed number in the prose scan"


def test_the_writer_refuses_an_unknown_citation_or_exercise_naming_the_page():
    bib = SimpleNamespace(data=SimpleNamespace(entries=_bib()))
    env = SimpleNamespace(doc2path=lambda d: f"book/{d}.md", get_domain=lambda name: SimpleNamespace(bibdata=bib),
                          sphinx_exercise_registry={})
    page = notebooks.PageMarkdown(SimpleNamespace(env=env), "s9_x")
    assert page("As {cite:t}`blinn-wrinkled` shows.").startswith("As Blinn \\[")
    with pytest.raises(notebooks.NotebookError, match=r"book/s9_x.md: \{cite:p\}`nobody`: no entry 'nobody'"):
        page("Shown {cite:p}`nobody`.")
    with pytest.raises(notebooks.NotebookError, match=r"book/s9_x.md: \{solution\} ex-none: no exercise labelled"):
        page("```{solution} ex-none\nIt is 2.\n```")


def _html_exercises(html):
    """[(number, title)] of the exercises a built page shows (sphinx-exercise's headings)."""
    return [(n, unescape(t).translate(str.maketrans("‘’", "''"))) for n, t in re.findall(
        r'<div class="exercise[^"]*" id="[^"]+">\s*<p class="admonition-title"><span class="caption-number">'
        r'Exercise (\d+) </span> \(([^)]*)\)</p>', html)]


def test_each_exercise_of_the_site_is_in_its_notebook_numbered_with_its_solution(book_html):
    found = 0
    for page in PAGES:
        html = (book_html / f"{page.stem}.html").read_text(encoding="utf-8")
        shown = _html_exercises(html)
        text = re.sub(r"\\(.)", r"\1", "\n\n".join("".join(c["source"]) for c in
                                                   _notebook(book_html, page.stem)["cells"]))
        written = re.findall(r"^\*\*Exercise (\d+) \((.*)\)\.\*\*$", text, re.M)
        assert written == shown, page.stem
        # Each solution follows its exercise: folded in a <details>, or a gated one opened by its heading.
        solutions = re.findall(r"(?:<summary>|^\*\*)Solution to Exercise (\d+)", text, re.M)
        assert solutions == [n for n, _ in shown], page.stem
        assert html.count('class="solution dropdown') == len(shown), f"{page.stem}: a solution is not folded"
        found += len(shown)
    assert found >= 1


def test_the_bibliography_lists_every_work_on_the_site_and_in_the_notebook(book_html):
    keys = _bib()
    html = (book_html / "s8_history.html").read_text(encoding="utf-8")
    listed = re.findall(r'<div class="citation" id="[^"]+" role="listitem">', html)
    assert len(listed) == len(keys)
    text = "".join("".join(c["source"]) for c in _notebook(book_html, "s8_history")["cells"])
    dois = re.findall(r"^- .*?\(https://doi\.org/([^)\s]+)\)", text, re.M | re.S)
    items = re.findall(r"^- ", text, re.M)
    assert len(items) >= len(keys)
    assert sorted(dois) == sorted(e.fields["doi"] for e in keys.values() if "doi" in e.fields)


def test_a_bibliography_lists_the_cited_works_or_with_all_every_work():
    from sphinxcontrib.bibtex.citation_target import CitationTarget
    from sphinxcontrib.bibtex.roles import CitationRef
    bib = _bib()
    cited = [CitationRef("id1", "s8_history", 1, [CitationTarget("squire-trapp", "", ""),
                                                  CitationTarget("blinn-wrinkled", "", "")])]
    domain = SimpleNamespace(bibdata=SimpleNamespace(data=SimpleNamespace(entries=bib)), citation_refs=cited)
    env = SimpleNamespace(doc2path=lambda d: f"book/{d}.md", get_domain=lambda name: domain)
    page = notebooks.PageMarkdown(SimpleNamespace(env=env), "s8_x")
    items = page("```{bibliography}\n```").split("\n- ")
    assert [bib[k].fields["doi"] in item for item, k in zip(items, ("blinn-wrinkled", "squire-trapp"))] == [True] * 2
    assert len(items) == 2
    assert len(page("```{bibliography}\n:all:\n```").split("\n- ")) == len(bib)
    with pytest.raises(notebooks.NotebookError, match=r"\{bibliography\}: options \['filter'\] have no notebook"):
        page("```{bibliography}\n:filter: docname in docnames\n```")
