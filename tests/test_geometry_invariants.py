"""Geometric invariants of rendered frames, checked against independent solves.

Hit points are rebuilt here from the pixel grid (written out below from the
seed's Cell 1 window) and the chamber map: t comes from the kernel's
`renderer.kernel.sphere_hit` for the spheres and is 1 for the floor, and t
itself is checked against an mpmath solve of the ray quadratic at 40 digits.
Then: every hit point lies on its surface, floor points have z == 0, normals
are unit vectors, the chamber is the nearest positive hit, nothing is NaN,
and the image lies in [0, 1].  The seed's sphere-B quadratic (constant term
|C_B|^2 - R_2^2, seed Cell 1) is shown to fail the on-surface invariant.

The G-buffer's own hit points on sphere A (`renderer.kernel.sphere_a_point`,
not E + t d) and its normals are checked against the exact hits (mpmath), at
these scenes and at the accepted extremes of the geometry (a sphere of the
least radius seen from the farthest camera, a camera one ulp outside the
sphere, the largest sphere, a sphere B as small and far).
"""

from __future__ import annotations

import dataclasses
import math

import mpmath
import numpy as np
import pytest

from renderer import GRADIENTS, PointLight, Scene, gbuffer, kernel, pointwise, render
from renderer import scene as S
from renderer.render import image_plane

from . import scalar_reference as ref

SIZE = 128
SURFACE_TOL = 1e-12        # relative to the radius
UNIT_TOL = 1e-12
# 40 digits: the float64 inputs are exact binary numbers, and the discriminant
# of a ray grazing a sphere loses at most ~16 of them to cancellation; 40 leaves
# more than 20 correct digits in t, far beyond the float64 error compared against.
MP_DPS = 40

SCENES = {
    "default": Scene(),
    "no sphere B": Scene(sphere_b=False),
    "no floor": Scene(floor=False),
    "bumpy sine, phong": Scene(height_field="sine", beta=1.5, model="phong", bump="chart"),
    "camera close, sphere B moved": Scene(camera_z=2.5, radius_a=0.8, center_b=(-0.6, 0.2, 0.9),
                                          radius_b=0.4),
    "sphere B through the floor": Scene(center_b=(0.9, -0.3, 0.2), radius_b=0.5,
                                        lights=(PointLight((3.0, -2.0, -4.0)),)),
    "displaced-surface normal": Scene(height_field="rings", beta=0.9, bump="surface"),
}


# --- independent pieces -----------------------------------------------------------------

def sphere_hit(X, Y, e, center, r):
    """`kernel.sphere_hit` (a scalar function) at each image-plane point of X, Y."""
    return np.array([kernel.sphere_hit(x, y, e, *map(float, center), r) for x, y in zip(np.ravel(X), np.ravel(Y))]
                    ).reshape(np.shape(X))

def pixel_grid(scene, width, height):
    """Image-plane (X, Y), shape (height, width): seed Cell 1's window."""
    e, R = scene.camera_z, scene.radius_a
    half = 1.25 * e * R / math.sqrt(e * e - R * R)
    x = half * (2.0 * (np.arange(width) + 0.5) / width - 1.0)
    y = half * (1.0 - 2.0 * (np.arange(height) + 0.5) / height) - 0.15 * half
    return np.meshgrid(x, y)


def hit_points(scene, X, Y, chamber):
    """(t, P) per pixel from the chamber map: t from the sphere hit, 1 on the floor."""
    e = scene.camera_z
    t = np.full(X.shape, np.nan)
    spheres = {1: ((0.0, 0.0, 0.0), scene.radius_a), 2: (scene.center_b, scene.radius_b)}
    for code, (C, r) in spheres.items():
        m = chamber == code
        if m.any():
            t[m] = sphere_hit(X[m], Y[m], e, C, r)
    t[chamber == 3] = 1.0
    P = np.stack([t * X, t * Y, e * (1.0 - t)], axis=-1)
    return t, P


