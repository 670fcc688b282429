"""book/_ext/nb_deps.py: a page's cache key follows exactly the project files it imports.

Synthetic packages in a temporary directory stand in for renderer/ and proofs/:

    plain/   __init__.py empty (like proofs/)
        a.py      imports nothing of ours
        b.py      from .c import THING            (transitive)
        c.py
        lazy.py   imports plain.c inside a function
        gen.py    reads js/*.js at run time       (like renderer/jsgen.py)
        other.py  imported by no page
    pkg/     __init__.py re-exports from .core    (like renderer/)
        core.py   from . import util
        util.py

Each check is also run against a wrong variant of the finder or of the key,
and must reject it: a check that a broken implementation passes proves nothing.
"""

from __future__ import annotations

import ast
import importlib.util
import json
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("nb_deps", ROOT / "book" / "_ext" / "nb_deps.py")
nb_deps = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(nb_deps)

FRONT = """---
jupytext:
  text_representation:
    extension: .md
    format_name: myst
kernelspec:
  display_name: Python 3
  language: python
  name: python3
---

# A page

Some prose.
"""

SOURCES = {
    "plain/__init__.py": "",
    "plain/a.py": "import math\nA = 1\n",
    "plain/b.py": "from .c import THING\n",
    "plain/c.py": "THING = 3\n",
    "plain/lazy.py": "def later():\n    from plain.c import THING\n    return THING\n",
    "plain/gen.py": "from pathlib import Path\nJS = Path(__file__).with_name('js')\n",
    "plain/js/sim.js": "export const X = 1;\n",
    "plain/other.py": "import numpy\n",
    "pkg/__init__.py": "from .core import f\n",
    "pkg/core.py": "from . import util\ndef f():\n    return util.g()\n",
    "pkg/util.py": "def g():\n    return 2\n",
}


def page(*cells: str) -> str:
    """A MyST markdown notebook whose code cells are ``cells``."""
    return FRONT + "".join(f"\n```{{code-cell}} ipython3\n{c}\n```\n\nMore prose.\n" for c in cells)


@pytest.fixture(autouse=True)
def fresh_memo(monkeypatch):
    """Each test parses module files afresh (the memo would hide a patched finder)."""
    monkeypatch.setattr(nb_deps, "_IMPORTS_MEMO", {})


@pytest.fixture
def project(tmp_path):
    for name, text in SOURCES.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    return tmp_path


@pytest.fixture
def packages(project):
    return {"plain": project / "plain", "pkg": project / "pkg"}


def rel(files, project):
    return {f.relative_to(project.resolve()).as_posix() for f in files}


# --- the finder -------------------------------------------------------------------------------

CASES = [
    # (what, code cells, the files importing them runs)
    ("direct import", ["import plain.a"], {"plain/__init__.py", "plain/a.py"}),
    ("from-import of a submodule", ["from plain import a"], {"plain/__init__.py", "plain/a.py"}),
    ("transitive", ["from plain.b import THING"], {"plain/__init__.py", "plain/b.py", "plain/c.py"}),
    ("package re-export", ["from pkg import f"], {"pkg/__init__.py", "pkg/core.py", "pkg/util.py"}),
    ("submodule runs the package __init__", ["import pkg.util"],
     {"pkg/__init__.py", "pkg/core.py", "pkg/util.py"}),
    ("import inside a function", ["import plain.lazy"],
     {"plain/__init__.py", "plain/lazy.py", "plain/c.py"}),
    ("IPython magic in the cell", ["%time import plain.a\n!echo hi"], {"plain/__init__.py", "plain/a.py"}),
    ("nothing from the project", ["import numpy as np\nfrom math import pi"], set()),
    ("several cells", ["import numpy", "from plain.a import A", "from pkg.util import g"],
     {"plain/__init__.py", "plain/a.py", "pkg/__init__.py", "pkg/core.py", "pkg/util.py"}),
]


