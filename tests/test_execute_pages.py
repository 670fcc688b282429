"""book/_ext/execute_pages.py: a page that fails to execute is named on the console with the
exception that stopped it (a changed verdict's claim and both verdicts), not only in a log file."""

from __future__ import annotations

import importlib.util
import logging
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from .pages import NOTEBOOK_FRONT_MATTER

ROOT = Path(__file__).resolve().parents[1]
#: The build forks its page pool, as it should; JAX warns at any fork of a test worker that imported it
#: (another test did), though the pool's processes run no JAX.
pytestmark = pytest.mark.filterwarnings(r"ignore:os\.fork\(\) was called:RuntimeWarning")

_spec = importlib.util.spec_from_file_location("execute_pages", ROOT / "book" / "_ext" / "execute_pages.py")
execute_pages = importlib.util.module_from_spec(_spec)
sys.modules["execute_pages"] = execute_pages        # as Sphinx loads it: its pool pickles its functions by name
_spec.loader.exec_module(execute_pages)

PAGE = NOTEBOOK_FRONT_MATTER + """
# A page

```{code-cell}
class ClaimChanged(AssertionError):
    pass
raise ClaimChanged("h3-scale: registered 'holds', computed 'does not hold' (ratio 2.1)")
```
"""


def test_a_page_that_fails_is_named_with_its_exception_on_the_console(tmp_path, caplog, monkeypatch):
    # _execute sets NUMBA_NUM_THREADS=1 for the page kernels (os.environ.setdefault); set here, it is
    # undone after the test: left in this process, numba's next compilation would refuse the change of
    # thread count once its threads run (RuntimeError in whichever test of this worker compiles next).
    monkeypatch.setenv("NUMBA_NUM_THREADS", "1")
    (tmp_path / "page.md").write_text(PAGE, encoding="utf-8")
    (tmp_path / "plain.md").write_text("# No code\n", encoding="utf-8")
    app = _app(tmp_path)
    with caplog.at_level(logging.WARNING):
        execute_pages._execute(app, app.env, ["page", "plain"])
    assert [r.getMessage() for r in caplog.records if "failed to execute" in r.getMessage()] == [
        "page failed to execute: ClaimChanged: h3-scale: registered 'holds', computed 'does not hold' (ratio 2.1)"]


def _app(tmp_path):
    """A stand-in for Sphinx's application: the pages are ``tmp_path/<name>.md``, the cache beside them."""
    env = SimpleNamespace(mystnb_config=SimpleNamespace(execution_mode="cache", execution_timeout=60),
                          doc2path=lambda d: str(tmp_path / f"{d}.md"))
    return SimpleNamespace(env=env, outdir=str(tmp_path / "html"),
                           config=SimpleNamespace(execute_pages_first=[], execute_pages_last=[],
                                                  nb_execution_cache_path=str(tmp_path / "cache")))


def _page(code):
    return NOTEBOOK_FRONT_MATTER + f"\n# A page\n\n```{{code-cell}}\n{code}\n```\n"


def test_the_page_kernels_start_without_ipykernels_tcp_warning(tmp_path, capfd, monkeypatch):
    """ipykernel logs "Kernel is running over TCP without encryption" at every start, on the
    build's stderr (nine lines a `make book`): the pool's kernels log errors only, and still run
    the page (it is cached)."""
    from jupyter_cache import get_cache
    monkeypatch.setenv("NUMBA_NUM_THREADS", "1")        # as in the test above
    (tmp_path / "page.md").write_text(_page("x = 1"), encoding="utf-8")
    app = _app(tmp_path)
    execute_pages._execute(app, app.env, ["page"])
    err = capfd.readouterr().err
    assert "without encryption" not in err, err
    assert len(get_cache(str(tmp_path / "cache")).list_cache_records()) == 1


def test_pages_start_in_the_configured_order():
    order = execute_pages.execution_order(["a", "s3", "b", "s5", "ledger", "c", "index"],
                                          first=["s5", "s3"], last=["index", "ledger"])
    assert order == ["s5", "s3", "a", "b", "c", "index", "ledger"]


def test_the_cause_is_the_exception_line_without_colours():
    tb = ("An error occurred while executing the following cell:\n------------------\nx = 1\n"
          "\x1b[0;31mKeyError\x1b[0m: 'inner'\n\nDuring handling...\n"
          "\x1b[0;31mTheoremFailed\x1b[0m: no-boundary: refuted, residual 3e-2\n")
    assert execute_pages.cause(tb) == "TheoremFailed: no-boundary: refuted, residual 3e-2"
    assert execute_pages.cause("") == "no traceback recorded"
    assert execute_pages.cause("just text\nlast line") == "last line"
    assert len(execute_pages.cause("ValueError: " + "9" * 900_000)) == 1000