def mp_nearest(scene, x, y, dps=MP_DPS):
    """(t, chamber, t_tol) of the nearest positive hit, by mpmath at ``dps`` digits.

    t_tol is the forward error bound of a float64 solve of the same ray:
    with a t^2 + 2 b t + c = 0, rounding b^2 and a c perturbs the discriminant
    D = b^2 - a c by about eps (b^2 + |a c|), which moves the root by that over
    2 a sqrt(D) (large for grazing rays, where D -> 0); the rest of the
    arithmetic adds a few eps t.  t_tol = 4 eps (t + (b^2 + |a c|) / (a sqrt D)),
    eps = 2^-52.  (Measured: float64 errors reach 0.56 of the bracket, 0.14 of t_tol.)
    """
    eps = 2.0**-52
    with mpmath.workdps(dps):
        x, y, e = mpmath.mpf(x), mpmath.mpf(y), mpmath.mpf(scene.camera_z)

        def sphere(C, r):
            ox, oy, oz = -mpmath.mpf(C[0]), -mpmath.mpf(C[1]), e - mpmath.mpf(C[2])
            a = x * x + y * y + e * e
            b = x * ox + y * oy - e * oz                   # half the linear coefficient
            c = ox * ox + oy * oy + oz * oz - mpmath.mpf(r) ** 2
            disc = b * b - a * c
            if disc < 0:
                return mpmath.inf, 0.0
            root = mpmath.sqrt(disc)
            for t in sorted(((-b - root) / a, (-b + root) / a)):
                if t > 0:
                    tol = 4 * eps * (t + (b * b + abs(a * c)) / (a * root))
                    return t, float(tol)
            return mpmath.inf, 0.0

        best = (mpmath.inf, 0, 0.0)
        cands = [(*sphere((0.0, 0.0, 0.0), scene.radius_a), 1)]
        if scene.sphere_b:
            cands.append((*sphere(scene.center_b, scene.radius_b), 2))
        if scene.floor:
            cands.append((mpmath.mpf(1), 0.0, 3))      # t = 1 exactly in both
        for t, tol, code in cands:
            if t < best[0]:
                best = (t, code, tol)
        return float(best[0]), best[1], best[2]


def sample_pixels(chamber, rng, n_random=300):
    """Every pixel next to a chamber boundary (where a wrong solve shows first),
    plus a random sample."""
    c = chamber
    edge = np.zeros(c.shape, dtype=bool)
    edge[:, 1:] |= c[:, 1:] != c[:, :-1]
    edge[:, :-1] |= c[:, 1:] != c[:, :-1]
    edge[1:, :] |= c[1:, :] != c[:-1, :]
    edge[:-1, :] |= c[1:, :] != c[:-1, :]
    pick = np.zeros(c.size, dtype=bool)
    pick[rng.choice(c.size, size=min(n_random, c.size), replace=False)] = True
    return np.argwhere(edge | pick.reshape(c.shape))


# --- the checks (each returns its evidence; the tests below assert on it) ----------------

def off_surface(P, C, r):
    """max | |P - C| - r | / r over points P (n, 3)."""
    if P.shape[0] == 0:
        return 0.0
    return float(np.abs(np.linalg.norm(P - np.asarray(C), axis=-1) - r).max() / r)


def off_unit(V):
    return float(np.abs(np.linalg.norm(V, axis=-1) - 1.0).max()) if V.shape[0] else 0.0


def chamber_mismatches(scene, X, Y, chamber, t, pixels):
    """[(j, i, ours, mp)] where the chamber or t disagrees with the mpmath solve."""
    bad = []
    for j, i in pixels:
        t_mp, code_mp, t_tol = mp_nearest(scene, X[j, i], Y[j, i])
        if code_mp != chamber[j, i]:
            bad.append((j, i, int(chamber[j, i]), code_mp))
        elif code_mp != 0 and not abs(t[j, i] - t_mp) <= t_tol:
            bad.append((j, i, float(t[j, i]), t_mp))
    return bad


def all_finite(*arrays):
    return all(bool(np.all(np.isfinite(a))) for a in arrays)


def in_unit_interval(image):
    return bool(np.all((image >= 0.0) & (image <= 1.0)))


# --- tests ------------------------------------------------------------------------------

@pytest.fixture(scope="module", params=sorted(SCENES))
def case(request):
    scene = SCENES[request.param]
    g = gbuffer(scene, SIZE, SIZE, gradient="exact")
    X, Y = pixel_grid(scene, SIZE, SIZE)
    t, P = hit_points(scene, X, Y, g.chamber)
    return scene, g, X, Y, t, P


