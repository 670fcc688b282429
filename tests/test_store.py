"""`lab.store`: a measurement is computed once per build and read back by later pages.

The pages of the book run in separate processes; here a second process is
played by clearing the store's in-process memory (`_MEMORY`).  Each check is
shown failing on a wrong variant of the store.
"""

from __future__ import annotations

import json
from contextlib import contextmanager

import pytest

from lab import store


@pytest.fixture
def fresh(tmp_path, monkeypatch):
    """An empty store directory and an empty process memory; returns a counter of computations."""
    monkeypatch.setenv(store.ENV, str(tmp_path))
    monkeypatch.setattr(store, "_MEMORY", {})
    calls = []

    def compute(**params):
        calls.append(params)
        return {"value": 0.1 + 0.2, "params": params}
    return tmp_path, calls, compute


def _new_process(monkeypatch):
    monkeypatch.setattr(store, "_MEMORY", {})


def test_a_second_process_reads_the_first_ones_value(fresh, monkeypatch):
    directory, calls, compute = fresh
    first = store.measured("u-curve", compute, size=256)
    _new_process(monkeypatch)
    second = store.measured("u-curve", compute, size=256)
    assert first == second == {"value": 0.1 + 0.2, "params": {"size": 256}}   # floats round-trip exactly
    assert len(calls) == 1
    record = json.loads((directory / "u-curve.json").read_text())
    assert record["params"] == {"size": 256} and record["digest"] == store.source_digest()


def test_other_parameters_or_another_digest_compute_again(fresh, monkeypatch):
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256)
    _new_process(monkeypatch)
    store.measured("u-curve", compute, size=128)
    assert len(calls) == 2
    _new_process(monkeypatch)
    monkeypatch.setattr(store, "_DIGEST", ["a different source tree"])
    store.measured("u-curve", compute, size=128)
    assert len(calls) == 3


def test_the_digest_reads_every_package_whose_code_stores_a_measurement():
    """Each module of the project that stores a measurement (calls ``measured``: lab's, and the book's
    helpers in book/chapter, whose theorem blocks the store holds) lies in a package the digest reads, so an
    edit to the code that computes a stored value is never answered with the value it computed before."""
    import re
    from pathlib import Path
    repo = Path(__file__).resolve().parents[1]
    roots = [root.resolve() for root in store._roots().values()]
    callers = [path for top in ("renderer", "proofs", "lab", "book") for path in (repo / top).rglob("*.py")
               if "_build" not in path.parts and re.search(r"\bmeasured\(", path.read_text(encoding="utf-8"))]
    assert any(path.parent.name == "chapter" for path in callers)       # the check sees the book's helpers
    assert [str(p.relative_to(repo)) for p in callers if not any(p.resolve().is_relative_to(r) for r in roots)] == []


def test_the_digest_follows_the_source_files(tmp_path, monkeypatch):
    """A changed byte in any file of any of the project's packages changes the digest."""
    for package in store.PACKAGES:
        (tmp_path / package).mkdir()
        (tmp_path / package / "a.py").write_text("x = 1\n")
    monkeypatch.setattr(store, "_roots", lambda: {p: tmp_path / p for p in store.PACKAGES})
    monkeypatch.setattr(store, "_DIGEST", [])
    before = store.source_digest()
    for package in store.PACKAGES:                      # each package alone, then put back
        (tmp_path / package / "a.py").write_text("x = 2\n")
        monkeypatch.setattr(store, "_DIGEST", [])
        assert store.source_digest() != before, package
        (tmp_path / package / "a.py").write_text("x = 1\n")
    monkeypatch.setattr(store, "_DIGEST", [])
    assert store.source_digest() == before
    (tmp_path / "renderer" / "a.py").write_text("x = 2\n")
    monkeypatch.setattr(store, "_DIGEST", [])
    changed = store.source_digest()
    # Bytecode and numba's cache (in __pycache__) and directories are not sources: the digest stays.
    (tmp_path / "renderer" / "__pycache__").mkdir()
    (tmp_path / "renderer" / "__pycache__" / "a.cpython-311.pyc").write_bytes(b"\0compiled")
    (tmp_path / "proofs" / "sub").mkdir()
    monkeypatch.setattr(store, "_DIGEST", [])
    assert store.source_digest() == changed
    # A file's name is part of what a measurement depends on: a renamed module changes the digest.
    (tmp_path / "renderer" / "a.py").rename(tmp_path / "renderer" / "b.py")
    monkeypatch.setattr(store, "_DIGEST", [])
    assert store.source_digest() != changed


