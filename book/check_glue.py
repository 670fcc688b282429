"""Check a built book: one value per quantity, under its name and under its words.

A quantity shown on several pages is glued under one name (``ucurve_eps_opt``,
say) and computed once per build (`lab.store`).  This reads, for each page,
the notebook jupyter-cache holds for the page's current execution (the record
of that page accessed last: the build touches the record it uses) and fails,
naming the pages and values, if two pages glue different values under one name.

Names are for code; a reader sees words.  `NAMED` gives each quantity the prose
names (the words it is called by, e.g. "RMS slope of the census").  In the built
HTML, wherever those words are followed in the same sentence by a number, that
number must be the glued value (to the digits shown): the same words cannot
carry two numbers, whether the number was glued, or written into a measurement's
text, or typed.  Each quantity's words must be met at least once, and no
quantity's words may contain another's.

Usage: python book/check_glue.py [CACHE_DIR [HTML_DIR]]
       (defaults: book/_build/.jupyter_cache, and html/ beside it)
Exit status 0 if every check passes, 1 if not, 2 if there is no cache or no site.
"""

from __future__ import annotations

import json
import re
import sys
from html.parser import HTMLParser
from pathlib import Path

MIME = "application/papermill.record/"

#: Glue name -> the words the prose calls that quantity by (lower case; matched
#: case-insensitively, in the text a reader sees outside maths and code).
NAMED = {
    "census_rms_slope": "rms slope",
    "census_off_slope": "off-band slope",
    "census_ratio": "crease ratio",
    "dn_residual": "closed form's worst error",
    "ucurve_eps_opt": "fitted optimal step",
    "ucurve_eps_pred": "predicted optimal step",
    "ucurve_rel_1e9": "relative error at a step of 1e-9",
    "ucurve_rel_1e11": "relative error at a step of 1e-11",
    "beta_median_order": "median order",
    "beta_rms_order": "rms order",
    "tilt_chart": "median tilt of the draft's normal",
    "tilt_surface": "median tilt of the displaced sphere's normal",
}


def page_glue(notebook: dict) -> dict:
    """{name: shown value} of every glue output of a notebook (a dict, nbformat 4): its
    text/markdown if it has one (`chapter.theorems.glue_math`), else its text/plain."""
    out = {}
    for cell in notebook.get("cells", []):
        for output in cell.get("outputs", []):
            scrap = output.get("metadata", {}).get("scrapbook")
            if scrap:
                data = output.get("data", {})
                prefix = scrap.get("mime_prefix", MIME)
                out[scrap["name"]] = data.get(prefix + "text/markdown", data.get(prefix + "text/plain"))
    return out


def glued(cache_dir) -> dict:
    """{name: {page: value}} over the current record of every page in the cache.

    Raises
    ------
    FileNotFoundError
        If ``cache_dir`` holds no jupyter-cache database.
    """
    from jupyter_cache import get_cache

    cache_dir = Path(cache_dir)
    if not (cache_dir / "global.db").is_file():
        raise FileNotFoundError(f"no jupyter-cache database in {cache_dir}")
    latest = {}
    for record in get_cache(str(cache_dir)).list_cache_records():
        if record.uri not in latest or record.accessed > latest[record.uri].accessed:
            latest[record.uri] = record
    names = {}
    for uri, record in latest.items():
        notebook = json.loads((cache_dir / "executed" / record.hashkey / "base.ipynb").read_text(encoding="utf-8"))
        for name, value in page_glue(notebook).items():
            names.setdefault(name, {})[Path(uri).stem] = value
    return names


def conflicts(names: dict) -> list:
    """One line per name glued with different values on different pages."""
    return [f"{name}: " + ", ".join(f"{page} = {value}" for page, value in sorted(pages.items()))
            for name, pages in sorted(names.items()) if len(set(pages.values())) > 1]


_SKIP = {"script", "style", "pre", "code", "mjx-container", "math"}
_BLOCK = {"p", "li", "td", "th", "dd", "dt", "figcaption", "summary", "h1", "h2", "h3", "h4", "div", "caption"}
#: A number as the prose shows it: 0.54, −1.3e-12, 2.0e-15, 29,919, 1e-9.
NUMBER = re.compile(r"[−-]?\d[\d,]*(?:\.\d+)?(?:e[−+-]?\d+)?")


