"""book/check_glue.py: a name glued on several pages must show one value, and a quantity
one value under all its names, the library's where the library holds it.

Pages are notebooks cached with jupyter-cache, as the book's build caches
them; each check is shown failing on a wrong variant.  The registry of quantities
(`check_glue.QUANTITIES`) is also checked against the built book's glue."""

from __future__ import annotations

import importlib.util
import os
import time
from pathlib import Path

import nbformat
import pytest
from jupyter_cache import get_cache
from jupyter_cache.base import CacheBundleIn
from lab.store import ENV

_SPEC = importlib.util.spec_from_file_location("check_glue", Path(__file__).parents[1] / "book" / "check_glue.py")
check_glue = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(check_glue)


def _page(page="", **values):
    """An executed notebook whose one cell glues ``values`` (as myst_nb.glue writes them)."""
    outputs = [nbformat.v4.new_output("display_data", data={check_glue.MIME + "text/plain": repr(v)},
                                      metadata={"scrapbook": {"name": k, "mime_prefix": check_glue.MIME}})
               for k, v in values.items()]
    cell = nbformat.v4.new_code_cell(f"# {page} {sorted(values.items())}", outputs=outputs)
    return nbformat.v4.new_notebook(cells=[cell])


#: The registry's check, as the module defines it (the fixture below sets it aside for the other tests).
quantity_conflicts = check_glue.quantity_conflicts


@pytest.fixture(autouse=True)
def _no_named(monkeypatch):
    """The tests of names glue no named quantities and no registered ones (the words' and the
    registry's tests set their own)."""
    monkeypatch.setattr(check_glue, "NAMED", {})
    monkeypatch.setattr(check_glue, "quantity_conflicts", lambda names: [])


def _cache(tmp_path, pages):
    (tmp_path / "html").mkdir(exist_ok=True)
    cache = get_cache(str(tmp_path / "cache"))
    for uri, nb in pages:
        cache.cache_notebook_bundle(CacheBundleIn(nb, uri), check_validity=False)
        time.sleep(0.01)
    return tmp_path / "cache"


def test_one_value_per_shared_name_passes(tmp_path, capsys):
    cache = _cache(tmp_path, [("/b/s5_lab.md", _page(eps_fitted_sine=4.3e-7, c2_cube=16000.0)),
                              ("/b/s7_pitfalls.md", _page(eps_fitted_sine=4.3e-7))])
    assert check_glue.glued(cache)["eps_fitted_sine"] == {"s5_lab": "4.3e-07", "s7_pitfalls": "4.3e-07"}
    assert check_glue.main([str(cache)]) == 0
    assert "1 shown on several pages" in capsys.readouterr().out


@pytest.mark.parametrize("caller", [None, "callers-store"])
def test_the_library_is_read_from_the_builds_store_and_the_callers_environment_is_left_as_it_was(
        tmp_path, monkeypatch, caller):
    """The library's values are evaluated against the build's store (beside the cache) unless the caller
    names one, and ``SYMRENDER_STORE`` is as the caller had it afterwards: left set, it sent every later
    measurement of the calling process (a test worker) to the store of a build it never asked for."""
    seen = []
    monkeypatch.setattr(check_glue, "quantity_conflicts", lambda names: seen.append(os.environ.get(ENV)) or [])
    if caller:
        monkeypatch.setenv(ENV, str(tmp_path / caller))
    else:
        monkeypatch.delenv(ENV, raising=False)
    cache = _cache(tmp_path, [("/b/s5_lab.md", _page(eps_fitted_sine=4.3e-7))])
    assert check_glue.main([str(cache)]) == 0
    assert seen == [str(tmp_path / caller) if caller else str(cache.parent / ".measurements")]
    assert os.environ.get(ENV) == (str(tmp_path / caller) if caller else None)


def test_two_values_under_one_name_fail_naming_pages_and_values(tmp_path, capsys):
    cache = _cache(tmp_path, [("/b/s5_lab.md", _page(eps_fitted_sine=3.9e-7)),
                              ("/b/s7_pitfalls.md", _page(eps_fitted_sine=1.0e-7))])
    assert check_glue.main([str(cache)]) == 1
    assert "eps_fitted_sine: s5_lab = 3.9e-07, s7_pitfalls = 1e-07" in capsys.readouterr().err


