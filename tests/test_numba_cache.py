"""numba's fallback cache directory: no other user can plant code in it.

numba unpickles the index files of its cache, so whoever can write the cache
directory runs code as the next user who renders.  Where numba can cache neither
beside the package nor in the user's home, `renderer` falls back to
``symrender-numba-<uid>`` in the temporary directory, and trusts it only when it
is a real directory of this user's with mode 0700 (`renderer._private_cache`).
"""

from __future__ import annotations

import os
import pickle
import pwd
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import renderer
from .jsnode import in_ci

ROOT = Path(__file__).parents[1]
#: One small compiled function, cached: the whole kernel would take many seconds more.
PROBE = ("from renderer import pointwise; import numpy as np; "
         "print('ok' if np.isfinite(pointwise.height('sine', 0.3, 0.4, 8, 4)).all() else 'bad')")


def _other_user():
    """(uid, gid) of a user other than this one, which only root can act as."""
    if os.getuid() != 0:
        if in_ci():
            pytest.fail("the planted-cache attack needs root (to act as a second user); CI runs as root")
        pytest.skip("needs root to act as a second user")
    entry = pwd.getpwnam("nobody")
    return entry.pw_uid, entry.pw_gid


class _Payload:
    """Unpickling it runs a shell command: what an attacker writes as an index file."""

    def __init__(self, command):
        self.command = command

    def __reduce__(self):
        return (os.system, (self.command,))


def _install(tmp_path):
    """A copy of renderer/ where numba can cache neither beside the package nor in the home
    (files in place of both directories stand for a read-only install and an unwritable home,
    for root too, whom permissions do not stop), and a shared temporary directory (mode 1777,
    as /tmp).  Returns (environment of the victim's process, the shared temporary directory)."""
    copy = tmp_path / "install"
    shutil.copytree(ROOT / "renderer", copy / "renderer", ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "renderer" / "__pycache__").write_text("not a directory")
    home = tmp_path / "home"
    home.mkdir()
    (home / ".cache").write_text("not a directory")
    shared = tmp_path / "shared-tmp"
    shared.mkdir()
    os.chmod(shared, 0o1777)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_", "XDG_"))}
    env.update(PYTHONPATH=str(copy), HOME=str(home), TMPDIR=str(shared))
    return env, shared


def _probe(env, cwd):
    return subprocess.run([sys.executable, "-c", PROBE], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=600)


def _as_user(uid, gid, cwd, work):
    """Run ``work()`` in a child process as ``uid``/``gid``, in the directory ``cwd`` (entered
    before the user changes: the directories above it need not be open to that user); fail if
    it fails."""
    pid = os.fork()
    if pid == 0:                                   # the child: drop to the other user, do the work, exit
        code = 1
        try:
            os.chdir(cwd)
            os.setgroups([])
            os.setgid(gid)
            os.setuid(uid)
            work()
            code = 0
        finally:
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, "the other user's process failed"


# JAX warns at any fork of a test worker that imported it (another test did); `_as_user`'s child runs no JAX.
@pytest.mark.filterwarnings(r"ignore:os\.fork\(\) was called:RuntimeWarning")
def test_a_cache_planted_by_another_user_is_refused_and_nothing_runs(tmp_path):
    """The attack: another user creates the victim's fallback directory first (world-writable),
    filled with the index files a real render writes, each replaced by a pickle that runs a
    command.  The victim renders; the directory is refused with one line, the render compiles
    in a private directory instead, and the command never runs."""
    uid, gid = _other_user()
    env, shared = _install(tmp_path)
    # Real cache files of the probe, as the attacker could make them with the same install.
    staged = tmp_path / "staged"
    done = _probe({**env, "NUMBA_CACHE_DIR": str(staged)}, tmp_path)
    assert done.returncode == 0 and done.stdout == "ok\n", done.stderr[-2000:]
    marker = shared / "ran-as-victim"
    payload = pickle.dumps(_Payload(f"id -u > {marker}"))
    planted = {p.relative_to(staged): payload if p.suffix == ".nbi" else p.read_bytes()
               for p in staged.rglob("*") if p.is_file()}
    assert any(p.suffix == ".nbi" for p in planted), sorted(planted)
    target = shared / f"symrender-numba-{os.getuid()}"

    def plant():                                   # as the other user, in the shared directory
        os.umask(0)
        mine = Path(target.name)
        mine.mkdir(mode=0o777)
        for rel, data in planted.items():
            (mine / rel).parent.mkdir(mode=0o777, parents=True, exist_ok=True)
            (mine / rel).write_bytes(data)
    _as_user(uid, gid, shared, plant)
    assert target.stat().st_uid == uid

    done = _probe(env, tmp_path)
    assert not marker.exists(), f"the planted index ran as the victim: {marker.read_text()!r}"
    assert done.returncode == 0 and done.stdout == "ok\n", done.stderr[-2000:]
    lines = done.stderr.splitlines()
    print(f"victim's stderr: {done.stderr!r}; planted by uid {uid}; {marker.name} exists: {marker.exists()}")
    assert len(lines) == 1 and f"refusing the cache directory {target}" in lines[0], done.stderr
    assert f"owned by uid {uid}" in lines[0] and "for this run only" in lines[0], lines[0]


