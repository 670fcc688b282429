"""Sphinx extension: generate the §4 simulator's script when the book is built.

On ``config-inited`` it writes ``sim/simulator.js`` (renderer.jsgen's bundle of
renderer/js/*.js with the formulas that renderer.codegen prints from
renderer/formulas.py) into a build-side directory and adds that directory to
``html_static_path``, so the site serves ``_static/sim/simulator.js``.
Nothing generated is written into book/.
"""

from __future__ import annotations

from pathlib import Path

from renderer import jsgen


def _generate(app, config):
    static = Path(app.outdir).parent / "sim_static"
    jsgen.write_bundle(static / "sim" / "simulator.js")
    config.html_static_path = list(config.html_static_path) + [str(static)]


def setup(app):
    app.connect("config-inited", _generate)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
