"""Fixtures shared by the tests of the built site, and their mark ``audit``."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from proofs import registry

ROOT = Path(__file__).parents[1]


def pytest_configure(config):
    config.addinivalue_line("markers", "audit: reads the built site (the book_html fixture); `make audit` runs these")


#: Audits that share an expensive module fixture, kept on one worker under ``--dist loadgroup`` (`make
#: audit`): every page opened twice and measured (test_book_pages.py's ``site``: its layout, formulas
#: and axe-core's audit, about a minute), the simulator's page loaded once (test_browser.py's
#: ``session``).  The other audits are dealt out one by one.
SHARED = ("site", "session")


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items):
    """Every test that reads the built site (it takes `book_html`) is an audit: `make test`
    leaves it to `make audit`; one that uses a fixture of `SHARED` joins that fixture's xdist group.
    First among the hooks: xdist's worker reads the groups in its own hook, which would otherwise run
    before this one and see none (each worker then built the shared fixture for itself)."""
    for item in items:
        names = getattr(item, "fixturenames", ())
        if "book_html" in names:
            item.add_marker(pytest.mark.audit)
            for shared in SHARED:
                if shared in names and item.config.pluginmanager.hasplugin("xdist"):   # not under -p no:xdist
                    item.add_marker(pytest.mark.xdist_group(f"{item.module.__name__}::{shared}"))


@pytest.fixture(autouse=True)
def _project_environment_kept():
    """Fails the test that leaves one of the project's environment variables (``SYMRENDER_*``: the
    store, the site, ...) set, changed or removed: its worker goes on to other tests, which would read
    another store or site than theirs and fail or pass by the order the tests were dealt.  A fixture
    of a wider scope (test_shown_values' module-scoped store) is set up before this looks and undone
    after it has."""
    def own():
        return {k: v for k, v in os.environ.items() if k.startswith("SYMRENDER_")}
    before = own()
    yield
    after = own()
    if after != before:
        pytest.fail("the test left the environment changed: " + ", ".join(
            f"{k}={after.get(k)!r} (was {before.get(k)!r})" for k in sorted(before.keys() | after.keys())
            if before.get(k) != after.get(k)), pytrace=False)


@pytest.fixture(autouse=True)
def _no_theorem_outlives_its_test():
    """Each theorem module's built theorems are dropped after each test (rebuilding one takes
    milliseconds): a theorem is built from its module's objects when first asked for and then kept,
    so one first built while a test had planted a wrong object (a monkeypatched normal, a loosened
    tolerance) would otherwise be every later test's in that worker, and pass or fail them by the
    order the tests were dealt."""
    yield
    for name in registry.MODULES:
        module = sys.modules.get(f"proofs.{name}")
        if module is not None:
            module.build.cache_clear()


@pytest.fixture(scope="session")
def book_html():
    """The built site: SYMRENDER_BOOK_HTML if set (``make audit`` builds the book first and
    passes it), else book/_build/html, built here as ``make book`` builds it (the test
    processes of one run take turns, as any two builds in one tree do: the build holds
    book/.build.lock, book/_ext/execute_pages.py; the first builds, the others find it current)."""
    given = os.environ.get("SYMRENDER_BOOK_HTML")
    if given:
        path = Path(given)
        if not (path / "s4_simulator.html").is_file():
            pytest.fail(f"SYMRENDER_BOOK_HTML={given} holds no s4_simulator.html")
        return path
    jb = Path(sys.executable).with_name("jupyter-book")
    subprocess.run([str(jb), "build", str(ROOT / "book"), "--warningiserror", "--keep-going", "--quiet"],
                   check=True, timeout=1800)
    return ROOT / "book" / "_build" / "html"
