"""A pytest plugin for mutmut's runs (pyproject.toml's ``[tool.mutmut]`` loads it with ``-p``): every
test starts with the mutated modules' memoised values forgotten.

mutmut runs, for each mutant, only the tests that called the mutated function during its stats run,
and it learns who called what by recording calls test by test.  A memoised value (a theorem built once
by `proofs.core.catalogue`'s cache, a verdict in ``proofs.core._DECIDED``, a measurement in
``lab.store._MEMORY``, any ``functools.lru_cache`` of lab/ and proofs/) is computed by the first test
that asks for it; every later test that reads it is never credited, so a mutant in a theorem's builder
was checked against a test that only read its title, and survived although ``pytest verify`` refutes
it.  With the caches emptied before each test, each test computes what it reads: the stats credit it,
and in the mutant's run it reads the mutant's value.  The renderer's caches are kept (they hold
compiled kernels; renderer/ucurve.py's is the one mutated module among them and is emptied).

Not run by ``make test``: only ``pytest -p tests.mutmut_fresh``.
"""

import functools
import gc
import sys
import tomllib
from pathlib import Path

import pytest

#: The modules whose caches are emptied: the mutated ones, pyproject.toml's ``[tool.mutmut]`` ``source_paths``
#: as module names ("renderer/ucurve.py" -> "renderer.ucurve").
MUTATED = tuple(path.removesuffix(".py").replace("/", ".") for path in tomllib.loads(
    (Path(__file__).parents[1] / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["mutmut"]["source_paths"])

_seen = {"modules": -1, "caches": []}


def _mutated(module):
    return any(module == m or module.startswith(m + ".") for m in MUTATED)


def _caches():
    """The lru_cache wrappers defined in `MUTATED` modules, found again only when modules were imported."""
    if len(sys.modules) != _seen["modules"]:
        _seen["modules"] = len(sys.modules)
        _seen["caches"] = [f for f in gc.get_objects() if type(f) is functools._lru_cache_wrapper   # not a weak proxy
                           and _mutated(str(getattr(f, "__module__", "")))]
    return _seen["caches"]


def forget():
    """Empty every lru_cache of the `MUTATED` modules, ``proofs.core._DECIDED`` and ``lab.store._MEMORY``."""
    for f in _caches():
        f.cache_clear()
    for module, name in (("proofs.core", "_DECIDED"), ("lab.store", "_MEMORY")):
        if module in sys.modules:
            getattr(sys.modules[module], name).clear()


@pytest.fixture(autouse=True)
def _forget_memoised_values():
    forget()
    yield