# A process forked from the build's (multiprocessing's "fork", as the page pool's are), after
# the build installed its signal handling; prints what became of it.
FORKED = """
import importlib.util, multiprocessing, os, signal, sys
spec = importlib.util.spec_from_file_location("execute_pages", sys.argv[1])
execute_pages = importlib.util.module_from_spec(spec)
spec.loader.exec_module(execute_pages)
execute_pages._handle_signals()
def signalled(queue):
    os.kill(os.getpid(), signal.SIGINT)
    os.kill(os.getpid(), signal.SIGTERM)
    queue.put("carried on")
fork = multiprocessing.get_context("fork")
queue = fork.Queue()
child = fork.Process(target=signalled, args=(queue,))
child.start()
child.join(20)
print(queue.get(timeout=1) if not queue.empty() else "nothing", child.exitcode)
"""


def _forked():
    import subprocess
    import sys
    run = subprocess.run([sys.executable, "-c", FORKED, str(ROOT / "book" / "_ext" / "execute_pages.py")],
                         capture_output=True, text=True, timeout=60)
    return run.stdout, run.stderr


def test_a_pool_process_leaves_the_signal_to_the_build():
    """A process forked from the build's inherits its handler, which does nothing there: a page
    worker neither prints nor exits on SIGINT or SIGTERM; the build's process ends it."""
    assert _forked() == ("carried on 0\n", "")


def _jobs(tmp_path, pages, timeout=60):
    """``pages`` (path under ``tmp_path`` -> text) written and added to a cache's project there, each
    cell given ``timeout`` seconds: the cache and the pages' jobs, in that order."""
    from jupyter_cache import get_cache
    from jupyter_cache.executors.basic import ProcessData
    cache, jobs = get_cache(str(tmp_path / "cache")), []
    for name, text in pages.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
        pk = cache.add_nb_to_project(str(tmp_path / name), read_data={"name": "jupytext", "type": "plugin"}).pk
        jobs.append(ProcessData(pk, cache.get_project_record(pk).uri, cache, timeout, False))
    return cache, jobs


def _in_one_process(jobs):
    """Each job's status, the jobs executed in turn by `_work` in one process of a pool like the build's."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context
    with ProcessPoolExecutor(1, mp_context=get_context("fork")) as pool:
        return [status for status, _ in pool.map(execute_pages._work, jobs)]


def _outputs(cache, job):
    """The outputs of the last cell of ``job``'s page as cached."""
    return cache.get_cache_bundle(cache.get_cached_project_nb(job.pk).pk).nb.cells[-1].outputs


#: A page's first lines: its kernel's process id and directory appended to ``log``, and the ids
#: of the kernels logged before it that are still alive in ``others``.
LOGGED = """import os
def alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True
others = sorted({{int(line.split()[0]) for line in open({log!r})}} - {{os.getpid()}}) if os.path.exists({log!r}) else []
others = [pid for pid in others if alive(pid)]
open({log!r}, "a").write(f"{{os.getpid()}} {{os.getcwd()}} {{others}}\\n")
"""


def test_a_pool_process_runs_its_pages_in_one_kernel_each_a_stranger_to_the_last(tmp_path, monkeypatch):
    """One process of the pool, pages in turn (`_work`): the first defines a name; the second, in
    the same kernel, does not know it (NameError, as alone) and runs in its own directory; the third
    counts its execution from 1; the fourth times out; the fifth runs in a new kernel, the last one
    gone; the sixth kills its kernel; the seventh runs in a new one.  The kernels end with the
    process.  The wrong variants: no reset between pages (the second passes), a kernel per page, a
    kernel kept after its cell timed out or after it died, no change of directory, the execution
    count not reset."""
    import psutil
    monkeypatch.setattr(execute_pages, "RESET_TIMEOUT", 120)      # a busy kernel kept would be waited for
    log = tmp_path / "kernels.log"
    (tmp_path / "sub").mkdir()
    pages = {"a.md": "shared = 1", "sub/b.md": "shared", "c.md": "1 + 1", "d.md": "import time\ntime.sleep(30)",
             "e.md": "print('e ran')", "f.md": "os._exit(9)", "g.md": "print('g ran')"}
    cache, jobs = _jobs(tmp_path, {name: _page(LOGGED.format(log=str(log)) + code) for name, code in pages.items()},
                        timeout=3)
    done = _in_one_process(jobs)
    assert done == [0, 1, 0, 1, 0, 2, 0], done
    assert "NameError: name 'shared' is not defined" in execute_pages.cause(cache.get_project_record(jobs[1].uri).traceback)
    assert "CellTimeoutError" in execute_pages.cause(cache.get_project_record(jobs[3].uri).traceback)
    [result] = _outputs(cache, jobs[2])
    assert (result["output_type"], result["execution_count"]) == ("execute_result", 1)
    pids, cwds, others = zip(*(line.split(" ", 2) for line in log.read_text().splitlines()))
    assert pids[0] == pids[1] == pids[2] == pids[3] != pids[4] == pids[5] != pids[6], pids
    assert cwds == (str(tmp_path), str(tmp_path / "sub")) + (str(tmp_path),) * 5, cwds
    assert set(others) == {"[]"}, others                # each page's kernel the only one alive
    assert not any(psutil.pid_exists(int(pid)) for pid in set(pids))