@pytest.mark.parametrize("what, cells, expected", CASES, ids=[c[0] for c in CASES])
def test_finder_finds_exactly_the_files_a_page_runs(project, packages, what, cells, expected):
    assert rel(nb_deps.dependencies(page(*cells), packages), project) == expected


def _finder_misses_a_case(project, packages):
    return any(rel(nb_deps.dependencies(page(*cells), packages), project) != expected
               for _, cells, expected in CASES)


def test_finder_checks_reject_a_finder_that_ignores_transitive_imports(project, packages, monkeypatch):
    monkeypatch.setattr(nb_deps, "_imports_of_file", lambda file, package: frozenset())
    assert _finder_misses_a_case(project, packages)


def test_finder_checks_reject_a_finder_that_ignores_package_inits(project, packages, monkeypatch):
    real = nb_deps._module_file
    monkeypatch.setattr(nb_deps, "_module_file", lambda name, pk: real(name, pk)[-1:])
    assert _finder_misses_a_case(project, packages)


def test_finder_checks_reject_a_finder_that_reads_only_top_level_imports(project, packages, monkeypatch):
    real = nb_deps.imported_names
    monkeypatch.setattr(nb_deps, "imported_names",
                        lambda tree, package="": real(ast.Module(body=[n for n in tree.body
                                                                       if isinstance(n, (ast.Import, ast.ImportFrom))],
                                                                 type_ignores=[]), package=package))
    assert _finder_misses_a_case(project, packages)


def test_star_import_and_unparsable_cell_depend_on_every_module(project, packages):
    everything = rel(nb_deps._all_modules(packages), project)
    assert rel(nb_deps.dependencies(page("from plain import *"), packages), project) >= {
        "plain/a.py", "plain/b.py", "plain/c.py", "plain/other.py"}
    assert rel(nb_deps.dependencies(page("def broken(:\n    pass"), packages), project) == everything


def test_data_files_a_module_reads_are_dependencies(project, packages, monkeypatch):
    monkeypatch.setattr(nb_deps, "DATA_FILES", {"plain.gen": ("js/*.js",)})
    assert "plain/js/sim.js" in rel(nb_deps.dependencies(page("import plain.gen"), packages), project)
    monkeypatch.setattr(nb_deps, "DATA_FILES", {})       # the wrong variant misses it
    assert "plain/js/sim.js" not in rel(nb_deps.dependencies(page("import plain.gen"), packages), project)


def test_a_page_that_is_not_a_notebook_has_no_dependencies(packages):
    assert nb_deps.dependencies("# Just markdown\n\n```python\nimport plain.a\n```\n", packages) is None
    assert nb_deps.page_digest("# Just markdown\n", packages) is None


def test_ipynb_pages_are_read_and_injected(project, packages):
    nb = {"cells": [{"cell_type": "code", "source": ["from plain.b ", "import THING"], "metadata": {},
                     "outputs": [], "execution_count": None}],
          "metadata": {}, "nbformat": 4, "nbformat_minor": 5}
    text = json.dumps(nb)
    files = nb_deps.dependencies(text, packages, path="page.ipynb")
    assert rel(files, project) == {"plain/__init__.py", "plain/b.py", "plain/c.py"}
    last = json.loads(nb_deps.inject(text, "abc", path="page.ipynb"))["cells"][-1]
    assert last["source"] == "# nb-deps: abc" and last["metadata"]["tags"] == ["remove-cell"]


# --- the digest -------------------------------------------------------------------------------

def _reacts_correctly(project, packages, digest_of):
    """The digest of a page importing plain.b changes when plain/c.py changes, and not
    when plain/other.py (imported by no page) or pkg/util.py changes."""
    text = page("from plain.b import THING")
    before = digest_of(text)
    (project / "plain/other.py").write_text("import numpy  # edited\n")
    (project / "pkg/util.py").write_text("def g():\n    return 3\n")
    unrelated = digest_of(text)
    (project / "plain/c.py").write_text("THING = 3  # a comment changes the key too\n")
    related = digest_of(text)
    return unrelated == before and related != before


