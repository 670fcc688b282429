"""Sphinx extension: a page re-executes when, and only when, the project code it imports changes.

With ``execute_notebooks: cache`` myst-nb keys a page's outputs in jupyter-cache
on the page's code cells alone, so an edit to ``renderer/`` or ``proofs/``
would be answered from the cache with stale figures and numbers.  This
extension puts the code a page runs into that key:

1. ``page_digest`` (a pure function) reads the page's code cells, collects
   every import of a project package (``PACKAGES``; ``import``, ``from``-
   imports, imports inside functions, ``importlib.import_module`` with a
   literal name), closes the set over the imports of the project's own
   modules (parent packages' ``__init__.py`` included, since importing
   ``renderer.kernel`` runs ``renderer/__init__.py``, which imports its
   submodules), adds the data files a module reads at run time
   (``DATA_FILES``), and hashes the contents of those files.
2. On ``source-read`` the page's source gains a last code cell, tagged
   ``remove-cell`` (so nothing of it is rendered), holding
   ``# nb-deps: <sha256>``.  myst-nb builds the notebook from this modified
   source, so jupyter-cache's key changes exactly when a file the page
   imports changes.  Appending (rather than editing the first cell) keeps the
   line numbers of warnings in the page right.
3. Sphinx re-reads only pages whose source file changed.  On
   ``env-get-outdated`` the digests of every page are recomputed and compared
   with the ones stored in the environment when the page was last read; a
   page whose digests differ is re-read (and so re-executed, or matched in
   the cache under its new key).  The second digest, ``asset_digest``, covers
   the static files a page loads that are generated from project code at build
   time (``ASSETS``: §4's simulator script, bundled by ``renderer.jsgen``
   from renderer/js/*.js and the formulas ``renderer.codegen`` prints).
   It is not part of the cache key: when only the simulator's sources change,
   §4 is re-read and re-written from the cache, which makes Sphinx copy the new
   script into the site (with no page to write, Sphinx copies no static file).

The search is static and errs towards re-executing: a cell that does not
parse even as IPython, and ``from package import *``, depend on every module
of the project packages.  Imports hidden from ``ast`` (``exec`` of a string, a
computed module name) and files read by a cell itself are not seen.
"""

from __future__ import annotations

import ast
import hashlib
import json
import re
from contextlib import suppress
from importlib.util import find_spec
from pathlib import Path
from typing import Iterable, Mapping

#: The project's own packages; imports of anything else (numpy, sympy, ...) are not followed.
PACKAGES = ("renderer", "proofs")

#: Files a module reads when it runs, beside the modules it imports: glob patterns
#: relative to the module's package directory.  renderer.jsgen bundles renderer/js/*.js.
DATA_FILES = {"renderer.jsgen": ("js/*.js",)}

#: Static files a page may load that are generated at build time, and the modules
#: that generate them (book/_ext/simulator_assets.py writes the simulator with jsgen).
ASSETS = {"_static/sim/simulator.js": ("renderer.jsgen",)}

#: The comment that carries the digest in the appended cell.
MARK = "# nb-deps:"

_CODE_FENCE = re.compile(r"^(`{3,}|~{3,})\{code-cell\}[ \t]*(\S*)", re.M)


# --- the pure part: page source -> project files -> digest ---------------------------------

def code_cells(text: str, *, path: str | Path | None = None) -> list[str] | None:
    """Sources of the code cells of a page, or None if the page is not a notebook.

    A page is a notebook if it is a MyST markdown notebook (front matter with
    ``jupytext``/``file_format: mystnb``, read with myst-nb's own reader, so
    the cells are the ones myst-nb executes) or, for ``path`` ending in
    ``.ipynb``, notebook JSON.
    """
    if path is not None and str(path).endswith(".ipynb"):
        cells = json.loads(text).get("cells", [])
        return ["".join(c["source"]) if isinstance(c["source"], list) else c["source"]
                for c in cells if c.get("cell_type") == "code"]
    from myst_nb.core.read import is_myst_markdown_notebook, read_myst_markdown_notebook
    if not is_myst_markdown_notebook(text):
        return None
    nb = read_myst_markdown_notebook(text, path=path)
    return [cell.source for cell in nb.cells if cell.cell_type == "code"]


def _parse(source: str) -> ast.AST | None:
    """The source as Python; IPython magics are translated first if plain Python fails."""
    try:
        return ast.parse(source)
    except SyntaxError:
        pass
    from IPython.core.inputtransformer2 import TransformerManager
    try:
        return ast.parse(TransformerManager().transform_cell(source))
    except SyntaxError:
        return None


