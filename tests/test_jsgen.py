"""renderer.jsgen: the generated modules come from their sources, and the bundle is joined safely."""

from __future__ import annotations

import importlib.util
import json
import math
import re
import subprocess
from pathlib import Path
from types import SimpleNamespace

import pytest

from renderer import codegen, fieldcode, generated, jsgen, pointwise
from renderer import formulas as F

from .jsnode import node_command

ROOT = Path(__file__).parents[1]


def _node():
    return node_command("the generated JavaScript is run under node")


# ---- the generated modules -------------------------------------------------------------

def test_formulas_js_is_the_generators_output():
    """formulas.js is renderer.codegen's JavaScript, unaltered, and the bundle carries it."""
    assert jsgen.formulas_js() == codegen.js_source()
    assert jsgen.sources()["formulas"] == codegen.js_source()
    bundle = jsgen.bundle_source()
    body = codegen.js_source().replace("export ", "")
    assert body in bundle


def test_the_book_uses_the_regenerated_bundle(tmp_path):
    """book/_ext/simulator_assets.py writes exactly `bundle_source` into the site's static files."""
    spec = importlib.util.spec_from_file_location("simulator_assets", ROOT / "book" / "_ext" / "simulator_assets.py")
    assets = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(assets)
    app = SimpleNamespace(outdir=str(tmp_path / "_build" / "html"))
    config = SimpleNamespace(html_static_path=["_static"])
    assets._generate(app, config)
    static = Path(config.html_static_path[-1])
    assert (static / "sim" / "simulator.js").read_text(encoding="utf-8") == jsgen.bundle_source()


def test_the_bundle_is_made_again_when_the_sources_change(tmp_path, monkeypatch):
    """simulator_assets keeps the bundle while the source digest it was made from holds, and makes it again
    when the digest changes (an edit of renderer/js or the formulas): a stale bundle is never served."""
    spec = importlib.util.spec_from_file_location("simulator_assets", ROOT / "book" / "_ext" / "simulator_assets.py")
    assets = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(assets)
    app = SimpleNamespace(outdir=str(tmp_path / "_build" / "html"))
    bundle = tmp_path / "_build" / "sim_static" / "sim" / "simulator.js"
    for digest, kept in (("one", False), ("one", True), ("two", False)):
        monkeypatch.setattr(assets, "source_digest", lambda digest=digest: digest)
        if bundle.exists():
            bundle.write_text("// what the build wrote before", encoding="utf-8")
        assets._generate(app, SimpleNamespace(html_static_path=["_static"]))
        want = "// what the build wrote before" if kept else jsgen.bundle_source()
        assert bundle.read_text(encoding="utf-8") == want, (digest, kept)


def test_a_built_book_carries_the_regenerated_bundle(book_html):
    """The simulator script of the built site (an audit: `make audit`) is today's bundle."""
    script = book_html / "_static" / "sim" / "simulator.js"
    assert script.read_text(encoding="utf-8") == jsgen.bundle_source(), \
        f"{script} is stale: rebuild the book"


#: A value for every argument name of `formulas.FUNCTIONS` (a unit normal, its
#: frame, a chart point away from creases and poles, a pixel of the default camera).
#: sin(phi) and the frame come from `renderer.pointwise`.
_N = (0.3, -0.4, math.sqrt(1 - 0.25))
_S = float(pointwise.chart(*_N)[2])
_ET, _EP = (tuple(map(float, e)) for e in pointwise.tangent_frame(*_N, _S))
ARGS = dict(u=0.31, v=0.58, k_u=8.0, k_v=4.0, eps_u=1e-3, eps_v=2e-3, N_x=_N[0], N_y=_N[1], N_z=_N[2],
            sin_phi=_S, et_x=_ET[0], et_y=_ET[1], et_z=_ET[2], ep_x=_EP[0], ep_y=_EP[1], ep_z=_EP[2],
            h_u=3.0, h_v=-2.0, beta=0.35, h=0.4, R=1.0, x=0.07, y=-0.1, dx=0.011, dy=0.012, camera_z=4.0,
            P_x=_N[0], P_y=_N[1], P_z=_N[2])


