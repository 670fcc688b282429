"""Sphinx extension: the pages' notebooks are executed by jupyter-cache, side by side, and
re-executed when the project's code changes; a build stopped or killed at any moment is
finished by the next one, and two builds in one tree take turns.

myst-nb (``execute_notebooks: cache``) keys a page's cached outputs on its code cells
alone, and executes the pages it has to one after another.  This extension:

1. Takes turns.  When the configuration is read, the build takes ``.build.lock`` in the
   book's directory (`filelock.FileLock`, held until the build's process ends); a second
   build in the same tree says in one line that it waits, and waits.
2. Trusts only what a finished build left.  A build that finishes without an error or a
   warning writes the project's one source digest (`lab.store.source_digest`: every file
   of the packages, and the numerical libraries' versions) to ``build-complete`` in the
   doctree directory, and every build deletes that file first.  The cache directory's
   ``source-digest`` is the digest its notebooks were executed under; when it is not the
   current one, the cache is emptied, then given the current one.  Unless both hold the
   current digest, Sphinx's saved environment is deleted, so every page is read and written
   again (its outputs from the cache where the cache holds the page).  So an edit to any
   module re-executes every page, and a build killed at any moment (the cache half filled,
   the environment saved but the pages not all written, a page's HTML half written) is
   redone by the next one, which executes again only the pages the cache lacks; a build
   that failed is not trusted either (the next reads every page again, and a page that
   failed fails again; the logs myst-nb wrote of its failed pages, in the site's reports/,
   are deleted, since myst-nb never deletes them).  After a build that did not finish, a cached notebook whose file
   does not read as a notebook (jupyter-cache records a notebook, then writes its file) is
   dropped from the cache.
3. Executes the pages before Sphinx reads them.  The pages about to be read are added to
   the cache's project (jupyter-cache's ``jupytext`` reader gives the same notebook, and
   so the same key, as myst-nb's) and the ones the cache does not hold run in a pool of
   processes forked from the build's (`concurrent.futures.ProcessPoolExecutor`), one per CPU, each with jupyter-cache's
   ``local-parallel`` worker, one page at a time to the first free process: first the pages of
   ``execute_pages_first``, last those of ``execute_pages_last`` (each in its order), the others
   between them (`execution_order`).  Each process runs its pages in one kernel (`_kernel`), emptied
   between pages (`RESET`): a page sees no name or figure an earlier one left, but the modules they
   imported stay loaded with what they hold: the functions numba and JAX compiled, `lab.store`'s
   values in memory, matplotlib's settings (each page that draws sets its style), the warnings
   already shown once.  myst-nb then finds each page in the
   cache; a page that failed is not cached, and myst-nb executes it again, in a new kernel, and reports its
   error as usual.  A process of the pool that dies (the OOM killer, a signal) is not replaced:
   the build warns once, and myst-nb executes the pages not yet cached.
Before any of this, the paths the build writes are checked (`refusal`): the lock, the cache's
   digest and the doctrees' ``build-complete`` must each be a regular file or absent (a link,
   a FIFO or a directory in their place would be followed, block the build or stop it with a
   traceback) and the directories writable; else the build stops with one line naming the
   path and what to do, exit status 2.
4. Stops on SIGINT (Ctrl-C) or SIGTERM.  The build's process freezes every process it
   started (the pool's, their kernels, a kernel myst-nb runs), so that none starts another,
   kills them, removes their kernels' connection files, prints one line and exits with
   128 + the signal's number.  The pool's processes are each a process group of their own,
   so that a terminal's Ctrl-C reaches the build's process only (nbclient in a pool process
   would otherwise shut its kernel down at once, and the kernel log its broken reply on
   stderr before the build freezes it); they die with the build's process (Linux's
   ``PR_SET_PDEATHSIG``), as they would with its process group.  The pool forks them all at its
   first page, from the build's main thread (the thread `_stop` runs in), and replaces none:
   no process starts while the build stops.  It leaves what
   a killed build leaves, which 2. does not trust.  ``make book`` runs this file
   (jupyter-book's command line) so that this holds from the first instant of the build,
   not only once Sphinx has loaded its extensions.  A signal the build was started with
   ignored stays ignored.

Pages share measurements through `lab.store` (a lock per measurement), so the
pages that wait for the theorem ledger go last.  Each page's kernel renders on one
thread (``NUMBA_NUM_THREADS=1`` unless set): the pages already fill the CPUs, and
numba's threads on top of them oversubscribe the cores (a cold build on 2 cores took
63 s with them and 47 s without).  Pages without code cells (no kernelspec) are not run.
"""

