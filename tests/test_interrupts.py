"""Ctrl-C and SIGTERM at any moment of a ``symrender`` command (`renderer.cli.main`).

Each test starts the command in a session of its own (as a shell starts a
foreground job), waits for a chosen moment, and sends SIGINT to the child's
whole process group, as a terminal's Ctrl-C does, or SIGTERM to the child, as
``timeout``, CI and service managers do.  Then it asks for: exit code 130 (143);
stderr exactly one line ``symrender: interrupted`` (``terminated``), no
traceback; the output directory as it was (no output file, no ``.part``
file, no temporary file); and no process left behind, neither in the child's
session nor anywhere else: every run carries a marker in its environment,
which all its descendants inherit, and any live process with that marker
after the run is a leftover (wherever it runs, in whatever session).

The moments: during the start-up imports (numpy, then numba's
llvmlite), found by watching the child's memory maps; and moments a harness
in the child announces by writing a file (`HARNESS`): inside the render's or
the sweep's band loop (compiled bands run again and again until the signal
comes), while the output's temporary file is being written, and after the
report is out but before the output is renamed into place.  In-process:
`main` ignores a second signal during the clean-up and restores the previous
handlers; a Ctrl-C whose KeyboardInterrupt C code drops (a C callback, as
llvmlite's does while numba compiles, or a call that clears any error) still stops
the command before it writes.
``import renderer.cli`` (what the console script does before `main` runs)
loads neither numpy nor the kernel.  The checkers are shown to fail on a
leaked process and on a traceback.

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

SYMRENDER = Path(sys.executable).with_name("symrender")
MARKER = "SYMRENDER_INTERRUPT_TEST"
INTERRUPTED = "symrender: interrupted\n"
#: What each signal must end in: the exit code and stderr's one line (after ``symrender: ``).
OUTCOME = {signal.SIGINT: (130, "interrupted"), signal.SIGTERM: (143, "terminated")}

#: Runs ``renderer.cli.main`` with the moment MOMENT held open: the harness writes the file
#: READY when the moment has come, and keeps the child there until the signal's exception
#: arrives (or exits 99 after 120 s).
#: band: the compiled band of the render or sweep, run once (numba compiles or loads it), then
#: repeated until the signal comes (its exception comes between two calls, as in a real render;
#: or, inside numba's typing of a band's arguments, it is dropped (the loop then ends as the render's
#: bands would, before the check before writing) or turned into a TypeError, both seen here);
#: write: the output's temporary file is written (before its
#: sync); commit: the report is out, the output not yet renamed into place.
HARNESS = """
import os, sys, time
import renderer.kernel as kernel
ready, moment = os.environ["READY"], os.environ["MOMENT"]

arrived = False

def arrive():
    # Once: the test deletes the file when it has seen it, and a later band must not write it again.
    global arrived
    if not arrived:
        arrived = True
        open(ready, "w").close()

def hold():
    arrive()
    for _ in range(12000):
        time.sleep(0.01)
    os._exit(99)

if moment == "band":
    def band(*args, real=kernel.render_rows):
        from renderer.cli import _signal
        real(*args)
        arrive()
        while not _signal:
            real(*args)
    kernel.render_rows = band
elif moment in ("write", "commit"):
    call = {"write": "fsync", "commit": "replace"}[moment]
    real = getattr(os, call)
    # fsync: of the output's temporary file; replace: of a staged output (a .part name).
    setattr(os, call, lambda *args: (call == "fsync" or ".part" in str(args[0])) and hold() or real(*args))