def test_grid_and_hit_points_agree_with_gbuffer(case):
    scene, g, X, Y, t, P = case
    assert np.array_equal(g.x, X[0]) and np.array_equal(g.y, Y[:, 0])
    x, y = image_plane(scene.radius_a, scene.camera_z, SIZE, SIZE)
    assert np.array_equal(x, X[0]) and np.array_equal(y, Y[:, 0])
    hit = g.chamber > 0
    assert np.array_equal(g.t[hit], t[hit])
    # Off sphere A the G-buffer's P is E + t d, the same bits; on A it is
    # computed afresh (`test_sphere_a_hit_points_are_the_exact_hits`).
    off_a = hit & (g.chamber != 1)
    assert np.array_equal(g.P[off_a], P[off_a])


def test_sphere_a_hits_are_on_sphere_a(case):
    scene, g, X, Y, t, P = case
    a = g.chamber == 1
    assert a.sum() > 100
    assert off_surface(P[a], (0, 0, 0), scene.radius_a) <= SURFACE_TOL


def test_sphere_b_hits_are_on_sphere_b(case):
    scene, g, X, Y, t, P = case
    b = g.chamber == 2
    assert b.any() == scene.sphere_b
    assert off_surface(P[b], scene.center_b, scene.radius_b) <= SURFACE_TOL


def test_floor_points_are_on_the_plane(case):
    scene, g, X, Y, t, P = case
    f = g.chamber == 3
    assert f.any() == scene.floor
    # t = 1 exactly, so z = e (1 - 1) is exactly 0.
    assert np.all(P[f][:, 2] == 0.0) and np.all(g.P[f][:, 2] == 0.0)


def test_normals_are_unit(case):
    scene, g, X, Y, t, P = case
    hit = g.chamber > 0
    assert off_unit(g.N[hit]) <= UNIT_TOL
    assert off_unit(g.Ns[hit]) <= UNIT_TOL
    # The geometric normal is that of the G-buffer's hit point: (P - C) / r, or +z on the floor.
    for code, C, r in ((1, (0, 0, 0), scene.radius_a), (2, scene.center_b, scene.radius_b)):
        m = g.chamber == code
        if m.any():
            assert np.abs(g.N[m] - (g.P[m] - np.asarray(C)) / r).max() <= 1e-15 / r * 4
    assert np.all(g.N[g.chamber == 3] == (0.0, 0.0, 1.0))


def test_sphere_a_hit_points_are_the_exact_hits(case):
    scene, g, X, Y, t, P = case
    pixels = sample_pixels(g.chamber, np.random.default_rng(20261121))
    assert exact_hit_errors(scene, g, pixels)[1] <= HIT_TOL


def test_chamber_is_the_nearest_positive_hit(case):
    scene, g, X, Y, t, P = case
    pixels = sample_pixels(g.chamber, np.random.default_rng(20261121))
    assert len(pixels) > 300
    assert chamber_mismatches(scene, X, Y, g.chamber, t, pixels) == []


@pytest.mark.parametrize("gradient", GRADIENTS)
def test_no_nan_and_image_in_unit_interval(case, gradient):
    scene = case[0]
    frame = render(scene, SIZE, SIZE, gradient=gradient)
    g = gbuffer(scene, SIZE, SIZE, gradient=gradient)
    assert all_finite(frame.image, frame.grad, g.t[g.chamber > 0], g.P, g.N, g.Ns, g.uv, g.grad)
    assert in_unit_interval(frame.image)
    assert np.array_equal(frame.chamber, g.chamber)
    assert np.all(frame.image[frame.chamber == 0] == 0.0)


# --- the G-buffer's hit points and normals against the exact hits, to the accepted extremes ----

#: Allowed error of a hit point on sphere A, in units of u R (1 + R / h), and of
#: a normal of sphere B, in units of u (1 + (|E - C| + |P| + |C|) / r) (1 + r / h),
#: u = 2^-53 and h the ray's half chord, sqrt(D / a) for a t^2 + 2 b t + c = 0:
#: a rounding of the discriminant D moves the hit along the ray by about
#: u R^2 / h (R / h is the grazing ray's ill-condition), and sphere B's N carries
#: the rounding of E - C, P and C against its radius (`kernel.surface`).  4: the
#: few roundings of either route.
HIT_TOL = 4.0
U = 2.0**-53