from __future__ import annotations

import multiprocessing
import os
import re
import shutil
import signal
import sys
from contextlib import suppress
from pathlib import Path

#: In the cache directory: the source digest its notebooks were executed under.
DIGEST_FILE = "source-digest"
#: In the doctree directory: the source digest of the last build that finished clean.
COMPLETE_FILE = "build-complete"
#: In the book's directory: the lock a build holds while it runs.
LOCK_FILE = ".build.lock"
#: The build's process ("pid") and its lock ("lock", a FileLock held until the process ends); in a
#: process of the page pool, its kernel and the kernel's shutdown ("kernel", `_kernel`).
_build = {}


def _cache_dir(app):
    return Path(app.config.nb_execution_cache_path or Path(app.outdir).parent / ".jupyter_cache")


def _read(path):
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return None


def _lock(path):
    """The `filelock.FileLock` on ``path``, taken; if another build holds it, after one line on stderr."""
    from filelock import FileLock, Timeout
    lock = FileLock(path)
    try:
        lock.acquire(timeout=0)
    except Timeout:
        print(f"waiting for the build running in {path.parent} to finish (it holds {path.name})",
              file=sys.stderr, flush=True)
        lock.acquire()
    return lock


_KINDS = ((os.path.islink, "a symbolic link"), (os.path.isdir, "a directory"), (os.path.isfile, None))


def refusal(book, doctrees, cache):
    """Why the build cannot use its paths, in one line naming the path, or None.

    ``book``, ``doctrees``, ``cache``: the book's directory, Sphinx's doctree directory and the
    jupyter-cache directory.  The lock (`LOCK_FILE`), the digest (`DIGEST_FILE`) and the build's
    mark (`COMPLETE_FILE`) must each be absent or a regular file (not a symbolic link, a FIFO, a
    device or a directory), and the book's directory and each of the others that exists writable."""
    for path in (Path(book) / LOCK_FILE, Path(cache) / DIGEST_FILE, Path(doctrees) / COMPLETE_FILE):
        if os.path.lexists(path):
            kind = next((k for test, k in _KINDS if test(path)), "a special file (a FIFO or a device)")
            if kind is not None:
                return f"{path} is {kind}, not the build's file: remove it and build again"
    for directory in (Path(book), Path(doctrees), Path(cache)):
        if directory.exists() and not os.access(directory, os.W_OK | os.X_OK):
            return f"{directory} cannot be written (read-only?): the build writes its output and its lock there"
    return None


def _begin(app, config):
    """Take the build's lock, then set aside what of the last build's output is not to be trusted (2.)."""
    from lab.store import source_digest
    from renderer import files
    from sphinx.application import ENV_PICKLE_FILENAME
    why = refusal(app.srcdir, app.doctreedir, _cache_dir(app))
    if why:
        print(f"make book: {why}", file=sys.stderr, flush=True)
        raise SystemExit(2)
    _build["lock"] = _lock(Path(app.srcdir) / LOCK_FILE)
    shutil.rmtree(Path(app.outdir) / "reports", ignore_errors=True)     # myst-nb's logs of the last build's failed pages
    digest, doctrees, cache = source_digest(), Path(app.doctreedir), _cache_dir(app)
    complete = _read(doctrees / COMPLETE_FILE) == digest
    (doctrees / COMPLETE_FILE).unlink(missing_ok=True)        # first: this build may be killed
    cached = _read(cache / DIGEST_FILE) == digest
    if not cached:
        if cache.exists():
            shutil.rmtree(cache)
        cache.mkdir(parents=True)
        files.write_bytes(cache / DIGEST_FILE, digest.encode())
    elif not complete:
        _drop_unreadable(cache)
    if not (complete and cached):
        (doctrees / ENV_PICKLE_FILENAME).unlink(missing_ok=True)


