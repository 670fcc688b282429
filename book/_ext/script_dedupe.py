"""Sphinx extension: emit each page script once.

sphinx-thebe registers its inline configuration script on every
``env-before-read-docs``, which Jupyter Book fires twice; the page then declares
``const THEBE_JS_URL`` twice and the browser logs a SyntaxError on every page.
This drops exact duplicates (same file, same inline body, same attributes)
from each page's script list, keeping the first.
"""

from __future__ import annotations


def _key(script):
    # An inline script is registered with filename None by one path and '' by another.
    filename = getattr(script, "filename", script) or ""
    attributes = getattr(script, "attributes", {}) or {}
    return str(filename), tuple(sorted((k, str(v)) for k, v in attributes.items()))


def _dedupe(app, pagename, templatename, context, doctree):
    scripts = context.get("script_files")
    if not scripts:
        return
    seen, kept = set(), []
    for script in scripts:
        key = _key(script)
        if key not in seen:
            seen.add(key)
            kept.append(script)
    context["script_files"][:] = kept       # in place: Sphinx restores the list from its own copy


def setup(app):
    # Early: html-page-context stops at the first handler that returns a template.
    app.connect("html-page-context", _dedupe, priority=100)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
