"""Mutation audit: does the proof checker catch realistic bugs, and do the tests?

Each semantic mutant in `MUTANTS` is one edit of the kind a person makes (a
swapped pair, a dropped factor, a moved threshold, a check that always
passes), applied alone to a scratch copy of this working tree (the files git
tracks, plus untracked ones not ignored).  After the edit, ``python -m
renderer.codegen`` regenerates the kernel's formulas when the edit is in
renderer/formulas.py, so that the mutant reaches the renderer as a real
change would.  Then ``pytest verify -x`` runs; a mutant it does not kill goes
on to ``pytest tests -x``.  Outcome per mutant: killed by verify, killed by
tests, or survived (listed with the reason it is acceptable, `ACCEPTED`, or
flagged).  Not run in CI: it takes about a minute per mutant killed by
verify and several per mutant that reaches the tests.

``--mutmut`` instead runs mutmut 3 (``pip install mutmut``) over each scope
of ``MUTMUT_SCOPES`` (modules, the tests named beside them), each in its own
scratch copy, and writes results/mutmut.md (kill rate per module, survivors).
mutmut runs the covering tests once per mutant.  The theorem modules' scope
runs the theorem checks of ``verify/test_theorems.py`` (seconds each, renders
included) in forkserver isolation, so that no cache warmed by the clean run
(`proofs.pixels`' frames) hides a mutant; its 3,000-odd mutants take about ten
hours on two cores, so it runs for ``--budget`` minutes (mutmut takes the
fastest mutants first) and the report counts the rest as not checked.  With
``--work DIR`` the scratch copies stay in DIR and a second run resumes where
the first stopped; ``--budget 0`` only collects what DIR holds.  mutmut cannot
mutate the numba kernel (its trampolines are Python calls, which compiled code
cannot make) nor module-level code (formulas.py's sympy, the theorems'
statements), which is why the semantic mutants cover those.  A function that
runs while the tests are imported does run under mutmut, but unmutated there
(mutmut imports before it switches a mutant on): ``--fresh MIN`` runs such
functions' survivors again, each in a new interpreter with the mutant on from
the start.  With ``--mutants`` only the scopes the globs name run; the report
keeps the earlier rows of the modules a run did not check.

Results: benchmarks/results/mutation_audit.md (and .json).  With ``--only`` the
named mutants are run again and their rows replace the earlier ones (from the
.json, or else the .md table), so a fix can be re-audited without a full run.
Usage: python benchmarks/mutation_audit.py [--only ID ...] [--mutmut [--work DIR] [--budget MIN] [--fresh MIN]
       [--mutants GLOB ...]] [--out FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYTHON = sys.executable
TIMEOUT = 1800

#: (id, file, old text, new text, what the bug is). Each old text occurs once in its file.
MUTANTS = [
    ("normal-swap", "renderer/formulas.py", '"chart": (beta * h_u, beta * h_v),',
     '"chart": (beta * h_v, beta * h_u),', "h_u and h_v swapped in the perturbed normal"),
    ("u-not-wrapped", "renderer/formulas.py", "(u_p, sp.Piecewise((u + eps_u - 1, u + eps_u >= 1), (u + eps_u, True))),",
     "(u_p, u + eps_u),", "u not wrapped in the central difference"),
    ("v-border-2eps", "renderer/formulas.py",
     "_den_v = sp.Piecewise((v_p - v_m, sp.Or(v + eps_v > 1, v - eps_v < 0)), (2 * eps_v, True))",
     "_den_v = 2 * eps_v", "the v border divided by 2 eps"),
    ("pole-3e-4", "renderer/formulas.py", "POLE_SIN_PHI = sp.Float(1e-4)", "POLE_SIN_PHI = sp.Float(3e-4)",
     "the pole threshold moved from 1e-4 to 3e-4"),
    ("chart-offset", "renderer/formulas.py", "CHART = ((sp.atan2(N_y, N_x) + sp.pi) / (2 * sp.pi),",
     "CHART = ((sp.atan2(N_y, N_x) - sp.pi) / (2 * sp.pi),", "u offset by -pi instead of +pi"),
    ("chart-acos", "renderer/formulas.py", "sp.atan2(sp.sqrt(N_x**2 + N_y**2), N_z) / sp.pi,",
     "sp.acos(N_z) / sp.pi,", "v from acos(N_z) (the draft's chart)"),
    ("fallback-frame", "renderer/formulas.py", "FALLBACK_FRAME = (1, 0, 0, 0, 1, 0)",
     "FALLBACK_FRAME = (0, 1, 0, 1, 0, 0)", "the pole fallback frame's axes swapped"),
    ("ephi-sign", "renderer/formulas.py", "N_z * N_x / sin_phi, N_z * N_y / sin_phi, -sin_phi)",
     "-N_z * N_x / sin_phi, -N_z * N_y / sin_phi, sin_phi)", "e_phi with the opposite sign"),
    ("surface-2", "renderer/formulas.py", '"surface": (_w * h_u / (2 * sp.pi * sp.Max(sin_phi, POLE_SIN_PHI)), _w * h_v / sp.pi),',
     '"surface": (_w * h_u / (sp.pi * sp.Max(sin_phi, POLE_SIN_PHI)), _w * h_v / sp.pi),',
     "the surface bump without the factor 2 of du/dtheta"),
    ("kink-width", "renderer/formulas.py", "KINK_BAND_HALF_WIDTH = sp.Float(0.03)",
     "KINK_BAND_HALF_WIDTH = sp.Float(0.3)", "the crease band ten times wider"),
    ("footprint-half", "renderer/formulas.py", "half = (sp.Abs(d[0]) + sp.Abs(d[1])) / 2",
     "half = sp.Abs(d[0]) + sp.Abs(d[1])", "the footprint without pbrt's factor 1/2"),
    ("sphere-b-no-shadow", "renderer/kernel.py", "    if code != SPHERE_B and (s.sphere_b or not skip):",
     "    if code == FLOOR and (s.sphere_b or not skip):", "sphere B no longer shadows sphere A"),
    ("light-inside", "renderer/kernel.py", "    if k < 0.0:\n        return True",
     "    if k < 0.0:\n        return False", "a light inside a sphere is not blocked"),
    ("far-root", "renderer/kernel.py", "    return near if near > 0.0 else (far if far > 0.0 else math.inf)",
     "    return far if far > 0.0 else math.inf", "the far root of the ray quadratic"),
    ("phong-factor", "renderer/kernel.py", "        spec_cos = 2.0 * mu * spec_cos - wv",
     "        spec_cos = mu * spec_cos - wv", "Phong's reflection without the factor 2"),
    ("no-ambient-ka", "renderer/kernel.py",
     "    r, g, b = s.ka * s.ambient[0], s.ka * s.ambient[1], s.ka * s.ambient[2]\n    view = (0.0, 0.0, 0.0)",
     "    r, g, b = s.ambient[0], s.ambient[1], s.ambient[2]\n    view = (0.0, 0.0, 0.0)",
     "ambient not scaled by ka (render; the sweep keeps it)"),
    ("central-eps-v", "renderer/kernel.py", "    eu = ev = eps\n", "    eu, ev = eps, 2 * eps\n",
     "the central difference in v with step 2 eps"),
    ("kink-inverted", "renderer/kernel.py", "            if want_kink:\n                kink[j, i] = flag",
     "            if want_kink:\n                kink[j, i] = not flag", "the crease flag written inverted"),
    ("beta0-shortcut", "renderer/kernel.py", "    et0, et1, et2, ep0, ep1, ep2 = frame\n",
     "    et0, et1, et2, ep0, ep1, ep2 = frame\n    if s.beta == 0.0:\n        return N\n",
     "the beta = 0 shortcut put back (N' = N without normalising)"),
    ("gate-always", "renderer/pointwise.py", "check_flag(\"gate\", gate), out)", "True, out)",
     "pointwise.reach always gated by the bumped normal"),
    ("ledger-all-pixels", "renderer/ledger.py", "            if a != SPHERE_A or b != SPHERE_A:\n                continue\n",
     "", "the ledger sums over every pixel, not sphere A"),
    ("check-always-proved", "proofs/core.py", "    for simplifier in (sp.expand,",
     "    return True\n    for simplifier in (sp.expand,", "the identity checker decides every identity true"),
    ("unit-roundoff", "proofs/ucurve.py", "UNIT_ROUNDOFF = 2.0**-53", "UNIT_ROUNDOFF = 2.0**-52",
     "the unit roundoff 2^-52 instead of 2^-53"),
    ("reference-digits", "proofs/ucurve.py", "DIGITS = 50", "DIGITS = 15",
     "the U-curve's reference at 15 digits, float64's own"),
    ("statement-drift", "proofs/normal.py", "M_CLAIMED = sp.MatAdd(N_S, F.beta * G_S, evaluate=False)",
     "M_CLAIMED = sp.MatAdd(N_S, -F.beta * G_S, evaluate=False)",
     "a theorem's statement edited (M = N - beta g): printed from the object the check substitutes into"),
    ("claim-threshold", "proofs/claims.py", 'rule(HOLDS, Bound("on/off ratio", 3, 30))',
     'rule(HOLDS, Bound("on/off ratio", 3, 30000))', "a claim's pass range widened until it holds"),
    ("erratum-criterion", "proofs/seed_errata.py", 'present=lambda m: m["max_rel_error_acos"] > 1e-3 and',
     'present=lambda m: m["max_rel_error_acos"] > -1 and', "an erratum's presence criterion made vacuous"),
    ("blinn-orientation", "proofs/blinn.py", "ORIENTATION = sp.simplify(N_BLINN.dot(N) / NORM_N)",
     "ORIENTATION = -sp.simplify(N_BLINN.dot(N) / NORM_N)", "Blinn's normal taken outward (F = +beta h)"),
    ("pixels-tolerance", "proofs/pixels.py", 'TOLERANCE = {"chart": 16 * UNIT, "gradient": 64 * UNIT, "normal": 64 * UNIT}',
     'TOLERANCE = {"chart": 1.0, "gradient": 1.0, "normal": 1.0}', "the renderer-output tolerances made vacuous"),
]

#: Survivors that are acceptable, with the reason (a mutant not listed here that survives is flagged).
ACCEPTED = {
    "pixels-tolerance": "only loosens a check: every renderer output still matches, so nothing can fail",
}
#: Why `pytest verify` alone lets these through (tests/ must kill them).
VERIFY_MISSES = {
    "phong-factor": "the shading model (Lambert plus Phong or Blinn) is no theorem of the chapter: the "
                    "theorems stop at N'; tests/ compares the kernel's Phong mode with the scalar reference",
    "beta0-shortcut": "at beta = 0 the shortcut returns N, which is unit already, so N' differs from the "
                      "normalised N by rounding only: the limit theorem holds either way; tests/ fails on "
                      "the changed bits",
}


def _tree_files():
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard"], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout.split("\n")
    return [f for f in out if f and not f.startswith(("book/_build", "benchmarks/results"))]


def _scratch(d=None):
    """A scratch copy of the working tree (in ``d``, if given; files that differ are
    replaced); returns its path and the files replaced or added."""
    d = Path(d) if d else Path(tempfile.mkdtemp(prefix="mutation-audit-"))
    changed = []
    for f in _tree_files():
        src = ROOT / f
        if src.is_file() and not ((d / f).is_file() and (d / f).read_bytes() == src.read_bytes()):
            (d / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, d / f)
            changed.append(f)
    return d, changed


def _run(cmd, cwd):
    env = dict(os.environ, PYTHONPATH=str(cwd), NUMBA_CACHE_DIR=str(cwd / ".numba_cache"))
    env.pop("SYMRENDER_STORE", None)
    try:
        return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=TIMEOUT).returncode
    except subprocess.TimeoutExpired:
        return "timeout"


def check_mutants():
    """Every mutant's old text occurs exactly once in its file (ValueError naming the mutant if not)."""
    for mid, path, old, _, _ in MUTANTS:
        count = (ROOT / path).read_text(encoding="utf-8").count(old)
        if count != 1:
            raise ValueError(f"mutant {mid}: its text occurs {count} times in {path}, expected once")


