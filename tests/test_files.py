"""Tests of `renderer.files.write_bytes`: the target is replaced whole or not at all.

A Ctrl-C or SIGTERM during a real command's write is tests/test_interrupts.py's.
"""

from __future__ import annotations

import errno
import os
import stat
import threading

import pytest

from renderer import files


def test_a_file_or_a_link_s_target_is_replaced_by_a_rename(tmp_path):
    new, old, link = tmp_path / "new.bin", tmp_path / "old.bin", tmp_path / "link.bin"
    old.write_bytes(b"old contents, longer than the new")
    link.symlink_to(old.name)
    inode = old.stat().st_ino
    files.write_bytes(new, b"new")
    files.write_bytes(link, b"through the link")
    assert new.read_bytes() == b"new" and old.read_bytes() == b"through the link"
    assert old.stat().st_ino != inode and os.readlink(link) == "old.bin"      # renamed over; the link stays
    assert stat.S_IMODE(new.stat().st_mode) == 0o666 & ~files.umask()        # not mkstemp's 0600
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.bin", "new.bin", "old.bin"]


@pytest.mark.parametrize("call, failure", [("fsync", OSError(errno.ENOSPC, "No space left on device")),
                                           ("replace", KeyboardInterrupt())], ids=["disk-full", "interrupt"])
def test_a_failure_while_writing_leaves_the_old_file_and_no_temporary_file(tmp_path, monkeypatch, call, failure):
    target = tmp_path / "o.png"
    target.write_bytes(b"old")

    def fail(*args):
        raise failure
    monkeypatch.setattr(files.os, call, fail)
    with pytest.raises(type(failure)) as info:
        files.write_bytes(target, b"new")
    assert target.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["o.png"]
    if call == "fsync":
        assert info.value.filename == str(target)         # the user's path, not the temporary file


def test_a_pipe_is_written_through_and_stays_a_pipe(tmp_path):
    """As ``-o /dev/stdout`` on a pipe (and ``/dev/null``): a rename would put a file in its place."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    files.write_bytes(fifo, b"through")
    reader.join(10)
    assert got == [b"through"] and stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_a_directory_is_refused_and_nothing_is_left(tmp_path):
    (tmp_path / "d").mkdir()
    with pytest.raises(IsADirectoryError) as info:
        files.write_bytes(tmp_path / "d", b"x")
    assert info.value.filename == str(tmp_path / "d") and [p.name for p in tmp_path.iterdir()] == ["d"]
    assert list((tmp_path / "d").iterdir()) == []
