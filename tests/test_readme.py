"""README.md stays true and short: at most `MAX_LINES` lines (the design's limit: what the project
is, the two commands, one example, the layout), a row of its layout table for each top-level
directory of the repository and none for a directory that is not there, and every file it names
present."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 100


def tracked_directories(root=ROOT):
    """The top-level directories git tracks files in, hidden ones (.ci) left out."""
    files = subprocess.run(["git", "ls-files"], cwd=root, capture_output=True, text=True, check=True).stdout
    return {f.split("/")[0] for f in files.splitlines() if "/" in f and not f.startswith(".")}


def readme_problems(text, directories, root=ROOT):
    """What is wrong with the README ``text``, as sentences: too long, a directory of ``directories``
    with no row of the layout table (a row is ``| `name/` | ... |``), a row naming no directory of them,
    a file path in backquotes (``a/b.py``) that does not exist under ``root``."""
    bad = []
    if len(text.splitlines()) > MAX_LINES:
        bad.append(f"{len(text.splitlines())} lines (at most {MAX_LINES}): move detail into the docstrings")
    rows = set(re.findall(r"^\| `([\w.-]+)/` \|", text, re.M))
    bad += [f"no layout row for {d}/" for d in sorted(directories - rows)]
    bad += [f"a layout row for {d}/, which is not a directory of the repository" for d in sorted(rows - directories)]
    bad += [f"names {p}, which does not exist" for p in sorted(set(re.findall(r"`([\w-]+/[\w./-]+\.\w+)`", text)))
            if not (root / p).exists()]
    return bad


def test_the_readme_is_short_and_names_every_directory_and_only_files_that_exist():
    assert readme_problems((ROOT / "README.md").read_text(encoding="utf-8"), tracked_directories()) == []


README = (ROOT / "README.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("wrong, found", [
    (README + "more\n" * (MAX_LINES + 1 - len(README.splitlines())), "lines (at most"),
    (re.sub(r"^\| `lab/` \|.*\n", "", README, flags=re.M), "no layout row for lab/"),
    (README + "| `docs/` | pages |\n", "a layout row for docs/"),
    (README.replace("`renderer/kernel.py`", "`renderer/kernels.py`"), "names renderer/kernels.py"),
])
def test_the_readme_check_catches_a_long_readme_a_missing_row_a_stray_row_and_a_missing_file(wrong, found):
    bad = readme_problems(wrong, tracked_directories())
    assert any(found in b for b in bad), bad
