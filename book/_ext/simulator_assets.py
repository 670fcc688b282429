"""Sphinx extension: generate the §4 simulator's script when the book is built.

On ``config-inited`` it writes ``sim/simulator.js`` (renderer.jsgen's bundle of
renderer/js/*.js with the formulas that renderer.codegen prints from
renderer/formulas.py) into a build-side directory and adds that directory to
``html_static_path``, so the site serves ``_static/sim/simulator.js``.
Nothing generated is written into book/.  The bundle is made again only when the
project's source digest (`lab.store.source_digest`, which covers renderer/js and
renderer/formulas.py) differs from the one it was made from.
"""

from __future__ import annotations

from pathlib import Path

from lab.store import source_digest


def _generate(app, config):
    static = Path(app.outdir).parent / "sim_static"
    bundle, stamp = static / "sim" / "simulator.js", static / "sim" / ".source-digest"
    if not (bundle.is_file() and stamp.is_file() and stamp.read_text(encoding="utf-8") == source_digest()):
        from renderer import jsgen           # sympy's printers: about 1.5 s
        jsgen.write_bundle(bundle)
        stamp.write_text(source_digest(), encoding="utf-8")
    config.html_static_path = list(config.html_static_path) + [str(static)]


def setup(app):
    app.connect("config-inited", _generate)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
