"""Sphinx extension: the pages' notebooks are executed by jupyter-cache, side by side, and
re-executed when the project's code changes.

myst-nb (``execute_notebooks: cache``) keys a page's cached outputs on its code cells
alone, and executes the pages it has to one after another.  Before Sphinx reads:

1. The project's one source digest (`lab.store.source_digest`: every file of the
   packages, and the numerical libraries' versions) is compared with the one the cache
   was filled under; when they differ the cache is emptied and every notebook page is
   read again, so an edit to any module re-executes every page.
2. The pages about to be read are added to the cache's project (jupyter-cache's
   ``jupytext`` reader gives the same notebook, and so the same key, as myst-nb's) and
   the ones the cache does not hold run in jupyter-cache's ``local-parallel`` executor,
   one process per CPU: first the pages of ``execute_pages_first``, last those of
   ``execute_pages_last``, the others between them.
   myst-nb then finds each page in the cache; a page that failed is not cached, and
   myst-nb executes it again and reports its error as usual.

Pages share measurements through `lab.store` (a lock per measurement), so the
pages that wait for the theorem ledger go last.  Each page's kernel renders on one
thread (``NUMBA_NUM_THREADS=1`` unless set): the pages already fill the CPUs, and
numba's threads on top of them oversubscribe the cores (a cold build on 2 cores took
63 s with them and 47 s without).  Pages without code cells (no kernelspec) are not run.
"""

from __future__ import annotations

import logging as std_logging
import os
import re
import shutil
from pathlib import Path

from sphinx.util import logging

from lab.store import source_digest

DIGEST_FILE = "source-digest"


def _cache_dir(app):
    return Path(app.env.mystnb_config.execution_cache_path or Path(app.outdir).parent / ".jupyter_cache")


def _outdated(app, env, added, changed, removed):
    """Every notebook page, when the source digest is not the one the cache holds."""
    path = _cache_dir(app) / DIGEST_FILE
    if path.is_file() and path.read_text(encoding="utf-8") == source_digest():
        return []
    shutil.rmtree(_cache_dir(app), ignore_errors=True)
    _cache_dir(app).mkdir(parents=True)
    path.write_text(source_digest(), encoding="utf-8")
    return sorted(d for d in env.found_docs - added - changed - removed if env.doc2path(d).endswith(".md"))


def _execute(app, env, docnames):
    if env.mystnb_config.execution_mode != "cache" or not docnames:
        return
    from jupyter_cache import get_cache
    from jupyter_cache.executors import load_executor
    from myst_nb.core.read import is_myst_markdown_notebook
    first, last = app.config.execute_pages_first, app.config.execute_pages_last
    order = sorted(docnames, key=lambda d: (d in last) - (d in first))
    paths = [env.doc2path(d) for d in order if env.doc2path(d).endswith(".md")]
    cache = get_cache(str(_cache_dir(app)))
    pks = [cache.add_nb_to_project(path, read_data={"name": "jupytext", "type": "plugin"}).pk
           for path in paths if is_myst_markdown_notebook(Path(path).read_text(encoding="utf-8"))]
    todo = [pk for pk in pks if cache.get_cached_project_nb(pk) is None]
    if not todo:
        return
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")          # the kernels inherit it
    quiet = std_logging.getLogger("execute_pages")          # multiprocessing's INFO lines stay off the console
    quiet.setLevel(std_logging.WARNING)
    result = load_executor("local-parallel", cache=cache, logger=quiet).run_and_cache(
        filter_pks=todo, timeout=env.mystnb_config.execution_timeout, allow_errors=False)
    for uri in result.errored + result.excepted:       # the console names the cause, not only the log file
        record = cache.get_project_record(uri)
        logging.getLogger(__name__).warning(f"{Path(uri).stem} failed to execute: {cause(record.traceback)}")


#: A terminal colour code, and an exception line as a traceback ends with it ("ClaimChanged: ...").
_ANSI, _RAISED = re.compile(r"\x1b\[[0-9;]*m"), re.compile(r"^[A-Za-z_][\w.]*(Error|Exception|Changed|Failed|Interrupt|Exit)\b.*")


def cause(traceback) -> str:
    """The exception line of a page's execution ``traceback`` (jupyter-cache's record of it),
    e.g. ``ClaimChanged: h3-scale: registered 'holds', computed 'does not hold' (...)``, at
    most 1,000 characters; the traceback's last line when no line names an exception."""
    lines = [line.strip() for line in _ANSI.sub("", traceback or "").splitlines() if line.strip()]
    raised = [line for line in lines if _RAISED.match(line)]
    return ((raised or lines or ["no traceback recorded"])[-1])[:1000]


def setup(app):
    app.add_config_value("execute_pages_first", [], "env", types=[list])
    app.add_config_value("execute_pages_last", [], "env", types=[list])
    app.connect("env-get-outdated", _outdated)
    app.connect("env-before-read-docs", _execute, priority=900)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
