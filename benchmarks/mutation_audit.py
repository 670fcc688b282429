"""Mutation audit: does `pytest verify` catch realistic bugs, and do the tests?

Each mutant is one edit of the kind a person makes (a swapped pair, a dropped factor,
a moved threshold, a check that always passes, an off-by-one, a stale cache key, a
copy-paste slip).  Each is applied alone to a scratch copy of this working tree (the
files git tracks, plus untracked ones it does not ignore); an edit of
renderer/formulas.py is followed by ``python -m renderer.codegen``, so that it reaches
the kernel as a real change would.  Then ``pytest verify -x`` runs in the copy, and if
it passes, ``pytest tests -x -m "not audit"`` (without the audits of the built book,
which need one, and without tests/test_mutation_list.py, which fails on any mutant's
edit).  Nothing is written into the repository.  About a minute per mutant verify
kills, several per mutant that reaches the tests.

Two lists: `MUTANTS`, the first audit's, and `SECOND`, the second audit's (new kinds
of bug, across proofs/, lab/, renderer/ and its JavaScript, and book/).  Every old
text of the chosen mutants is checked to occur once in its file before anything runs.

Output: a Markdown table (mutant, file, the bug, killed by: codegen, verify, tests,
survived, or a timeout; the first failing test's node id; seconds), then the kill
rates: verify's, and the tests' of all mutants and of those verify missed.  With
``--baseline`` the unmutated copy runs first, and the audit stops if it does not pass
(a failing baseline would count every mutant as killed).

mutmut's own run covers lab/, proofs/ and the renderer's pure-Python references against
the tests `make test` runs in its own process (its configuration, and what it leaves out
and why, is ``[tool.mutmut]`` in pyproject.toml): ``pip install mutmut``, then ``mutmut run``
(or ``mutmut run "renderer.ucurve*"`` for one module) and ``mutmut results``, as mutmut
documents.  A mutant costs seconds (a survivor runs every test that reached its function):
on 2 cores one module takes minutes to an hour, all of them a day.  It cannot mutate the
numba kernel, the JavaScript, the pages or the build, which is what the mutants here cover.
A mutant of a function that runs at import or collection (a theorem's cases, the registry's
mapping, a theorem's wrong variants, which tests/test_checker.py's parameters hold) is never
active in its run (its workers fork after the tests were collected), and is reported as
surviving: run it in a new process, where the import runs it mutated:
``cd mutants && MUTANT_UNDER_TEST=<name> python -m pytest -x -p tests.mutmut_fresh <its tests>``.

Usage: python benchmarks/mutation_audit.py [--list first|second|all] [--baseline] [ID ...]
       (default: every mutant of both lists; IDs choose among the list's)
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT = 1800

#: (id, file, old text, new text, what the bug is).  Each old text occurs once in its file.
#: One or more per part: formulas, kernel, sweep, ledger, the simulator's JavaScript, the
#: checker engine, the claims register, the references, the figure encoding and the camera.
MUTANTS = [
    ("rings-k-u", "renderer/formulas.py", 'register(HeightField("rings", sp.sin(2 * sp.pi * k_v * v)))',
     'register(HeightField("rings", sp.sin(2 * sp.pi * k_u * v)))', "the rings field's frequency taken from k_u"),
    ("ridges-one-frequency", "renderer/formulas.py",
     "_s1, _s2 = sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_v * v)",
     "_s1, _s2 = sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_u * v)", "both factors of sine and ridges with k_u"),
    ("albedo-channel", "renderer/kernel.py", "    return (color[0] * (diffuse * albedo[0] + spec),",
     "    return (color[0] * (diffuse * albedo[2] + spec),", "red lit with the blue albedo"),
    ("specular-kd", "renderer/kernel.py", "    spec = (int_power(base, n) if n == s.shininess else base ** s.shininess) * s.ks",
     "    spec = (int_power(base, n) if n == s.shininess else base ** s.shininess) * s.kd", "the highlight weighted by kd"),
    ("floor-tint-inverted", "renderer/kernel.py", "    rg = base * (1.0 - s.floor_tint)",
     "    rg = base * s.floor_tint", "the floor tint applied inverted (the simulator keeps it)"),
    ("ambient-red-for-green", "renderer/kernel.py",
     "    r, g, b = s.ka * s.ambient[0], s.ka * s.ambient[1], s.ka * s.ambient[2]\n    for k in range(lights.shape[0]):",
     "    r, g, b = s.ka * s.ambient[0], s.ka * s.ambient[0], s.ka * s.ambient[2]\n    for k in range(lights.shape[0]):",
     "the shading takes the red ambient for green"),
    ("sweep-census-against-numeric", "renderer/sweep.py", "compare(frame, frames[0]) for frame in frames[1:]",
     "compare(frame, frames[1]) for frame in frames[1:]",
     "the sweep's census compares each step with the first numeric frame, not the exact one"),
    ("sweep-step-off-by-one", "renderer/kernel.py", "methods[f], steps[f], u, v,", "methods[f], steps[max(f - 1, 0)], u, v,",
     "the sweep shades frame f with the step before its own"),
    ("ledger-rms-per-pixel", "renderer/ledger.py", "rms=math.sqrt(sq / entries) if entries else 0.0,",
     "rms=math.sqrt(sq / pixels) if entries else 0.0,", "the RMS over pixels, not channel values"),
    ("ledger-squares", "renderer/ledger.py", "top, sq = max(top, d), sq + d * d", "top, sq = max(top, d), sq + d",
     "the ledger sums abs(dI), not its square"),
    ("js-srgb-gamma", "renderer/js/ledger.js", "1.055 * Math.pow(c, 1.0 / 2.4) - 0.055",
     "Math.pow(c, 1.0 / 2.2)", "the simulator encodes with gamma 2.2"),
    ("js-floor-tint", "renderer/js/render.js", "const rg = base * (1.0 - s.floor_tint);",
     "const rg = base * s.floor_tint;", "the simulator's floor tint inverted"),
    ("js-diffuse-ks", "renderer/js/render.js", "const diffuse = mu * s.kd;", "const diffuse = mu * s.ks;",
     "the simulator's Lambert term weighted by ks"),
    ("checker-skips-unevaluable", "proofs/core.py", "                raise Unevaluable(identity.label, point, e) from None",
     "                continue", "the checker skips points where an identity cannot be evaluated"),
    ("checker-nan-passes-probe", "proofs/core.py", "        if not r < tolerance:                       # a NaN",
     "        if r > tolerance:                       # a NaN", "the quick probe lets a NaN residual through"),
    ("checker-loose-tolerance", "proofs/core.py", "TOLERANCE_DIGITS = 20", "TOLERANCE_DIGITS = 2",
     "the numerical verdict's tolerance 1e-2"),
    ("checker-no-reach", "proofs/core.py", "    return any(steps[a].lhs == lhs and steps[b].rhs == rhs",
     "    return True or any(steps[a].lhs == lhs and steps[b].rhs == rhs",
     "a proof need not reach its statement"),
    ("register-nan-decides", "lab/claims.py", "            if not finite:", "            if False:",
     "a claim decided on a NaN measurement"),
    ("register-default-holds", "lab/claims.py", "def rule(*cases, otherwise=FAILS):",
     "def rule(*cases, otherwise=HOLDS):", "a claim holds when no case does"),
    ("ucurve-nominal-denominator", "renderer/ucurve.py", "/ mpmath.mpf(den)",
     "/ (2 * mpmath.mpf(e))",
     "the exact quotient over 2 eps, not the float denominator (roundoff misattributed)"),
    ("pixels-gradient-tolerance", "proofs/pixels.py", '"gradient": 64 * UNIT', '"gradient": 1e6 * UNIT',
     "the renderer's gradients compared loosely with mpmath"),
    ("png-truncates", "renderer/cli.py", "rgb8 = np.round(np.clip(", "rgb8 = np.floor(np.clip(",
     "8-bit values truncated, not rounded"),
    ("srgb-breakpoint", "renderer/ledger.py", "return np.where(c <= 0.0031308, 12.92 * c,",
     "return np.where(c <= 0.04045, 12.92 * c,", "the sRGB breakpoint of the decoding side"),
    ("camera-offset", "renderer/render.py", "WINDOW_MARGIN, WINDOW_OFFSET = 1.25, 0.15",
     "WINDOW_MARGIN, WINDOW_OFFSET = 1.25, -0.15", "the window shifted up, not down"),
    ("model-coefficient", "renderer/formulas.py", "ERROR_MODEL = sp.Add(sp.Mul(sp.Rational(1, 6),",
     "ERROR_MODEL = sp.Add(sp.Mul(sp.Rational(1, 2),", "the plotted U-curve model's truncation term over 2, not 6"),
]

#: The second audit: new kinds of bug, none of `MUTANTS`' kinds.  At least eight in proofs/ (the
#: engine and the theorem modules), five in lab/, the rest in renderer/ (Python and JavaScript) and
#: book/.  Each changes what a user or reader sees (a verdict, a ledger line, a printed number, a
#: frame, a report, a served measurement), on today's inputs or on an input the code accepts.
SECOND = [
    # ------------------------------------------------------------------ proofs/: the engine
    ("core-worst-step-residual", "proofs/core.py",
     'worst = max((v.residual for _, v in decided if v.status == "verified"), default=None)',
     'worst = min((v.residual for _, v in decided if v.status == "verified"), default=None)',
     "a theorem's residual is its best numerically verified step's, not its worst (the pin and the ledger "
     "see the smaller)"),
    ("core-claim-reach-last-step", "proofs/core.py",
     "for a in range(first, last + 1) for b in range(a, last + 1))",
     "for a in range(first, last + 1) for b in range(a, last))",
     "a claim cannot end at a chain's last step (off by one)"),
    ("core-verified-needs-both", "proofs/core.py",
     'status = "verified" if numeric or e.status == "verified" else "proved"',
     'status = "verified" if numeric and e.status == "verified" else "proved"',
     "a theorem with numerically verified steps is called proved when its evidence is"),
    ("core-link-compared-with-itself", "proofs/core.py",
     "v = _decide(t, step, before, step.lhs, rewrites)",
     "v = _decide(t, step, step.lhs, step.lhs, rewrites)",
     "a link's left side is compared with itself, not with the previous step's right side"),
    # ------------------------------------------------------------------ proofs/: the theorems
    ("frame-evidence-chart-bump-only", "proofs/frame.py",
     'for b in ("chart", "surface")])', 'for b in ("chart",)])',
     "frame-orthonormal's evidence compares the chart bump's normals only"),
    ("kink-loci-last-circle", "proofs/kink_loci.py",
     "_circle_angle()(np.arange(int(np.floor(k_v)) + 1), k_v)",
     "_circle_angle()(np.arange(int(np.floor(k_v))), k_v)",
     "the circle v = 1 (phi = pi) left out of the v-creases (off by one)"),
    ("kink-loci-half-width-small-angle", "proofs/kink_loci.py",
     "return float(np.arcsin(float(F.KINK_BAND_HALF_WIDTH)) / (np.pi * k))",
     "return float(float(F.KINK_BAND_HALF_WIDTH) / (np.pi * k))",
     "the predicted crease band's half-width w / (pi k), the small-angle reading of asin(w) / (pi k)"),
    ("normal-rate-tolerance", "proofs/normal.py",
     "abs(slope - order) <= 0.1", "abs(slope - order) <= 1.0",
     "the fitted order of the beta -> 0 limit accepted within 1, not 0.1"),
    ("gradients-scale-without-2", "renderer/formulas.py",
     "rates = set().union(*(_argument_rates(r.expr) for r in records))",
     "rates = set().union(*(_argument_rates(r.expr) for r in records[:1]))",
     "the gradient scale from the first field alone, pi max(k_u, k_v): the factor 2 of the rings' h_v lost"),
    ("pixels-spacing-sign", "proofs/pixels.py",
     "spacing = (g.x[1] - g.x[0], g.y[0] - g.y[1])", "spacing = (g.x[1] - g.x[0], g.y[1] - g.y[0])",
     "the footprint reference fed the row spacing with its sign flipped"),
    # ------------------------------------------------------------------ lab/
    ("census-ratio-first-step", "lab/claims.py",
     'on, off = (out[key][CENSUS_STEPS.index(scene.eps)] for key in ("on_band", "off_band"))',
     'on, off = (out[key][0] for key in ("on_band", "off_band"))',
     "the census's crease ratio taken at the first step, not the default one"),
    ("stacking-any-sample-on-a", "lab/claims.py",
     ".all(axis=(1, 3))", ".any(axis=(1, 3))",
     "the stacking claim's pixels: any of the 16 samples on sphere A, not all"),
    ("errata-leak-ignores-cast-shadow", "lab/seed_errata.py",
     "leak = (cos_geo <= 0) & (cos_bump > 0) & ~cast", "leak = (cos_geo <= 0) & (cos_bump > 0)",
     "the terminator leak counts pairs in sphere B's cast shadow"),
    ("errata-specular-sphere-a-only", "lab/seed_errata.py",
     "for kind in (SPHERE_A, SPHERE_B):", "for kind in (SPHERE_A,):",
     "the ungated lobe counted on sphere A only"),
    ("errata-v-border-copy-paste", "lab/seed_errata.py",
     'out["rel_change"].append(float(rel.max())', 'out["nearer"].append(float(rel.max())',
     "the v-border erratum's relative change appended to the list of shares nearer the exact h_v"),
    ("beta-order-forward", "lab/accuracy.py", "        return (hi - lo) / (2 * db)",
     "        return (hi - render(scene, size, size).image) / db",
     "the image's beta-derivative order measured with a forward difference (first order)"),
    ("dn-closed-form-projects-on-n", "proofs/normal.py", "CLAIMED_DERIVATIVE = (sp.Identity(3) - NP_S * NP_S.T)",
     "CLAIMED_DERIVATIVE = (sp.Identity(3) - NP_S * N_S.T)",
     "the closed form of dN'/dbeta projecting g on the unbumped N"),
    ("store-key-without-params", "lab/store.py",
     'if (record["name"], record["params"], record["digest"]) != (name, params, source_digest()):',
     'if (record["name"], record["digest"]) != (name, source_digest()):',
     "a stored measurement served for other parameters (stale cache key)"),
    ("store-digest-without-chapter", "lab/store.py",
     'PACKAGES = ("renderer", "proofs", "lab", "chapter")', 'PACKAGES = ("renderer", "proofs", "lab")',
     "the source digest misses book/chapter (a stored theorem block outlives its code)"),
    ("pareto-strictly-better-in-both", "lab/gradient_benchmark.py",
     "((t < t[i]) | (e < e[i]))", "((t < t[i]) & (e < e[i]))",
     "a method dominated only if strictly better in time and error (ties in one kept on the front)"),
    ("beta-order-intercept", "lab/accuracy.py",
     "fit = lambda e: float(np.polyfit(np.log(steps), np.log(e), 1)[0])",
     "fit = lambda e: float(np.polyfit(np.log(steps), np.log(e), 1)[1])",
     "the beta-derivative's order read from the fit's intercept, not its slope"),
    # ------------------------------------------------------------------ renderer/
    ("kernel-phong-without-mu", "renderer/kernel.py",
     "spec_cos = 2.0 * mu * spec_cos - wv", "spec_cos = 2.0 * spec_cos - wv",
     "Phong's reflected ray without its factor N . w"),
    ("bands-last-row", "renderer/render.py",
     "return [(j, min(j + rows, height)) for j in range(0, height, rows)]",
     "return [(j, min(j + rows, height - 1)) for j in range(0, height, rows)]",
     "the last band stops a row short (the bottom row never rendered)"),
    ("render-pixel-limit-exclusive", "renderer/render.py",
     "if width * height > MAX_PIXELS:", "if width * height >= MAX_PIXELS:",
     "a 4096 x 4096 frame refused, though documented as accepted"),
    ("sweep-iterator-cut-silently", "renderer/sweep.py",
     "itertools.islice(eps_values, MAX_STEPS + 1)", "itertools.islice(eps_values, MAX_STEPS)",
     "a sweep of 65 steps cut to 64 without an error"),
    ("ucurve-crease-crossing", "renderer/ucurve.py",
     "if abs(slope) > mpmath.mpf(10) ** (-DIGITS // 2) and", "if abs(slope) >= 0 and",
     "where two creases cross (h_u exists, it is 0) the U-curve says there is no derivative"),
    ("ucurve-one-sided-from-outside", "renderer/ucurve.py",
     "true = _real(dh_mp, X + mpmath.mpf(10) ** -(DIGITS - 10) * (-1 if x == 1.0 else 1))",
     "true = _real(dh_mp, X + mpmath.mpf(10) ** -(DIGITS - 10))",
     "at u or v = 1 the one-sided reference taken from beyond the chart"),
    ("pointwise-eps_v-unchecked", "renderer/pointwise.py",
     'RANGES_CENTRAL = {**RANGES, "u": UNIT, "v": UNIT, "eps_v": RANGES["eps"]}',
     'RANGES_CENTRAL = {**RANGES, "u": UNIT, "v": UNIT}',
     "central_gradient's eps_v checked as a coordinate: 0 or a negative step accepted"),
    ("cli-kink-dimmed-in-linear", "renderer/cli.py",
     "out = 0.4 * to_srgb(selected.image)", "out = to_srgb(0.4 * selected.image)",
     "the kink view dimmed before the sRGB encoding, not after it (the simulator's 40 % of the byte)"),
    ("cli-sweep-json-size-swapped", "renderer/cli.py",
     'doc = {"size": [width, height],', 'doc = {"size": [height, width],',
     "the sweep's JSON report gives the size as [height, width]"),
    ("cli-ucurve-minimum-swapped", "renderer/cli.py",
     'measured minimum {uc.error_at_measured_min:.3e} at eps {uc.eps_measured_min:.3e}"',
     'measured minimum {uc.eps_measured_min:.3e} at eps {uc.error_at_measured_min:.3e}"',
     "the U-curve report prints the measured minimum's step and error under each other's labels"),
    ("js-field-terms-key-without-k_v", "renderer/js/render.js",
     "const key = `${s.field} ${s.k_u} ${s.k_v}`;", "const key = `${s.field} ${s.k_u}`;",
     "the simulator keeps the crease band, h and the exact gradient when k_v changes (stale cache key)"),
    ("js-pair-key-without-gradient", "renderer/js/render.js",
     'numeric: [scene.height_field, scene.k_u, scene.k_v, numeric, numeric === "central"',
     'numeric: [scene.height_field, scene.k_u, scene.k_v, numeric === "central"',
     "the simulator keeps the numeric frame when its gradient changes from central to footprint"),
    ("curve-steps-off-by-one", "renderer/ledger.py",
     "range(2 * (SLIDER_LOG_EPS[1] - SLIDER_LOG_EPS[0]) + 1)", "range(2 * (SLIDER_LOG_EPS[1] - SLIDER_LOG_EPS[0]))",
     "the simulator's U-curve stops half a decade short of the slider's largest step"),
    ("js-curve-stride-floor", "renderer/js/simulator.js",
     "Math.max(1, Math.ceil(resolution / CURVE_SAMPLE))", "Math.max(1, Math.floor(resolution / CURVE_SAMPLE))",
     "the U-curve's sampling stride rounded down: more than CURVE_SAMPLE pixels a side"),
    # ------------------------------------------------------------------ book/
    ("book-proof-link-shown-bare", "book/chapter/latex.py",
     "        if step.lhs != sides[-1]:", "        if False:",
     "a calc link's rewritten left side dropped: the chain shows the step proving the rewrite"),
    ("core-citation-unchecked", "proofs/core.py",
     "unknown = [i for i in citations(text) if i not in CITABLE]", "unknown = []",
     "a citation of an id that is no theorem passes"),
    ("book-numeric-step-unexplained", "book/chapter/theorems.py",
     "unexplained = [k for k in numeric if not t.steps[k - 1].why_numeric]", "unexplained = []",
     "a VERIFIED box prints a numeric step without saying why sympy left it"),
    ("book-tex-number-two-digits", "book/chapter/theorems.py",
     'mantissa, exponent = f"{x:.2e}".split("e")', 'mantissa, exponent = f"{x:.1e}".split("e")',
     "the prose's small numbers to two significant digits, not three"),
    ("glue-words-a-full-unit", "book/check_glue.py",
     "return abs(float(shown) - value) <= 0.5 * unit * (1 + 1e-9) + 1e-300",
     "return abs(float(shown) - value) <= unit * (1 + 1e-9) + 1e-300",
     "a number in prose accepted within a whole unit of its last digit, not half"),
    ("glue-oldest-record", "book/check_glue.py",
     "record.accessed > latest[record.uri].accessed", "record.accessed < latest[record.uri].accessed",
     "check_glue reads the page's oldest cached execution, not the current one"),
    ("simulator-bundle-stamp-ignored", "book/_ext/simulator_assets.py",
     'stamp.is_file() and stamp.read_text(encoding="utf-8") == source_digest()',
     "stamp.is_file()",
     "the simulator's bundle is not made again when the sources change (stale build output)"),
    ("floor-checker-swapped", "renderer/kernel.py", "    base = FLOOR_LIGHT if checker >= 0.0 else FLOOR_DARK",
     "    base = FLOOR_DARK if checker >= 0.0 else FLOOR_LIGHT", "the floor's light and dark squares swapped"),
]

#: The lists by name.
LISTS = {"first": MUTANTS, "second": SECOND}


def scratch_copy(into: Path) -> Path:
    """The working tree's tracked and unignored files, copied into ``into``."""
    names = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT, check=True,
                           capture_output=True).stdout.decode().split("\0")
    for name in filter(None, names):
        if (ROOT / name).is_file():
            (into / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, into / name)
    return into