_MAGIC_CALLS = ("run_line_magic", "run_cell_magic")


def imported_names(tree: ast.AST, *, package: str = "") -> set[str]:
    """Absolute dotted names that the import statements in ``tree`` may load.

    ``from a.b import c`` gives both ``a.b`` and ``a.b.c`` (``c`` may be a
    submodule or a name; the resolver keeps whichever is a file), ``from a
    import *`` gives ``a.*``.  Relative imports are resolved against
    ``package``, the package the code lives in.
    """
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".") if package else []
                if node.level - 1 >= len(parts):
                    continue                       # beyond the top package: not ours
                base = ".".join(parts[:len(parts) - (node.level - 1)])
                module = f"{base}.{node.module}" if node.module else base
            else:
                module = node.module
            names.add(module)
            for alias in node.names:
                names.add(f"{module}.{alias.name}" if alias.name != "*" else f"{module}.*")
        elif (isinstance(node, ast.Call) and node.args
              and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)
              and (getattr(node.func, "attr", None) == "import_module"
                   or getattr(node.func, "id", None) in ("import_module", "__import__"))):
            names.add(node.args[0].value)
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", None) in _MAGIC_CALLS:
            # IPython's translation of %time, %%timeit, ...: the code is a string argument.
            for arg in node.args[1:]:
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                    with suppress(SyntaxError):
                        names |= imported_names(ast.parse(arg.value), package=package)
    return names


def _all_modules(packages: Mapping[str, Path]) -> set[Path]:
    return {p.resolve() for d in packages.values() for p in Path(d).rglob("*.py")}


def _module_file(name: str, packages: Mapping[str, Path]) -> list[tuple[str, Path]]:
    """(module, file) for ``name`` and each parent package, in import order."""
    parts = name.split(".")
    if parts[0] not in packages:
        return []
    found, directory = [], Path(packages[parts[0]])
    for i in range(len(parts)):
        module = ".".join(parts[:i + 1])
        here = directory.joinpath(*parts[1:i + 1])
        if (here / "__init__.py").is_file():
            found.append((module, here / "__init__.py"))
        elif i and here.with_suffix(".py").is_file():
            found.append((module, here.with_suffix(".py")))
            break
        else:
            break                                  # an attribute, not a module
    return found


_IMPORTS_MEMO: dict[tuple[str, str], frozenset[str]] = {}


def _imports_of_file(file: Path, package: str) -> frozenset[str] | None:
    """imported_names of a module file, memoised on its content."""
    data = file.read_bytes()
    key = (package, hashlib.sha256(data).hexdigest())
    if key not in _IMPORTS_MEMO:
        tree = _parse(data.decode("utf-8"))
        if tree is None:
            return None
        _IMPORTS_MEMO[key] = frozenset(imported_names(tree, package=package))
    return _IMPORTS_MEMO[key]


def module_files(names: Iterable[str], packages: Mapping[str, Path]) -> set[Path]:
    """Every project file that importing ``names`` runs or reads, transitively.

    ``packages`` maps each project package name to its directory.  Names
    outside those packages are ignored; a name that is an attribute rather than
    a module stops at the module that defines it.
    """
    todo, files, seen = list(names), set(), set()
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        if name.endswith(".*"):
            # from package import *: __all__ may name submodules; take them all.
            pkg = _module_file(name[:-2], packages)
            if pkg and pkg[-1][1].name == "__init__.py":
                todo += [f"{name[:-2]}.{p.stem}" for p in pkg[-1][1].parent.glob("*.py")]
            todo.append(name[:-2])
            continue
        for module, file in _module_file(name, packages):
            if file in files:
                continue
            files.add(file)
            package = module if file.name == "__init__.py" else module.rpartition(".")[0]
            imports = _imports_of_file(file, package)
            if imports is None:                    # unparsable: depend on everything
                return _all_modules(packages)
            todo += imports
            for pattern in DATA_FILES.get(module, ()):
                files.update(p for p in file.parent.glob(pattern) if p.is_file())
    return {f.resolve() for f in files}


def dependencies(text: str, packages: Mapping[str, Path], *,
                 path: str | Path | None = None) -> set[Path] | None:
    """The project files a page's code runs or reads; None if the page is not a notebook."""
    cells = code_cells(text, path=path)
    if cells is None:
        return None
    names = set()
    for source in cells:
        tree = _parse(source)
        if tree is None:                           # not even IPython: assume the worst
            return _all_modules(packages)
        names |= imported_names(tree)
    return module_files(names, packages)


