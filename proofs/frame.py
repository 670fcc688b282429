"""The chart and the tangent frame of sphere A, as the renderer holds them (seed §3, Cell 2).

The theorems are about `renderer.formulas`: its chart ``CHART`` (u, v, sin phi
of a unit normal) and the regular branch of its ``TANGENT_FRAME`` (the
branch taken where sin phi > ``POLE_SIN_PHI``).  The independent side is the
unit sphere in spherical coordinates, N(theta, phi), and its derivatives
dN/dtheta and dN/dphi, written here.
"""

import dataclasses

import sympy as sp

from renderer import formulas as F

from .core import Identity, Theorem, Verdict, check_identities

theta, phi = sp.symbols("theta phi", real=True)
#: The unit normal in spherical coordinates (the independent side).
N = sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
#: The renderer's symbols at N(theta, phi).  sin_phi is the kernel's sqrt(N_x^2 + N_y^2)
#: (`formulas.CHART`), which is sin(phi) for 0 < phi < pi (theorem `chart`).
ON_SPHERE = {F.N_x: N[0], F.N_y: N[1], F.N_z: N[2], F.sin_phi: sp.sin(phi)}
#: Sampling domain: away from the poles, where sin(phi) > 0, and off the seam theta = +-pi.
DOMAIN = {theta: (-3.1, 3.1), phi: (0.01, 3.13)}
#: LaTeX names of the renderer's symbols.
NAMES = {F.sin_phi: r"\sin\varphi"}


def regular_branch(component):
    """The first (regular) branch of a component of `formulas.TANGENT_FRAME`.  A
    component whose two branches are equal (e_theta's z, 0 in both) is not a
    Piecewise: sympy folded it, and it is its own regular branch."""
    return component.args[0].expr if isinstance(component, sp.Piecewise) else component


#: The renderer's frame where sin(phi) > POLE_SIN_PHI, in terms of N_x, N_y, N_z, sin_phi.
REGULAR = tuple(regular_branch(c) for c in F.TANGENT_FRAME)
#: ... and at N(theta, phi).
e_theta = sp.Matrix(REGULAR[:3]).subs(ON_SPHERE)
e_phi = sp.Matrix(REGULAR[3:]).subs(ON_SPHERE)


def _frame_identities(et, ep):
    return [
        Identity(r"e_\theta\cdot e_\theta", et.dot(et), sp.Integer(1), DOMAIN),
        Identity(r"e_\varphi\cdot e_\varphi", ep.dot(ep), sp.Integer(1), DOMAIN),
        Identity(r"e_\theta\cdot e_\varphi", et.dot(ep), sp.Integer(0), DOMAIN),
        Identity(r"e_\theta\cdot N", et.dot(N), sp.Integer(0), DOMAIN),
        Identity(r"e_\varphi\cdot N", ep.dot(N), sp.Integer(0), DOMAIN),
        Identity(r"e_\theta", et, sp.diff(N, theta) / sp.sin(phi), DOMAIN),
        Identity(r"e_\varphi", ep, sp.diff(N, phi), DOMAIN),
    ]


#: The cut-off below which the frame is the fallback (seed Cell 1, ``tangent_frame``: sin phi > 1e-4).
SEED_POLE_SIN_PHI = 1e-4


def _branch_structure(frame=F.TANGENT_FRAME, pole=F.POLE_SIN_PHI):
    """Refuted unless every component of ``frame`` (TANGENT_FRAME) is Piecewise((regular,
    sin_phi > POLE_SIN_PHI), (fallback, True)) with FALLBACK_FRAME's values,
    and ``pole`` (POLE_SIN_PHI) is the seed's cut-off."""
    if pole != SEED_POLE_SIN_PHI:
        return Verdict("refuted", f"POLE_SIN_PHI is {pole}, the seed's cut-off is {SEED_POLE_SIN_PHI}")
    for k, (c, fallback) in enumerate(zip(frame, F.FALLBACK_FRAME)):
        if not isinstance(c, sp.Piecewise):
            ok = c.is_number and c - fallback == 0         # both branches equal: folded by sympy
        else:
            ok = (len(c.args) == 2 and c.args[0].cond == (F.sin_phi > F.POLE_SIN_PHI)
                  and c.args[1].cond == sp.true and c.args[1].expr - fallback == 0)
        if not ok:
            return Verdict("refuted", f"TANGENT_FRAME[{k}] is not (regular, sin_phi > POLE_SIN_PHI), "
                           f"(fallback, True): {c}")
    return None