def audit(mutant, work):
    """Apply one mutant in the scratch copy ``work``, run the checks, restore; returns the outcome."""
    mid, path, old, new, _ = mutant
    target = work / path
    original = target.read_text(encoding="utf-8")
    try:
        target.write_text(original.replace(old, new, 1), encoding="utf-8")
        if path == "renderer/formulas.py":
            if _run([PYTHON, "-m", "renderer.codegen"], work) != 0:
                return "killed by the generator"
        t0 = time.time()
        if _run([PYTHON, "-m", "pytest", "verify", "-x", "-q", "-p", "no:cacheprovider"], work) != 0:
            return f"verify ({time.time() - t0:.0f} s)"
        if _run([PYTHON, "-m", "pytest", "tests", "-x", "-q", "-p", "no:cacheprovider"], work) != 0:
            return f"tests ({time.time() - t0:.0f} s)"
        return "survived"
    finally:
        target.write_text(original, encoding="utf-8")
        if path == "renderer/formulas.py":
            _run([PYTHON, "-m", "renderer.codegen"], work)


#: mutmut's scopes: a module and the tests that exercise it (fast enough to run per mutant).
#: (modules, tests, isolation, run for at most --budget minutes)
THEOREM_MODULES = tuple(f"proofs/{m}.py" for m in (
    "frame", "gradients", "kinks", "kink_loci", "no_boundary", "normal", "finite_difference",
    "displacement", "blinn", "pixels", "registry"))
MUTMUT_SCOPES = ((("proofs/store.py",), "tests/test_store.py", "fork", False),
                 (("proofs/core.py",), "tests/test_core.py", "fork", False),
                 (("proofs/claims.py",), "tests/test_claim_rules.py", "fork", False),
                 (THEOREM_MODULES, "verify/test_theorems.py", "forkserver", True))


