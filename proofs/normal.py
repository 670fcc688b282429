"""The perturbed normal: its beta-derivative and its beta -> 0 limit (seed §3, Cells 5, 6)."""

import numpy as np
import sympy as sp

from .core import Identity, Theorem, Verdict, check_identities, identities_theorem

beta = sp.Symbol("beta", positive=True)
Nv = sp.Matrix(sp.symbols("N_x N_y N_z", real=True))
gv = sp.Matrix(sp.symbols("g_x g_y g_z", real=True))
M = Nv + beta * gv
norm_M = sp.sqrt(M.dot(M))
N_prime = M / norm_M
DOMAIN = {**{s: (-2.0, 2.0) for s in list(Nv) + list(gv)}, beta: (0.01, 3.0)}

CLOSED_FORM = (sp.eye(3) - N_prime * N_prime.T) * gv / norm_M

NORMAL_BETA_DERIVATIVE = identities_theorem(
    "normal-beta-derivative", "The beta-derivative of the perturbed normal",
    r"With $M = N + \beta g$ and $N' = M/\lVert M\rVert$: "
    r"$\partial N'/\partial\beta = (I - N'N'^{\top})\,g/\lVert M\rVert$, for any $N$ and $g$.",
    [Identity(r"\partial N'/\partial\beta", sp.diff(N_prime, beta), CLOSED_FORM, DOMAIN)],
    [("sign of the projection flipped", [Identity("dN'/dbeta", sp.diff(N_prime, beta),
                                                   (sp.eye(3) + N_prime * N_prime.T) * gv / norm_M,
                                                   DOMAIN)]),
     ("the 1/|M| factor dropped", [Identity("dN'/dbeta", sp.diff(N_prime, beta),
                                            (sp.eye(3) - N_prime * N_prime.T) * gv, DOMAIN)])],
    pages=("s3", "s5"),
    seed_says="§3 and §6: 'verified to 1e-12' (Cell 5); Cell 5's Expect: '~1e-9 worst component'.",
)

theta, phi = sp.symbols("theta phi", real=True)
N_unit = sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
g_sym = sp.Matrix(sp.symbols("g_x g_y g_z", real=True))
M0 = N_unit + 0 * g_sym
N_prime_0 = M0 / sp.sqrt(M0.dot(M0))
UNIT_DOMAIN = {theta: (-3.1, 3.1), phi: (0.0, 3.14)}


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
    symbolic = check_identities([Identity(r"N'|_{\beta=0}", N_prime_0, N_unit, UNIT_DOMAIN)])
    if not symbolic.holds:
        return symbolic
    mismatched = _render_regression(beta_value)
    if mismatched:
        return Verdict("refuted", f"beta = {beta_value}: {mismatched} channel values differ from the "
                       "unbumped render")
    return Verdict(symbolic.status, f"{symbolic.evidence}; 6 renders (3 fields x 2 pipelines, "
                   "96x80) equal the unbumped render bit for bit")


BETA_ZERO_REGRESSION = Theorem(
    id="beta-zero-regression", title="The beta -> 0 regression",
    statement=r"At $\beta = 0$, $N' = N$ exactly for unit $N$, and the rendered image equals the "
              r"unbumped render bit for bit, for both pipelines and every height field.",
    steps=((r"N'|_{\beta=0}", N_prime_0.applyfunc(sp.simplify), N_unit),),
    check=_check_regression,
    wrong_variants=(("beta = 1e-3 instead of 0", lambda: _check_regression(1e-3)),),
    pages=("s3", "s5"),
    seed_says="Cell 6 expects beta = 0 agreement at ~1e-16.",
)

THEOREMS = (NORMAL_BETA_DERIVATIVE, BETA_ZERO_REGRESSION)