def test_the_fallback_is_trusted_only_as_a_private_directory_of_this_user(tmp_path):
    """Each way the directory can be unsafe is refused, naming it; an absent one is created
    private (mode 0700, whatever the umask), and a private one is trusted."""
    fresh = tmp_path / "fresh"
    old = os.umask(0)
    try:
        assert renderer._private_cache(fresh) is None
    finally:
        os.umask(old)
    assert (fresh.stat().st_mode & 0o777) == 0o700
    assert renderer._private_cache(fresh) is None                  # exists, private: reused

    shared = tmp_path / "shared"
    shared.mkdir()
    for mode in (0o755, 0o777, 0o1777, 0o710, 0o701):
        os.chmod(shared, mode)
        assert renderer._private_cache(shared) == f"has mode {mode & 0o7777:04o}, not 0700"

    link = tmp_path / "link"
    link.symlink_to(fresh)                                          # a link, even to a private directory
    assert renderer._private_cache(link) == "is a symbolic link"
    plain = tmp_path / "file"
    plain.write_text("")
    assert renderer._private_cache(plain) == "is not a directory"
    assert "cannot be created" in renderer._private_cache(tmp_path / "missing-parent" / "cache")


def test_a_private_directory_of_another_user_is_refused(tmp_path):
    uid, gid = _other_user()
    theirs = tmp_path / "theirs"
    theirs.mkdir(mode=0o700)
    os.chown(theirs, uid, gid)
    assert renderer._private_cache(theirs) == f"is owned by uid {uid}, not by this user (uid {os.getuid()})"


def test_a_read_only_install_without_a_writable_home_compiles_in_the_fallback(tmp_path):
    """numba refuses to compile where it can cache neither beside the package nor in the user's
    cache ("no locator available"): the kernel loads (importing it decorates every compiled
    function), with one line of notice, and the cache lands in the temporary directory."""
    env, shared = _install(tmp_path)
    done = subprocess.run([sys.executable, "-c", f"import renderer.kernel; {PROBE}"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0 and done.stdout == "ok\n", done.stderr[-2000:]
    assert done.stderr.count("\n") == 1 and "compiled functions are cached in" in done.stderr, done.stderr
    assert list((shared / f"symrender-numba-{os.getuid()}").rglob("*.nbi"))


def cross_file_globals(module):
    """[(function, name)]: the globals each function ``module`` compiles with numba's on-disk cache reads
    from another file.  numba compiles a global in as a constant and invalidates a cached function only
    when its own file changes, so an edit to that other file would leave the cached code stale (a
    constant moved in renderer.kernel, say, and renderer.ledger's cached sums still reading the old one).
    Modules, builtins and the module's own top-level names are not counted."""
    import ast
    import builtins
    import dis
    import inspect
    import types

    from numba.core.caching import NullCache
    from numba.core.registry import CPUDispatcher
    tree = ast.parse(inspect.getsource(module))
    own = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))} | {
        t.id for n in tree.body if isinstance(n, (ast.Assign, ast.AnnAssign))
        for target in (n.targets if isinstance(n, ast.Assign) else [n.target]) for t in ast.walk(target)
        if isinstance(t, ast.Name)}
    out = []
    for name, f in vars(module).items():
        if not (isinstance(f, CPUDispatcher) and f.py_func.__module__ == module.__name__
                and not isinstance(f._cache, NullCache)):
            continue
        for ins in dis.get_instructions(f.py_func):
            g = ins.argval
            if ins.opname == "LOAD_GLOBAL" and g not in own and not hasattr(builtins, g) \
                    and not isinstance(f.py_func.__globals__.get(g), types.ModuleType):
                out.append((name, g))
    return sorted(set(out))


def test_no_cached_kernel_reads_a_constant_or_function_of_another_file(tmp_path, monkeypatch):
    """Every cached numba function of renderer/ and lab/ reads only its own file's globals, except the
    kernel's calls into generated.py, which kernel.py's FORMULAS_DIGEST ties to kernel.py's own text (an
    edited generated.py fails the import until the digest, and so kernel.py and its cache, change too).
    A planted module whose cached function compares with another file's constant is named."""
    import ast
    import importlib
    import pkgutil

    import lab
    kernel = ROOT / "renderer" / "kernel.py"
    guarded = {("renderer.kernel", a.asname or a.name) for n in ast.walk(ast.parse(kernel.read_text(encoding="utf-8")))
               if isinstance(n, ast.ImportFrom) and n.module == "generated" for a in n.names}
    assert len(guarded) >= 5
    found = [(m.name, f, g) for package in (renderer, lab) for m in pkgutil.iter_modules(package.__path__, package.__name__ + ".")
             for f, g in cross_file_globals(importlib.import_module(m.name)) if (m.name, g) not in guarded]
    assert found == []
    (tmp_path / "planted_sums.py").write_text(
        "from numba import njit\nfrom renderer.render import SPHERE_A\n\n\n@njit(cache=True)\ndef on_a(code):\n"
        "    return code == SPHERE_A\n\n\n@njit\ndef uncached(code):\n    return code == SPHERE_A\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert cross_file_globals(importlib.import_module("planted_sums")) == [("on_a", "SPHERE_A")]
