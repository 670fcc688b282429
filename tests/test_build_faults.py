"""Builds that survive faults (book/_ext/execute_pages.py, as ``make book`` runs it).

Each test builds a miniature book in a temporary directory: one notebook page, ``a``,
the book's own extension (``execute_pages`` from book/_ext), and the test's extension
``faults.py`` beside the page.  That extension makes the project's source digest the text
of ``version.txt`` (so a test "edits the code" by writing the file) and, with
``HOLD=<where>:<page>`` in the build's environment, makes the build wait at a chosen
moment until the file ``release`` appears, after creating ``held``: while Sphinx loads
the extensions, while the page executes (the page itself waits), after the page is
executed but before Sphinx reads it, or while Sphinx writes the page's HTML (a
half-written file in its place).  So each fault hits its window for certain: the test
waits for ``held``, then signals.

The page prints the version it ran under and logs each execution to ``executions.log``.
Every build carries a marker in its environment, inherited by all its processes (the
kernels start sessions of their own): a live process with the marker after a build ended
is one it left behind.  Linux only (/proc, fork, flock).
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import psutil
import pytest

from .pages import NOTEBOOK_FRONT_MATTER

pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")

ROOT = Path(__file__).resolve().parents[1]
ENTRY = ROOT / "book" / "_ext" / "execute_pages.py"
MARKER = "SYMRENDER_BUILD_TEST"
WAITING = "waiting for the build running in {book} to finish (it holds .build.lock)\n"
STOPPED = "book build stopped by {name}; the next build redoes what it left unfinished\n"

CONFIG = f"""\
title: Faults
only_build_toc_files: true
execute:
  execute_notebooks: cache
  timeout: 120
sphinx:
  local_extensions:
    faults: .
    execute_pages: {ROOT / "book" / "_ext"}
"""

FAULTS = '''\
import os, time
from pathlib import Path

import lab.store

HERE = Path(__file__).parent


def hold():
    (HERE / "held").touch()
    while not (HERE / "release").exists():
        time.sleep(0.05)


def _half_written(app, pagename, *args):
    if os.environ.get("HOLD") == f"write:{pagename}":
        Path(app.outdir, f"{pagename}.html").write_text("<!DOCTYPE html><html><body><p>half")
        hold()


def setup(app):
    lab.store._DIGEST[:] = [(HERE / "version.txt").read_text()]       # the digest, as computed once
    if os.environ.get("HOLD") == "read:":
        app.connect("env-before-read-docs", lambda app, env, docnames: hold(), priority=950)
    app.connect("html-page-context", _half_written)
    if os.environ.get("HOLD") == "setup:":           # Sphinx loading the extensions, execute_pages not yet
        hold()
    return {"parallel_read_safe": True}
'''

PAGE = NOTEBOOK_FRONT_MATTER + '''
# Page {page}

```{{code-cell}}
import os, time
from pathlib import Path
version = Path("version.txt").read_text()
with open("executions.log", "a") as log:
    print("{page}", version, file=log)
if os.environ.get("HOLD") == "execute:{page}":
    Path("held").touch()
    while not Path("release").exists():
        time.sleep(0.05)
print("page {page}, version", version)
```
'''


def make_book(path):
    """A miniature book at ``path``: one notebook page, ``a``; version v1."""
    path.mkdir()
    (path / "_config.yml").write_text(CONFIG)
    (path / "_toc.yml").write_text("format: jb-book\nroot: a\n")
    (path / "faults.py").write_text(FAULTS)
    (path / "version.txt").write_text("v1")
    (path / "a.md").write_text(PAGE.format(page="a"))
    (path / "tmp").mkdir()
    return path


class Build:
    """``python book/_ext/execute_pages.py build <book> ...`` as ``make book`` runs it, in a
    session of its own (as a shell starts a foreground job), SIGINT and SIGTERM at their
    defaults, with the marker ``token`` and ``HOLD`` in its environment and TMPDIR in the book."""

    def __init__(self, book, token, hold="", name="build"):
        self.book, self.err = book, book.parent / f"{name}.err"
        reset = "import os, signal, sys; [signal.signal(s, signal.SIG_DFL) for s in (2, 15)]; os.execv(sys.argv[1], sys.argv[1:])"
        env = {**os.environ, MARKER: token, "HOLD": hold, "TMPDIR": str(book / "tmp")}
        with open(self.err, "wb") as err:
            self.proc = subprocess.Popen(
                [sys.executable, "-c", reset, sys.executable, str(ENTRY), "build", str(book),
                 "--warningiserror", "--keep-going", "--quiet"],
                env=env, stdout=subprocess.DEVNULL, stderr=err, start_new_session=True)

    def stderr(self):
        return self.err.read_text(errors="replace")

    def wait(self, timeout=180):
        return self.proc.wait(timeout=timeout)

    def passes(self):
        assert self.wait() == 0, self.stderr()[-3000:]


def held(book, *builds, timeout=120):
    """Wait until a build holds (``held`` appears); fails if one ends first."""
    deadline = time.monotonic() + timeout
    while not (book / "held").exists():
        ended = [b for b in builds if b.proc.poll() is not None]
        assert not ended, f"the build ended (status {ended[0].proc.returncode}) before it held:\n{ended[0].stderr()[-3000:]}"
        assert time.monotonic() < deadline, "the build did not reach its hold"
        time.sleep(0.05)
    (book / "held").unlink()


def left_behind(token):
    """Live processes (zombies excluded) carrying the marker ``token``: [(pid, command line)]."""
    found = []
    for p in psutil.process_iter(["pid", "status", "cmdline"]):
        with_marker = False
        try:
            with_marker = p.environ().get(MARKER) == token
        except psutil.Error:
            pass
        if with_marker and p.info["status"] != psutil.STATUS_ZOMBIE:
            found.append((p.pid, " ".join(p.info["cmdline"] or [])))
    return found


def pool_processes(build):
    """The processes forked from the build's (its page pool's: the same command line), and the build's."""
    me = psutil.Process(build.proc.pid)
    return [p for p in me.children() if p.cmdline() == me.cmdline()], me