#: Why a mutmut survivor is equivalent or acceptable: (module, pattern searched in "before → after", reason).
#: A survivor no pattern explains is flagged in the report.
MUTMUT_EXPLAINED = (
    ("proofs/store.py", r'encoding=(None|"UTF-8")|"w", \)',
     "equivalent: a record is ASCII JSON (json escapes the rest), the same bytes in any ASCII-compatible encoding"),
    ("proofs/store.py", r"mkstemp\(",
     "the temporary file's name is gone once it is renamed over the record; without dir= it would sit in "
     "the system's temporary directory, which matters only when that is another file system"),
    ("proofs/store.py", r"_locked\(None\)",
     "the lock is for pages run in parallel processes: test_pages_running_at_once_compute_a_measurement_once "
     "fails without it, but runs `measured` in subprocesses, where mutmut's per-test coverage does not see it"),
    ("proofs/store.py", r'"XXnameXX"|"NAME"',
     "the record's name field is for a reader of the file; the store finds a record by its file name"),
    ("proofs/store.py", r'b"XX\\0XX"',
     "another separator makes another, equally injective digest: only the digest's value changes"),
    ("proofs/store.py", r"sort_keys",
     "with a store directory a record's parameters are compared as dicts, in any order; in-process the "
     "order is tested (test_without_a_store_parameters_in_any_order_are_one_measurement)"),
    ("proofs/core.py", r"if expr == 1:",
     "equivalent: the first simplifier (expand) maps 0 to 0; the line is a shortcut"),
    ("proofs/core.py", r"continue → break",
     "in the handler for sympy's own failures (TypeError, ValueError, NotImplementedError), which no "
     "identity here provokes"),
    ("proofs/core.py", r"lambda e: None",
     "simplify after expand_trig is a fallback: every identity of the tests and the theorems is decided "
     "by another simplifier or sampled"),
    ("proofs/core.py", r"mpmath\.mpf\(1\)|r >= worst or where is None|if r > worst:",
     "equivalent: the first point always sets the worst (where is None); ties only change which of two "
     "equal residuals is reported"),
    ("proofs/core.py", r"seed [-+] 100[01] [-+] i|seed - i|_numeric_residual\(comp, None|, 4, digits\)",
     "another seed or a fourth probe point is an equally valid sample: no verdict changes"),
    ("proofs/core.py", r"if r > tolerance:|if worst <= tolerance:",
     "differs only at a residual exactly equal to the tolerance, 1e-20"),
    ("proofs/core.py", r"and False else sp\.Matrix",
     "equivalent: sp.Matrix of a column matrix is the same matrix"),
    ("proofs/claims.py", r"abs\(x\) (<= 1e6|< 1000001\.0)",
     "differs only for the integer 1,000,000 itself, which no claim shows"),
    ("proofs/no_boundary.py", r"x__seed_attached_predicate__",
     "builds a wrong variant, the seed's attached rule with the bumped N': any N' it is fed (either gradient, "
     "components in any order) contains beta, which is what refutes the variant"),
)
MUTMUT_EXPLAINED += (
    ("proofs/frame.py", r"x__check_(frame|chart)__mutmut_\d+: .*(verdict\.residual, verdict\.digits, verdict\.points, "
     r"count\)|PERTURBED_NORMAL in this frame)",
     "the identities' residual, digits and points (None when sympy decided them all, as here) or the evidence "
     "text; the status and the renderer count are unchanged"),
    ("proofs/frame.py", r"if worst >= TOLERANCE\[",
     "differs only when the worst error equals the tolerance (64 or 16 units of roundoff) exactly"),
    ("proofs/frame.py", r"x__check_orientation__mutmut_\d+: if not verdict\.holds: → if verdict\.holds:",
     "the verdict's evidence text: a verdict that holds keeps its status, without the handedness sentence"),
    ("proofs/kink_loci.py", r"x__loci__mutmut_\d+: .*(what = |family = |frame_label\(|\.join\(|"
     r"return Verdict\(symbolic\.status, f)",
     "the verdict's evidence text, for a reader of the ledger; the status it carries is unchanged"),
    ("proofs/kink_loci.py", r"x__tex__",
     "the statement's typesetting (sp.latex of the checked expressions: term order, symbol names); the "
     "checks compare the expressions, and no check reads the LaTeX back"),
    ("proofs/kink_loci.py", r"if mismatched > 1:|per_locus > 1,",
     "differs only with exactly one mismatched pixel, or a visible locus with exactly one crease pixel; "
     "the wrong variants mismatch hundreds, and the fewest crease pixels of a visible locus is 4"),
    ("proofs/kink_loci.py", r"np\.ones\(len\(per_locus\), (dtype=None|)\)|dtype=None|dtype=float\), \)|"
     r"np\.asarray\(phi_, \)|modules=None|, \)\(\*at\)",
     "equivalent: the values are float64 already (np.array_equal compares 1.0 with True by value), and "
     "lambdify's default modules include numpy"),
    ("proofs/kink_loci.py", r"k_u\), \)$|\(\*at\), \),$",
     "equivalent: the values are float64 already"),
    ("proofs/kink_loci.py", r"band_scale=2\.0\):$",
     "the other family's bands, which only take pixels out of the comparison: twice as wide, they take "
     "more (thousands are still compared)"),
    ("proofs/kink_loci.py", r"np\.pi / band_scale \*",
     "equivalent at band_scale 1; in the wrong variant (2) the bands come out half as wide instead of twice, "
     "and are refuted either way"),
    ("proofs/frame.py", r"c \+ fallback == 0",
     "equivalent: the only component sympy folds is e_theta's z, 0 in both branches, so c + 0 is c - 0"),
    ("proofs/kink_loci.py", r"\(\*at\) >= 0\)|\(r >= lo\)|\(r <= hi\)|np\.abs\(off\) <= ",
     "differs only for a pixel exactly on a band's edge or a circle exactly on the horizon"),
    ("proofs/kink_loci.py", r"arange\(int\(np\.floor\(k_v\)\) [-+] [12]\)",
     "adds or drops only circles past the horizon (phi_m >= 3 pi/4 at k_v = 4): their bands are empty either "
     "way, and only the evidence's list of circles changes"),
    ("proofs/kink_loci.py", r"ray_angles\(scene\.k_u\)\[:, None, None\] \+ shift|\[None\] \+ ray_angles|"
     r"\[:, None, None\] - shift$",
     "equivalent: the rays' angles are symmetric under negation (k_u = 8), and a shift of half a period is "
     "the same either way"),
    ("proofs/kink_loci.py", r"rho, \)|drho, \)|drho=drho\) → .*rho=rho, \)",
     "drho reaches the bands only in a wrong variant that its identity (d rho/d phi) refutes first"),
    ("proofs/kink_loci.py", r"count_nonzero\(mine & \(rendered \| where\)",
     "equivalent once no pixel mismatches (checked first): on the compared pixels the rendered flag is the "
     "predicted band"),
    ("proofs/kink_loci.py", r"x__check__mutmut_\d+: .*or True else symbolic",
     "runs the render comparison for identities that failed as well; the verdict keeps their status"),
    ("proofs/kink_loci.py", r"Identity\(\"y\", y_img, rho \* sp\.sin\(theta\), (None|)\)",
     "the sampling domain, used only if sympy cannot decide the identity, which it does"),
    ("proofs/finite_difference.py", r"sp\.latex\(None\)",
     "the verdict's evidence text, for a reader of the ledger; the status it carries is unchanged"),
)
MUTMUT_EXPLAINED += (
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: def footprint_error\(half=0\.5, size=96\): → .*half=1\.5",
     "fixed since this run: footprint_error's half has no default any more (its only caller passes it)"),
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: .*(size=97\)|zoom in \((2\.0|1\.0), (300|301)\.0\)|"
     r"gbuffer\(scene, size, size, \))",
     "another frame or zoom: an equally valid sample of sphere-A pixels (the kernel and the rule agree on every "
     "pixel of each)"),
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: .*\"IJ,IJ->I\"",
     "equivalent: einsum's subscripts are letters of either case"),
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: .*lstsq\(a, b, \)",
     "equivalent: the 3x2 systems have full rank, and rcond only drops singular values below its cutoff"),
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: .*np\.where\(\((s >= 0|s > 0)\) [&|] \((s <= limit|s < limit)\)"
     r", np\.minimum\(s, cap\), (fallback|None)\)\)$",
     "differs only for a footprint step exactly 0 or at least FOOTPRINT_LIMIT (1e8), which no sphere-A pixel "
     "of these frames has"),
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: .*np\.abs\(have - want\) \* want",
     "scales the difference by the step (at most 0.25) instead of dividing by it: a kernel off by 1e-9 relative "
     "on any step above the fallback (5e-4) still fails"),
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: (count \+= int\(x\.size\) → count = |worst, count = 0\.0, 0 → )",
     "the evidence's pixel count: still above its pinned least count (registry.RENDERED); the comparison is "
     "unchanged"),
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: dx, dy = g\.x\[1\] - g\.x\[0\], g\.y\[0\] - g\.y\[1\] → ",
     "the pixel spacing is an input to both the kernel and the rule, which agree for any spacing; the spacing "
     "the renderer passes is checked through its footprint gradients (theorems gradient-*)"),
    ("proofs/pixels.py", r"x_footprint_error__mutmut_\d+: dpdu, dpdv = .* → .*(np\.pi / R \* sin_phi|np\.pi / R \* ep)",
     "fixed since this run: footprint_error runs at R = 0.8, where a lost factor R gives a relative error of 0.56"),
    ("proofs/frame.py", r"x_vector_latex__", "the statement's typesetting (sp.latex of the checked vectors); the "
     "checks compare the expressions, and no check reads the LaTeX back"),
    ("proofs/blinn.py", r"x__tex__|x__slopes_tex__", "the statement's typesetting (sp.latex of the checked slopes); "
     "the checks compare the expressions, and no check reads the LaTeX back"),
    ("proofs/normal.py", r"x__check_derivative__mutmut_\d+: if not verdict\.holds: → if verdict\.holds:$",
     "a holding verdict then goes out without the evidence's 'renderer.formulas.PERTURBED_NORMAL' prefix, a refuted "
     "one wrapped with its status kept: the statuses are unchanged"),
    ("proofs/normal.py", r"x__render_rate__mutmut_\d+: flat = render\(scene, 96, 80, gradient=gradient\)\.image → "
     r"flat = render\(scene, 96, 80, \)\.image$",
     "equivalent: at beta = 0 the exact and central pipelines render the same image bit for bit (N + 0 g = N), "
     "for every field and bump mode"),
    ("proofs/normal.py", r"x__render_rate__mutmut_\d+: across_fields \+= int\(np\.count_nonzero\(flat != base\)\) → "
     r"across_fields (=|-=) int\(np\.count_nonzero\(flat != base\)\)$",
     "the count of field-dependent beta = 0 values: the last field's alone, or negated, is still nonzero when any "
     "field reaches the image (the variant with the reference at beta = 1e-12 is still refuted)"),
    ("proofs/normal.py", r"x__render_rate__mutmut_\d+: if k == 0: → if k == 1:$",
     "the configurations' distinct images counted at beta = 1e-3 instead of 1e-2: another beta > 0, where each of "
     "the 12 reaches the image as well (and the one-field variant gives 4 of 12 alike)"),
    ("proofs/normal.py", r"x__render_rate__mutmut_\d+: renders \+= 1 → renders \+= 2$",
     "the evidence's render count: still above its pinned least count (registry.RENDERED); the comparison is "
     "unchanged"),
    ("proofs/normal.py", r"x__check_limit__mutmut_\d+: line = worst\[-2\] \* TINY_BETA / RATE_BETAS\[-1\] → "
     r"line = worst\[-3\] \* TINY_BETA / RATE_BETAS\[-1\]$",
     "the linear rate's allowance at 1e-12 drawn through the 1e-7 render instead of the 1e-8 one: 10 times looser, "
     "which still refutes the variant whose last render sits 25 times above the tight allowance"),
    ("proofs/normal.py", r"x__check_limit__mutmut_\d+: if not \(abs\(slope - order\) <= 0\.1 and worst\[-1\] <= 4 \* line "
     r"\+ 4 \* 2\.0\*\*-52\): → if not \(abs\(slope - order\) (< 0\.1 and worst\[-1\] <= 4 \* line \+ 4 \* 2\.0\*\*-52|"
     r"<= 0\.1 and worst\[-1\] (< 4 \* line \+ 4 \* 2\.0\*\*-52|<= 4 \* line - 4 \* 2\.0\*\*-52|<= 5 \* line \+ 4 \* 2\.0\*\*-52|"
     r"<= 4 \* line \+ 5 \* 2\.0\*\*-52|<= 4 \* line \+ 4 \* 3\.0\*\*-52|<= 4 \* line \+ 4 \* 2\.0\*\*-53))\):$",
     "the order's tolerance or the allowance at 1e-12 moved by at most a quarter (or by a few units of roundoff): the "
     "renderer's fitted order is 1.00 and its difference a quarter of the allowance, the wrong variants' order 1 off "
     "and difference 25 times the allowance"),
    ("proofs/normal.py", r"x__check_limit__mutmut_\d+: .*(the difference is \{worst\[-1\]:\.1e\}|the linear rate allows \{4 \* "
     r"line:\.1e\}|at beta = \{RATE_BETAS\[0\]:g\} only \{distinct\} of the|\{distinct\} distinct at beta = |\"renders \(fields x bump modes x pipelines\) "
     r"differ|\(\{worst\[0\]:\.1e\} to "
     r"\{worst\[-2\]:\.1e\}\), \{worst\[-1\]:\.1e\}|bit for bit\", rendered=renders\)).* → ",
     "the verdict's evidence text (which measurement it prints), for a reader of the ledger; the status it carries "
     "is unchanged"),
    ("proofs/normal.py", r"x_tilt_latex__", "the statement's typesetting (sp.latex of the checked tilt); the "
     "checks compare the expressions, and no check reads the LaTeX back"),
    ("proofs/frame.py", r"x__chart_identities__mutmut_\d+: .*RATES_CLAIMED\[[01]\], (None|)\),$",
     "the sampling domain, used only if sympy cannot decide the identity, which it does"),
)
MUTMUT_EXPLAINED += (
    ("proofs/gradients.py", r"x_generated_code_residual__mutmut_\d+: (.*seed=1, points|.*Random\(None\)|taken = 0 → "
     r"taken = 1|taken \+= 1 → taken \+= 2|while taken < points: → while taken <= points:|.*rng\.uniform\((0\.5|1\.5), (12|13)\.0\), "
     r"rng\.uniform\((0\.5|1\.5), (12|13)\.0\)$)",
     "another seed, another number of points, or k drawn from a slightly other range: an equally valid sample"),
    ("proofs/gradients.py", r"x_generated_code_residual__mutmut_\d+: (if name == \"ridges\" and .* → if name (!= \"ridges\""
     r"|== \"XXridgesXX\"|== \"RIDGES\")|.*mpmath\.pi (\*|/) k[uv] (\*|/) [uv]{2}\)+ <?=? ?(< )?1e-9:?|.* < 1e-9: → .* <= 1e-9:)",
     "which points near a ridges crease are skipped (or also skipped for the smooth fields): another valid sample, "
     "where the float64 sign factor is decided"),
    ("proofs/gradients.py", r"x_generated_code_residual__mutmut_\d+: .* → .*mpmath\.pi (\*|/) ku (\*|/) uu\)\),$",
     "which points near a ridges crease are skipped: another valid sample, where the float64 sign factor is "
     "decided"),
    ("proofs/gradients.py", r"x_generated_code_residual__mutmut_\d+: continue → break",
     "stops the sample at the first point near a ridges crease: fewer points, each within the tolerance "
     "(the renderer's own gradients are compared at hundreds of pixels after this)"),
    ("proofs/gradients.py", r"x_generated_code_residual__mutmut_\d+: scale = mpmath\.pi \* max\(ku, 2 \* kv\) → ",
     "another normalising scale for the error (within a factor 48 of this one): float64 errors of a few "
     "units of roundoff stay far inside the 1e-13 tolerance, and a wrong formula far outside"),
    ("proofs/displacement.py", r"x__check__mutmut_\d+: .*Identity\(\"G_theta \(rings\)\".*|.*sp\.diff\((-sp\.pi \* R / rings|"
     r"-sp\.pi / R \* rings|\+sp\.pi \* R \* rings), theta\)",
     "equivalent: the rings field does not depend on theta, so any multiple of it has theta-derivative 0"),
    ("proofs/displacement.py", r"x__check__mutmut_\d+: .*sp\.diff\(-sp\.pi \* R \* rings, (theta|phi)\), (None|)\)",
     "the sampling domain, used only if sympy cannot decide the identity, which it does"),
    ("proofs/displacement.py", r"x__check__mutmut_\d+: .*\{found (or|and) '(no field|XXno fieldXX|NO FIELD)'\}|"
     r"'XX, XX'\.join\(found\)",
     "the verdict's evidence text, for a reader of the ledger; the status it carries is unchanged"),
    ("proofs/displacement.py", r"x__check__mutmut_\d+: .*by \{worst:\.2e\}\", (worst|None), (rendered=(compared|None)|)\)$",
     "a refutation's residual and renderer count, which nothing reads: a refuted theorem fails the build "
     "whatever they are"),
    ("proofs/displacement.py", r"x__kernel_identities__mutmut_\d+: .*CHART_COEFFS\[1\], (None|)\)\]$",
     "the sampling domain of b_v's identity, used only if sympy cannot decide it, which it does"),
    ("proofs/displacement.py", r"x_surface_normal_residual__mutmut_\d+: def .* → .*bump=\"(XXsurfaceXX|SURFACE)\"\):$",
     "fixed since this run: surface_normal_residual's bump and gradient have no defaults (its only caller "
     "passes them)"),
    ("proofs/displacement.py", r"x__check__mutmut_\d+: if worst > 1e-12: → if worst > 1\.000000000001:",
     "fixed since this run: a new wrong variant, the central-difference pipeline's surface normals, differs "
     "by 0.41 and is refuted only with the 1e-12 threshold"),
    ("proofs/displacement.py", r"x__check__mutmut_\d+: .*by \{worst:\.2e\}\", worst, rendered=compared\) → "
     r".*by \{worst:\.2e\}\", rendered=compared\)$",
     "a refutation's residual, which nothing reads: a refuted theorem fails the build whatever it is"),
    ("proofs/displacement.py", r"x__check__mutmut_\d+: if worst > 1e-12: → if worst >= 1e-12:",
     "differs only when the worst difference is exactly 1e-12"),
    ("proofs/displacement.py", r"x_surface_normal_residual__mutmut_\d+: .*simultaneous=(None|False)\)$|"
     r"_PHI_OF_V\}, \)$",
     "equivalent: theta(u) and phi(v) contain neither theta nor phi, so one substitution after the other "
     "is the simultaneous one"),
    ("proofs/displacement.py", r"x_surface_normal_residual__mutmut_\d+: .*> float\(F\.POLE_SIN_PHI\) → .*>= float",
     "differs only for a pixel with sin phi exactly POLE_SIN_PHI"),
    ("proofs/displacement.py", r"x_surface_normal_residual__mutmut_\d+: (.*left_out [-+] int\(np\.count_nonzero\((None|keep)\)\)"
     r"|.*left_out - int|worst, compared, left_out = 0\.0, [01], [01] → )",
     "the counts in the evidence (pixels left out inside the pole floor; compared, still above the pinned "
     "least count, registry.RENDERED); the comparison is unchanged"),
)
MUTMUT_EXPLAINED += (
    ("proofs/gradients.py", r"x__theorem__mutmut_\d+: .* → (rf\"\$h_u = \{sp\.latex\((None|hu)\)\}\$ and \$h_v = \{sp\.latex\((None|hv)"
     r"\)\}\$|\s*r\"(XXgenerated code evaluates them to float64 accuracy\.XX|GENERATED CODE EVALUATES THEM TO FLOAT64 "
     r"ACCURACY\.)\"\),|statement=\(rf\"For \$h = \{sp\.latex\(None\)\}\$: \")",
     "the statement's typesetting (sp.latex of the checked expressions); the checks compare the expressions, and "
     "no check reads the LaTeX back"),
    ("proofs/gradients.py", r"x__theorem__mutmut_\d+: .* → .*\(r\"(H_U|XXh_uXX|H_V|XXh_vXX)\", sp\.Derivative",
     "a step's caption in the book; the step's two sides are checked (test_a_step_the_book_shows_holds)"),
    ("proofs/gradients.py", r"x__theorem__mutmut_\d+: .* → \s*\(\"(THE KERNEL'S H_U AND H_V SWAPPED|XXthe kernel's h_u and "
     r"h_v swappedXX)\",",
     "a wrong variant's description, the test's name; the variant itself is unchanged"),
    ("proofs/gradients.py", r"x__gradient_check__mutmut_\d+: .*Identity\(f\"h_[uv] \(\{name\}\)\", .* → "
     r".*Identity\(None, F\.GRADIENT",
     "an identity's label: it names the component in a refutation's evidence; the check compares lhs and rhs only"),
    ("proofs/gradients.py", r"x__theorem__mutmut_\d+: .*corrupt=lambda g: g\[:, ::-1\]\)+, → .*corrupt=lambda g: "
     r"g\[:, ::-2\]\)+,$",
     "the swapped-gradient variant then keeps h_v alone (a one-column array), another wrong gradient, which the "
     "check refutes as well"),
    ("proofs/gradients.py", r"x__theorem__mutmut_\d+: (.* → .*(title=None|pages=(None|\(\"(S3|XXs3XX)\", \"s5\"\)|"
     r"\(\"s3\", \"(S5|XXs5XX)\"\))),|pages=\(\"s3\", \"s5\"\), → \) → \))$",
     "fixed since this run: test_every_theorem_is_titled_and_used_on_pages_that_place_it checks each theorem's "
     "title and that its pages exist and include the page whose theorem block shows it"),
    ("proofs/gradients.py", r"x__gradient_check__mutmut_\d+: return Verdict\(\"refuted\", f\"generated \(compiled\) .* → "
     r"return Verdict\(None, ",
     "fixed since this run: a wrong variant (the kernel's gradient in float32) now reaches the compiled-code "
     "refutation, and test_wrong_variant_is_refuted asks for its status"),
    ("proofs/blinn.py", r"x__check__mutmut_\d+: if not verdict\.holds: → if verdict\.holds:$",
     "a holding verdict then goes out without the evidence's explanation, a refuted one wrapped with its status "
     "kept: the statuses are unchanged"),
    ("proofs/blinn.py", r"x__identities__mutmut_\d+: .*, DOMAIN\)+,? → .*, (None|)\)+,?$",
     "the sampling domain, used only if sympy cannot decide an identity; it decides all of them (the pinned "
     "verdict is proved)"),
    ("proofs/blinn.py", r"x__identities__mutmut_\d+: def _identities\(normal, factors, \*, exact=False\): → "
     r"def _identities\(normal, factors, \*, exact=True\):$",
     "fixed since this run: the default was never used (its only caller passes exact) and is gone"),
    ("proofs/blinn.py", r"x__identities__mutmut_\d+: ids\.append\(Identity\(r\"\\text\{all orders: surface vs Blinn\}\", "
     r"SURFACE, blinn, DOMAIN\)\) → ids\.append\(Identity\((r\"[^\"]+\", None, blinn|r\"[^\"]+\", SURFACE, None|"
     r"SURFACE, blinn|r\"[^\"]+\", blinn|r\"[^\"]+\", SURFACE), DOMAIN\)\)$",
     "the all-orders identity is built only for the wrong variant that claims it; broken (a side None or missing) it "
     "still refutes that variant, and the holding check never builds it"),
    ("proofs/blinn.py", r"x__check__mutmut_\d+: (return Verdict\(\"refuted\", \"the surface bump's pole floor|"
     r"\"found in renderer\.formulas\.PERTURBED_NORMAL\['surface'\]\"\) → )",
     "the guard for a surface bump without its pole floor, which only an edit of renderer/formulas.py's module-level "
     "sympy can reach (the semantic mutants do); every mutant of this return (status None, no evidence, a missing "
     "argument) still fails the pinned verdict, as the guard should"),
    ("proofs/blinn.py", r"x__at_angles__mutmut_\d+: .* → return expr\.subs\(_TO_ANGLES, (simultaneous=(None|False)|)\)"
     r"\.applyfunc\(sp\.simplify\)$",
     "equivalent: u(theta) and v(phi) contain neither u nor v, so one substitution after the other is the "
     "simultaneous one"),
)
MUTMUT_EXPLAINED += (
    ("proofs/finite_difference.py",
     r"x__border_rule__mutmut_\d+: (u_p = .* → u_p = u \+ eps - 1 if u \+ eps > 1 else u \+ eps|"
     r"u_m = .* → u_m = u - eps \+ 1 if u - eps <= 0 else u - eps|"
     r"return .* → .*\((v \+ eps >= 1 or v - eps < 0|v \+ eps > 1 or v - eps <= 0)\) else 2 \* eps)$",
     "differs only where u + eps, u - eps, v + eps or v - eps is exactly 1 or 0 in float64, which none of the "
     "2,000 seeded border points is (and for v both branches then give the same distance, 2 eps)"),
    ("proofs/finite_difference.py",
     r"x__border_rule__mutmut_\d+: return .* → .*\((v \+ eps > 1 or v - eps < 0\) or True|"
     r"v \+ eps > 1 or v - eps < 1\)) else 2 \* eps$",
     "the rule then divides by v_p - v_m everywhere (v - eps < 1 holds for every v in [0, 1]), which away from "
     "the v borders is 2 eps up to rounding, about 1e-10 relative at the smallest step (1e-6), inside the "
     "quotient's 1e-9 tolerance"),
    ("proofs/finite_difference.py",
     r'x__check_truncation__mutmut_\d+: "clamp v and divide by the clamped distance"\) → '
     r'"(XXclamp v and divide by the clamped distanceXX|CLAMP V AND DIVIDE BY THE CLAMPED DISTANCE)"\)$',
     "the border refutation's evidence text, for a reader of the ledger; the status it carries is unchanged"),
    ("proofs/finite_difference.py",
     r"x__check_truncation__mutmut_\d+: if fp > 1e-9: → if fp >= 1e-9:$",
     "differs only for a footprint error of exactly 1e-9; the kernel's is about 1e-13 and the wrong variant's 0.5"),
    ("proofs/finite_difference.py",
     r"x__check_truncation__mutmut_\d+: verdict\.residual, verdict\.digits, verdict\.points, pixels\) → "
     r"(None, verdict\.digits, verdict\.points|verdict\.residual, None, verdict\.points|"
     r"verdict\.residual, verdict\.digits, None), pixels\)$",
     "the identities are proved (the pinned verdict), so their residual, digits and points are None already; "
     "the status and the pixel count are unchanged"),
    ("proofs/finite_difference.py",
     r'x__kernel_identities__mutmut_\d+: return \[Identity\(rf"\\text\{\{CENTRAL\[\{name\}\]\}\}_\{var\}", '
     r"(.*) → return \[Identity\(None, \1$",
     "an identity's label: it names the component in a refutation's evidence; the check compares lhs and rhs only"),
    ("proofs/finite_difference.py",
     r"(x__kernel_identities__mutmut_\d+: def _kernel_identities\(denominator=2\): → "
     r"def _kernel_identities\(denominator=3\):|x_quotient__mutmut_\d+: def quotient\(h, var, denominator=2\): → "
     r"def quotient\(h, var, denominator=3\):)$",
     "fixed since this run: the default was never used (every call passes the denominator) and is gone"),
    ("proofs/finite_difference.py",
     r"x_central_series__mutmut_\d+: return sp\.series\(q, eps, 0, order\)\.removeO\(\)\.doit\(\) → "
     r"return sp\.series\(q, eps, (None, order|0, )\)\.removeO\(\)\.doit\(\)$",
     "equivalent: sympy's Expr.series expands about 0 when x0 is falsy (None), and its default order n is 6, "
     "which is ORDER"),
    ("proofs/finite_difference.py",
     r"x_interior__mutmut_\d+: .*lambda e: e\.args\[-1\]\.expr\) → .*lambda e: e\.args\[\+1\]\.expr\)$",
     "equivalent: every Piecewise of the kernel's stencil points and v-denominator has two branches, so args[1] "
     "is args[-1]"),
    ("proofs/finite_difference.py",
     r"x_border_mismatches__mutmut_\d+: (def border_mismatches\(samples=2000, seed=12, rule=_border_rule\): → "
     r"def border_mismatches\((samples=2001, seed=12|samples=2000, seed=13), rule=_border_rule\):|"
     r"rng = random\.Random\(seed\) → rng = random\.Random\(None\))$",
     "one more point, or another seed or none: an equally valid sample of border points, at each of which the "
     "kernel matches the rule, and where every border variant is still refuted"),
    ("proofs/finite_difference.py",
     r"x_interior_branch_mismatches__mutmut_\d+: (def interior_branch_mismatches\(samples=2000, seed=11\): → "
     r"def interior_branch_mismatches\((samples=2001, seed=11|samples=2000, seed=12)\):|"
     r"rng = random\.Random\(seed\) → rng = random\.Random\(None\))$",
     "one more point, or another seed or none: an equally valid sample of interior points, every one of which "
     "is compared and takes the interior branch"),
    ("proofs/finite_difference.py",
     r'x_(border|interior_branch)_mismatches__mutmut_\d+: .*modules="math"\) → (.*modules=None\)|.*, \)|\))$',
     "lambdify's default modules (numpy) give the same float64 values for the stencil's sums, min and max, and "
     "sines within a few ulps of math's, far inside the quotient's 1e-9 tolerance"),
    ("proofs/finite_difference.py",
     r"x_border_mismatches__mutmut_\d+: step = 10\.0 \*\* rng\.uniform\(-6, -1\) → step = "
     r"(11\.0 \*\* rng\.uniform\(-6, -1\)|10\.0 \*\* rng\.uniform\((\+6, -1|-7, -1|-6, \+1|-6, -2)\))$",
     "another range of steps (base 11, 1e-7 to 0.1, 1e-6 to 0.01, 1e-6 to 10 or 0.1 to 1e6): the kernel and the "
     "rule do the same float64 operations at any step, and every wrap and clamp is still taken, so each border "
     "variant is still refuted"),
    ("proofs/finite_difference.py",
     r"x_interior_branch_mismatches__mutmut_\d+: step = 10\.0 \*\* rng\.uniform\(-9, -1\) → step = "
     r"(11\.0 \*\* rng\.uniform\(-9, -1\)|10\.0 \*\* rng\.uniform\((-10, -1|-9, -2)\))$",
     "another range of small steps (4e-10 to 0.09, 1e-10 to 0.1, or 1e-9 to 0.01): an equally valid sample, "
     "all 2,000 points still interior, compared, and on the interior branch"),
    ("proofs/finite_difference.py",
     r"x_border_mismatches__mutmut_\d+: ([uv])_ = rng\.choice\(.* → \1_ = rng\.choice\(\(rng\.uniform\((0\.0|1\.0), "
     r"step\), rng\.uniform\((1\.0|2\.0) [-+] step, (1\.0|2\.0)( [-+] (1e-12|1\.000000000001))?\), "
     r"rng\.uniform\((0, 1|1, 1|0, 2)\)\)\)$",
     "one of the three intervals u or v is drawn from moved: every wrap and clamp is still reached (within a step "
     "of 0 or 1 also through uniform(0, 1), steps up to 0.1; beyond 1 on the same branch as just below), the "
     "kernel matches the rule at any point, and each border variant is still refuted"),
    ("proofs/finite_difference.py",
     r"x_border_mismatches__mutmut_\d+: bad \+= list\(got\) .* → bad -= list\(got\) |"
     r"x_interior_branch_mismatches__mutmut_\d+: bad \+= full\(.* → bad -= full\(",
     "the count comes out negative, which is as truthy as a positive one: the check refutes at the same points, "
     "and only the evidence's count changes sign"),
    ("proofs/finite_difference.py",
     r"x_border_mismatches__mutmut_\d+: .* → .*abs\(central_v\(u_, v_, None, step\) - quotient\)",
     "equivalent: the v-quotient's stencil points and denominator use eps_v only, so the value passed for eps_u "
     "is never read"),
    ("proofs/finite_difference.py",
     r"x_border_mismatches__mutmut_\d+: .* → .*- quotient\) >= 1e-9 \* \(1 \+ abs\(quotient\)\)$",
     "differs only when the kernel's quotient is off by exactly the tolerance"),
    ("proofs/finite_difference.py",
     r"x_border_mismatches__mutmut_\d+: .* → .*- quotient\) > 1e-9 (/ \(1|\* \(2) \+ abs\(quotient\)\)$",
     "a tolerance at most (1 + 2 pi)^2 times tighter (|h_v| <= 2 pi for the sampled sine field) or under twice "
     "as loose: the kernel evaluates the same quotient up to rounding, and the border variant misses by up to "
     "50 percent"),
    ("proofs/finite_difference.py",
     r"x_interior_branch_mismatches__mutmut_\d+: if u_ \+ step < 1\.0 and u_ - step >= 0\.0 and v_ \+ step <= 1\.0 "
     r"and v_ - step >= 0\.0: → if (u_ \+ step < 1\.0 and u_ - step >= 0\.0 and v_ \+ step <= 1\.0 or |"
     r"u_ \+ step < 1\.0 and u_ - step >= 0\.0 or |u_ \+ step < 1\.0 or |u_ - step < 1\.0 |u_ \+ step <= 1\.0 |"
     r"u_ \+ step < 2\.0 |u_ \+ step < 1\.0 and u_ \+ step >= 0\.0 |.* and v_ - step <= 1\.0 and |"
     r".* and v_ \+ step <= 2\.0 and |.* and v_ \+ step >= 0\.0:$)",
     "the seeded u_ and v_ lie in [step, 1 - step], where every clause of this guard holds (all 2,000 points "
     "pass), so a weakened clause admits the same points"),
    ("proofs/finite_difference.py",
     r"x_interior_branch_mismatches__mutmut_\d+: if u_ \+ step < 1\.0 and u_ - step >= 0\.0 and v_ \+ step <= 1\.0 "
     r"and v_ - step >= 0\.0: → if .*(u_ - step > 0\.0 and v_ \+ step <= 1\.0|v_ \+ step < 1\.0 and|"
     r"v_ - step > 0\.0:$)",
     "differs only where u_ - step, v_ + step or v_ - step is exactly 0 or 1, which none of the 2,000 seeded "
     "points is (all pass the strict test too)"),
)
MUTMUT_EXPLAINED += (
    ("proofs/kinks.py", r"x__identities__mutmut_\d+: (?P<p>.*)sp\.diff\(sp\.Abs\(x\), x\)(?P<r>.*) → "
     r"(?P=p)sp\.diff\(sp\.Abs\(x\), \)(?P=r)$",
     "equivalent: without a variable sp.diff differentiates in the expression's only free symbol, x"),
    ("proofs/kinks.py", r"x__identities__mutmut_\d+: \{x: \(-3\.0, 3\.0\)\}\), → "
     r"(None\)|\)|\{x: \((\+3\.0, 3\.0|-4\.0, 3\.0|-3\.0, 4\.0)\)\}\)),$",
     "the sampling domain of d|x|/dx = sign(x), never read: for x real and nonzero sympy builds diff(Abs(x), x) "
     "as sign(x) itself, so lhs - rhs is 0 with no symbol left to sample"),
    ("proofs/kinks.py", r"x__identities__mutmut_\d+: (?P<k>.*(sp\.Integer\([01]\)|sp\.Integer\(flag\)|"
     r"sp\.Abs\(FACTORS\[0\] \* FACTORS\[1\]\))), DOMAIN\)(?P<t>\]?,?) → (?P=k), (None|)\)(?P=t)$",
     "the sampling domain, never read: lhs - rhs is 0 as sympy builds it (h is Abs(s1 s2) itself, sin(pi m) is 0 "
     "for the integer m, the flag's Piecewise evaluates to 0 or 1), so no symbol is sampled, and a wrong lhs "
     "would still fail the test, sampling raising without a domain"),
    ("proofs/kinks.py", r'x__identities__mutmut_\d+: (?P<p>.*)Identity\((?:rf"[^"]*"|None),(?P<r>.*) → '
     r'(?P=p)Identity\((?:rf"[^"]*"|None),(?P=r)$',
     "an identity's label (an f-string here): the name a refutation's evidence shows; the check compares lhs "
     "and rhs only"),
    ("proofs/kinks.py", r'x_one_sided__mutmut_\d+: (right|left) = sp\.limit\((.*), delta, 0, "\+"\) → '
     r"\1 = sp\.limit\(\2, delta, 0, \)$",
     "equivalent: \"+\" is sp.limit's default direction"),
    ("proofs/kinks.py", r'x_one_sided__mutmut_\d+: (right = sp\.limit\(\(expr\.subs\(var, at \+ delta\) - base\) / delta, '
     r'delta, 0, "\+"\) → right = sp\.limit\(\(expr\.subs\(var, at (\+ delta\) \+|- delta\) -) base\) / delta, delta, 0, '
     r'"\+"\)|left = sp\.limit\(\(base - expr\.subs\(var, at - delta\)\) / delta, delta, 0, "\+"\) → left = sp\.limit\('
     r'\(base - expr\.subs\(var, at \+ delta\)\) / delta, delta, 0, "\+"\))$',
     "equivalent for the only expression one_sided is given, h with the other factor c at a zero line: there h "
     "is 0 (base) and even in the distance to the line (|sin| is symmetric about its zeros), so adding base, or "
     "taking the point on the other side, gives the same limits, and an h other than |s1 s2| is refuted by that "
     "identity first"),
    ("proofs/kinks.py", r"x__check__mutmut_\d+: return Verdict\(\"refuted\", f\"KINK_BAND_HALF_WIDTH is ",
     "fixed since this run: the comparison of the constant KINK_BAND_HALF_WIDTH is gone; the check now evaluates "
     "the renderer's band (KINK_BAND) just inside and just outside the seed's half-width, and the wrong variants "
     "with a band ten times wider and half as wide reach it"),
)
MUTMUT_EXPLAINED += (
    ("proofs/finite_difference.py", r"x__check_truncation__mutmut_(9|1[0-5]): (bad = interior_branch_mismatches\(\)|"
     r"return Verdict\(\"refuted\", f\"at \{bad\} interior points)",
     "fixed since this run: a new wrong variant (v_p clamped to 1/2 in the kernel and the border rule alike) is "
     "refuted only by the interior-branch check, which no variant reached before"),
    ("proofs/finite_difference.py", r"x_interior_branch_mismatches__mutmut_\d+: (step = 10\.0 \*\* rng\.uniform\(-9, -1\)|"
     r"u_, v_ = rng\.uniform\(step, 1\.0 - step\)|if u_ \+ step < 1\.0 and u_ - step >= 0\.0|bad \+= full\()",
     "fixed since this run: the check now counts the interior points it compares and refutes with fewer than "
     "2,000, and the v_p variant reaches the mismatch count"),
    ("proofs/finite_difference.py", r"x_interior__mutmut_\d+: ",
     "fixed since this run: the interior branches are worked out inside the check (interior_points), no longer "
     "only at import, where mutmut could not switch these mutants on"),
    ("proofs/finite_difference.py", r"x_border_mismatches__mutmut_\d+: bad \+= list\(got\) .* → bad = list\(got\)",
     "fixed since this run: the new variant with u_m's interior branch everywhere mismatches at points before "
     "the last, so a count that keeps only the last point is refuted"),
    ("proofs/kinks.py", r"x__flag__mutmut_\d+: return sp\.Piecewise\(\(sp\.Integer\(1\), condition\), \(sp\.Integer\(0\), "
     r"True\)\) → ",
     "fixed since this run: the check evaluates the renderer's band just outside the seed's half-width, where "
     "the flag's otherwise-branch must give 0"),
)
MUTMUT_EXPLAINED += (
    ("proofs/no_boundary.py",
     r'x__check__mutmut_\d+: .* → .*"XX(predicates depend on bump parameters: |; |pixels differ from the beta = 0 frame|'
     r'\(pixel, light\) pairs|have the chamber, t, P |and N of the beta = 0 frame|lights behind A|inside sphere B, lights)',
     "the verdict's evidence text, for a reader of the ledger; the status it carries is unchanged"),
    ("proofs/no_boundary.py",
     r'x__check__mutmut_\d+: .* → .*"(PREDICATES DEPEND ON BUMP|PIXELS DIFFER FROM|\(PIXEL, LIGHT\) PAIRS|HAVE THE CHAMBER, T, P|'
     r'have the chamber, t, p |AND N OF THE BETA|and n of the beta|LIGHTS BEHIND A|lights behind a and|INSIDE SPHERE B|'
     r'inside sphere b, )',
     "the verdict's evidence text, for a reader of the ledger; the status it carries is unchanged"),
    ("proofs/no_boundary.py",
     r"x__check__mutmut_\d+: leaking = \{name: sorted\(str\(sym\) .* → leaking = \{name: sorted\(str\(None\) for sym in "
     r"expr\.free_symbols & BUMP_SYMBOLS\)",
     "the refutation's evidence text: each leaking predicate lists 'None' once per leaking symbol instead of its name, "
     "so the list is non-empty exactly when before and the status is unchanged"),
    ("proofs/no_boundary.py",
     r"x__check__mutmut_\d+: .* → .*residual=float\(values (- masks \+|\+ masks -) differing\)",
     "equivalent: the verified verdict is returned only when values, masks and differing are all 0, so any signed sum "
     "of them is 0 too, and a refutation carries no residual"),
    ("proofs/no_boundary.py",
     r"x__check__mutmut_\d+: .* → .*if differing or compared <= pairs \* 0\.99:$",
     "equivalent: compared is an integer and pairs x 0.99 (131072 x 0.99 = 129761.28) is not, so they are never equal"),
    ("proofs/no_boundary.py",
     r"x_(render_flips|reach_mismatches|root_mismatches)__mutmut_\d+: def \w+\((root, )?size=(64|128)(, \w+=\w+)*\): → "
     r"def \w+\((root, )?size=(65|129)(, \w+=\w+)*\):$",
     "another frame size (65 or 129 pixels a side instead of 64 or 128): an equally valid sample of the same "
     "scenes, where the renderer and the predicates agree as well; only the size the evidence states is off"),
    ("proofs/no_boundary.py",
     r"x_render_flips__mutmut_\d+: def render_flips\(size=64, gate=False(, shading=None)?\): → "
     r"def render_flips\(size=64, gate=True(, shading=None)?\):$",
     "the theorem's check and its variants always pass gate (False, or True in the gated variant); the default serves "
     "only claims.py's flips-zero claim, outside verify"),
    ("proofs/no_boundary.py",
     r'x_render_flips__mutmut_\d+: (base, base_masks|base) = geometry\(Scene\(height_field="sine", beta=0\.0\)\)(\[1\])? → '
     r'(base, base_masks|base) = geometry\(Scene\((beta=0\.0|height_field="sine", |height_field="sine", beta=1\.0)\)\)(\[1\])?$',
     "another reference frame (the default ridges field, the default beta 0.35, or beta 1.0): the beta = 0 sine frame is "
     "among the G-buffers compared with it, so every frame equals the reference only if every frame equals the beta = 0 "
     "one, and a reference that differed would itself be a moved boundary"),
    ("proofs/no_boundary.py",
     r'x_predicate_masks__mutmut_\d+: .* → .*np\.einsum\("HWC,HWC->HW"',
     "equivalent: einsum's subscripts are letters of either case"),
    ("proofs/no_boundary.py",
     r"x_predicate_masks__mutmut_\d+: ok, sure = attached > 0, np\.abs\(attached\) > margin → "
     r"ok, sure = attached (>= 0, np\.abs\(attached\) > margin|> 0, np\.abs\(attached\) >= margin)$",
     "differs only where N . (L - P) is exactly 0 or exactly the margin 1e-9, and a pair at 0 is left undecided either "
     "way"),
    ("proofs/no_boundary.py",
     r"x_predicate_masks__mutmut_\d+: cut = .* → cut = \(disc >=? 0\) & \(\(\(s1 >=? 0\) & \(s1 <=? 1\)\) \| "
     r"\(\(s2 >=? 0\) & \(s2 <=? 1\)\)\)$",
     "differs only for a discriminant exactly 0 or a root exactly 0 or 1 (the hit point or the light on a blocker's "
     "surface), which no (pixel, light) pair of these scenes has: the masks are identical"),
    ("proofs/no_boundary.py",
     r"x_predicate_masks__mutmut_\d+: (s1, s2 = \(-b - root\) / \(2 \* a\), \(-b \+ root\) / \(2 \* a\) → s1, s2 = "
     r"\(-b - root\) / \(2 \* a\), \(-b - root\) / \(2 \* a\)$|cut = .* → cut = .*\(\(s2 > 1\) & \(s2 < 1\)\)\)$)",
     "equivalent: the far root s2 alone decides a cut only when s1 <= 0 < s2, a hit point inside a blocker sphere, "
     "and no visible point is (the camera is outside every sphere, so an eye ray enters a sphere before any point inside it)"),
    ("proofs/no_boundary.py",
     r"x_predicate_masks__mutmut_\d+: (near = \(np\.abs\(disc\) <= margin \* b \* b\)|\(np\.minimum\(np\.abs\(s1 - 1\), "
     r"np\.abs\(s2 - 1\)\) < margin\) →|sure &= ~\(applies & near & ok\) →|decided\.append\(sure \| ~on\) →)",
     "these lines decide only which pairs within the margin 1e-9 of a threshold are compared, never a mask: comparing "
     "more pairs could only add a mismatch, comparing fewer is caught by the 99% floor, and here every one of the "
     "131072 pairs stays decided"),
    ("proofs/no_boundary.py",
     r"x_predicate_masks__mutmut_\d+: ok &= ~\(\(code != 3\) .* → ok &= ~\(\(code != 4\) & \(light\.position\[2\] \* "
     r"P\[\.\.\., 2\] < 0\)\)$",
     "equivalent: a floor pixel's P_z is exactly 0 (the eye ray meets z = 0 at t = 1), so L_z P_z < 0 is false for it "
     "whether or not the floor chamber (3) is excluded, and there is no chamber 4"),
    ("proofs/no_boundary.py",
     r"x_predicate_masks__mutmut_\d+: ok &= ~\(\(code != 3\) .* → ok &= ~\(\(code != 3\) & \(light\.position\[2\] / "
     r"P\[\.\.\., 2\] < 0\)\)$",
     "equivalent: L_z / P_z has the sign of L_z P_z wherever P_z is not 0, and P_z is 0 only on floor pixels, which "
     "code != 3 excludes"),
    ("proofs/no_boundary.py",
     r"x_predicate_masks__mutmut_\d+: ok &= ~\(\(code != 3\) .* → ok &= ~\(\(code != 3\) & \(light\.position\[2\] \* "
     r"P\[\.\.\., 2\] <= 0\)\)$",
     "differs only where L_z P_z is exactly 0 off the floor: no light of these scenes lies in the floor plane, and "
     "visible sphere points have z >= 0.26"),
    ("proofs/no_boundary.py",
     r"x_root_mismatches__mutmut_\d+: .* → .*~\(np\.abs\(want - g\.t\) < 1e-9\)\)",
     "differs only for a root exactly 1e-9 from the renderer's t; they agree to 6e-16"),
)
MUTMUT_EXPLAINED += (
    ("proofs/no_boundary.py", r"x__sphere_roots__mutmut_\d+: ",
     "fixed since this run: the check evaluates _sphere_roots' near root against the renderer's t at every "
     "sphere pixel (within 1e-9; 6e-16 today), and a variant taking the far root is refuted"),
    ("proofs/no_boundary.py", r"x_predicate_masks__mutmut_(40|92|93|96|97|107|112): ",
     "fixed since this run: a reach scene with sphere B off and two lights just above the floor beside A "
     "reaches the roots beyond the light and the lights below a surface point's height"),
    ("proofs/no_boundary.py", r"x_predicate_masks__mutmut_1: |x_reach_mismatches__mutmut_(18|19|28|29|31): ",
     "fixed since this run: reach_mismatches sums per-scene counts, and at least 99 % of (pixel, light) pairs "
     "must be decided"),
    ("proofs/no_boundary.py", r"x_render_flips__mutmut_(13|51|54|55|64|69|70|71|72|73|74|77|83|84|90): ",
     "fixed since this run: the check requires as many distinct bumped normals as its betas, steps, fields "
     "and bump modes make (136), and counts the five arrays in one list per frame"),
)
#: Explanations that hold in every theorem module.
for _m in THEOREM_MODULES:
    MUTMUT_EXPLAINED += (
        (_m, r'Identity\((?:r?f?"[^"]*"|None), (.*) → .*Identity\((?:r?f?"[^"]*"|None), \1',
         "an identity's label: the name its step shows in the book; the check compares lhs and rhs only"),
        (_m, r"verdict\.residual, verdict\.digits, verdict\.points\) → (None, verdict\.digits, verdict\.points|"
         r"verdict\.residual, None, verdict\.points|verdict\.residual, verdict\.digits, None|verdict\.digits, "
         r"verdict\.points|verdict\.residual, verdict\.points|verdict\.residual, verdict\.digits, )\)$",
         "sympy decides every identity (the pinned verdict is proved), so residual, digits and points are None "
         "already; the status is unchanged"),
        (_m, r"-handed about the outward normal|Verdict\(verdict\.status, None",
         "the verdict's evidence text, for a reader of the ledger; the status it carries is unchanged"),
    )


