"""The bump moves no boundary (seed §3, theorem).

The argument: the chamber (which root is nearest) and every shadow predicate
(attached: N . (L - P) > 0; cast: a root of the segment quadratic in (0, 1); the
floor plane between P and L), written here in sympy, are built from geometry
symbols only: their Jacobian in beta, eps_u, eps_v, k_u and k_v vanishes.  Those
predicates are this module's, not the kernel's (`renderer.kernel` tests them in
hand-written numba), so the verdict is "verified", earned on the renderer's own
outputs: independent G-buffers across height fields, beta, eps, both bump
modes and both pipelines have the same chamber, t, P and N bit for bit, and the
kernel's own reach predicate (`renderer.pointwise.reach`) gives every light the
same mask.  The sphere roots written here are the renderer's t, and its reach
masks are these predicates, evaluated at its hit points.
"""

import itertools
from functools import lru_cache, partial

import numpy as np
import sympy as sp

from renderer import formulas as F
from renderer.scene import PointLight, Scene

from .core import Dot, Jacobian, Step, Theorem, Verdict, catalogue

x, y, e, R, t, s = sp.symbols("x y e R t s", real=True)
Cb = sp.Matrix(sp.symbols("C_x C_y C_z", real=True))
r_b = sp.Symbol("r_B", positive=True)
L = sp.Matrix(sp.symbols("L_x L_y L_z", real=True))

O = sp.Matrix([0, 0, e])
d = sp.Matrix([x, y, -e])
ray = O + t * d


def _sphere_roots(C, r):
    """(near, far) roots t of |O + t d - C|^2 = r^2: (-b -+ sqrt(b^2 - 4 a c)) / 2a."""
    a_, b_, c_ = d.dot(d), 2 * d.dot(O - C), (O - C).dot(O - C) - r**2
    return tuple((-b_ + sign * sp.sqrt(b_**2 - 4 * a_ * c_)) / (2 * a_) for sign in (-1, 1))


P_A = ray.subs(t, _sphere_roots(sp.zeros(3, 1), R)[0])
N_A = P_A / R
SEGMENT = P_A + s * (L - P_A)

#: The chamber's roots and the shadow predicates at sphere A's hit point, by the names the proof uses.
T_A, T_B, T_FLOOR, ATTACHED, CAST, FLOOR = sp.symbols("t_A t_B t_floor a q f")
PREDICATES = {
    T_A: _sphere_roots(sp.zeros(3, 1), R)[0],
    T_B: _sphere_roots(Cb, r_b)[0],
    T_FLOOR: -ray[2].subs(t, 0) / sp.diff(ray[2], t),
    ATTACHED: N_A.dot(L - P_A),
    CAST: (SEGMENT - Cb).dot(SEGMENT - Cb) - r_b**2,
    FLOOR: P_A[2] * L[2],
}
#: The vectors the statement's attached predicate names: the normal, the light and the hit point.
N_S, L_S, P_S = (sp.MatrixSymbol(x, 3, 1) for x in "NLP")
NAMES = {T_FLOOR: r"t_{\mathrm{floor}}", ATTACHED: r"a", CAST: r"q", FLOOR: r"f"}


def _seed_attached_predicate(gradient="exact"):
    """The seed's attached predicate N' . (L - P) (the light counts where it is > 0), with N' the
    renderer's chart-mode perturbed normal (`formulas.PERTURBED_NORMAL`) at
    sphere A's hit point, fed the first registered field's exact gradient (`HeightField.gradient`)
    or central difference (`HeightField.central`)."""
    field = next(iter(F.FIELDS.values()))
    grad = field.gradient if gradient == "exact" else field.central
    at_hit = {F.N_x: N_A[0], F.N_y: N_A[1], F.N_z: N_A[2], F.h_u: grad[0], F.h_v: grad[1]}
    N_prime = sp.Matrix(F.PERTURBED_NORMAL["chart"]).subs(at_hit)
    return N_prime.dot(L - P_A)


BETAS = (0.0, 0.35, 1.5, 10.0)
#: bump="surface" needs beta below sphere A's radius (Scene refuses more).
SURFACE_BETAS = (0.0, 0.35, 0.9)
EPSILONS = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def render_flips(size=64, gate=False):
    """(G-buffers, differing values, differing reach-mask pixels, distinct shading normals):
    each G-buffer independent (the registered fields x `EPSILONS` x 2 pipelines x `BETAS` for
    the chart bump and `SURFACE_BETAS` for the surface bump), its chamber, t, P, N and per-light
    reach masks (`renderer.pointwise.reach`, with ``gate`` the kernel's Ns . w > 0 gate as
    well) compared with those of a beta = 0 G-buffer of the first field; the last count is of
    the G-buffers' distinct Ns arrays, `shadings()` if every parameter reached the shading.
    Computed once per process and arguments: theorem no-boundary and claim flips-zero
    ask for the same renders."""
    return _render_flips(int(size), bool(gate), tuple(F.FIELDS))


