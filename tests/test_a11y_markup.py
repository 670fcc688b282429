"""book/_ext/a11y_markup.py's minus signs: the post-transform types the minus sign into each text
node of the prose and leaves code, literals, maths and raw markup as written."""

import importlib.util
from pathlib import Path

from docutils import nodes
from docutils.frontend import get_default_settings
from docutils.parsers.rst import Parser
from docutils.utils import new_document

_spec = importlib.util.spec_from_file_location(
    "a11y_markup", Path(__file__).resolve().parents[1] / "book" / "_ext" / "a11y_markup.py")
a11y_markup = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(a11y_markup)


def test_the_prose_gets_minus_signs_and_code_maths_and_raw_markup_keep_their_hyphens():
    document = new_document("<test>", get_default_settings(Parser))
    prose = nodes.paragraph("", "", nodes.Text("h = -0.651 at "),
                            nodes.inline("", "(-0.58, +0.61)", classes=["pasted-text"]),
                            nodes.strong("", "-9.252"), nodes.Text(", 1.3e-12; "),
                            nodes.literal("", "eps = -1e-3"), nodes.math("", "x = -1"))
    document += [prose, nodes.literal_block("", "print(-1)"), nodes.raw("", "<b>-2</b>", format="html"),
                 nodes.table("", nodes.entry("", nodes.paragraph("", "-4")))]
    a11y_markup.MinusSigns(document).run()
    assert prose.astext() == "h = −0.651 at (−0.58, +0.61)−9.252, 1.3e-12; eps = -1e-3x = -1"
    assert [n.astext() for n in document.children[1:]] == ["print(-1)", "<b>-2</b>", "−4"]
