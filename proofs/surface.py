"""The displaced surface's normal, on any parametric surface (pbrt-v4, "Bump Mapping"; Blinn 1978).

A surface p(u, v) with unit normal n is displaced along it by beta h(u, v): p' = p + beta h n.
By the product rule p'_u = p_u + beta h_u n + beta h n_u (likewise v), and expanding the cross
product (n x n = 0), exactly

    p'_u x p'_v = (p_u + beta h n_u) x (p_v + beta h n_v)
                  + beta h_u n x (p_v + beta h n_v) + beta h_v (p_u + beta h n_u) x n.

Every vector in the first product is tangent (n_u and n_v are, since |n| = 1), so that product
lies along n; the tilt comes from the other two terms.  The theorem measures the normal by its
slopes t: its components along e_u = p_u/|p_u| and e_v = p_v/|p_v| over its component along n,
which fix the unit normal whatever its length or orientation.  For an orthogonal chart, to first
order in beta and for either handedness,

    t = -beta (h_u / |p_u|, h_v / |p_v|) + O(beta^2):

the slope of h divided by the chart's arc lengths, tilting away from rising h.  Where the chart
follows lines of curvature (n_u = kappa_u p_u, n_v = kappa_v p_v: a sphere, a torus, a
plane) the slopes are exactly -beta (h_u / ((1 + beta h kappa_u) |p_u|), h_v / ((1 + beta h
kappa_v) |p_v|)).  For sphere A (kappa = 1/R, |p_u| = 2 pi R sin phi, |p_v| = pi R) these are the
coefficients of the renderer's bump="surface" (`renderer.formulas.BUMP`), the theorem
bump-vs-displacement states for the sphere.

Each step is checked in coordinates a person can check by hand: cross products and slopes are
unchanged by a rotation, so at a point n is taken as (0, 0, 1) and e_u as (1, 0, 0), with e_v =
(0, s, 0) and s = +1 (a right-handed chart) or -1 (a left-handed one, the renderer's); the
product rule and the expansion are checked for arbitrary functions and vectors.
"""

import sympy as sp

from renderer import formulas as F

from .core import Cross, Dot, Step, Theorem, catalogue
from .displacement import KERNEL_COEFFS
from .frame import CHART_RATES, PHI_OFF_POLES

u, v, beta, h, h_u, h_v = F.u, F.v, F.beta, F.h, F.h_u, F.h_v

#: The vectors the proof names.
P_S, N_S = sp.MatrixSymbol("p", 3, 1), sp.MatrixSymbol("n", 3, 1)
PU_S, PV_S = sp.MatrixSymbol("p_u", 3, 1), sp.MatrixSymbol("p_v", 3, 1)
NU_S, NV_S = sp.MatrixSymbol("n_u", 3, 1), sp.MatrixSymbol("n_v", 3, 1)
DU_S, DV_S = sp.MatrixSymbol("p'_u", 3, 1), sp.MatrixSymbol("p'_v", 3, 1)
EU_S, EV_S = sp.MatrixSymbol("e_u", 3, 1), sp.MatrixSymbol("e_v", 3, 1)
C_S = sp.MatrixSymbol("c", 3, 1)
XI_U, XI_V = sp.symbols("xi_u xi_v")
#: |p_u|, |p_v| and the normal curvatures along the chart's directions.
L_U, L_V = sp.symbols("L_u L_v", positive=True)
K_U, K_V = sp.symbols("kappa_u kappa_v", real=True)
NAMES = {DU_S: "p'_u", DV_S: "p'_v", L_U: r"\lvert p_u\rvert", L_V: r"\lvert p_v\rvert",
         K_U: r"\kappa_u", K_V: r"\kappa_v"}


def _sum(*terms):
    return sp.MatAdd(*terms, evaluate=False)


#: The displaced surface p + beta h n, as the statement writes it.
DISPLACED = _sum(P_S, sp.MatMul(beta * h, N_S, evaluate=False))
#: p_u + beta h n_u and p_v + beta h n_v, as the statement writes them.
A = _sum(PU_S, sp.MatMul(beta * h, NU_S, evaluate=False))
B = _sum(PV_S, sp.MatMul(beta * h, NV_S, evaluate=False))
#: The exact decomposition of p'_u x p'_v the statement claims.
CROSS = _sum(Cross(A, B), sp.MatMul(beta * h_u, Cross(N_S, B), evaluate=False),
             sp.MatMul(beta * h_v, Cross(A, N_S), evaluate=False))
