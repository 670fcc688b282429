"""Atomic file writes, shared by the command line and the JavaScript generator."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["atomic_write", "umask"]


def umask():
    """The process's file-creation mask (read without changing it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write(path, write):
    """Write a file atomically: ``write(fileobj)`` (a binary file object) into a
    temporary file in the target directory, then `os.replace` it onto ``path``.

    On any exception (including KeyboardInterrupt) the temporary file is
    removed and the exception propagates; ``path`` is then untouched (absent if
    it did not exist).  The file gets the usual 0666 & ~umask permissions, not
    mkstemp's 0600.

    Raises
    ------
    OSError
        If the directory does not exist or cannot be written.
    """
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(dir=parent, prefix=f".{target.name}.", suffix=".part")
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o666 & ~umask())
        os.replace(tmp, target)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