#: Scenes at the limits of renderer/scene.py (R, e up to MAX_LENGTH, radii down to MIN_RADIUS).
EXTREME_SCENES = {
    "least sphere from the farthest camera": Scene(radius_a=S.MIN_RADIUS, camera_z=S.MAX_LENGTH, bump="chart"),
    "unit sphere from the farthest camera": Scene(radius_a=1.0, camera_z=S.MAX_LENGTH),
    "camera one ulp outside sphere A": Scene(radius_a=0.3, camera_z=math.nextafter(0.3, 1.0),
                                             center_b=(0.5, 0.5, 5.0), bump="chart"),
    "largest sphere A": Scene(radius_a=math.nextafter(S.MAX_LENGTH, 0.0), camera_z=S.MAX_LENGTH,
                              center_b=(0.0, 0.0, -S.MAX_LENGTH), radius_b=1.0),
    "least sphere B, far from all": Scene(radius_a=S.MIN_RADIUS, camera_z=S.MAX_LENGTH,
                                          center_b=(0.0, 0.0, 1e5), radius_b=S.MIN_RADIUS, bump="chart"),
}


def mp_sphere_hit(x, y, e, C, r, dps=80):
    """(P, N, h) of the nearest hit of the ray through (x, y) on the sphere (C, r),
    exactly (mpmath at ``dps`` digits, rounded to float64 at the end); None for a
    miss or a tangent ray.  80 digits: at e = 1e6, R = 1e-6 the discriminant
    cancels 24 of them, and a float64 answer needs 17 more."""
    with mpmath.workdps(dps):
        x, y, e, r = (mpmath.mpf(v) for v in (x, y, e, r))
        C = [mpmath.mpf(c) for c in C]
        d, oc = (x, y, -e), (-C[0], -C[1], e - C[2])
        a = sum(v * v for v in d)
        b = sum(p * q for p, q in zip(d, oc))
        D = b * b - a * (sum(v * v for v in oc) - r * r)
        if D <= 0:
            return None
        t = (-b - mpmath.sqrt(D)) / a
        rel = [oc[k] + t * d[k] for k in range(3)]               # P - C
        return (np.array([float(rel[k] + C[k]) for k in range(3)]), np.array([float(v / r) for v in rel]),
                float(mpmath.sqrt(D / a)))


def exact_hit_errors(scene, g, pixels):
    """Worst error, in units of `HIT_TOL`'s, of the G-buffer's hit points on sphere A
    and normals on sphere B over ``pixels`` (rows of (j, i)), and each normal's
    |  |N| - 1 |: (worst on A, worst on B, worst | |N| - 1 |)."""
    e, worst = scene.camera_z, {1: 0.0, 2: 0.0}
    for j, i in pixels:
        code = int(g.chamber[j, i])
        if code not in worst:
            continue
        C, r = ((0.0, 0.0, 0.0), scene.radius_a) if code == 1 else (scene.center_b, scene.radius_b)
        exact = mp_sphere_hit(g.x[i], g.y[j], e, C, r)
        if exact is None:
            continue
        P, N, h = exact
        if code == 1:
            error = np.abs(g.P[j, i] - P).max() / (U * r * (1 + r / h))
        else:
            size = math.dist((0.0, 0.0, e), C) + np.abs(P).max() + np.abs(C).max()
            error = np.abs(g.N[j, i] - N).max() / (U * (1 + size / r) * (1 + r / h))
        worst[code] = max(worst[code], float(error))
    hit = g.chamber[tuple(np.transpose(pixels))] > 0
    return worst[1], worst[2], off_unit(g.N[tuple(np.transpose(pixels))][hit])


@pytest.mark.parametrize("zoom", [1.0, 1e3])
@pytest.mark.parametrize("name", sorted(EXTREME_SCENES))
def test_hit_points_and_normals_are_exact_at_the_accepted_extremes(name, zoom):
    """The tester's case first: at R = 1e-6, e = 1e6, N = P / R was not unit while
    P_z = e (1 - t) cancelled to an error of u e against R."""
    scene = EXTREME_SCENES[name]
    g = gbuffer(scene, 24, 24, zoom=zoom)
    pixels = np.argwhere(g.chamber > 0)
    error_a, error_b, unit = exact_hit_errors(scene, g, pixels)
    assert error_a <= HIT_TOL and error_b <= HIT_TOL and unit <= UNIT_TOL, (error_a, error_b, unit)
    assert np.count_nonzero(np.isin(g.chamber, (1, 2))) > 250         # half the frame or more


