"""The chart and the tangent frame of sphere A, as the renderer holds them (seed §3, Cell 2).

The theorems are about `renderer.formulas`: its chart ``CHART`` (u, v, sin phi
of a unit normal) and the regular branch of its ``TANGENT_FRAME`` (the
branch taken where sin phi > ``POLE_SIN_PHI``).  The independent side is the
unit sphere in spherical coordinates, N(theta, phi), and its derivatives
dN/dtheta and dN/dphi.  The proofs write the renderer's formulas in its own
symbols (N_x, N_y, N_z, sin_phi) and check each step at N(theta, phi).
"""

from functools import partial

import sympy as sp

from renderer import formulas as F

from .core import Cross, Dot, Step, Theorem, Verdict, calc, catalogue

theta, phi = sp.symbols("theta phi", real=True)
#: The unit normal in spherical coordinates (the independent side).
N = sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
#: The renderer's symbols at N(theta, phi).  sin_phi is the kernel's sqrt(N_x^2 + N_y^2)
#: (`formulas.CHART`), which is sin(phi) for 0 < phi < pi (theorem `chart`).
ON_SPHERE = {F.N_x: N[0], F.N_y: N[1], F.N_z: N[2], F.sin_phi: sp.sin(phi)}
#: The theorems' hypotheses, as their statements show them: off the seam theta = +-pi, away from the poles.
THETA_OFF_SEAM = sp.Contains(theta, sp.Interval.open(-sp.pi, sp.pi), evaluate=False)
PHI_OFF_POLES = sp.Contains(phi, sp.Interval.open(0, sp.pi), evaluate=False)
#: Sampling domain: inside the hypotheses, where sin(phi) > 0.
DOMAIN = {theta: (-3.1, 3.1), phi: (0.01, 3.13)}

#: The vectors the proofs name: N, e_theta and e_phi, defined (``where``) as the renderer's.
N_S = sp.MatrixSymbol("N", 3, 1)
ET_S, EP_S = sp.MatrixSymbol("e_theta", 3, 1), sp.MatrixSymbol("e_phi", 3, 1)
VECTOR_NAMES = {ET_S: r"e_\theta", EP_S: r"e_\varphi"}


#: A left-handed orthonormal basis, as the renderer's frame is (theorems frame-orthonormal, frame-orientation):
#: e_theta = x, e_phi = y, N = -z, for the named vectors and the renderer's symbols alike.  A quantity built from
#: the frame by dot and cross products (a normal's slopes, its coefficients in the frame) takes the same value
#: in every orthonormal frame of that handedness, so a step about one may be checked in this one.
STANDARD_FRAME = {N_S: sp.ImmutableMatrix([0, 0, -1]), ET_S: sp.ImmutableMatrix([1, 0, 0]),
                  EP_S: sp.ImmutableMatrix([0, 1, 0]), F.N_x: 0, F.N_y: 0, F.N_z: -1,
                  **dict(zip(F.e_theta, (1, 0, 0))), **dict(zip(F.e_phi, (0, 1, 0)))}


def regular_branch(component):
    """The first (regular) branch of a component of `formulas.TANGENT_FRAME`.  A
    component whose two branches are equal (e_theta's z, 0 in both) is not a
    Piecewise: sympy folded it, and it is its own regular branch."""
    return component.args[0].expr if isinstance(component, sp.Piecewise) else component


def off_pole(expr):
    """``expr`` (a sympy expression or matrix in the symbols of `renderer.formulas`) with each
    pole branch, a Piecewise whose first condition is sin_phi > POLE_SIN_PHI (the frame's, and
    the surface bump's e_theta coefficient), replaced by its regular branch: equal to ``expr``
    wherever sin phi > POLE_SIN_PHI (2^-1022), the only region the symbolic identities compare."""
    return expr.replace(lambda e: isinstance(e, sp.Piecewise) and e.args[0].cond == (F.sin_phi > F.POLE_SIN_PHI),
                        lambda e: e.args[0].expr)


#: The renderer's frame where sin(phi) > POLE_SIN_PHI, in terms of N_x, N_y, N_z, sin_phi.
REGULAR = tuple(regular_branch(c) for c in F.TANGENT_FRAME)
#: ... and at N(theta, phi).
e_theta = sp.Matrix(REGULAR[:3]).subs(ON_SPHERE)
e_phi = sp.Matrix(REGULAR[3:]).subs(ON_SPHERE)


