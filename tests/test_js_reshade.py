"""The §4 simulator re-shades sphere A on kept geometry, and gets a full render's bits.

The simulator (renderer/js/simulator.js) keeps a G-buffer between updates
(render.js `PairRenderer`): hit, chamber, P, N, chart, tangent frame, footprint
steps and the reach masks of every light, everything the theorem "bump moves no
boundary" says is independent of the bump.  A change of eps, beta, bump, height
field or frequencies re-shades sphere A only; a change of anything else (size,
zoom, sphere B, shading model, ...) makes a new G-buffer.

Checked under node, through a sequence of scenes (`STEPS`) fed to one
`PairRenderer`: after each step both of its frames equal, bit for bit in every
array (image, gradient, chart, chamber, crease flag), a full render of that
scene by `render` (the kernel's twin, step by step, which tests/test_js_parity.py
holds to the Python renderer); each step makes a new G-buffer exactly when the
geometry changed, and re-shades exactly the pipelines whose inputs changed.
The simulator's U-curve (`ledger_along_eps`) equals, bit for bit, the ledger
`compare` of full renders at each of its steps (every pixel), and, on its pixel
sample (every `SAMPLE_STRIDE`-th column and row), the ledger of those pixels
computed here from full renders.  Bit for bit is the right demand: both paths run the same operations
on the same doubles in the same order; only the order of the loops differs.

Wrong variants of render.js (`WRONG_VARIANTS`), each must fail: a re-shade that
keeps the numeric gradient after eps moved, height-field terms kept when k_u
moved, a geometry key blind to sphere B, curve gradients kept when the field
changed, and reach masks that miss sphere B's cast shadow.
"""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest

from renderer import jsgen

from .jsnode import DRIVERS, node_command, read_frame, scene_json, write_modules

WIDTH, HEIGHT = 48, 40                      # non-square: a transposed image shows
SIM = jsgen.SIMULATOR_SCENE.replace(height_field="ridges")     # the draft's field: the steps below leave it
#: The U-curve's steps here: both slopes and the bottom of the U.
CURVE = [1e-1, 1e-4, 1e-7, 1e-11]
SAMPLE_STRIDE = 3

#: (id, scene, zoom, numeric pipeline, new G-buffer?, pipelines re-shaded), in order.
STEPS = [
    ("start", SIM, 1.0, "central", True, ["symbolic", "numeric"]),
    ("eps-1e-6", SIM.replace(eps=1e-6), 1.0, "central", False, ["numeric"]),
    ("beta-0.7", SIM.replace(eps=1e-6, beta=0.7), 1.0, "central", False, ["symbolic", "numeric"]),
    ("chart-beta-1.5", SIM.replace(eps=1e-6, beta=1.5, bump="chart"), 1.0, "central", False,
     ["symbolic", "numeric"]),
    ("sine-eps-1e-9", SIM.replace(eps=1e-9, beta=1.5, bump="chart", height_field="sine"), 1.0, "central", False,
     ["symbolic", "numeric"]),
    ("sine-ku-5", SIM.replace(eps=1e-9, beta=1.5, bump="chart", height_field="sine", k_u=5.0), 1.0, "central",
     False, ["symbolic", "numeric"]),
    ("sine-kv-7", SIM.replace(eps=1e-9, beta=1.5, bump="chart", height_field="sine", k_u=5.0, k_v=7.0), 1.0,
     "central", False, ["symbolic", "numeric"]),
    ("footprint", SIM.replace(eps=1e-9, beta=1.5, bump="chart", height_field="sine", k_u=5.0, k_v=7.0), 1.0,
     "footprint", False, ["numeric"]),
    ("footprint-eps-moves", SIM.replace(eps=1e-2, beta=1.5, bump="chart", height_field="sine", k_u=5.0, k_v=7.0),
     1.0, "footprint", False, []),
    ("footprint-beta-0.2", SIM.replace(eps=1e-2, beta=0.2, height_field="sine", k_u=5.0, k_v=7.0), 1.0,
     "footprint", False, ["symbolic", "numeric"]),
    ("rings-eps-1e-2", SIM.replace(eps=1e-2, beta=0.5, height_field="rings"), 1.0, "central", False,
     ["symbolic", "numeric"]),
    ("rings-pole-x8", SIM.replace(eps=1e-2, beta=0.5, height_field="rings"), 8.0, "central", True,
     ["symbolic", "numeric"]),
    ("beta-0", SIM.replace(eps=1e-2, beta=0.0, height_field="rings"), 8.0, "central", False,
     ["symbolic", "numeric"]),
    ("no-sphere-b", SIM.replace(eps=1e-2, beta=0.0, height_field="rings", sphere_b=False), 8.0, "central", True,
     ["symbolic", "numeric"]),
    ("phong-ridges", SIM.replace(eps=1e-3, sphere_b=False, model="phong"), 1.0, "central", True,
     ["symbolic", "numeric"]),
    ("ridges-eps-1e-3", SIM.replace(eps=1e-5, sphere_b=False, model="phong"), 1.0, "central", False, ["numeric"]),
]
ARRAYS = ("image", "grad", "chamber", "kink", "uv")


