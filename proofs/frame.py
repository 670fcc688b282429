"""The tangent frame of sphere A (seed §3, Cell 2)."""

import sympy as sp

from .core import Identity, Theorem, Verdict, check_identities, identities_theorem

theta, phi = sp.symbols("theta phi", real=True)
N = sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
Nx, Ny, Nz = N
sin_phi = sp.sin(phi)
#: §3's frame, written from the components of N as the seed prints it.
e_theta = sp.Matrix([-Ny, Nx, 0]) / sin_phi
e_phi = sp.Matrix([Nz * Nx, Nz * Ny, -sin_phi**2]) / sin_phi
#: Sampling domain: away from the poles, where sin(phi) > 0.
DOMAIN = {theta: (-3.14, 3.14), phi: (0.01, 3.13)}


def _frame_identities(et, ep):
    return [
        Identity(r"e_\theta\cdot e_\theta", et.dot(et), sp.Integer(1), DOMAIN),
        Identity(r"e_\varphi\cdot e_\varphi", ep.dot(ep), sp.Integer(1), DOMAIN),
        Identity(r"e_\theta\cdot e_\varphi", et.dot(ep), sp.Integer(0), DOMAIN),
        Identity(r"e_\theta\cdot N", et.dot(N), sp.Integer(0), DOMAIN),
        Identity(r"e_\varphi\cdot N", ep.dot(N), sp.Integer(0), DOMAIN),
        Identity(r"e_\theta", et, sp.diff(N, theta) / sin_phi, DOMAIN),
        Identity(r"e_\varphi", ep, sp.diff(N, phi), DOMAIN),
    ]


FRAME_ORTHONORMAL = identities_theorem(
    "frame-orthonormal", "The tangent frame is orthonormal and tangent",
    r"For $0 < \varphi < \pi$, $e_\theta = (-N_y, N_x, 0)/\sin\varphi$ and "
    r"$e_\varphi = (N_z N_x, N_z N_y, -\sin^2\varphi)/\sin\varphi$ are unit vectors, orthogonal to "
    r"each other and to $N$, and equal $\frac{1}{\sin\varphi}\partial N/\partial\theta$ and "
    r"$\partial N/\partial\varphi$.",
    _frame_identities(e_theta, e_phi),
    [("e_phi with its 1/sin(phi) dropped",
      _frame_identities(e_theta, sp.Matrix([Nz * Nx, Nz * Ny, -sin_phi**2]))),
     ("e_theta with a flipped sign",
      [Identity(r"e_\theta", -e_theta, sp.diff(N, theta) / sin_phi, DOMAIN)])],
    pages=("s3",),
)


def _orientation(et, ep, claimed):
    return check_identities([Identity(r"(e_\theta\times e_\varphi)\cdot N", et.cross(ep).dot(N),
                                      sp.Integer(claimed), DOMAIN)])


def _orientation_value():
    return sp.simplify(e_theta.cross(e_phi).dot(N))


def _check_orientation() -> Verdict:
    value = _orientation_value()
    verdict = _orientation(e_theta, e_phi, value)
    if value not in (1, -1):
        return Verdict("refuted", f"(e_theta x e_phi) . N simplifies to {value}, not a sign")
    return Verdict(verdict.status, f"(e_theta x e_phi) . N = {value} exactly: the frame is "
                   f"{'right' if value == 1 else 'left'}-handed about the outward normal; "
                   + verdict.evidence, verdict.residual, verdict.digits, verdict.points)


FRAME_ORIENTATION = Theorem(
    id="frame-orientation", title="Orientation of the tangent frame",
    statement=r"$(e_\theta \times e_\varphi)\cdot N = -1$: the pair $(e_\theta, e_\varphi)$ is "
              r"left-handed about the outward normal, $e_\theta\times e_\varphi = -N$.",
    steps=((r"cross product", r"e_\theta\times e_\varphi", e_theta.cross(e_phi).applyfunc(sp.simplify)),
           (r"outward normal", "N", N),
           (r"orientation", r"(e_\theta\times e_\varphi)\cdot N", _orientation_value())),
    check=_check_orientation,
    wrong_variants=(("the seed's reading: aligned with N (+1)",
                     lambda: _orientation(e_theta, e_phi, 1)),),
    pages=("s3", "s5"),
    seed_says="Cell 2 prints (e_theta x e_phi) . N and labels the frame 'unit, aligned with N'.",
)

THEOREMS = (FRAME_ORTHONORMAL, FRAME_ORIENTATION)
