"""Sphinx extension: the pages of one build share one store of measurements.

Sets ``SYMRENDER_STORE`` (`lab.store.ENV`) to ``<build dir>/.measurements``
unless it is set already; the kernels myst-nb starts for the pages inherit it,
so a quantity shown on several pages (a theorem's verdict) is computed by the
first page that needs it and read by the others (`lab.store.measured`).
``make clean`` removes it with the rest of the build.
"""

from __future__ import annotations

import os
from pathlib import Path

from chapter.page import BUILD_ENV
from lab.store import ENV


def _set_store(app, config):
    os.environ.setdefault(ENV, str(Path(app.outdir).parent / ".measurements"))
    os.environ[BUILD_ENV] = "1"        # chapter.page: glue for the prose instead of displaying


def setup(app):
    app.connect("config-inited", _set_store)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