def _check_frame(et, ep, corrupt=None, frame=F.TANGENT_FRAME, pole=F.POLE_SIN_PHI):
    bad = _branch_structure(frame, pole)
    if bad is not None:
        return bad
    verdict = check_identities(_frame_identities(et, ep))
    if not verdict.holds:
        return verdict
    # The renderer's shading normals, which the frame builds (proofs/pixels.py).
    from .pixels import TOLERANCE, normal_error, worst_of
    worst, count = worst_of(normal_error, [(f, b, corrupt) for f in ("sine", "ridges", "rings")
                                           for b in ("chart", "surface")])
    if worst > TOLERANCE["normal"]:
        return Verdict("refuted", f"the renderer's N' differs from PERTURBED_NORMAL in this frame by {worst:.1e} "
                       f"at some of {count} sphere-A pixels")
    return Verdict(verdict.status, f"renderer.formulas.TANGENT_FRAME, regular branch at N(theta, phi): "
                   f"{verdict.evidence}; the renderer's N' (GBuffer.Ns, both bump modes, 3 fields) at {count} "
                   f"seeded sphere-A pixels (pole ring and fallback included) within {worst:.1e} of mpmath's "
                   "PERTURBED_NORMAL in this frame", verdict.residual, verdict.digits, verdict.points, count)


def vector_latex(components):
    """LaTeX of a row vector of the renderer's expressions (sin_phi as sin(varphi)).
    The z-component 0 of e_theta is a sympy Float; shown as 0."""
    return sp.latex(sp.Matrix(components).T.applyfunc(lambda c: sp.Integer(0) if c.is_zero else c),
                    symbol_names=NAMES)


FRAME_ORTHONORMAL = Theorem(
    id="frame-orthonormal", title="The tangent frame is orthonormal and tangent",
    statement=(r"For $0 < \varphi < \pi$ the renderer's frame (`renderer.formulas.TANGENT_FRAME`, "
               rf"regular branch) $e_\theta = {vector_latex(REGULAR[:3])}$ and "
               rf"$e_\varphi = {vector_latex(REGULAR[3:])}$ "
               r"are unit vectors, orthogonal to each other and to $N$, and equal "
               r"$\frac{1}{\sin\varphi}\partial N/\partial\theta$ and $\partial N/\partial\varphi$."),
    steps=tuple((i.label, i.lhs, i.rhs) for i in _frame_identities(e_theta, e_phi)),
    check=lambda: _check_frame(e_theta, e_phi),
    wrong_variants=(("e_phi multiplied by sin(phi)", lambda: _check_frame(e_theta, e_phi * sp.sin(phi))),
                    ("e_theta with a flipped sign",
                     lambda: check_identities([Identity(r"e_\theta", -e_theta, sp.diff(N, theta) / sp.sin(phi),
                                                        DOMAIN)])),
                    ("the kernel's N' built with h_u and h_v swapped",
                     lambda: _check_frame(e_theta, e_phi, corrupt=lambda g: g[:, ::-1])),
                    ("the pole cut-off moved from 1e-4 to 3e-4", lambda: _check_frame(e_theta, e_phi, pole=3e-4)),
                    ("e_theta's z the constant 1 in both branches (the regular branch's 0 and the fallback's "
                     "replaced)", lambda: _check_frame(e_theta, e_phi, frame=F.TANGENT_FRAME[:2] + (sp.Integer(1),)
                                                        + F.TANGENT_FRAME[3:])),
                    ("the fallback's e_theta turned to (0, 1, 0)",
                     lambda: _check_frame(e_theta, e_phi, frame=tuple(
                         sp.Piecewise((c.args[0].expr, c.args[0].cond), (sp.Integer(k == 1), True))
                         if k < 3 and isinstance(c, sp.Piecewise) else c for k, c in enumerate(F.TANGENT_FRAME))))),
    pages=("s3",),
)


def _orientation_value():
    return sp.simplify(e_theta.cross(e_phi).dot(N))


