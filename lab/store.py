"""The build's measurements: each computed once, then read by every page that shows it.

The book's pages run in separate kernels, some at the same time.  A quantity two
pages show (a theorem's verdict, say) is computed by the first page that asks
for it and written to the store; later pages read the same value instead of
computing their own, so the pages cannot disagree and the build pays once.

The store is a directory named by the environment variable ``SYMRENDER_STORE``
(the book's build sets it to ``book/_build/.measurements``, see
book/_ext/measurement_store.py); without it, values are kept for the life of
the process only.  Each measurement is one JSON file, ``<name>.json``, holding
its parameters, its value and the digest of what it was computed from: every
file of renderer/ and proofs/ and the versions of the numerical libraries.  A
stored value whose parameters or digest differ is computed again, so an edit
to the code never shows a stale number.  While a measurement is computed its
file is locked (``fcntl.flock`` on ``.<name>.json.lock``): a page that needs it
meanwhile waits and reads the value instead of computing it a second time.

A record is served only when it is well formed (`_served`): a JSON object of exactly
the fields written, each of its type, whose ``sha256`` is the checksum of the others
(`_checksum`).  Anything else (not JSON, another shape, a value edited by hand
while the digest still matches, a record larger than `MAX_RECORD_BYTES`, not a
regular file: a link, a FIFO) is computed again and replaced, never served and never
a traceback.  The checksum guards against accidents only (a truncated write, an edit
by hand): anyone who can write the directory can write a record with a matching
checksum.  So the store refuses a directory that is not this user's or that other
users can write (`UntrustedStore`), as the renderer's compile cache does, and never
follows a link or blocks on a FIFO where its lock or its record should be.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import re
import stat
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

from renderer import files

__all__ = ["ENV", "UntrustedStore", "measured", "source_digest"]

#: Environment variable naming the store's directory.
ENV = "SYMRENDER_STORE"
#: The packages whose files a measurement may depend on (the libraries whose versions it may: `libraries`).
PACKAGES = ("renderer", "proofs", "lab", "chapter")
_NAME = re.compile(r"[a-z0-9][a-z0-9_.-]{0,99}")
#: Largest record read (bytes); the largest the book writes (the theorem ledger) is some tens of KiB.
MAX_RECORD_BYTES = 16 << 20
#: The fields of a record and the type of each.
FIELDS = {"name": str, "params": dict, "digest": str, "value": object, "sha256": str}
_MEMORY = {}
_DIGEST = []


class UntrustedStore(ValueError):
    """The store's directory (``SYMRENDER_STORE``) could hold another user's records: it is not
    owned by this user, or others can write it."""


def _trusted(directory):
    """``directory`` as a Path, created (mode 0700) when absent; `UntrustedStore` naming it and why
    when it is not a directory this user owns and only this user can write."""
    path = Path(directory)
    try:
        path.mkdir(mode=0o700, parents=True, exist_ok=True)
        st = os.stat(path)
    except OSError as exc:
        raise UntrustedStore(f"{ENV}={directory}: cannot be used as the measurement store ({exc.strerror})") from None
    # (A path that is not a directory failed mkdir above.)
    why = (f"is owned by uid {st.st_uid}, not by this user (uid {os.getuid()})" if st.st_uid != os.getuid() else
           f"can be written by other users (mode {stat.S_IMODE(st.st_mode):04o})"
           if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH) else None)
    if why:
        raise UntrustedStore(f"{ENV}={directory} {why}: a record planted there, its checksum recomputed, would be "
                             "served as a measurement; use a directory only you can write (chmod go-w)")
    return path


def _roots():
    """{package: its directory} of `PACKAGES`, where Python imports them from."""
    from importlib.util import find_spec
    return {package: Path(find_spec(package).origin).parent for package in PACKAGES}


def libraries():
    """The installed distributions the project's code runs on, sorted: the requirements of the
    distribution that installs `renderer` (its extras left out) and theirs, transitively (numpy,
    sympy, matplotlib, jax and jaxlib, drjit, numba and llvmlite, ...).  Derived from the installed
    metadata, so a dependency added to pyproject.toml is in the digest without a second list."""
    def name(requirement):
        return re.match(r"[A-Za-z0-9][A-Za-z0-9._-]*", requirement).group().lower().replace("_", "-")
    todo = list(metadata.packages_distributions().get("renderer", ()))
    seen = set()
    while todo:
        try:
            requirements = metadata.requires(todo.pop()) or ()
        except metadata.PackageNotFoundError:
            continue
        for r in requirements:
            dist = name(r)
            if "extra ==" not in r and dist not in seen:
                try:
                    metadata.version(dist)
                except metadata.PackageNotFoundError:
                    continue
                seen.add(dist)
                todo.append(dist)
    return sorted(seen)


def source_digest():
    """SHA-256 (hex str) of every file of the project's packages (`PACKAGES`, found where
    Python imports them from: a checkout or an installed wheel; paths and bytes,
    __pycache__ left out) and the versions of `libraries`; computed once per process.
    The project's one source digest: the store, the book's page cache and the figure
    manifests all use it."""
    if not _DIGEST:
        h = hashlib.sha256()
        for package, root in _roots().items():
            for path in sorted(root.rglob("*")):
                if path.is_file() and "__pycache__" not in path.parts:
                    h.update(f"{package}/{path.relative_to(root)}".encode() + b"\0" + path.read_bytes() + b"\0")
        for name in libraries():
            h.update(f"{name}=={metadata.version(name)}\0".encode())
        _DIGEST.append(h.hexdigest())
    return _DIGEST[0]


def measured(name, compute, **params):
    """The value of the measurement ``name``: ``compute(**params)`` once per build.

    Parameters
    ----------
    name : str
        Lower-case letters, digits, ``_ . -``; at most 100 characters (it names a file).
    compute : callable
        Called with ``params`` when the store has no value for them; must return
        a value JSON can hold (numbers, strings, lists, dicts with str keys):
        it is returned as it reads back from JSON (tuples become lists).
    **params
        JSON-able parameters (scene, resolution, ...), stored beside the value.

    Raises
    ------
    ValueError
        ``name`` is not of that form.
    UntrustedStore
        The store's directory is not this user's own (`_trusted`).
    TypeError
        The value or the parameters are not JSON-able (nothing is written).
    """
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ValueError(f"name must be 1-100 characters of a-z 0-9 _ . - starting with a letter or digit, "
                         f"got {name!r}")
    key = json.dumps(params, sort_keys=True)
    if (name, key) in _MEMORY:
        return _MEMORY[name, key]
    directory = os.environ.get(ENV)
    path = _trusted(directory) / f"{name}.json" if directory else None
    with _locked(path):
        record = _served(_read(path), name, json.loads(key))
        if record is not None:
            value = record["value"]
        else:
            value = json.loads(json.dumps(compute(**params)))
            if path is not None:
                record = {"name": name, "params": json.loads(key), "digest": source_digest(), "value": value}
                _write(path, {**record, "sha256": _checksum(record)})
    _MEMORY[name, key] = value
    return value


@contextmanager
def _locked(path):
    """Hold an exclusive lock on ``.<name>.json.lock`` beside ``path`` (no lock for the in-memory
    store): pages executed at once that need the same measurement wait for the first to compute
    it.  The lock file is opened without following a link and without blocking on a FIFO; where
    it is not a regular file the measurement is computed unlocked (at worst twice: each record is
    written whole), with a warning naming it."""
    if path is None:
        yield
        return
    lock_path = path.with_name(f".{path.name}.lock")
    try:
        fd = os.open(lock_path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, 0o600)
    except OSError as exc:
        fd, why = None, exc.strerror
    else:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            os.close(fd)
            fd, why = None, "not a regular file"
    if fd is None:
        import warnings
        warnings.warn(f"{lock_path} cannot be the measurement's lock ({why}); computing {path.name} without it",
                      stacklevel=4)
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)                                  # releases the lock


def _checksum(record):
    """SHA-256 (hex) of a record's fields other than ``sha256``, in one canonical JSON form."""
    fields = {k: v for k, v in record.items() if k != "sha256"}
    return hashlib.sha256(json.dumps(fields, sort_keys=True, separators=(",", ":")).encode("utf-8")).hexdigest()


