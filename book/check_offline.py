"""Fail the build if the built site needs the network to read.

Scans every HTML and CSS file under the build directory for resources that a
browser would fetch from another host (script src, link href of stylesheets,
preloads and icons, img/iframe/source src, CSS url() and @import), and checks
that MathJax is served from the site itself.  An inline script that names a
URL on another host (a CDN copy of a library it may load later) fails too.  Hyperlinks a reader may click
(<a href>) are not fetched when the page loads and are allowed.

Usage: python book/check_offline.py book/_build/html
"""

from __future__ import annotations

import re
import sys
from html.parser import HTMLParser
from pathlib import Path

REMOTE = re.compile(r"^\s*(https?:)?//", re.IGNORECASE)
INLINE_URL = re.compile(r"""(?<![\w.])(https?:)?//[\w.-]+\.[a-z]{2,}[^\s'"]*""", re.IGNORECASE)
CSS_URL = re.compile(r"""(?:url\(\s*['"]?|@import\s+['"])([^'")\s]+)""", re.IGNORECASE)


class _Fetches(HTMLParser):
    """Collect every URL the page loads on its own."""

    def __init__(self):
        super().__init__()
        self.urls = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in ("script", "img", "iframe", "source", "audio", "video", "embed") and a.get("src"):
            self.urls.append((tag, a["src"]))
        if tag == "link" and a.get("href"):
            rel = (a.get("rel") or "").lower()
            if rel not in ("canonical", "next", "prev", "search", "index", "author", "license"):
                self.urls.append((f"link rel={rel}", a["href"]))
        if tag == "style" or a.get("style"):
            for m in CSS_URL.finditer(a.get("style") or ""):
                self.urls.append((tag + " style", m.group(1)))


def tag_is_script(kind: str) -> bool:
    return kind == "script"


def problems(root: Path) -> list[str]:
    out = []
    pages = sorted(root.rglob("*.html"))
    if not pages:
        return [f"no HTML pages under {root}"]
    for page in pages:
        parser = _Fetches()
        text = page.read_text(encoding="utf-8")
        parser.feed(text)
        for m in re.finditer(r"<style[^>]*>(.*?)</style>", text, re.S | re.I):
            parser.urls += [("style", u.group(1)) for u in CSS_URL.finditer(m.group(1))]
        for m in re.finditer(r"<script[^>]*>(.*?)</script>", text, re.S | re.I):
            for u in INLINE_URL.finditer(m.group(1)):     # a URL a script may load later (a CDN's, say)
                out.append(f"{page.relative_to(root)}: inline script names {u.group(0)}")
        for kind, url in parser.urls:
            if REMOTE.match(url):
                out.append(f"{page.relative_to(root)}: {kind} loads {url}")
            elif tag_is_script(kind) and not url.startswith("data:") and "{{" not in url:
                # A local script that is missing breaks the page as surely as a CDN.
                local = (page.parent / url.split("?")[0].split("#")[0]).resolve()
                if not local.is_file():
                    out.append(f"{page.relative_to(root)}: script {url} is not in the site")
    for js in sorted(root.rglob("_static/sim/*.js")):
        for m in re.finditer(r"""(?:import\s*\(|from\s+|fetch\s*\(|src\s*=)\s*['"](https?:)?//""",
                             js.read_text(encoding="utf-8")):
            out.append(f"{js.relative_to(root)}: loads {m.group(0)}")
    for css in sorted(root.rglob("*.css")):
        for m in CSS_URL.finditer(css.read_text(encoding="utf-8", errors="replace")):
            if REMOTE.match(m.group(1)):
                out.append(f"{css.relative_to(root)}: css loads {m.group(1)}")
    mathjax = root / "_static" / "mathjax" / "tex-chtml.js"
    if not mathjax.is_file():
        out.append(f"MathJax is not served from the site: {mathjax} is missing")
    if not any("_static/mathjax/tex-chtml.js" in p.read_text(encoding="utf-8") for p in pages):
        out.append("no page loads MathJax from _static/mathjax/tex-chtml.js")
    return out


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    root = Path(argv[1])
    found = problems(root)
    for line in found:
        print("offline check:", line, file=sys.stderr)
    if found:
        print(f"offline check FAILED: {len(found)} problem(s)", file=sys.stderr)
        return 1
    print(f"offline check: {len(list(root.rglob('*.html')))} pages load nothing from the network")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
