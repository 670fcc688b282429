"""The perturbed normal: its beta-derivative and its beta -> 0 limit (seed §3, Cells 5, 6).

The theorems are about the renderer's perturbed normals,
`renderer.formulas.PERTURBED_NORMAL` ("chart": the seed's formula; "surface":
the normal of the displaced sphere).  The independent side is the seed's
formula N' = M / |M| with M = N + beta g, g = h_u e_theta + h_v e_phi, written
here.
"""

from functools import partial

import numpy as np
import sympy as sp

from renderer import formulas as F
from renderer.scene import BUMPS

from . import frame
from .core import Dot, Step, Theorem, Verdict, calc, catalogue, spelled, written

Nv = sp.Matrix([F.N_x, F.N_y, F.N_z])
et, ep = sp.Matrix(F.e_theta), sp.Matrix(F.e_phi)
#: The renderer's chart-mode normal, a function of N, the frame, (h_u, h_v) and beta.
N_PRIME = sp.Matrix(F.PERTURBED_NORMAL["chart"])
#: The seed's formula (§3), written here as the statement prints it (matrix
#: symbols N, e_theta, e_phi, g): the bump direction g and M = N + beta g.  The
#: check substitutes the renderer's symbols into these same objects, so the
#: statement cannot say one thing while another is checked.
N_S, G_S = sp.MatrixSymbol("N", 3, 1), sp.MatrixSymbol("g", 3, 1)
E_THETA_S, E_PHI_S = frame.ET_S, frame.EP_S
G_CLAIMED = F.h_u * E_THETA_S + F.h_v * E_PHI_S
M_CLAIMED = sp.MatAdd(N_S, F.beta * G_S, evaluate=False)
DOMAIN = {**{s: (-2.0, 2.0) for s in list(Nv) + list(et) + list(ep) + [F.h_u, F.h_v]},
          F.beta: (0.01, 3.0)}

#: The names the proof uses: N', M and ||M||, and the claimed derivative as the statement prints it.
NP_S, M_S = sp.MatrixSymbol("N'", 3, 1), sp.MatrixSymbol("M", 3, 1)
NORM_M_S = sp.Symbol(r"\lVert M\rVert", positive=True)
CLAIMED_DERIVATIVE = (sp.Identity(3) - NP_S * NP_S.T) * G_S / NORM_M_S


def _derivative(claimed=CLAIMED_DERIVATIVE, m=M_CLAIMED):
    """Theorem normal-beta-derivative claiming ``claimed`` for M = ``m`` (wrong variants)."""
    slope = sp.Derivative(NP_S, F.beta)
    return Theorem(
        id="normal-beta-derivative", title=TITLES["normal-beta-derivative"],
        statement=r"The draft's shading normal (the renderer's chart mode, "
                  r"whose $M$ is linear in $\beta$) is $⟦normal⟧$ with $⟦M⟧$, $⟦g⟧$, and $⟦derivative⟧$, for any "
                  r"$N$, frame and gradient: the derivative of the unit vector $N'$ is $g$ projected onto the plane "
                  r"perpendicular to $N'$, divided by $\lVert M\rVert$.  (In the surface mode $M$ is not linear in "
                  r"$\beta$, and this closed form does not apply.)",
        steps=(
            Step("The renderer's $N'$ is $M$ normalised", NP_S, M_S / NORM_M_S),
            Step(r"$M$ is linear in $\beta$, and $N$, the frame, $h_u$ and $h_v$ do not depend on $\beta$",
                 sp.Derivative(M_S, F.beta), G_S),
            Step(r"So $\lVert M\rVert = \sqrt{M \cdot M}$ has the derivative", sp.Derivative(NORM_M_S, F.beta),
                 Dot(M_S, G_S) / NORM_M_S),
            *calc(slope, (r"The quotient rule on $M/\lVert M\rVert$, with steps 2 and 3",
                          G_S / NORM_M_S - M_S * Dot(M_S, G_S) / NORM_M_S**3),
                  (r"$M/\lVert M\rVert = N'$ (step 1), so $M (M \cdot g)/\lVert M\rVert^3 = N' N'^{T} g/\lVert M\rVert$",
                   claimed)),
        ),
        claims={"normal": (NP_S, M_S / NORM_M_S), "derivative": (slope, claimed)},
        where={NP_S: N_PRIME, M_S: m, G_S: G_CLAIMED, N_S: Nv, E_THETA_S: et, E_PHI_S: ep,
               NORM_M_S: sp.sqrt(Dot(M_S, M_S))},
        names=frame.VECTOR_NAMES, domain=DOMAIN,
        wrong_variants=(("sign of the projection flipped",
                         lambda: _derivative((sp.Identity(3) + NP_S * NP_S.T) * G_S / NORM_M_S).check()),
                        ("the 1/|M| factor dropped", lambda: _derivative((sp.Identity(3) - NP_S * NP_S.T) * G_S).check())),
    )