def test_only_the_record_a_page_used_last_counts(tmp_path):
    """A stale execution of a page (an earlier version, still cached) is not the page."""
    cache = _cache(tmp_path, [("/b/s7_pitfalls.md", _page(eps_fitted_sine=1.0e-7)),
                              ("/b/s7_pitfalls.md", _page(eps_fitted_sine=4.3e-7)),
                              ("/b/s5_lab.md", _page("s5", eps_fitted_sine=4.3e-7))])
    assert check_glue.conflicts(check_glue.glued(cache)) == []
    # A wrong variant that reads every record sees the stale value and fails.
    records = get_cache(str(cache)).list_cache_records()
    every = {}
    for r in records:
        nb = (cache / "executed" / r.hashkey / "base.ipynb").read_text()
        for name, value in check_glue.page_glue(nbformat.reads(nb, 4)).items():
            every.setdefault(name, {})[f"{Path(r.uri).stem}#{r.pk}"] = value
    assert check_glue.conflicts(every)


def test_no_cache_is_an_error(tmp_path):
    assert check_glue.main([str(tmp_path)]) == 2
    with pytest.raises(FileNotFoundError):
        check_glue.glued(tmp_path)


def _math_page(**values):
    """A page whose cell glues each value as `chapter.theorems.glue_math` does: a
    Markdown object, whose text/plain is the same for every value."""
    from chapter.theorems import tex_number
    data = lambda v: {check_glue.MIME + "text/plain": "<IPython.core.display.Markdown object>",  # noqa: E731
                      check_glue.MIME + "text/markdown": f"${tex_number(v)}$"}
    outputs = [nbformat.v4.new_output("display_data", data=data(v),
                                      metadata={"scrapbook": {"name": k, "mime_prefix": check_glue.MIME}})
               for k, v in values.items()]
    return nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(f"# {sorted(values.items())}", outputs=outputs)])


def test_math_glue_is_compared_by_its_markdown(tmp_path, capsys):
    """Two pages that glue 1e-4 and 3e-4 as math under one name conflict.
    Wrong variant: comparing text/plain, as for a plain glue, sees two equal
    reprs and lets the conflict through."""
    cache = _cache(tmp_path, [("/b/s3_math.md", _math_page(pole_sin_phi=1e-4)),
                              ("/b/s5_lab.md", _math_page(pole_sin_phi=3e-4))])
    assert check_glue.main([str(cache)]) == 1
    assert r"pole_sin_phi: s3_math = $10^{-4}$, s5_lab = $3\cdot 10^{-4}$" in capsys.readouterr().err
    plain = lambda nb: {o["metadata"]["scrapbook"]["name"]: o["data"][check_glue.MIME + "text/plain"]  # noqa: E731
                        for c in nb["cells"] for o in c["outputs"]}
    assert plain(_math_page(x=1e-4)) == plain(_math_page(x=3e-4))


@pytest.mark.parametrize("x, tex", [(1e-3, "10^{-3}"), (1e-16, "10^{-16}"), (5e-4, r"5\cdot 10^{-4}"),
                                    (-1e-5, "-10^{-5}"), (2.5e-7, r"2.5\cdot 10^{-7}"), (0.47, "0.47"),
                                    (1.5, "1.5"), (256, "256"), (0.0, "0"),
                                    (1.25e-4, r"1.25\cdot 10^{-4}"), (-3.14159e-6, r"-3.14\cdot 10^{-6}")])
def test_tex_number(x, tex):
    from chapter.theorems import tex_number
    assert tex_number(x) == tex


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_tex_number_refuses_a_non_finite_number(bad):
    from chapter.theorems import tex_number
    with pytest.raises(ValueError, match="x must be a finite number"):
        tex_number(bad)


