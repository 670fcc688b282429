"""The shading normal at sphere A's pole, inside the draft's cut-off sin(phi) <= 1e-4, on every backend.

The draft replaced the tangent frame by a fixed basis where sin(phi) <= 1e-4 and
floored the 1/sin(phi) of the displaced sphere's normal there: magnified 1e3 times
about the pole, 138 of the 128 x 128 pixels lie in that disc, at 1e4 13,032 of them,
and the displaced sphere's normal there was up to 157 degrees off (default scene, every
field).  The renderer now keeps the chart's frame and the true 1/sin(phi) down to
sin(phi) = `formulas.POLE_SIN_PHI` (2^-1022, float64's smallest normal number).

Reference.  Per pixel centre (x, y) of `render.image_plane`, in mpmath at `DIGITS`
digits: the ray's hit on sphere A, its chart angles theta = atan2(N_y, N_x) and
phi = atan2(|(N_x, N_y)|, N_z), u = (theta + pi) / 2 pi, v = phi / pi; then the
displaced surface p(u, v) = (R + beta h(u, v)) N(u, v), N(u, v) = (sin pi v cos(2 pi u - pi),
sin pi v sin(2 pi u - pi), cos pi v), and its unit normal p_v x p_u / |p_v x p_u| (outward),
with p's partial derivatives taken by sympy from this parametrisation: nothing of
`renderer.formulas` but the field's h.  For bump="chart" the draft's formula
N + beta (h_u e_theta + h_v e_phi) with the unit tangents e_theta = N_u / |N_u|,
e_phi = N_v / |N_v| of the same parametrisation.

Backends: the numba kernel (`gbuffer`'s Ns), the array kernel on numpy and on Dr.Jit
(`arraykernel.render_block` with ``normal=True``; Dr.Jit skips where its LLVM is
missing, and fails when CI=true), and the pointwise path (the numba G-buffer's N through
`pointwise.chart`, `pointwise.tangent_frame`, `pointwise.height`,
`pointwise.exact_gradient` and the generated normal's loop).

Tolerance.  The renderer's N carries a few units of roundoff u = 2^-53 per component
(`kernel.sphere_a_point`), so its u has an absolute error of a few u and its v a relative
one (v = atan2(sin phi, N_z) / pi with sin phi = hypot(N_x, N_y), each of relative error
an ulp or so, at every sin(phi) > 0: nothing here grows like 1 / sin phi).  The normal moves
by |n_u| du + |n_v| dv, n_u and n_v its partial derivatives (mpmath, central differences),
plus its own evaluation's roundings.  So the angle between the two normals is held to

    angle <= TOL_FACTOR u (1 + |n_u| + v |n_v|)     (radians).

Measured: the largest angle / (u (1 + |n_u| + v |n_v|)) over every case here is 5.7 (numba,
numpy and the pointwise path, the sine field at zoom 1e4; Dr.Jit, whose sin, cos and atan2
are a few ulp from libm's, 6.1); TOL_FACTOR = 32 leaves a factor 5 for another libm and CPU.
Over the same pixels 1 + |n_u| + v |n_v| reaches 250 (the sine field at k_u = 13): the bound
is then 9e-13 radians, and the largest angle measured 3e-14 radians (2e-12 degrees).  The
draft's cut-off put these normals 0.3 to 175 degrees off: the planted variant below (the
pointwise path fed the draft's fixed pair and floor) is refused by 13 orders of magnitude
or more.
"""

from __future__ import annotations

import math
from functools import lru_cache

import mpmath
import numpy as np
import pytest
import sympy as sp

from renderer import Scene, arraykernel, backends, gbuffer, generated, pointwise
from renderer import formulas as F
from renderer.render import SPHERE_A, image_plane

from .test_parity import require_backend

U = 2.0**-53
#: The draft's cut-off (seed Cell 1, ``tangent_frame``): the pixels checked here lie inside it.
DRAFT_POLE_SIN_PHI = 1e-4
DIGITS = 40
TOL_FACTOR = 32
#: (zoom, image side): at 1e3 about one pixel in a hundred lies in the disc, at 1e4 most do, at
#: 1e6 (`render.MAX_ZOOM`) all, within 1e-6 of the pole.
FRAMES = ((1e3, 40), (1e4, 16), (1e6, 8))
BACKENDS = ("numba", "numpy", "drjit", "pointwise")
#: Fewest pixels inside the disc per frame, so that the check cannot pass on an empty set.
MIN_INSIDE = {1e3: 8, 1e4: 150, 1e6: 64}