@pytest.fixture
def token():
    """The marker of the test's builds; whatever carries it is killed after the test."""
    token = uuid.uuid4().hex
    yield token
    for pid, _ in left_behind(token):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def page_html(book):
    return (book / "_build" / "html" / "a.html").read_text(encoding="utf-8")


def executions(book):
    return (book / "executions.log").read_text().splitlines() if (book / "executions.log").exists() else []


def shows(book, version):
    """The page's HTML is whole and shows the output of its cell run under ``version``."""
    html = page_html(book)
    assert f"page a, version {version}" in html and html.rstrip().endswith("</html>"), html[-300:]


# ------------------------------------------------------------------ one Ctrl-C, or SIGTERM


@pytest.mark.parametrize("signum, hold", [(signal.SIGINT, "setup:"), (signal.SIGINT, "execute:a"),
                                          (signal.SIGTERM, "write:a")],
                         ids=["SIGINT-starting", "SIGINT-executing", "SIGTERM-writing"])
def test_a_signal_stops_the_build_at_once_with_one_line_and_nothing_left(tmp_path, token, signum, hold):
    """The signal to the build's process group, as a terminal sends Ctrl-C: the build ends
    within seconds with status 128 + signum and one line on stderr after the signal; no
    process of it lives on, its kernels' connection files are gone (TMPDIR is empty), and
    the next build passes and shows every page whole.  The moments: Sphinx loading the
    extensions, before execute_pages (only the handler ``make book``'s entry installed
    acts), the pool executing a page (the build's process waits for it), and Sphinx
    writing a page (the build's process busy, the page's HTML half written)."""
    book = make_book(tmp_path / "book")
    build = Build(book, token, hold=hold)
    held(book, build)
    before = len(build.err.read_bytes())
    sent = time.monotonic()
    os.killpg(build.proc.pid, signum)
    status = build.wait(timeout=60)
    took = time.monotonic() - sent
    after = build.err.read_bytes()[before:].decode(errors="replace")
    alive = left_behind(token)
    assert (status, after, alive) == (128 + signum, STOPPED.format(name=signal.Signals(signum).name), [])
    assert took < 10, f"the build took {took:.1f} s to stop"
    assert list((book / "tmp").iterdir()) == []
    Build(book, token, name="again").passes()
    shows(book, "v1")


def test_the_pools_processes_leave_a_ctrl_c_to_the_build_and_die_with_it(tmp_path, token):
    """A terminal's Ctrl-C goes to the build's process group.  The pool's processes are each a
    process group of their own, so that only the build's process sees it (nbclient in a pool
    process would shut its kernel down, racing the build's freeze, and the kernel could log a
    traceback on stderr).  Out of the group, they still die with the build's process: here it
    alone is killed with SIGKILL."""
    book = make_book(tmp_path / "book")
    build = Build(book, token, hold="execute:a")
    held(book, build)
    pool, me = pool_processes(build)
    assert pool and all(os.getpgid(p.pid) == p.pid != os.getpgid(me.pid) for p in pool)
    os.kill(me.pid, signal.SIGKILL)
    build.wait()
    _, alive = psutil.wait_procs(pool, timeout=10)
    assert alive == []


