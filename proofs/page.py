"""What a book page calls to put a number or a figure on the page.

`glue` and `show` are the only ways a page hands a computed value to its
prose.  Inside a book build (myst-nb executing the page) they glue the value
under a name, for the prose's ``{glue:text}`` roles and ``{glue:figure}``
directives.  Run as a plain notebook (a downloaded page, in Jupyter) there is
no glue to read: `show` displays the figure where it was made, and `glue`
keeps the value only.

`show` refuses a figure whose text overlaps (`proofs.figures.text_overlaps`),
so the build fails on one instead of publishing it.
"""

from __future__ import annotations

import os

__all__ = ["glue", "show", "BUILD_ENV", "in_book_build", "FigureLayoutError"]

#: Set (to "1") by the book build (book/_ext/measurement_store.py) for the kernels it starts.
BUILD_ENV = "SYMRENDER_BOOK_BUILD"


class FigureLayoutError(ValueError):
    """A figure's text artists overlap one another."""


def in_book_build() -> bool:
    """Whether this process is a page kernel of the book build."""
    return os.environ.get(BUILD_ENV) == "1"


def glue(name, value):
    """Glue ``value`` under ``name`` for the page's prose (myst-nb), without displaying it.

    Outside a book build, or where myst-nb is not installed, nothing is glued:
    the value stays the caller's.  Returns ``value``.
    """
    try:
        from myst_nb import glue as nb_glue
    except ImportError:                        # a downloaded notebook without the book extra
        return value
    nb_glue(name, value, display=False)
    return value


def show(name, fig):
    """Glue the matplotlib Figure ``fig`` under ``name`` (for a ``{glue:figure}``
    directive) after checking its layout, then close it.  Outside a book build
    the figure is displayed here instead.

    Raises
    ------
    FigureLayoutError
        If two of the figure's text artists overlap (the message names them).
    """
    import matplotlib.pyplot as plt

    from .figures import text_overlaps
    clashes = text_overlaps(fig)
    if clashes:
        plt.close(fig)
        raise FigureLayoutError(f"figure {name!r}: text overlaps: " + "; ".join(clashes))
    if in_book_build():
        glue(name, fig)
    else:
        from IPython.display import display
        display(fig)
    plt.close(fig)
    return fig