from renderer.cli import main
sys.exit(main(sys.argv[1:]))
"""


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
    environment so that every descendant can be found.  With ``moment``, the
    `HARNESS` runs the command and holds that moment open; `ready` is its file."""

    def __init__(self, *args, cwd, env=None, moment=None):
        self.token = uuid.uuid4().hex
        self.ready = Path(cwd) / f".ready-{self.token}"
        environ = dict(os.environ, **(env or {}))
        environ.update({MARKER: self.token, "READY": str(self.ready), "MOMENT": moment or ""})
        command = [sys.executable, "-c", HARNESS] if moment else [str(SYMRENDER)]
        self.started = time.monotonic()
        self.proc = subprocess.Popen([*command, *map(str, args)], cwd=cwd, env=environ,
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

    def send(self, signum):
        """SIGINT as a terminal sends it (`interrupt`), SIGTERM as ``timeout`` does: to the child."""
        if signum == signal.SIGINT:
            self.interrupt()
        else:
            self.proc.send_signal(signum)

    def at_the_moment(self, timeout=120):
        """Wait until the harness has announced its moment (its READY file), then remove
        the file (it is not the command's output)."""
        self.wait_until(self.ready.exists, timeout, "the harness's moment")
        self.ready.unlink()

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


def interrupt_problems(rc, err, before, after, left, signum=signal.SIGINT):
    """What is wrong with a run stopped by ``signum``: an exit code other than 130
    (SIGINT) or 143 (SIGTERM), stderr other than the one line, a traceback, a file
    added to the output directory, a process left behind."""
    problems = []
    code, word = OUTCOME[signum]
    if rc != code:
        problems.append(f"exit code {rc}")
    if err != f"symrender: {word}\n":
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


def check(run, directory, before, grace=5.0, signum=signal.SIGINT):
    rc, out, err, seconds = run.finish()
    problems = interrupt_problems(rc, err, before, listing(directory), run.leftovers(grace), signum)
    assert problems == [], problems
    return seconds


# ------------------------------------------------------------------ the checkers can fail


def test_checker_rejects_wrong_variants():
    assert interrupt_problems(130, INTERRUPTED, [], [], []) == []
    assert interrupt_problems(143, "symrender: terminated\n", [], [], [], signal.SIGTERM) == []
    assert interrupt_problems(130, INTERRUPTED, [], [], [], signal.SIGTERM)   # SIGTERM reported as Ctrl-C
    assert interrupt_problems(-15, "", [], [], [], signal.SIGTERM)          # killed by the signal, silently
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


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("library, delay", [("_multiarray_umath", 0.1), ("libllvmlite", 0.0)])
def test_a_signal_during_start_up_imports(tmp_path, library, delay, signum):
    """A signal while ``render`` imports numpy and the renderer: ``delay`` s
    after numpy's extension module, or numba's llvmlite library, has been
    mapped.  The one line, 130
    (143), nothing written.

    The clock starts inside `main`, not at the spawn: before `main` runs,
    Python itself starts (interpreter, site, the console script's ``import
    renderer.cli``, which loads no numpy), and a signal
    then is Python's to report."""
    run = Run("render", "--size", "64x64", "-o", "out.png", cwd=tmp_path)
    run.wait_until(lambda: run.maps(library), 10, f"{library} being imported")
    time.sleep(delay)
    run.send(signum)
    check(run, tmp_path, [], signum=signum)


HEAVY = ("numpy", "sympy", "matplotlib", "numba", "renderer.kernel", "renderer.render")


def heavy_modules_after(code):
    """The heavy modules (`HEAVY`) loaded once ``code`` has run in a fresh interpreter."""
    probe = f"import sys\n{code}\nprint(sorted(m for m in {HEAVY!r} if m in sys.modules))"
    return subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout.strip()


def test_importing_the_command_line_loads_no_numpy():
    """``import renderer.cli`` loads neither numpy, sympy, matplotlib nor
    numba, nor any of the renderer: the command line starts at once, and `main` does the
    heavy imports where it handles a signal.  The probe sees a heavy import: a command line
    that imported numpy at the top would show it."""
    assert heavy_modules_after("import renderer.cli") == "[]"
    assert heavy_modules_after("import renderer.cli, numpy") == "['numpy']"


# ------------------------------------------------------------------ commands at work


SIGNALS = [signal.SIGINT, signal.SIGTERM]


@pytest.mark.parametrize("signum", SIGNALS, ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("args", [
    ("render", "--size", "256x256", "-o", "big.png"),
    ("sweep", "--size", "64x64", "--eps", "1e-1:1e-6:6", "--format", "csv"),
], ids=["render", "sweep"])
def test_a_signal_inside_the_band_loop(tmp_path, args, signum):
    """The signal arrives while compiled bands run (they do not check for signals); the
    exception comes between two bands; then no PNG and no temporary file."""
    run = Run(*args, cwd=tmp_path, moment="band")
    run.at_the_moment()
    run.send(signum)
    check(run, tmp_path, [], signum=signum)


RENDER_8 = ("render", "--size", "8x8", "-o", "out.png")


@pytest.mark.parametrize("args, moment, signum", [
    *[(RENDER_8, moment, signum) for moment in ("write", "commit") for signum in SIGNALS],
    (("ucurve", "--eps", "1e-3", "--plot", "out.png"), "commit", signal.SIGTERM),
], ids=["render-write-SIGINT", "render-write-SIGTERM", "render-commit-SIGINT", "render-commit-SIGTERM",
        "ucurve-commit-SIGTERM"])
def test_a_signal_while_the_output_is_written_leaves_nothing(tmp_path, args, moment, signum):
    """SIGTERM while the output's temporary file was written exited 143 silently and left
    ``.out.png.XXXX.part`` behind; SIGINT was clean.  Both now: one line, nothing left, at
    either moment of the write."""
    run = Run(*args, cwd=tmp_path, moment=moment)
    run.at_the_moment()
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".part")], "no temporary file at the moment"
    run.send(signum)
    check(run, tmp_path, [], signum=signum)


