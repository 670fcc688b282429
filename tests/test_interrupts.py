"""Ctrl-C at any moment of a ``symrender`` command (renderer/cli.py, `main`).

Each test starts the installed console script in a session of its own (as a
shell starts a foreground job), waits for a chosen moment, and sends SIGINT
to the child's whole process group, as a terminal's Ctrl-C does.  Then it
asks for: exit code 130; stderr exactly one line ``symrender: interrupted``
(no traceback); the output directory as it was (no output file, no ``.part``
staging directory, no temporary file); and no process left behind, neither in
the child's session nor anywhere else.  The notebook kernel (jupyter_client)
starts a session of its own, so
a session check alone would miss them: every run carries a marker in its
environment, which all its descendants inherit, and any live process with
that marker after the run is a leftover.

The moments: during the start-up imports (numpy, the renderer, then
matplotlib), and during ``render`` of a large frame and ``sweep`` once numba
is loaded.  In-process: `main` ignores a second Ctrl-C during the clean-up
and restores the previous handler; a Ctrl-C whose KeyboardInterrupt a C
callback drops (as llvmlite's does while numba compiles) still stops the
command before it writes.  ``import renderer.cli`` (what the console script
does before `main` runs) loads neither numpy nor the kernel.  The checkers
are shown to fail on a leaked process and on a traceback.

Linux only (/proc).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")

ROOT = Path(__file__).resolve().parent.parent
SYMRENDER = Path(sys.executable).with_name("symrender")
MARKER = "SYMRENDER_INTERRUPT_TEST"
INTERRUPTED = "symrender: interrupted\n"


# ------------------------------------------------------------------ processes


def _stat(pid):
    """(state, session id) of a process (proc(5)), or None if it is gone."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            text = f.read().decode(errors="replace")
    except OSError:
        return None
    rest = text[text.rindex(")") + 2:].split()   # after "pid (comm) "
    return rest[0], int(rest[3])


def _cmdline(pid):
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().replace(b"\0", b" ").decode(errors="replace").strip()
    except OSError:
        return ""


def _has_marker(pid, token):
    try:
        with open(f"/proc/{pid}/environ", "rb") as f:
            return f"{MARKER}={token}".encode() in f.read().split(b"\0")
    except OSError:
        return False


