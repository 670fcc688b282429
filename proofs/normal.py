"""The perturbed normal: its beta-derivative and its beta -> 0 limit (seed §3, Cells 5, 6).

The theorems are about the renderer's perturbed normals,
`renderer.formulas.PERTURBED_NORMAL` ("chart": the seed's formula; "surface":
the normal of the displaced sphere).  The independent side is the seed's
formula N' = M / |M| with M = N + beta g, g = h_u e_theta + h_v e_phi, written
here.
"""

import numpy as np
import sympy as sp

from renderer import formulas as F

from .core import Identity, Theorem, Verdict, check_identities

Nv = sp.Matrix([F.N_x, F.N_y, F.N_z])
et, ep = sp.Matrix(F.e_theta), sp.Matrix(F.e_phi)
#: The renderer's chart-mode normal, a function of N, the frame, (h_u, h_v) and beta.
N_PRIME = sp.Matrix(F.PERTURBED_NORMAL["chart"])
#: The seed's formula (§3), written here: the bump direction g and M = N + beta g.
g = F.h_u * et + F.h_v * ep
M = Nv + F.beta * g
norm_M = sp.sqrt(M.dot(M))
DOMAIN = {**{s: (-2.0, 2.0) for s in list(Nv) + list(et) + list(ep) + [F.h_u, F.h_v]},
          F.beta: (0.01, 3.0)}

#: M as the book shows it: the frame's components named as in §3.
M_SHOWN = M.subs({**dict(zip(et, sp.symbols(r"e_{\theta\,x} e_{\theta\,y} e_{\theta\,z}"))),
                  **dict(zip(ep, sp.symbols(r"e_{\varphi\,x} e_{\varphi\,y} e_{\varphi\,z}")))})

CLOSED_FORM = (sp.eye(3) - N_PRIME * N_PRIME.T) * g / norm_M


def _identities(closed_form):
    return [Identity(r"N' = M/\lVert M\rVert", N_PRIME, M / norm_M, DOMAIN),
            Identity(r"\partial N'/\partial\beta", sp.diff(N_PRIME, F.beta), closed_form, DOMAIN)]


def _check_derivative(closed_form):
    verdict = check_identities(_identities(closed_form))
    if not verdict.holds:
        return verdict
    return Verdict(verdict.status, f"renderer.formulas.PERTURBED_NORMAL['chart']: {verdict.evidence}",
                   verdict.residual, verdict.digits, verdict.points)


NORMAL_BETA_DERIVATIVE = Theorem(
    id="normal-beta-derivative", title="The beta-derivative of the perturbed normal",
    statement=r"The renderer's shading normal (`renderer.formulas.PERTURBED_NORMAL['chart']`) is "
              r"$N' = M/\lVert M\rVert$ with $M = N + \beta g$, $g = h_u e_\theta + h_v e_\varphi$, and "
              r"$\partial N'/\partial\beta = (I - N'N'^{\top})\,g/\lVert M\rVert$, for any $N$, frame and "
              r"gradient.",
    steps=((r"M", r"M", M_SHOWN), (r"N'", r"N'", r"M/\lVert M\rVert"),
           (r"\partial N'/\partial\beta", r"\partial N'/\partial\beta",
            r"(I - N'N'^{\top})\,g/\lVert M\rVert")),
    check=lambda: _check_derivative(CLOSED_FORM),
    wrong_variants=(("sign of the projection flipped",
                     lambda: _check_derivative((sp.eye(3) + N_PRIME * N_PRIME.T) * g / norm_M)),
                    ("the 1/|M| factor dropped",
                     lambda: _check_derivative((sp.eye(3) - N_PRIME * N_PRIME.T) * g))),
    pages=("s3", "s5"),
    seed_says="§3 and §6: 'verified to 1e-12' (Cell 5); Cell 5's Expect: '~1e-9 worst component'.",
)

theta, phi = sp.symbols("theta phi", real=True)
N_unit = sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
ON_SPHERE = {F.N_x: N_unit[0], F.N_y: N_unit[1], F.N_z: N_unit[2]}
#: Both of the renderer's perturbed normals at beta = 0, for a unit N.
AT_BETA_ZERO = {mode: sp.Matrix(n).subs(F.beta, 0).subs(ON_SPHERE) for mode, n in F.PERTURBED_NORMAL.items()}
UNIT_DOMAIN = {theta: (-3.1, 3.1), phi: (0.0, 3.14),
               **{s: (-2.0, 2.0) for s in list(et) + list(ep) + [F.h_u, F.h_v, F.h]},
               F.R: (0.5, 2.0), F.sin_phi: (0.0, 1.0)}


def _render_regression(beta_value):
    """Bitwise comparison of beta = ``beta_value`` renders against the unbumped scene.

    The unbumped scene is any height field at beta = 0 (the gradient does not
    reach the shading); each render is independent.
    """
    from renderer import Scene, render
    reference = render(Scene(height_field="sine", beta=0.0, k_u=3.0), 96, 80).image
    mismatched = 0
    for field in ("sine", "ridges", "rings"):
        for gradient in ("exact", "central"):
            image = render(Scene(height_field=field, beta=beta_value), 96, 80, gradient=gradient).image
            mismatched += int(np.count_nonzero(image != reference))
    return mismatched


def _check_regression(beta_value=0.0):
    symbolic = check_identities([Identity(rf"N'_{{\mathrm{{{mode}}}}}|_{{\beta=0}}", n, N_unit, UNIT_DOMAIN)
                                 for mode, n in AT_BETA_ZERO.items()])
    if not symbolic.holds:
        return symbolic
    mismatched = _render_regression(beta_value)
    if mismatched:
        return Verdict("refuted", f"beta = {beta_value}: {mismatched} channel values differ from the "
                       "unbumped render")
    return Verdict(symbolic.status, f"renderer.formulas.PERTURBED_NORMAL (both modes): {symbolic.evidence}; "
                   "6 renders (3 fields x 2 pipelines, 96x80) equal the unbumped render bit for bit")


BETA_ZERO_REGRESSION = Theorem(
    id="beta-zero-regression", title="The beta -> 0 regression",
    statement=r"At $\beta = 0$ both of the renderer's perturbed normals "
              r"(`renderer.formulas.PERTURBED_NORMAL`, bump modes chart and surface) are $N' = N$ "
              r"exactly for unit $N$, and the rendered image equals the unbumped render bit for bit, "
              r"for both pipelines and every height field.",
    steps=tuple((rf"N'_{{\mathrm{{{mode}}}}}|_{{\beta=0}}", n.applyfunc(sp.simplify), N_unit)
                for mode, n in AT_BETA_ZERO.items()),
    check=_check_regression,
    wrong_variants=(("beta = 1e-3 instead of 0", lambda: _check_regression(1e-3)),),
    pages=("s3", "s5"),
    seed_says="Cell 6 expects beta = 0 agreement at ~1e-16.",
)

THEOREMS = (NORMAL_BETA_DERIVATIVE, BETA_ZERO_REGRESSION)