@pytest.mark.parametrize("kind", ["module", "javascript", "data"])
def test_every_kind_of_file_a_page_reads_through_the_packages_changes_the_digest(tmp_path, monkeypatch, kind):
    """A page reads the packages' modules, the simulator's JavaScript (renderer/js, printed into §4)
    and any data file beside them: a changed byte of each kind changes the digest (the wrong
    variant, a digest of .py files alone, misses the last two)."""
    name = {"module": "a.py", "javascript": "js/render.js", "data": "tables/points.json"}[kind]
    for package in store.PACKAGES:
        (tmp_path / package / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / package / name).write_text("1")
    monkeypatch.setattr(store, "_roots", lambda: {p: tmp_path / p for p in store.PACKAGES})
    monkeypatch.setattr(store, "_DIGEST", [])
    before = store.source_digest()
    (tmp_path / "lab" / name).write_text("2")
    monkeypatch.setattr(store, "_DIGEST", [])
    assert store.source_digest() != before


def test_the_digest_follows_every_library_the_project_runs_on(monkeypatch):
    """The libraries are the installed requirements of the project, transitively: the ones the pages
    import (matplotlib draws every figure, jax and jaxlib compute §5's AD, scipy its crease roots, drjit
    the fast backend, pillow the PNGs) are among them, and a new version of any one changes the digest
    (before: five libraries were typed, and a matplotlib or jax upgrade reused the old pages)."""
    from importlib import metadata
    libraries = store.libraries()
    assert {"numpy", "sympy", "mpmath", "numba", "llvmlite", "matplotlib", "jax", "jaxlib", "scipy", "drjit",
            "pillow"} <= set(libraries)
    # The files' part is test_the_digest_follows_the_source_files', the walk the next test's.
    monkeypatch.setattr(store, "_roots", dict)
    monkeypatch.setattr(store, "libraries", lambda: libraries)
    monkeypatch.setattr(store, "_DIGEST", [])
    before = store.source_digest()
    real = metadata.version
    for library in libraries:
        monkeypatch.setattr(metadata, "version", lambda d, lib=library: "0.0.0-other" if d == lib else real(d))
        monkeypatch.setattr(store, "_DIGEST", [])
        assert store.source_digest() != before, library
    monkeypatch.setattr(metadata, "version", real)


def test_the_library_walk_follows_installed_requirements_past_absent_ones(monkeypatch):
    """`store.libraries` on a made-up installation: names normalised (``Typing_Extensions`` is the
    distribution typing-extensions), requirements of an extra left out, a requirement not installed
    (its marker false here) skipped without ending the walk, a distribution that vanished skipped; and
    a checkout that is not installed (no distribution holds `renderer`) runs on no known library."""
    from importlib import metadata
    from types import SimpleNamespace
    requires = {"sym-render": ["Typing_Extensions>=4", "absent-lib; python_version < '3'", "NumPy>=1.26",
                               'pytest>=8; extra == "test"'],
                "numpy": ["absent-two", "mpmath"], "typing-extensions": None, "mpmath": [], "pytest": []}

    def installed(table):
        def look(dist):
            if dist not in requires:
                raise metadata.PackageNotFoundError(dist)
            return table[dist]
        return look
    fake = SimpleNamespace(PackageNotFoundError=metadata.PackageNotFoundError,
                           packages_distributions=lambda: {"renderer": ["sym-render", "gone-dist"]},
                           requires=installed(requires), version=installed(dict.fromkeys(requires, "1.0")))
    monkeypatch.setattr(store, "metadata", fake)
    assert store.libraries() == ["mpmath", "numpy", "typing-extensions"]
    fake.packages_distributions = lambda: {"lab": ["sym-render"]}
    assert store.libraries() == []