def _drop_unreadable(cache_dir):
    """Remove from the jupyter-cache in ``cache_dir`` every executed notebook whose file is
    missing or does not read as a notebook, leaving the records of the others untouched."""
    import nbformat
    from jupyter_cache import get_cache
    from jupyter_cache.cache.db import NbCacheRecord
    cache = get_cache(str(cache_dir))
    for record in cache.list_cache_records():
        path = Path(cache_dir, "executed", record.hashkey, "base.ipynb")
        try:
            nbformat.reads(path.read_text(encoding="utf-8"), nbformat.NO_CONVERT)
        except (OSError, ValueError):
            shutil.rmtree(path.parent, ignore_errors=True)
            NbCacheRecord.remove_records([record.pk], cache.db)


def _finish(app, exception):
    """A build that finished without an error or a warning: the next one may trust what it wrote."""
    if exception is None and not app._warncount:
        from lab.store import source_digest
        from renderer import files
        files.write_bytes(Path(app.doctreedir) / COMPLETE_FILE, source_digest().encode())


def _static_changed(app, env, added, changed, removed):
    """Every page, when a file of the book's own ``html_static_path`` (the directories in the book,
    not those extensions add, whose ``*_t`` templates are copied under other names) is newer than
    its copy in the site or has none: Sphinx copies those files only when it writes a page, so an
    edited stylesheet would not reach a site whose pages are all current."""
    site, book = Path(app.outdir) / "_static", Path(app.confdir).resolve()
    for base in app.config.html_static_path:
        root = (book / base).resolve()
        if not root.is_relative_to(book):
            continue
        for source in (p for p in root.rglob("*") if p.is_file()):
            copy = site / source.relative_to(root)
            if not copy.is_file() or copy.stat().st_mtime < source.stat().st_mtime:
                return sorted(env.found_docs)
    return []


def _execute(app, env, docnames):
    if env.mystnb_config.execution_mode != "cache" or not docnames:
        return
    from concurrent.futures.process import BrokenProcessPool
    from jupyter_cache import get_cache
    from myst_nb.core.read import is_myst_markdown_notebook
    from sphinx.util import logging
    order = execution_order(docnames, app.config.execute_pages_first, app.config.execute_pages_last)
    paths = [env.doc2path(d) for d in order if env.doc2path(d).endswith(".md")]
    cache = get_cache(str(_cache_dir(app)))
    pks = [cache.add_nb_to_project(path, read_data={"name": "jupytext", "type": "plugin"}).pk
           for path in paths if is_myst_markdown_notebook(Path(path).read_text(encoding="utf-8"))]
    todo = [pk for pk in pks if cache.get_cached_project_nb(pk) is None]
    if not todo:
        return
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")          # the kernels inherit it
    log = logging.getLogger(__name__)
    try:
        done = _run(cache, todo, env.mystnb_config.execution_timeout)
    except BrokenProcessPool:
        log.warning("a process executing the pages died (killed from outside the build?); "
                    "the pages it left are executed one by one")
        return
    for status, uri in done:
        if status:                                      # the console names the cause, not only the log file
            log.warning(f"{Path(uri).stem} failed to execute: {cause(cache.get_project_record(uri).traceback)}")


def execution_order(docnames, first, last):
    """``docnames`` in the order their notebooks start: those in ``first`` in its order, the others
    in theirs, those in ``last`` in its order.  The pool gives the next page to the first free
    process, so a long page listed first runs beside the others, not after them."""
    return sorted(docnames, key=lambda d: (first.index(d) - len(first) if d in first else
                                           len(last) + last.index(d) if d in last else 0))


#: Arguments of each page's kernel (`KernelManager.start_kernel`'s ``extra_arguments``): its history
#: in memory, not in the user's IPython history file (as nbclient starts its kernels: kernels side by
#: side writing one file lock it); its log at ERROR, so that ipykernel's warning at every start,
#: "Kernel is running over TCP without encryption", is not printed (the kernel listens on the loopback
#: interface only and checks each message's signature; the key is in its connection file, readable by
#: this user only).
KERNEL_ARGUMENTS = ("--HistoryManager.hist_file=:memory:", "--IPKernelApp.log_level=ERROR")