@lru_cache(maxsize=None)
def _render_flips(size, gate, fields):
    from renderer import gbuffer, pointwise

    def geometry(scene, gradient="exact"):
        g = gbuffer(scene, size, size, gradient=gradient)
        return g.Ns, (g.chamber, g.t, g.P, g.N, pointwise.reach(scene, g, gate=gate))

    base = geometry(Scene(height_field=fields[0], beta=0.0))[1]
    counts, shading = [], set()
    for field, eps_, bump in itertools.product(fields, EPSILONS, ("chart", "surface")):
        for b, gradient in itertools.product(BETAS if bump == "chart" else SURFACE_BETAS, ("exact", "central")):
            Ns, arrays = geometry(Scene(height_field=field, beta=b, eps=eps_, bump=bump), gradient)
            counts.append([np.count_nonzero(a != a0) for a, a0 in zip(arrays, base)])
            shading.add(Ns.tobytes())
    *values, masks = (int(sum(n)) for n in zip(*counts))
    return len(counts), sum(values), masks, len(shading)


def shadings():
    """Distinct shading normals Ns over `render_flips`' G-buffers: one for all beta = 0 frames, one per
    field, bump and beta > 0 in the exact pipeline, and per eps as well in the central-difference one."""
    return 1 + len(F.FIELDS) * (len(BETAS) + len(SURFACE_BETAS) - 2) * (1 + len(EPSILONS))


def root_mismatches(root, size=64):
    """(differing, compared): pixels of the default scene on sphere A or B where root ``root``
    of `_sphere_roots` (0, the near one; 1 for a wrong variant), written here and
    evaluated in float64, differs from the renderer's ray parameter t by more than 1e-9."""
    from renderer import gbuffer
    from renderer.render import SPHERE_A, SPHERE_B
    scene = Scene()
    g = gbuffer(scene, size, size)
    at = (*np.meshgrid(g.x, g.y), scene.camera_z, scene.radius_a, scene.radius_b, *scene.center_b)
    with np.errstate(invalid="ignore"):                 # sqrt of a negative off the sphere
        near = [sp.lambdify((x, y, e, R, r_b, *Cb), _sphere_roots(C, r)[root])(*at)
                for C, r in ((sp.zeros(3, 1), R), (Cb, r_b))]
    on = (g.chamber == SPHERE_A) | (g.chamber == SPHERE_B)
    want = np.where(g.chamber == SPHERE_A, *near)
    return int(np.count_nonzero(on & ~(np.abs(want - g.t) <= 1e-9))), int(np.count_nonzero(on))


#: Scenes for comparing the renderer's reach masks with the predicates: the default, lights
#: behind sphere A and below the floor, a light inside sphere B, and (sphere B off) lights just
#: above the floor beside A, which lies beyond them from nearby floor pixels (roots s > 1).
REACH_SCENES = (Scene(), Scene(lights=(PointLight((0.5, -1.0, -6.0)), PointLight((3.0, -2.0, -4.0)))),
                Scene(lights=(PointLight((0.5, 0.5, 1.3)), PointLight((5.0, 5.0, 10.0)))),
                Scene(sphere_b=False, lights=(PointLight((0.0, -1.02, 0.1)), PointLight((1.0, -0.4, 0.15)))))


#: The side of the square frames of `REACH_SCENES` that `reach_mismatches` compares, in pixels.
REACH_SIZE = 128


