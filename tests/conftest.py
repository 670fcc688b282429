"""Fixtures shared by the tests of the built site."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[1]


@pytest.fixture(scope="session")
def book_html(tmp_path_factory):
    """The built site: SYMRENDER_BOOK_HTML if set (.ci/run builds the book first and passes it),
    else a build of book/ into a temporary directory."""
    given = os.environ.get("SYMRENDER_BOOK_HTML")
    if given:
        path = Path(given)
        if not (path / "s4_simulator.html").is_file():
            pytest.fail(f"SYMRENDER_BOOK_HTML={given} holds no s4_simulator.html")
        return path
    out = tmp_path_factory.mktemp("book")
    jb = Path(sys.executable).with_name("jupyter-book")
    subprocess.run([str(jb), "build", str(ROOT / "book"), "--path-output", str(out), "--warningiserror",
                    "--keep-going", "--quiet"], check=True, timeout=1800)
    return out / "_build" / "html"
