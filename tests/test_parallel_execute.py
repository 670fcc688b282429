"""book/_ext/parallel_execute.py: the pages run side by side, and myst-nb then finds them all in the cache.

A two-page Sphinx project (myst-nb in cache mode, nb_deps and the extension,
as the book configures them) is built in a subprocess.  Each page records when
its kernel ran and imports project code, so nb_deps gives it a digest cell:
the notebook the extension executes must carry the same cell, or myst-nb's
lookup misses and it executes the page a second time.  Each check is shown
failing on a wrong variant: one page at a time, and an extension that builds
the notebook from the page as written.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

CONF = """
extensions = ["myst_nb", "nb_deps", "parallel_execute"]
nb_execution_mode = "cache"
nb_execution_cache_path = {cache!r}
exclude_patterns = ["_build"]
"""

WRONG_NOTEBOOK = """
from pathlib import Path
import parallel_execute
from myst_nb.core.read import create_nb_reader

def _notebook(app, docname):      # the wrong variant: the page as written, without nb_deps' digest cell
    path = Path(app.env.doc2path(docname))
    text = path.read_text(encoding="utf-8")
    reader = create_nb_reader(str(path), app.env.myst_config, app.env.mystnb_config, text)
    return None if reader is None else (path, reader.read(text))

parallel_execute._notebook = _notebook
"""

PAGE = """\
---
jupytext:
  text_representation:
    format_name: myst
kernelspec:
  display_name: Python 3
  name: python3
---
# Page {name}

```{{code-cell}} ipython3
import json, time
from renderer import formulas
start = time.time()
time.sleep(1.5)
with open({log!r}, "a") as f:
    f.write(json.dumps(["{name}", start, time.time()]) + "\\n")
```
"""


def _build(tmp_path, *, jobs, conf_extra=""):
    src = tmp_path / "src"
    src.mkdir()
    log = tmp_path / "runs.jsonl"
    (src / "conf.py").write_text(CONF.format(cache=str(tmp_path / "cache")) + conf_extra)
    (src / "index.md").write_text("# Index\n\n```{toctree}\na\nb\n```\n")
    for name in "ab":
        (src / f"{name}.md").write_text(PAGE.format(name=name, log=str(log)))
    env = {**os.environ, "SYMRENDER_BOOK_JOBS": str(jobs),
           "PYTHONPATH": os.pathsep.join([str(ROOT), str(ROOT / "book" / "_ext")])}
    result = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", str(src), str(tmp_path / "out")],
                            env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    runs = [json.loads(line) for line in log.read_text().splitlines()]
    return result.stdout + result.stderr, runs


def _overlap(runs):
    (_, s1, e1), (_, s2, e2) = runs
    return min(e1, e2) - max(s1, s2)


@pytest.mark.parametrize("jobs", [2, 1])
def test_pages_execute_side_by_side_once_and_myst_nb_reads_them_from_the_cache(tmp_path, jobs):
    log, runs = _build(tmp_path, jobs=jobs)
    assert sorted(r[0] for r in runs) == ["a", "b"]               # each page ran once
    assert log.count("Using cached notebook") == 2 and "Executing notebook" not in log
    assert log.count(": executed in") == 2
    if jobs == 2:
        assert _overlap(runs) > 0.5                               # the two kernels ran at once
    else:
        assert _overlap(runs) < 0                                 # the wrong variant: one after the other


def test_check_rejects_a_notebook_without_the_digest_cell(tmp_path):
    log, runs = _build(tmp_path, jobs=2, conf_extra=textwrap.dedent(WRONG_NOTEBOOK))
    assert sorted(r[0] for r in runs) == ["a", "a", "b", "b"]     # myst-nb missed the cache: twice each
    assert log.count("Executing notebook") == 2


@pytest.mark.parametrize("value", ["0", "-1", "two", "1.5"])
def test_a_bad_job_count_is_refused_naming_the_variable(value, monkeypatch):
    sys.path.insert(0, str(ROOT / "book" / "_ext"))
    try:
        import parallel_execute
    finally:
        sys.path.remove(str(ROOT / "book" / "_ext"))
    monkeypatch.setenv("SYMRENDER_BOOK_JOBS", value)
    with pytest.raises(ValueError, match=f"SYMRENDER_BOOK_JOBS must be a whole number >= 1, got '{value}'"):
        parallel_execute.jobs()
