"""The §4 simulator's JavaScript renderer against Python's `render`, under node.

Acceptance: identical chamber codes and |dI| <= 1e-9 per channel, for
every field, both models, both pipelines, beta = 0, sphere B on and off, and eps
from 1e-1 down to 1e-10.  The central pipeline is held to more than that: its
gradient must be the same bits, because both sides difference the same values of
h (renderer/detmath.py).  Each check is shown rejecting a wrong variant of the JS.
"""

from __future__ import annotations

import numpy as np
import pytest

from renderer import PointLight, Scene, render

from .jsnode import ARTIFACTS, read_frame, run_render_cases, write_modules

TOL = 1e-9

#: (id, scene, width, height, gradient, zoom); non-square sizes catch a transposed
#: image, odd widths put a pixel column exactly on x = 0 (the seam's meridian).
CASES = [
    ("default-central", Scene(), 96, 80, "central", 1.0),
    ("default-exact", Scene(), 96, 80, "exact", 1.0),
    ("sine-phong-eps1e-1", Scene(height_field="sine", model="phong", eps=1e-1), 96, 80, "central", 1.0),
    ("sine-exact-beta1.5", Scene(height_field="sine", beta=1.5), 96, 80, "exact", 1.0),
    ("rings-eps1e-10-noB", Scene(height_field="rings", eps=1e-10, sphere_b=False), 96, 80, "central", 1.0),
    ("rings-phong-exact-nofloor", Scene(height_field="rings", model="phong", floor=False), 96, 80, "exact", 1.0),
    ("ridges-eps1e-6-beta0", Scene(eps=1e-6, beta=0.0), 96, 80, "central", 1.0),
    ("ridges-exact-beta0-noB", Scene(beta=0.0, sphere_b=False), 96, 80, "exact", 1.0),
    ("sine-eps1e-8-surface", Scene(height_field="sine", eps=1e-8, bump="surface", beta=0.5), 96, 80,
     "central", 1.0),
    ("rings-eps1e-4-pole-x8", Scene(height_field="rings", eps=1e-4), 96, 80, "central", 8.0),
    ("ridges-phong-eps1e-10-k5x3", Scene(model="phong", eps=1e-10, k_u=5.0, k_v=3.0), 99, 61,
     "central", 1.0),
    ("ridges-exact-odd", Scene(), 99, 61, "exact", 1.0),
    ("sine-eps1e-2-lights", Scene(height_field="sine", eps=1e-2, lights=(
        PointLight((5.0, 5.0, 10.0), (1.0, 1.0, 1.0)), PointLight((0.0, 3.0, -2.0), (0.5, 0.5, 0.5)),
        PointLight((-6.0, 2.0, 8.0), (0.0, 0.0, 0.0)))), 96, 80, "central", 1.0),
    ("default-central-256", Scene(), 256, 256, "central", 1.0),
]


def _as_cases(cases):
    return [dict(id=i, scene=s, width=w, height=h, gradient=g, zoom=z) for i, s, w, h, g, z in cases]


def parity_rows(module_dir, out_dir, cases=CASES):
    """Render ``cases`` in node and in Python; one row of measurements per case."""
    ms = run_render_cases(module_dir, _as_cases(cases), out_dir)
    rows = []
    for case_id, scene, w, h, gradient, zoom in cases:
        py = render(scene, w, h, gradient=gradient, zoom=zoom)
        image, grad, chamber, kink = read_frame(out_dir, case_id, w, h)
        on_a = py.chamber == 1
        rows.append(dict(
            id=case_id, gradient=gradient, size=f"{w}x{h}",
            max_abs=float(np.abs(image - py.image).max()),
            chamber_mismatches=int(np.count_nonzero(chamber != py.chamber)),
            kink_mismatches=int(np.count_nonzero(kink != py.kink)),
            grad_max_abs=float(np.abs(grad - py.grad)[on_a].max()) if on_a.any() else 0.0,
            grad_bits_differ=int(np.count_nonzero(grad != py.grad)),
            pixels_a=int(on_a.sum()), node_ms=ms[case_id],
        ))
    return rows


def _violations(row):
    bad = []
    if row["chamber_mismatches"]:
        bad.append(f"{row['chamber_mismatches']} chamber mismatches")
    if row["kink_mismatches"]:
        bad.append(f"{row['kink_mismatches']} kink mismatches")
    if not row["max_abs"] <= TOL:
        bad.append(f"max |dI| = {row['max_abs']:.3e} > {TOL}")
    if row["gradient"] == "central" and row["grad_bits_differ"]:
        bad.append(f"{row['grad_bits_differ']} central gradients differ in their bits")
    return bad


