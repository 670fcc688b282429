"""Safe file writes and bounded reads, shared by the command line and the
JavaScript generator.

Writes never rename over anything but a regular file: a path that is absent or
a regular file is replaced atomically (a temporary file beside it, then
`os.replace`), and so is the final target of a symbolic link to a regular
file (the link stays a link); a character device or FIFO (``/dev/null``), or
a link to one (``/dev/stdout`` on a pipe), is written through and stays what
it was; anything else (a directory, a dangling link, a block device, a
socket, a path ending in ``/``) is refused.  Reads take regular files only,
up to a stated size, with a bounded read.
"""

from __future__ import annotations

import io
import os
import stat
import tempfile
from pathlib import Path

__all__ = ["atomic_write", "write_bytes", "Staged", "output_route", "read_regular", "RefusedPath", "umask"]


class RefusedPath(ValueError):
    """A path this module will not write to or read from; the message names it
    and says what is accepted (a ValueError, as an argument refused)."""


def umask():
    """The process's file-creation mask (read without changing it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _named(exc, path):
    """``exc`` (an OSError) re-raised naming ``path`` instead of whatever file
    the failing call was given (a temporary file, a descriptor)."""
    return OSError(exc.errno, exc.strerror or str(exc), os.fspath(path))


def output_route(path):
    """How `write_bytes` would write ``path``, without writing anything.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    str
        ``"replace"`` if ``path`` is absent or a regular file (not a symbolic
        link): a temporary file in its directory is renamed onto it.
        ``"link"`` if it is a symbolic link to a regular file: the same, onto
        the link's final target (the link stays a link).  ``"through"`` if it
        is a character device or a FIFO, or a link to one: it is opened for
        writing and written, and stays what it was.

    Raises
    ------
    RefusedPath
        An empty path, a path ending in ``/`` (or in a ``.`` or ``..``
        component), a directory, a block device, a socket, or a symbolic
        link whose target does not exist or is one of those.
    OSError
        If ``path`` cannot be examined (other than being absent), naming it.
    """
    text = os.fspath(path)
    if not text:
        raise RefusedPath("'' is an empty path (give a file name)")
    if text.endswith(("/", "/.", "/..")) or text in (".", ".."):
        raise RefusedPath(f"{text!r} names a directory (give a file name without a trailing '/')")
    try:
        st = os.lstat(text)
    except FileNotFoundError:
        return "replace"
    except OSError as exc:
        raise _named(exc, text) from None
    if stat.S_ISREG(st.st_mode):
        return "replace"
    if stat.S_ISLNK(st.st_mode):
        try:
            st = os.stat(text)
        except FileNotFoundError:
            raise RefusedPath(f"{text!r} is a symbolic link to {os.readlink(text)!r}, which does not "
                              "exist (accepted: a link to an existing file or device)") from None
        except OSError as exc:
            raise _named(exc, text) from None
        if stat.S_ISDIR(st.st_mode):
            raise RefusedPath(f"{text!r} is a symbolic link to a directory (give a file name)")
    if stat.S_ISDIR(st.st_mode):
        raise RefusedPath(f"{text!r} is a directory (give a file name)")
    if stat.S_ISBLK(st.st_mode) or stat.S_ISSOCK(st.st_mode):
        kind = "a block device" if stat.S_ISBLK(st.st_mode) else "a socket"
        raise RefusedPath(f"{text!r} is {kind} (accepted: a new or regular file, a character "
                          "device, a FIFO, or a link to one of those)")
    if stat.S_ISREG(st.st_mode):
        return "link"
    return "through"


def _write_all(fd, data):
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


class Staged:
    """An output prepared but not yet in place: `write_bytes` in two steps, so that a
    caller can do something between them (a command reports, then commits).

    On creation the route is chosen (`output_route`) and, for a replaced file, the
    whole content is written and synced into a temporary file beside the target
    (``.<name>.XXXX.part``); `commit` renames it onto the target, `discard` removes
    it.  A device or FIFO is written through at `commit` (nothing is staged on disk).
    Until `commit` returns, ``path`` is untouched; on any exception in either step
    (KeyboardInterrupt included) the temporary file is removed.

    Parameters
    ----------
    path : str or os.PathLike
    data : bytes-like
        The whole content.

    Raises
    ------
    RefusedPath
        As `output_route`.
    OSError
        If the directory or the target cannot be written; the error names
        ``path``, never the temporary file.
    """

    def __init__(self, path, data):
        self.path, self._data, self._tmp = path, None, None
        route = output_route(path)
        if route == "through":
            self._data = data
            return
        target = Path(os.path.realpath(path)) if route == "link" else Path(path)
        self._target = target
        try:
            fd, self._tmp = tempfile.mkstemp(dir=target.parent if str(target.parent) else Path("."),
                                             prefix=f".{target.name[:64]}.", suffix=".part")
        except OSError as exc:
            raise _named(exc, path) from None
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
            os.chmod(self._tmp, 0o666 & ~umask())
        except BaseException as exc:
            self.discard()
            if isinstance(exc, OSError):
                raise _named(exc, path) from None
            raise

    def commit(self):
        """Put the content in place: rename the temporary file onto the target, or write
        a device or FIFO through.  Raises OSError naming ``path``."""
        try:
            if self._tmp is None:
                fd = os.open(self.path, os.O_WRONLY | os.O_CLOEXEC | getattr(os, "O_NOCTTY", 0))
                try:
                    _write_all(fd, self._data)
                finally:
                    os.close(fd)
            else:
                os.replace(self._tmp, self._target)
                self._tmp = None
        except BaseException as exc:
            self.discard()
            if isinstance(exc, OSError):
                raise _named(exc, self.path) from None
            raise

    def discard(self):
        """Remove the temporary file, if any (the target is left as it was)."""
        tmp, self._tmp = self._tmp, None
        if tmp is not None:
            try:
                os.unlink(tmp)
            except FileNotFoundError:
                pass


def write_bytes(path, data):
    """Write ``data`` to ``path`` by the route of `output_route`: `Staged`, then its commit.

    Parameters
    ----------
    path : str or os.PathLike
    data : bytes-like
        The whole content, prepared before the target is opened.

    Replaced files are written atomically: on any exception (including
    KeyboardInterrupt) the temporary file is removed and ``path`` is untouched
    (absent if it did not exist); the file gets 0666 & ~umask permissions, not
    mkstemp's 0600; a link to a regular file is followed to its final target,
    which is replaced the same way.  Written-through targets (devices,
    FIFOs) are opened without ``O_CREAT`` and never unlinked.

    Raises
    ------
    RefusedPath
        As `output_route`.
    OSError
        If the directory or the target cannot be written; the error names
        ``path``, never the temporary file.
    """
    Staged(path, data).commit()


def atomic_write(path, write):
    """Write a file from ``write(fileobj)`` (a callable given a binary file
    object): the bytes are prepared in memory first, then written by
    `write_bytes` (atomically for a regular file or the file a link leads
    to, through a device or FIFO).  An exception in ``write`` writes nothing.

    Raises
    ------
    RefusedPath, OSError
        As `write_bytes`; whatever ``write`` raises propagates.
    """
    buf = io.BytesIO()
    write(buf)
    write_bytes(path, buf.getbuffer())


def read_regular(path, limit, *, follow=True):
    """Read a whole regular file of at most ``limit`` bytes.

    The file is opened with ``O_NONBLOCK`` (a FIFO does not block the open)
    and, if ``follow`` is false, ``O_NOFOLLOW`` (a symbolic link is refused);
    its type and size are checked on the open descriptor, and at most
    ``limit + 1`` bytes are read, so a file that grows is refused too.

    Parameters
    ----------
    path : str or os.PathLike
    limit : int
        Most bytes accepted.
    follow : bool
        Whether a symbolic link is followed (default) or refused.

    Returns
    -------
    bytes

    Raises
    ------
    RefusedPath
        Not a regular file (a directory, device, FIFO or socket; a symbolic
        link when ``follow`` is false), or larger than ``limit`` bytes.
    OSError
        If it cannot be opened or read, naming ``path``.
    """
    text = os.fspath(path)
    flags = os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC | (0 if follow else os.O_NOFOLLOW)
    try:
        fd = os.open(text, flags)
    except OSError as exc:
        if not follow and os.path.islink(text):
            raise RefusedPath(f"{text!r} is a symbolic link (accepted: a regular file)") from None
        raise _named(exc, text) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = ("a directory" if stat.S_ISDIR(st.st_mode) else "a FIFO" if stat.S_ISFIFO(st.st_mode)
                    else "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode)
                    else "not a regular file")
            raise RefusedPath(f"{text!r} is {kind} (accepted: a regular file)")
        too_big = RefusedPath(f"{text!r} is larger than {limit:,} bytes (the most accepted)")
        if st.st_size > limit:
            raise too_big
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, limit + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:
            raise too_big
        return b"".join(chunks)
    except OSError as exc:
        raise _named(exc, text) from None
    finally:
        os.close(fd)