def explain(module, name, change, current=False):
    """The reason `MUTMUT_EXPLAINED` gives for a survivor (its pattern searched in
    "mutant name: before → after"), or None.  A reason "fixed since this run: ..." speaks of
    an earlier run's survivor; for a ``current`` run's it does not count."""
    return next((why for mod, pattern, why in MUTMUT_EXPLAINED
                 if mod == module and re.search(pattern, f"{name}: {change}")
                 and not (current and why.startswith("fixed since this run"))), None)


#: Lists the functions of the theorem modules that run while `verify/test_theorems.py` is
#: imported: "module.function" per line (nested functions under their outer one).
_IMPORT_TIME_PROBE = """
import sys
ran = set()
def probe(frame, event, arg):
    f = frame.f_code.co_filename.replace(chr(92), "/")
    if event == "call" and "/proofs/" in f and frame.f_code.co_name != "<module>":
        ran.add("proofs." + f.rsplit("/", 1)[1][:-3] + "." + frame.f_code.co_qualname.split(".")[0])
sys.setprofile(probe)
import verify.test_theorems
sys.setprofile(None)
print("\\n".join(sorted(ran)))
"""


def import_time_functions(d, env):
    """{"proofs.module.function"} of the functions that run when the theorem tests are imported,
    in scratch copy ``d`` (unmutated).  mutmut imports the modules before it switches a mutant
    on, so these functions' import-time calls never run mutated under it."""
    out = subprocess.run([PYTHON, "-c", _IMPORT_TIME_PROBE], cwd=d, env=dict(env, PYTHONPATH=str(d)),
                         capture_output=True, text=True, check=True).stdout
    return set(out.split())