def _js_values(tmp_path, calls):
    """Run formulas.js under node: {key: (name, [args])} -> {key: value or [values]}."""
    module = tmp_path / "formulas.js"
    module.write_text(jsgen.formulas_js(), encoding="utf-8")
    driver = tmp_path / "driver.mjs"
    driver.write_text(
        f'import * as F from "{module.as_uri()}";\n'
        f"const calls = {json.dumps(calls)};\n"
        "const out = {};\n"
        "for (const [key, [name, args]] of Object.entries(calls)) {\n"
        "  const r = F[name](...args, new Float64Array(8));\n"
        "  out[key] = typeof r === 'object' ? Array.from(r) : r;\n"
        "}\n"
        "console.log(JSON.stringify(out));\n", encoding="utf-8")
    proc = subprocess.run([*_node(), str(driver)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_every_generated_function_runs_in_javascript_and_agrees_with_python(tmp_path):
    """Every function of formulas.js, every field's branch, runs under node (no
    Python name such as False printed into it) and returns what renderer/generated.py
    returns, to rounding: a handful of libm-vs-V8 ulps, amplified by at most
    1/eps = 1e3 in the central quotient, stays far inside 1e-9 relative."""
    calls, expect = {}, {}
    for name, (args, _) in F.FUNCTIONS.items():
        values = [ARGS[str(a)] for a in args]
        calls[name], expect[name] = (name, values), getattr(generated, name)(*values)
    for code, (field, record) in enumerate(F.FIELDS.items()):       # formulas.js's FIELD_CODES
        for name, (entry, keep) in codegen.JS_FIELD_FUNCTIONS.items():
            values = [ARGS[str(a)] for a in F.FIELD_FUNCTIONS[entry][0]]
            out = getattr(fieldcode.compiled(record), entry)(*values)
            out = out if isinstance(out, tuple) else (out,)
            calls[f"{name}[{field}]"] = (name, [code] + values)
            expect[f"{name}[{field}]"] = tuple(out[i] for i in keep)
    got = _js_values(tmp_path, calls)
    assert set(got) == set(calls)
    for key, want in expect.items():
        want = list(want) if isinstance(want, tuple) else [want]
        have = got[key] if isinstance(got[key], list) else [got[key]]
        have = have[:len(want)]
        for w, h in zip(want, have):
            if isinstance(w, bool) or type(w).__name__ == "bool_":
                # A flag: a boolean, or 1/0 where it is written into an `out` array.
                assert h in (0, 1) and bool(h) == bool(w), (key, h, w)
            else:
                assert math.isclose(h, w, rel_tol=1e-9, abs_tol=1e-12), (key, h, w)


def test_constants_js_carries_the_python_values():
    text = jsgen.constants_js()
    assert '"height_field": "ridges"' in text and '"eps": 0.001' in text
    assert 'export const GRADIENTS = ["exact", "central", "footprint"];' in text
    assert "export const TINY = 1e-300;" in text
    assert "export const FLOOR_LIGHT = 0.85;" in text and "export const FLOOR_DARK = 0.15;" in text


def test_the_modules_are_exactly_the_hand_written_files_and_the_generated_ones():
    """renderer/js holds the hand-written modules of MODULE_ORDER, nothing else (no stale module)."""
    on_disk = {p.stem for p in jsgen.JS_DIR.glob("*.js")}
    assert on_disk == set(jsgen.MODULE_ORDER) - set(jsgen.GENERATED)
    assert set(jsgen.GENERATED) <= set(jsgen.MODULE_ORDER)


# ---- nothing hand-written retypes a formula --------------------------------------------

#: Calls that only formulas.js may make (the chart's atan2 and hypot, the seed's acos, the gradients' cos).
_FORMULA_CALLS = ("Math.atan2", "Math.hypot", "Math.acos", "Math.cos", "Math.sign")
#: The constants of renderer/formulas.py.
_FORMULA_CONSTANTS = {float(c) for c in (F.POLE_SIN_PHI, F.KINK_BAND_HALF_WIDTH, F.FOOTPRINT_FALLBACK,
                                        F.FOOTPRINT_MAX)}
_NUMBER = re.compile(r"(?<![\w.])(\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?)")


def retyped_formulas(text):
    """Calls and numeric literals in ``text`` that belong to renderer/formulas.py."""
    code = "\n".join(line.split("//")[0] for line in text.splitlines())
    found = [c for c in _FORMULA_CALLS if c in code]
    found += [n for n in _NUMBER.findall(code) if float(n) in _FORMULA_CONSTANTS]
    return found


def test_the_renderer_core_retypes_no_formula():
    text = (jsgen.JS_DIR / "render.js").read_text(encoding="utf-8")
    assert retyped_formulas(text) == []
    # The check rejects a hand-written chart, pole cut-off or crease band.
    assert retyped_formulas(text + "\nconst theta = Math.atan2(N[1], N[0]);\n") == ["Math.atan2"]
    assert retyped_formulas(text + "\nif (sin_phi > 2.2250738585072014e-308) {}\n") == ["2.2250738585072014e-308"]
    assert retyped_formulas(text + "\nconst s = Math.hypot(N[0], N[1]);\n") == ["Math.hypot"]
    assert retyped_formulas(text + "\nconst band = Math.abs(f) < 0.03;\n") == ["0.03"]


# ---- the bundle --------------------------------------------------------------------------

def test_bundle_is_valid_javascript(tmp_path):
    path = jsgen.write_bundle(tmp_path / "simulator.js")
    subprocess.run([*_node(), "--check", str(path)], check=True, timeout=60)
    text = path.read_text()
    assert "import " not in text.replace("// ", "") and "\nexport " not in text
    assert "http://" not in text and "https://" not in text


def _sources(**changes):
    src = dict(jsgen.sources())
    src.update(changes)
    return src


def test_bundle_rejects_an_import_of_a_name_not_exported():
    bad = jsgen.sources()["ledger"].replace("import { SPHERE_A }", "import { SPHERE_A, NOT_THERE }")
    with pytest.raises(jsgen.BundleError, match="NOT_THERE"):
        jsgen.bundle_source(_sources(ledger=bad))


def test_bundle_rejects_a_forward_import():
    bad = 'import { render } from "./render.js";\n' + jsgen.sources()["formulas"]
    with pytest.raises(jsgen.BundleError, match="not an earlier module"):
        jsgen.bundle_source(_sources(formulas=bad))


def test_bundle_rejects_a_name_declared_twice():
    bad = jsgen.sources()["ledger"] + "\nfunction copysign(a, b) { return a; }\n"
    with pytest.raises(jsgen.BundleError, match="copysign"):
        jsgen.bundle_source(_sources(ledger=bad))


def test_bundle_rejects_an_unhandled_export_form():
    bad = jsgen.sources()["ledger"] + "\nexport default compare;\n"
    with pytest.raises(jsgen.BundleError, match="export default"):
        jsgen.bundle_source(_sources(ledger=bad))


def test_generated_files_get_the_usual_permissions(tmp_path):
    """mkstemp creates 0600 files; a generated script must be readable like any other."""
    from renderer.files import umask
    path = jsgen.write_bundle(tmp_path / "sim.js")
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask()
    assert (path.stat().st_mode & 0o777) != 0o600 or umask() == 0o066