#: The slopes claimed: to first order on an orthogonal chart; exactly on a principal one.
FIRST = (-beta * h_u / L_U + sp.O(beta**2), -beta * h_v / L_V + sp.O(beta**2))
PRINCIPAL = sp.ImmutableMatrix([-beta * h_u / ((1 + beta * h * K_U) * L_U),
                                -beta * h_v / ((1 + beta * h * K_V) * L_V)])
#: Sphere A: kappa = 1/R, |p_u| = R sin(phi) dtheta/du = 2 pi R sin(phi) and |p_v| = R dphi/dv = pi R
#: (the chart's rates, theorem `chart`).
SPHERE = {K_U: 1 / F.R, K_V: 1 / F.R, L_U: F.R * F.sin_phi / CHART_RATES[0], L_V: F.R / CHART_RATES[1]}
#: The renderer's bump="surface" coefficients of e_theta and e_phi, off its pole floor.
RENDERER = sp.ImmutableMatrix(KERNEL_COEFFS)


def _vector(name):
    return sp.ImmutableMatrix(sp.symbols(f"{name}1:4", real=True))


# Any surface: p, n and h arbitrary functions of (u, v).
_XF = [sp.Function(f"X{i}") for i in range(3)]
_NF = [sp.Function(f"n{i}") for i in range(3)]
_HF = sp.Function("H")
_X = sp.ImmutableMatrix([f(u, v) for f in _XF])
_Nf = sp.ImmutableMatrix([f(u, v) for f in _NF])
_H = _HF(u, v)
#: Instances of the arbitrary functions, for the numerical check only.
INSTANCES = {f: sp.Lambda((u, v), sp.sin((k + 1) * u + (2 - k) * v)) for k, f in enumerate(_XF + _NF + [_HF])}
ANY_SURFACE = {P_S: _X, N_S: _Nf, PU_S: _X.diff(u), PV_S: _X.diff(v), NU_S: _Nf.diff(u), NV_S: _Nf.diff(v),
               DU_S: (_X + beta * _H * _Nf).diff(u), DV_S: (_X + beta * _H * _Nf).diff(v),
               h: _H, h_u: _H.diff(u), h_v: _H.diff(v)}
#: Any five vectors: the expansion of the cross product is algebra.
ANY_VECTORS = {N_S: _vector("n"), PU_S: _vector("a"), PV_S: _vector("b"), NU_S: _vector("c"), NV_S: _vector("d")}

_c1, _c2, _d1, _d2 = sp.symbols("c1 c2 d1 d2", real=True)


def _chart(s, principal):
    """A point's coordinates: n = z, e_u = x, e_v = s y (s = +1 right-handed, -1 left-handed), p_u = |p_u|
    e_u, p_v = |p_v| e_v, and n_u, n_v tangent: arbitrary, or kappa p_u and kappa p_v (``principal``)."""
    e_u, e_v = sp.ImmutableMatrix([1, 0, 0]), sp.ImmutableMatrix([0, s, 0])
    p_u, p_v = L_U * e_u, L_V * e_v
    n_u, n_v = (K_U * p_u, K_V * p_v) if principal else (sp.ImmutableMatrix([_c1, _c2, 0]),
                                                         sp.ImmutableMatrix([_d1, _d2, 0]))
    return {N_S: sp.ImmutableMatrix([0, 0, 1]), EU_S: e_u, EV_S: e_v, PU_S: p_u, PV_S: p_v, NU_S: n_u, NV_S: n_v}


HANDED = (("a right-handed chart", +1), ("a left-handed chart", -1))
ORTHOGONAL = tuple((label, _chart(s, False)) for label, s in HANDED)
PRINCIPAL_CHARTS = tuple((label, _chart(s, True)) for label, s in HANDED)
DOMAIN = {beta: (0.0, 0.5), h: (-1.0, 1.0), h_u: (-30.0, 30.0), h_v: (-30.0, 30.0), L_U: (0.2, 5.0),
          L_V: (0.2, 5.0), K_U: (-1.0, 1.0), K_V: (-1.0, 1.0), _c1: (-2.0, 2.0), _c2: (-2.0, 2.0),
          _d1: (-2.0, 2.0), _d2: (-2.0, 2.0), F.R: (0.5, 2.0), F.sin_phi: (0.01, 1.0), u: (0.0, 1.0), v: (0.0, 1.0),
          **{x: (-2.0, 2.0) for vec in ANY_VECTORS.values() for x in vec}}


