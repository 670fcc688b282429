"""The benchmark's counts as the page says them (`chapter.benchmark.share_in_words`, `fastest_on`)."""

from types import SimpleNamespace

import pytest

from chapter.benchmark import fastest_on, share_in_words
from lab import gradient_methods as gm


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
    slow = {gm.FIELDS[-1]}
    rows = {f: [SimpleNamespace(method="exact", median=2.0 if f in slow else 1.0),
                SimpleNamespace(method="central", median=1.5)] for f in gm.FIELDS}
    fake = SimpleNamespace(of=rows.__getitem__)
    assert fastest_on(fake, "exact") == share_in_words(len(gm.FIELDS) - 1, len(gm.FIELDS))
    assert fastest_on(fake, "central") == share_in_words(1, len(gm.FIELDS))
