"""Tests of `renderer.files`: the writer never renames over anything but a
regular file, and the reader takes bounded regular files only.

Outputs that are devices, FIFOs or links are written through and keep their
kind (checked with ``os.lstat``); refused paths leave nothing behind; errors
name the user's path, never the temporary file.  Each check is shown to reject
a wrong variant: a writer that always renames, an error that is not re-named,
a reader that follows links.  CI runs as root, so the private character
device (``os.mknod``) case runs there; it skips only without root.
"""

from __future__ import annotations

import os
from pathlib import Path
import stat
import tempfile
import threading

import pytest

from renderer.cli import main
from renderer import files

from .test_cli import returns_without_blocking

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
RENDER = ["render", "--size", "8x8", "-o"]


def kind(path):
    """The file type of ``path`` itself (not following a link)."""
    mode = os.lstat(path).st_mode
    for name in ("LNK", "REG", "CHR", "FIFO", "DIR", "BLK", "SOCK"):
        if getattr(stat, f"S_IS{name}")(mode):
            return name
    return "?"


def always_replace(path, data):
    """Wrong variant: the writer before this module's routes (temporary file,
    then `os.replace` whatever ``path`` is)."""
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path) or ".", suffix=".part")
    with os.fdopen(fd, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def read_fifo_in_thread(path):
    """Start a thread that reads ``path`` (a FIFO) to its end; returns
    (thread, list that receives the bytes)."""
    got = []

    def reader():
        with open(path, "rb") as f:
            got.append(f.read())

    t = threading.Thread(target=reader, daemon=True)
    t.start()
    return t, got


# ------------------------------------------------------------------ routes


def test_regular_and_absent_paths_are_replaced_atomically(tmp_path):
    new, old = tmp_path / "new.bin", tmp_path / "old.bin"
    old.write_bytes(b"old contents, longer than the new")
    ino = os.stat(old).st_ino
    for p in (new, old):
        assert files.output_route(p) == "replace"
        files.write_bytes(p, b"new")
        assert p.read_bytes() == b"new" and kind(p) == "REG"
    assert os.stat(old).st_ino != ino  # renamed over, not rewritten in place
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new.bin", "old.bin"]


def test_dev_null_stays_a_character_device(capsys):
    assert main([*RENDER, "/dev/null"]) == 0
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert "ledger" in capsys.readouterr().out


@pytest.mark.skipif(os.geteuid() != 0, reason="os.mknod of a character device needs root")
def test_private_character_device_stays_one(tmp_path, capsys):
    dev = tmp_path / "null"
    os.mknod(dev, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    assert main([*RENDER, str(dev)]) == 0
    assert kind(dev) == "CHR" and os.stat(dev).st_rdev == os.makedev(1, 3)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["null"]
    # Wrong variant: renaming unconditionally turns the device into a regular file.
    always_replace(str(dev), PNG_SIGNATURE)
    assert kind(dev) == "REG"


def test_fifo_receives_the_png_and_stays_a_fifo(tmp_path, capsys):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    t, got = read_fifo_in_thread(fifo)
    assert main([*RENDER, str(fifo)]) == 0
    t.join(10)
    assert got and got[0].startswith(PNG_SIGNATURE) and got[0].endswith(b"IEND\xaeB`\x82")
    assert kind(fifo) == "FIFO"
    # Wrong variant: renaming unconditionally replaces the FIFO with a regular file.
    always_replace(str(fifo), PNG_SIGNATURE)
    assert kind(fifo) == "REG"


def test_symlink_to_a_file_stays_a_link_and_its_target_gets_the_png(tmp_path, capsys):
    target, link = tmp_path / "real.png", tmp_path / "link.png"
    target.write_bytes(b"old contents, longer than a header" * 100)
    link.symlink_to(target.name)
    inode = target.stat().st_ino
    assert main([*RENDER, str(link)]) == 0
    assert kind(link) == "LNK" and os.readlink(link) == "real.png"
    data = target.read_bytes()
    assert data.startswith(PNG_SIGNATURE) and data.endswith(b"IEND\xaeB`\x82")
    assert target.stat().st_ino != inode               # replaced by a rename, not rewritten in place
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.png", "real.png"]
    # Wrong variant: renaming unconditionally replaces the link by a file.
    always_replace(str(link), PNG_SIGNATURE)
    assert kind(link) == "REG"


def test_a_write_through_a_link_interrupted_at_the_rename_leaves_the_target_whole(tmp_path, monkeypatch):
    target, link = tmp_path / "real.png", tmp_path / "link.png"
    target.write_bytes(b"old")
    link.symlink_to(target.name)

    def interrupted(*args):
        raise KeyboardInterrupt
    monkeypatch.setattr(files.os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        files.write_bytes(link, PNG_SIGNATURE * 1000)
    assert target.read_bytes() == b"old" and sorted(p.name for p in tmp_path.iterdir()) == ["link.png", "real.png"]


def test_link_to_dev_stdout_writes_through_the_pipe(tmp_path):
    """A link like /dev/stdout whose target is a pipe: the bytes go down the pipe."""
    fifo, link = tmp_path / "pipe", tmp_path / "stdout"
    os.mkfifo(fifo)
    link.symlink_to(fifo)
    t, got = read_fifo_in_thread(fifo)
    files.write_bytes(link, b"through")
    t.join(10)
    assert got == [b"through"] and kind(link) == "LNK" and kind(fifo) == "FIFO"


def _unix_socket(path):
    """A bound Unix socket file at ``path`` (kept open for the test's life)."""
    import socket
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(path))
    _SOCKETS.append(sock)
    return path


_SOCKETS = []


@pytest.mark.parametrize("make, word", [
    (lambda d: (d / "dangling.png").symlink_to(d / "missing.png") or d / "dangling.png", "does not exist"),
    (lambda d: str(d / "x.png") + "/", "trailing '/'"),
    (lambda d: str(d / "x.png") + "/.", "trailing '/'"),
    (lambda d: d, "directory"),
    (lambda d: (d / "dirlink").symlink_to(d) or d / "dirlink", "directory"),
    (lambda d: "", "empty"),
    (lambda d: _unix_socket(d / "sock"), "socket"),
])
def test_refused_outputs_are_one_line_and_create_nothing(tmp_path, capsys, make, word):
    path = make(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    assert main([*RENDER, str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("symrender: error: -o ") and word in err
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    with pytest.raises(files.RefusedPath):
        files.write_bytes(path, b"x")
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_trailing_slash_is_checked_on_the_text_not_the_path(tmp_path):
    # Wrong variant: pathlib drops a trailing '/', so a check on Path(...) misses it.
    assert str(tmp_path / "x.png/") == str(tmp_path / "x.png")
    with pytest.raises(files.RefusedPath):
        files.output_route(str(tmp_path / "x.png") + "/")


def test_errors_name_the_target_not_the_temporary_file(tmp_path):
    (tmp_path / "file.txt").write_text("x")
    target = tmp_path / "file.txt" / "o.png"  # its parent is a regular file
    with pytest.raises(OSError) as info:
        files.write_bytes(target, b"x")
    assert info.value.filename == str(target) and ".part" not in str(info.value)
    # Wrong variant: the unwrapped error of mkstemp names the temporary file.
    with pytest.raises(OSError) as raw:
        tempfile.mkstemp(dir=target.parent, prefix=".o.png.", suffix=".part")
    assert ".part" in str(raw.value.filename)


def test_failed_rename_is_reported_with_the_users_path(tmp_path, capsys, monkeypatch):
    """A rename refused by the system (as in a read-only directory, which root
    bypasses) is one line naming -o's path, and leaves no temporary file."""
    def refuse(src, dst):
        raise PermissionError(13, "Permission denied", src)

    monkeypatch.setattr(files.os, "replace", refuse)
    out = tmp_path / "o.png"
    assert main([*RENDER, str(out)]) == 2
    err = capsys.readouterr().err
    assert err == f"symrender: error: {out}: Permission denied\n" and ".part" not in err
    assert list(tmp_path.iterdir()) == []


def test_an_error_while_encoding_writes_nothing(tmp_path):
    target, link = tmp_path / "real.png", tmp_path / "link.png"
    target.write_bytes(b"old")
    link.symlink_to(target)

    def half_then_fail(f):
        f.write(b"half")
        raise ValueError("encoder failed")

    for path in (target, link, tmp_path / "new.png"):
        with pytest.raises(ValueError):
            files.atomic_write(path, half_then_fail)
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.png", "real.png"]
    # Wrong variant: writing through the link while encoding leaves half a file.
    with pytest.raises(ValueError), open(link, "wb") as f:
        half_then_fail(f)
    assert target.read_bytes() == b"half"


# ------------------------------------------------------------------ staged writes


def test_a_staged_file_is_in_place_only_once_committed(tmp_path):
    """`files.Staged`: the content waits in a temporary file beside the target; the target
    is untouched until `commit`; `discard` (any number of times) leaves it as it was."""
    target = tmp_path / "o.png"
    target.write_bytes(b"old")
    staged = files.Staged(target, b"new")
    (part,) = [p for p in tmp_path.iterdir() if p.name != "o.png"]
    assert part.name.startswith(".o.png.") and part.name.endswith(".part") and part.read_bytes() == b"new"
    assert target.read_bytes() == b"old"
    staged.commit()
    assert target.read_bytes() == b"new" and sorted(p.name for p in tmp_path.iterdir()) == ["o.png"]
    staged = files.Staged(target, b"newer")
    staged.discard()
    staged.discard()
    assert target.read_bytes() == b"new" and sorted(p.name for p in tmp_path.iterdir()) == ["o.png"]


def test_a_staged_fifo_is_written_at_commit_only(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    staged = files.Staged(fifo, b"through")          # opening the FIFO now would block: no reader yet
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe"]
    t, got = read_fifo_in_thread(fifo)
    staged.commit()
    t.join(10)
    assert got == [b"through"] and kind(fifo) == "FIFO"


def test_an_interrupt_at_the_commit_keeps_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "o.png"
    target.write_bytes(b"old")
    staged = files.Staged(target, b"new")

    def interrupted(*args):
        raise KeyboardInterrupt
    monkeypatch.setattr(files.os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        staged.commit()
    assert target.read_bytes() == b"old" and sorted(p.name for p in tmp_path.iterdir()) == ["o.png"]


# ------------------------------------------------------------------ bounded reads


def test_read_regular_reads_a_file_and_follows_links_only_when_asked(tmp_path):
    f, link = tmp_path / "a.toml", tmp_path / "b.toml"
    f.write_bytes(b"beta = 1\n")
    link.symlink_to(f)
    assert files.read_regular(f, 100) == files.read_regular(link, 100) == b"beta = 1\n"
    assert files.read_regular(f, 100, follow=False) == b"beta = 1\n"
    with pytest.raises(files.RefusedPath, match="symbolic link"):
        files.read_regular(link, 100, follow=False)


@pytest.mark.parametrize("make, word", [
    (lambda d: "/dev/zero", "device"),
    (lambda d: os.mkfifo(d / "fifo") or d / "fifo", "FIFO"),
    (lambda d: d, "directory"),
])
def test_read_regular_refuses_other_kinds_without_blocking(tmp_path, make, word):
    path = make(tmp_path)

    def refused():
        with pytest.raises(files.RefusedPath, match=word):
            files.read_regular(path, 1 << 20)
        return True
    # A FIFO opened without O_NONBLOCK would block until a writer came: never.
    assert returns_without_blocking(refused)


def test_read_regular_refuses_a_large_file_without_reading_it(tmp_path, monkeypatch):
    big = tmp_path / "big"
    with open(big, "wb") as f:
        f.truncate(2 << 30)  # sparse: 2 GiB of holes
    reads = []
    real_read = os.read
    monkeypatch.setattr(files.os, "read", lambda fd, n: reads.append(n) or real_read(fd, n))
    with pytest.raises(files.RefusedPath, match="larger than 1,048,576 bytes"):
        files.read_regular(big, 1 << 20)
    assert reads == []
    # At the limit it is read, with a read bounded by the limit.
    small = tmp_path / "small"
    small.write_bytes(b"x" * 100)
    assert files.read_regular(small, 100) == b"x" * 100 and max(reads) <= 101
    with pytest.raises(files.RefusedPath):
        files.read_regular(small, 99)


def test_a_read_only_install_without_a_writable_home_renders(tmp_path):
    """numba refuses to compile where it can cache neither beside the package nor in the user's
    cache ("no locator available").  Files in place of both directories stand for a read-only
    install and a missing home (for root too, whom permissions do not stop): the kernel loads,
    with one line of notice, and the cache lands in the temporary directory."""
    import shutil
    import subprocess
    import sys
    copy = tmp_path / "install"
    shutil.copytree(Path(__file__).parents[1] / "renderer", copy / "renderer",
                    ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "renderer" / "__pycache__").write_text("not a directory")
    home = tmp_path / "home"
    home.mkdir()
    (home / ".cache").write_text("not a directory")
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_", "XDG_"))}
    env.update(PYTHONPATH=str(copy), HOME=str(home), TMPDIR=str(scratch))
    # Importing the kernel decorates every compiled function (where numba refused); one small
    # function is then compiled and cached (the whole frame's kernel would take 15 s more).
    done = subprocess.run([sys.executable, "-c", "import renderer.kernel; from renderer import pointwise; "
                           "import numpy as np; print('ok' if np.isfinite(pointwise.height('sine', 0.3, 0.4, 8, 4)).all() else 'bad')"],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0 and done.stdout == "ok\n", done.stderr[-2000:]
    assert done.stderr.count("\n") == 1 and "compiled functions are cached in" in done.stderr, done.stderr
    assert list((scratch / f"symrender-numba-{os.getuid()}").rglob("*.nbi"))