def _fallback_cross(fallback=F.FALLBACK_FRAME):
    """e_theta x e_phi of the pole fallback (a constant frame)."""
    return sp.Matrix(fallback[:3]).cross(sp.Matrix(fallback[3:]))


#: What the theorem claims (e_theta x e_phi) . N is: the check compares the
#: frame with this constant, not with its own simplification.
CLAIMED_ORIENTATION = -1
#: ... and what it claims the pole fallback's e_theta x e_phi is: +z, the outward
#: normal at the north pole, so the fallback is right-handed there, unlike the regular frame.
CLAIMED_FALLBACK_CROSS = sp.Matrix([0, 0, 1])


def _check_orientation(claimed=CLAIMED_ORIENTATION, fallback=F.FALLBACK_FRAME, et=e_theta, ep=e_phi) -> Verdict:
    verdict = check_identities([
        Identity(r"(e_\theta\times e_\varphi)\cdot N", et.cross(ep).dot(N), sp.Integer(claimed), DOMAIN),
        Identity(r"\text{fallback } e_\theta\times e_\varphi", _fallback_cross(fallback), CLAIMED_FALLBACK_CROSS)])
    if not verdict.holds:
        return verdict
    return dataclasses.replace(verdict, evidence=(
        f"(e_theta x e_phi) . N = {claimed:+d} on the regular branch: the frame is "
        f"{'right' if claimed == 1 else 'left'}-handed about the outward normal; the pole fallback's "
        f"e_theta x e_phi = {list(CLAIMED_FALLBACK_CROSS)}, right-handed at the north pole; {verdict.evidence}"))


FRAME_ORIENTATION = Theorem(
    id="frame-orientation", title="Orientation of the tangent frame",
    statement=rf"$(e_\theta \times e_\varphi)\cdot N = {CLAIMED_ORIENTATION}$: the pair $(e_\theta, e_\varphi)$ is "
              r"left-handed about the outward normal, $e_\theta\times e_\varphi = -N$. The pole fallback "
              rf"($\sin\varphi \le {sp.latex(sp.Float(F.POLE_SIN_PHI, 2))}$), "
              rf"$e_\theta = {vector_latex(F.FALLBACK_FRAME[:3])}$, $e_\varphi = {vector_latex(F.FALLBACK_FRAME[3:])}$, "
              rf"has $e_\theta\times e_\varphi = {sp.latex(CLAIMED_FALLBACK_CROSS.T)}$: right-handed at the "
              r"north pole, where the outward normal is $+z$.",
    steps=((r"cross product", r"e_\theta\times e_\varphi", e_theta.cross(e_phi).applyfunc(sp.simplify)),
           (r"outward normal", "N", N),
           (r"orientation", r"(e_\theta\times e_\varphi)\cdot N", _orientation_value()),
           (r"pole fallback", r"e_\theta\times e_\varphi", _fallback_cross())),
    check=_check_orientation,
    wrong_variants=(("the seed's reading: aligned with N (+1)", lambda: _check_orientation(1)),
                    ("the frame with e_theta and e_phi swapped", lambda: _check_orientation(et=e_phi, ep=e_theta)),
                    ("the pole fallback with e_theta and e_phi swapped",
                     lambda: _check_orientation(fallback=F.FALLBACK_FRAME[3:] + F.FALLBACK_FRAME[:3]))),
    pages=("s3", "s5"),
    seed_says="Cell 2 prints (e_theta x e_phi) . N and labels the frame 'unit, aligned with N'.",
)


# ------------------------------------------------------------------------------- the chart
#: The renderer's chart (u, v, sin phi) at N(theta, phi).
CHART_AT = tuple(c.subs({F.N_x: N[0], F.N_y: N[1], F.N_z: N[2]}) for c in F.CHART)
#: The chart's rates du/dtheta and dv/dphi, from `formulas.CHART` with its own sin phi
#: (CHART[2]) written as the symbol sin_phi and then as sin(phi): the factors that turn
#: chart derivatives h_u, h_v into angular ones.
CHART_RATES = (sp.simplify(sp.diff(CHART_AT[0], theta)),
               sp.simplify(sp.diff(F.CHART[1].subs(F.CHART[2], F.sin_phi).subs(ON_SPHERE), phi)))


