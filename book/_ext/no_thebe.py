"""Sphinx extension: no Thebe on the pages.

Jupyter Book always loads sphinx-thebe, which puts on every page a script
naming a CDN copy of Thebe (unpkg.com), a Binder configuration for an unrelated
example repository, its own script and stylesheet, and (because Jupyter Book
fires ``env-before-read-docs`` twice) its inline script twice, which makes the
browser log a SyntaxError.  The book runs no code in the browser but its own
simulator and reads offline, so this extension, loaded after sphinx-thebe,
disconnects sphinx-thebe's event handlers (its static path, scripts and
per-page configuration) and drops its stylesheet.  The ``thebe-button``
directive stays registered and unused.
"""

from __future__ import annotations

THEBE = "sphinx_thebe"


def remove_thebe(app):
    """Disconnect every handler sphinx-thebe connected and drop its CSS; returns how many of each."""
    handlers = [listener.id for listeners in app.events.listeners.values() for listener in listeners
                if getattr(listener.handler, "__module__", "") == THEBE]
    for listener_id in handlers:
        app.disconnect(listener_id)
    before = len(app.registry.css_files)
    app.registry.css_files[:] = [(name, attrs) for name, attrs in app.registry.css_files
                                 if "thebe" not in str(name)]
    return len(handlers), before - len(app.registry.css_files)


def setup(app):
    if THEBE in app.extensions:
        remove_thebe(app)
    return {"version": "2", "parallel_read_safe": True, "parallel_write_safe": True}