#: Run in a process's kernel before each of its pages but the first: the page starts in its directory,
#: without the names and figures of the pages before it, its execution count at 1, as in a new kernel.
#: What the modules imported hold stays (see the module's docstring, 3.).
RESET = """
import os, sys
os.chdir({cwd!r})
if "matplotlib.pyplot" in sys.modules:
    sys.modules["matplotlib.pyplot"].close("all")
get_ipython().reset(new_session=True)
"""
#: The client class of `_kernel`'s manager, whose ``client()`` nbclient calls: nbclient waits for
#: messages in an event loop, where a blocking client's wait blocks the loop (a kernel that dies
#: mid-page is then never noticed).
ASYNC_CLIENT = "jupyter_client.asynchronous.AsyncKernelClient"
#: Seconds `RESET` may take before the kernel is replaced (it takes a few milliseconds).
RESET_TIMEOUT = 10


def _run(cache, pks, timeout):
    """Execute the project notebooks ``pks`` of ``cache`` in this order, in a pool of processes
    forked from this one (so `_stop` is theirs too), one per CPU, caching each that succeeds.
    Returns [(status, uri)] in the same order: status 0 if it succeeded, 1 if a cell raised,
    2 if it could not be executed or cached.  Raises `BrokenProcessPool` if a process of the pool died.

    `ProcessPoolExecutor` with fork forks every process at the first job, in this thread, and
    replaces none that dies (`multiprocessing.Pool`'s own thread forks replacements at any moment,
    even while `_stop` kills the pool, and waits forever for a job its dead process held)."""
    from concurrent.futures import ProcessPoolExecutor
    from jupyter_cache.cache.db import NbProjectRecord
    from jupyter_cache.executors.basic import ProcessData
    NbProjectRecord.remove_tracebacks(pks, cache.db)
    jobs = [ProcessData(pk, cache.get_project_record(pk).uri, cache, timeout, False) for pk in pks]
    with ProcessPoolExecutor(mp_context=multiprocessing.get_context("fork")) as pool:
        return list(pool.map(_work, jobs))         # one page at a time to whichever process is free


def _work(job):
    """A page's notebook ``job`` executed by jupyter-cache's ``local-parallel`` worker, in this
    process's kernel (`_kernel`)."""
    from jupyter_cache.executors.basic import ExecutionWorkerLocalMProc
    from jupyter_cache.executors.utils import single_nb_execution
    from nbclient.exceptions import CellTimeoutError

    class InOneKernel(ExecutionWorkerLocalMProc):
        @staticmethod
        def execute(project_nb, data):
            cwd, name = str(Path(project_nb.uri).parent), project_nb.nb.metadata.kernelspec.name
            km = _kernel(name, cwd)
            try:
                result = single_nb_execution(project_nb.nb, cwd=cwd, timeout=data.timeout,
                                             allow_errors=data.allow_errors, km=km)
            finally:                        # nbclient, not owning the kernel, leaves its client running
                while km.clients:
                    km.clients.pop().stop_channels()
            if isinstance(result.err, CellTimeoutError):       # the kernel still runs the cell
                _build.pop("kernel")[1]()
            return result
    return InOneKernel()(job)


def _kernel(name, cwd):
    """This process's kernel (a `jupyter_client.KernelManager` of the kernel spec ``name``), ready
    for a page in the directory ``cwd``: the one its last page ran in, emptied by `RESET`, or a new
    one (at the first page, or when the last one was of another spec, died, did not reply or timed
    out), which this process shuts down when it exits (`multiprocessing.util.Finalize`; a process
    killed, or terminated by the pool when another died, leaves its kernel to end itself when it
    finds its parent gone, and the kernel's connection file behind).  The clients nbclient makes
    of it are kept in ``km.clients``, to be stopped after the page.

    A page's kernel and its imports cost about 2 s of CPU.  One kernel per process instead of one per
    page: cold builds on 2 CPUs, alternated, three each, medians 52.6 s against 58.6 s (70 against 85
    core-seconds).  The job that compiled the renderer's kernels ahead of the pages then gained nothing
    (53.1 s without it, 52.6 s with) and was dropped.  The pages stay each other's strangers as far as
    names go: a page that uses a name an earlier one defined fails, as it would alone."""
    if "kernel" in _build:
        km, shut_down = _build["kernel"]
        if km.kernel_name == name and _emptied(km, cwd):
            return km
        shut_down()
    from multiprocessing.util import Finalize
    from jupyter_client.manager import KernelManager

    class PageKernel(KernelManager):
        def client(self, **kwargs):
            made = super().client(**kwargs)
            self.clients.append(made)
            return made
    km = PageKernel(kernel_name=name, client_class=ASYNC_CLIENT)
    km.clients = []
    km.start_kernel(cwd=cwd, extra_arguments=list(KERNEL_ARGUMENTS))
    _build["kernel"] = km, Finalize(km, km.shutdown_kernel, kwargs={"now": True}, exitpriority=0)
    return km