def _site(tmp_path, **pages):
    """A built site: one HTML page per keyword, its body the given HTML."""
    site = tmp_path / "html"
    site.mkdir(exist_ok=True)
    for name, body in pages.items():
        (site / f"{name}.html").write_text(f"<html><body><article>{body}</article></body></html>", encoding="utf-8")
    return site


NAMED = {"census_rms_slope": "rms slope", "census_off_slope": "off-band slope"}
VALUES = {"census_rms_slope": {"s5_lab": "0.5412"}, "census_off_slope": {"s5_lab": "2.19"}}


def test_words_carrying_their_value_pass(tmp_path):
    site = _site(tmp_path, s5_lab="<p>The RMS slope is <span class='pasted-text'>0.54</span> and the off-band "
                                  "slope 2.19.</p>", s6_ledger="<p>Its off-band slope, <b>2.2</b>, is second order.</p>")
    assert check_glue.words_conflicts(site, VALUES, NAMED) == []


def test_the_same_words_with_another_number_fail_wherever_the_number_comes_from(tmp_path):
    """The register's text (not a glued span) says 1.65 under the words that carry 0.54 in §5."""
    site = _site(tmp_path, s5_lab="<p>The RMS slope is 0.54; the off-band slope is 2.19.</p>",
                 s6_ledger="<li>fitted exponent: the RMS slope 1.65 over 1e-3 to 1e-5.</li>")
    bad = check_glue.words_conflicts(site, VALUES, NAMED)
    assert len(bad) == 1 and "s6_ledger: 'rms slope' is followed by 1.65" in bad[0]


@pytest.mark.parametrize("words", ["RMS slope", "rms  slope", "RMS\nslope", "RMS slopes", "rms-slope", "RMS‑slope",
                                   "Rms Slope"])
def test_the_words_are_met_in_any_case_spacing_hyphenation_or_plural(tmp_path, words):
    """The variants of a quantity's words a writer might type carry the rule with them: each, followed
    by the wrong number, is found (before: only the exact lower-case phrase with single spaces)."""
    site = _site(tmp_path, s5_lab="<p>The RMS slope is 0.54; the off-band slope is 2.19.</p>",
                 s6_ledger=f"<p>Measured, the {words} is −1.65e-3.</p>")
    bad = check_glue.words_conflicts(site, VALUES, NAMED)
    assert len(bad) == 1 and "is followed by −1.65e-3" in bad[0], bad


def test_a_rule_threshold_after_the_words_is_not_a_value(tmp_path):
    site = _site(tmp_path, s6_ledger="<p>Holds if RMS slope &gt; 1.8. The RMS slope is 0.54, the off-band slope 2.19.</p>")
    assert check_glue.words_conflicts(site, VALUES, NAMED) == []


def test_words_inside_maths_or_code_are_not_prose(tmp_path):
    site = _site(tmp_path, s5_lab="<p>RMS slope 0.54, off-band slope 2.19. <code>rms slope 9.9</code> "
                                  "<span class='math'>rms slope 7</span></p>")
    assert check_glue.words_conflicts(site, VALUES, NAMED) == []


def test_words_never_met_or_a_name_never_glued_or_words_inside_words_fail(tmp_path):
    site = _site(tmp_path, s5_lab="<p>The RMS slope is 0.54.</p>")
    bad = check_glue.words_conflicts(site, VALUES, {**NAMED, "extra": "slope"})
    assert any("prose never calls it 'off-band slope'" in b for b in bad)
    assert any("extra: glued nowhere" in b for b in bad)
    assert any("contain 'slope'" in b for b in bad)


