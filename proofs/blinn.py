"""Blinn's perturbed normal, set for sphere A (seed §8; beyond the seed's code).

Blinn (1978, "Simulation of Wrinkled Surfaces", SIGGRAPH) displaces a
parametric surface P(u, v) by a bump function F along its unit normal,
P' = P + F N / |N| with N = P_u x P_v, drops the terms of P'_u x P'_v that
carry F itself (those with F d(N/|N|)/du or /dv), and keeps

    N' = N + (F_u (N x P_v) - F_v (N x P_u)) / |N|.

Here P(u, v) = R N(theta(u), phi(v)) in the renderer's chart (theorem `chart`:
u = (theta + pi) / 2 pi, v = phi / pi).  With that chart P_u x P_v points
*inward* (the frame is left-handed, theorem `frame-orientation`), so the
outward displacement P = (R + beta h) N of the renderer is F = -beta h; the
sign is computed, not assumed.

Each normal is compared through its slopes: its components along e_theta and
e_phi (`formulas.TANGENT_FRAME`, regular branch) divided by its component
along N.  They fix the unit normal and do not depend on its length or
orientation.  Blinn's slopes are -beta (h_u / (2 pi R sin phi), h_v / (pi R)),
exactly linear in beta; the displaced sphere's (`PERTURBED_NORMAL["surface"]`)
are the same with R replaced by R + beta h, so the two agree to first order and
differ at the second.  The draft's (`PERTURBED_NORMAL["chart"]`) are
+beta (h_u, h_v): to first order Blinn's times -2 pi R sin phi and -pi R.

The proof also computes the displaced sphere's own normal P'_u x P'_v, for
P' = (R + beta h) N and a general bump h(u, v), and finds the renderer's
surface slopes at every beta.
"""

from functools import lru_cache

import sympy as sp

from renderer import formulas as F

from .core import Cross, Dot, Step, Theorem, catalogue
from .frame import (CHART_RATES, EP_S, ET_S, N, N_S, ON_SPHERE, PHI_OF_V, PHI_OFF_POLES, STANDARD_FRAME, THETA_OF_U, U_OF_THETA,
                    V_OF_PHI, VECTOR_NAMES, e_phi, e_theta, off_pole, phi, theta)

_TO_ANGLES = {F.u: U_OF_THETA, F.v: V_OF_PHI}
#: Sphere A as a parametric surface P(u, v) of the renderer's chart.
P_UV = F.R * N.subs({theta: THETA_OF_U, phi: PHI_OF_V}, simultaneous=True)
#: The displaced sphere P' = (R + beta h(u, v)) N(u, v), h a general bump, and its normal P'_u x P'_v in
#: the renderer's h, h_u, h_v at N(theta, phi) (built, not simplified: the check simplifies).
_H = sp.Function("H")
_P_DISPLACED = (F.R + F.beta * _H(F.u, F.v)) * P_UV / F.R
_SYMBOLS = {sp.Derivative(_H(F.u, F.v), F.u): F.h_u, sp.Derivative(_H(F.u, F.v), F.v): F.h_v, _H(F.u, F.v): F.h}


@lru_cache(maxsize=None)
def exact_normal():
    """The displaced sphere's normal P'_u x P'_v (a 3 x 1 sympy ImmutableMatrix), as above."""
    return sp.ImmutableMatrix(_P_DISPLACED.diff(F.u).cross(_P_DISPLACED.diff(F.v)).subs(_SYMBOLS)
                              .subs(_TO_ANGLES, simultaneous=True))

#: The names the proof uses: N, e_theta, e_phi at N(theta, phi); P_u, P_v; Blinn's N_B = P_u x P_v, its
#: length and his N'_B; the bump's F_u, F_v; and the slopes xi (components along e_theta, e_phi over the
#: one along N) of Blinn's normal, of the displaced sphere's and of the renderer's two bump modes.
PU_S, PV_S = sp.MatrixSymbol("P_u", 3, 1), sp.MatrixSymbol("P_v", 3, 1)
NB_S, NBP_S = sp.MatrixSymbol("N_B", 3, 1), sp.MatrixSymbol("N'_B", 3, 1)
NORM_NB, F_U, F_V = sp.symbols("|N_B| F_u F_v")
XI = {k: sp.MatrixSymbol(f"xi_{k}", 2, 1) for k in ("blinn", "displaced", "surface", "chart")}
NAMES = {**VECTOR_NAMES, NB_S: "N_B", NBP_S: "N'_B", NORM_NB: r"\lvert N_B\rvert",
         XI["blinn"]: r"\xi_{\mathrm{Blinn}}", XI["displaced"]: r"\xi_{P'}", XI["surface"]: r"\xi_{\mathrm{surface}}",
         XI["chart"]: r"\xi_{\mathrm{chart}}"}


def _slopes(n):
    """The slopes of a normal ``n`` (a vector expression): (n . e_theta, n . e_phi) / (n . N)."""
    return sp.ImmutableMatrix([Dot(n, ET_S) / Dot(n, N_S), Dot(n, EP_S) / Dot(n, N_S)])