def _emptied(km, cwd):
    """Whether the kernel of ``km`` replied to `RESET` in the directory ``cwd`` without an error
    within `RESET_TIMEOUT` (a kernel that died or hangs does not; one whose cell timed out was
    already shut down by `_work`)."""
    client = km.blocking_client()
    client.start_channels()
    try:
        client.wait_for_ready(timeout=RESET_TIMEOUT)
        reply = client.execute_interactive(RESET.format(cwd=cwd), store_history=False, timeout=RESET_TIMEOUT)
        return reply["content"]["status"] == "ok"
    except (RuntimeError, TimeoutError):
        return False
    finally:
        client.stop_channels()


def _stop(signum, frame):
    """SIGINT or SIGTERM in the build's process: freeze, kill and wait for every process it
    started, remove their kernels' connection files (``ipykernel_launcher -f <file>``), say so
    on stderr in one line and exit with 128 + ``signum``.  In the pool's processes: nothing."""
    if os.getpid() != _build.get("pid"):
        return
    for other in (signal.SIGINT, signal.SIGTERM):     # a second Ctrl-C changes nothing
        signal.signal(other, signal.SIG_IGN)
    import psutil
    me, frozen = psutil.Process(), {}
    while new := [p for p in me.children(recursive=True) if p.pid not in frozen]:
        for p in new:
            frozen[p.pid] = p
            with suppress(psutil.Error):
                p.suspend()
    leftovers = []
    for p in frozen.values():
        with suppress(psutil.Error):
            command = p.cmdline()
            if "ipykernel_launcher" in command and "-f" in command[:-1]:
                leftovers.append(command[command.index("-f") + 1])
        with suppress(psutil.Error):
            p.kill()
    psutil.wait_procs(list(frozen.values()), timeout=5)
    for path in leftovers:
        with suppress(OSError):
            os.unlink(path)
    os.write(2, f"book build stopped by {signal.Signals(signum).name}; the next build redoes "
                f"what it left unfinished\n".encode())
    os._exit(128 + signum)


def _forked():
    """In a process forked from the build's (the pool's): leaves the build's process group and
    dies when the build's process does.  A process its children fork is left alone (which
    process forked is noted before the fork: the parent may have died since)."""
    if _build.get("forker") != _build.get("pid"):
        return
    os.setpgid(0, 0)
    if sys.platform.startswith("linux"):
        import ctypes
        PR_SET_PDEATHSIG = 1
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != _build.get("pid"):          # the build ended before prctl took effect
            os._exit(128 + signal.SIGKILL)


def _handle_signals():
    """`_stop` on SIGINT and SIGTERM in this process, the build's (a signal it ignores stays ignored)."""
    if "pid" not in _build:
        os.register_at_fork(before=lambda: _build.update(forker=os.getpid()), after_in_child=_forked)
    _build["pid"] = os.getpid()
    for signum in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(signum) is not signal.SIG_IGN:
            signal.signal(signum, _stop)


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
    _handle_signals()
    app.add_config_value("execute_pages_first", [], "env", types=[list])
    app.add_config_value("execute_pages_last", [], "env", types=[list])
    app.connect("config-inited", _begin, priority=100)          # before the extensions that write
    app.connect("env-get-outdated", _static_changed)
    app.connect("env-before-read-docs", _execute, priority=900)
    app.connect("build-finished", _finish, priority=900)        # after the extensions that write
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}


if __name__ == "__main__":
    # make book runs this file: jupyter-book's command line, stopped as `_stop` says from the
    # start, not only once Sphinx has imported and loaded this extension.
    _handle_signals()
    from jupyter_book.cli.main import main
    main()