def live_processes(session, token):
    """Live processes (zombies excluded) in ``session`` or carrying the run's
    marker ``token`` in their environment: a list of (pid, command line)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        pid = int(entry)
        st = _stat(pid)
        if st is None or st[0] in "ZX":
            continue
        if st[1] == session or _has_marker(pid, token):
            found.append((pid, _cmdline(pid)))
    return found


class Run:
    """``symrender *args`` in a new session with piped output, marked in its
    environment so that every descendant can be found."""

    def __init__(self, *args, cwd, env=None):
        self.token = uuid.uuid4().hex
        environ = dict(os.environ, **(env or {}))
        environ[MARKER] = self.token
        self.started = time.monotonic()
        self.proc = subprocess.Popen([str(SYMRENDER), *map(str, args)], cwd=cwd, env=environ,
                                     stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, start_new_session=True)

    def descendants(self, needle):
        """Live marked processes, other than the command itself, whose command
        line contains ``needle``."""
        return [(pid, cmd) for pid, cmd in live_processes(self.proc.pid, self.token)
                if pid != self.proc.pid and needle in cmd]

    def wait_until(self, condition, timeout, what):
        """Poll ``condition()`` every 10 ms; fail if the command ends first or
        ``timeout`` s pass."""
        deadline = time.monotonic() + timeout
        while not condition():
            if self.proc.poll() is not None:
                out, err = self.proc.communicate()
                pytest.fail(f"symrender ended (code {self.proc.returncode}) before {what}: "
                            f"{err.decode()[-2000:]!r}")
            if time.monotonic() > deadline:
                self.interrupt()
                self.finish()
                pytest.fail(f"no {what} within {timeout} s")
            time.sleep(0.01)

    def maps(self, needle):
        """True once a file whose path contains ``needle`` is mapped into the command."""
        try:
            with open(f"/proc/{self.proc.pid}/maps") as f:
                return needle in f.read()
        except OSError:
            return False

    def interrupt(self):
        """Ctrl-C at a terminal: SIGINT to the whole foreground process group."""
        os.killpg(self.proc.pid, signal.SIGINT)

    def finish(self, timeout=60):
        """Wait for the command; return (exit code, stdout, stderr, seconds
        from start)."""
        try:
            out, err = self.proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            out, err = self.proc.communicate()
            pytest.fail(f"symrender did not exit within {timeout} s of the interrupt; stderr "
                        f"{err.decode()[-2000:]!r}")
        return self.proc.returncode, out.decode(), err.decode(), time.monotonic() - self.started

    def leftovers(self, grace=5.0):
        return leftovers(self.proc.pid, self.token, grace)


def leftovers(session, token, grace):
    """Processes of a run (its session, or its marker ``token``) still alive
    after up to ``grace`` seconds (polled)."""
    deadline = time.monotonic() + grace
    while True:
        left = live_processes(session, token)
        if not left or time.monotonic() > deadline:
            return left
        time.sleep(0.05)


def interrupt_problems(rc, err, before, after, left):
    """What is wrong with an interrupted run: an exit code other than 130,
    stderr other than the one line, a traceback, a file added to the output
    directory, a process left behind."""
    problems = []
    if rc != 130:
        problems.append(f"exit code {rc}")
    if err != INTERRUPTED:
        problems.append(f"stderr is not the one line: {err[-3000:]!r}")
    if "Traceback" in err:
        problems.append("traceback")
    if sorted(set(after) - set(before)):
        problems.append(f"files left: {sorted(set(after) - set(before))}")
    if left:
        problems.append(f"processes left: {left}")
    return problems


def listing(directory):
    return sorted(p.name for p in Path(directory).iterdir())


def check(run, directory, before, grace=5.0):
    rc, out, err, seconds = run.finish()
    problems = interrupt_problems(rc, err, before, listing(directory), run.leftovers(grace))
    assert problems == [], problems
    return seconds


# ------------------------------------------------------------------ the checkers can fail


def test_checker_rejects_wrong_variants():
    assert interrupt_problems(130, INTERRUPTED, [], [], []) == []
    assert interrupt_problems(1, INTERRUPTED, [], [], [])
    assert interrupt_problems(-2, "", [], [], [])
    assert interrupt_problems(130, "", [], [], [])
    assert interrupt_problems(130, INTERRUPTED * 2, [], [], [])
    tb = "Traceback (most recent call last):\n  File ...\nKeyboardInterrupt\n" + INTERRUPTED
    assert "traceback" in interrupt_problems(130, tb, [], [], [])
    assert interrupt_problems(130, INTERRUPTED, [], [".figs.x1.part"], [])
    assert interrupt_problems(130, INTERRUPTED, [], [], [(123, "python -m ipykernel_launcher")])


def test_orphan_check_catches_a_leaked_process():
    """A command that exits 130 but leaves a ``sleep`` behind, one in its own
    session and one in a new session, is caught; once they are killed the
    check passes."""
    token = uuid.uuid4().hex
    leak = ("import subprocess, sys; "
            "subprocess.Popen(['sleep', '30']); "
            "subprocess.Popen(['sleep', '31'], start_new_session=True); "
            "sys.exit(130)")
    proc = subprocess.Popen([sys.executable, "-c", leak], env=dict(os.environ, **{MARKER: token}),
                            start_new_session=True)
    assert proc.wait() == 130
    left = leftovers(proc.pid, token, grace=0.5)
    try:
        assert sorted(cmd for _, cmd in left) == ["sleep 30", "sleep 31"], left
        assert interrupt_problems(130, INTERRUPTED, [], [], left) == [f"processes left: {left}"]
    finally:
        for pid, _ in left:
            os.kill(pid, signal.SIGKILL)
    assert leftovers(proc.pid, token, grace=5.0) == []


# ------------------------------------------------------------------ start-up


@pytest.mark.parametrize("library, delay", [("_multiarray_umath", 0.1), ("kiwisolver", 0.0)])
def test_interrupt_during_start_up_imports(tmp_path, library, delay):
    """SIGINT while ``render`` imports numpy, sympy and the renderer, and
    later matplotlib: ``delay`` s after numpy's extension
    module, or matplotlib's kiwisolver, has been mapped.  The one line, 130,
    nothing written.

    The clock starts inside `main`, not at the spawn: before `main` runs,
    Python itself starts (interpreter, site, the console script's ``import
    renderer.cli``, which loads no numpy), and a SIGINT
    then is Python's to report."""
    run = Run("render", "--size", "64x64", "-o", "out.png", cwd=tmp_path)
    run.wait_until(lambda: run.maps(library), 10, f"{library} being imported")
    time.sleep(delay)
    run.interrupt()
    check(run, tmp_path, [])


