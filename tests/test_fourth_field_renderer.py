"""A fourth height field, registered as a newcomer would, reaches every renderer with no other edit.

The fixture writes a module of its own to a temporary directory, as a newcomer's file, that
registers h = sin^2(pi k_u u) sin^2(pi k_v v) as "squares" (`renderer.formulas.register`), and
imports it; nothing else in the repository changes.  Then, each against the independent
per-pixel reference of tests/scalar_reference.py (which evaluates the field's record) or against
the field's sympy objects:

* its generated functions (the kernel's compiled cfuncs, the array backends' and formulas.js's)
  with the checks of tests/test_codegen.py;
* the numba kernel and the array kernel on numpy and on Dr.Jit (skipped where Dr.Jit's LLVM
  backend is missing, failed when CI=true), with the parity check of tests/test_parity.py;
* the JavaScript renderer under node, bundled after the registration;
* `renderer.ucurve.measure`: its float64 central differences are the reference's quotients and
  its derivative the reference's;
* and a reader's expression, given to `Scene` as text, renders as the reference renders it.

The proofs' half of the fourth-field test is tests/test_fourth_field.py.
"""

from __future__ import annotations

import importlib
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from renderer import GRADIENTS, Scene, ucurve
from renderer import formulas as F

from . import scalar_reference as ref
from . import test_codegen as codegen_checks
from .jsnode import read_frame, run_render_cases, write_modules
from .test_parity import BACKENDS, U, assert_parity, field_bounds, parity_failures

NEWCOMER = '''"""A newcomer's height field: one record, registered."""
import sympy as sp

from renderer import formulas as F

SQUARES = F.register(F.HeightField("squares", sp.sin(sp.pi * F.k_u * F.u) ** 2 * sp.sin(sp.pi * F.k_v * F.v) ** 2))
'''
#: A reader's own field, as text (`renderer.formulas.field` parses it).
READERS = "cos(pi*k_u*u) * sin(pi*k_v*v)^3 + u/2"
#: A reader's field calling every function a field may (`formulas.ELEMENTARY`), each where it is real,
#: and both constants.
EVERY_FUNCTION = " + ".join(f"{f.__name__}((0.3*u + 0.2*v)*k_u/8 + 0.1)/8" for f in F.ELEMENTARY) + " + E*pi/64"


@pytest.fixture(scope="module")
def squares(tmp_path_factory):
    """The name of the field the newcomer's module registers, for this module's tests."""
    where = tmp_path_factory.mktemp("newcomer")
    (where / "squares_field.py").write_text(NEWCOMER, encoding="utf-8")
    sys.path.insert(0, str(where))
    try:
        yield importlib.import_module("squares_field").SQUARES.name
    finally:
        F.FIELDS.pop("squares", None)
        sys.modules.pop("squares_field", None)
        sys.path.remove(str(where))


def test_the_newcomers_module_registers_it(squares):
    assert squares == "squares" and list(F.FIELDS)[-1] == "squares" and squares not in F.BUILTIN
    assert Scene(height_field=squares).field is F.FIELDS[squares]


def test_its_generated_functions_agree_with_its_sympy_objects(squares, tmp_path):
    """The kernel's cfuncs, the numpy array functions and formulas.js, each against the mpmath
    value of the record's objects (tests/test_codegen.py's evaluator and allowance)."""
    from renderer import backends
    points = {key: pts for key, pts in codegen_checks._points(fields=(squares,)).items() if key[1] == squares}
    references = {key: [codegen_checks.reference(*key, p) for p in pts] for key, pts in points.items()}
    compiled = codegen_checks.outputs_of(None, points)
    xp = backends.namespace("numpy")
    arrays = codegen_checks.array_outputs(None, points, xp)
    javascript = codegen_checks.run_js(codegen_checks.codegen.js_source(), points, tmp_path)
    for name, results in (("compiled", compiled), ("numpy", arrays), ("javascript", javascript)):
        bad = codegen_checks.mismatches(results, references, points)
        assert bad == [], (name, bad[:3])