def predicate_masks(scene, g, margin=1e-9):
    """(masks (n_lights, H, W) bool, decided (n_lights, H, W) bool): the statement's predicates
    evaluated at the G-buffer's hit points in float64, written here from their definitions:
    attached N . (L - P) > 0; the floor plane z = 0 not between P and L (floor on, P off
    it); no blocker sphere (B for A, A for B, both for the floor) with a root of
    |P + s (L - P) - C|^2 = r^2 in (0, 1).  ``decided`` is False where a root, the
    discriminant or the attached product lies within ``margin`` of its threshold."""
    P, N, code = g.P, g.N, g.chamber
    blockers = [(np.zeros(3), scene.radius_a, code != 1)]
    if scene.sphere_b:
        blockers.append((np.asarray(scene.center_b), scene.radius_b, code != 2))
    masks, decided = [], []
    for light in scene.lights:
        w = np.asarray(light.position) - P
        attached = np.einsum("hwc,hwc->hw", N, w)
        ok, sure = attached > 0, np.abs(attached) > margin
        if scene.floor:
            ok &= ~((code != 3) & (light.position[2] * P[..., 2] < 0))
        a = np.einsum("hwc,hwc->hw", w, w)
        for center, radius, applies in blockers:
            d = P - center
            b, c = 2 * np.einsum("hwc,hwc->hw", d, w), np.einsum("hwc,hwc->hw", d, d) - radius**2
            disc = b * b - 4 * a * c
            root = np.sqrt(np.maximum(disc, 0.0))
            s1, s2 = (-b - root) / (2 * a), (-b + root) / (2 * a)
            cut = (disc >= 0) & (((s1 > 0) & (s1 < 1)) | ((s2 > 0) & (s2 < 1)))
            ok &= ~(applies & cut)
            near = (np.abs(disc) <= margin * b * b) | (np.minimum(np.abs(s1), np.abs(s2)) < margin) | \
                (np.minimum(np.abs(s1 - 1), np.abs(s2 - 1)) < margin)
            sure &= ~(applies & near & ok)
        on = code != 0
        masks.append(ok & on)
        decided.append(sure | ~on)
    return np.array(masks), np.array(decided)


def reach_mismatches(size=REACH_SIZE, reach=None):
    """(differing, decided, all): (pixel, light) pairs over `REACH_SCENES` where
    `renderer.pointwise.reach` (or ``reach``, for wrong variants) and `predicate_masks` differ
    (decided pairs only), the decided pairs, and all pairs."""
    from renderer import gbuffer, pointwise
    reach = reach or pointwise.reach
    counts = []
    for scene in REACH_SCENES:
        g = gbuffer(scene, size, size)
        want, decided = predicate_masks(scene, g)
        counts.append((np.count_nonzero((reach(scene, g) != want) & decided), np.count_nonzero(decided),
                       decided.size))
    return tuple(int(sum(n)) for n in zip(*counts))


def _evidence(gate=False, reach=None, root=0):
    """The renderer's own: the near roots written here are its t; its G-buffers across the bump's
    parameters have the geometry of the beta = 0 frame bit for bit; its reach masks are the shadow
    predicates.  ``gate``, ``reach``, ``root``: wrong variants (`render_flips`, `reach_mismatches`,
    `root_mismatches`)."""
    roots, on_spheres = root_mismatches(root)
    if roots:
        return Verdict("refuted", f"the roots t_A, t_B written here miss the renderer's t at {roots} of "
                       f"{on_spheres} sphere pixels")
    frames, values, masks, distinct = render_flips(gate=gate)
    if values or masks or distinct != shadings():
        return Verdict("refuted", f"over {frames} G-buffers, {values} geometry values and {masks} reach-mask "
                       f"pixels differ from the beta = 0 frame ({distinct} distinct Ns, want {shadings()})")
    differing, compared, pairs = reach_mismatches(reach=reach)
    if differing or compared < pairs * 0.99:
        return Verdict("refuted", f"kernel.reach differs from the shadow predicates at {differing} of {compared} "
                       f"decided (pixel, light) pairs (of {pairs:,}; 99% must be decided)")
    return Verdict("verified", f"the near roots t_A, t_B are the renderer's t (to 1e-9) at its {on_spheres:,} sphere "
                   f"pixels; {frames} independent G-buffers ({len(F.FIELDS)} fields x eps 1e-1..1e-8 x 2 pipelines x beta {BETAS} "
                   f"(chart) or {SURFACE_BETAS} (surface), 64x64) have the chamber, t, P and N of the beta = 0 frame "
                   "bit for bit, and the kernel's reach predicate gives each light the same mask "
                   f"({distinct} distinct shading normals: every parameter reaches them); that predicate equals "
                   f"the predicates, evaluated at the hit points, at all {compared:,} decided (pixel, light) pairs (of "
                   f"{pairs:,}) of {len(REACH_SCENES)} scenes ({REACH_SIZE}x{REACH_SIZE}; a light inside sphere B, lights behind A, below "
                   "the floor, and beside A just above it)",
                   residual=float(values + masks + differing), points=frames, rendered=frames)


