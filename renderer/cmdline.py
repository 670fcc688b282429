"""The command-line toolkit of ``symrender`` (`renderer.cli`) and of the maintainers'
``book/check_figures.py``: one way to parse, report, write and exit.

`main` runs a command and maps its outcome to an exit code, with at most one line
on standard error:

====  ==========================================================================
0     done (or the command's own code: ``check_figures.py --check`` returns 1 for
      a changed figure)
1     ``<prog>: internal error: ...``: a bug (no traceback); or a broken pipe (quiet)
2     ``<prog>: error: ...``: an input error: a bad argument (`UsageError`), a value
      the library's validation refuses (`renderer.validate.InputError`, with the
      library's message), a path refused (`renderer.files.RefusedPath`), a file or
      stream that cannot be read or written (OSError, naming it), a bad
      environment (``NUMBA_NUM_THREADS``), memory exhausted
130   ``<prog>: interrupted``: SIGINT (Ctrl-C)
143   ``<prog>: terminated``: SIGTERM (what ``timeout``, CI and service managers send)
====  ==========================================================================

Outputs.  A command writes its report into `Outputs` and stages its output files
there; nothing reaches the report's stream or the files while it runs.  When it
returns, the report is written and flushed, and only then are the files committed
(renamed into place).  So an exit code other than 0 never comes with an output
written: an error, a signal, or a report that cannot be written (a full or broken
standard output) leaves every output as it was and no temporary file.

Streams.  A standard stream that is closed at start (``2>&-``) is reopened on
/dev/null at the descriptor level, so that no file the command opens takes its
descriptor number (and a library's message to it cannot land in an output); its
messages are lost, never sent to another stream.  A closed standard output is an
input error before any work: the report could not be read.

Signals.  SIGINT and SIGTERM raise `KeyboardInterrupt` in the main thread, so that
every clean-up runs; the signal is recorded, and decides the message and the exit
code.  A second signal during the clean-up is ignored, and the previous handlers
are back when `main` returns.  A signal whose exception a C callback dropped
(llvmlite's, while numba compiles) is remembered and raised again by
`check_signal` before anything is written.

This module imports neither numpy nor matplotlib: ``symrender`` starts at once.
"""

from __future__ import annotations

import argparse
import io
import logging
import os
import re
import signal
import sys

from . import files

__all__ = ["main", "Parser", "UsageError", "Outputs", "check_signal", "record_signal",
           "one_line", "progress", "show_progress", "import_matplotlib", "png_bytes", "binary_stdout", "is_stdout",
           "STDOUT"]

#: The output path that means standard output (``-o -``).
STDOUT = "-"


class UsageError(Exception):
    """A bad argument or input: printed as one line, exit code 2."""


_NEGATIVE_VALUE = re.compile(r"-[0-9.]")


class Parser(argparse.ArgumentParser):
    """argparse without abbreviations (``--v`` is not ``--version``, ``--chec`` not
    ``--check``), raising `UsageError` instead of printing usage and exiting, and
    taking a value that starts with ``-`` and a digit or ``.`` as the value of the
    option before it (``--size -5x5``, ``--eps -1e-3``), so that such values reach
    the command's own checks and messages."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, allow_abbrev=False, **kwargs)

    def error(self, message):
        raise UsageError(message)

    def parse_known_args(self, args=None, namespace=None):
        if args is not None:
            takes_value = {o for a in self._actions if a.nargs is None for o in a.option_strings}
            args, joined = list(args), []
            while args:
                token = args.pop(0)
                if token == "--":
                    joined += [token, *args]
                    break
                if token in takes_value and args and _NEGATIVE_VALUE.match(args[0]):
                    token = f"{token}={args.pop(0)}"
                joined.append(token)
            args = joined
        return super().parse_known_args(args, namespace)


def one_line(msg, limit=500):
    """``msg`` on one line, cut to ``limit`` characters (a bad value can be megabytes long)."""
    text = " ".join(str(msg).split())
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text):,} characters)"


# ---------------------------------------------------------------- streams


def show_progress():
    """Whether a progress bar is shown: standard error is open and a terminal."""
    try:
        return sys.stderr is not None and sys.stderr.isatty()
    except ValueError:                       # closed by someone
        return False


def progress(iterable=None, **kwargs):
    """A tqdm bar on standard error, shown only when `show_progress` and the work
    takes more than a second; usable as an iterator or a context manager."""
    from tqdm import tqdm
    return tqdm(iterable, file=sys.stderr, disable=not show_progress(), delay=1.0, leave=False, **kwargs)


def _silence(stream):
    """Point ``stream``'s descriptor at /dev/null after a write to it failed, so that
    Python's flush at exit does not fail again (a message, and exit code 120)."""
    try:
        null = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(null, stream.fileno())
        finally:
            os.close(null)
    except (OSError, ValueError, AttributeError):   # no descriptor (a test's StringIO)
        pass


