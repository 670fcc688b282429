"""The perturbed normal: its beta-derivative and its beta -> 0 limit (seed §3, Cells 5, 6).

The theorems are about the renderer's perturbed normals,
`renderer.formulas.PERTURBED_NORMAL` ("chart": the seed's formula; "surface":
the normal of the displaced sphere).  The independent side is the seed's
formula N' = M / |M| with M = N + beta g, g = h_u e_theta + h_v e_phi, written
here.
"""

import numpy as np
import sympy as sp

from renderer import BUMPS, HEIGHT_FIELDS
from renderer import formulas as F

from . import frame
from .core import Identity, Theorem, Verdict, check_identities

Nv = sp.Matrix([F.N_x, F.N_y, F.N_z])
et, ep = sp.Matrix(F.e_theta), sp.Matrix(F.e_phi)
#: The renderer's chart-mode normal, a function of N, the frame, (h_u, h_v) and beta.
N_PRIME = sp.Matrix(F.PERTURBED_NORMAL["chart"])
#: The seed's formula (§3), written here as the statement prints it (matrix
#: symbols N, e_theta, e_phi, g): the bump direction g and M = N + beta g.  The
#: check substitutes the renderer's symbols into these same objects, so the
#: statement cannot say one thing while another is checked.
N_S, G_S = sp.MatrixSymbol("N", 3, 1), sp.MatrixSymbol("g", 3, 1)
E_THETA_S, E_PHI_S = sp.MatrixSymbol(r"e_\theta", 3, 1), sp.MatrixSymbol(r"e_\varphi", 3, 1)
G_CLAIMED = F.h_u * E_THETA_S + F.h_v * E_PHI_S
M_CLAIMED = sp.MatAdd(N_S, F.beta * G_S, evaluate=False)
g = sp.Matrix(G_CLAIMED.subs({E_THETA_S: et, E_PHI_S: ep}).doit().as_explicit())
M = sp.Matrix(M_CLAIMED.subs({N_S: Nv, G_S: g}).doit().as_explicit())
norm_M = sp.sqrt(M.dot(M))
DOMAIN = {**{s: (-2.0, 2.0) for s in list(Nv) + list(et) + list(ep) + [F.h_u, F.h_v]},
          F.beta: (0.01, 3.0)}

#: M as the book shows it: the frame's components named as in §3.
M_SHOWN = M.subs({**dict(zip(et, sp.symbols(r"e_{\theta\,x} e_{\theta\,y} e_{\theta\,z}"))),
                  **dict(zip(ep, sp.symbols(r"e_{\varphi\,x} e_{\varphi\,y} e_{\varphi\,z}")))})

#: The claimed derivative as the statement prints it (matrix symbols N', g and the scalar
#: ||M||), and, substituted into it, the explicit 3-vector the check compares with.
NP_S = sp.MatrixSymbol("N'", 3, 1)
NORM_M_S = sp.Symbol(r"\lVert M\rVert", positive=True)
CLAIMED_DERIVATIVE = (sp.Identity(3) - NP_S * NP_S.T) * G_S / NORM_M_S


def explicit(shown):
    """The 3-vector of a claim written in N', g and ||M|| (as `CLAIMED_DERIVATIVE`)."""
    return sp.Matrix(shown.subs({NP_S: N_PRIME, G_S: g, NORM_M_S: norm_M}).doit().as_explicit())


CLOSED_FORM = explicit(CLAIMED_DERIVATIVE)


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
              rf"$N' = M/\lVert M\rVert$ with $M = {sp.latex(M_CLAIMED, order='none')}$, "
              rf"$g = {sp.latex(G_CLAIMED)}$, and "
              rf"$\partial N'/\partial\beta = {sp.latex(CLAIMED_DERIVATIVE)}$, for any $N$, frame and "
              r"gradient.",
    steps=((r"M", r"M", M_SHOWN), (r"N'", r"N'", r"M/\lVert M\rVert"),
           (r"\partial N'/\partial\beta", r"\partial N'/\partial\beta", CLAIMED_DERIVATIVE)),
    check=lambda: _check_derivative(CLOSED_FORM),
    wrong_variants=(("sign of the projection flipped",
                     lambda: _check_derivative(explicit((sp.Identity(3) + NP_S * NP_S.T) * G_S / NORM_M_S))),
                    ("the 1/|M| factor dropped",
                     lambda: _check_derivative(explicit((sp.Identity(3) - NP_S * NP_S.T) * G_S)))),
    pages=("s3", "s5"),
    seed_says="§3 and §6: 'verified to 1e-12' (Cell 5); Cell 5's Expect: '~1e-9 worst component'.",
)