def test_an_old_output_stays_whole_when_the_write_is_stopped(tmp_path):
    (tmp_path / "out.png").write_bytes(b"old")
    run = Run("render", "--size", "8x8", "-o", "out.png", cwd=tmp_path, moment="commit")
    run.at_the_moment()
    run.send(signal.SIGTERM)
    check(run, tmp_path, ["out.png"], signum=signal.SIGTERM)
    assert (tmp_path / "out.png").read_bytes() == b"old"


# ------------------------------------------------------------------ in-process and start-up path


@pytest.mark.parametrize("first, second", [(signal.SIGINT, signal.SIGINT), (signal.SIGTERM, signal.SIGINT),
                                           (signal.SIGINT, signal.SIGTERM)], ids=["INT-INT", "TERM-INT", "INT-TERM"])
def test_main_in_process_restores_the_handlers_and_ignores_a_second_signal(capsys, monkeypatch, first, second):
    """main([...]) in this process: a signal during the command gives its code and
    one line; a second signal during the clean-up is ignored (no second line, the
    clean-up finishes); the previous handlers are back afterwards."""
    import renderer.cli as cli

    cleaned = []

    def command(args):
        try:
            os.kill(os.getpid(), first)
            time.sleep(1.0)                       # the exception comes here
            pytest.fail("no exception")
        finally:
            os.kill(os.getpid(), second)          # a second signal during the clean-up
            time.sleep(0.05)
            cleaned.append(True)

    before = {sig: signal.getsignal(sig) for sig in SIGNALS}
    monkeypatch.setitem(cli._COMMANDS, "render", command)
    code, word = OUTCOME[first]
    assert cli.main(["render", "-o", "x.png"]) == code
    assert cleaned == [True]
    assert capsys.readouterr().err == f"symrender: {word}\n"
    assert {sig: signal.getsignal(sig) for sig in SIGNALS} == before
    # Without a signal: the handlers are back too.
    assert cli.main(["sweep", "--size", "8x8", "--eps", "1e-2"]) == 0
    assert {sig: signal.getsignal(sig) for sig in SIGNALS} == before
    capsys.readouterr()