def _write(stream, name, text):
    """Write ``text`` to ``stream`` and flush it; an OSError names the stream."""
    try:
        stream.write(text)
        stream.flush()
    except OSError as exc:
        _silence(stream)
        raise OSError(exc.errno, exc.strerror, name) from None


def _say(line):
    """One line on standard error, if it can be written at all (else it is lost)."""
    if sys.stderr is not None:
        try:
            _write(sys.stderr, "standard error", line + "\n")
        except (OSError, ValueError):
            pass


def _open_standard_descriptors():
    """Reopen a closed descriptor 0, 1 or 2 on /dev/null (see the module's Streams)."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            null = os.open(os.devnull, os.O_RDWR)       # the lowest free descriptor: ``fd``
            if null != fd:
                os.dup2(null, fd)
                os.close(null)


def binary_stdout(flag):
    """The binary stream under standard output, for ``flag`` ``-``.

    Raises
    ------
    UsageError
        Standard output is a terminal (a PNG there is noise), or takes no bytes.
    """
    stream = sys.stdout
    if stream.isatty():
        raise UsageError(f"{flag} '-' is standard output, which is a terminal; redirect it to a "
                         "file or a pipe, or give a file name")
    if getattr(stream, "buffer", None) is None:
        raise UsageError(f"{flag} '-': standard output does not take bytes here; give a file name")
    return stream.buffer


def is_stdout(path):
    """Whether ``path`` names standard output itself: ``-``, or a file that is the one
    standard output writes to (``/dev/stdout``, ``/proc/self/fd/1``): a command then
    reports on standard error, so that no message lands in the output."""
    if path == STDOUT:
        return True
    try:
        a, b = os.stat(path), os.fstat(sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):      # absent, or no descriptor (a test's StringIO)
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


class _StdoutBytes:
    """Bytes for standard output, written at `commit` (as `renderer.files.Staged`)."""

    def __init__(self, flag, data):
        binary_stdout(flag)
        self._data = data

    def commit(self):
        sys.stdout.flush()
        _write(sys.stdout.buffer, "standard output", self._data)

    def discard(self):
        pass


class Outputs:
    """What a command writes: its report and its output files, held until it returns.

    The report is text: ``print(..., file=outputs)``.  It goes to standard output,
    or to standard error once ``to_stderr`` is set (when an output file is
    standard output).  Files are staged by `stage` (an object with ``commit()`` and
    ``discard()``, as `renderer.files.Staged`) or `stage_bytes`.  `main` calls
    `finish` after the command, `discard` on every exit.
    """

    def __init__(self):
        self._report = io.StringIO()
        self._staged = []
        self.to_stderr = False

    def write(self, text):
        return self._report.write(text)

    def stage(self, staged):
        """Hold ``staged`` until `finish` commits it (or `discard` drops it); returns it."""
        self._staged.append(staged)
        return staged

    def stage_bytes(self, path, data, flag):
        """Stage ``data`` for ``path`` (`renderer.files.Staged`; ``-`` is standard
        output).  Raises as `renderer.files.Staged` and `binary_stdout`."""
        if path == STDOUT:
            return self.stage(_StdoutBytes(flag, data))
        return self.stage(files.Staged(path, data))

    def finish(self):
        """Write and flush the report, then commit the staged files in order.

        Raises
        ------
        OSError
            The report's stream or a file cannot be written (naming it); the files
            not yet committed are left to `discard`.
        """
        stream, name = (sys.stderr, "standard error") if self.to_stderr else (sys.stdout, "standard output")
        text = self._report.getvalue()
        if text and stream is not None:
            _write(stream, name, text)
        while self._staged:
            self._staged[0].commit()
            self._staged.pop(0)

    def discard(self):
        """Drop every staged file not yet committed (their temporary files removed)."""
        while self._staged:
            self._staged.pop().discard()


# ---------------------------------------------------------------- signals


_SIGNALS = (signal.SIGINT, signal.SIGTERM)
#: The first signal seen during `main` (None: none): kept because numba's compiler runs
#: Python callbacks from C, which drop the exception raised in them.
_seen = None


def record_signal(signum):
    """Note that ``signum`` arrived (for a handler other than `main`'s, as a page
    runner's); return whether it is the first signal of the run."""
    global _seen
    first = _seen is None
    if first:
        _seen = signum
    return first


def _on_signal(signum, frame):
    if record_signal(signum):
        for sig in _SIGNALS:                 # a second signal does not cut the clean-up short
            signal.signal(sig, signal.SIG_IGN)
        raise KeyboardInterrupt


def check_signal():
    """Raise `KeyboardInterrupt` if a signal came during `main`, even one whose
    exception a C callback dropped."""
    if _seen is not None:
        raise KeyboardInterrupt


# ---------------------------------------------------------------- libraries


def import_matplotlib():
    """matplotlib (with ``matplotlib.image``), imported with what it logs meanwhile dropped.

    Where $HOME (or XDG_CONFIG_HOME, XDG_CACHE_HOME) is not writable, matplotlib
    falls back to a temporary directory of its own, removed at exit, logs two
    warnings saying so, and builds its font cache there (a third warning if that
    takes over 5 s): a command's standard error gets none of that."""
    loggers = [logging.getLogger(name) for name in ("matplotlib", "matplotlib.font_manager")]
    drop = lambda record: False  # noqa: E731
    for log in loggers:
        log.addFilter(drop)
    try:
        import matplotlib
        import matplotlib.image              # the font manager is loaded (or its cache built) here
    finally:
        for log in loggers:
            log.removeFilter(drop)
    return matplotlib


def png_bytes(pixels):
    """PNG bytes of an (H, W, 3 or 4) uint8 image without metadata: no tEXt chunk
    ("Software" is matplotlib's only default key), so two runs give the same bytes."""
    matplotlib = import_matplotlib()
    buf = io.BytesIO()
    matplotlib.image.imsave(buf, pixels, format="png", metadata={"Software": None})
    return buf.getvalue()


def _check_environment():
    """Refuse an environment numba cannot start with (it would warn with a traceback,
    or fail later as a bug)."""
    value = os.environ.get("NUMBA_NUM_THREADS")
    if value is not None:
        try:
            ok = int(value) >= 1                 # as numba reads it
        except ValueError:
            ok = False
        if not ok:
            raise UsageError(f"the environment variable NUMBA_NUM_THREADS must be a positive integer "
                             f"(numba's thread count), got {value!r}")


# ---------------------------------------------------------------- main


def main(prog, command, argv) -> int:
    """Run ``command(argv, outputs)`` and return the exit code of the module's table.

    Parameters
    ----------
    prog : str
        The name the messages start with.
    command : callable (list of str, Outputs) -> int
        Parses ``argv`` (a `Parser`) and does the work; its return value is the exit
        code when it returns.
    argv : list of str

    Never raises; ``--help`` and ``--version`` print to standard output and return 0.
    """
    global _seen
    _seen = None
    _open_standard_descriptors()
    for stream in (sys.stdout, sys.stderr):     # a name the terminal cannot encode prints escaped
        if hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")
    hook, previous = sys.unraisablehook, {}
    # The report of an interrupt swallowed in a C callback stays off stderr: `_seen` has it.
    sys.unraisablehook = lambda u: None if isinstance(u.exc_value, KeyboardInterrupt) else hook(u)
    try:
        for sig in _SIGNALS:
            previous[sig] = signal.signal(sig, _on_signal)
    except ValueError:                       # not the main thread: signals are left alone
        pass
    try:
        return _run(prog, command, argv)
    finally:
        sys.unraisablehook = hook
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _run(prog, command, argv):
    """`main` without its signal handlers."""
    outputs = Outputs()
    try:
        try:
            _check_environment()
            if sys.stdout is None:
                raise UsageError(f"standard output is closed: {prog} reports there")
            code = command(argv, outputs)
            check_signal()
            outputs.finish()
            return code
        finally:
            outputs.discard()
    except SystemExit as exc:                # --help, --version: argparse printed them
        if sys.stdout is not None:
            try:
                _write(sys.stdout, "standard output", "")
            except OSError as err:
                _say(f"{prog}: error: {err.filename}: {one_line(err.strerror)}")
                return 2
        return exc.code if isinstance(exc.code, int) else 0
    except KeyboardInterrupt:
        signum = _seen or signal.SIGINT        # raised without our handler: Python's Ctrl-C
        _say(f"{prog}: {'terminated' if signum == signal.SIGTERM else 'interrupted'}")
        return 128 + signum
    except UsageError as exc:
        _say(f"{prog}: error: {one_line(exc)}")
        return 2
    except BrokenPipeError:                  # the reader left (| head): stop quietly, as cat does
        _silence(sys.stdout)
        return 1
    except OSError as exc:
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        _say(f"{prog}: error: {where}{one_line(exc.strerror or exc)}")
        return 2
    except MemoryError:
        _say(f"{prog}: error: out of memory")
        return 2
    except Exception as exc:
        validate = sys.modules.get("renderer.validate")     # loaded if it raised
        if isinstance(exc, files.RefusedPath) or (validate and isinstance(exc, validate.InputError)):
            _say(f"{prog}: error: {one_line(exc)}")
            return 2
        _say(f"{prog}: internal error: {type(exc).__name__}: {one_line(exc)}")   # a bug: no traceback
        return 1