#: A failing test in pytest's short summary (``-ra``): "FAILED node - message" or "ERROR node".
_FAILED = re.compile(r"^(?:FAILED|ERROR) (\S+)", re.MULTILINE)


def run(copy: Path, *args):
    """(passed, first failing test's node id or "", timed out) of ``python -m <args>`` in ``copy``
    (its packages first on the path; the build's store and site of this shell left out)."""
    env = {**os.environ, "PYTHONPATH": f"{copy}{os.pathsep}{copy / 'book'}", "NUMBA_CACHE_DIR": str(copy / ".numba")}
    for name in ("SYMRENDER_BOOK_HTML", "SYMRENDER_STORE"):
        env.pop(name, None)
    try:
        done = subprocess.run([sys.executable, "-m", *args], cwd=copy, env=env, capture_output=True, text=True,
                              timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return False, "", True
    failed = _FAILED.search(done.stdout)
    return done.returncode == 0, failed.group(1) if failed else "", False


#: The test that holds each mutant's old text to occur once in its file: in a mutated copy it would
#: fail on the mutant's own edit, and count every mutant as killed.
MUTATION_LIST_TEST = "tests/test_mutation_list.py"


def check(mutants):
    """Refuse, before anything runs, a mutant whose old text does not occur exactly once in its file
    or whose new text is the old one."""
    for name, path, old, new, _ in mutants:
        count = (ROOT / path).read_text(encoding="utf-8").count(old)
        if count != 1 or new == old:
            raise SystemExit(f"mutant {name}: its old text occurs {count} times in {path}, not once"
                             if count != 1 else f"mutant {name}: its new text is its old text")


def audit(mutant):
    """(who killed ``mutant``: 'codegen', 'verify', 'tests', 'survived', 'timeout (verify)' or
    'timeout (tests)'; the first failing test; seconds).  ``mutant`` None: the unmutated copy."""
    with tempfile.TemporaryDirectory(prefix="symrender-mutant-") as tmp:
        copy = scratch_copy(Path(tmp))
        path = None
        if mutant is not None:
            name, path, old, new, _ = mutant
            text = (copy / path).read_text(encoding="utf-8")
            if text.count(old) != 1:
                raise SystemExit(f"mutant {name}: its old text occurs {text.count(old)} times in {path}, not once")
            (copy / path).write_text(text.replace(old, new), encoding="utf-8")
        start = time.monotonic()
        if path == "renderer/formulas.py":
            ok, _, late = run(copy, "renderer.codegen")
            if not ok:
                return "timeout (codegen)" if late else "codegen", "", time.monotonic() - start
        for who, args in (("verify", ("pytest", "verify", "-x", "-q", "-p", "no:cacheprovider")),
                          ("tests", ("pytest", "tests", "-x", "-q", "-n", "2", "-p", "no:cacheprovider",
                                     "-m", "not audit", "--ignore", MUTATION_LIST_TEST))):
            ok, failed, late = run(copy, *args)
            if not ok:
                return f"timeout ({who})" if late else who, failed, time.monotonic() - start
        return "survived", "", time.monotonic() - start


def rates(results):
    """The kill rates of (killed by, ...) results: verify's of all, the tests' of all and of those
    verify missed, as lines of text."""
    n = len(results)
    verify = sum(r == "verify" or r == "codegen" for r in results)
    tests = sum(r == "tests" for r in results)
    missed = n - verify
    pct = lambda a, b: f"{a}/{b} ({100 * a / b:.0f} %)" if b else "0/0"  # noqa: E731
    return [f"verify killed {pct(verify, n)}; the tests killed {pct(tests, n)} of all and "
            f"{pct(tests, missed)} of those verify missed; {pct(n - verify - tests, n)} survived or timed out"]


def main(argv):
    p = argparse.ArgumentParser(prog="mutation_audit.py", description=__doc__.splitlines()[0])
    p.add_argument("--list", choices=("first", "second", "all"), default="all", help="which list (default all)")
    p.add_argument("--baseline", action="store_true", help="run the unmutated copy first; stop if it fails")
    p.add_argument("ids", nargs="*", help="mutant ids of the list (default: every one)")
    args = p.parse_args(argv)
    pool = MUTANTS + SECOND if args.list == "all" else LISTS[args.list]
    unknown = sorted(set(args.ids) - {m[0] for m in pool})
    if unknown:
        raise SystemExit(f"no mutant {', '.join(unknown)} in the list {args.list!r}")
    chosen = [m for m in pool if not args.ids or m[0] in args.ids]
    check(chosen)
    if args.baseline:
        who, failed, seconds = audit(None)
        if who != "survived":
            raise SystemExit(f"the unmutated copy fails ({who}: {failed or 'no test named'}, {seconds:.0f} s): "
                             "fix that first, or every mutant counts as killed")
        print(f"baseline: the unmutated copy passes verify and the tests in {seconds:.0f} s\n", flush=True)
    print("| mutant | file | the bug | killed by | first failing test | seconds |\n|---|---|---|---|---|---:|",
          flush=True)
    results, total = [], time.monotonic()
    for m in chosen:
        who, failed, seconds = audit(m)
        results.append(who)
        print(f"| `{m[0]}` | `{m[1]}` | {m[4]} | {who} | {f'`{failed}`' if failed else ''} | {seconds:.0f} |",
              flush=True)
    print("\n" + "\n".join(rates(results)) + f"\ntotal {time.monotonic() - total:.0f} s", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