def test_the_same_process_asks_twice_and_computes_once(fresh):
    directory, calls, compute = fresh
    first = store.measured("u-curve", compute, size=256)
    assert store.measured("u-curve", compute, size=256) == first and len(calls) == 1


def test_parameters_name_the_same_record_in_any_order(fresh, monkeypatch):
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256, field="sine")
    _new_process(monkeypatch)
    store.measured("u-curve", compute, field="sine", size=256)
    assert len(calls) == 1


def test_the_check_rejects_a_store_that_ignores_the_digest(fresh, monkeypatch):
    """A wrong store that trusts any record of the right name and parameters
    serves the old value after an edit: the count the test above asserts
    (computed again) would not be reached."""
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256)
    _new_process(monkeypatch)
    monkeypatch.setattr(store, "_DIGEST", ["edited"])
    monkeypatch.setattr(store, "_read", lambda path: _sealed({**json.loads(path.read_text()), "digest": "edited"}))
    store.measured("u-curve", compute, size=256)
    assert len(calls) == 1


def _sealed(record):
    """``record`` with a checksum matching its (edited) fields, as the store writes one."""
    return {**record, "sha256": store._checksum(record)}


@contextmanager
def _unblocked(seconds=20):
    """Fails the test, instead of hanging it, if the block takes ``seconds`` (a read of a FIFO blocks)."""
    import signal
    old = signal.signal(signal.SIGALRM, lambda *a: pytest.fail("the store blocked (on a FIFO?)"))
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _stored(directory, name="u-curve"):
    return json.loads((directory / f"{name}.json").read_text())


_GOOD = object()        # stands for the record as written, in the table below


@pytest.mark.parametrize("edit", [
    lambda r: [r],                                       # JSON of another shape: a list, a string, a number
    lambda r: "record",
    lambda r: 3.0,
    lambda r: {k: v for k, v in r.items() if k != "value"},          # a field missing
    lambda r: {k: v for k, v in r.items() if k != "sha256"},
    lambda r: {**r, "extra": 1},                                     # a field too many
    lambda r: {**r, "params": [["size", 256]]},                      # a field of the wrong type
    lambda r: {**r, "digest": None},
    lambda r: {**r, "sha256": 7},
    lambda r: {**r, "value": {"value": 0.4, "params": {"size": 256}}},   # the value edited, digest intact
    lambda r: {**r, "sha256": "0" * 64},                             # the checksum edited
    lambda r: _sealed({**r, "name": "other"}),                       # another measurement's record, sealed
    lambda r: _sealed({**r, "params": {"size": 128}}),
], ids=["list", "str", "number", "no-value", "no-sha256", "extra-field", "params-list", "digest-null",
        "sha256-int", "value-edited", "sha256-edited", "other-name", "other-params"])
def test_a_record_of_the_wrong_shape_or_an_edited_one_is_computed_again(fresh, monkeypatch, edit):
    """The record on disk is replaced by a malformed or tampered one: the next process computes the
    value again and rewrites the record (never a traceback, never the stored value)."""
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256)
    (directory / "u-curve.json").write_text(json.dumps(edit(_stored(directory))))
    _new_process(monkeypatch)
    assert store.measured("u-curve", compute, size=256) == {"value": 0.1 + 0.2, "params": {"size": 256}}
    assert len(calls) == 2
    assert _stored(directory)["sha256"] == store._checksum(_stored(directory))


def test_the_checksum_rejects_an_edited_value_that_the_digest_alone_would_serve(fresh, monkeypatch):
    """Wrong variant: a store that checks the digest and parameters but not the checksum serves
    a value edited by hand (the test above would see one computation, not two)."""
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256)
    (directory / "u-curve.json").write_text(json.dumps({**_stored(directory), "value": "edited"}))
    _new_process(monkeypatch)
    monkeypatch.setattr(store, "_checksum", lambda record: record.get("sha256"))
    assert store.measured("u-curve", compute, size=256) == "edited" and len(calls) == 1