#: The renderer's normals, for "surface" with sin phi above the pole cut-off (its pole branch
#: read as the regular one, `frame.off_pole`).
NP_MODE = {mode: sp.MatrixSymbol(f"N'_{mode}", 3, 1) for mode in F.PERTURBED_NORMAL}
ON_FRAME = {NP_MODE[mode]: frame.off_pole(sp.ImmutableMatrix(n)) for mode, n in F.PERTURBED_NORMAL.items()}
#: The frame's vectors and the normal as the statement prints them.
ET_S, EP_S, N_SPHERE = frame.ET_S, frame.EP_S, frame.N_S
#: The first-order tilt dN'/dbeta at beta = 0, written by hand in e_theta, e_phi: the chart
#: mode tilts by g = h_u e_theta + h_v e_phi (seed §3); the displaced sphere by the
#: gradient of beta h over the sphere's metric, |P_u| = 2 pi R sin phi, |P_v| = pi R.
TILT_SHOWN = {"chart": F.h_u * ET_S + F.h_v * EP_S,
              "surface": -(F.h_u / (2 * sp.pi * F.R * sp.sin(frame.phi))) * ET_S - (F.h_v / (sp.pi * F.R)) * EP_S}
SPHERE_DOMAIN = {frame.phi: (0.05, 3.09), F.R: (0.5, 2.0), F.h: (-1.0, 1.0), F.h_u: (-2.0, 2.0), F.h_v: (-2.0, 2.0)}
#: The renders: beta -> 0 over these steps, on a 96x80 frame.
RATE_BETAS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
TINY_BETA = 1e-12
#: The seed's two pipelines: the exact gradient and central differences.
PIPELINES = ("exact", "central")


def _render_rate(reference_beta=0.0, tiny_beta=TINY_BETA, fields=None):
    """Renders of ``fields`` (the registered fields by default) x 2 bump modes x 2 pipelines (96x80): max |I(beta) - I(0)| over
    them per beta in RATE_BETAS and at ``tiny_beta`` (float64 array, length 8); the channel
    values of the beta = 0 renders (at ``reference_beta``, 0 but in a wrong variant) that differ
    between fields (the height field must not reach the shading at beta = 0); how many renders
    were compared; and how many of the configurations' beta = 1e-2 renders are distinct (each
    field, mode and pipeline must reach the image once beta > 0)."""
    from renderer import Scene, render
    fields = tuple(F.FIELDS) if fields is None else fields
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
    return worst, across_fields, renders, len(bumped), tuple(dict.fromkeys(fields))


def _rate_evidence(order=1.0, **sampling):
    """The rendered limit: the images approach the beta = 0 image at rate beta^``order``, every
    configuration reaches the image, and at beta = 0 the field does not (``sampling`` goes to
    `_render_rate`, for the wrong variants)."""
    worst, across_fields, renders, distinct, covered = _render_rate(**sampling)
    configurations = len(BUMPS) * len(PIPELINES) * len(F.FIELDS)
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
    return Verdict("proved", f"{configurations} renders per beta ({len(F.FIELDS)} fields x 2 modes x 2 pipelines, 96x80), "
                   f"{distinct} distinct at beta = {RATE_BETAS[0]:g}: max |I(beta) - I(0)| falls with fitted order "
                   f"{slope:.2f} over beta = 1e-2 ... 1e-8 ({worst[0]:.1e} to {worst[-2]:.1e}), {worst[-1]:.1e} at "
                   f"beta = {TINY_BETA:g} (the linear rate allows {4 * line:.1e}); the beta = 0 renders of the "
                   f"{spelled(len(F.FIELDS))} fields are equal bit for bit", rendered=renders, covers=covered)


#: Taylor's theorem about beta = 0, as the statement shows it for either normal N'(beta) (its derivative there
#: a name: `TAYLOR_NAMES`).
_NP, _N, _SLOPE = sp.Function("N'"), sp.Symbol("N"), sp.Symbol("slope")
TAYLOR = sp.Eq(_NP(F.beta), written(sp.Add(_N, sp.Mul(F.beta, _SLOPE, evaluate=False), sp.Order(F.beta**2), evaluate=False)),
               evaluate=False)
TAYLOR_NAMES = {_SLOPE: r"\left.\partial N'/\partial\beta\right|_{\beta=0}"}


