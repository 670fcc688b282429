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
#: One or more per part: formulas, kernel, sweep, ledger, the simulator's JavaScript, the
#: checker engine, the claims register, the references, the figure encoding and the camera.
MUTANTS = [
    ("rings-k-u", "renderer/formulas.py", '"rings": sp.sin(2 * sp.pi * k_v * v),',
     '"rings": sp.sin(2 * sp.pi * k_u * v),', "the rings field's frequency taken from k_u"),
    ("ridges-one-frequency", "renderer/formulas.py",
     "RIDGE_FACTORS = (sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_v * v))",
     "RIDGE_FACTORS = (sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_u * v))", "both ridge factors with k_u"),
    ("albedo-channel", "renderer/kernel.py", "    return (color[0] * (diffuse * albedo[0] + spec),",
     "    return (color[0] * (diffuse * albedo[2] + spec),", "red lit with the blue albedo"),
    ("specular-kd", "renderer/kernel.py", "    spec = (base ** n if n == s.shininess else base ** s.shininess) * s.ks",
     "    spec = (base ** n if n == s.shininess else base ** s.shininess) * s.kd", "the highlight weighted by kd"),
    ("floor-tint-inverted", "renderer/kernel.py", "    rg = base * (1.0 - s.floor_tint)",
     "    rg = base * s.floor_tint", "the floor tint applied inverted (the simulator keeps it)"),
    ("sweep-ambient-red", "renderer/kernel.py",
     "            r, g, b = s.ka * s.ambient[0], s.ka * s.ambient[1], s.ka * s.ambient[2]\n            for k in range(n):",
     "            r, g, b = s.ka * s.ambient[0], s.ka * s.ambient[0], s.ka * s.ambient[2]\n            for k in range(n):",
     "the sweep's re-shading takes the red ambient for green"),
    ("sweep-crease-from-last", "renderer/kernel.py", "            if f == 0:\n                kink[j, i] = flag",
     "            if f == images.shape[0] - 1:\n                kink[j, i] = flag",
     "the sweep's crease flag from the last central frame"),
    ("sweep-step-off-by-one", "renderer/kernel.py", "(CENTRAL, steps[f - 1])", "(CENTRAL, steps[max(f - 2, 0)])",
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
    ("ucurve-nominal-denominator", "renderer/ucurve.py", "exact_fd = (f_plus - f_minus) / mpmath.mpf(den)",
     "exact_fd = (f_plus - f_minus) / (2 * mpmath.mpf(e))",
     "the exact quotient over 2 eps, not the float denominator (roundoff misattributed)"),
    ("pixels-gradient-tolerance", "proofs/pixels.py", '"gradient": 64 * UNIT', '"gradient": 1e6 * UNIT',
     "the renderer's gradients compared loosely with mpmath"),
    ("png-truncates", "renderer/cli.py", "rgb8 = np.round(np.clip(", "rgb8 = np.floor(np.clip(",
     "8-bit values truncated, not rounded"),
    ("srgb-breakpoint", "renderer/ledger.py", "return np.where(c <= 0.0031308, 12.92 * c,",
     "return np.where(c <= 0.04045, 12.92 * c,", "the sRGB breakpoint of the decoding side"),
    ("camera-offset", "renderer/render.py", "WINDOW_MARGIN, WINDOW_OFFSET = 1.25, 0.15",
     "WINDOW_MARGIN, WINDOW_OFFSET = 1.25, -0.15", "the window shifted up, not down"),
    ("model-coefficient", "renderer/ucurve.py", "model = steps**2 * abs(h3f) / 6 +", "model = steps**2 * abs(h3f) / 2 +",
     "the plotted U-curve model's truncation term over 2, not 6"),
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
        if not run(copy, "pytest", "tests", "-x", "-q", "-n", "2", "-p", "no:cacheprovider",
                   "--ignore=tests/test_browser.py",
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
