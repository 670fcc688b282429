"""Sphinx extension: execute the pages that need it side by side, before Sphinx reads them.

myst-nb (``execute_notebooks: cache``) executes a page when Sphinx reads it,
so a cold build runs the pages' kernels one after another.  Sphinx's own
parallel read (``-j``) is not an option: a Jupyter Book extension is not
parallel-safe, and Sphinx falls back to reading serially.  This extension
does the executing first and leaves the reading to myst-nb:

1. On ``env-before-read-docs`` every page about to be read is turned into the
   notebook myst-nb will build from it: myst-nb's own reader, applied to the
   source as ``nb_deps`` (if loaded) rewrites it (the hidden digest cell), so the notebook
   has the same jupyter-cache key as the one myst-nb looks up.
2. The notebooks the cache does not hold are executed by jupyter-cache's
   ``single_nb_execution`` in a pool of threads, one kernel per thread, as many
   threads as the machine has CPUs (``SYMRENDER_BOOK_JOBS`` overrides): first
   the pages named by the config value ``parallel_execute_first`` (those that
   compute what other pages wait for), last those named by
   ``parallel_execute_last`` (those that wait), the rest in the order of the book.
3. Each notebook that ran without error goes into the cache.  myst-nb then
   finds every page there and only renders it.  A notebook that failed is not
   cached: myst-nb executes it again when it reads it, and reports the error
   as it always does.

Pages share measurements through `lab.store`, which locks each one while
it is computed, so two pages running at once that need the same measurement
compute it once.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from contextlib import suppress
from pathlib import Path

from sphinx.util import logging

#: Environment variable: the number of pages executed at once (default: the CPU count).
JOBS_ENV = "SYMRENDER_BOOK_JOBS"


def jobs():
    """Pages executed at once: ``SYMRENDER_BOOK_JOBS`` if set (an int >= 1), else the CPU count.

    Raises ValueError naming the variable if it is set to anything else."""
    value = os.environ.get(JOBS_ENV)
    if value is None:
        return os.cpu_count() or 1
    if not value.isdigit() or int(value) < 1:
        raise ValueError(f"{JOBS_ENV} must be a whole number >= 1, got {value!r}")
    return int(value)


def _notebook(app, docname):
    """(path, notebook) as myst-nb will build it from the page; None if not a notebook."""
    from myst_nb.core.read import create_nb_reader
    env = app.env
    path = Path(env.doc2path(docname))
    source = [path.read_text(encoding="utf-8")]
    if "nb_deps" in app.extensions:
        import nb_deps
        nb_deps.rewrite(app, docname, source)
    reader = create_nb_reader(str(path), env.myst_config, env.mystnb_config, source[0])
    return None if reader is None else (path, reader.read(source[0]))


def _pre_execute(app, env, docnames):
    config = env.mystnb_config
    if config.execution_mode != "cache" or not docnames:
        return
    from jupyter_cache import get_cache
    from jupyter_cache.base import CacheBundleIn
    from jupyter_cache.executors.utils import single_nb_execution
    cache = get_cache(config.execution_cache_path or ".jupyter_cache")
    todo = []
    for docname in docnames:
        page = _notebook(app, docname)
        if page is None:
            continue
        with suppress(KeyError):
            cache.match_cache_notebook(page[1])
            continue
        todo.append((*page, docname))
    if len(todo) < 2:
        return                                      # nothing to run side by side
    first, last = app.config.parallel_execute_first, app.config.parallel_execute_last
    todo.sort(key=lambda page: (page[2] in last) - (page[2] in first))   # stable: else the book's order

    def run(page):
        path, notebook, _ = page
        try:
            return path, single_nb_execution(notebook, cwd=str(path.parent), timeout=config.execution_timeout,
                                             allow_errors=config.execution_allow_errors)
        except Exception:                           # the kernel died, say: as a failed cell
            return path, None

    logger = logging.getLogger(__name__)
    with ThreadPoolExecutor(max_workers=min(jobs(), len(todo))) as pool:
        for path, result in pool.map(run, todo):
            if result is None or result.err is not None:
                logger.info(f"{path}: failed; myst-nb executes it again and reports the error")
                continue
            logger.info(f"{path}: executed in {result.time:.2f} s")
            cache.cache_notebook_bundle(CacheBundleIn(result.nb, str(path), data={"execution_seconds": result.time}),
                                        check_validity=False, overwrite=True)


def setup(app):
    app.add_config_value("parallel_execute_first", [], "env", types=[list])
    app.add_config_value("parallel_execute_last", [], "env", types=[list])
    app.connect("env-before-read-docs", _pre_execute, priority=900)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