def test_the_exact_hit_check_rejects_the_hit_point_from_t():
    """Teeth: P = (t x, t y, e (1 - t)) from `kernel.sphere_hit` and N = P / R (the
    kernel before), and the same with N renormalised (unit, but the point is still
    off by u e): both are rejected at the tester's scene; the kernel's passes."""
    scene = EXTREME_SCENES["least sphere from the farthest camera"]
    g = gbuffer(scene, 24, 24)
    X, Y = pixel_grid(scene, 24, 24)
    t, P = hit_points(scene, X, Y, g.chamber)
    pixels = np.argwhere(g.chamber == 1)
    for N in (P / scene.radius_a, P / np.linalg.norm(P, axis=-1, keepdims=True)):
        wrong = dataclasses.replace(g, P=P, N=N)
        assert exact_hit_errors(scene, wrong, pixels)[0] > 1e6 * HIT_TOL
    assert off_unit((P / scene.radius_a)[g.chamber == 1]) > 1e6 * UNIT_TOL
    assert exact_hit_errors(scene, g, pixels)[0] <= HIT_TOL


# --- the seed's sphere-B quadratic, and teeth for each check -----------------------------

def seed_sphere_b(scene, X, Y):
    """t of the seed's Cell 1 sphere-B hit (c = |C_B|^2 - R_2^2, taken as written)."""
    e, C, r = scene.camera_z, np.asarray(scene.center_b), scene.radius_b
    a = X * X + Y * Y + e * e
    b_half = -C[0] * X - C[1] * Y - (e - C[2]) * e
    disc = b_half * b_half - a * (C @ C - r * r)
    with np.errstate(invalid="ignore"):
        return np.where(disc >= 0.0, (-b_half - np.sqrt(disc)) / a, np.inf)


def seed_chamber(scene, X, Y):
    """The seed's chamber: tm = min(tA, tB, 1), first of A, B, floor to equal it."""
    e, R = scene.camera_z, scene.radius_a
    a = X * X + Y * Y + e * e
    disc_a = e * e * R * R - (e * e - R * R) * (X * X + Y * Y)
    with np.errstate(invalid="ignore"):
        tA = np.where(disc_a >= 0.0, (e * e - np.sqrt(disc_a)) / a, np.inf)
    tB = seed_sphere_b(scene, X, Y)
    tm = np.minimum(np.minimum(tA, tB), 1.0)
    return np.where(tm == tA, 1, np.where(tm == tB, 2, 3)).astype(np.uint8), tB


def test_seed_sphere_b_points_are_off_the_sphere():
    """Measured at 128^2: the seed's 'hit points' sit up to 2.07 units (6.5 R_2) off sphere B."""
    scene = Scene()
    X, Y = pixel_grid(scene, SIZE, SIZE)
    tB = seed_sphere_b(scene, X, Y)
    hit = np.isfinite(tB)
    P = np.stack([tB * X, tB * Y, scene.camera_z * (1.0 - tB)], axis=-1)[hit]
    err = off_surface(P, scene.center_b, scene.radius_b)
    assert err > 1e10 * SURFACE_TOL          # rejected, by ten orders of magnitude
    assert 6.0 < err < 7.0                   # 2.07 / 0.32 = 6.46 radii (measured)


def test_seed_sphere_b_flips_the_chamber_of_most_of_the_frame():
    """At the seed's own 256^2 the seed's sphere B covers every pixel; the corrected
    sphere covers 6635, so 58901 of 65536 pixels change chamber (measured)."""
    scene, n = Scene(), 256
    X, Y = pixel_grid(scene, n, n)
    seed, _ = seed_chamber(scene, X, Y)
    ours = render(scene, n, n).chamber
    flips = int(np.count_nonzero(seed != ours))
    assert np.all(seed == 2)
    assert int(np.count_nonzero(ours == 2)) == 6635
    assert flips == 58901


def test_seed_sphere_b_is_a_larger_sphere_about_the_same_centre():
    """Why the seed's B covers the frame: c = |C|^2 - r^2 is the constant term of the
    sphere about C_B with r'^2 = |E - C_B|^2 - |C_B|^2 + r^2, i.e. r' = 2.39, not 0.32."""
    scene = Scene()
    X, Y = pixel_grid(scene, 64, 64)
    C, e, r = np.asarray(scene.center_b), scene.camera_z, scene.radius_b
    r_seed = math.sqrt(float((C - (0, 0, e)) @ (C - (0, 0, e)) - C @ C + r * r))
    assert 2.38 < r_seed < 2.39
    t_seed = seed_sphere_b(scene, X, Y)
    t_big = sphere_hit(X, Y, e, scene.center_b, r_seed)
    assert np.abs(t_seed - t_big).max() <= 1e-14