def blinn_normal(f_u=F_U, f_v=F_V, sign_v=-1):
    """Blinn's N' = N_B + (F_u (N_B x P_v) + sign_v F_v (N_B x P_u)) / |N_B| (his formula: sign_v = -1)."""
    return NB_S + (f_u * Cross(NB_S, PV_S) + sign_v * f_v * Cross(NB_S, PU_S)) / NORM_NB


#: The renderer's normals on the sphere: its symbols at N(theta, phi) in its frame's regular branch, and
#: for bump="surface" its pole branch read as the regular one (`frame.off_pole`: off the cut-off).
_RENDERER_AT = {**ON_SPHERE, **dict(zip(F.e_theta, e_theta)), **dict(zip(F.e_phi, e_phi))}
RENDERER = {mode: off_pole(sp.ImmutableMatrix(F.PERTURBED_NORMAL[mode])) for mode in ("surface", "chart")}

#: The slopes the theorem states, written by hand: Blinn's, exactly linear in beta; the displaced sphere's
#: (and the renderer's bump="surface"), R + beta h in place of R; the draft's (bump="chart"), +beta (h_u, h_v).
R, beta, h, h_u, h_v, s = F.R, F.beta, F.h, F.h_u, F.h_v, sp.sin(phi)
BLINN = sp.Matrix([-beta * h_u / (2 * sp.pi * R * s), -beta * h_v / (sp.pi * R)])
SURFACE = sp.Matrix([-beta * h_u / (2 * sp.pi * (R + beta * h) * s), -beta * h_v / (sp.pi * (R + beta * h))])
CHART = sp.Matrix([beta * h_u, beta * h_v])
#: The draft's slopes over Blinn's, claimed: -R sin(phi) / (du/dtheta) and -R / (dv/dphi), with the
#: chart's rates (theorem `chart`), i.e. -|P_u| and -|P_v|.
FACTORS = sp.Matrix([-F.R * sp.sin(phi) / CHART_RATES[0], -F.R / CHART_RATES[1]])

DOMAIN = {theta: (-3.1, 3.1), phi: (0.01, 3.13), F.R: (0.5, 2.0), F.beta: (0.0, 2.0),
          F.h: (-1.0, 1.0), F.h_u: (-30.0, 30.0), F.h_v: (-30.0, 30.0)}