#: The bump's parameters, in the order the Jacobians take them.
BUMP = (F.beta, F.eps_u, F.eps_v, F.k_u, F.k_v)
#: Sampling intervals: pixels whose rays meet sphere A, and every symbol a wrong variant brings in.
DOMAIN = {x: (-0.2, 0.2), y: (-0.2, 0.2), e: (3.0, 6.0), R: (0.5, 1.0), r_b: (0.2, 0.5), s: (0.0, 1.0),
          **{c: (-2.0, 2.0) for c in (*Cb, *L)},
          **{c: (0.05, 0.95) for c in (F.u, F.v, F.u_p, F.u_m, F.v_p, F.v_m)},
          **{c: (-1.0, 1.0) for c in (*F.e_theta, *F.e_phi)},
          F.beta: (0.1, 2.0), F.eps_u: (1e-3, 0.1), F.eps_v: (1e-3, 0.1), F.k_u: (0.5, 12.0), F.k_v: (0.5, 12.0)}


def _without_sphere_b(scene, g):
    """`renderer.pointwise.reach` of the scene without sphere B (a wrong variant)."""
    from renderer import pointwise
    return pointwise.reach(scene.replace(sphere_b=False), g)


def _no_boundary(attached=None, **evidence):
    """Theorem no-boundary, its attached predicate ``attached`` (default: the geometric one), with the
    evidence's options (wrong variants)."""
    chamber, shadow = Jacobian((T_A, T_B, T_FLOOR), BUMP), Jacobian((ATTACHED, CAST, FLOOR), BUMP)
    where = {**PREDICATES, **({ATTACHED: attached} if attached is not None else {})}
    return Theorem(
        id="no-boundary", title=TITLES["no-boundary"],
        statement=r"The chamber of every pixel (the nearest of the hits $t_A$, $t_B$, $t_{\mathrm{floor}}$) and "
                  r"every shadow predicate (attached, $a$: $⟦attached⟧$; cast, $q$: sphere B's quadratic along the "
                  r"segment from $P$ to $L$ has a root in $(0, 1)$; floor, $f$: the floor plane between $P$ and $L$) are functions of the geometry alone, of none of the bump's parameters: "
                  r"its strength $\beta$, its frequencies $k_u$, $k_v$ and the central difference's steps "
                  r"$\varepsilon_u$, $\varepsilon_v$ (fixed or footprint): $$⟦chamber⟧$$ and $$⟦shadow⟧$$ "
                  r"Hence no pixel changes chamber, and no shadow boundary moves, when the bump's parameters "
                  r"change: the renderer's per-pixel hits and shadow tests come out bit for bit the same.",
        steps=(
            Step(r"The chamber is the nearest hit: the near roots $t_A$ of $\lvert O + t d\rvert^2 = R^2$ (sphere A) and "
                 r"$t_B$ of $\lvert O + t d - C_B\rvert^2 = r_B^2$ (sphere B) and the floor plane's $t_{\mathrm{floor}}$, with $O = (0, 0, e)$ the eye and "
                 r"$d = (x, y, -e)$ the pixel's ray; none involves $\beta$, the steps $\varepsilon$ or the frequencies",
                 chamber, sp.ZeroMatrix(3, len(BUMP))),
            Step(r"The shadow predicates at sphere A's hit $P = O + t_A d$, with $N = P/R$ and $L$ the light, are "
                 r"$a = N \cdot (L - P)$, the segment quadratic $q = \lvert P + s(L - P) - C_B\rvert^2 - r_B^2$ and "
                 r"$f = P_z L_z$: built from the same geometry", shadow, sp.ZeroMatrix(3, len(BUMP))),
        ),
        claims={"chamber": (chamber, sp.ZeroMatrix(3, len(BUMP))), "shadow": (shadow, sp.ZeroMatrix(3, len(BUMP)))},
        shown={"attached": sp.Gt(Dot(N_S, L_S - P_S), 0)},
        where=where, names=NAMES, domain=DOMAIN, evidence=partial(_evidence, **evidence),
        wrong_variants=(("the seed's attached-shadow rule, with the bumped normal",
                         lambda: _no_boundary(_seed_attached_predicate()).check()),
                        ("the seed's rule with the central-difference gradient",
                         lambda: _no_boundary(_seed_attached_predicate("central")).check()),
                        ("the renderer's reach masks gated by the bumped normal (the seed's rule)",
                         lambda: _no_boundary(gate=True).check()),
                        ("the far root of each sphere's quadratic for the hit (t_A, t_B)",
                         lambda: _no_boundary(root=1).check()),
                        ("a reach predicate in which sphere B shadows nothing",
                         lambda: _no_boundary(reach=_without_sphere_b).check())),
    )


#: This module's theorem: id -> title.
TITLES = {"no-boundary": "The bump moves no boundary"}

titles, build = catalogue(TITLES, {"no-boundary": _no_boundary})