#: The renderer's normals on the sphere, in the frame it uses there (regular
#: branch; for "surface", sin phi above the pole cut-off).
_FRAME_AT = {**frame.ON_SPHERE, **dict(zip(F.e_theta, frame.e_theta)), **dict(zip(F.e_phi, frame.e_phi))}
ON_FRAME = {mode: sp.Matrix(n).subs(sp.Max(F.sin_phi, F.POLE_SIN_PHI), F.sin_phi).subs(_FRAME_AT)
            for mode, n in F.PERTURBED_NORMAL.items()}
#: The frame's vectors as the statement prints them (non-commuting, so that they stay on the right).
E_THETA, E_PHI = sp.symbols(r"e_\theta e_\varphi", commutative=False)
#: The first-order tilt dN'/dbeta at beta = 0, written by hand in e_theta, e_phi: the chart
#: mode tilts by g = h_u e_theta + h_v e_phi (seed §3); the displaced sphere by the
#: gradient of beta h over the sphere's metric, |P_u| = 2 pi R sin phi, |P_v| = pi R.
TILT_SHOWN = {"chart": F.h_u * E_THETA + F.h_v * E_PHI,
              "surface": -(F.h_u / (2 * sp.pi * F.R * sp.sin(frame.phi))) * E_THETA
                         - (F.h_v / (sp.pi * F.R)) * E_PHI}


def tilt_vector(shown):
    """The 3-vector of a tilt written in e_theta, e_phi (as `TILT_SHOWN`), in the frame at N(theta, phi)."""
    return shown.coeff(E_THETA) * frame.e_theta + shown.coeff(E_PHI) * frame.e_phi


def tilt_latex(shown):
    return sp.latex(shown, symbol_names=frame.ANGLE_NAMES)


TILT = {mode: tilt_vector(t) for mode, t in TILT_SHOWN.items()}
SPHERE_DOMAIN = {frame.theta: (-3.1, 3.1), frame.phi: (0.05, 3.09), F.R: (0.5, 2.0), F.h: (-1.0, 1.0),
                 F.h_u: (-2.0, 2.0), F.h_v: (-2.0, 2.0)}
#: The renders: beta -> 0 over these steps, on a 96x80 frame.
RATE_BETAS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
TINY_BETA = 1e-12
#: The seed's two pipelines: the exact gradient and central differences.
PIPELINES = ("exact", "central")


def _limit_identities(tilt):
    ids = []
    for mode, n in ON_FRAME.items():
        ids += [Identity(rf"N'_{{\mathrm{{{mode}}}}}|_{{\beta=0}}", n.subs(F.beta, 0), frame.N, SPHERE_DOMAIN),
                Identity(rf"\partial_\beta N'_{{\mathrm{{{mode}}}}}|_{{\beta=0}}", n.diff(F.beta).subs(F.beta, 0),
                         tilt[mode], SPHERE_DOMAIN)]
    return ids


def _render_rate(reference_beta=0.0, tiny_beta=TINY_BETA, fields=HEIGHT_FIELDS):
    """Renders of ``fields`` x 2 bump modes x 2 pipelines (96x80): max |I(beta) - I(0)| over
    them per beta in RATE_BETAS and at ``tiny_beta`` (float64 array, length 8); the channel
    values of the beta = 0 renders (at ``reference_beta``, 0 but in a wrong variant) that differ
    between fields (the height field must not reach the shading at beta = 0); how many renders
    were compared; and how many of the configurations' beta = 1e-2 renders are distinct (each
    field, mode and pipeline must reach the image once beta > 0)."""
    from renderer import Scene, render
    worst = np.zeros(len(RATE_BETAS) + 1)
    across_fields = renders = 0
    bumped = set()
    for mode in BUMPS:
        for gradient in PIPELINES:
            base = None
            for field in fields:
                scene = Scene(height_field=field, bump=mode, beta=reference_beta)
                flat = render(scene, 96, 80, gradient=gradient).image
                base = flat if base is None else base
                across_fields += int(np.count_nonzero(flat != base))
                for k, b in enumerate(RATE_BETAS + (tiny_beta,)):
                    image = render(scene.replace(beta=b), 96, 80, gradient=gradient).image
                    worst[k] = max(worst[k], float(np.abs(image - flat).max()))
                    renders += 1
                    if k == 0:
                        bumped.add(image.tobytes())
    return worst, across_fields, renders, len(bumped)