def run(module_dir, out_dir, steps=STEPS, strides=(1,)):
    """Run the driver, the U-curve at each of ``strides`` per step; {id: its JSON line}.
    Raises RuntimeError if node fails."""
    node = node_command("the re-shade test runs the simulator's renderer under node")
    out_dir.mkdir(parents=True, exist_ok=True)
    spec = dict(width=WIDTH, height=HEIGHT, curve=CURVE, strides=list(strides),
                steps=[dict(id=i, scene=scene_json(s), zoom=z, numeric=n) for i, s, z, n, _, _ in steps])
    (out_dir / "spec.json").write_text(json.dumps(spec), encoding="utf-8")
    proc = subprocess.run([*node, str(DRIVERS / "reshade_driver.mjs"), str(module_dir), str(out_dir / "spec.json"),
                           str(out_dir)], capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"node re-shade driver failed:\n{proc.stderr}")
    return {rec["id"]: rec for rec in map(json.loads, proc.stdout.splitlines())}


def sample_ledger(numeric, symbolic, stride):
    """max and RMS |dI| over the pixels of sphere A (in both frames) whose column and row
    are multiples of ``stride``, summed in the simulator's order (row-major, then channel)."""
    image_n, _, chamber_n, _, _ = numeric
    image_s, _, chamber_s, _, _ = symbolic
    top, sum2, count = 0.0, 0.0, 0
    for j in range(0, HEIGHT, stride):
        for i in range(0, WIDTH, stride):
            if chamber_n[j, i] != 1 or chamber_s[j, i] != 1:
                continue
            count += 1
            for c in range(3):
                d = abs(float(image_n[j, i, c]) - float(image_s[j, i, c]))
                top = max(top, d)
                sum2 += d * d
    return top, math.sqrt(sum2 / (3 * count)) if count else 0.0


def problems(module_dir, out_dir, steps=STEPS):
    """Every way the re-shaded frames, the G-buffer reuse or the U-curve depart from full renders."""
    try:
        records = run(module_dir, out_dir, steps)
    except RuntimeError as error:
        return [f"driver: {error}"]
    bad = []
    for step_id, scene, zoom, numeric, full, shaded in steps:
        rec = records[step_id]
        if rec["full"] != full or rec["shaded"] != shaded:
            bad.append(f"{step_id}: new G-buffer {rec['full']} (expected {full}), re-shaded {rec['shaded']} "
                       f"(expected {shaded})")
        for pipe, ref in (("numeric", "numeric"), ("symbolic", "exact")):
            got = read_frame(out_dir, f"{step_id}.reshade.{pipe}", WIDTH, HEIGHT)
            want = read_frame(out_dir, f"{step_id}.render.{ref}", WIDTH, HEIGHT)
            for name, a, b in zip(ARRAYS, got, want):
                if a.tobytes() != b.tobytes():
                    bad.append(f"{step_id}: {pipe} {name}: {int(np.count_nonzero(a != b))} values differ")
        for eps, point, full_ledger in zip(CURVE, rec["curves"]["1"], rec["curve_render"]):
            if (point["max_abs"], point["rms"]) != (full_ledger["max_abs"], full_ledger["rms"]):
                bad.append(f"{step_id}: curve at eps = {eps:g}: {point} != compare {full_ledger}")
    return bad


@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    return write_modules(tmp_path_factory.mktemp("js"))


def test_the_steps_cover_the_bump_fields_and_the_geometry():
    changed = set()
    for (_, a, za, na, _, _), (_, b, zb, nb, _, _) in zip(STEPS, STEPS[1:]):
        changed |= {f for f in a.__dataclass_fields__ if getattr(a, f) != getattr(b, f)}
        changed |= {"zoom"} if za != zb else set()
        changed |= {"numeric"} if na != nb else set()
    assert set(jsgen_bump_fields()) <= changed
    assert {"zoom", "sphere_b", "model", "numeric"} <= changed
    assert {s.bump for _, s, *_ in STEPS} == {"chart", "surface"}
    # The field changes, between a field with creases and one without (from their records).
    assert {bool(s.field.crease_factors) for _, s, *_ in STEPS} == {True, False} and "height_field" in changed


def jsgen_bump_fields():
    """BUMP_FIELDS as render.js declares them."""
    text = (jsgen.JS_DIR / "render.js").read_text(encoding="utf-8")
    line = next(ln for ln in text.splitlines() if ln.startswith("export const BUMP_FIELDS"))
    return json.loads(line.split("=", 1)[1].strip().rstrip(";"))