#: The rates the statement claims (printed from these objects).
RATES_CLAIMED = (1 / (2 * sp.pi), 1 / sp.pi)


def _chart_identities(u_claim, v_claim):
    return [
        Identity("u", CHART_AT[0], u_claim, DOMAIN),
        Identity("v", CHART_AT[1], v_claim, DOMAIN),
        Identity(r"\sin\varphi", CHART_AT[2], sp.sin(phi), DOMAIN),
        Identity(r"\partial u/\partial\theta", CHART_RATES[0], RATES_CLAIMED[0], DOMAIN),
        Identity(r"\partial v/\partial\varphi", CHART_RATES[1], RATES_CLAIMED[1], DOMAIN),
    ]


U_OF_THETA, V_OF_PHI = (theta + sp.pi) / (2 * sp.pi), phi / sp.pi
#: The chart's inverse, theta(u) and phi(v), solved from u(theta) and v(phi).
THETA_OF_U = sp.solve(sp.Eq(U_OF_THETA, F.u), theta)[0]
PHI_OF_V = sp.solve(sp.Eq(V_OF_PHI, F.v), phi)[0]
ANGLE_NAMES = {phi: r"\varphi"}


def _check_chart(identities, corrupt=None):
    verdict = check_identities(identities)
    if not verdict.holds:
        return verdict
    # The renderer's own chart (GBuffer.uv) at its own N (proofs/pixels.py).
    from .pixels import TOLERANCE, chart_error, worst_of
    worst, count = worst_of(chart_error, [(f, corrupt) for f in ("sine", "ridges", "rings")])
    if worst > TOLERANCE["chart"]:
        return Verdict("refuted", f"the renderer's (u, v) differs from CHART(N) by {worst:.1e} at some of "
                       f"{count} sphere-A pixels")
    return Verdict(verdict.status, f"renderer.formulas.CHART at N(theta, phi): {verdict.evidence}; the "
                   f"renderer's (u, v) (GBuffer.uv) at {count} seeded sphere-A pixels (pole ring and fallback "
                   f"included) within {worst:.1e} of mpmath's CHART at its N", verdict.residual, verdict.digits,
                   verdict.points, count)


_swapped = [Identity("v", sp.atan2(N[2], sp.sqrt(N[0]**2 + N[1]**2)) / sp.pi, V_OF_PHI, DOMAIN)]

CHART_INVERSE = Theorem(
    id="chart", title="The chart is the spherical angles",
    statement=(r"For $-\pi < \theta < \pi$ and $0 < \varphi < \pi$ the renderer's chart "
               r"(`renderer.formulas.CHART`) of $N(\theta, \varphi)$ is "
               rf"$u = {sp.latex(F.CHART[0])} = {sp.latex(U_OF_THETA)}$, "
               rf"$v = {sp.latex(F.CHART[1])} = {sp.latex(V_OF_PHI, symbol_names=ANGLE_NAMES)}$ and "
               rf"${sp.latex(F.CHART[2])} = \sin\varphi$; so $\partial u/\partial\theta = {sp.latex(RATES_CLAIMED[0])}$ "
               rf"and $\partial v/\partial\varphi = {sp.latex(RATES_CLAIMED[1])}$, the factors between chart and angular "
               r"derivatives of $h$."),
    steps=tuple((i.label, i.lhs, i.rhs) for i in _chart_identities(U_OF_THETA, V_OF_PHI)),
    check=lambda: _check_chart(_chart_identities(U_OF_THETA, V_OF_PHI)),
    wrong_variants=(("u without the offset pi: theta / 2 pi",
                     lambda: _check_chart(_chart_identities(theta / (2 * sp.pi), V_OF_PHI))),
                    ("v with the arguments of atan2 swapped", lambda: _check_chart(_swapped)),
                    ("the kernel's u and v swapped",
                     lambda: _check_chart(_chart_identities(U_OF_THETA, V_OF_PHI), corrupt=lambda a: a[:, ::-1]))),
    pages=("s3",),
    seed_says="Cell 1 (chartA1): u = (theta + pi) / 2 pi, v = acos(N_z) / pi.",
)

THEOREMS = (CHART_INVERSE, FRAME_ORTHONORMAL, FRAME_ORIENTATION)