@pytest.mark.parametrize("signum", SIGNALS, ids=["SIGINT", "SIGTERM"])
def test_an_exception_the_interrupted_code_raises_instead_is_the_signals(capsys, monkeypatch, signum):
    """Code that a signal interrupts may turn its KeyboardInterrupt into another exception (numba's
    typing of a band's arguments raised ``TypeError: _get_wrapper_address() missing 1 required
    positional argument``): the command still ends with the signal's code and one line.  Without a
    signal the same exception is an internal error (exit 1).  The wrong variant, `main` catching
    only KeyboardInterrupt for the signal, exits 1 with ``internal error`` (checked by hand)."""
    import renderer.cli as cli

    def command(args):
        try:
            os.kill(os.getpid(), signum)
            time.sleep(1.0)                       # the exception comes here
        except KeyboardInterrupt:
            pass
        raise TypeError("what the interrupted code raised")

    monkeypatch.setitem(cli._COMMANDS, "render", command)
    code, word = OUTCOME[signum]
    assert cli.main(["render", "-o", "x.png"]) == code
    assert capsys.readouterr().err == f"symrender: {word}\n"
    monkeypatch.setitem(cli._COMMANDS, "render", lambda args: (_ for _ in ()).throw(TypeError("a bug")))
    assert cli.main(["render", "-o", "x.png"]) == 1
    assert "internal error: TypeError: a bug" in capsys.readouterr().err


def _render_with_a_dropped_ctrl_c(monkeypatch, how):
    """Make ``render`` take a Ctrl-C, before its frame, inside C code that drops the
    KeyboardInterrupt: a ctypes callback, which reports it (``sys.unraisablehook``), as
    llvmlite's object-cache callback does while numba compiles a kernel ("reported"), or
    ``PyObject_HasAttr``, which clears any error without a report ("cleared").
    Returns the list that the frame's end appends to."""
    import ctypes
    import importlib

    module = importlib.import_module("renderer.render")   # the package's `render` is the function
    real, rendered = module.render, []

    def ctrl_c(*_):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)                          # the KeyboardInterrupt is raised here, and dropped
        return 0

    class Probe:
        __getattr__ = ctrl_c

    has_attr = ctypes.pythonapi.PyObject_HasAttr
    has_attr.argtypes, has_attr.restype = (ctypes.py_object, ctypes.py_object), ctypes.c_int
    drop = {"reported": ctypes.CFUNCTYPE(ctypes.c_int)(ctrl_c),
            "cleared": lambda: has_attr(Probe(), "x")}[how]

    def render(*args, **kwargs):
        drop()
        frame = real(*args, **kwargs)
        rendered.append(True)
        return frame

    monkeypatch.setattr(module, "render", render)
    return rendered


@pytest.mark.parametrize("how", ["reported", "cleared"])
@pytest.mark.parametrize("variant", ["as built", "no check before writing"])
def test_a_ctrl_c_that_c_code_drops_still_stops_the_command(tmp_path, capsys, monkeypatch, how, variant):
    """A Ctrl-C whose KeyboardInterrupt C code drops, reported or not, still ends the command
    with 130 and the one line, and writes nothing.  Wrong variants: without
    `renderer.cli._stop_if_signalled` the command finishes, writes its PNG and exits 0."""
    import renderer.cli as cli

    if variant == "no check before writing":
        monkeypatch.setattr(cli, "_stop_if_signalled", lambda: None)
    # Python's own hook, which prints the report (pytest's turns it into a warning).
    monkeypatch.setattr(sys, "unraisablehook", sys.__unraisablehook__)
    rendered = _render_with_a_dropped_ctrl_c(monkeypatch, how)
    out = tmp_path / "out.png"
    before = sys.unraisablehook
    code = cli.main(["render", "--size", "16x12", "-o", str(out)])
    err = capsys.readouterr().err
    assert rendered, "the render did not run"
    assert sys.unraisablehook is before
    problems = interrupt_problems(code, err, [], listing(tmp_path), [])
    if variant == "as built":
        assert problems == []
    else:
        assert "exit code 0" in problems and "files left: ['out.png']" in problems