def test_chamber_check_rejects_the_seeds_chamber():
    scene = Scene()
    X, Y = pixel_grid(scene, SIZE, SIZE)
    code, tB = seed_chamber(scene, X, Y)
    t = np.where(code == 2, tB, np.nan)
    pixels = sample_pixels(code, np.random.default_rng(1), n_random=50)
    assert len(chamber_mismatches(scene, X, Y, code, t, pixels)) > 40


def test_t_check_rejects_the_far_root():
    """Right chamber, wrong root: the far intersection of sphere A fails the t comparison."""
    scene = Scene(sphere_b=False, floor=False)
    g = gbuffer(scene, 32, 32)
    X, Y = pixel_grid(scene, 32, 32)
    e, R = scene.camera_z, scene.radius_a
    a = X * X + Y * Y + e * e
    disc = e * e * R * R - (e * e - R * R) * (X * X + Y * Y)
    with np.errstate(invalid="ignore"):
        far = np.where(g.chamber == 1, (e * e + np.sqrt(disc)) / a, np.nan)
    # Twenty pixels nearest the middle of sphere A's disc (rays far from grazing).
    order = np.argsort(np.where(g.chamber == 1, X * X + (Y - Y[g.chamber == 1].mean()) ** 2,
                                np.inf), axis=None)
    pixels = np.column_stack(np.unravel_index(order[:20], X.shape))
    assert len(chamber_mismatches(scene, X, Y, g.chamber, far, pixels)) == 20
    assert chamber_mismatches(scene, X, Y, g.chamber, g.t, pixels) == []


def test_unit_check_rejects_the_unnormalized_perturbed_normal():
    scene = Scene(beta=0.35)
    g = gbuffer(scene, 64, 64)
    a = g.chamber == 1
    N, (hu, hv) = g.N[a], g.grad[a].T
    _, _, sin_phi = pointwise.chart(N[:, 0], N[:, 1], N[:, 2])
    e_th, e_ph = (np.stack(e, -1) for e in pointwise.tangent_frame(N[:, 0], N[:, 1], N[:, 2], sin_phi))
    # The seed's M = N + beta (h_u e_theta + h_v e_phi) before N' = M / |M| (tests/scalar_reference.py).
    M = np.array([ref.chart_bump_vector(tuple(n), tuple(t), tuple(p), gu, gv, scene.beta)
                  for n, t, p, gu, gv in zip(N, e_th, e_ph, hu, hv)])
    assert off_unit(M) > 1e-2
    assert off_unit(M / np.linalg.norm(M, axis=-1, keepdims=True)) <= UNIT_TOL


def test_surface_check_rejects_a_point_one_part_in_1e11_off():
    P = np.array([[0.6, 0.0, 0.8]]) * (1.0 + 1e-11)
    assert off_surface(P, (0, 0, 0), 1.0) > SURFACE_TOL
    assert off_surface(np.array([[0.6, 0.0, 0.8]]), (0, 0, 0), 1.0) <= SURFACE_TOL


def test_finite_and_range_checks_reject_bad_values():
    """Each helper on its own (``all_finite`` is the only check on the buffers without a range), and
    ``all_finite`` on every array it is given, not only the first."""
    image = np.full((4, 4, 3), 0.5)
    assert all_finite(image) and in_unit_interval(image)
    for bad in (np.nan, np.inf, -np.inf, 1.0 + 2**-52, -1e-300):
        wrong = image.copy()
        wrong[2, 1, 0] = bad
        assert all_finite(wrong) == all_finite(image, wrong) == math.isfinite(bad)
        assert not in_unit_interval(wrong)


# --- valid scenes outside the seed's range -------------------------------------------------