def test_main_fails_on_words_with_two_values(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(check_glue, "NAMED", {"c3_rms_slope": "rms slope"})
    cache = _cache(tmp_path, [("/b/s5_lab.md", _page(c3_rms_slope=0.5412))])
    _site(tmp_path, s5_lab="<p>The RMS slope is 0.54.</p>", s6_ledger="<p>The RMS slope is 1.65.</p>")
    assert check_glue.main([str(cache)]) == 1
    assert "the same words carry different numbers" in capsys.readouterr().err
    _site(tmp_path, s6_ledger="<p>The RMS slope is 0.541.</p>")
    assert check_glue.main([str(cache)]) == 0


@pytest.mark.parametrize("shown, value, ok", [("0.54", 0.5412, True), ("0.54", 0.546, False), ("2.0e-15", 2.04e-15, True),
                                              ("2.0e-15", 2.7e-15, False), ("29,919", 29919, True), ("−0.3", -0.3, True),
                                              ("1e-9", 1.4e-9, True), ("1.4e-9", 1.9e-8, False)])
def test_a_number_matches_its_value_to_the_digits_shown(shown, value, ok):
    assert check_glue._matches(shown, value) is ok


# --- the registry: one quantity, one source, whatever its names ---------------------------------------

#: A registry of three quantities: one with two names and no library value, one with the library's
#: value (plain), one shown as math; and a name of its own.
REGISTRY = {"the gain": (("s4_gain", "c3_gain"), None), "the optimum": (("eps_fitted_sine",), lambda: 4.03e-7),
            "the black": (("s4_log_floor",), lambda: 1e-16)}
OWN = ("s1_size",)
SHOWN = {"s4_gain": {"s4_simulator": "100"}, "c3_gain": {"s5_lab": "100"}, "eps_fitted_sine": {"s5_lab": "4.03e-07"},
         "s4_log_floor": {"s4_simulator": "$10^{-16}$"}, "s1_size": {"s1_what_changes": "'256 × 256'"},
         "fig-x": {"s5_lab": "<Figure size 640x380 with 1 Axes>"}}


def test_a_registered_book_whose_names_agree_with_each_other_and_the_library_passes():
    assert quantity_conflicts(SHOWN, REGISTRY, OWN) == []


@pytest.mark.parametrize("change, message", [
    ({"c3_gain": {"s5_lab": "1000"}},
     "the gain: one quantity, two values: s4_simulator s4_gain = 100, s5_lab c3_gain = 1000"),
    ({"eps_fitted_sine": {"s5_lab": "3.73e-07"}},
     "the optimum: s5_lab eps_fitted_sine = 3.73e-07, but the library's value is 4.03e-07"),
    ({"s4_log_floor": {"s4_simulator": "$10^{-15}$"}}, "the library's value is 1e-16"),
    ({"s7_eps_opt": {"s7_pitfalls": "3.73e-07"}}, "s7_eps_opt: glued on s7_pitfalls, but registered nowhere"),
    ({"s1_size": {}}, "s1_size: registered, but no page glues it"),
    # A figure's name is exempt only where every page glues a figure under it: a number beside one is not.
    ({"fig-x": {"s5_lab": "<Figure size 640x380 with 1 Axes>", "s6_ledger": "3.73e-07"}},
     "fig-x: glued on s5_lab, s6_ledger, but registered nowhere"),
])
def test_two_values_of_one_quantity_an_unregistered_name_or_a_value_off_the_library_fail(change, message):
    shown = {k: v for k, v in {**SHOWN, **change}.items() if v}
    found = quantity_conflicts(shown, REGISTRY, OWN)
    assert any(message in line for line in found), found


def test_a_name_registered_twice_fails():
    assert quantity_conflicts(SHOWN, REGISTRY, OWN + ("c3_gain",)) == ["c3_gain: the name is registered twice"]


def test_the_books_glue_is_the_registrys_and_its_fitted_optimum_not_the_argmin(book_html, monkeypatch):
    """The built book: every glued name registered, every quantity one value under all its names and
    the library's where it holds one (stored measurements read from the build's store).  The same
    glue with the U-curve's optimum taken from its noisy argmin (the wrong variant) is caught."""
    monkeypatch.setenv("SYMRENDER_STORE", str(book_html.parent / ".measurements"))
    names = check_glue.glued(book_html.parent / ".jupyter_cache")
    assert quantity_conflicts(names) == []
    argmin = {**names, "eps_fitted_sine": {"s5_lab": repr(check_glue._ucurve().eps_measured_min)}}
    assert [line.split(":")[0] for line in quantity_conflicts(argmin)] == ["the fitted optimal step"]


def test_a_count_without_thousands_separators_is_found_and_years_dois_decimals_and_maths_are_not(tmp_path):
    """"on 13686 pixels" (a glue shown without ',', or a count typed into a measurement's text) fails;
    the book's 13,686, a year, a DOI, a decimal, an exponent and a number inside maths or code pass."""
    ok = ("<p>On 13,686 pixels (Blinn, 1978; doi:10.1137/S003614459631241X), 0.12345 and 1e-1000, "
          "2^-1022; <span class='math'>\\frac{1}{1000000}</span> <code>N = 4096</code>.</p>")
    assert check_glue.bare_counts(_site(tmp_path, s7_pitfalls=ok)) == []
    bad = check_glue.bare_counts(_site(tmp_path, s7_pitfalls=ok + "<li>It covers 13686 pixels.</li><td>2899</td>"
                                                                  "<td>84532.1336</td>"))
    assert [b.split(" in ")[0] for b in bad] == ["s7_pitfalls: 13686", "s7_pitfalls: 2899", "s7_pitfalls: 84532"], bad


def test_a_number_glued_without_a_separating_format_is_found_whatever_its_value_on_this_build(tmp_path):
    """A time glued as `ms:.0f` shows 986 here and 2286 on a slower machine: every number glued into
    prose by a format that can write four digits carries ','; e-formats, strings and flags need none."""
    names = {"ms": {"s5_lab": "986.25"}, "n": {"s5_lab": "12"}, "x": {"s5_lab": "1.5e-07"},
             "label": {"s5_lab": "'128 × 128'"}, "flag": {"s5_lab": "True"}}
    (tmp_path / "s5_lab.md").write_text("{glue:text}`ms:,.0f` {glue:text}`x:.1e` {glue:text}`label` "
                                        "{glue:text}`flag` {glue:text}`n:,` {glue:text}`x:,g`", encoding="utf-8")
    assert check_glue.unseparated_formats(names, tmp_path) == []
    (tmp_path / "s5_lab.md").write_text("{glue:text}`ms:.0f` {glue:text}`n` {glue:text}`x:g` {glue:text}`ms:.1%`",
                                        encoding="utf-8")
    bad = check_glue.unseparated_formats(names, tmp_path)
    assert [b.split(" (")[0] for b in bad] == ["s5_lab: {glue:text}`ms:.0f`", "s5_lab: {glue:text}`n`",
                                              "s5_lab: {glue:text}`x:g`", "s5_lab: {glue:text}`ms:.1%`"], bad


def test_main_fails_on_a_bare_count(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(check_glue, "words_conflicts", lambda *a: [])
    monkeypatch.setattr(check_glue, "quantity_conflicts", lambda names: [])
    monkeypatch.setattr(check_glue, "glued", lambda cache: {})
    site = _site(tmp_path, s7_pitfalls="<p>It covers 13686 pixels.</p>")
    assert check_glue.main([str(tmp_path / "cache"), str(site)]) == 1
    assert "s7_pitfalls: 13686" in capsys.readouterr().err


def test_a_negative_number_with_a_hyphen_is_found_and_exponents_ranges_words_and_maths_are_not(tmp_path):
    """"-0.651" in the prose fails wherever it stands (a glue, a table cell, a tuple); the minus sign,
    an exponent's hyphen, a range, a hyphenated word and a hyphen inside maths or code pass."""
    ok = ("<p>At −0.651 (−0.58, +0.61), 1.3e-12 and 2^-1022, pages 12-15, the k-1 term, a 3-D view; "
          "<span class='math'>x = -1</span> <code>eps = -1e-3</code>.</p>")
    assert check_glue.hyphen_minus(_site(tmp_path, s3_math=ok)) == []
    bad = check_glue.hyphen_minus(_site(tmp_path, s3_math=ok + "<p>h is <span class='pasted-text'>-0.6510</span>."
                                                        "</p><td>-9.252, +9.252</td><li>(-0.58, +0.61)</li>"))
    assert [b.split(" in ")[0].split()[1] for b in bad] == ["-0.6510.", "-9.252,", "-0.58,"], bad
