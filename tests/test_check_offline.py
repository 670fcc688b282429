"""book/check_offline.py: a site that would fetch from another host fails, one that does not passes."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("check_offline", ROOT / "book" / "check_offline.py")
check_offline = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(check_offline)

PAGE = ('<html><head><script src="_static/mathjax/tex-chtml.js"></script>{head}</head>'
        '<body><p>text</p></body></html>')


def _site(tmp_path, head=""):
    (tmp_path / "_static" / "mathjax").mkdir(parents=True)
    (tmp_path / "_static" / "mathjax" / "tex-chtml.js").write_text("// local MathJax\n")
    (tmp_path / "index.html").write_text(PAGE.format(head=head))
    return tmp_path


def test_a_site_that_loads_only_its_own_files_passes(tmp_path):
    site = _site(tmp_path, '<script>const x = 1; // a comment, not a URL\nvar y = "a//b";</script>')
    assert check_offline.problems(site) == []


@pytest.mark.parametrize("head, found", [
    ('<script src="https://cdn.example.org/lib.js"></script>', "script loads https://cdn.example.org/lib.js"),
    ('<link rel="stylesheet" href="//fonts.example.com/a.css">', "loads //fonts.example.com/a.css"),
    ('<script>const THEBE_JS_URL = "https://unpkg.com/thebe@0.8.2/lib/index.js"</script>',
     "inline script names https://unpkg.com/thebe@0.8.2/lib/index.js"),
    ('<script src="_static/missing.js"></script>', "script _static/missing.js is not in the site"),
])
def test_a_site_that_would_fetch_or_miss_a_script_fails(tmp_path, head, found):
    problems = check_offline.problems(_site(tmp_path, head))
    assert len(problems) == 1 and found in problems[0]