@pytest.mark.parametrize("camera_z", [1e3, S.MAX_LENGTH])
def test_chamber_is_the_nearest_positive_hit_for_a_distant_camera(camera_z):
    """A distant camera, up to the farthest Scene accepts, renders the right chamber.  The window
    is scaled to sphere A's silhouette, so A fills the same disc at any
    distance.  The discriminant b^2 - a c of the ray quadratic is a difference
    of two numbers of size e^4 whose true value is of size e^2 R^2, so it
    cancels once e^2 >> 1 / eps_machine (pbrt-v4 and Ray Tracing Gems ch. 7
    use the cancellation-free form r^2 - |o - (o.d) d|^2 for this reason)."""
    scene = Scene(camera_z=camera_z, sphere_b=False)
    n = 48
    frame = render(scene, n, n)
    X, Y = pixel_grid(scene, n, n)
    # The mpmath discriminant cancels the same ~4 log10(e) digits; 40 + 40 keeps 40.
    wrong = [(j, i) for j in range(n) for i in range(n)
             if mp_nearest(scene, X[j, i], Y[j, i], dps=80)[1] != frame.chamber[j, i]]
    assert wrong == [], f"{len(wrong)} of {n * n} pixels have the wrong chamber: {wrong[:4]}"


@pytest.mark.parametrize("kwargs", [
    dict(beta=S.MAX_BETA, bump="chart"), dict(beta=0.999, bump="surface"),
    dict(k_u=S.MAX_FREQUENCY, height_field="sine"),
    dict(beta=S.MAX_BETA, bump="chart", k_u=S.MAX_FREQUENCY, k_v=S.MAX_FREQUENCY, height_field="sine"),
], ids=["largest beta", "surface beta near R", "largest k_u", "both"])
def test_perturbed_normal_is_unit_for_the_largest_inputs_scene_accepts(kwargs):
    """N' = M / |M| stays a unit vector at the largest beta and frequencies (the limit
    beta -> inf is the direction of the gradient); |M|^2 does not overflow."""
    g = gbuffer(Scene(**kwargs), 32, 32)
    err = off_unit(g.Ns[g.chamber == 1])
    assert err <= UNIT_TOL, f"| |N'| - 1 | reaches {err}"


@pytest.mark.parametrize("kwargs, field", [
    (dict(beta=1e200), "beta"), (dict(k_u=1e200), "k_u"), (dict(beta=1e6), "beta"),
    (dict(k_u=1e6, height_field="sine"), "k_u"), (dict(camera_z=1e9), "camera_z"),
])
def test_inputs_past_the_limits_are_refused_naming_the_field(kwargs, field):
    with pytest.raises(ValueError, match=f"^Scene.{field} "):
        Scene(**kwargs)


# --- the kernel's reach predicate, as pointwise.reach exposes it ---------------------------

@pytest.mark.parametrize("scene", [Scene(beta=0.0), Scene(beta=0.0, height_field="sine", sphere_b=False),
                                   Scene(beta=0.0, lights=(PointLight((0.5, -1.0, -6.0)), PointLight((3.0, 2.0, 5.0))))],
                         ids=["default", "no sphere B", "a light below the floor"])
def test_reach_masks_are_where_a_lone_diffuse_light_lights_the_image(scene):
    """With one light, no ambient and no lobe, at beta = 0 (Ns = N), a pixel is
    lit exactly where `pointwise.reach` says the light reaches it."""
    g = gbuffer(scene, 64, 48)
    masks = pointwise.reach(scene, g)
    assert masks.shape == (len(scene.lights), 48, 64) and masks.any()
    for k, light in enumerate(scene.lights):
        alone = scene.replace(lights=(light,), ka=0.0, ks=0.0)
        lit = render(alone, 64, 48).image.max(axis=-1) > 0
        assert np.array_equal(lit, masks[k])
    # The check has teeth: the mask of the other light does not match.
    if len(scene.lights) > 1:
        lone = render(scene.replace(lights=scene.lights[:1], ka=0.0, ks=0.0), 64, 48).image.max(axis=-1) > 0
        assert not np.array_equal(lone, masks[1])


def test_reach_gate_adds_the_shading_normal_and_bad_arguments_are_named():
    scene = Scene(beta=1.5, height_field="sine", bump="chart")
    g = gbuffer(scene, 64, 48)
    plain, gated = pointwise.reach(scene, g), pointwise.reach(scene, g, gate=True)
    assert np.all(gated <= plain) and np.count_nonzero(plain & ~gated) > 0
    with pytest.raises(TypeError, match="^scene must be a renderer.Scene, got object$"):
        pointwise.reach(object(), g)
    with pytest.raises(TypeError, match="^gbuffer must be a renderer.GBuffer, got Frame$"):
        pointwise.reach(scene, render(scene, 8, 8))
    with pytest.raises(TypeError, match="^gate must be True or False, got int 1$"):
        pointwise.reach(scene, g, gate=1)


