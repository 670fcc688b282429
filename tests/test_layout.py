"""The layout is the architecture: four layers, each importing only from the layers below it.

    renderer  the scene, the kernel, its formulas (sympy) and the users' command line
    proofs    the checker engine (core), the theorems and their registry
    lab       measurements, the draft's claims register and its errata
    chapter   the book's presentation helpers (book/chapter)

Read from the source with `ast` (every ``import`` and ``from ... import``, inside functions
too): an import of a higher layer, or a cycle among a layer's modules, fails.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = {"renderer": ROOT / "renderer", "proofs": ROOT / "proofs", "lab": ROOT / "lab",
          "chapter": ROOT / "book" / "chapter"}
RANK = {name: k for k, name in enumerate(LAYERS)}


def imports(path: Path, package: str) -> set[str]:
    """Absolute names of the project modules a file imports (relative imports resolved)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join([package, *([base] if base else [])])
            found |= {base} | {f"{base}.{a.name}" for a in node.names}
    return {f"{name}.__init__" if name in LAYERS else name for name in found if name.split(".")[0] in LAYERS}


def graph(layers=LAYERS) -> dict[str, set[str]]:
    """{module: project modules it imports} over every module of ``layers``."""
    modules = {f"{pkg}.{p.stem}": p for pkg, root in layers.items() for p in root.glob("*.py")}
    return {name: {m for m in imports(path, name.split(".")[0]) if m in modules}
            for name, path in modules.items()}


def upward(g) -> list[tuple[str, str]]:
    return sorted((a, b) for a, targets in g.items() for b in targets
                  if RANK[b.split(".")[0]] > RANK[a.split(".")[0]])


def cycle(g) -> list[str] | None:
    """One import cycle of ``g`` (a list of modules, first = last), or None."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(g.get(node, ())):
            if nxt == node.rsplit(".", 1)[0] + ".__init__" or nxt == node:
                continue
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        state[node] = "done"
        stack.pop()
        return None

    for node in sorted(g):
        if node not in state and (found := visit(node)):
            return found
    return None


def test_no_module_imports_a_higher_layer():
    assert upward(graph()) == []


def test_no_import_cycle():
    assert cycle(graph()) is None


def test_every_layer_is_read():
    g = graph()
    assert {name.split(".")[0] for name in g} == set(LAYERS)
    assert "renderer.kernel" in g["renderer.render"] and "proofs.core" in g["proofs.blinn"]


@pytest.mark.parametrize("source, layer, bad", [
    ("from chapter.page import glue\n", "renderer", [("renderer.x", "chapter.page")]),
    ("def f():\n    from lab import store\n", "proofs", [("proofs.x", "lab.__init__"), ("proofs.x", "lab.store")]),
    ("import chapter.theorems as t\n", "lab", [("lab.x", "chapter.theorems")]),
    ("import lab\n", "proofs", [("proofs.x", "lab.__init__")]),
])
def test_an_upward_import_is_caught_even_inside_a_function(tmp_path, source, layer, bad):
    layers = {name: tmp_path / name for name in LAYERS}
    for name, root in layers.items():
        root.mkdir()
        (root / "page.py").write_text("")
        (root / "store.py").write_text("")
        (root / "theorems.py").write_text("")
        (root / "__init__.py").write_text("")
    (layers[layer] / "x.py").write_text(source)
    assert upward(graph(layers)) == bad


def test_a_cycle_is_caught(tmp_path):
    layers = {name: tmp_path / name for name in LAYERS}
    for root in layers.values():
        root.mkdir()
    (layers["lab"] / "a.py").write_text("from . import b\n")
    (layers["lab"] / "b.py").write_text("def f():\n    from lab.a import x\n")
    assert cycle(graph(layers)) == ["lab.a", "lab.b", "lab.a"]


_SHADOW = ("import sys, types\n"
           "{undo}"
           "import renderer.render, renderer.sweep\n"
           "from renderer import render, sweep\n"
           "print(type(render).__name__, type(sweep).__name__)\n")


def test_the_package_keeps_its_functions_when_their_submodules_load_first():
    """``renderer.render`` and ``renderer.sweep`` are submodules and functions of the same names;
    with the submodules imported first, ``from renderer import render, sweep`` still gives the
    functions.  Wrong variant: a plain module (the package's class undone) gives the modules."""
    import subprocess
    import sys
    run = lambda undo: subprocess.run([sys.executable, "-c", _SHADOW.format(undo=undo)], capture_output=True,  # noqa: E731
                                      text=True, check=True, cwd=ROOT).stdout.split()
    assert run("") == ["function", "function"]
    assert run("import renderer; sys.modules['renderer'].__class__ = types.ModuleType\n") == ["module", "module"]
