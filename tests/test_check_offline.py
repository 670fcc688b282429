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


def _write(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


#: Every way the module's docstring names for a page to fetch, each planted alone: (what, plant(site), found).
FETCHES = [
    *((f"<{tag} src>", lambda site, tag=tag: _head(site, f'<{tag} src="https://x.example.org/a"></{tag}>'),
       f"{tag} loads https://x.example.org/a") for tag in ("img", "iframe", "source", "audio", "video", "embed")),
    *((f"link rel={rel}", lambda site, rel=rel: _head(site, f'<link rel="{rel}" href="//x.example.org/a">'),
       f"link rel={rel} loads //x.example.org/a") for rel in ("preload", "icon", "modulepreload")),
    ("@import in <style>", lambda site: _head(site, '<style>@import "https://x.example.org/a.css";</style>'),
     "style loads https://x.example.org/a.css"),
    ("url() in <style>", lambda site: _head(site, "<style>p { background: url(https://x.example.org/a.png) }</style>"),
     "style loads https://x.example.org/a.png"),
    ("url() in a style attribute",
     lambda site: _head(site, "<div style=\"background: url('//x.example.org/a.png')\"></div>"),
     "div style loads //x.example.org/a.png"),
    ("url() in a CSS file",
     lambda site: _write(site / "_static" / "a.css", "p { background: url('https://x.example.org/a.png') }"),
     "_static/a.css: css loads https://x.example.org/a.png"),
    ("@import in a CSS file", lambda site: _write(site / "_static" / "b.css", '@import "//x.example.org/b.css";'),
     "_static/b.css: css loads //x.example.org/b.css"),
    *((f"the simulator's {how}", lambda site, how=how: _write(site / "_static" / "sim" / "a.js", how),
       "_static/sim/a.js: loads")
      for how in ('import("https://x.example.org/m.js")', 'import x from "//x.example.org/m.js"',
                  'fetch("https://x.example.org/d.json")', 'el.src = "//x.example.org/a.png"')),
    ("MathJax missing", lambda site: (site / "_static" / "mathjax" / "tex-chtml.js").unlink(), "MathJax is not served"),
    ("MathJax never loaded", lambda site: (site / "index.html").write_text("<html><body>text</body></html>"),
     "no page loads MathJax"),
]


def _head(site, html):
    page = site / "index.html"
    page.write_text(page.read_text().replace("</head>", html + "</head>"))


@pytest.mark.parametrize("plant, found", [f[1:] for f in FETCHES], ids=[f[0] for f in FETCHES])
def test_every_kind_of_fetch_the_check_names_fails_it(tmp_path, plant, found):
    site = _site(tmp_path)
    plant(site)
    problems = check_offline.problems(site)
    assert any(found in p for p in problems), problems


#: What the learning aids put on a page: a margin note citing a work, an exercise with its folded
#: solution (sphinx-exercise, sphinx-togglebutton) and the bibliography's entries with their DOI links.
AIDS = ('<aside class="sidebar margin"><p>Goldberg [<a class="reference internal" href="s8_history.html#id11">'
        '1991</a>]</p></aside><div class="exercise admonition" id="ex-a"><p class="admonition-title">Exercise 1'
        '</p></div><div class="solution dropdown admonition"><p>6.9e-07</p></div>'
        '<div class="citation" role="listitem"><p>D. Goldberg. <a class="reference external" '
        'href="https://doi.org/10.1145/103162.103163">doi:10.1145/103162.103163</a>.</p></div>')


def test_exercises_margin_notes_and_doi_links_are_read_offline_but_a_fetch_beside_them_is_not(tmp_path):
    site = _site(tmp_path, '<link rel="stylesheet" href="_static/exercise.css">')
    (site / "_static" / "exercise.css").write_text('div.exercise p.admonition-title::after { content: "\\f303"; }')
    page = site / "index.html"
    page.write_text(page.read_text().replace("<p>text</p>", AIDS))
    assert check_offline.problems(site) == []
    page.write_text(page.read_text().replace("</div></body>", '<img src="https://doi.org/cover.png"></div></body>'))
    assert check_offline.problems(site) == ["index.html: img loads https://doi.org/cover.png"]