def _where(et=REGULAR[:3], ep=REGULAR[3:]):
    """The named vectors as the renderer's, and its symbols at N(theta, phi)."""
    return {N_S: sp.ImmutableMatrix([F.N_x, F.N_y, F.N_z]), ET_S: sp.ImmutableMatrix(et),
            EP_S: sp.ImmutableMatrix(ep), **ON_SPHERE}


# ------------------------------------------------------------------------------- the chart
U_OF_THETA, V_OF_PHI = (theta + sp.pi) / (2 * sp.pi), phi / sp.pi
#: The chart's inverse, theta(u) and phi(v), solved from u(theta) and v(phi) (linear: without
#: solve's simplification, 0.3 s at every import, then factored).
THETA_OF_U, PHI_OF_V = (sp.factor(sp.solve(sp.Eq(c, F.u if a == theta else F.v), a, simplify=False)[0])
                        for c, a in ((U_OF_THETA, theta), (V_OF_PHI, phi)))
#: The rates du/dtheta and dv/dphi the theorem proves: the factors that turn chart
#: derivatives h_u, h_v into angular ones.
RATES_CLAIMED = (1 / (2 * sp.pi), 1 / sp.pi)
CHART_RATES = RATES_CLAIMED


def _chart_evidence(corrupt=None):
    """The renderer's own chart (GBuffer.uv) at its own N against CHART (proofs/pixels.py); ``corrupt``
    alters the renderer's (u, v) first (a wrong variant)."""
    from .pixels import TOLERANCE, chart_error, worst_of
    worst, count, covered = worst_of(chart_error, [(f, corrupt) for f in F.FIELDS])
    if worst > TOLERANCE["chart"]:
        return Verdict("refuted", f"the renderer's (u, v) differs from CHART(N) by {worst:.1e} at some of "
                       f"{count:,} sphere-A pixels")
    return Verdict("proved", f"the renderer's (u, v) at {count:,} seeded sphere-A pixels (zoomed pole ring and the "
                   f"draft's disc sin phi <= {SEED_POLE_SIN_PHI:g} included) within {worst:.1e} of the chart, "
                   "evaluated by mpmath at its N", residual=worst, rendered=count, bound=TOLERANCE["chart"],
                   covers=covered)


def _chart(u_claim=U_OF_THETA, v_kernel=F.CHART[1], corrupt=None):
    """Theorem chart, claiming u = ``u_claim`` for the kernel's v = ``v_kernel`` (wrong variants)."""
    u_kernel, sin_kernel = F.CHART[0], F.CHART[2]
    rates = sp.Tuple(sp.Derivative(U_OF_THETA, theta), sp.Derivative(V_OF_PHI, phi))
    return Theorem(
        id="chart", title=TITLES["chart"],
        statement=(r"For $⟦theta⟧$ and $⟦phi⟧$ the renderer's chart "
                   r"at the unit normal $N(\theta, \varphi)$, $⟦N_x⟧$, $⟦N_y⟧$, $⟦N_z⟧$, computes "
                   r"$u$ as $⟦u⟧$ and $v$ as $⟦v⟧$, with $⟦sin⟧$; so $⟦rates⟧$, the factors from "
                   r"$h_u$, $h_v$ to $\partial h/\partial\theta$, $\partial h/\partial\varphi$."),
        steps=(
            Step(r"$\operatorname{hypot}(N_x, N_y) = \sqrt{N_x^2 + N_y^2}$ (evaluated without forming the squares); "
                 r"at $N(\theta, \varphi)$ the radicand is $\sin^2\varphi\,(\cos^2\theta + \sin^2\theta) = "
                 r"\sin^2\varphi$, and $\sin\varphi > 0$ for $0 < \varphi < \pi$", sin_kernel, sp.sin(phi),
                 why_numeric=r"sympy leaves $\sqrt{\sin^2\varphi}$ as $\lvert\sin\varphi\rvert$: its symbol "
                             r"$\varphi$ is real, with no interval to tell it $\sin\varphi > 0$"),
            Step(r"Both arguments of atan2 carry the factor $\sin\varphi > 0$, which leaves the angle unchanged, and "
                 r"$\mathrm{atan2}(\sin\theta, \cos\theta) = \theta$ for $-\pi < \theta < \pi$", u_kernel, u_claim,
                 why_numeric=r"sympy simplifies neither the positive factor out of atan2 nor "
                             r"$\mathrm{atan2}(\sin\theta, \cos\theta)$ to $\theta$, true on one branch only"),
            Step(r"By step 1 the first argument is $\sin\varphi$, and $\mathrm{atan2}(\sin\varphi, \cos\varphi) "
                 r"= \varphi$ for $0 < \varphi < \pi$", v_kernel, V_OF_PHI,
                 why_numeric=r"as in step 2, sympy does not reduce $\mathrm{atan2}(\sin\varphi, \cos\varphi)$ "
                             r"to $\varphi$, true on $0 < \varphi < \pi$ only"),
            Step("Differentiate $u$ and $v$", rates, sp.Tuple(*RATES_CLAIMED)),
        ),
        claims={"u": (u_kernel, u_claim), "v": (v_kernel, V_OF_PHI), "sin": (sin_kernel, sp.sin(phi)),
                "rates": (rates, sp.Tuple(*RATES_CLAIMED))},
        shown={"theta": THETA_OFF_SEAM, "phi": PHI_OFF_POLES},
        where={F.N_x: N[0], F.N_y: N[1], F.N_z: N[2]}, domain=DOMAIN,
        evidence=partial(_chart_evidence, corrupt),
        wrong_variants=(("u without the offset pi: theta / 2 pi", lambda: _chart(u_claim=theta / (2 * sp.pi)).check()),
                        ("v with the arguments of atan2 swapped",
                         lambda: _chart(v_kernel=sp.atan2(F.N_z, sp.sqrt(F.N_x**2 + F.N_y**2)) / sp.pi).check()),
                        ("the kernel's u and v swapped", lambda: _chart(corrupt=lambda a: a[:, ::-1]).check())),
    )