@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    return write_modules(tmp_path_factory.mktemp("js"))


@pytest.fixture(scope="module")
def rows(modules, tmp_path_factory):
    return parity_rows(modules, tmp_path_factory.mktemp("out"))


def test_parity_cover_the_acceptance_grid():
    scenes = [c[1] for c in CASES]
    assert len(CASES) >= 10
    assert {s.height_field for s in scenes} == {"sine", "ridges", "rings"}
    assert {s.model for s in scenes} == {"blinn", "phong"}
    assert {c[4] for c in CASES} == {"exact", "central"}
    assert any(s.beta == 0.0 for s in scenes)
    assert {s.sphere_b for s in scenes} == {True, False}
    central_eps = {s.eps for s, g in ((c[1], c[4]) for c in CASES) if g == "central"}
    assert min(central_eps) <= 1e-10 and max(central_eps) >= 1e-1


def test_js_renderer_matches_python(rows):
    lines = ["| case | pipeline | size | max abs dI | chamber mismatches | kink mismatches | "
             "max abs d(grad) on A | node ms |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['id']} | {r['gradient']} | {r['size']} | {r['max_abs']:.2e} | "
                     f"{r['chamber_mismatches']} | {r['kink_mismatches']} | {r['grad_max_abs']:.1e} | "
                     f"{r['node_ms']:.0f} |")
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    (ARTIFACTS / "js_parity.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    failures = {r["id"]: _violations(r) for r in rows if _violations(r)}
    assert not failures, failures
    assert all(r["pixels_a"] > 0 for r in rows)


def test_render_pair_is_render_bit_for_bit(modules, tmp_path):
    """The simulator's one-pass pair equals two separate renders, bit for bit."""
    cases = [("pair-default", Scene(), 64, 48), ("pair-sine-phong", Scene(height_field="sine", model="phong",
              eps=1e-7), 64, 48), ("pair-rings-noB", Scene(height_field="rings", sphere_b=False), 64, 48)]
    spec = []
    for cid, scene, w, h in cases:
        spec += [dict(id=cid, scene=scene, width=w, height=h, gradient="pair", zoom=1.0),
                 dict(id=cid + "-c", scene=scene, width=w, height=h, gradient="central", zoom=1.0),
                 dict(id=cid + "-e", scene=scene, width=w, height=h, gradient="exact", zoom=1.0)]
    run_render_cases(modules, spec, tmp_path)
    for cid, _, w, h in cases:
        for pipe, suffix in (("central", "-c"), ("exact", "-e")):
            pair = read_frame(tmp_path, f"{cid}.{pipe}", w, h)
            single = read_frame(tmp_path, cid + suffix, w, h)
            for a, b in zip(pair, single):
                assert np.array_equal(a, b), (cid, pipe)


# ---- the checks reject wrong variants of the JavaScript ------------------------------

WRONG_VARIANTS = {
    # numpy's mod takes the divisor's sign; JavaScript's % the dividend's.
    "truncated mod in the u-wrap": ("render", "const m = x % 1.0;\n  if (m === 0) return 0.0;\n"
                                    "  return m < 0 ? m + 1.0 : m;", "return x % 1.0;"),
    "V8 Math.sin in h": ("fields", "det_sin(Math.PI", "Math.sin(Math.PI"),
    "Math.hypot in the chart": ("geometry", "Math.sqrt(Nx * Nx + Ny * Ny)", "Math.hypot(Nx, Ny)"),
    "shadow ray ignores the floor plane": ("render", "if (floor_blocks) lit", "if (false) lit"),
    "ties go to sphere B": ("render", "if (tB < t)", "if (tB <= t)"),
}


@pytest.mark.parametrize("variant", sorted(WRONG_VARIANTS))
def test_parity_check_rejects_wrong_variant(variant, tmp_path):
    module, old, new = WRONG_VARIANTS[variant]

    def transform(name, text):
        if name != module:
            return text
        assert old in text, f"variant {variant!r} no longer applies to {module}.js"
        return text.replace(old, new)

    modules = write_modules(tmp_path / "js", transform)
    scenes = [c for c in CASES if c[0] in ("rings-eps1e-10-noB", "ridges-phong-eps1e-10-k5x3",
                                           "sine-eps1e-2-lights", "default-central-256")]
    if variant == "ties go to sphere B":
        # A tie needs equal t for A and B: make B coincide with A.
        scenes = [("tie", Scene(center_b=(0.0, 0.0, 0.0), radius_b=1.0), 33, 33, "exact", 1.0)]
    rows = parity_rows(modules, tmp_path / "out", scenes)
    assert any(_violations(r) for r in rows), f"wrong variant {variant!r} passed the parity check"