def test_digest_changes_with_a_dependency_and_not_with_an_unrelated_file(project, packages):
    assert _reacts_correctly(project, packages, lambda text: nb_deps.page_digest(text, packages))


def test_digest_check_rejects_a_key_on_file_names_only(project, packages):
    def names_only(text):
        return sorted(rel(nb_deps.dependencies(text, packages), project))
    assert not _reacts_correctly(project, packages, names_only)


def test_digest_check_rejects_a_key_on_every_project_file(project, packages):
    def everything(text):
        return nb_deps.digest(nb_deps._all_modules(packages), packages)
    assert not _reacts_correctly(project, packages, everything)


def test_asset_digest_follows_the_generating_module_but_stays_out_of_the_cache_key(project, packages,
                                                                                  monkeypatch):
    monkeypatch.setattr(nb_deps, "DATA_FILES", {"plain.gen": ("js/*.js",)})
    monkeypatch.setattr(nb_deps, "ASSETS", {"_static/sim.js": ("plain.gen",)})
    text = page("import plain.a") + '\n<script src="_static/sim.js"></script>\n'
    key, asset = nb_deps.page_digest(text, packages), nb_deps.asset_digest(text, packages)
    (project / "plain/js/sim.js").write_text("export const X = 2;\n")
    assert nb_deps.page_digest(text, packages) == key
    assert nb_deps.asset_digest(text, packages) != asset
    assert nb_deps.asset_digest(page("import plain.a"), packages) is None


# --- the cache key jupyter-cache computes ------------------------------------------------------

def _jcache_key(text):
    from jupyter_cache.cache.main import JupyterCacheBase
    from myst_nb.core.read import read_myst_markdown_notebook
    return JupyterCacheBase.create_hashed_notebook(None, read_myst_markdown_notebook(text))[1]


def test_injected_cell_changes_the_jupyter_cache_key_and_renders_nothing():
    text = page("import plain.a", "x = 1")
    one, two = nb_deps.inject(text, "1" * 64), nb_deps.inject(text, "2" * 64)
    assert _jcache_key(one) != _jcache_key(two) != _jcache_key(text)
    assert _jcache_key(one) == _jcache_key(nb_deps.inject(text, "1" * 64))
    assert one.startswith(text.rstrip())                 # the page's own lines keep their numbers
    from myst_nb.core.read import read_myst_markdown_notebook
    cells = read_myst_markdown_notebook(one).cells
    assert [c.source for c in cells if c.cell_type == "code"][-1] == "# nb-deps: " + "1" * 64
    assert cells[-1].metadata["tags"] == ["remove-cell"]


def test_key_check_rejects_a_digest_carried_in_markdown():
    # jupyter-cache hashes code cells only: a digest in a markdown comment would not reach the key.
    text = page("import plain.a")
    assert _jcache_key(text + "\n<!-- nb-deps: 1 -->\n") == _jcache_key(text + "\n<!-- nb-deps: 2 -->\n")


# --- the Sphinx side: pages re-read when their digest changes ----------------------------------

def test_outdated_returns_unchanged_pages_whose_dependencies_changed(project, packages, monkeypatch):
    monkeypatch.setattr(nb_deps, "project_packages", lambda names=nb_deps.PACKAGES: packages)
    docs = {"uses_c": page("from plain.b import THING"), "uses_a": page("import plain.a"),
            "prose": "# prose\n", "edited": page("import plain.c")}
    for name, text in docs.items():
        (project / f"{name}.md").write_text(text)
    env = SimpleNamespace(found_docs=set(docs), doc2path=lambda d: project / f"{d}.md", nb_deps={})
    app = SimpleNamespace(env=env)
    for name in docs:                                    # the first build reads every page
        source = [docs[name]]
        nb_deps.rewrite(app, name, source)
        assert ("# nb-deps:" in source[0]) == (name != "prose")
    assert nb_deps._outdated(app, env, set(), set(), set()) == []
    (project / "plain/c.py").write_text("THING = 4\n")
    # "edited" is already in Sphinx's own changed set and is not repeated.
    assert nb_deps._outdated(app, env, set(), {"edited"}, set()) == ["uses_c"]
    env.nb_deps.pop("uses_a")                            # read before the extension existed
    assert nb_deps._outdated(app, env, set(), {"edited"}, set()) == ["uses_a", "uses_c"]


