"""renderer.jsgen: the generated modules come from sympy, and the bundle is joined safely."""

from __future__ import annotations

import subprocess

import pytest
import sympy as sp

from renderer import fields, jsgen

from .jsnode import require_tool


def test_fields_js_is_printed_from_the_sympy_expressions():
    text = jsgen.fields_js()
    for name, (hu, hv) in fields.GRADIENT_EXPRS.items():
        replacements, (ru, rv) = sp.cse([hu, hv])
        assert f"out[0] = {sp.jscode(ru)};" in text, name
        assert f"out[1] = {sp.jscode(rv)};" in text, name
    assert "det_sin(Math.PI*k_u*u)*det_sin(Math.PI*k_v*v)" in text
    assert "Math.sin(" not in text.split("function gradient_sine")[0]   # h uses the deterministic sine


def test_constants_js_carries_the_python_defaults():
    text = jsgen.constants_js()
    assert '"height_field": "ridges"' in text and '"eps": 0.001' in text
    assert "export const POLE_SIN_PHI = 0.0001;" in text


def test_bundle_is_valid_javascript(tmp_path):
    node = require_tool("node", "node --check parses the bundle")
    path = jsgen.write_bundle(tmp_path / "simulator.js")
    subprocess.run([node, "--check", str(path)], check=True, timeout=60)
    text = path.read_text()
    assert "import " not in text.replace("// ", "") and "\nexport " not in text
    assert "http://" not in text and "https://" not in text


def _sources(**changes):
    src = dict(jsgen._sources())
    src.update(changes)
    return src


def test_bundle_rejects_an_import_of_a_name_not_exported():
    bad = jsgen._sources()["ledger"].replace("import { SPHERE_A }", "import { SPHERE_A, NOT_THERE }")
    with pytest.raises(jsgen.BundleError, match="NOT_THERE"):
        jsgen.bundle_source(_sources(ledger=bad))


def test_bundle_rejects_a_forward_import():
    bad = 'import { render } from "./render.js";\n' + jsgen._sources()["geometry"]
    with pytest.raises(jsgen.BundleError, match="not an earlier module"):
        jsgen.bundle_source(_sources(geometry=bad))


def test_bundle_rejects_a_name_declared_twice():
    bad = jsgen._sources()["ledger"] + "\nfunction _dot(a, b) { return a * b; }\n"
    with pytest.raises(jsgen.BundleError, match="_dot"):
        jsgen.bundle_source(_sources(ledger=bad))


def test_bundle_rejects_an_unhandled_export_form():
    bad = jsgen._sources()["ledger"] + "\nexport default compare;\n"
    with pytest.raises(jsgen.BundleError, match="export default"):
        jsgen.bundle_source(_sources(ledger=bad))


def test_generated_files_get_the_usual_permissions(tmp_path):
    """mkstemp creates 0600 files; a generated script must be readable like any other."""
    from renderer.files import umask
    path = jsgen.write_bundle(tmp_path / "sim.js")
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask()
    assert (path.stat().st_mode & 0o777) != 0o600 or umask() == 0o066
