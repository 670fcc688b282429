"""Atomic file output, for ``symrender``, the code generators, the measurement store and the
book's extensions."""

from __future__ import annotations

import contextlib
import os
import tempfile

__all__ = ["write_bytes", "umask"]


def umask():
    """The process's file-creation mask (read without changing it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_bytes(path, data, before=None):
    """Write ``data`` to ``path`` atomically: into a temporary file beside it, then `os.replace`.

    Parameters
    ----------
    path : str or os.PathLike
        A new or regular file, or a symbolic link to one (the link stays a link and its
        target is replaced).  An existing device or pipe (``/dev/null``, ``/dev/stdout``
        on a pipe) is written through instead, and stays what it was.
    data : bytes-like
        The whole content.
    before : callable, optional
        Called with the temporary file's path once ``data`` is in it, just before it takes ``path``'s
        place: what it raises leaves ``path`` as it was (a device: called with None once written through).

    On any exception, KeyboardInterrupt included, the temporary file
    (``.<name>.XXXX.part``) is removed and ``path`` is as it was.  The file gets
    the permissions ``0o666 & ~umask``, as ``open`` would give it.

    Raises
    ------
    OSError
        The directory or the target cannot be written, or ``path`` is a directory;
        the error names ``path``, never the temporary file.
    """
    path = os.fspath(path)
    if os.path.exists(path) and not os.path.isfile(path) and not os.path.isdir(path):
        try:
            with open(path, "wb") as f:             # a device or a pipe: written through
                f.write(data)
        except OSError as exc:                      # /dev/full: no space, naming the device
            raise type(exc)(exc.errno, exc.strerror, path) from None
        if before is not None:
            before(None)
        return
    target = os.path.realpath(path)
    try:
        fd, tmp = tempfile.mkstemp(dir=os.path.dirname(target), prefix=f".{os.path.basename(target)}.",
                                   suffix=".part")
    except OSError as exc:
        raise type(exc)(exc.errno, exc.strerror, path) from None
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o666 & ~umask())
        if before is not None:
            before(tmp)
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise type(exc)(exc.errno, exc.strerror, path) from None
        raise