def _theorem(cross=CROSS, first=FIRST, principal=PRINCIPAL, sphere=SPHERE, renderer=RENDERER):
    """Theorem displaced-normal claiming the decomposition ``cross``, the first-order slopes ``first``, the
    principal chart's slopes ``principal`` and, with the sphere's ``sphere`` values, the renderer's
    coefficients ``renderer`` (wrong variants)."""
    product = Cross(DU_S, DV_S)
    derivatives = sp.Tuple(_sum(PU_S, sp.MatMul(beta * h_u, N_S, evaluate=False),
                                sp.MatMul(beta * h, NU_S, evaluate=False)),
                           _sum(PV_S, sp.MatMul(beta * h_v, N_S, evaluate=False),
                                sp.MatMul(beta * h, NV_S, evaluate=False)))
    slopes = sp.ImmutableMatrix([XI_U, XI_V])
    at_sphere = principal.subs(sphere)
    return Theorem(
        id="displaced-normal", title=TITLES["displaced-normal"],
        statement=r"Let $p(u, v)$ be a surface with unit normal $n$, displaced along it by $\beta$ times a "
                  r"height $h(u, v)$: $⟦displaced⟧$. Then exactly $$⟦cross⟧$$ and the first product "
                  r"lies along $n$. Measure a normal by its slopes $⟦xi⟧$: its components along "
                  r"$⟦e_u⟧$ and $⟦e_v⟧$ over its component along $n$. "
                  r"On an orthogonal chart, right- or left-handed, the displaced normal's slopes are, to first "
                  r"order in $\beta$, $⟦first_u⟧$ and $⟦first_v⟧$: the slope of $h$ divided by the chart's "
                  r"arc lengths, tilting away from rising $h$. Where the chart follows lines of curvature, "
                  r"$⟦n_u⟧$ and $⟦n_v⟧$ (a sphere, a torus, a plane), exactly "
                  r"$$⟦principal⟧$$ On sphere A, for $⟦phi⟧$ ($⟦kappa_u⟧$, $⟦kappa_v⟧$, $⟦L_u⟧$, "
                  r"$⟦L_v⟧$) these are the renderer's surface bump, $\xi_u$ above and $\xi_v$ below: $$⟦sphere⟧$$",
        steps=(
            Step(r"Differentiate $p' = p + \beta h\, n$ by the product rule", sp.Tuple(DU_S, DV_S), derivatives,
                 cases=(("any surface", ANY_SURFACE),)),
            Step(r"Substitute step 1 and expand the cross product: $n \times n = 0$", product, cross, using=(1,),
                 cases=(("any vectors", ANY_VECTORS),)),
            Step(r"Write $c$ for the right side. In coordinates with $n = (0, 0, 1)$, $e_u = (1, 0, 0)$ and "
                 r"$e_v = (0, \pm 1, 0)$ (a rotation changes no cross product or slope), $p_u$, $p_v$, $n_u$ and "
                 r"$n_v$ are tangent ($n_u \perp n$ since $\lvert n\rvert = 1$), so $c$'s first product is "
                 r"along $n$ and, with $p_u = \lvert p_u\rvert e_u$ and $p_v = \lvert p_v\rvert e_v$, "
                 r"$c\cdot n = \pm\lvert p_u\rvert\lvert p_v\rvert + O(\beta)$; of $c$'s terms only "
                 r"$\beta h_u\, n \times p_v = \mp\beta h_u\lvert p_v\rvert\, e_u$, already $O(\beta)$, lies along $e_u$, so the slope "
                 r"$\xi_u = c\cdot e_u / c\cdot n$ is, to first order",
                 XI_U, first[0], cases=ORTHOGONAL),
            Step(r"Likewise $\xi_v = c\cdot e_v / c\cdot n$", XI_V, first[1], cases=ORTHOGONAL),
            Step(r"With $n_u = \kappa_u p_u$ and $n_v = \kappa_v p_v$ the first product is "
                 r"$(1 + \beta h\kappa_u)(1 + \beta h\kappa_v)\, p_u \times p_v$, the term in $h_u$ carries "
                 r"$1 + \beta h\kappa_v$ and the term in $h_v$ carries $1 + \beta h\kappa_u$, so exactly", slopes, principal,
                 cases=PRINCIPAL_CHARTS),
            Step(r"On sphere A, $n = p/R$ gives $\kappa_u = \kappa_v = 1/R$, and by ⟪chart⟫ a step in $u$ "
                 r"covers $\lvert p_u\rvert = 2\pi R\sin\varphi$, one in $v$ covers $\lvert p_v\rvert = \pi R$; "
                 r"in the renderer's left-handed chart (⟪frame-orientation⟫) step 5 gives its surface bump's "
                 r"coefficients $(\xi_u, \xi_v)$", at_sphere, renderer),
        ),
        claims={"cross": (product, cross), "first_u": (XI_U, first[0]), "first_v": (XI_V, first[1]),
                "principal": (slopes, principal), "sphere": (at_sphere, renderer)},
        shown={"displaced": sp.Eq(sp.MatrixSymbol("p'", 3, 1), DISPLACED, evaluate=False),
               "xi": sp.Eq(sp.Symbol("xi"), sp.Tuple(XI_U, XI_V), evaluate=False),
               **{str(e): sp.Eq(e, sp.MatMul(1 / length, p, evaluate=False), evaluate=False)
                  for e, p, length in ((EU_S, PU_S, L_U), (EV_S, PV_S, L_V))},
               **{str(n): sp.Eq(n, sp.MatMul(k, p, evaluate=False), evaluate=False)
                  for n, k, p in ((NU_S, K_U, PU_S), (NV_S, K_V, PV_S))},
               **{str(k): sp.Eq(k, value, evaluate=False) for k, value in sphere.items()}, "phi": PHI_OFF_POLES},
        where={C_S: cross, XI_U: Dot(C_S, EU_S) / Dot(C_S, N_S), XI_V: Dot(C_S, EV_S) / Dot(C_S, N_S)},
        names=NAMES, domain=DOMAIN, functions=INSTANCES,
        wrong_variants=(
            ("Blinn's drop of the terms in h itself, claimed exact on a principal chart",
             lambda: _theorem(principal=sp.ImmutableMatrix([-beta * h_u / L_U, -beta * h_v / L_V])).check()),
            ("the draft's slopes, +beta (h_u, h_v): no arc lengths and the opposite sign",
             lambda: _theorem(first=(beta * h_u + sp.O(beta**2), beta * h_v + sp.O(beta**2))).check()),
            ("the first-order slope along e_v divided by |p_u|, not |p_v|",
             lambda: _theorem(first=(FIRST[0], -beta * h_v / L_U + sp.O(beta**2))).check()),
            ("the e_u term's cross product reversed: (p_v + beta h n_v) x n",
             lambda: _theorem(cross=_sum(Cross(A, B), sp.MatMul(beta * h_u, Cross(B, N_S), evaluate=False),
                                         sp.MatMul(beta * h_v, Cross(A, N_S), evaluate=False))).check()),
            ("the expansion without its n_u term in the second product",
             lambda: _theorem(cross=_sum(Cross(PU_S, B), sp.MatMul(beta * h_u, Cross(N_S, B), evaluate=False),
                                         sp.MatMul(beta * h_v, Cross(A, N_S), evaluate=False))).check()),
            ("the sphere's curvature 2/R (its mean curvature counted twice)",
             lambda: _theorem(sphere={**SPHERE, K_U: 2 / F.R, K_V: 2 / F.R}).check()),
            ("the renderer's chart bump (the draft's) as the sphere's slopes",
             lambda: _theorem(renderer=sp.ImmutableMatrix(F.BUMP["chart"])).check()),
        ),
    )


#: This module's theorem: id -> title.
TITLES = {"displaced-normal": "The displaced surface's normal"}

titles, build = catalogue(TITLES, {"displaced-normal": _theorem})
