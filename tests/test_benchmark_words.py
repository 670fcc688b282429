"""The benchmark's counts as the page says them (`chapter.benchmark.share_in_words`, `fastest_on`)."""

from types import SimpleNamespace

import pytest

from chapter.benchmark import fastest_on, share_in_words
from renderer import formulas as F


@pytest.mark.parametrize("count, total, words", [(3, 3, "all three"), (2, 3, "two of the three"),
                                                 (1, 3, "one of the three"), (0, 3, "none of the three"),
                                                 (2, 2, "both"), (1, 2, "one of the two")])
def test_share_in_words(count, total, words):
    assert share_in_words(count, total) == words


@pytest.mark.parametrize("count, total", [(4, 3), (-1, 3), (1, 0), (1.0, 3), (1, 11)])
def test_share_in_words_refuses_what_it_cannot_say(count, total):
    with pytest.raises(ValueError, match="count"):
        share_in_words(count, total)


def test_fastest_on_counts_the_fields_where_the_method_is_fastest():
    """A made-up measurement: exact fastest on every field but the last."""
    fields = list(F.FIELDS)
    rows = {f: [SimpleNamespace(field=f, method="exact", median=2.0 if f == fields[-1] else 1.0),
                SimpleNamespace(field=f, method="central", median=1.5)] for f in fields}
    fake = SimpleNamespace(of=rows.__getitem__, results=[r for f in fields for r in rows[f]])

    def named(wins):                        # "(sine)", "(sine and ridges)", "(sine, ridges and rings)"
        return f" ({', '.join(wins[:-1])} and {wins[-1]})" if len(wins) > 1 else f" ({wins[0]})"

    assert fastest_on(fake, "exact") == share_in_words(len(fields) - 1, len(fields)) + " fields" + named(fields[:-1])
    assert fastest_on(fake, "central") == share_in_words(1, len(fields)) + " fields" + named(fields[-1:])


def test_a_median_within_the_margin_is_no_win():
    """Medians 1 % apart (the rings field's exact gradient and AD): neither is the fastest; 20 % apart, the
    faster is.  Counting the nearer median as a win (margin 1) is the rule that let the page's verdict
    change with the machine's noise."""
    fields = list(F.FIELDS)
    rows = {f: [SimpleNamespace(field=f, method="exact", median=1.0),
                SimpleNamespace(field=f, method="AD", median=1.01 if f == fields[0] else 1.2)] for f in fields}
    fake = SimpleNamespace(of=rows.__getitem__, results=[r for f in fields for r in rows[f]])
    assert fastest_on(fake, "exact").startswith(share_in_words(len(fields) - 1, len(fields)) + " fields (")
    assert fastest_on(fake, "AD") == share_in_words(0, len(fields)) + " fields"
    assert fastest_on(fake, "exact", margin=1.0) == share_in_words(len(fields), len(fields)) + " fields"


def test_the_methods_sentence_names_every_record_with_its_steps_and_sources(monkeypatch):
    """`methods_sentence` reads the records: each label in order, each step of the configuration, each
    source as a citation, and the fields where a method applies when it does not apply everywhere; a
    record appended to METHODS is named with no other change."""
    import re

    from chapter.benchmark import methods_sentence, step_text
    from lab import gradient_benchmark as gb
    from lab import gradient_methods as gm
    toy = gm.Method("backward", None, None, "backward difference", gm.Style("k", "v", 5), steps="forward_steps",
                    applies=lambda f: f.name == "rings", sources=("higham-accuracy",))
    monkeypatch.setattr(gm, "METHODS", [*gm.METHODS, toy])
    text = methods_sentence(gb.FAST)
    parts = text.split(": ", 1)[1].rstrip(".").split("; ")
    count = {8: "Eight", 9: "Nine", 10: "Ten"}.get(len(gm.METHODS), str(len(gm.METHODS)))   # the toy included
    assert len(parts) == len(gm.METHODS) and text.startswith(f"{count} methods")
    for m, part in zip(gm.METHODS, parts):
        assert part.startswith(m.label)
        assert re.findall(r"\{cite:p\}`([^`]*)`", part) == ([",".join(m.sources)] if m.sources else [])
        for eps in (m.steps_in(gb.FAST) if m.steps else ()):
            assert step_text(eps) in part
    assert parts[-1].endswith("(on rings)") and "(on" not in parts[0]