# ------------------------------------------------------------------------------- the frame
#: The seed's cut-off below which its frame is the fallback (seed Cell 1, ``tangent_frame``: sin phi > 1e-4).
SEED_POLE_SIN_PHI = 1e-4
#: The renderer's: float64's smallest normal number.  Above it 1/sin phi is finite and sin phi
#: has its 53 bits, so the regular branch is evaluated as written; at or below it sin phi is 0
#: (the pole itself) or subnormal.
POLE_CLAIMED = 2.0**-1022
#: ... and the pole's fallback pair (e_theta, e_phi) it claims the kernel takes, written here: the
#: branches of `renderer.formulas.TANGENT_FRAME` are held to it, not to `F.FALLBACK_FRAME` itself.
CLAIMED_FALLBACK = (1, 0, 0, 0, 1, 0)


def _branch_structure(frame=F.TANGENT_FRAME, pole=F.POLE_SIN_PHI):
    """Refuted unless every component of ``frame`` (TANGENT_FRAME) is Piecewise((regular,
    sin_phi > POLE_SIN_PHI), (fallback, True)) with `CLAIMED_FALLBACK`'s values,
    and ``pole`` (POLE_SIN_PHI) is `POLE_CLAIMED`."""
    if float(pole) != POLE_CLAIMED:
        return Verdict("refuted", f"POLE_SIN_PHI is {pole}: the regular frame is evaluable in float64 down to "
                       f"its smallest normal number {POLE_CLAIMED:g} (the draft cut it off at {SEED_POLE_SIN_PHI:g})")
    for k, (c, fallback) in enumerate(zip(frame, CLAIMED_FALLBACK)):
        if not isinstance(c, sp.Piecewise):
            ok = c.is_number and c - fallback == 0         # both branches equal: folded by sympy
        else:
            ok = (len(c.args) == 2 and c.args[0].cond == (F.sin_phi > F.POLE_SIN_PHI)
                  and c.args[1].cond == sp.true and c.args[1].expr - fallback == 0)
        if not ok:
            return Verdict("refuted", f"TANGENT_FRAME[{k}] is not (regular, sin_phi > POLE_SIN_PHI), "
                           f"(fallback, True): {c}")
    return None