def test_a_record_of_exactly_the_largest_size_is_served(fresh, monkeypatch):
    directory, calls, compute = fresh
    first = store.measured("u-curve", compute, size=256)
    monkeypatch.setattr(store, "MAX_RECORD_BYTES", (directory / "u-curve.json").stat().st_size)
    _new_process(monkeypatch)
    assert store.measured("u-curve", compute, size=256) == first and len(calls) == 1


@pytest.mark.parametrize("kind", ["link", "fifo", "too-big"])
def test_a_record_that_is_not_a_small_regular_file_is_never_served_and_is_replaced(fresh, monkeypatch, kind):
    """A symbolic link (to a valid record, even), a FIFO (which would block a plain read) or a
    file over `MAX_RECORD_BYTES` is not read: the value is computed again and a record the store
    writes takes its place.  A link is replaced itself, its target left as it was; nothing is
    written through it or into the FIFO."""
    import os
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256)
    path, elsewhere = directory / "u-curve.json", directory / "elsewhere.json"
    if kind == "link":
        path.rename(elsewhere)
        path.symlink_to(elsewhere)
    elif kind == "fifo":
        path.unlink()
        os.mkfifo(path)
    else:
        monkeypatch.setattr(store, "MAX_RECORD_BYTES", path.stat().st_size - 1)
    before = elsewhere.read_bytes() if kind == "link" else None
    _new_process(monkeypatch)
    with _unblocked():
        store.measured("u-curve", compute, size=256)
    assert len(calls) == 2 and path.is_file() and not path.is_symlink()
    assert _stored(directory)["sha256"] == store._checksum(_stored(directory))
    if kind == "link":
        assert elsewhere.read_bytes() == before


def test_a_directory_in_place_of_a_record_is_kept_and_the_value_is_still_given(fresh, monkeypatch):
    directory, calls, compute = fresh
    (directory / "u-curve.json").mkdir()
    with pytest.warns(UserWarning, match=r"u-curve.json is not a record and cannot be replaced \(.*\); the "
                      r"measurement is kept for this process only$"):
        assert store.measured("u-curve", compute, size=256)["value"] == 0.1 + 0.2
    assert (directory / "u-curve.json").is_dir() and len(calls) == 1
    assert sorted(p.name for p in directory.iterdir() if not p.name.endswith(".lock")) == ["u-curve.json"]


@pytest.mark.parametrize("mode", [0o777, 0o770, 0o722])
def test_a_store_others_can_write_is_refused_and_its_planted_record_never_served(fresh, monkeypatch, mode):
    """The checksum is not an authentication: a record planted in a directory others can write, its
    sha256 recomputed, would be served.  Such a directory is refused, naming it and its mode; the
    same directory private to the user serves the record (the wrong variant: the check off)."""
    import os
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256)
    planted = {**_stored(directory), "value": 999}
    (directory / "u-curve.json").write_text(json.dumps({**planted, "sha256": store._checksum(planted)}))
    _new_process(monkeypatch)
    os.chmod(directory, mode)
    with pytest.raises(store.UntrustedStore, match=rf"^{store.ENV}={directory} can be written by other users "
                                                   rf"\(mode {mode:04o}\): .*chmod go-w\)$"):
        store.measured("u-curve", compute, size=256)
    monkeypatch.setattr(store, "_trusted", lambda d: directory)             # the check removed
    assert store.measured("u-curve", compute, size=256) == 999


def test_a_store_of_another_user_or_not_a_directory_is_refused(fresh, monkeypatch, tmp_path):
    import os
    directory, calls, compute = fresh
    uid = os.getuid()
    monkeypatch.setattr(store.os, "getuid", lambda: uid + 1)
    with pytest.raises(store.UntrustedStore, match=rf"is owned by uid {uid}, not by this user \(uid {uid + 1}\)"):
        store.measured("u-curve", compute)
    monkeypatch.setattr(store.os, "getuid", lambda: uid)
    monkeypatch.setenv(store.ENV, str(directory / "file"))
    (directory / "file").write_text("")
    with pytest.raises(store.UntrustedStore, match=r"/file: cannot be used as the measurement store"):
        store.measured("u-curve", compute)
    assert calls == []