# --- the real book: the finder covers what the pages' imports load ------------------------------

_LOADED = r"""
import ast, json, sys
sys.path.insert(0, sys.argv[1])
from myst_nb.core.read import read_myst_markdown_notebook
out = {}
for path in sys.argv[2:]:
    for name in [m for m in sys.modules if m.split(".")[0] in ("renderer", "proofs")]:
        del sys.modules[name]
    nb = read_myst_markdown_notebook(open(path, encoding="utf-8").read())
    for cell in nb.cells:
        if cell.cell_type == "code":
            for node in ast.parse(cell.source).body:
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    exec(compile(ast.Module(body=[node], type_ignores=[]), path, "exec"), {})
    out[path] = sorted(m.__file__ for n, m in sys.modules.items()
                       if n.split(".")[0] in ("renderer", "proofs") and getattr(m, "__file__", None))
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def loaded_by_book_pages():
    """Per page, the project files Python loads when it runs the page's import statements."""
    pages = sorted(str(p) for p in (ROOT / "book").glob("s*.md"))
    result = subprocess.run([sys.executable, "-c", _LOADED, str(ROOT), *pages],
                            capture_output=True, text=True, timeout=600, cwd=ROOT)
    # A page whose imports fail (a module renamed or removed) is named in the traceback.
    assert result.returncode == 0, f"running the book pages' imports failed:\n{result.stderr[-3000:]}"
    return {Path(k): {Path(f).resolve() for f in v} for k, v in json.loads(result.stdout).items()}


def _covers(loaded, packages):
    return all(files <= (nb_deps.dependencies(p.read_text(encoding="utf-8"), packages, path=p) or set())
               for p, files in loaded.items())


def test_finder_covers_every_module_the_book_pages_load(loaded_by_book_pages):
    packages = {"renderer": ROOT / "renderer", "proofs": ROOT / "proofs"}
    assert any(loaded_by_book_pages.values())            # the book does import the project
    assert _covers(loaded_by_book_pages, packages)


def test_book_check_rejects_a_finder_without_the_transitive_closure(loaded_by_book_pages, monkeypatch):
    packages = {"renderer": ROOT / "renderer", "proofs": ROOT / "proofs"}
    monkeypatch.setattr(nb_deps, "_imports_of_file", lambda file, package: frozenset())
    assert not _covers(loaded_by_book_pages, packages)


def test_the_simulator_bundle_follows_the_formulas_it_is_printed_from(monkeypatch):
    """renderer.jsgen prints formulas.js from renderer/formulas.py through
    renderer/codegen.py and joins renderer/js/*.js: a page importing it
    depends on all of them (so the §4 asset is rebuilt when a formula changes)."""
    packages = {"renderer": ROOT / "renderer", "proofs": ROOT / "proofs"}
    files = {f.relative_to(ROOT).as_posix() for f in nb_deps.dependencies(page("import renderer.jsgen"), packages)}
    assert {"renderer/formulas.py", "renderer/codegen.py", "renderer/jsgen.py", "renderer/js/render.js"} <= files
    monkeypatch.setattr(nb_deps, "DATA_FILES", {})          # the wrong variant misses the hand-written modules
    files = {f.relative_to(ROOT).as_posix() for f in nb_deps.dependencies(page("import renderer.jsgen"), packages)}
    assert "renderer/js/render.js" not in files and "renderer/formulas.py" in files