def _frame_evidence(corrupt=None, frame=F.TANGENT_FRAME, pole=F.POLE_SIN_PHI):
    """The frame's branches and pole cut-off, and the renderer's shading normals, which the frame
    builds (proofs/pixels.py); ``corrupt`` alters the gradient the kernel is compared with."""
    bad = _branch_structure(frame, pole)
    if bad is not None:
        return bad
    from .pixels import TOLERANCE, normal_error, worst_of
    worst, count, covered = worst_of(normal_error, [(f, b, corrupt) for f in F.FIELDS
                                           for b in ("chart", "surface")])
    if worst > TOLERANCE["normal"]:
        return Verdict("refuted", f"the renderer's N' differs from PERTURBED_NORMAL in this frame by {worst:.1e} "
                       f"at some of {count:,} sphere-A pixels")
    return Verdict("proved", f"the tangent frame is its regular branch where sin phi > {float(F.POLE_SIN_PHI):g} "
                   "(float64's smallest normal number) and its fallback elsewhere, in each component; the "
                   f"renderer's N' (both bump modes, {len(F.FIELDS)} fields) at {count:,} seeded sphere-A pixels (zoomed pole "
                   f"ring and the draft's fallback disc sin phi <= {SEED_POLE_SIN_PHI:g} included) within {worst:.1e} "
                   "of the perturbed normal evaluated by mpmath in this frame", residual=worst, rendered=count,
                   bound=TOLERANCE["normal"], covers=covered)


def _orthonormal(et=REGULAR[:3], ep=REGULAR[3:], **evidence):
    """Theorem frame-orthonormal for the frame (``et``, ``ep``) and the evidence's options (wrong variants)."""
    d_theta, d_phi = sp.Mul(1 / sp.sin(phi), sp.Derivative(N_S, theta)), sp.Derivative(N_S, phi)
    tangent, unit = sp.Tuple(Dot(ET_S, N_S), Dot(EP_S, N_S)), sp.Tuple(Dot(ET_S, ET_S), Dot(EP_S, EP_S), Dot(ET_S, EP_S))
    return Theorem(
        id="frame-orthonormal", title=TITLES["frame-orthonormal"],
        statement=(r"For $⟦phi⟧$ the renderer's tangent frame (its "
                   r"branch away from the poles) $⟦kernel_e_theta⟧$ and "
                   r"$⟦kernel_e_phi⟧$, at $N(\theta, \varphi)$, satisfies "
                   r"$⟦e_theta⟧$ and $⟦e_phi⟧$; it is tangent, $⟦tangent⟧$, and orthonormal, $⟦unit⟧$."),
        steps=(
            *calc(ET_S, (r"Substitute $N(\theta, \varphi)$ into $e_\theta = (-N_y, N_x, 0)/\sin\varphi$ (there the "
                         r"kernel's $\operatorname{hypot}(N_x, N_y)$ is $\sin\varphi$, by ⟪chart⟫)", sp.Matrix([-sp.sin(theta), sp.cos(theta), 0])),
                  (r"This is $\partial N/\partial\theta = \sin\varphi\,(-\sin\theta, \cos\theta, 0)$ divided by "
                   r"$\sin\varphi$", d_theta)),
            *calc(EP_S, (r"Likewise, substitute it into $e_\varphi = (N_z N_x, N_z N_y, -\sin^2\varphi)/\sin\varphi$",
                         sp.Matrix([sp.cos(phi) * sp.cos(theta), sp.cos(phi) * sp.sin(theta), -sp.sin(phi)])),
                  (r"This is the $\varphi$-derivative of $N$", d_phi)),
            Step(r"Differentiating $N \cdot N = 1$ gives $N \cdot \partial N/\partial\theta = N \cdot \partial N/"
                 r"\partial\varphi = 0$, so by steps 2 and 4 both vectors are tangent", tangent, sp.Tuple(0, 0)),
            Step(r"From steps 1 and 3: $\sin^2\theta + \cos^2\theta = 1$, $\cos^2\varphi + \sin^2\varphi = 1$, and the "
                 r"mixed products cancel", unit, sp.Tuple(1, 1, 0)),
        ),
        claims={"e_theta": (ET_S, d_theta), "e_phi": (EP_S, d_phi), "tangent": (tangent, sp.Tuple(0, 0)),
                "unit": (unit, sp.Tuple(1, 1, 0))},
        shown={"phi": PHI_OFF_POLES, "kernel_e_theta": sp.Eq(ET_S, sp.Tuple(*REGULAR[:3]), evaluate=False),
               "kernel_e_phi": sp.Eq(EP_S, sp.Tuple(*REGULAR[3:]), evaluate=False)},
        where=_where(et, ep), names=VECTOR_NAMES, domain=DOMAIN, evidence=partial(_frame_evidence, **evidence),
        wrong_variants=(("e_phi multiplied by sin(phi)", lambda: _orthonormal(ep=[c * F.sin_phi for c in REGULAR[3:]]).check()),
                        ("e_theta with a flipped sign", lambda: _orthonormal(et=[-c for c in REGULAR[:3]]).check()),
                        ("the kernel's N' built with h_u and h_v swapped",
                         lambda: _orthonormal(corrupt=lambda g: g[:, ::-1]).check()),
                        ("the seed's pole cut-off 1e-4 back", lambda: _orthonormal(pole=SEED_POLE_SIN_PHI).check()),
                        ("e_theta's z the constant 1 in both branches (the regular branch's 0 and the fallback's "
                         "replaced)", lambda: _orthonormal(frame=F.TANGENT_FRAME[:2] + (sp.Integer(1),)
                                                           + F.TANGENT_FRAME[3:]).check()),
                        ("the fallback's e_theta turned to (0, 1, 0)",
                         lambda: _orthonormal(frame=tuple(
                             sp.Piecewise((c.args[0].expr, c.args[0].cond), (sp.Integer(k == 1), True))
                             if k < 3 and isinstance(c, sp.Piecewise) else c
                             for k, c in enumerate(F.TANGENT_FRAME))).check())),
    )