def _theorem(normal=None, factors=FACTORS, blinn=BLINN, f=(-beta * h_u, -beta * h_v)):
    """Theorem blinn-perturbation for Blinn's normal ``normal`` (default his formula) with the bump's
    derivatives ``f`` (F_u, F_v), claiming his slopes ``blinn`` and the draft's factors ``factors``
    (wrong variants)."""
    frame = sp.Tuple(PU_S, PV_S)
    inward = -2 * sp.pi**2 * R**2 * s * N_S
    renderer, scaled = sp.Tuple(XI["surface"], XI["chart"]), sp.Tuple(SURFACE, CHART)
    draft = sp.ImmutableMatrix(sp.diag(*factors)) * XI["blinn"]
    return Theorem(
        id="blinn-perturbation", title=TITLES["blinn-perturbation"],
        statement=(
            r"Set Blinn's $$⟦N'_B⟧$$ with $⟦N_B⟧$, for sphere A in the renderer's chart, away from the poles ($⟦phi_range⟧$), "
            r"$⟦P⟧$ with $⟦theta⟧$, $⟦phi⟧$. Then $⟦inward⟧$ points inward, so the outward displacement "
            r"$⟦displacement⟧$ is, in Blinn's terms (along $N_B$), $⟦F_u⟧$ and $⟦F_v⟧$. As slopes $\xi$ (components along "
            r"$e_\theta$, $e_\varphi$ over the one along $N$), Blinn's normal has $$⟦blinn⟧$$ the displaced sphere's "
            r"$$⟦displaced⟧$$ and the renderer's bump modes surface and chart (the draft's) "
            r"$$⟦renderer⟧$$ Blinn's slopes equal the displaced sphere's to first order in $\beta$, not beyond "
            r"($R + \beta h$ in place of $R$: he drops the terms in $F$ itself); the draft's are Blinn's times "
            r"$⟦scale⟧$, $⟦factors⟧$: the opposite sign, and the chart's metric factors "
            r"missing."),
        steps=(
            Step(r"By the chain rule with $\theta = \pi(2u - 1)$ and $\varphi = \pi v$ of ⟪chart⟫, "
                 r"$P_u = 2\pi\,\partial P/\partial\theta$ and $P_v = \pi\,\partial P/\partial\varphi$, with "
                 r"$\partial N/\partial\theta = \sin\varphi\, e_\theta$, $\partial N/\partial\varphi = e_\varphi$ "
                 r"by ⟪frame-orthonormal⟫", frame, sp.Tuple(2 * sp.pi * R * s * ET_S, sp.pi * R * EP_S)),
            Step(r"So $N_B = P_u \times P_v = 2\pi^2 R^2 \sin\varphi\,(e_\theta \times e_\varphi)$, and $e_\theta "
                 r"\times e_\varphi = -N$ by ⟪frame-orientation⟫: Blinn's normal points into the sphere, "
                 r"$\lvert N_B\rvert = 2\pi^2 R^2\sin\varphi$, and the outward displacement is $F = -\beta h$", NB_S,
                 inward, using=(1,)),
            Step(r"His $N'_B$, with $F_u = -\beta h_u$, $F_v = -\beta h_v$ and steps 1 and 2, is built from $N$, "
                 r"$e_\theta$, $e_\varphi$ by dot and cross products, the same in every left-handed orthonormal "
                 r"frame; in $e_\theta = x$, $e_\varphi = y$, $N = -z$ its slopes are", XI["blinn"], blinn,
                 using=(1, 2), cases=(("a left-handed orthonormal basis", {**STANDARD_FRAME, F.sin_phi: s}),)),
            Step(r"The displaced sphere $P' = (R + \beta h)N$ has the normal $P'_u \times P'_v$, whose slopes carry "
                 r"$R + \beta h$ where Blinn's carry $R$: equal to first order in $\beta$, different at the second",
                 XI["displaced"], SURFACE),
            Step(r"The renderer's normals are $M/\lVert M\rVert$ with $M = N + \xi_u e_\theta + \xi_v e_\varphi$, whose "
                 r"slopes in an orthonormal frame are $(\xi_u, \xi_v)$: the displaced sphere's for `bump='surface'`, "
                 r"the draft's $+\beta(h_u, h_v)$ for `bump='chart'`", renderer, scaled,
                 cases=(("a left-handed orthonormal basis", {**STANDARD_FRAME, F.sin_phi: s}),)),
            Step(r"Comparing steps 3 and 5, the draft's slopes are Blinn's scaled by $-2\pi R\sin\varphi$ and "
                 r"$-\pi R$", XI["chart"], draft, using=(3, 5)),
        ),
        claims={"inward": (NB_S, inward), "blinn": (XI["blinn"], blinn), "displaced": (XI["displaced"], SURFACE),
                "renderer": (renderer, scaled), "factors": (XI["chart"], draft)},
        shown={"P": sp.Eq(sp.Function("P")(F.u, F.v), R * sp.Function("N")(theta, phi), evaluate=False),
               "theta": sp.Eq(theta, THETA_OF_U, evaluate=False), "phi": sp.Eq(phi, PHI_OF_V, evaluate=False),
               "phi_range": PHI_OFF_POLES,
               "displacement": sp.Eq(sp.MatrixSymbol("P'", 3, 1), sp.MatMul(R + beta * h, N_S, evaluate=False),
                                     evaluate=False),
               "scale": sp.Tuple(*factors)},
        where={N_S: sp.ImmutableMatrix(N), ET_S: sp.ImmutableMatrix(e_theta), EP_S: sp.ImmutableMatrix(e_phi),
               PU_S: sp.ImmutableMatrix(P_UV.diff(F.u).subs(_TO_ANGLES, simultaneous=True)),
               PV_S: sp.ImmutableMatrix(P_UV.diff(F.v).subs(_TO_ANGLES, simultaneous=True)),
               NB_S: Cross(PU_S, PV_S), NORM_NB: 2 * sp.pi**2 * R**2 * s, F_U: f[0], F_V: f[1],
               NBP_S: blinn_normal() if normal is None else normal,
               XI["blinn"]: _slopes(NBP_S), XI["displaced"]: _slopes(exact_normal()),
               XI["surface"]: _slopes(RENDERER["surface"]), XI["chart"]: _slopes(RENDERER["chart"]), **_RENDERER_AT},
        names=NAMES, domain=DOMAIN,
        wrong_variants=(
            ("Blinn's formula with the sign of the F_v term flipped", lambda: _theorem(blinn_normal(sign_v=+1)).check()),
            ("the draft's chart bump equal to Blinn's to first order, without the factors",
             lambda: _theorem(factors=sp.ones(2, 1)).check()),
            ("the draft's factors without the sign: +2 pi R sin(phi), +pi R", lambda: _theorem(factors=-FACTORS).check()),
            ("F = +beta h, ignoring that P_u x P_v points inward", lambda: _theorem(f=(beta * h_u, beta * h_v)).check()),
            ("Blinn's normal equal to the displaced sphere's at every beta", lambda: _theorem(blinn=SURFACE).check()),
            ("Blinn's e_phi slope (the last) at beta^2, not beta",
             lambda: _theorem(blinn=sp.Matrix([BLINN[0], -beta**2 * h_v / (sp.pi * R)])).check()),
            ("Blinn's e_phi slope over 2 pi R, not pi R",
             lambda: _theorem(blinn=sp.Matrix([BLINN[0], -beta * h_v / (2 * sp.pi * R)])).check()),
        ),
    )


#: This module's theorem: id -> title.
TITLES = {"blinn-perturbation": "Blinn's perturbation on the sphere"}

titles, build = catalogue(TITLES, {"blinn-perturbation": _theorem})
