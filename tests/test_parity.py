"""Parity: `renderer.render` against the scalar oracle `scalar_reference`.

Every height field x both models x the three pipelines (exact, central,
footprint) x sphere B on/off x floor on/off x beta in {0, 0.35, 1.5}, on
three small frames chosen for what they hit:

* 24 x 20: even width, non-square;
* 17 x 13: odd width (column 8 lies on x = 0), odd height;
* 17 x 20: x = 0 at column 8 and y = 3.6e-17 at row 8, so pixel (8, 8) lands on
  sphere A's pole: sin(phi) = 4e-17, the frame fallback and the one-sided v
  difference (v = 1.3e-17 < eps) are exercised.

Each frame is rendered by every backend of `renderer.render`: the numba
kernel, the array kernel on numpy (everywhere) and on Dr.Jit's LLVM backend
(where the system's libLLVM is; skipped without it, failed when CI=true).
Dr.Jit runs the program numpy runs, with its own sin, cos and atan2, so it
is checked on a subset that still covers every field, model, pipeline and
scene variant (see `with_backends`' callers): each new scene is a new compiled kernel
(a fifth of a second), which the whole matrix would pay some 700 times.

Checks per frame: identical chamber codes, identical crease flags,
|dI| <= 1e-12 per channel (the issue's tolerance), and the gradient within the
tolerance of `grad_tolerance` (justified there).  The footprint pipeline's
step is computed by both routes from the pixel's geometry, so its gradient
carries the step's rounding too: `footprint_bound` bounds that, and the
image tolerance of that pipeline grows by what the gradient tolerance can
move the reference's own shading (`footprint_allowances`).  The only
exemption is a ray tangent to a sphere (`grazing_mask`: at most two pixels,
checked at 1e-6).  Each kind of check is shown to reject a wrong variant at
the end of the file.
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np
import pytest

from renderer import PointLight, Scene, backends, render
from tests import scalar_reference as ref
from tests.jsnode import in_ci

pytestmark = pytest.mark.cpu_dependent     # make test-baseline-simd runs the file again

SIZES = ((24, 20), (17, 13), (17, 20))
IMAGE_TOL = 1e-12          # per channel, required by the issue
FIELDS = ("sine", "ridges", "rings")
MODELS = ("blinn", "phong")
GRADIENTS = ("exact", "central", "footprint")
LIGHT_2 = PointLight((-6.0, 2.0, 8.0), (0.9, 0.65, 0.25))     # the seed's second light
U = 2.0**-53               # unit roundoff


def lipschitz(scene):
    """Bound on |h_u| and |h_v| of every field: pi max(k_u, 2 k_v)."""
    return math.pi * max(scene.k_u, 2.0 * scene.k_v)


def grad_tolerance(scene, gradient, grad_ref, steps=None, delta=None):
    """Allowed |grad_renderer - grad_reference|, per component.

    Both routes evaluate the same closed forms, so 1e-12 (1 + |g|) covers
    rounding for the exact pipeline (measured worst on these frames: 4.7e-14 relative).

    The central pipeline needs an absolute slack on top.  The two routes
    compute the chart (u, v) of a hit point differently (textbook vs
    cancellation-free quadratic for t, and their own atan2/hypot sequences),
    and the results differ by a few ulp.  The common shift cancels in
    h(u + eps) - h(u - eps), but u + eps and u - eps are each rounded
    afresh, so the two samples can sit up to 2^-52 apart per side.  h is
    Lipschitz with constant LIP = pi max(k_u, 2 k_v) in each chart variable,
    so the quotient can move by 2 LIP 2^-52 / (2 eps) = LIP 2^-52 / eps
    (5.6e-12 at the defaults).

    The footprint pipeline is the central one with steps ``steps`` (H, W, 2),
    the reference's, per component; the renderer's own steps differ from
    them by at most the relative ``delta`` (H, W, 2) of `footprint_bound`.
    With g(eps) = (h(u + eps) - h(u - eps)) / (2 eps),
    eps g'(eps) = (h'(u + eps) + h'(u - eps)) / 2 - g, at most 2 LIP in size
    (also for the one-sided quotient at the v border), so a relative change
    delta of the step moves the quotient by at most 2 LIP delta.
    """
    tol = 1e-12 * (1.0 + np.abs(grad_ref))
    lip = lipschitz(scene)
    if gradient == "central":
        tol = tol + lip * 2.0**-52 / scene.eps
    elif gradient == "footprint":
        tol = tol + lip * 2.0**-52 / steps + 2.0 * lip * delta
    return tol


# Tangent rays.  A ray that touches a sphere has discriminant D = 0, and where
# D is within rounding of 0 the root t is determined only to about
# sqrt(eps_machine): two correct implementations that round D differently then
# disagree at 1e-8, not 1e-12.  The 17 x 20 frame has two such pixels by
# construction, (0, 8) and (16, 8): x = 0 and y = +-0.8 half = +-e R / sqrt(e^2 - R^2),
# sphere A's silhouette radius.
GRAZING_REL_T = 1e-12      # eps * condition number of t above which a hit counts as tangent;
                           # measured <= 8e-14 on every other pixel of these frames
MAX_GRAZING = 2            # per frame: the exemption cannot swallow a silhouette
GRAZING_TOL = 1e-6         # |dI| still bounded there, and the chart point within this
                           # distance; h's gradient then moves by at most its second
                           # derivative bound (pi max(k_u, 2 k_v))^2 times that.


def hit_condition(scene, x, y, C, r):
    """Condition number kappa of the nearest root t of the ray through (x, y) on a sphere.

    For a t^2 + 2 b t + c = 0 a relative error eps in b^2 and a c moves D by
    eps (b^2 + |a c|) and t by that over 2 a sqrt(D); relative to t this is
    eps * kappa with kappa = (b^2 + |a c|) / (a sqrt(D) t).  inf if D <= 0.
    """
    e = scene.camera_z
    d, oc = (x, y, -e), ref.sub((0.0, 0.0, e), C)
    a, b, c = ref.dot(d, d), ref.dot(d, oc), ref.dot(oc, oc) - r * r
    D = b * b - a * c
    if D <= 0.0:
        return math.inf
    t = (-b - math.sqrt(D)) / a
    return (b * b + abs(a * c)) / (a * math.sqrt(D) * t)


def grazing_mask(scene, width, height, chamber):
    """Pixels whose sphere hit is ill-conditioned by input rounding alone."""
    mask = np.zeros(chamber.shape, dtype=bool)
    spheres = {ref.SPHERE_A: ((0.0, 0.0, 0.0), scene.radius_a),
               ref.SPHERE_B: (scene.center_b, scene.radius_b)}
    for j, i in zip(*np.nonzero(np.isin(chamber, list(spheres)))):
        x, y = ref.pixel_point(scene, i, j, width, height)
        mask[j, i] = 2.0**-52 * hit_condition(scene, x, y, *spheres[int(chamber[j, i])]) > GRAZING_REL_T
    return mask


def _norm(a):
    return math.sqrt(ref.dot(a, a))


def footprint_bound(scene, i, j, width, height):
    """(steps, delta): the reference's footprint steps (eps_u, eps_v) at a
    sphere-A pixel, and bounds on |eps_renderer - eps_reference| / eps.

    The step is (|a_x| + |a_y|) / (2 L) with a_k = e . dp_k, where dp_k =
    E + t_k d_k - P is the k-th neighbour's ray d_k on the tangent plane at P
    (t_k = N . (P - E) / N . d_k), e = e_theta and L = |dP/du| = 2 pi R sin(phi)
    for u, e = e_phi and L = |dP/dv| = pi R for v (`scalar_reference.chart_tangents`).
    The two routes differ in

    * the hit point: P, and N = P / R, agree to dP = 4 u (1 + kappa) |P - E|
      + 4 u |P| (kappa the condition of the hit, `hit_condition`), dN = dP / R
      + 2 u;
    * the neighbour's centre (x + dx against x_{i+1}): dd = 2 u (|x_k| + |y_k|);
    * their own roundings: dp_k is a difference of terms of size
      A_k = |E| + |t_k| |d_k| + |P|, and t_k a quotient of two dot products
      of conditions kappa_k = |d_k| / |N . d_k| + |P - E| / |N . (P - E)|.

    First order, from the derivatives of dp_k in P, N and d_k:
    |d dp_k| <= 4 u (A_k + |t_k| |d_k| kappa_k) + s_k dP
    + |d_k| (|P - E| + |t_k| |d_k|) / |N . d_k| dN + |t_k| s_k dd,
    s_k = 1 + |d_k| / |N . d_k|; the frame (e over sin(phi)) and L (u only)
    add 2 (dN + u) / sin(phi) relatively.  Then delta = 4 (sum_k |d a_k| /
    sum_k |a_k| + frame terms + u): 4 covers the few roundings each step
    takes in either route.  A step both routes cap at 0.25 (its uncapped
    value shrunk by delta still above) has delta = 0; inf where the routes
    may take different frames (sin(phi) within rounding of the pole cut-off).
    """
    e, R = scene.camera_z, scene.radius_a
    x, y = ref.pixel_point(scene, i, j, width, height)
    t, _ = ref.nearest_hit(x, y, scene)
    P = ref.ray_point(t, x, y, e)
    N = ref.scale(1.0 / R, P)
    _, _, sin_phi = ref.chart_a(N)
    e_th, e_ph = ref.tangent_frame_a(N, sin_phi)
    neighbours = ref.footprint_neighbours(scene, i, j, width, height)
    steps = ref.footprint_steps(scene, P, N, e_th, e_ph, sin_phi, *neighbours)
    PE = ref.sub(P, (0.0, 0.0, e))
    dP = 4 * U * (1.0 + hit_condition(scene, x, y, (0.0, 0.0, 0.0), R)) * _norm(PE) + 4 * U * _norm(P)
    dN = dP / R + 2 * U
    errors, offsets = [], []
    for xk, yk in neighbours:
        d = (xk, yk, -e)
        nd, dk = abs(ref.dot(N, d)), _norm(d)
        tk = abs(ref.dot(N, PE) / ref.dot(N, d))
        kappa = dk / nd + _norm(PE) / abs(ref.dot(N, PE))
        slope = 1.0 + dk / nd
        errors.append(4 * U * (e + tk * dk + _norm(P) + tk * dk * kappa) + slope * dP
                      + dk * (_norm(PE) + tk * dk) / nd * dN + tk * slope * 2 * U * (abs(xk) + abs(yk)))
        offsets.append(ref.tangent_plane_offset(scene, P, N, xk, yk))
    near_cut = abs(sin_phi - ref.POLE_SIN_PHI) <= 4 * (dN + U)
    regular = sin_phi > ref.POLE_SIN_PHI
    frame = 2 * (dN + U) / sin_phi if regular else 0.0
    dpdu, dpdv = ref.chart_tangents(R, sin_phi, e_th, e_ph)
    delta = []
    for axis, (vec, L, extra) in enumerate(((e_th, _norm(dpdu), frame), (e_ph, _norm(dpdv), 0.0))):
        a = sum(abs(ref.dot(vec, dp)) for dp in offsets)
        change = sum(errors) + frame * sum(_norm(dp) for dp in offsets)
        bound = 4 * (change / a + frame + extra + U) if a > 0 else math.inf
        uncapped = a / (2 * L) if L > 0 else math.inf
        if near_cut:
            bound = math.inf
        elif uncapped * (1 - bound) > ref.FOOTPRINT_MAX:
            bound = 0.0                     # both routes take the cap
        delta.append(bound)
    return steps, tuple(delta)


#: Above this relative step bound a pixel's footprint is too ill-conditioned to
#: compare (a ray grazing the tangent plane); as many as tangent pixels may be.
WIDE_DELTA = 1e-6


def footprint_allowances(scene, width, height, chamber, grad_ref):
    """(grad tolerance, extra image tolerance, pixels with delta > WIDE_DELTA) of the footprint pipeline.

    The image allowance is how far the reference's own shading of the pixel
    moves when its gradient moves by the gradient tolerance (the largest
    change over the four corners of the tolerance box, first order).  Where
    delta > WIDE_DELTA the step may be anything the cap and the fallback
    allow, and first order bounds nothing: the image is not compared there
    (no more than MAX_GRAZING such pixels, `parity_failures`).
    """
    steps, delta = np.ones(grad_ref.shape), np.zeros(grad_ref.shape)
    extra = np.zeros(chamber.shape)
    on_a = np.argwhere(chamber == ref.SPHERE_A)
    for j, i in on_a:
        steps[j, i], delta[j, i] = footprint_bound(scene, i, j, width, height)
    tol = grad_tolerance(scene, "footprint", grad_ref, steps, delta)
    for j, i in on_a:
        if not np.all(np.isfinite(tol[j, i])) or np.any(delta[j, i] > WIDE_DELTA):
            extra[j, i] = math.inf
            continue
        x, y = ref.pixel_point(scene, i, j, width, height)
        P = ref.ray_point(ref.nearest_hit(x, y, scene)[0], x, y, scene.camera_z)
        N = ref.scale(1.0 / scene.radius_a, P)
        u, v, sin_phi = ref.chart_a(N)
        e_th, e_ph = ref.tangent_frame_a(N, sin_phi)
        colour = lambda g: np.array(ref.sphere_a_colour(scene, P, N, e_th, e_ph, sin_phi, u, v, *g))  # noqa: E731
        base = colour(grad_ref[j, i])
        extra[j, i] = max(float(np.abs(colour(grad_ref[j, i] + np.array(s) * tol[j, i]) - base).max())
                          for s in itertools.product((-1.0, 1.0), repeat=2))
    return tol, extra, int(np.count_nonzero((delta > WIDE_DELTA).any(axis=-1)))


def parity_failures(scene, width, height, gradient, *, frame=None, backend="numba", reference=None):
    """Compare one render (``frame``, else rendered by ``backend``) with the reference
    (``reference``, else `scalar_reference.render_reference`'s); return a list of failure
    strings (empty: parity)."""
    if frame is None:
        frame = render(scene, width, height, gradient=gradient, backend=backend)
    image, chamber, kink, grad = reference or ref.render_reference(scene, width, height, gradient=gradient)
    failures = []
    n = int(np.count_nonzero(frame.chamber != chamber))
    if n:
        failures.append(f"chamber differs at {n} pixels")
    n = int(np.count_nonzero(frame.kink != kink))
    if n:
        failures.append(f"kink differs at {n} pixels")
    tangent = grazing_mask(scene, width, height, chamber)
    if np.count_nonzero(tangent) > MAX_GRAZING:
        failures.append(f"{np.count_nonzero(tangent)} tangent pixels > {MAX_GRAZING}")
    if gradient == "footprint":
        tol, extra, wide = footprint_allowances(scene, width, height, chamber, grad)
        if wide > MAX_GRAZING:
            failures.append(f"{wide} pixels with an ill-conditioned footprint > {MAX_GRAZING}")
    else:
        tol, extra = grad_tolerance(scene, gradient, grad), np.zeros(chamber.shape)
    d_image = np.abs(frame.image - image).max(axis=-1)
    excess = (np.abs(frame.grad - grad) - tol).max(axis=-1)
    lip = lipschitz(scene)
    for where, image_tol, what in ((~tangent, IMAGE_TOL, ""), (tangent, GRAZING_TOL, " (tangent)")):
        if not where.any():
            continue
        worst = float((d_image - extra)[where].max())
        if not worst <= image_tol:                       # also catches NaN
            failures.append(f"max |dI|{what} beyond the allowance = {worst:.3e} > {image_tol}")
        worst = float(excess[where].max())
        if not worst <= (0.0 if what == "" else GRAZING_TOL * lip * lip):
            failures.append(f"grad{what} differs beyond tolerance by up to {worst:.3e}")
    return failures


# --- the full matrix --------------------------------------------------------------------

BACKENDS = ("numba", "numpy", "drjit")


def with_backends(cases, drjit_subset):
    """``cases`` (tuples) each with every backend appended; "drjit" only where ``drjit_subset(case)``."""
    return [case + (b,) for case in cases for b in BACKENDS if b != "drjit" or drjit_subset(case)]


def require_backend(backend):
    """Skip a Dr.Jit case where its LLVM backend is missing, and fail it when CI=true."""
    why = backends.missing(backend)
    if why is not None:
        if in_ci():
            pytest.fail(why + " (CI=true: this test may not skip)")
        pytest.skip(why)


@functools.lru_cache(maxsize=32)
def cached_reference(scene, width, height, gradient):
    """`scalar_reference.render_reference`, computed once for the backends of one case."""
    return ref.render_reference(scene, width, height, gradient=gradient)


def assert_parity(scene, gradient, backend):
    require_backend(backend)
    for width, height in SIZES:
        reference = cached_reference(scene, width, height, gradient)
        assert parity_failures(scene, width, height, gradient, backend=backend, reference=reference) == [], \
            (width, height)


MATRIX = list(itertools.product(FIELDS, MODELS, GRADIENTS, (True, False), (True, False),
                                (0.0, 0.35, 1.5)))


@pytest.mark.parametrize("field, model, gradient, sphere_b, floor, beta, backend",
                         with_backends(MATRIX, lambda case: case[3:] == (True, True, 0.35)))
def test_matches_reference(field, model, gradient, sphere_b, floor, beta, backend):
    scene = Scene(height_field=field, model=model, sphere_b=sphere_b, floor=floor, beta=beta, bump="chart")
    assert_parity(scene, gradient, backend)


@pytest.mark.parametrize("field, model, gradient, beta, backend",
                         with_backends(list(itertools.product(FIELDS, MODELS, GRADIENTS, (0.35, 0.9))),
                                       lambda case: case[3] == 0.9))
def test_matches_reference_displaced_surface_normal(field, model, gradient, beta, backend):
    """Scene.bump = "surface": the displaced sphere's normal, derived by hand in the reference."""
    assert_parity(Scene(height_field=field, model=model, beta=beta, bump="surface"), gradient, backend)


# Scenes that exercise what the default scene does not.
VARIANTS = {
    # Sphere points are lit from below the floor plane only if the plane does not separate them.
    "light below the floor": dict(lights=(PointLight((5.0, 5.0, 10.0)),
                                          PointLight((3.0, -2.0, -4.0), (0.5, 0.6, 0.7)))),
    "black light skipped": dict(lights=(PointLight((5.0, 5.0, 10.0), (0.0, 0.0, 0.0)), LIGHT_2)),
    "no lights": dict(lights=()),
    "light inside sphere B": dict(lights=(PointLight((0.5, 0.5, 1.3)), LIGHT_2)),
    # k_u = 7: the pole pixel of 17 x 20 has h_v != 0, so the fallback frame matters.
    "pole with nonzero gradient": dict(k_u=7.0, beta=1.5, bump="chart"),
    "non-integer frequencies": dict(k_u=3.3, k_v=7.1, beta=1.0, bump="chart"),
    "large eps": dict(eps=0.25),
    "eps 0.05": dict(eps=0.05),
    "camera close, sphere B moved": dict(camera_z=2.5, radius_a=0.8, center_b=(-0.6, 0.2, 0.9),
                                         radius_b=0.4),
    "saturated (clipping)": dict(kd=1.0, ks=1.0, shininess=1.0, floor_tint=1.0,
                                 lights=(PointLight((5.0, 5.0, 10.0), (3.0, 3.0, 3.0)), LIGHT_2)),
    "sphere B through the floor": dict(center_b=(0.9, -0.3, 0.2), radius_b=0.5, floor_tint=0.0),
}


@pytest.mark.parametrize("name, field, gradient, backend",
                         with_backends(list(itertools.product(sorted(VARIANTS), FIELDS, GRADIENTS)),
                                       lambda case: case[1] == "ridges"))
def test_matches_reference_scene_variants(name, field, gradient, backend):
    assert_parity(Scene(height_field=field, **VARIANTS[name]), gradient, backend)



def test_frame_sizes_reach_the_pole():
    """The 17 x 20 frame does put a pixel on the pole, as the module docstring claims."""
    width, height = 17, 20
    x, y = ref.pixel_point(Scene(), 8, 8, width, height)
    assert x == 0.0 and abs(y) < 1e-16
    _, _, _, grad = ref.render_reference(Scene(**VARIANTS["pole with nonzero gradient"]),
                                         width, height)
    assert abs(grad[8, 8, 1]) > 1.0


def test_light_on_a_blocker_surface_does_not_shadow_the_outside():
    """A light exactly on sphere B's surface: the seed's sign logic (a root in the
    open interval (0, 1)) lights a floor point whose segment only touches B at
    the light.  Here L = (0.5, 0.5, 1.25) is B's lowest point (C = (0.5, 0.5, 1.5),
    r = 0.25, |L - C|^2 - r^2 = 0 exactly in float64), the tangent plane at L is
    z = 1.25 and every floor point lies below it, so no floor segment enters B.
    The image must be continuous in the light position: moving the light 1e-9
    below B (outside it) changes the image by O(1e-9), not by O(1).
    """
    base = dict(center_b=(0.5, 0.5, 1.5), radius_b=0.25, height_field="sine")
    on = Scene(lights=(PointLight((0.5, 0.5, 1.25)),), **base)
    near = Scene(lights=(PointLight((0.5, 0.5, 1.25 - 1e-9)),), **base)
    a, b = render(on, 24, 20), render(near, 24, 20)
    floor = a.chamber == 3
    assert floor.any()
    # The reference with the light 1e-9 away agrees with the renderer there...
    assert parity_failures(near, 24, 20, "exact", frame=b) == []
    # ...and the renderer must not jump when the light touches the sphere.
    jump = float(np.abs(a.image - b.image)[floor].max())
    assert jump <= 1e-6, f"floor image jumps by {jump:.3f} when the light touches sphere B"


# --- teeth: each check rejects a wrong variant ------------------------------------------

@pytest.mark.parametrize("change, gradient, kind", [
    (dict(beta=0.36), "exact", "|dI|"),
    (dict(k_u=8.25), "exact", "grad"),
    (dict(model="phong"), "exact", "|dI|"),
    (dict(floor_tint=0.26), "exact", "|dI|"),
    (dict(albedo_a=(0.63, 0.19, 0.17)), "exact", "|dI|"),
    (dict(lights=(PointLight((5.0, 5.0, 10.5)), LIGHT_2)), "exact", "|dI|"),
    (dict(eps=1.1e-3), "central", "grad"),
    (dict(center_b=(0.5, 0.45, 1.3)), "exact", "chamber"),
    (dict(height_field="sine"), "exact", "kink"),
    (dict(bump="chart"), "exact", "|dI|"),
    (dict(k_v=4.25), "footprint", "grad"),
    (dict(beta=0.36), "footprint", "|dI|"),
])
def test_parity_rejects_a_scene_that_differs_in_one_field(change, gradient, kind):
    scene = Scene()
    wrong = render(scene.replace(**change), 24, 20, gradient=gradient)
    failures = parity_failures(scene, 24, 20, gradient, frame=wrong)
    assert any(kind in f for f in failures), failures


def _seed_sphere_b_t(x, y, scene):
    """The seed's Cell 1 sphere-B hit: constant term |C|^2 - r^2 instead of |E - C|^2 - r^2."""
    e, C, r = scene.camera_z, scene.center_b, scene.radius_b
    a = x * x + y * y + e * e
    b_half = -C[0] * x - C[1] * y - (e - C[2]) * e
    c_seed = C[0] ** 2 + C[1] ** 2 + C[2] ** 2 - r * r
    disc = b_half * b_half - a * c_seed
    return (-b_half - math.sqrt(disc)) / a if disc >= 0 else math.inf


def test_parity_rejects_the_seeds_sphere_b_quadratic(monkeypatch):
    monkeypatch.setattr(ref, "sphere_b_t", _seed_sphere_b_t)
    failures = parity_failures(Scene(), 24, 20, "exact")
    assert any("chamber" in f for f in failures), failures


def test_parity_rejects_a_reference_without_the_floor_plane_shadow(monkeypatch):
    monkeypatch.setattr(ref, "floor_separates", lambda P, L: False)
    scene = Scene(**VARIANTS["light below the floor"])
    assert any("|dI|" in f for f in parity_failures(scene, 24, 20, "exact"))


def test_parity_rejects_the_seeds_terminator_rule(monkeypatch):
    """The seed tests the light against the perturbed normal only (no geometric attached shadow)."""
    shade = ref.shade
    monkeypatch.setattr(ref, "shade", lambda scene, P, N, Ns, *rest: shade(scene, P, Ns, Ns, *rest))
    assert any("|dI|" in f for f in parity_failures(Scene(beta=1.5, bump="chart"), 24, 20, "exact"))


def test_parity_rejects_a_different_pole_fallback(monkeypatch):
    frame = ref.tangent_frame_a

    def swapped(N, sin_phi):
        if sin_phi > ref.POLE_SIN_PHI:
            return frame(N, sin_phi)
        return (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)

    monkeypatch.setattr(ref, "tangent_frame_a", swapped)
    scene = Scene(**VARIANTS["pole with nonzero gradient"])
    assert any("|dI|" in f for f in parity_failures(scene, 17, 20, "exact"))


def test_parity_rejects_a_two_sided_quotient_at_the_pole(monkeypatch):
    """Dividing by 2 eps even where v was clamped (v = 1.3e-17 at the pole pixel)."""
    stencil = ref.stencil_v
    monkeypatch.setattr(ref, "stencil_v", lambda v, eps: stencil(v, eps)[:2] + (2.0 * eps,))
    scene = Scene(**VARIANTS["pole with nonzero gradient"])
    assert any("grad" in f for f in parity_failures(scene, 17, 20, "central"))


def test_parity_rejects_a_wider_kink_band(monkeypatch):
    monkeypatch.setattr(ref, "KINK_HALF_WIDTH", 0.1)
    assert any("kink" in f for f in parity_failures(Scene(), 24, 20, "exact"))


def test_grad_tolerance_is_tight_enough_to_catch_a_half_step_error():
    """The central slack (5.6e-12 at the defaults) is far below any real pipeline error:
    the reference's central gradient at eps differs from the renderer's at 1.001 eps."""
    scene = Scene()
    frame = render(scene.replace(eps=1.001e-3), 24, 20, gradient="central")
    failures = parity_failures(scene, 24, 20, "central", frame=frame)
    assert any("grad" in f for f in failures), failures


def test_tangent_exemption_covers_only_the_two_tangent_pixels():
    for width, height in SIZES:
        image, chamber, _, _ = ref.render_reference(Scene(), width, height)
        got = np.argwhere(grazing_mask(Scene(), width, height, chamber)).tolist()
        assert got == ([[0, 8], [16, 8]] if (width, height) == (17, 20) else [])


def test_parity_still_checks_the_tangent_pixels():
    """A wrong colour (1e-3) at an exempted pixel is still rejected."""
    scene = Scene()
    frame = render(scene, 17, 20)
    assert parity_failures(scene, 17, 20, "exact", frame=frame) == []
    frame.image[0, 8] += 1e-3
    assert any("(tangent)" in f for f in parity_failures(scene, 17, 20, "exact", frame=frame))


# --- teeth of the footprint pipeline's checks ----------------------------------------------

def _pbrt_raster_row(scene, i, j, width, height):
    """pbrt-v4's y differential: the next raster row, one row *down* (j + 1)."""
    return ref.pixel_point(scene, i + 1, j, width, height), ref.pixel_point(scene, i, j + 1, width, height)


def test_footprint_parity_rejects_the_other_neighbouring_row(monkeypatch):
    """The neighbour below instead of above: the same rule to first order in the
    pixel spacing, a different step at second order, which the tolerance sees."""
    monkeypatch.setattr(ref, "footprint_neighbours", _pbrt_raster_row)
    failures = parity_failures(Scene(), 24, 20, "footprint")
    assert any("grad" in f for f in failures), failures


def test_footprint_parity_rejects_a_step_without_pbrts_half(monkeypatch):
    steps = ref.footprint_steps
    monkeypatch.setattr(ref, "footprint_steps",
                        lambda *a: tuple(min(2 * s, ref.FOOTPRINT_MAX) for s in steps(*a)))
    failures = parity_failures(Scene(), 24, 20, "footprint")
    assert any("grad" in f for f in failures) and any("|dI|" in f for f in failures), failures


def test_footprint_parity_rejects_the_central_pipelines_frame():
    frame = render(Scene(), 24, 20, gradient="central")
    assert any("grad" in f for f in parity_failures(Scene(), 24, 20, "footprint", frame=frame))


def test_footprint_exemption_is_limited_to_a_few_pixels(monkeypatch):
    """A footprint too ill-conditioned to compare (delta > WIDE_DELTA) is
    allowed on at most MAX_GRAZING pixels: with no pixel well-conditioned
    enough the check fails instead of passing vacuously."""
    assert parity_failures(Scene(), 17, 20, "footprint") == []
    monkeypatch.setitem(globals(), "WIDE_DELTA", -1.0)
    assert any("ill-conditioned footprint" in f for f in parity_failures(Scene(), 17, 20, "footprint"))