def _orientation_value():
    return sp.simplify(e_theta.cross(e_phi).dot(N))


#: What the theorem claims (e_theta x e_phi) . N is.
CLAIMED_ORIENTATION = -1
#: ... and what it claims the pole fallback's e_theta x e_phi is: +z, the outward normal at the
#: north pole, so the fallback is right-handed there, unlike the regular frame.
CLAIMED_FALLBACK_CROSS = sp.Matrix([0, 0, 1])


def _orientation(claimed=CLAIMED_ORIENTATION, fallback=F.FALLBACK_FRAME, et=REGULAR[:3], ep=REGULAR[3:]):
    """Theorem frame-orientation claiming ``claimed``, for the frame (``et``, ``ep``) and pole ``fallback``."""
    triple = Dot(Cross(ET_S, EP_S), N_S)
    poles = Cross(sp.Matrix(fallback[:3]), sp.Matrix(fallback[3:]))
    return Theorem(
        id="frame-orientation", title=TITLES["frame-orientation"],
        statement=r"$⟦orientation⟧$: the pair $(e_\theta, e_\varphi)$ is left-handed about the outward normal, "
                  r"$⟦cross⟧$. The pole fallback "
                  r"($⟦pole⟧$, float64's smallest normal number: the pole itself) has "
                  r"$⟦fallback⟧$: right-handed at the north pole, where the outward normal is $+z$.",
        steps=(
            Step(r"Cross the frame of ⟪frame-orthonormal⟫: $(-\sin\theta, \cos\theta, 0) \times (\cos\varphi"
                 r"\cos\theta, \cos\varphi\sin\theta, -\sin\varphi) = (-\sin\varphi\cos\theta, -\sin\varphi\sin\theta, "
                 r"-\cos\varphi)$", Cross(ET_S, EP_S), -N_S),
            *calc(triple, ("Dot both sides of step 1 with $N$", -Dot(N_S, N_S)),
                  ("$N$ is a unit vector", sp.Integer(claimed))),
            Step(rf"At the poles the kernel takes the fixed pair $e_\theta = {tuple(fallback[:3])}$, "
                 rf"$e_\varphi = {tuple(fallback[3:])}$, whose cross product is $+z$, the outward normal at the "
                 r"north pole", poles, CLAIMED_FALLBACK_CROSS),
        ),
        claims={"orientation": (triple, sp.Integer(claimed)), "fallback": (poles, CLAIMED_FALLBACK_CROSS),
                "cross": (Cross(ET_S, EP_S), -N_S)},
        shown={"pole": sp.LessThan(F.sin_phi, sp.Float(F.POLE_SIN_PHI, 2))},
        where=_where(et, ep), names=VECTOR_NAMES, domain=DOMAIN,
        wrong_variants=(("the seed's reading: aligned with N (+1)", lambda: _orientation(1).check()),
                        ("the frame with e_theta and e_phi swapped",
                         lambda: _orientation(et=REGULAR[3:], ep=REGULAR[:3]).check()),
                        ("the pole fallback with e_theta and e_phi swapped",
                         lambda: _orientation(fallback=F.FALLBACK_FRAME[3:] + F.FALLBACK_FRAME[:3]).check())),
    )


#: This module's theorems: id -> title.
TITLES = {"chart": "The chart is the spherical angles",
          "frame-orthonormal": "The tangent frame is orthonormal and tangent",
          "frame-orientation": "Orientation of the tangent frame"}

titles, build = catalogue(TITLES, {"chart": _chart, "frame-orthonormal": _orthonormal,
                                   "frame-orientation": _orientation})
