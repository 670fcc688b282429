"""Check a built book: every glued name shows one value on every page that glues it.

A quantity shown on several pages is glued under one name (``ucurve_eps_opt``,
say) and computed once per build (`proofs.store`).  This reads, for each page,
the notebook jupyter-cache holds for the page's current execution (the record
of that page accessed last: the build touches the record it uses) and fails,
naming the pages and values, if two pages glue different values under one name.

Usage: python book/check_glue.py [CACHE_DIR]   (default: book/_build/.jupyter_cache)
Exit status 0 if every shared name agrees, 1 if not, 2 if there is no cache.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

MIME = "application/papermill.record/"


def page_glue(notebook: dict) -> dict:
    """{name: shown value} of every glue output of a notebook (a dict, nbformat 4): its
    text/markdown if it has one (`proofs.book.glue_math`), else its text/plain."""
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


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    cache_dir = Path(argv[0] if argv else "book/_build/.jupyter_cache")
    try:
        names = glued(cache_dir)
    except FileNotFoundError as error:
        print(f"check_glue: {error}", file=sys.stderr)
        return 2
    bad = conflicts(names)
    shared = sum(len(pages) > 1 for pages in names.values())
    if bad:
        print("check_glue: the same name shows different values on different pages:\n  " + "\n  ".join(bad),
              file=sys.stderr)
        return 1
    print(f"check_glue: {len(names)} glued names; {shared} shown on several pages, each with one value")
    return 0


if __name__ == "__main__":
    sys.exit(main())