def test_a_page_of_another_kernel_spec_gets_a_kernel_of_its_own(tmp_path, monkeypatch):
    """The process's kernel serves the pages of its spec only: a page whose notebook names another
    spec runs in a kernel of that spec, and the next page of the first spec in a new kernel of its
    own, each the only kernel alive.  The wrong variants: the spec not compared (all three in one
    kernel), the kernel replaced but not shut down."""
    import json
    spec = tmp_path / "jupyter" / "kernels" / "other"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "Another Python", "language": "python", "env": {"KERNEL_SPEC": "other"}}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    log = tmp_path / "kernels.log"
    report = LOGGED.format(log=str(log)) + "print(os.environ.get('KERNEL_SPEC'))  # page "   # one code, one record
    other = _page(report + "b").replace("name: python3", "name: other")
    cache, jobs = _jobs(tmp_path, {"a.md": _page(report + "a"), "b.md": other, "c.md": _page(report + "c")})
    assert _in_one_process(jobs) == [0, 0, 0]
    assert [_outputs(cache, job)[0]["text"] for job in jobs] == ["None\n", "other\n", "None\n"]
    pids, _, others = zip(*(line.split(" ", 2) for line in log.read_text().splitlines()))
    assert len(set(pids)) == 3 and set(others) == {"[]"}, (pids, others)


def test_no_kernel_client_outlives_its_page(tmp_path):
    """nbclient, given a kernel it does not own, leaves the client it made running (a heartbeat
    thread and its sockets); `_work` stops it after the page: pages in turn in one process leave
    no client and no thread behind.  The wrong variants: the clients not stopped, or dropped
    without being stopped (one thread more per page)."""
    import threading
    cache, jobs = _jobs(tmp_path, {f"{name}.md": _page(f"{name} = 1") for name in "abc"})
    threads = []
    try:
        for job in jobs:
            assert execute_pages._work(job)[0] == 0
            threads.append(threading.active_count())
        assert execute_pages._build["kernel"][0].clients == []
    finally:
        execute_pages._build.pop("kernel")[1]()
    assert threads[0] == threads[1] == threads[2], threads


def _last_build(tmp_path, monkeypatch, complete, cached):
    """A book tree as a build left it: the doctrees' ``build-complete`` reading ``complete``, the cache's
    digest ``cached``, Sphinx's saved environment and an executed page; the project's digest is "now"."""
    from lab import store
    monkeypatch.setattr(store, "_DIGEST", ["now"])
    monkeypatch.setattr(execute_pages, "_drop_unreadable", lambda cache: None)
    book = tmp_path / "book"
    doctrees, cache, out = book / "_build" / ".doctrees", book / "_build" / ".jupyter_cache", book / "_build" / "html"
    for d in (doctrees, cache, out):
        d.mkdir(parents=True)
    (cache / execute_pages.DIGEST_FILE).write_text(cached)
    (doctrees / execute_pages.COMPLETE_FILE).write_text(complete)
    (doctrees / "environment.pickle").write_text("env")
    (cache / "executed-page").write_text("old output")
    app = SimpleNamespace(srcdir=book, doctreedir=doctrees, outdir=out, _warncount=0,
                          config=SimpleNamespace(nb_execution_cache_path=str(cache)))
    return app, doctrees, cache


@pytest.mark.parametrize("complete, cached, environment_kept, cache_kept", [
    ("now", "now", True, True), ("before", "now", False, True), ("now", "before", False, False)])
def test_a_build_trusts_only_what_both_digests_vouch_for(tmp_path, monkeypatch, complete, cached, environment_kept,
                                                         cache_kept):
    """Sphinx's saved environment is kept only when the last build finished under the current digest and
    the cache was executed under it; the cache only when it was; build-complete is gone either way (this
    build may be killed).  A build-complete that merely exists, stale, is not trusted."""
    app, doctrees, cache = _last_build(tmp_path, monkeypatch, complete, cached)
    try:
        execute_pages._begin(app, None)
    finally:
        execute_pages._build.pop("lock").release()
    assert (doctrees / "environment.pickle").exists() == environment_kept
    assert (cache / "executed-page").exists() == cache_kept
    assert (cache / execute_pages.DIGEST_FILE).read_text() == "now"
    assert not (doctrees / execute_pages.COMPLETE_FILE).exists()


def test_only_a_build_without_an_error_or_a_warning_is_marked_complete(tmp_path, monkeypatch):
    app, doctrees, _ = _last_build(tmp_path, monkeypatch, "x", "x")
    (doctrees / execute_pages.COMPLETE_FILE).unlink()
    execute_pages._finish(app, RuntimeError("sphinx failed"))
    assert not (doctrees / execute_pages.COMPLETE_FILE).exists()
    app._warncount = 1
    execute_pages._finish(app, None)
    assert not (doctrees / execute_pages.COMPLETE_FILE).exists()
    app._warncount = 0
    execute_pages._finish(app, None)
    assert (doctrees / execute_pages.COMPLETE_FILE).read_text() == "now"