def scenes(bump, seed=2024):
    """One scene per registered field at seeded random beta, frequencies, radius and camera
    distance (sphere B off: it is nowhere near the pole)."""
    rng = np.random.default_rng(seed)
    out = []
    for name in F.FIELDS:
        R = float(rng.uniform(0.5, 2.0))
        out.append(Scene(height_field=name, bump=bump, radius_a=R, camera_z=R * float(rng.uniform(2.0, 8.0)),
                         beta=R * float(rng.uniform(0.05, 0.9)), k_u=float(rng.uniform(0.5, 16.0)),
                         k_v=float(rng.uniform(0.5, 16.0)), sphere_b=False))
    return out


@lru_cache(maxsize=None)
def _surface(scene):
    """mpmath function (u, v) -> the reference normal of ``scene``'s bump (a list of 3 mpf)."""
    uu, vv = F.u, F.v
    h = scene.field.expr.xreplace({F.k_u: sp.Float(scene.k_u, 30), F.k_v: sp.Float(scene.k_v, 30)})
    R, beta = sp.Float(scene.radius_a, 30), sp.Float(scene.beta, 30)
    theta, phi = 2 * sp.pi * uu - sp.pi, sp.pi * vv
    N = sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])
    if scene.bump == "surface":
        p = (R + beta * h) * N
        m = p.diff(vv).cross(p.diff(uu))
    else:
        e_theta, e_phi = N.diff(uu), N.diff(vv)
        m = N + beta * (sp.diff(h, uu) * e_theta / e_theta.norm() + sp.diff(h, vv) * e_phi / e_phi.norm())
    fn = sp.lambdify((uu, vv), list(m), modules="mpmath", cse=True)

    def normal(u, v):
        c = fn(u, v)
        n = mpmath.sqrt(sum(x * x for x in c))
        return [x / n for x in c]
    return normal


def reference(scene, x, y):
    """(normal, bound, sin phi) at the pixel centre (x, y): the reference normal (3 mpf), the
    tolerance of the module's error model (radians) and the hit's sin(phi) (float)."""
    normal = _surface(scene)
    with mpmath.workdps(DIGITS):
        x, y = mpmath.mpf(float(x)), mpmath.mpf(float(y))
        e, R = mpmath.mpf(scene.camera_z), mpmath.mpf(scene.radius_a)
        a = x * x + y * y + e * e
        t = (e * e - mpmath.sqrt(e**4 - a * (e * e - R * R))) / a          # the nearer root
        N = (t * x / R, t * y / R, e * (1 - t) / R)
        s = mpmath.hypot(N[0], N[1])
        u = (mpmath.atan2(N[1], N[0]) + mpmath.pi) / (2 * mpmath.pi)
        v = mpmath.atan2(s, N[2]) / mpmath.pi
        n = normal(u, v)
        step = mpmath.mpf(10) ** -12
        slope = [mpmath.sqrt(sum((p - q) ** 2 for p, q in zip(normal(*plus), normal(*minus)))) / (2 * step)
                 for plus, minus in (((u + step, v), (u - step, v)), ((u, v + step), (u, v - step)))]
        bound = TOL_FACTOR * U * (1 + slope[0] + v * slope[1])
        return n, float(bound), float(s)


def angle(a, b):
    """The angle between the float64 triple ``a`` and the mpmath unit triple ``b`` (radians, float)."""
    with mpmath.workdps(DIGITS):
        a = [mpmath.mpf(float(c)) for c in a]
        cross = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
        return float(mpmath.atan2(mpmath.sqrt(sum(c * c for c in cross)), sum(p * q for p, q in zip(a, b))))


def pointwise_normals(scene, N, frame=None, floor=0.0):
    """The pointwise path's shading normals (k, 3) at the unit normals N (k, 3): chart, frame,
    h and the exact gradient, then the generated normal of ``scene.bump``.  ``frame`` (the
    fixed pair and where it applies) and ``floor`` (a floor of sin phi) plant the draft's cut-off."""
    u, v, sin_phi = pointwise.chart(*N.T)
    e_theta, e_phi = pointwise.tangent_frame(*N.T, sin_phi)
    if frame is not None:
        where, fixed = frame(sin_phi), dict(zip(range(6), F.FALLBACK_FRAME))
        e_theta, e_phi = ([np.where(where, fixed[3 * k + i], c) for i, c in enumerate(e)]
                          for k, e in enumerate((e_theta, e_phi)))
    hu, hv = pointwise.exact_gradient(scene.field, u, v, scene.k_u, scene.k_v)
    h = pointwise.height(scene.field, u, v, scene.k_u, scene.k_v)
    full = lambda value: np.full(N.shape[0], float(value))        # noqa: E731
    out = np.empty((3, N.shape[0]))
    if scene.bump == "surface":
        generated.perturbed_normal_surface_array(*N.T, *e_theta, *e_phi, hu, hv, full(scene.beta), h,
                                                 full(scene.radius_a), np.maximum(sin_phi, floor), out)
    else:
        generated.perturbed_normal_chart_array(*N.T, *e_theta, *e_phi, hu, hv, full(scene.beta), out)
    return out.T