def test_a_pool_process_killed_from_outside_is_named_and_its_pages_still_executed(tmp_path, token):
    """The pool's processes SIGKILLed while a page executes (as the OOM killer would): the build
    neither waits for the dead process's page nor starts another process in the pool; it warns in one
    line and myst-nb executes the page (status 1: the warning is an error).  The wrong variant,
    `multiprocessing.Pool`, forked a replacement within 0.1 s and waited forever."""
    book = make_book(tmp_path / "book")
    build = Build(book, token, hold="execute:a")
    held(book, build)
    pool, _ = pool_processes(build)
    assert pool
    for p in pool:
        # The first killed, the executor may end the others itself before this loop reaches them.
        with contextlib.suppress(psutil.NoSuchProcess, ProcessLookupError):
            p.kill()
    psutil.wait_procs(pool, timeout=10)
    time.sleep(0.5)
    assert pool_processes(build)[0] == []
    (book / "release").touch()
    assert build.wait(timeout=120) == 1, build.stderr()[-3000:]
    assert "a process executing the pages died (killed from outside the build?)" in build.stderr()
    assert executions(book) == ["a v1", "a v1"]
    shows(book, "v1")


# ------------------------------------------------------------------ SIGKILL, then a build


@pytest.mark.parametrize("hold, change, executed_again", [
    ("execute:a", "code", ["a v2"]),     # the page never finished: executed again
    ("read:", "code", ["a v2"]),         # executed, its notebook cut short in the cache: executed again
    ("write:a", "page", []),             # its HTML half written, the digest unchanged: written again
], ids=["while-executing", "while-caching", "while-writing"])
def test_a_build_after_a_killed_one_redoes_what_is_stale(tmp_path, token, hold, change, executed_again):
    """A finished build under v1; then a change (the code, i.e. the source digest, or the
    page's code cell); a build killed with SIGKILL (its whole process group) in the window;
    then a build, which must pass, execute again what the cache lacks and no more, and show
    the page whole and current.  While caching: the build is killed once the page is
    executed and cached, before Sphinx reads it, and the page's cached notebook is then cut
    short, as a kill while jupyter-cache writes it leaves it (the record first, the file next)."""
    book = make_book(tmp_path / "book")
    Build(book, token, name="first").passes()
    shows(book, "v1")
    if change == "code":
        (book / "version.txt").write_text("v2")
    else:
        (book / "a.md").write_text((book / "a.md").read_text().replace("import os, time", "import os, time  # second edition"))
    killed = Build(book, token, hold=hold, name="killed")
    held(book, killed)
    os.killpg(killed.proc.pid, signal.SIGKILL)
    killed.wait()
    for pid, _ in left_behind(token):          # its kernels (sessions of their own) would end within a second
        os.kill(pid, signal.SIGKILL)
    if hold == "read:":
        [notebook] = (book / "_build" / ".jupyter_cache" / "executed").glob("*/base.ipynb")
        notebook.write_bytes(notebook.read_bytes()[:200])
    done = executions(book)
    Build(book, token, name="after").passes()
    shows(book, "v2" if change == "code" else "v1")
    assert executions(book)[len(done):] == executed_again
    if change == "page":
        assert "second edition" in page_html(book)


def test_an_edited_static_file_reaches_a_site_whose_pages_are_current(tmp_path, token):
    """Sphinx copies html_static_path only when it writes a page: the build makes every page out
    of date when a static file is newer than its copy, so the edit reaches the site (and a file
    the site lost is copied again), the page executed once; with nothing newer, no page is written."""
    book = make_book(tmp_path / "book")
    (book / "_config.yml").write_text(CONFIG + "  config:\n    html_static_path: [_static]\n")
    (book / "_static").mkdir()
    style, copy = book / "_static" / "fit.css", book / "_build" / "html" / "_static" / "fit.css"
    style.write_text("p { color: black; }\n")
    Build(book, token, name="first").passes()
    assert copy.read_text() == style.read_text()
    for name, edit in (("edited", lambda: style.write_text("p { color: navy; }\n")), ("lost", copy.unlink)):
        time.sleep(0.05)                                  # a later mtime on coarse clocks
        edit()
        Build(book, token, name=name).passes()
        assert copy.read_text() == style.read_text(), name
    written = (book / "_build" / "html" / "a.html").stat().st_mtime_ns
    Build(book, token, name="unchanged").passes()              # nothing newer: no page written again
    assert (book / "_build" / "html" / "a.html").stat().st_mtime_ns == written
    assert executions(book) == ["a v1"]


