"""tests/conftest.py fails a test that leaves a ``SYMRENDER_*`` variable changed, and drops the
theorems a test built.

Such a leak fails or passes the later tests of the same worker by the order the tests
were dealt (book/check_glue.py's ``main`` once left the build's store set in the worker that
called it, and a later test of the in-memory store then read a stored value).  The scratch
modules below run under the project's conftest, in a process of their own (a leak planted here
would otherwise be this worker's).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]

#: Module -> its source: a test per way of leaving the environment changed, and three that undo their patch
#: (a module-scoped one lasts across the module's tests).
MODULES = {
    "test_sets": "import os\ndef test_it():\n    os.environ['SYMRENDER_PLANTED'] = '1'\n",
    "test_changes": "import os\ndef test_it():\n    os.environ['SYMRENDER_STORE'] = '/elsewhere'\n",
    "test_removes": "import os\ndef test_it():\n    del os.environ['SYMRENDER_SHOTS']\n",
    "test_monkeypatched": "def test_it(monkeypatch):\n    monkeypatch.setenv('SYMRENDER_STORE', '/elsewhere')\n",
    "test_module_patch": (
        "import os, pytest\n"
        "@pytest.fixture(scope='module')\n"
        "def store():\n"
        "    with pytest.MonkeyPatch.context() as patch:\n"
        "        patch.setenv('SYMRENDER_STORE', '/module')\n"
        "        yield\n"
        "def test_one(store):\n    assert os.environ['SYMRENDER_STORE'] == '/module'\n"
        "def test_two(store):\n    assert os.environ['SYMRENDER_STORE'] == '/module'\n"),
}


def test_a_test_that_sets_changes_or_removes_a_project_variable_fails_and_a_patch_undone_passes(tmp_path):
    for name, source in MODULES.items():
        (tmp_path / f"{name}.py").write_text(source)
    (tmp_path / "conftest.py").write_text("from tests.conftest import _project_environment_kept\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1",
           "SYMRENDER_STORE": "/given", "SYMRENDER_SHOTS": "0"}
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-o", "addopts=",
                           "--rootdir", str(tmp_path), "-rE", str(tmp_path)],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    errored = {line.split("::")[0].removeprefix("ERROR ")
               for line in done.stdout.splitlines() if line.startswith("ERROR ")}
    assert errored == {"test_sets.py", "test_changes.py", "test_removes.py"}, done.stdout + done.stderr
    for message in ("SYMRENDER_PLANTED='1' (was None)", "SYMRENDER_STORE='/elsewhere' (was '/given')",
                    "SYMRENDER_SHOTS=None (was '0')"):
        assert message in done.stdout, done.stdout
    assert "6 passed, 3 errors" in done.stdout, done.stdout


#: Two tests dealt in this order: the first plants a normal without its β in proofs.normal and builds
#: the theorem that reads it; the second asks for that theorem again.
PLANTED = (
    "from proofs import normal, registry\n"
    "from renderer import formulas as F\n"
    "BUILT = []\n"
    "def test_planted(monkeypatch):\n"
    "    monkeypatch.setattr(normal, 'N_PRIME', normal.N_PRIME.subs(F.beta, 0))\n"
    "    BUILT.append(registry.get('normal-beta-derivative'))\n"
    "def test_next():\n"
    "    assert registry.get('normal-beta-derivative') is not BUILT[0]\n")


@pytest.mark.parametrize("kept", [True, False], ids=["conftest", "without it"])
def test_a_theorem_built_while_a_test_planted_is_not_the_next_tests(tmp_path, kept):
    """A theorem is built when first asked for and then kept by its module: without the conftest's
    fixture, one built under a test's plant was the next test's (run alone, a test of the ∂N′/∂β
    measurement failed so; in a worker, the later tests would have read the planted theorem)."""
    (tmp_path / "test_plant.py").write_text(PLANTED)
    (tmp_path / "conftest.py").write_text("from tests.conftest import _no_theorem_outlives_its_test\n" if kept else "")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1"}
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-o", "addopts=",
                           "--rootdir", str(tmp_path), str(tmp_path)],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert ("2 passed" if kept else "1 failed, 1 passed") in done.stdout, done.stdout + done.stderr
