"""book/_ext/a11y_markup.py's post-transforms on documents made here: the minus sign typed into each text
node of the prose (code, literals, maths and raw markup left as written), and the names of links that say
the same and lead to different places."""

import importlib.util
from pathlib import Path
from types import SimpleNamespace

import pytest
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


def _linked(*targets, docname="glossary"):
    """A document of one paragraph with a link for each (words, address), and what LinkNames reads of
    Sphinx's environment: the page's name and the titles of two sections of §3."""
    document = new_document("<test>", get_default_settings(Parser))
    document.settings.env = SimpleNamespace(docname=docname, domaindata={"std": {"labels": {
        "s3-ucurve": ("s3_math", "s3-ucurve", "The finite-difference U-curve"),
        "s3-gradients": ("s3_math", "s3-gradients", "The gradients and the kink loci")}}})
    links = [nodes.reference("", words, internal=True, refuri=uri) for words, uri in targets]
    document += nodes.paragraph("", "", *links)
    return document, links


def test_links_that_say_the_same_and_lead_elsewhere_are_named_by_where_they_lead():
    from chapter.verdicts import NUMBERS
    from proofs.registry import CITABLE
    claim, theorem = next(iter(NUMBERS)), next(iter(CITABLE))
    document, links = _linked(("§3", "s3_math.html#s3-ucurve"), ("§3", "s3_math.html#s3-gradients"),
                              ("§3", "s3_math.html#s3-ucurve"), ("why", f"s6_ledger.html#claim-{claim}"),
                              ("§6", f"s6_ledger.html#ledger-{theorem}"), ("§6", f"s6_ledger.html#claim-{claim}"),
                              ("§7", "s7_pitfalls.html#s7-crease"))
    a11y_markup.LinkNames(document).run()
    assert [link.get("aria-label") for link in links] == [
        "§3: The finite-difference U-curve", "§3: The gradients and the kink loci", "§3: The finite-difference U-curve",
        None, f"§6: the evidence for “{CITABLE[theorem]}”", f"§6: claim {NUMBERS[claim]}", None]


@pytest.mark.parametrize("anchor", ["s3-kinks", "fig-frame"])
def test_a_link_to_a_target_without_a_title_is_refused_where_its_words_are_shared(anchor):
    """The words of a label ("s3 kinks") are no name: a paragraph's or untitled figure's label fails the page."""
    document, _ = _linked(("§3", "s3_math.html#s3-ucurve"), ("§3", f"s3_math.html#{anchor}"))
    with pytest.raises(ValueError, match=rf"glossary: the links '§3' lead to different places, and s3_math#{anchor} has no title"):
        a11y_markup.LinkNames(document).run()
    document, links = _linked(("§3", f"s3_math.html#{anchor}"), ("§3", f"s3_math.html#{anchor}"))
    a11y_markup.LinkNames(document).run()                # one place: the words say where it leads
    assert [link.get("aria-label") for link in links] == [None, None]


def test_an_id_given_twice_is_numbered_by_its_place_skipping_one_taken():
    """sphinx-proof gives every proof's section the id "proof-content": the second and later are numbered, and
    a number another element has is skipped; every id of the page is then given once."""
    document = new_document("<test>", get_default_settings(Parser))
    sections = [nodes.section(ids=["proof-content"]) for _ in range(3)] + [nodes.section(ids=["proof-content-2", "x"])]
    document += sections
    a11y_markup.UniqueIds(document).run()
    assert [s["ids"] for s in sections] == [["proof-content"], ["proof-content-3"], ["proof-content-4"],
                                            ["proof-content-2", "x"]]