def _function_of(mutant):
    """"proofs.frame.x_regular_branch__mutmut_3" -> "proofs.frame.regular_branch"."""
    module, _, name = mutant.rpartition(".")
    return module + "." + re.sub(r"^x_|__mutmut_\d+$", "", name)


def fresh_process_recheck(d, env, survivors, deadline):
    """Run each of ``survivors`` (mutant names) again in a new interpreter with the mutant
    switched on before anything is imported, ``pytest -x verify/test_theorems.py`` in
    ``d``/mutants: {name: "killed" | "survived"} (kept in ``d``/fresh.json, so that a resumed run
    skips what it has), until ``deadline`` (time.time()); two at a time."""
    done_file = d / "fresh.json"
    done = json.loads(done_file.read_text(encoding="utf-8")) if done_file.is_file() else {}
    todo = [n for n in survivors if n not in done]
    running = {}
    while (todo or running) and time.time() < deadline:
        while todo and len(running) < (os.cpu_count() or 2):
            name = todo.pop(0)
            running[name] = subprocess.Popen(
                [PYTHON, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "--rootdir=.",
                 "verify/test_theorems.py"], cwd=d / "mutants",
                env=dict(env, PYTHONPATH=str(d / "mutants"), MUTANT_UNDER_TEST=name),
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(1)
        for name, proc in list(running.items()):
            if proc.poll() is not None:
                done[name] = "survived" if proc.returncode == 0 else "killed"
                del running[name]
                done_file.write_text(json.dumps(done, indent=1) + "\n", encoding="utf-8")
    for proc in running.values():
        proc.kill()
    return {n: done[n] for n in survivors if n in done}


def run_mutmut(work, budget, patterns=(), fresh_budget=0.0, earlier=None):
    """mutmut 3 over each of `MUTMUT_SCOPES`, scope i in ``work``/scope-i (a scratch copy
    made if absent, else resumed): ([(module, tests, {status: count}, [(surviving mutant, its
    change)])], {mutant: fresh-process outcome}), or None if mutmut is missing.  ``work``'s copies are refreshed from the
    working tree first.  A budgeted scope runs for at most ``budget``
    minutes (0: only collected), over its mutants matching ``patterns`` (mutmut's globs, e.g.
    "proofs.frame.*"; none: all).  mutmut's statuses: killed, survived, "no tests" (no named
    test calls the mutated function), timeout, "not checked" (budget spent), ...  Then, for
    ``fresh_budget`` minutes, the budgeted scope's survivors in functions that run at import
    time are run again in a fresh process (`fresh_process_recheck`); those it kills count as
    killed ("fresh": how many).  So are ``earlier``'s ({module: [(mutant, change)]}, the last
    report's survivors) where the mutant is still the same change."""
    mutmut = Path(PYTHON).parent / "mutmut"
    if not mutmut.is_file():
        return None
    found, fresh = [], {}
    for i, (modules, tests, isolation, budgeted) in enumerate(MUTMUT_SCOPES):
        d = work / f"scope-{i}"
        changed = _scratch(d)[1]
        if changed and (d / "mutants").is_dir():
            # mutmut 3's incremental update kept stale test coverage for new functions (their
            # mutants "survived" without their tests): a changed module starts afresh.
            (d / "mutants" / "mutmut-stats.json").unlink(missing_ok=True)
            for module in set(modules) & set(changed):
                (d / "mutants" / f"{module}.meta").unlink(missing_ok=True)
        (d / "setup.cfg").write_text("[mutmut]\nsource_paths=" + "\n    ".join(modules) + "\n"
                                     f"pytest_add_cli_args_test_selection={tests}\n"
                                     "also_copy=renderer/\n    book/\n    verify/\n"
                                     f"process_isolation={isolation}\n", encoding="utf-8")
        env = dict(os.environ, NUMBA_CACHE_DIR=str(d / ".numba_cache"))
        env.pop("SYMRENDER_STORE", None)
        chosen = [p for p in patterns if any(p.startswith(m[:-3].replace("/", ".") + ".") for m in modules)]
        if patterns and not chosen:
            continue                                        # the globs name no mutant of this scope
        if not budgeted or budget > 0:
            run = subprocess.Popen([str(mutmut), "run", "--max-children", str(os.cpu_count() or 2), *chosen], cwd=d,
                                   env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            try:
                run.wait(timeout=budget * 60 if budgeted else None)
            except subprocess.TimeoutExpired:
                run.send_signal(signal.SIGINT)              # mutmut keeps each result as it comes
                try:
                    run.wait(timeout=120)
                except subprocess.TimeoutExpired:
                    run.kill()
        if not (d / "mutants").is_dir():
            continue
        out = subprocess.run([str(mutmut), "results", "--all", "true"], cwd=d, env=env,
                             capture_output=True, text=True).stdout
        statuses = dict(line.strip().rsplit(": ", 1) for line in out.splitlines() if ": " in line)
        show = lambda name: " → ".join(  # noqa: E731
            line[1:].strip() for line in subprocess.run([str(mutmut), "show", name], cwd=d, env=env,
                                                        capture_output=True, text=True).stdout.splitlines()
            if line.startswith(("-", "+")) and not line.startswith(("---", "+++")))
        if budgeted:                            # with fresh_budget 0: what fresh.json holds
            at_import = import_time_functions(d, env)
            suspects = {n: show(n) for n, v in statuses.items() if v == "survived" and _function_of(n) in at_import}
            # The earlier report's survivors of import-time functions, where the mutant is still the same.
            suspects.update((n, c) for m, sv in (earlier or {}).items() for n, c in sv
                            if _function_of(n) in at_import and n in statuses and show(n) == c)
            fresh.update(fresh_process_recheck(d, env, [n for n, c in suspects.items() if explain(
                n.rsplit(".", 1)[0].replace(".", "/") + ".py", n, c, current=True) is None],
                time.time() + fresh_budget * 60))
        for module in modules:
            prefix = module[:-3].replace("/", ".") + "."
            mine = {k: v for k, v in statuses.items() if k.startswith(prefix)}
            mine.update((k, "killed") for k in mine if fresh.get(k) == "killed")
            survivors = [(name, show(name)) for name in sorted(k for k, v in mine.items() if v == "survived")]
            n = Counter(mine.values())
            n["fresh"] = sum(fresh.get(k) == "killed" for k in mine)
            found.append((module, tests, n, survivors))
    return found, fresh


def _earlier_mutmut(out):
    """{module: (tests, Counter, [(mutant, change)], when)} of the last report: its .json, or
    else its .md (table and survivor lists)."""
    if out.with_suffix(".json").is_file():
        return {m: (t, Counter(n), [tuple(x) for x in sv], w)
                for m, (t, n, sv, w) in json.loads(out.with_suffix(".json").read_text(encoding="utf-8")).items()}
    if not out.is_file():
        return {}
    text = out.read_text(encoding="utf-8")
    when = re.search(r"on (\d{4}-\d\d-\d\d \d\d:\d\d) UTC", text).group(1)
    found, module = {}, None
    for line in text.splitlines():
        row = re.match(r"^\| `([^`]+)` \| `([^`]+)` \|" + r" (\d+) \|" * 7, line)
        if row:
            counts = [int(x) for x in row.groups()[3:]]
            found[row.group(1)] = (row.group(2), Counter(dict(zip(
                ("killed", "survived", "timeout", "no tests", "not checked", "other"), counts))), [], when)
        head = re.match(r"^Survivors in `([^`]+)`", line)
        module = head.group(1) if head else module
        item = re.match(r"^- `([^`]+)`: `(.*?)`: ", line)
        if item and module in found:
            found[module][2].append(item.groups())
    return found


def _write_mutmut(found, fresh, out, started):
    """Write results/mutmut.md (and .json): this run's rows, and the earlier report's for the
    modules this run did not check (their "run" column says when they were)."""
    now = f"{datetime.now(timezone.utc):%Y-%m-%d %H:%M}"
    merged = _earlier_mutmut(out)
    for module, tests, n, survivors in found:
        # A row this run checked replaces the earlier one; kills made only by rerunning the earlier
        # report's survivors in a fresh process (n["fresh"]) amend it.
        if n["killed"] - n["fresh"] + n["survived"] + n["timeout"] or module not in merged:
            merged[module] = (tests, n, survivors, now)
        else:                                   # an earlier row: its survivors this run killed afresh
            tests, n, survivors, when = merged[module]
            gone = [s for s in survivors if fresh.get(s[0]) == "killed"]
            if gone:
                n = n + Counter(killed=len(gone), fresh=len(gone))
                n["survived"] -= len(gone)
                merged[module] = (tests, n, [s for s in survivors if s not in gone],
                                  f"{when}; {len(gone)} rerun {now}")
    out.with_suffix(".json").write_text(json.dumps(merged, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    lines = ["# mutmut", "",
             f"`python benchmarks/mutation_audit.py --mutmut`, last on {now} UTC ({time.time() - started:.0f} s); "
             "a module this run did not check keeps the row of the run named in its last column.  mutmut 3 "
             "over each module with the tests named, in a scratch copy per scope; the theorem modules for a "
             "budget of minutes, fastest mutants first (\"not checked\": the rest).  \"killed\" counts in "
             "brackets those killed only in a fresh process: survivors in functions that run while the tests "
             "are imported, which mutmut (it imports before it switches a mutant on) never ran mutated there, "
             "run again with the mutant on from the start.", "",
             "Kill rate: killed / (killed + survived + timeout), the mutants the named tests reach.  "
             "\"not reached\": mutants in functions no named test calls (mutmut's \"no tests\"; the "
             "register's measurements, which `pytest verify` runs, take minutes per mutant).", "",
             "| module | tests | mutants | killed | survived | timeout | not reached | not checked | other | "
             "kill rate | run (UTC) |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for module, (tests, n, _, when) in merged.items():
        reached = n["killed"] + n["survived"] + n["timeout"]
        total = sum(v for k, v in n.items() if k != "fresh")
        other = total - reached - n["no tests"] - n["not checked"]
        rate = f"{100 * n['killed'] / reached:.0f} %" if reached else "–"
        killed = f"{n['killed']} ({n['fresh']})" if n["fresh"] else f"{n['killed']}"
        lines.append(f"| `{module}` | `{tests}` | {total} | {killed} | {n['survived']} | "
                     f"{n['timeout']} | {n['no tests']} | {n['not checked']} | {other} | {rate} | {when} |")
    why = {(m, n): explain(m, n, c, current=w == now) for m, (_, _, s, w) in merged.items() for n, c in s}
    for module, (_, _, survivors, _) in merged.items():
        lines += ["", f"Survivors in `{module}` (the line before → after; why it is equivalent or acceptable):", ""]
        lines += [f"- `{name}`: `{change}`: " + (why[module, name] or "**flagged**: not explained")
                  for name, change in survivors] or ["- none"]
    flagged = sum(w is None for w in why.values())
    lines += ["", f"Survivors not explained (flagged): {flagged}."]
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))


def _earlier(out):
    """{mutant id: outcome} of the last run, from its .json or else its .md table."""
    if out.with_suffix(".json").is_file():
        return json.loads(out.with_suffix(".json").read_text(encoding="utf-8"))
    rows = {}
    if out.is_file():
        for line in out.read_text(encoding="utf-8").splitlines():
            m = re.match(r"^\| `([^`]+)` \(`[^`]+`\) \| .* \| (verify \(\d+ s\)|tests \(\d+ s\)|survived|"
                         r"killed by the generator|timeout)", line)
            if m:
                rows[m.group(1)] = m.group(2)
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", help="mutant ids to run (default: all)")
    parser.add_argument("--mutmut", action="store_true",
                        help="run mutmut over MUTMUT_SCOPES instead (results/mutmut.md)")
    parser.add_argument("--work", help="with --mutmut: keep the scratch copies here, and resume from them")
    parser.add_argument("--budget", type=float, default=60.0,
                        help="with --mutmut: minutes for the theorem modules' scope (0: only collect)")
    parser.add_argument("--fresh", type=float, default=0.0,
                        help="with --mutmut: minutes to run survivors of import-time functions again, each "
                             "in a fresh process with the mutant on from the start")
    parser.add_argument("--mutants", nargs="*", default=(),
                        help="with --mutmut: run only the mutants matching these globs, and only the "
                             "scopes they name (e.g. 'proofs.kink_loci.*')")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "mutation_audit.md"))
    args = parser.parse_args(argv)
    if args.mutmut:
        work, started = Path(args.work or tempfile.mkdtemp(prefix="mutation-audit-")), time.time()
        work.mkdir(parents=True, exist_ok=True)
        try:
            out = ROOT / "benchmarks" / "results" / "mutmut.md"
            found = run_mutmut(work, args.budget, args.mutants, args.fresh,
                               {m: sv for m, (_, _, sv, _) in _earlier_mutmut(out).items()})
        finally:
            if not args.work:
                shutil.rmtree(work, ignore_errors=True)
        if found is None:
            print("mutmut is not installed (pip install mutmut)", file=sys.stderr)
            return 1
        _write_mutmut(*found, out, started)
        return 0
    check_mutants()
    chosen = [m for m in MUTANTS if not args.only or m[0] in args.only]
    work = _scratch()[0]
    rows, started = [], time.time()
    try:
        for m in chosen:
            outcome = audit(m, work)
            print(f"{m[0]:24s} {outcome}", flush=True)
            rows.append((m, outcome))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    out = Path(args.out)
    if args.only:                                   # merge into the earlier full run
        earlier = _earlier(out)
        fresh = {m[0]: o for m, o in rows}
        rows = [(m, fresh.get(m[0], earlier.get(m[0]))) for m in MUTANTS if m[0] in fresh or m[0] in earlier]
    out.with_suffix(".json").write_text(json.dumps({m[0]: o for m, o in rows}, indent=1) + "\n", encoding="utf-8")
    by_verify = sum(o.startswith(("verify", "killed by the generator")) for _, o in rows)
    by_any = sum(o != "survived" for _, o in rows)
    n = len(rows)
    lines = ["# Mutation audit", "",
             f"`python benchmarks/mutation_audit.py` on {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, "
             f"{os.cpu_count()} CPUs, Python {platform.python_version()}, {time.time() - started:.0f} s.",
             "Each mutant applied alone to a scratch copy of the working tree; formulas regenerated; "
             "`pytest verify -x`, then (if it survives) `pytest tests -x`.", "",
             "| mutant | the bug | killed by |", "|---|---|---|"]
    for (mid, path, _, _, what), outcome in rows:
        note = f" ({ACCEPTED[mid]})" if outcome == "survived" and mid in ACCEPTED else \
            (" (**flagged**: not an accepted survivor)" if outcome == "survived" else "")
        if outcome.startswith("tests"):
            note = f" (verify: {VERIFY_MISSES[mid]})" if mid in VERIFY_MISSES else " (**flagged**: verify misses it)"
        lines.append(f"| `{mid}` (`{path}`) | {what} | {outcome}{note} |")
    lines += ["", f"Kill rate: `pytest verify` alone {by_verify}/{n} ({100 * by_verify / max(n, 1):.0f} %); "
              f"verify + tests {by_any}/{n} ({100 * by_any / max(n, 1):.0f} %). Targets: 90 % and 98 %."]
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines[-2:]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