def test_importing_the_command_line_loads_no_numpy():
    """``import renderer.cli`` loads neither numpy, sympy nor matplotlib, nor any
    of the renderer (importing the package ``renderer`` loads numpy): the
    command line starts at once, and `main` does the heavy imports where it
    handles a Ctrl-C.  Wrong variant: once the command line touches numpy
    (parsing ``--eps``), the same check sees it."""
    code = ("import sys, renderer.cli as cli\n"
            "heavy = ('numpy', 'sympy', 'matplotlib', 'renderer.kernel', 'renderer.render')\n"
            "print(sorted(m for m in heavy if m in sys.modules))\n"
            "cli.parse_eps('1e-2')\n"
            "print(sorted(m for m in heavy if m in sys.modules))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    first, then = out.splitlines()
    assert first == "[]" and "'numpy'" in then and "'renderer.kernel'" in then, out


# ------------------------------------------------------------------ commands at work


@pytest.mark.parametrize("args", [
    ("render", "--size", "4096x4096", "-o", "big.png"),                          # two 4096^2 frames
    ("sweep", "--size", "2048x2048", "--eps", "1e-1:1e-6:6", "--format", "csv"),
], ids=["render", "sweep"])
def test_interrupt_during_render_or_sweep(tmp_path, args):
    """SIGINT once the compiled kernel's library is loaded.  A render under
    way finishes first (compiled code does not check for signals); then no
    PNG and no temporary file."""
    run = Run(*args, cwd=tmp_path)
    run.wait_until(lambda: run.maps("llvmlite"), 20, "numba being loaded")
    time.sleep(0.5)
    assert run.proc.poll() is None, f"{args[0]} ended before the interrupt; make it larger"
    run.interrupt()
    check(run, tmp_path, [])


# ------------------------------------------------------------------ in-process and start-up path


def test_main_in_process_restores_the_handler_and_ignores_a_second_ctrl_c(capsys, monkeypatch):
    """main([...]) in this process: a SIGINT during the command gives 130 and
    the one line; a second SIGINT during its clean-up is ignored (no second
    line, the clean-up finishes); the previous handler is back afterwards."""
    import renderer.cli as cli

    cleaned = []

    def command(args, out):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)                       # the KeyboardInterrupt comes here
            pytest.fail("no KeyboardInterrupt")
        finally:
            os.kill(os.getpid(), signal.SIGINT)   # a second Ctrl-C during the clean-up
            time.sleep(0.05)
            cleaned.append(True)

    before = signal.getsignal(signal.SIGINT)
    monkeypatch.setitem(cli._COMMANDS, "render", command)
    assert cli.main(["render", "-o", "x.png"]) == 130
    assert cleaned == [True]
    assert capsys.readouterr().err == INTERRUPTED
    assert signal.getsignal(signal.SIGINT) is before
    # Without a Ctrl-C: the handler is back too.
    assert cli.main(["sweep", "--size", "8x8", "--eps", "1e-2"]) == 0
    assert signal.getsignal(signal.SIGINT) is before
    capsys.readouterr()



def _render_with_a_dropped_ctrl_c(monkeypatch):
    """Make ``render``'s first frame take a Ctrl-C inside a C callback, as
    llvmlite's object-cache callback does while numba compiles the kernel:
    ctypes drops the KeyboardInterrupt (it only reports it) and the render
    goes on."""
    import ctypes
    import importlib

    module = importlib.import_module("renderer.render")   # the package's `render` is the function
    real = module.render
    calls = []

    def body():
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)                          # the KeyboardInterrupt is raised here, and dropped

    callback = ctypes.CFUNCTYPE(None)(body)

    def render(*args, **kwargs):
        if not calls:
            callback()
        calls.append(True)
        return real(*args, **kwargs)

    monkeypatch.setattr(module, "render", render)
    return calls


@pytest.mark.parametrize("variant", ["as built", "no check before writing"])
def test_a_ctrl_c_that_a_c_callback_drops_still_stops_the_command(tmp_path, capsys, monkeypatch, variant):
    """A Ctrl-C whose KeyboardInterrupt a C callback drops still ends the
    command with 130 and the one line, and writes nothing.  Wrong variants:
    without `_stop_if_interrupted` the command finishes, writes its PNG and
    exits 0 (`renderer.cmdline.check_signal`)."""
    import renderer.cli as cli
    from renderer import cmdline

    if variant == "no check before writing":
        monkeypatch.setattr(cmdline, "check_signal", lambda: None)
    # Python's own hook, which prints the report (pytest's turns it into a warning).
    monkeypatch.setattr(sys, "unraisablehook", sys.__unraisablehook__)
    calls = _render_with_a_dropped_ctrl_c(monkeypatch)
    out = tmp_path / "out.png"
    before = sys.unraisablehook
    code = cli.main(["render", "--size", "16x12", "-o", str(out)])
    err = capsys.readouterr().err
    assert calls, "the render did not run"
    assert sys.unraisablehook is before
    problems = interrupt_problems(code, err, [], listing(tmp_path), [])
    if variant == "as built":
        assert problems == []
    else:
        assert "exit code 0" in problems and "files left: ['out.png']" in problems