def renderer_normals(scene, zoom, side, backend):
    """(x, y, Ns, inside): the pixel centres, the backend's shading normals (side, side, 3) and the
    sphere-A pixels with sin(phi) <= `DRAFT_POLE_SIN_PHI` (by the numba kernel's hit point)."""
    g = gbuffer(scene, side, side, zoom=zoom)
    inside = (g.chamber == SPHERE_A) & (np.hypot(g.N[..., 0], g.N[..., 1]) <= DRAFT_POLE_SIN_PHI)
    if backend == "numba":
        Ns = g.Ns
    elif backend == "pointwise":
        Ns = np.zeros_like(g.N)
        Ns[inside] = pointwise_normals(scene, g.N[inside])
    else:
        require_backend(backend)
        x, y = image_plane(scene.radius_a, scene.camera_z, side, side, zoom)
        out = arraykernel.render_block(backends.namespace(backend), scene, x, y, method="exact", eps=scene.eps,
                                       dx=float(x[1] - x[0]), dy=float(y[0] - y[1]), kink=False, grad=False,
                                       normal=True)
        Ns = out["normal"].reshape(side, side, 3)
    return g.x, g.y, Ns, inside


@lru_cache(maxsize=None)
def references(scene, zoom, side):
    """{(j, i): (normal, bound, sin phi)} at the pixels inside the disc."""
    x, y, _, inside = renderer_normals(scene, zoom, side, "numba")
    return {(j, i): reference(scene, x[i], y[j]) for j, i in zip(*np.nonzero(inside))}


def worst(scene, zoom, side, Ns):
    """(largest angle / bound, largest angle in degrees, pixels) of the normals ``Ns`` inside the disc."""
    refs = references(scene, zoom, side)
    ratios = [(angle(Ns[j, i], n) / bound, angle(Ns[j, i], n)) for (j, i), (n, bound, _) in refs.items()]
    return max(r for r, _ in ratios), math.degrees(max(a for _, a in ratios)), len(ratios)


@pytest.mark.parametrize("zoom, side", FRAMES)
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("bump", ["surface", "chart"])
def test_the_normal_inside_the_draft_cut_off_is_the_true_one(bump, backend, zoom, side):
    for scene in scenes(bump):
        _, _, Ns, _ = renderer_normals(scene, zoom, side, backend)
        ratio, degrees, count = worst(scene, zoom, side, Ns)
        assert count >= MIN_INSIDE[zoom], (scene.height_field, count)
        assert ratio <= 1.0, f"{scene.height_field}: {degrees:.3g} degrees, {ratio:.3g} x the bound"


def test_the_pixels_span_the_disc():
    """The checked pixels reach from the disc's rim to within 1e-6 of the pole: what is held is
    the frame at every sin(phi) of an accepted zoom's disc, not at one."""
    scene = scenes("surface")[0]
    s = [sin_phi for zoom, side in FRAMES for _, _, sin_phi in references(scene, zoom, side).values()]
    assert max(s) > 0.5 * DRAFT_POLE_SIN_PHI and min(s) < 1e-6


@pytest.mark.parametrize("bump", ["surface", "chart"])
def test_the_draft_cut_off_is_refused(bump):
    """The check shown failing: the pointwise path fed the draft's fixed pair where sin(phi) <= 1e-4
    and, for the surface, its floor max(sin phi, 1e-4) (the renderer before this change).  Every
    field's frame is refused by far; by how many degrees it errs depends on the field (one flat at
    the pole, as sin^2 is, errs by less), so the visible size is asserted of the worst field."""
    worst_degrees = 0.0
    for zoom, side in FRAMES:
        for scene in scenes(bump):
            g = gbuffer(scene, side, side, zoom=zoom)
            inside = (g.chamber == SPHERE_A) & (np.hypot(g.N[..., 0], g.N[..., 1]) <= DRAFT_POLE_SIN_PHI)
            Ns = np.zeros_like(g.N)
            Ns[inside] = pointwise_normals(scene, g.N[inside], frame=lambda s: s <= DRAFT_POLE_SIN_PHI,
                                           floor=DRAFT_POLE_SIN_PHI if bump == "surface" else 0.0)
            ratio, degrees, _ = worst(scene, zoom, side, Ns)
            assert ratio > 1e9, (scene.height_field, zoom, degrees)
            worst_degrees = max(worst_degrees, degrees)
    assert worst_degrees > 1.0