def test_reshaded_frames_are_full_renders_bit_for_bit(modules, tmp_path):
    assert problems(modules, tmp_path) == []


def test_the_sampled_curve_is_the_ledger_of_its_pixels(modules, tmp_path):
    """The U-curve's sample (every SAMPLE_STRIDE-th column and row) against the ledger of those
    pixels computed here from a full central render at each step."""
    node = node_command("the re-shade test runs the simulator's renderer under node")
    step_id, scene = "sample", SIM.replace(height_field="sine")
    spec = []
    for eps in CURVE:
        spec.append(dict(id=f"{step_id}.curve.{eps:g}", scene=scene_json(scene.replace(eps=eps)), width=WIDTH,
                         height=HEIGHT, gradient="central", zoom=1.0))
    spec.append(dict(id=f"{step_id}.exact", scene=scene_json(scene), width=WIDTH, height=HEIGHT, gradient="exact",
                     zoom=1.0))
    (tmp_path / "cases.json").write_text(json.dumps(spec), encoding="utf-8")
    subprocess.run([*node, str(DRIVERS / "parity_driver.mjs"), str(modules), str(tmp_path / "cases.json"),
                    str(tmp_path)], check=True, capture_output=True, timeout=600)
    records = run(modules, tmp_path / "seq", [(step_id, scene, 1.0, "central", True, ["symbolic", "numeric"])],
                  strides=(1, SAMPLE_STRIDE))
    curves = records[step_id]["curves"]
    symbolic = read_frame(tmp_path, f"{step_id}.exact", WIDTH, HEIGHT)
    for eps, point in zip(CURVE, curves[str(SAMPLE_STRIDE)]):
        want = sample_ledger(read_frame(tmp_path, f"{step_id}.curve.{eps:g}", WIDTH, HEIGHT), symbolic, SAMPLE_STRIDE)
        assert (point["max_abs"], point["rms"]) == want, eps
        assert point["pixels_a"] < curves["1"][0]["pixels_a"] / 4     # a sample, not every pixel
    # The check can fail: the wrong stride's ledger is another number.
    assert sample_ledger(read_frame(tmp_path, f"{step_id}.curve.{CURVE[1]:g}", WIDTH, HEIGHT), symbolic,
                         SAMPLE_STRIDE + 1) != (curves[str(SAMPLE_STRIDE)][1]["max_abs"],
                                                curves[str(SAMPLE_STRIDE)][1]["rms"])


def test_a_geometry_field_cannot_be_reshaded(modules, tmp_path):
    """shade_a refuses a scene whose geometry is not the G-buffer's, naming the field."""
    node = node_command("the re-shade test runs the simulator's renderer under node")
    script = tmp_path / "refuse.mjs"
    script.write_text(
        f'import {{ gbuffer, shade_a, PairRenderer }} from "{(modules / "render.js").as_uri()}";\n'
        f'import {{ DEFAULT_SCENE }} from "{(modules / "constants.js").as_uri()}";\n'
        "const gb = gbuffer(DEFAULT_SCENE, 8, 8);\n"
        "const out = [];\n"
        "for (const f of [() => shade_a(gb, { ...DEFAULT_SCENE, sphere_b: false }, 'exact'),\n"
        "                 () => shade_a(gb, { ...DEFAULT_SCENE, bump: 'surface', beta: 1.0 }, 'exact'),\n"
        "                 () => new PairRenderer().update(DEFAULT_SCENE, 8, 8, 1.0, 'exact')]) {\n"
        "  try { f(); out.push('accepted'); } catch (e) { out.push(`${e.name}: ${e.message}`); }\n"
        "}\n"
        "console.log(JSON.stringify(out));\n", encoding="utf-8")
    proc = subprocess.run([*node, str(script)], capture_output=True, text=True, timeout=60, check=True)
    sphere_b, beta, exact = json.loads(proc.stdout)
    assert sphere_b.startswith("RangeError: scene.sphere_b is false, but the G-buffer was made with true")
    assert beta.startswith("RangeError: beta must be < radius_a = 1 when bump is \"surface\", got 1")
    assert exact.startswith("RangeError: numeric must be a numeric gradient")


