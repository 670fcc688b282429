"""Proof checks for §3: the tangent frame and the closed-form gradients.

Each identity is decided by sympy (``simplify(lhs - rhs) == 0``), and each has a
companion showing that a wrong variant is rejected.  The full theorem registry
(proofs/ objects with verdicts) extends these.
"""

import pytest
import sympy as sp

from renderer import fields

theta, phi = sp.symbols("theta phi", real=True)
N = sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
# §3's formulas, written from the components of N (not from the derivatives).
Nx, Ny, Nz = N
e_theta = sp.Matrix([-Ny, Nx, 0]) / sp.sin(phi)
e_phi = sp.Matrix([Nz * Nx, Nz * Ny, -sp.sin(phi) ** 2]) / sp.sin(phi)


def is_zero(expr):
    return sp.simplify(expr) == 0


@pytest.mark.parametrize("lhs, rhs", [
    (e_theta.dot(e_theta), 1), (e_phi.dot(e_phi), 1), (e_theta.dot(e_phi), 0),
    (e_theta.dot(N), 0), (e_phi.dot(N), 0),
])
def test_frame_is_orthonormal_and_tangent(lhs, rhs):
    assert is_zero(lhs - rhs)


def test_frame_equals_chart_derivatives():
    assert all(is_zero(c) for c in e_theta - sp.diff(N, theta) / sp.sin(phi))
    assert all(is_zero(c) for c in e_phi - sp.diff(N, phi))


def test_frame_orientation_is_minus_one():
    # The seed's Cell 2 prints this value and calls it "aligned with N".
    assert sp.simplify(e_theta.cross(e_phi).dot(N)) == -1


def test_wrong_frame_is_rejected():
    wrong = sp.Matrix([Nz * Nx, Nz * Ny, -sp.sin(phi)])       # a dropped 1/sin(phi) factor
    assert not is_zero(wrong.dot(wrong) - 1)
    assert sp.simplify(e_phi.cross(e_theta).dot(N)) != -1     # swapped order flips the sign


u, v, ku, kv = fields.u, fields.v, fields.k_u, fields.k_v
s1, s2 = sp.sin(sp.pi * ku * u), sp.sin(sp.pi * kv * v)
sigma = sp.sign(s1 * s2)
# The closed forms printed in seed §3.
SECTION3 = {
    "sine": (sp.pi * ku * sp.cos(sp.pi * ku * u) * s2, sp.pi * kv * s1 * sp.cos(sp.pi * kv * v)),
    "ridges": (sp.pi * ku * sp.cos(sp.pi * ku * u) * s2 * sigma,
               sp.pi * kv * s1 * sp.cos(sp.pi * kv * v) * sigma),
    "rings": (sp.Integer(0), 2 * sp.pi * kv * sp.cos(2 * sp.pi * kv * v)),
}


@pytest.mark.parametrize("name", sorted(SECTION3))
def test_generated_gradient_equals_section3(name):
    for generated, printed in zip(fields.GRADIENT_EXPRS[name], SECTION3[name]):
        assert is_zero(generated - printed)


def test_wrong_gradient_is_rejected():
    hu, _ = fields.GRADIENT_EXPRS["sine"]
    assert not is_zero(hu - sp.pi * ku * sp.cos(sp.pi * ku * u))   # dropped factor s2
    _, hv = fields.GRADIENT_EXPRS["rings"]
    assert not is_zero(hv - sp.pi * kv * sp.cos(2 * sp.pi * kv * v))  # lost factor 2