def _check_limit(tilt=None, order=1.0, **sampling):
    """The limit beta -> 0: symbolic (N'(0) = N and dN'/dbeta at 0 = ``tilt``, both
    modes) and rendered (the images approach the beta = 0 image at rate beta^``order``;
    ``sampling`` goes to `_render_rate`, for the wrong variants)."""
    symbolic = check_identities(_limit_identities(TILT if tilt is None else tilt))
    if not symbolic.holds:
        return symbolic
    worst, across_fields, renders, distinct = _render_rate(**sampling)
    configurations = len(BUMPS) * len(PIPELINES) * len(HEIGHT_FIELDS)
    if across_fields:
        return Verdict("refuted", f"at beta = 0, {across_fields} channel values depend on the height field")
    if distinct < configurations:
        return Verdict("refuted", f"at beta = {RATE_BETAS[0]:g} only {distinct} of the {configurations} "
                       "renders (fields x bump modes x pipelines) differ: not every configuration was rendered")
    slope = float(np.polyfit(np.log(RATE_BETAS), np.log(worst[:-1]), 1)[0])
    # Linear rate: the tiny step's difference is at most the fitted line's value there (and
    # a few ulps of rounding in the normalisation).
    line = worst[-2] * TINY_BETA / RATE_BETAS[-1]
    if not (abs(slope - order) <= 0.1 and worst[-1] <= 4 * line + 4 * 2.0**-52):
        return Verdict("refuted", f"renders approach the beta = 0 render with fitted order {slope:.2f} "
                       f"(claimed {order:g}); at beta = {TINY_BETA:g} the difference is {worst[-1]:.1e}, "
                       f"the linear rate allows {4 * line:.1e}")
    return Verdict(symbolic.status, f"renderer.formulas.PERTURBED_NORMAL (both modes) at N(theta, phi) in the "
                   f"renderer's frame: {symbolic.evidence}; {configurations} renders per beta (3 fields x 2 modes "
                   f"x 2 pipelines, 96x80), {distinct} distinct at beta = {RATE_BETAS[0]:g}: max |I(beta) - I(0)| falls with fitted order {slope:.2f} over beta = "
                   f"1e-2 ... 1e-8 ({worst[0]:.1e} to {worst[-2]:.1e}), {worst[-1]:.1e} at beta = {TINY_BETA:g} "
                   f"(the linear rate allows {4 * line:.1e}); the beta = 0 renders of the three fields are equal "
                   "bit for bit", rendered=renders)


BETA_ZERO_REGRESSION = Theorem(
    id="beta-zero-regression", title="The beta -> 0 limit",
    statement=r"Both of the renderer's perturbed normals (`renderer.formulas.PERTURBED_NORMAL`, bump modes "
              r"chart and surface), on sphere A in the renderer's frame, satisfy $N'(0) = N$ and "
              rf"$N'(\beta) = N + \beta T + O(\beta^2)$ with $T_{{\mathrm{{chart}}}} = {tilt_latex(TILT_SHOWN['chart'])}$ "
              rf"and $T_{{\mathrm{{surface}}}} = {tilt_latex(TILT_SHOWN['surface'])}$: "
              r"the regression is a limit of rate $\beta$.  The rendered images approach the $\beta = 0$ "
              r"image at that rate for both pipelines and every height field, and at $\beta = 0$ the height "
              r"field does not reach the image.",
    steps=tuple((rf"\partial_\beta N'_{{\mathrm{{{mode}}}}}|_{{\beta=0}}", r"T_{\mathrm{" + mode + "}}",
                 tilt_latex(t)) for mode, t in TILT_SHOWN.items()),
    check=_check_limit,
    wrong_variants=(("the chart tilt with h_u and h_v swapped",
                     lambda: _check_limit({**TILT, "chart": tilt_vector(F.h_v * E_THETA + F.h_u * E_PHI)})),
                    ("the surface tilt without the metric factor 2 pi R sin phi",
                     lambda: _check_limit({**TILT, "surface": tilt_vector(-F.h_u * E_THETA
                                                                           - F.h_v / (sp.pi * F.R) * E_PHI)})),
                    ("a quadratic rate claimed", lambda: _check_limit(order=2.0)),
                    ("the beta = 0 reference rendered at beta = 1e-12, where the field reaches it",
                     lambda: _check_limit(reference_beta=TINY_BETA)),
                    ("the last render at beta = 1e-10 taken for 1e-12 (a floor above the linear rate)",
                     lambda: _check_limit(tiny_beta=1e-10)),
                    ("one height field rendered three times", lambda: _check_limit(fields=("sine",) * 3))),
    pages=("s3", "s5"),
    seed_says="Cell 6 expects beta = 0 agreement at ~1e-16.",
)

THEOREMS = (NORMAL_BETA_DERIVATIVE, BETA_ZERO_REGRESSION)