# The settings of the field's renders: every pipeline on every backend, the bump modes and
# models alternating (each pair of the four met at least once).
RENDERS = [(g, b, ("chart", "surface")[(i + j) % 2], ("blinn", "phong")[j % 2])
           for i, g in enumerate(GRADIENTS) for j, b in enumerate(BACKENDS)]


@pytest.mark.parametrize("gradient, backend, bump, model", RENDERS)
def test_every_kernel_renders_it_as_the_reference(squares, gradient, backend, bump, model):
    scene = Scene(height_field=squares, bump=bump, model=model, beta=0.6, k_u=5.0, k_v=3.0)
    assert_parity(scene, gradient, backend, ((24, 20),))


def test_the_node_renderer_renders_it_as_the_reference(squares, tmp_path):
    """formulas.js and the bundle's constants written after the registration: the simulator's
    renderer knows the field, and its frames pass the parity check."""
    modules = write_modules(tmp_path / "js")
    scene, size = Scene(height_field=squares, beta=0.6, k_u=5.0, k_v=3.0), (24, 20)
    run_render_cases(modules, [dict(id=g, scene=scene, width=size[0], height=size[1], gradient=g, zoom=1.0)
                               for g in GRADIENTS], tmp_path / "out")
    for gradient in GRADIENTS:
        image, grad, chamber, kink, _ = read_frame(tmp_path / "out", gradient, *size)
        frame = SimpleNamespace(image=image, grad=grad, chamber=chamber, kink=kink)
        assert parity_failures(scene, *size, gradient, frame=frame) == [], gradient


def test_its_u_curve_is_the_references(squares):
    """`ucurve.measure`'s float64 quotient (its derivative plus the measured truncation and
    roundoff) is the reference's central quotient at each step, to the quotient's rounding
    (each sample a few ulp of its argument times the Lipschitz bound, over the step); its
    derivative is the reference's exact one to a few ulp."""
    u, v, k_u, k_v = 0.23, 0.61, 5.0, 3.0
    steps = np.logspace(-1, -9, 9)
    lip = field_bounds(squares, k_u, k_v)[0]
    for k, component in enumerate("uv"):
        uc = ucurve.measure(squares, u, v, component, steps, k_u, k_v)
        assert uc.reason is None
        want = ref.grad_exact(squares, u, v, k_u, k_v)[k]
        assert abs(uc.derivative - want) <= 8 * U * (1 + abs(want)) * lip
        quotient = uc.derivative + uc.truncation + uc.roundoff
        reference = [ref.grad_central(squares, u, v, k_u, k_v, e)[k] for e in steps]
        assert np.all(np.abs(quotient - reference) <= 4 * (lip + 1) * 2 * U / steps + 4 * U * abs(want))


@pytest.mark.parametrize("text, gradient, backend", [
    (READERS, "exact", "numba"), (READERS, "central", "numpy"), (READERS, "footprint", "numba"),
    (EVERY_FUNCTION, "exact", "numba"), (EVERY_FUNCTION, "central", "numpy"), (EVERY_FUNCTION, "footprint", "drjit")],
    ids=lambda p: {READERS: "readers", EVERY_FUNCTION: "every-function"}.get(p))
def test_a_readers_expression_renders_as_the_reference(text, gradient, backend):
    scene = Scene(height_field=text, beta=0.5, bump="chart")
    assert scene.height_field not in F.FIELDS and scene.field.expr.has(F.u, F.v, F.k_u, F.k_v)
    assert_parity(scene, gradient, backend, ((17, 20),))


def test_the_checks_reject_another_field(squares):
    """The parity check sees the field: a frame of squares at other frequencies, or of sine,
    is refused against the squares reference."""
    from renderer import render
    scene = Scene(height_field=squares, beta=0.6, k_u=5.0, k_v=3.0)
    for wrong in (scene.replace(k_v=3.25), scene.replace(height_field="sine")):
        assert parity_failures(scene, 24, 20, "exact", frame=render(wrong, 24, 20)) != []