def test_reach_keeps_a_light_of_zero_colour_in_its_place():
    """One mask per light of the scene, in order, those of zero colour included (the kernel leaves
    them out of shading, where they add exactly 0): the dark light's mask is the one it would have
    with a colour."""
    dark, lit = PointLight((3.0, 2.0, 5.0), (0.0, 0.0, 0.0)), PointLight((3.0, 2.0, 5.0))
    scene = Scene(beta=0.0)
    g = gbuffer(scene, 32, 24)
    masks = pointwise.reach(scene.replace(lights=(*scene.lights[:1], dark, *scene.lights[1:])), g)
    assert masks.shape == (len(scene.lights) + 1, 24, 32)
    assert np.array_equal(masks[1], pointwise.reach(scene.replace(lights=(lit,)), g)[0]) and masks[1].any()


@pytest.mark.parametrize("width, height", [(64, 64), (96, 48), (40, 120)])
def test_sphere_a_fills_the_seeds_window_where_cell_1_puts_it(width, height):
    """Seed Cell 1's window: sphere A's silhouette (radius r = eR / sqrt(e^2 - R^2) on z = 0) is
    0.8 of the half-width (half = 1.25 r), centred across, and the window is shifted down by
    0.15 half, so the disk spans the pixel centres 0.1..0.9 across and 0.025..0.825 down.  A
    wrong vertical offset, sign or scale moves those rows, whatever the pixel count does."""
    scene = Scene(sphere_b=False, floor=False)
    rows, cols = np.nonzero(gbuffer(scene, width, height).chamber == 1)
    inside = lambda n, lo, hi: np.flatnonzero((lo * n < np.arange(n) + 0.5) & (np.arange(n) + 0.5 < hi * n))  # noqa: E731
    assert np.array_equal(np.unique(rows), inside(height, 0.025, 0.825))
    assert np.array_equal(np.unique(cols), inside(width, 0.1, 0.9))


@pytest.mark.parametrize("field", ["P", "N", "Ns", "chamber"])
def test_reach_refuses_a_gbuffer_whose_arrays_are_of_another_frame(field):
    """The compiled loop indexes P, N, Ns by chamber's shape: arrays of another size were read
    past their end, and the masks came back wrong without a word."""
    scene = Scene()
    small, big = gbuffer(scene, 8, 8), gbuffer(scene, 16, 12)
    mixed = dataclasses.replace(big, **{field: getattr(small, field)})
    with pytest.raises(ValueError, match=r"^gbuffer\.\w+ has shape \(8, 8, 3\), gbuffer\.chamber \(12, 16\): "
                                         r"the arrays must be one frame's, \(12, 16, 3\)$"
                                         if field != "chamber" else r"^gbuffer\.P has shape \(12, 16, 3\), "
                                                                     r"gbuffer\.chamber \(8, 8\)"):
        pointwise.reach(scene, mixed)
    with pytest.raises(ValueError, match=r"^gbuffer\.chamber must be an \(H, W\) array, got shape \(12, 16, 3\)"):
        pointwise.reach(scene, dataclasses.replace(big, chamber=big.P))


def test_no_pixel_is_a_negative_zero():
    """A -0.0 albedo or ambient term (accepted: it is zero) gave -0.0 pixels, which print as -0."""
    from renderer import sweep
    scene = Scene(albedo_a=(-0.0, 0.5, 0.5), ambient=(-0.0, 0.1, 0.1), albedo_b=(-0.0, 0.2, 0.2))
    s = sweep(scene, (1e-3,), 16, 16)
    for image in (render(scene, 32, 32).image, render(scene, 32, 32, gradient="central").image,
                  s.numeric[0].image, s.symbolic.image):
        assert not np.signbit(image).any()


@pytest.mark.parametrize("value", [0.3 + 0j, np.array([0.3, 0.4 + 1e-3j]), [0.3, 1j]])
def test_pointwise_refuses_complex_numbers_naming_the_argument(value):
    """numpy would drop the imaginary part with a ComplexWarning and compute on the rest."""
    with pytest.raises(TypeError, match=r"^u must be real numbers"):
        pointwise.height("sine", value, 0.4, 8, 4)