def _served(record, name, params):
    """``record`` if it may be served for ``name`` and ``params`` under today's source digest: of
    the shape `FIELDS` says, its checksum matching; else None (it is computed again)."""
    if not (isinstance(record, dict) and record.keys() == FIELDS.keys()
            and all(isinstance(record[k], t) for k, t in FIELDS.items())):
        return None
    if record["sha256"] != _checksum(record):
        return None
    if (record["name"], record["params"], record["digest"]) != (name, params, source_digest()):
        return None
    return record


def _read(path):
    """The parsed JSON of ``path``, or None when there is none or it cannot be read or parsed:
    only a regular file of at most `MAX_RECORD_BYTES` is read (not through a link, and a FIFO
    does not block the open)."""
    if path is None:
        return None
    try:
        with open(os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK), "rb") as f:
            if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                return None
            data = f.read(MAX_RECORD_BYTES + 1)
        return json.loads(data.decode("utf-8")) if len(data) <= MAX_RECORD_BYTES else None
    except (OSError, ValueError, RecursionError):      # absent, a link, not JSON
        return None


def _write(path, record):
    """Write ``record`` to ``path`` atomically (`renderer.files.write_bytes`); the directory
    exists (`_trusted` made it).  Whatever else is at ``path`` (a symbolic link, a FIFO, a
    device node) is removed first, never written through; where that cannot be done (a
    directory) the value is kept for this process only, with a warning naming the path."""
    if os.path.lexists(path) and (os.path.islink(path) or not os.path.isfile(path)):
        try:
            os.unlink(path)                        # the link itself, not its target
        except OSError as exc:
            import warnings
            warnings.warn(f"{path} is not a record and cannot be replaced ({exc.strerror}); the measurement "
                          "is kept for this process only", stacklevel=3)   # the line calling measured()
            return
    files.write_bytes(path, json.dumps(record).encode("utf-8"))   # key order kept: reads back as written
