"""Renderer of the Chapter-9 scene (two spheres, two point lights, a checker
floor, bump-mapped sphere A) with a numeric (central difference) and a
symbolic (exact gradient) pipeline: one per-pixel kernel compiled with numba
(`renderer.kernel`), its formulas generated from the sympy objects of
`renderer.formulas`.

Public API::

    from renderer import Scene, render
    frame = render(Scene(), 256, 256, gradient="exact")
"""

import functools
import importlib
import os
import stat
import sys
import tempfile
import types
from pathlib import Path

#: Each public name and the submodule that defines it, loaded on first use (PEP 562):
#: ``import renderer`` alone loads neither numpy nor the compiled kernel, so the command
#: line starts at once and ``python -m renderer.codegen`` runs even when the kernel's
#: digest guard would refuse the generated file it is about to rewrite.
_WHERE = {
    "Scene": "scene", "DRAFT_SCENE": "scene", "DRAFT_NAMES": "scene", "PointLight": "scene", "BUMPS": "scene",
    "MODELS": "scene",
    "render": "render", "gbuffer": "render", "Frame": "render", "GBuffer": "render",
    "GRADIENTS": "render", "CHAMBER_NAMES": "render",
    "Ledger": "ledger", "compare": "ledger", "to_srgb": "ledger",
    "Sweep": "sweep", "sweep": "sweep",
}
__all__ = list(_WHERE)


def __getattr__(name):
    if name not in _WHERE:
        raise AttributeError(f"module 'renderer' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))


class _Package(types.ModuleType):
    """``render`` and ``sweep`` name both a function of the API and the submodule that
    defines it; the import system binds a loaded submodule to its package's attribute,
    which would hide the function, so the package keeps the function (the submodules
    stay in ``sys.modules``)."""

    def __setattr__(self, name, value):
        if name in ("render", "sweep") and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def _writable(path):
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
        return True
    except OSError:
        return False


def _private_cache(path):
    """``path`` if it is a directory this user may trust with numba's cache, else why not.

    numba unpickles its index files, so whoever can write the cache directory runs code as
    the user who renders.  A directory in the shared temporary directory is trusted only
    when it is no symbolic link, is owned by this user and has mode 0700 (no one else can
    have put or replaced a file in it); it is created so when absent.  Returns None when
    trusted, else a phrase saying what is wrong with it."""
    try:
        os.mkdir(path, 0o700)
    except FileExistsError:
        pass
    except OSError as exc:
        return f"cannot be created ({exc.strerror})"
    try:
        st = os.lstat(path)
    except OSError as exc:
        return f"cannot be examined ({exc.strerror})"
    if stat.S_ISLNK(st.st_mode):
        return "is a symbolic link"
    if not stat.S_ISDIR(st.st_mode):
        return "is not a directory"
    if st.st_uid != os.getuid():
        return f"is owned by uid {st.st_uid}, not by this user (uid {os.getuid()})"
    if stat.S_IMODE(st.st_mode) != 0o700:
        return f"has mode {stat.S_IMODE(st.st_mode):04o}, not 0700"
    return None


@functools.cache
def _numba_cache():
    """Where numba can cache the compiled kernel, decided once per process when the kernel is
    first loaded (`renderer.kernel` calls it before its functions are compiled): importing
    renderer writes nothing.  numba caches beside the package
    (``renderer/__pycache__``) or in the user's cache directory, and refuses to compile
    at all ("no locator available") where it can write neither: a read-only or
    system-wide install run by a user without a writable home.  There the cache goes
    to ``symrender-numba-<uid>`` in the temporary directory, created private to the user
    (mode 0700), and one line on stderr says so.  When that name exists and is not
    private to the user (`_private_cache`: another user could have planted index files,
    which numba unpickles), it is refused, with one line naming it, and this process
    caches in a new private directory (``mkdtemp``) removed at exit.  ``NUMBA_CACHE_DIR``,
    when set, is left to numba."""
    if os.environ.get("NUMBA_CACHE_DIR") or _writable(Path(__file__).with_name("__pycache__")):
        return
    from numba.misc.appdirs import AppDirs
    user = AppDirs(appname="numba", appauthor=False).user_cache_dir
    if _writable(user):
        return
    fallback = os.path.join(tempfile.gettempdir(), f"symrender-numba-{os.getuid()}")
    refused = _private_cache(fallback)
    if refused is None:
        note = f"compiled functions are cached in {fallback}"
    else:
        import atexit
        import shutil
        refused_path, fallback = fallback, tempfile.mkdtemp(prefix="symrender-numba-")
        atexit.register(shutil.rmtree, fallback, ignore_errors=True)
        note = (f"refusing the cache directory {refused_path}, which {refused}; compiled functions "
                f"are cached in {fallback} for this run only")
    os.environ["NUMBA_CACHE_DIR"] = fallback
    import numba
    numba.config.CACHE_DIR = fallback
    if sys.stderr is not None:           # started with stderr closed: the note is lost, not sent elsewhere
        print(f"symrender: numba cannot cache beside the package nor in {user}: {note}", file=sys.stderr)