def test_a_new_store_is_created_private(tmp_path, monkeypatch):
    import os
    monkeypatch.setattr(store, "_MEMORY", {})
    monkeypatch.setenv(store.ENV, str(tmp_path / "new" / "store"))
    old = os.umask(0o002)                                      # a group-writable umask
    try:
        store.measured("x", lambda: 1)
    finally:
        os.umask(old)
    assert (tmp_path / "new" / "store").stat().st_mode & 0o777 == 0o700


@pytest.mark.parametrize("plant", ["record", "lock"])
def test_the_store_warns_at_the_line_that_asked_for_the_measurement(fresh, plant):
    """A directory in place of the record, or of its lock: the warning points at the line that called
    `store.measured`, not into the store.  (mutmut's trampolines add a frame: its runs leave this out.)"""
    directory, calls, compute = fresh
    (directory / ("u-curve.json" if plant == "record" else ".u-curve.json.lock")).mkdir()

    def ask():
        return store.measured("u-curve", compute, size=256)
    with pytest.warns(UserWarning) as caught:
        assert ask()["value"] == 0.1 + 0.2
    assert [(w.filename, w.lineno) for w in caught] == [(__file__, ask.__code__.co_firstlineno + 1)]


@pytest.mark.parametrize("kind", ["fifo", "link", "directory"])
def test_a_lock_that_is_not_a_regular_file_neither_blocks_nor_is_followed(fresh, kind):
    """A FIFO in place of a measurement's lock would block a plain open, a link would make the store
    create its target: each is opened without following and without blocking, and the value is
    computed unlocked, with a warning naming the lock; the link's target is never created."""
    import os
    import signal
    directory, calls, compute = fresh
    lock, target = directory / ".u-curve.json.lock", directory.parent / f"victim-{kind}"
    {"fifo": lambda: os.mkfifo(lock), "link": lambda: lock.symlink_to(target), "directory": lock.mkdir}[kind]()
    signal.signal(signal.SIGALRM, lambda *a: pytest.fail("the store blocked on its lock"))
    signal.alarm(20)
    try:
        with pytest.warns(UserWarning, match=r"\.u-curve\.json\.lock cannot be the measurement's lock"):
            assert store.measured("u-curve", compute, size=256)["value"] == 0.1 + 0.2
    finally:
        signal.alarm(0)
    assert len(calls) == 1 and not target.exists() and _stored(directory)["value"]["value"] == 0.1 + 0.2


def test_an_unreadable_record_is_computed_again(fresh, monkeypatch):
    directory, calls, compute = fresh
    (directory / "u-curve.json").write_text("{not json")
    assert store.measured("u-curve", compute)["value"] == 0.1 + 0.2
    assert len(calls) == 1 and json.loads((directory / "u-curve.json").read_text())["value"]


@pytest.mark.parametrize("name", ["", "Upper", "../escape", "a/b", "x" * 101, 7])
def test_bad_names_are_refused(name, fresh):
    _, calls, compute = fresh
    with pytest.raises(ValueError, match="name must be"):
        store.measured(name, compute)
    assert calls == []


def test_a_value_json_cannot_hold_writes_nothing(fresh):
    directory, _, _ = fresh
    with pytest.raises(TypeError):
        store.measured("bad", lambda: {1, 2})
    with pytest.raises(TypeError):
        store.measured("bad", lambda: 1, scene=object())
    assert [p.name for p in directory.iterdir() if not p.name.endswith(".lock")] == []   # no record, no part file


_RACER = """
import sys, time
from pathlib import Path
from lab import store
if sys.argv[2] == "unlocked":                       # the wrong variant: no lock around the computation
    import contextlib
    store._locked = lambda path: (path.parent.mkdir(parents=True, exist_ok=True), contextlib.nullcontext())[1]
def compute():
    with open(sys.argv[1], "a") as log:
        log.write("computed\\n")
    time.sleep(1.0)
    return 42
print(store.measured("shared", compute))
"""