def test_the_frame_is_the_fixed_pair_only_at_sin_phi_zero_or_subnormal():
    """`formulas.POLE_SIN_PHI` is float64's smallest normal: just above it the chart's frame
    (finite, unit, e_theta = (-N_y, N_x, 0) / sin phi); at it, below it and at 0 the fixed pair."""
    tiny = float(F.POLE_SIN_PHI)
    assert tiny == np.finfo(np.float64).tiny
    s = np.array([np.nextafter(tiny, 1.0), 1e-300, 1e-160, 1e-20])
    N = np.stack([s * 0.6, s * 0.8, np.ones_like(s)])
    (et, ep) = (np.array(e) for e in pointwise.tangent_frame(*N, s))
    assert np.allclose(et.T, [[-0.8, 0.6, 0.0]] * 4, rtol=0, atol=8 * U)      # 0.6 s is subnormal at the first
    assert np.allclose(ep.T[:, :2], [[0.6, 0.8]] * 4, rtol=0, atol=8 * U)
    fixed = [np.array(e).ravel() for e in pointwise.tangent_frame(0.0, 0.0, 1.0, np.array([0.0, tiny, 2.0**-1074]))]
    assert np.array_equal(np.concatenate(fixed), np.repeat(np.array(F.FALLBACK_FRAME, float), 3))


def test_the_sine_fields_slope_per_unit_length_has_a_different_limit_on_each_meridian():
    """§7's "The pole": h_u / (2 pi R sin phi), phi = pi v, tends to k_u k_v cos(pi k_u u) / 2R as v -> 0
    along the meridian u, so the sine field's bumped normal has no limit at the pole.  The rings
    field has no u: its slope along e_theta tends to 0 (its slope along e_phi, which turns with the
    meridian, does not: `test_the_pinch_claim_measures_the_rings_cone_point`)."""
    import sympy as sp

    from renderer import formulas as F
    R = sp.Symbol("R", positive=True)
    ku, kv = sp.Symbol("k_u", positive=True), sp.Symbol("k_v", positive=True)

    def limit(name):
        h_u = F.FIELDS[name].gradient[0].subs({F.k_u: ku, F.k_v: kv})
        return sp.limit(h_u / (2 * sp.pi * R * sp.sin(sp.pi * F.v)), F.v, 0, "+")
    assert sp.simplify(limit("sine") - ku * kv * sp.cos(sp.pi * ku * F.u) / (2 * R)) == 0
    assert limit("sine").subs({F.u: 0}) != limit("sine").subs({F.u: sp.Rational(1, 2) / ku})
    assert limit("rings") == 0


@pytest.mark.parametrize("seed", range(4))
def test_the_pinch_claim_measures_the_rings_cone_point(seed, monkeypatch):
    """`lab.claims._rings_pinch` against the closed form, at random beta, k_v and colatitude phi: on
    the meridians theta = 0 and pi the rings field's h_v = 2 pi k_v cos(2 pi k_v v), v = phi / pi, tilts
    the draft's N + beta h_v e_phi away from the pole by atan(beta h_v) and the displaced sphere's
    N - beta h_v / (pi (R + beta h)) e_phi towards it by atan(beta h_v / (pi (R + beta h))), N itself
    being phi off the pole: the two sides' normals differ by 2 (tilt + phi) and 2 (tilt - phi)."""
    from lab import claims
    rng = np.random.default_rng(seed)
    beta, k_v, phi = rng.uniform(0.05, 0.9), rng.uniform(1.0, 12.0), 10.0 ** rng.uniform(-6, -2)
    scene = claims.DRAFT_SCENE.replace(beta=float(beta), k_v=float(k_v))
    monkeypatch.setattr(claims, "DRAFT_SCENE", scene)
    monkeypatch.setattr(claims, "PINCH_PHI", float(phi))
    v = phi / math.pi
    h, h_v = math.sin(2 * math.pi * k_v * v), 2 * math.pi * k_v * math.cos(2 * math.pi * k_v * v)
    chart = 2 * (math.atan(beta * h_v) + phi)
    surface = 2 * (math.atan(beta * h_v / (math.pi * (scene.radius_a + beta * h))) - phi)
    m = claims._rings_pinch()
    assert m["angle (degrees)"] == pytest.approx(math.degrees(chart), rel=1e-9, abs=0)
    assert m["displaced sphere's angle (degrees)"] == pytest.approx(math.degrees(surface), rel=1e-9, abs=0)