def test_a_build_that_failed_is_not_trusted_by_the_next(tmp_path, token):
    """A page whose cell raises fails the build (status 1, the page and the exception named);
    the next build, nothing changed, fails the same way instead of finding the page current.  The
    site's reports/ holds the logs of its own build's failures only (myst-nb never deletes one)."""
    book = make_book(tmp_path / "book")
    (book / "a.md").write_text(PAGE.format(page="a") + '\n```{code-cell}\nraise ValueError("page a refuses")\n```\n')
    reports = book / "_build" / "html" / "reports"
    for name in ("first", "again"):
        build = Build(book, token, name=name)
        assert build.wait() == 1, build.stderr()[-3000:]
        assert "a failed to execute: ValueError: page a refuses" in build.stderr()
        assert sorted(p.name for p in reports.iterdir()) == ["a.err.log"]
        (reports / "gone.err.log").write_text("a page of an earlier build that failed")


# ------------------------------------------------------------------ two builds at once


def test_two_builds_in_one_tree_take_turns(tmp_path, token):
    """A second build started while the first executes a page says in one line that it waits,
    and waits: it executes nothing meanwhile, both pass, and the page was executed once."""
    book = make_book(tmp_path / "book")
    first = Build(book, token, hold="execute:a", name="first")
    held(book, first)
    second = Build(book, token, name="second")
    waiting = WAITING.format(book=book.resolve())
    deadline = time.monotonic() + 120
    while waiting not in second.stderr():
        assert second.proc.poll() is None, f"the second build ended without waiting:\n{second.stderr()[-3000:]}"
        assert len(executions(book)) == 1, "the second build executes the page the first one executes"
        assert time.monotonic() < deadline, "the second build neither waited nor ended"
        time.sleep(0.05)
    (book / "release").touch()
    first.passes()
    second.passes()
    assert second.stderr().count(waiting) == 1 and executions(book) == ["a v1"]
    shows(book, "v1")


# ------------------------------------------------------------------ paths the build cannot use


def _refusal():
    sys.path.insert(0, str(ENTRY.parent))
    try:
        from execute_pages import refusal
    finally:
        sys.path.pop(0)
    return refusal


@pytest.mark.parametrize("where", ["lock", "digest", "complete"])
@pytest.mark.parametrize("kind", ["fifo", "link", "loop", "directory"])
def test_a_special_file_where_the_build_writes_is_named_in_one_line(tmp_path, where, kind):
    """The lock, the cache's digest and the doctrees' mark: a FIFO (a blocking open), a link (followed
    out of the tree), a link loop or a directory in place of each is refused by name, its kind said;
    a regular file or none passes (the wrong variant: the check would refuse the build's own files)."""
    refusal = _refusal()
    book, doctrees, cache = tmp_path / "book", tmp_path / "book/_build/.doctrees", tmp_path / "book/_build/.jc"
    for d in (book, doctrees, cache):
        d.mkdir(parents=True, exist_ok=True)
    path = {"lock": book / ".build.lock", "digest": cache / "source-digest", "complete": doctrees / "build-complete"}[where]
    assert refusal(book, doctrees, cache) is None
    path.write_text("x")
    assert refusal(book, doctrees, cache) is None
    path.unlink()
    {"fifo": lambda: os.mkfifo(path), "link": lambda: path.symlink_to(tmp_path / "outside"),
     "loop": lambda: path.symlink_to(path), "directory": path.mkdir}[kind]()
    said = {"fifo": "a special file (a FIFO or a device)", "link": "a symbolic link", "loop": "a symbolic link",
            "directory": "a directory"}[kind]
    assert refusal(book, doctrees, cache) == f"{path} is {said}, not the build's file: remove it and build again"
    assert not (tmp_path / "outside").exists()


@pytest.mark.parametrize("which", ["book", "doctrees", "cache"])
def test_a_tree_the_build_cannot_write_is_named(tmp_path, monkeypatch, which):
    """A read-only book, doctree or cache directory (os.access says so: root passes every mode check, so
    the test asks os.access as a read-only mount would answer) is refused in one line naming it."""
    refusal = _refusal()
    book = tmp_path / "book"
    paths = {"book": book, "doctrees": book / "_build/.doctrees", "cache": book / "_build/.jc"}
    for path in paths.values():
        path.mkdir(parents=True, exist_ok=True)
    real = os.access
    monkeypatch.setattr(os, "access", lambda p, mode: False if Path(p) == paths[which] else real(p, mode))
    assert refusal(*paths.values()) == \
        f"{paths[which]} cannot be written (read-only?): the build writes its output and its lock there"


def test_make_book_with_a_fifo_for_its_lock_stops_at_once_with_one_line(tmp_path, token):
    """End to end: the build neither hangs on the FIFO nor prints a traceback; exit status 2."""
    book = make_book(tmp_path / "book")
    os.mkfifo(book / ".build.lock")
    build = Build(book, token)
    assert build.wait(timeout=120) == 2
    err = build.stderr()
    assert f"make book: {book / '.build.lock'} is a special file (a FIFO or a device)" in err
    assert "Traceback" not in err and not executions(book)