def _limit(tilt=None, **evidence):
    """Theorem beta-zero-regression claiming the tilts ``tilt`` ({mode: T}, default `TILT_SHOWN`), with the
    evidence's options (wrong variants)."""
    tilt = {**TILT_SHOWN, **(tilt or {})}
    at_zero = sp.Tuple(*(sp.Subs(NP_MODE[mode], F.beta, 0) for mode in NP_MODE))
    slope = {mode: sp.Subs(sp.Derivative(NP_MODE[mode], F.beta), F.beta, 0) for mode in NP_MODE}
    return Theorem(
        id="beta-zero-regression", title=TITLES["beta-zero-regression"],
        statement=r"Both of the renderer's perturbed normals (bump modes "
                  r"chart and surface), on sphere A for $⟦phi⟧$ in the renderer's frame, orthonormal by ⟪frame-orthonormal⟫ "
                  r"and left-handed by ⟪frame-orientation⟫, satisfy $⟦limit⟧$ and "
                  r"$⟦taylor⟧$ with $⟦chart⟧$ and "
                  r"$⟦surface⟧$: at $⟦zero⟧$ neither normal depends on the height field, and each returns "
                  r"to $N$ at rate $\beta$.  (This is about the normals; that the rendered images approach the "
                  r"$⟦zero⟧$ image at that rate is measured, in the ledger's evidence, not proved.)",
        steps=(
            Step(r"Both normals are built from $N$, $e_\theta$, $e_\varphi$ by dot products, the same in every "
                 r"orthonormal frame, so take $e_\theta = x$, $e_\varphi = y$, $N = -z$; at $\beta = 0$ both bump "
                 r"modes leave $M = N$, a unit vector", at_zero, sp.Tuple(N_SPHERE, N_SPHERE)),
            Step(r"By ⟪normal-beta-derivative⟫ at $\beta = 0$, where $N' = N$ and $\lVert M\rVert = 1$, the "
                 r"chart mode tilts by the part of $g$ orthogonal to $N$, which is $g$ itself", slope["chart"],
                 tilt["chart"]),
            Step(r"The displaced sphere's $M = N - \beta\bigl(h_u e_\theta / {(2\pi\sin\varphi)} "
                 r"+ h_v e_\varphi / \pi\bigr) / {(R + \beta h)}$ tilts by its tangential part's $\beta$-derivative at 0 "
                 r"($M$ is not linear in $\beta$, but $\lVert M\rVert = 1$ there): minus the gradient over the arc lengths "
                 r"$2\pi R\sin\varphi$ and $\pi R$",
                 slope["surface"], tilt["surface"]),
        ),
        claims={"limit": (at_zero, sp.Tuple(N_SPHERE, N_SPHERE)), "chart": (slope["chart"], tilt["chart"]),
                "surface": (slope["surface"], tilt["surface"])},
        shown={"zero": sp.Eq(F.beta, 0), "taylor": TAYLOR, "phi": frame.PHI_OFF_POLES},
        where={**ON_FRAME, **frame.STANDARD_FRAME, F.sin_phi: sp.sin(frame.phi)},
        names={**frame.VECTOR_NAMES, **TAYLOR_NAMES, NP_MODE["chart"]: r"N'_{\mathrm{chart}}",
               NP_MODE["surface"]: r"N'_{\mathrm{surface}}"},
        domain=SPHERE_DOMAIN, evidence=partial(_rate_evidence, **evidence),
        wrong_variants=(("the chart tilt with h_u and h_v swapped",
                         lambda: _limit({"chart": F.h_v * ET_S + F.h_u * EP_S}).check()),
                        ("the surface tilt without the metric factor 2 pi R sin phi",
                         lambda: _limit({"surface": -F.h_u * ET_S - F.h_v / (sp.pi * F.R) * EP_S}).check()),
                        ("the chart tilt's e_phi term (its last) with coefficient 2 h_v",
                         lambda: _limit({"chart": F.h_u * ET_S + 2 * F.h_v * EP_S}).check()),
                        ("the surface tilt's e_phi term (its last) over 2 pi R, not pi R",
                         lambda: _limit({"surface": -(F.h_u / (2 * sp.pi * F.R * sp.sin(frame.phi))) * ET_S
                                         - (F.h_v / (2 * sp.pi * F.R)) * EP_S}).check()),
                        ("a quadratic rate claimed", lambda: _limit(order=2.0).check()),
                        ("the beta = 0 reference rendered at beta = 1e-12, where the field reaches it",
                         lambda: _limit(reference_beta=TINY_BETA).check()),
                        ("the last render at beta = 1e-10 taken for 1e-12 (a floor above the linear rate)",
                         lambda: _limit(tiny_beta=1e-10).check()),
                        ("one height field rendered in place of every field",
                         lambda: _limit(fields=(next(iter(F.FIELDS)),) * len(F.FIELDS)).check())),
    )


#: This module's theorems: id -> title.
TITLES = {"normal-beta-derivative": "The β-derivative of the perturbed normal",
          "beta-zero-regression": "The β → 0 limit"}

titles, build = catalogue(TITLES, {"normal-beta-derivative": _derivative, "beta-zero-regression": _limit})