#: name: (old text of render.js, new text).  Each must make `problems` report something.
WRONG_VARIANTS = {
    "re-shade keeps the numeric gradient after eps moved": (
        'numeric, numeric === "central" ? scene.eps : null]', "numeric, null]"),
    "re-shade reuses stale gradients whenever the field stays": (
        "const same = this.frames[name] !== null && grad === this.keys[name + \"_grad\"];",
        "const same = this.frames[name] !== null && JSON.parse(grad)[0] === JSON.parse(this.keys[name + \"_grad\"] "
        "?? \"[null]\")[0];"),
    "height-field terms kept when k_u moved": ("const key = `${s.field} ${s.k_u} ${s.k_v}`;",
                                               "const key = `${s.field} ${s.k_v}`;"),
    "a geometry key blind to sphere B": ("!BUMP_FIELDS.includes(name))]);",
                                         "!BUMP_FIELDS.includes(name) && name !== \"sphere_b\")]);"),
    "curve gradients kept when the field changed": ("const key = JSON.stringify([terms.key, eps_list, stride]);",
                                                    "const key = JSON.stringify([eps_list, stride]);"),
    "reach masks without sphere B's cast shadow": (
        "gb.lit[q] = reach(s, s.lights[l].position, px.P, N, SPHERE_A, null, px.w, false) ? 1 : 0;",
        "gb.lit[q] = reach(s, s.lights[l].position, px.P, N, SPHERE_B, null, px.w, false) ? 1 : 0;"),
}


@pytest.mark.parametrize("variant", sorted(WRONG_VARIANTS))
def test_the_check_rejects_a_wrong_reshade(variant, tmp_path):
    old, new = WRONG_VARIANTS[variant]

    def transform(name, text):
        if name != "render":
            return text
        assert old in text, f"variant {variant!r} no longer applies to render.js"
        return text.replace(old, new)

    found = problems(write_modules(tmp_path / "js", transform), tmp_path / "out")
    assert found, f"wrong variant {variant!r} passed"


def _node_json(modules, tmp_path, why, imports, expression):
    """The JSON value of the JavaScript ``expression`` under node, with ``imports`` ({module: names}) of
    the simulator's modules in ``modules``; ``why`` names the test (`node_command`)."""
    script = tmp_path / "probe.mjs"
    script.write_text("".join(f'import {{ {", ".join(names)} }} from "{(modules / f"{m}.js").as_uri()}";\n'
                              for m, names in imports.items()) + f"console.log(JSON.stringify({expression}));\n",
                      encoding="utf-8")
    out = subprocess.run([*node_command(why), str(script)], check=True, capture_output=True, text=True, timeout=120)
    return json.loads(out.stdout)


def test_the_simulators_curve_steps_are_the_half_decades_python_measures(modules, tmp_path):
    """The simulator's U-curve steps (``CURVE_LOG_EPS`` as the slider prints them, `eps_of`) are
    `lab.accuracy.HALF_DECADES`, the steps the book's image-best step is measured over; and they are
    every half decade of the slider, both ends included."""
    from lab.accuracy import HALF_DECADES
    from renderer.ledger import CURVE_LOG_EPS, SLIDER_LOG_EPS
    assert (CURVE_LOG_EPS[0], CURVE_LOG_EPS[-1]) == SLIDER_LOG_EPS
    assert np.diff(CURVE_LOG_EPS).tolist() == [0.5] * (len(CURVE_LOG_EPS) - 1)
    steps, slider = _node_json(modules, tmp_path, "the simulator's curve steps are read under node",
                               {"constants": ["CURVE_LOG_EPS"], "simulator": ["eps_of", "CONTROLS"]},
                               "[CURVE_LOG_EPS.map(eps_of), ['min', 'max'].map((k) => "
                               "CONTROLS.find((c) => c.name === 'log_eps')[k])]")
    assert steps == [float(f"{x:.2g}") for x in HALF_DECADES]
    assert tuple(slider) == SLIDER_LOG_EPS


def test_the_simulators_curve_samples_at_most_curve_sample_pixels_a_side_and_no_fewer_than_it_must(
        modules, tmp_path):
    """``curve_stride(resolution)``: the U-curve reads every stride-th column and row, so at most
    ``CURVE_SAMPLE`` of them a side at every resolution the control offers and every side up to
    `renderer.render.MAX_SIDE`, and the least such stride (one less would read more than
    ``CURVE_SAMPLE``)."""
    from renderer.render import MAX_SIDE
    sample, offered, strides = _node_json(
        modules, tmp_path, "the simulator's curve stride is read under node",
        {"simulator": ["curve_stride", "CURVE_SAMPLE", "CONTROLS"]},
        f"[CURVE_SAMPLE, CONTROLS.find((c) => c.name === 'resolution').options, "
        f"Array.from({{ length: {MAX_SIDE} }}, (_, i) => curve_stride(i + 1))]")
    assert set(offered) <= set(range(1, MAX_SIDE + 1)), offered
    read = lambda side, stride: -(-side // stride)            # columns 0, stride, 2 stride, ... below side
    bad = [(side, stride) for side, stride in enumerate(strides, 1)
           if read(side, stride) > sample or (stride > 1 and read(side, stride - 1) <= sample)]
    assert not bad, bad[:5]
