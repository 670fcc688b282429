"""Mutation audit: does `pytest verify` catch realistic bugs, and do the tests?

Each mutant of `MUTANTS` is one edit of the kind a person makes (a swapped pair, a
dropped factor, a moved threshold, a check that always passes).  Each is applied alone
to a scratch copy of this working tree (the files git tracks, plus untracked ones it
does not ignore); an edit of renderer/formulas.py is followed by ``python -m
renderer.codegen``, so that it reaches the kernel as a real change would.  Then
``pytest verify -x`` runs in the copy, and if it passes, ``pytest tests -x``.  The
table (mutant, the bug, killed by, seconds) is printed as Markdown; nothing is written
into the repository.  About a minute per mutant verify kills, several per mutant
that reaches the tests.

mutmut's own run covers the pure-Python modules the fast tests exercise (its
configuration is ``[tool.mutmut]`` in pyproject.toml): ``pip install mutmut``, then
``mutmut run`` and ``mutmut results``, as mutmut documents.  It cannot mutate the
numba kernel or module-level sympy, which is what the mutants here cover.

Usage: python benchmarks/mutation_audit.py [ID ...]      (default: every mutant)
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT = 1800

#: (id, file, old text, new text, what the bug is).  Each old text occurs once in its file.
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
    ("unit-roundoff", "renderer/ucurve.py", "UNIT_ROUNDOFF = 2.0**-53", "UNIT_ROUNDOFF = 2.0**-52",
     "the unit roundoff 2^-52 instead of 2^-53"),
    ("reference-digits", "renderer/ucurve.py", "DIGITS = 50", "DIGITS = 15",
     "the U-curve's reference at 15 digits, float64's own"),
    ("statement-drift", "proofs/normal.py", "M_CLAIMED = sp.MatAdd(N_S, F.beta * G_S, evaluate=False)",
     "M_CLAIMED = sp.MatAdd(N_S, -F.beta * G_S, evaluate=False)",
     "a theorem's statement edited (M = N - beta g): printed from the object the check substitutes into"),
    ("claim-threshold", "lab/claims.py", 'rule(HOLDS, Bound("on/off ratio", 3, 30), CORRECTED',
     'rule(HOLDS, Bound("on/off ratio", 3, 30000), CORRECTED', "a claim's pass range widened until it holds"),
    ("erratum-criterion", "lab/seed_errata.py", 'present=lambda m: m["max_rel_error_acos"] > 1e-3 and',
     'present=lambda m: m["max_rel_error_acos"] > -1 and', "an erratum's presence criterion made vacuous"),
    ("blinn-orientation", "proofs/blinn.py", "    inward = -2 * sp.pi**2 * R**2 * s * N_S",
     "    inward = 2 * sp.pi**2 * R**2 * s * N_S", "Blinn's normal taken outward (F = +beta h)"),
    ("pixels-tolerance", "proofs/pixels.py", 'TOLERANCE = {"chart": 16 * UNIT, "gradient": 64 * UNIT, "normal": 64 * UNIT}',
     'TOLERANCE = {"chart": 1.0, "gradient": 1.0, "normal": 1.0}', "the renderer-output tolerances made vacuous"),
]


def scratch_copy(into: Path) -> Path:
    """The working tree's tracked and unignored files, copied into ``into``."""
    names = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT, check=True,
                           capture_output=True).stdout.decode().split("\0")
    for name in filter(None, names):
        if (ROOT / name).is_file():
            (into / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / name, into / name)
    return into


def run(copy: Path, *args) -> bool:
    """Whether ``python -m <args>`` passes in ``copy`` (its packages first on the path)."""
    env = {**os.environ, "PYTHONPATH": f"{copy}{os.pathsep}{copy / 'book'}", "NUMBA_CACHE_DIR": str(copy / ".numba")}
    env.pop("SYMRENDER_BOOK_HTML", None)
    try:
        return subprocess.run([sys.executable, "-m", *args], cwd=copy, env=env, capture_output=True,
                              timeout=TIMEOUT).returncode == 0
    except subprocess.TimeoutExpired:
        return False


def audit(mutant) -> tuple[str, float]:
    """(who killed ``mutant``: 'verify', 'tests' or 'survived', seconds)."""
    name, path, old, new, _ = mutant
    with tempfile.TemporaryDirectory(prefix="symrender-mutant-") as tmp:
        copy = scratch_copy(Path(tmp))
        text = (copy / path).read_text(encoding="utf-8")
        if text.count(old) != 1:
            raise SystemExit(f"mutant {name}: its old text occurs {text.count(old)} times in {path}, not once")
        (copy / path).write_text(text.replace(old, new), encoding="utf-8")
        start = time.monotonic()
        if path == "renderer/formulas.py" and not run(copy, "renderer.codegen"):
            return "codegen", time.monotonic() - start
        if not run(copy, "pytest", "verify", "-x", "-q", "-p", "no:cacheprovider"):
            return "verify", time.monotonic() - start
        if not run(copy, "pytest", "tests", "-x", "-q", "-p", "no:cacheprovider", "--ignore=tests/test_browser.py",
                   "--ignore=tests/test_book_pages.py", "--ignore=tests/test_notebooks.py"):
            return "tests", time.monotonic() - start
        return "survived", time.monotonic() - start


def main(argv):
    chosen = [m for m in MUTANTS if not argv or m[0] in argv]
    print("| mutant | file | the bug | killed by | seconds |\n|---|---|---|---|---:|")
    for m in chosen:
        who, seconds = audit(m)
        print(f"| `{m[0]}` | `{m[1]}` | {m[4]} | {who} | {seconds:.0f} |", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