class _Prose(HTMLParser):
    """The text a reader sees in each block element, maths (MathJax source) and code left out."""

    def __init__(self):
        super().__init__()
        self.blocks, self._text, self._skip = [], [], []

    def _flush(self):
        text = " ".join("".join(self._text).split())
        if text:
            self.blocks.append(text)
        self._text = []

    def handle_starttag(self, tag, attrs):
        classes = (dict(attrs).get("class") or "").split()
        if tag in _BLOCK:
            self._flush()
        if tag in _SKIP or "math" in classes:
            self._skip.append(tag)
            self._text.append(" ⟨·⟩ ")

    def handle_endtag(self, tag):
        if self._skip and self._skip[-1] == tag:
            self._skip.pop()
        if tag in _BLOCK:
            self._flush()

    def handle_data(self, data):
        if not self._skip:
            self._text.append(data)


def prose_sentences(html: str) -> list:
    """The sentences of a page's prose (outside maths and code), one string each."""
    parser = _Prose()
    parser.feed(html)
    parser._flush()
    return [s.replace("’", "'") for block in parser.blocks for s in re.split(r"(?<=[.;!?])\s+(?=[A-Z(“])", block)]


def _value(text):
    """A glued text/plain value as a float, or None if it is not a number."""
    try:
        return float(str(text).strip("'\""))
    except ValueError:
        return None


def _matches(shown: str, value: float) -> bool:
    """Whether the number as shown (``0.54``, ``2.0e-15``, ``29,919``) is ``value`` to the digits it shows."""
    shown = shown.replace("−", "-").replace(",", "")
    mantissa, _, exponent = shown.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    unit = 10.0 ** (int(exponent or 0) - decimals)
    return abs(float(shown) - value) <= 0.5 * unit * (1 + 1e-9) + 1e-300


def words_conflicts(html_dir, names: dict, named=None) -> list:
    """One line per place where a quantity's words (`NAMED`) carry a number other than its
    glued value, per quantity whose words are met nowhere (or that is glued nowhere), and
    per pair of quantities whose words contain one another.  ``names`` is `glued`'s."""
    named = NAMED if named is None else named
    bad = [f"the words {a!r} ({n}) contain {b!r} ({m}): a sentence naming one names both"
           for n, a in named.items() for m, b in named.items() if n != m and b in a]
    met = {n: 0 for n in named}
    for page in sorted(Path(html_dir).glob("*.html")):
        for sentence in prose_sentences(page.read_text(encoding="utf-8")):
            low = sentence.lower()
            for name, words in named.items():
                at = low.find(words)
                if at < 0:
                    continue
                met[name] += 1
                number = NUMBER.search(sentence, at + len(words))
                values = {_value(v) for v in names.get(name, {}).values()} - {None}
                if number is None or not values or re.search(r"[<>≤≥]", sentence[at:number.start()]):
                    continue                     # no number, or a threshold of a rule, not a value
                if not any(_matches(number.group(), v) for v in values):
                    bad.append(f"{page.stem}: {words!r} is followed by {number.group()}, but {name} "
                               f"= {', '.join(f'{v:g}' for v in sorted(values))}: “{sentence}”")
    bad += [f"{name}: glued nowhere" for name in named if name not in names]
    bad += [f"{name}: the prose never calls it {words!r}" for name, words in named.items() if not met[name]]
    return bad


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    cache_dir = Path(argv[0] if argv else "book/_build/.jupyter_cache")
    html_dir = Path(argv[1]) if len(argv) > 1 else cache_dir.parent / "html"
    try:
        names = glued(cache_dir)
        if not html_dir.is_dir():
            raise FileNotFoundError(f"no built site in {html_dir}")
    except FileNotFoundError as error:
        print(f"check_glue: {error}", file=sys.stderr)
        return 2
    bad = conflicts(names)
    shared = sum(len(pages) > 1 for pages in names.values())
    if bad:
        print("check_glue: the same name shows different values on different pages:\n  " + "\n  ".join(bad),
              file=sys.stderr)
        return 1
    worded = words_conflicts(html_dir, names)
    if worded:
        print("check_glue: the same words carry different numbers:\n  " + "\n  ".join(worded), file=sys.stderr)
        return 1
    print(f"check_glue: {len(names)} glued names; {shared} shown on several pages, each with one value; "
          f"{len(NAMED)} quantities named in prose, each with one value under its words")
    return 0


if __name__ == "__main__":
    sys.exit(main())
