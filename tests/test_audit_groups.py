"""`make audit` builds each shared fixture of tests/conftest.py's `SHARED` once: the audits that use
it form one xdist group, run by one worker under ``--dist loadgroup``.

The grouping can fail silently (every test still passes, each worker building the fixture for
itself: about 30 s of Chromium more per extra build of test_book_pages.py's ``site``): pytest 9.2's
node ids made pytest-xdist 3.8 drop every group, and a hook of ours that ran after xdist's would too.
The test runs the project's conftest hooks under two workers on a scratch module whose shared fixture
counts its builds.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).parents[1]

SCRATCH = '''
import os
import pytest

@pytest.fixture(scope="session")
def book_html(tmp_path_factory):
    return tmp_path_factory.mktemp("site")

@pytest.fixture(scope="module")
def site(book_html):
    with open(os.environ["BUILDS"], "a") as f:
        f.write(f"{os.getpid()}\\n")
    return {}

@pytest.mark.parametrize("k", range(12))
def test_shared(site, k):
    pass

@pytest.mark.parametrize("k", range(12))
def test_alone(book_html, k):
    pass
'''


def run_audit(tmp_path, hook_order=None, xdist=True, conftest=None):
    """Two workers, ``--dist loadgroup`` and ``-m audit`` as `make audit` runs them (or, ``xdist``
    false, one process with xdist not loaded), over a scratch module whose module fixture ``site``
    (one of `SHARED`) appends its process id to a file per build; the project's hooks as
    tests/conftest.py declares them, or (``hook_order``: pytest.hookimpl's arguments, as text) the
    grouping hook called from a hook of that order, or ``conftest``'s text.
    Returns (pytest's return code, builds)."""
    (tmp_path / "test_scratch.py").write_text(SCRATCH)
    (tmp_path / "conftest.py").write_text(conftest or (
        "from tests.conftest import pytest_configure, pytest_collection_modifyitems\n" if hook_order is None
        else textwrap.dedent(f"""
            import pytest
            from tests import conftest as project
            pytest_configure = project.pytest_configure

            @pytest.hookimpl({hook_order})
            def pytest_collection_modifyitems(items):
                project.pytest_collection_modifyitems(items)
            """)))
    builds = tmp_path / "builds"
    # Only xdist among the plugins (the others cost each process a second of imports).
    env = dict(os.environ, BUILDS=str(builds), PYTHONPATH=str(ROOT), PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
    workers = ["-p", "xdist", "-n", "2", "--dist", "loadgroup"] if xdist else ["-p", "no:xdist"]
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", *workers, "-p", "no:cacheprovider",
                           "-m", "audit", "-o", "addopts=", "--strict-markers", "--rootdir", str(tmp_path),
                           str(tmp_path)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    return done, builds.read_text().split() if builds.exists() else []


def test_a_shared_fixture_is_built_once_under_two_workers(tmp_path):
    done, builds = run_audit(tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "24 passed" in done.stdout, done.stdout
    assert len(builds) == 1, f"the shared fixture was built {len(builds)} times: the xdist group was lost"


def test_the_check_catches_groups_assigned_after_xdist_read_them(tmp_path):
    """The wrong variant: the grouping hook in its default place, after xdist's worker hook (which
    reads the groups) in pluggy's order; each worker then builds the fixture for itself."""
    done, builds = run_audit(tmp_path, hook_order="")
    assert done.returncode == 0, done.stdout + done.stderr
    assert len(builds) == 2, builds


#: The grouping hook as it was: the xdist_group mark added whether or not xdist is loaded.
UNGUARDED = """
from tests import conftest as project
pytest_configure = project.pytest_configure

def pytest_collection_modifyitems(config, items):
    config.pluginmanager.hasplugin = lambda name: True
    project.pytest_collection_modifyitems(items)
"""


def test_the_audits_run_in_one_process_without_xdist(tmp_path):
    """``-p no:xdist`` (one process, as a debugger wants it): the audits run, the shared fixture built
    once, and no mark of a plugin not loaded (under --strict-markers, pytest's internal error)."""
    done, builds = run_audit(tmp_path, xdist=False)
    assert done.returncode == 0 and "24 passed" in done.stdout, done.stdout + done.stderr
    assert len(builds) == 1, builds
    done, _ = run_audit(tmp_path, xdist=False, conftest=UNGUARDED)
    assert done.returncode != 0 and "'xdist_group' not found in `markers`" in done.stdout + done.stderr, done.stdout