def digest(files: Iterable[Path], packages: Mapping[str, Path]) -> str:
    """sha256 over the files' package-relative names and contents, in sorted order."""
    roots = {Path(d).resolve().parent: Path(d).resolve() for d in packages.values()}
    lines = []
    for file in files:
        file = Path(file).resolve()
        root = next((r for r in roots if file.is_relative_to(r)), file.parent)
        lines.append(f"{file.relative_to(root).as_posix()}\0"
                     f"{hashlib.sha256(file.read_bytes()).hexdigest()}\n")
    return hashlib.sha256("".join(sorted(lines)).encode()).hexdigest()


def page_digest(text: str, packages: Mapping[str, Path], *,
                path: str | Path | None = None) -> str | None:
    """Digest of the project files a page depends on; None if it depends on none."""
    files = dependencies(text, packages, path=path)
    return digest(files, packages) if files else None


def asset_digest(text: str, packages: Mapping[str, Path]) -> str | None:
    """Digest of the project files behind the generated ``ASSETS`` the page names; None if none."""
    names = {m for asset, modules in ASSETS.items() if asset in text for m in modules}
    files = module_files(names, packages)
    return digest(files, packages) if files else None


def inject(text: str, page_hash: str, *, path: str | Path | None = None) -> str:
    """The page with a last, hidden code cell ``# nb-deps: <page_hash>``."""
    if path is not None and str(path).endswith(".ipynb"):
        nb = json.loads(text)
        nb["cells"].append({"cell_type": "code", "execution_count": None, "outputs": [],
                            "metadata": {"tags": ["remove-cell"]},
                            "source": f"{MARK} {page_hash}"})
        return json.dumps(nb)
    fence = _CODE_FENCE.search(text)
    lexer = fence.group(2) if fence else "ipython3"
    return (f"{text.rstrip()}\n\n```{{code-cell}} {lexer}\n:tags: [remove-cell]\n\n"
            f"{MARK} {page_hash}\n```\n")


# --- the Sphinx side --------------------------------------------------------------------------

def project_packages(names: Iterable[str] = PACKAGES) -> dict[str, Path]:
    """Directories of the packages as this interpreter (and so the kernel) imports them."""
    found = {}
    for name in names:
        spec = find_spec(name)
        if spec is not None and spec.submodule_search_locations:
            found[name] = Path(list(spec.submodule_search_locations)[0]).resolve()
    return found


def _fingerprint(text, packages, path):
    return page_digest(text, packages, path=path), asset_digest(text, packages)


def rewrite(app, docname, source):
    """The ``source-read`` handler: records the page's digests and, if it
    imports project code, appends the digest cell to ``source[0]`` (a list of
    one str, as Sphinx passes it)."""
    path = app.env.doc2path(docname)
    fingerprint = _fingerprint(source[0], project_packages(), path)
    app.env.nb_deps[docname] = fingerprint
    if fingerprint[0] is not None:
        source[0] = inject(source[0], fingerprint[0], path=path)


def _outdated(app, env, added, changed, removed):
    """Pages whose source is unchanged but whose digests are not the stored ones."""
    packages = project_packages()
    stale = []
    for docname in sorted(env.found_docs - added - changed - removed):
        path = env.doc2path(docname)
        text = Path(path).read_text(encoding="utf-8")
        if env.nb_deps.get(docname) != _fingerprint(text, packages, path):
            stale.append(docname)
    return stale


def _init_env(app, env, docnames):
    if not hasattr(env, "nb_deps"):
        env.nb_deps = {}


def _purge(app, env, docname):
    getattr(env, "nb_deps", {}).pop(docname, None)


def _merge(app, env, docnames, other):
    env.nb_deps.update({d: other.nb_deps[d] for d in docnames if d in other.nb_deps})


def setup(app):
    app.connect("builder-inited", lambda app: _init_env(app, app.env, ()))
    app.connect("env-before-read-docs", _init_env)
    app.connect("env-get-outdated", _outdated)
    app.connect("source-read", rewrite)
    app.connect("env-purge-doc", _purge)
    app.connect("env-merge-info", _merge)
    return {"version": "1", "env_version": 1,
            "parallel_read_safe": True, "parallel_write_safe": True}