@pytest.mark.parametrize("variant", ["locked", "unlocked"])
def test_pages_running_at_once_compute_a_measurement_once(tmp_path, variant):
    """Two processes started together ask for the same measurement: the second waits
    for the first's value (the build runs pages side by side, book/_ext/execute_pages.py)."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    log = tmp_path / "log"
    # The processes import the store this test imported (a scratch copy under test, not the installed one).
    here = str(Path(store.__file__).parents[1])
    env = {**os.environ, store.ENV: str(tmp_path / "store"),
           "PYTHONPATH": os.pathsep.join(filter(None, [here, os.environ.get("PYTHONPATH")]))}
    racers = [subprocess.Popen([sys.executable, "-c", _RACER, str(log), variant], env=env,
                               stdout=subprocess.PIPE, text=True) for _ in range(2)]
    outputs = [r.communicate(timeout=120)[0].strip() for r in racers]
    assert outputs == ["42", "42"]
    computed = log.read_text().count("computed")
    assert computed == (1 if variant == "locked" else 2)


def test_without_a_store_parameters_in_any_order_are_one_measurement(monkeypatch):
    """In-process only (no store directory), the key does not depend on the
    order the parameters are given in.  Wrong variant: a key of the
    parameters as given computes twice."""
    monkeypatch.delenv(store.ENV, raising=False)
    calls = []

    def ask():
        monkeypatch.setattr(store, "_MEMORY", {})
        store.measured("count", lambda **p: calls.append(p) or len(calls), size=256, field="sine")
        store.measured("count", lambda **p: calls.append(p) or len(calls), field="sine", size=256)
        return len(calls)
    assert ask() == 1
    calls.clear()
    real_dumps = store.json.dumps
    monkeypatch.setattr(store.json, "dumps", lambda obj, **kw: real_dumps(obj))   # ignores sort_keys
    assert ask() == 2


def test_a_record_with_its_fields_in_another_order_is_served(fresh, monkeypatch):
    """The checksum is of the record's content, not of how a tool happened to order its keys:
    the same record rewritten with its fields and parameters in reverse order is served."""
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256, field="sine")
    record = _stored(directory)
    reordered = {k: record[k] for k in reversed(list(record))}
    reordered["params"] = {k: record["params"][k] for k in reversed(list(record["params"]))}
    assert list(reordered) != list(record)
    (directory / "u-curve.json").write_text(json.dumps(reordered))
    _new_process(monkeypatch)
    store.measured("u-curve", compute, size=256, field="sine")
    assert len(calls) == 1


def test_the_digest_reads_the_packages_where_python_imports_them_from():
    """`_roots` names each package's directory as imported (a checkout or an installed wheel)."""
    import importlib
    from pathlib import Path
    roots = store._roots()
    assert sorted(roots) == sorted(store.PACKAGES)
    for package, root in roots.items():
        assert root == Path(importlib.import_module(package).__file__).parent


def test_a_fifo_fed_a_sealed_record_is_never_read(fresh, monkeypatch):
    """A FIFO in a record's place, a writer holding it open with a well-formed record in the pipe (value 999,
    its checksum matching): the store does not read it (only a regular file is), and computes the value."""
    import os
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256)
    path = directory / "u-curve.json"
    planted = _sealed({**{k: v for k, v in _stored(directory).items() if k != "sha256"}, "value": 999})
    path.unlink()
    os.mkfifo(path)
    writer = os.open(path, os.O_RDWR | os.O_NONBLOCK)
    os.write(writer, json.dumps(planted).encode())
    try:
        _new_process(monkeypatch)
        with _unblocked():
            assert store.measured("u-curve", compute, size=256) != 999 and len(calls) == 2
    finally:
        os.close(writer)


def test_a_sealed_record_with_a_field_more_is_computed_again(fresh, monkeypatch):
    """A record whose checksum matches its fields, with one field the store never writes: not served."""
    directory, calls, compute = fresh
    store.measured("u-curve", compute, size=256)
    record = {k: v for k, v in _stored(directory).items() if k != "sha256"}
    (directory / "u-curve.json").write_text(json.dumps(_sealed({**record, "value": 999, "extra": 1})))
    _new_process(monkeypatch)
    assert store.measured("u-curve", compute, size=256) != 999 and len(calls) == 2
