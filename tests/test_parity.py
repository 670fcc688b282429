"""Parity: `renderer.render` against the scalar oracle `scalar_reference`.

The scenes cover, not enumerate.  The settings (every registered height field,
`renderer.formulas.FIELDS`; both models; the three pipelines, exact, central
and footprint; both bump modes; beta; sphere B and the floor on and off; the
frame; the backend; and the scene variants of `VARIANTS`, which exercise what
the default scene does not) are drawn from a pairwise covering array
(`allpairspy`): every pair of values of any two settings is rendered in some
scene, which finds any bug that two settings make together (a wrong term only
for phong and central differences, say) in some fifty scenes instead of the
full product's thousands.  Random scenes (`test_random_scenes_match_the_reference`,
seeded) move every number of a scene off the values the array uses.

The frames, chosen for what they hit:

* 24 x 20: even width, non-square;
* 17 x 13: odd width (column 8 lies on x = 0), odd height;
* 17 x 20: x = 0 at column 8 and y = 3.6e-17 at row 8, so pixel (8, 8) lands on
  sphere A's pole: sin(phi) = 4e-17, the chart's frame at a sin(phi) far inside the
  draft's fallback disc (1e-4) and the one-sided v difference (v = 1.3e-17 < eps)
  are exercised.

The backends are those of `renderer.render`: the numba kernel, the array
kernel on numpy (everywhere) and on Dr.Jit's LLVM backend (where the system's
libLLVM is; skipped without it, failed when CI=true).

Checks per frame: identical chamber codes, identical crease flags,
|dI| <= 1e-12 per channel (the issue's tolerance), and the gradient within the
tolerance of `grad_tolerance`, derived from bounds of the field's first and
second derivatives over the chart (`field_bounds`, interval arithmetic on the
record's expression, so that any registered field or a reader's expression
gets its own).  The footprint pipeline's step is computed by both routes from
the pixel's geometry, so its gradient carries the step's rounding too:
`footprint_bound` bounds that.  The image tolerance of the central and footprint
pipelines grows by what their gradient tolerance can move the reference's own
shading (`shading_allowance`: at small steps the quotient's rounding is large).  The only exemption is a ray tangent to a sphere
(`grazing_mask`: at most two pixels, checked at 1e-6).  Each kind of check is
shown to reject a wrong variant at the end of the file.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
from collections import OrderedDict

import mpmath
import numpy as np
import pytest
import sympy as sp
from allpairspy import AllPairs
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from mpmath import iv

from renderer import GRADIENTS, MODELS, PointLight, Scene, backends, render
from renderer import formulas as F
from renderer.validate import InputError
from tests import scalar_reference as ref
from tests.test_any_scene import accepted_scenes
from tests.jsnode import in_ci

pytestmark = pytest.mark.cpu_dependent     # make test-baseline-simd runs the file again

SIZES = ((24, 20), (17, 13), (17, 20))
IMAGE_TOL = 1e-12          # per channel, required by the issue
LIGHT_2 = PointLight((-6.0, 2.0, 8.0), (0.9, 0.65, 0.25))     # the seed's second light
U = 2.0**-53               # unit roundoff
#: How far the two routes' chart points (u, v) may lie apart on a well-conditioned hit: a few
#: ulp of 1 (their own hit points and atan2 sequences; measured within 2^-52).  Near a
#: silhouette the hit itself moves by the root's condition number times that (`chart_shift`).
CHART_SHIFT = 2.0**-50

def _monotonic(f):
    """An interval version of the monotonic function ``f`` (an mpmath function): f at the ends."""
    return lambda x: iv.mpf(sorted((f(iv.mpf(x).a), f(iv.mpf(x).b))))


def _cosh(x):
    x = iv.mpf(x)
    low = 1 if x.a <= 0 <= x.b else min(mpmath.cosh(x.a), mpmath.cosh(x.b))
    return iv.mpf([low, max(mpmath.cosh(x.a), mpmath.cosh(x.b))])


#: Interval versions (``mpmath.iv``) of the functions a field may use (`formulas.ELEMENTARY`):
#: mpmath's own where it has one, else the function at the interval's ends (each monotonic;
#: cosh even, increasing on [0, inf)).
_INTERVAL = {"sin": iv.sin, "cos": iv.cos, "tan": iv.tan, "exp": iv.exp, "log": iv.log, "sqrt": iv.sqrt,
             "pi": iv.pi, "E": iv.e, "Abs": abs, "cosh": _cosh,
             **{name: _monotonic(getattr(mpmath, name)) for name in ("asin", "acos", "atan", "sinh", "tanh")}}


@functools.lru_cache(maxsize=None)
def field_bounds(field, k_u, k_v):
    """(L1, L2): bounds on |h_u|, |h_v| and on the four second derivatives of the height field
    ``field`` (a Scene's ``height_field``) over the chart [0, 1]^2, where they exist.

    Interval arithmetic (``mpmath.iv``) on the record's expression with its ``Abs`` taken off
    (|f| has the slope of f up to its sign, away from f's zeros, where h has a crease and no
    second derivative): an upper bound, not an estimate; the product of intervals
    overestimates a product of sines, which only widens the tolerance a little.
    """
    record = F.field(field)
    smooth = record.expr.replace(sp.Abs, lambda a: a)
    first = [sp.diff(smooth, x) for x in (F.u, F.v)]
    second = [sp.diff(d, x) for d in first for x in (F.u, F.v)]
    fn = sp.lambdify(F.FIELD_SYMBOLS, [*first, *second], modules=[_INTERVAL])
    chart = iv.mpf([0, 1])
    values = [abs(iv.mpf(b)).b for b in fn(chart, chart, iv.mpf(k_u), iv.mpf(k_v))]
    return float(max(values[:2])), float(max(values[2:]))


def lipschitz(scene):
    """L1 of `field_bounds`: a Lipschitz constant of h in each chart variable."""
    return field_bounds(scene.height_field, scene.k_u, scene.k_v)[0]


def chart_shift(scene, width, height, chamber):
    """How far the two routes' chart points may lie apart, per pixel (H, W, 1): `CHART_SHIFT`
    times the condition number of sphere A's hit (`hit_condition`, at least 1).  The two routes
    round the hit's t differently, and a relative error U kappa of t moves the hit point, and so
    (u, v), by that much more (a random scene's pixel near the silhouette, kappa = 48, had its
    exact gradient 2.2 CHART_SHIFT-widths of L2 apart)."""
    shift = np.full((*chamber.shape, 1), CHART_SHIFT)
    for j, i in np.argwhere(chamber == ref.SPHERE_A):
        kappa = hit_condition(scene, *ref.pixel_point(scene, i, j, width, height), (0.0, 0.0, 0.0), scene.radius_a)
        shift[j, i] *= max(1.0, kappa)
    return shift


def grad_tolerance(scene, gradient, grad_ref, steps=None, delta=None, shift=CHART_SHIFT):
    """Allowed |grad_renderer - grad_reference|, per component.

    Both routes evaluate the same sympy expressions (the kernel the printed and
    compiled ones, the reference sympy's ``math`` printing), so 1e-12 (1 + |g|)
    covers their roundings (measured worst on these frames: 4.7e-14 relative),
    and the chart points of the two routes lie up to ``shift`` apart (`CHART_SHIFT`, or
    per pixel `chart_shift`), which moves the exact gradient by at most L2 shift (L2
    bounds h's second derivatives, `field_bounds`).

    The central pipeline needs an absolute slack on top.  The two routes
    compute the chart (u, v) of a hit point differently (textbook vs
    cancellation-free quadratic for t, and their own atan2/hypot sequences),
    and the results differ by a few ulp.  The common shift cancels in
    h(u + eps) - h(u - eps), but u + eps and u - eps are each rounded
    afresh, so the two samples can sit up to 2^-52 apart per side.  h is
    Lipschitz with constant LIP = L1 in each chart variable, so the quotient
    can move by 2 LIP 2^-52 / (2 eps) = LIP 2^-52 / eps (5.6e-12 for the
    ridges at the defaults).

    The footprint pipeline is the central one with steps ``steps`` (H, W, 2),
    the reference's, per component; the renderer's own steps differ from
    them by at most the relative ``delta`` (H, W, 2) of `footprint_bound`.
    With g(eps) = (h(u + eps) - h(u - eps)) / (2 eps),
    eps g'(eps) = (h'(u + eps) + h'(u - eps)) / 2 - g, at most 2 LIP in size
    (also for the one-sided quotient at the v border), so a relative change
    delta of the step moves the quotient by at most 2 LIP delta.
    """
    lip, second = field_bounds(scene.height_field, scene.k_u, scene.k_v)
    tol = 1e-12 * (1.0 + np.abs(grad_ref))
    if gradient == "exact":
        tol = tol + second * shift
    elif gradient == "central":
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
                           # derivatives' bound (L2 of `field_bounds`) times that.


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


def grazing_mask(scene, width, height, *chambers):
    """Pixels whose sphere hit, in any of ``chambers`` (the reference's, the renderer's), is
    ill-conditioned by input rounding alone."""
    mask = np.zeros(chambers[0].shape, dtype=bool)
    spheres = {ref.SPHERE_A: ((0.0, 0.0, 0.0), scene.radius_a),
               ref.SPHERE_B: (scene.center_b, scene.radius_b)}
    for chamber in chambers:
        for j, i in zip(*np.nonzero(np.isin(chamber, list(spheres)))):
            x, y = ref.pixel_point(scene, i, j, width, height)
            mask[j, i] |= 2.0**-52 * hit_condition(scene, x, y, *spheres[int(chamber[j, i])]) > GRAZING_REL_T
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
    add 2 (dN + dP / |P - E| + 4 u) relatively: both routes take N_x, N_y =
    t (x, y) / R (`kernel.sphere_a_point`, `scalar_reference.ray_point`), so
    the frame's direction in the xy-plane is the pixel centre's at every
    sin(phi), and sin(phi) = |t| hypot(x, y) / R carries t's relative error
    (below dP / |P - E|) and a few roundings; e_phi's N_z and -sin(phi) move
    by dN.  Then delta = 4 (sum_k |d a_k| / sum_k |a_k| + frame terms + u):
    4 covers the few roundings each step takes in either route.  A step both
    routes cap at 0.25 (its uncapped value shrunk by delta still above) has
    delta = 0; inf where the routes may take different frames (sin(phi)
    within 4 ulps of the pole cut-off, 2^-1022: none of a frame's pixels).
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
    near_cut = abs(sin_phi - ref.POLE_SIN_PHI) <= 4 * ref.POLE_SIN_PHI * 2.0**-52
    regular = sin_phi > ref.POLE_SIN_PHI
    frame = 2 * (dN + dP / _norm(PE) + 4 * U) if regular else 0.0
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


def shading_allowance(scene, width, height, chamber, grad_ref, tol):
    """Extra image tolerance per pixel of sphere A: how far the reference's own shading of the
    pixel moves when its gradient moves by the gradient tolerance ``tol`` (the largest change
    over the four corners of the tolerance box, first order); inf where ``tol`` is not finite."""
    extra = np.zeros(chamber.shape)
    for j, i in np.argwhere(chamber == ref.SPHERE_A):
        if not np.all(np.isfinite(tol[j, i])):
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
    return extra


def footprint_allowances(scene, width, height, chamber, grad_ref):
    """(grad tolerance, extra image tolerance, pixels with delta > WIDE_DELTA) of the footprint
    pipeline (the image's, `shading_allowance`).  Where delta > WIDE_DELTA the step may be
    anything the cap and the fallback allow, and first order bounds nothing: the image is not
    compared there (no more than MAX_GRAZING such pixels, `parity_failures`).
    """
    steps, delta = np.ones(grad_ref.shape), np.zeros(grad_ref.shape)
    for j, i in np.argwhere(chamber == ref.SPHERE_A):
        steps[j, i], delta[j, i] = footprint_bound(scene, i, j, width, height)
    tol = grad_tolerance(scene, "footprint", grad_ref, steps, delta)
    wide = (delta > WIDE_DELTA).any(axis=-1)
    extra = shading_allowance(scene, width, height, chamber, grad_ref, tol)
    extra[wide] = math.inf
    return tol, extra, int(np.count_nonzero(wide))


def parity_failures(scene, width, height, gradient, *, frame=None, backend="numba", reference=None):
    """Compare one render (``frame``, else rendered by ``backend``) with the reference
    (``reference``, else `scalar_reference.render_reference`'s); return a list of failure
    strings (empty: parity)."""
    if frame is None:
        frame = render(scene, width, height, gradient=gradient, backend=backend)
    image, chamber, kink, grad = reference or ref.render_reference(scene, width, height, gradient=gradient)
    failures = []
    # A tangent ray's hit is decided by rounding: where the chambers differ there, nothing else
    # of the pixel compares either.
    tangent = grazing_mask(scene, width, height, chamber, frame.chamber)
    if np.count_nonzero(tangent) > MAX_GRAZING:            # then no pixel is exempt
        failures.append(f"{np.count_nonzero(tangent)} tangent pixels > {MAX_GRAZING}")
        tangent[:] = False
    hit_differs = frame.chamber != chamber
    n = int(np.count_nonzero(hit_differs & ~tangent))
    if n:
        failures.append(f"chamber differs at {n} pixels")
    n = int(np.count_nonzero((frame.kink != kink) & ~hit_differs))
    if n:
        failures.append(f"kink differs at {n} pixels")
    tangent &= ~hit_differs
    if gradient == "footprint":
        tol, extra, wide = footprint_allowances(scene, width, height, chamber, grad)
        if wide > MAX_GRAZING:
            failures.append(f"{wide} pixels with an ill-conditioned footprint > {MAX_GRAZING}")
    elif gradient == "central":
        tol = grad_tolerance(scene, gradient, grad)
        extra = shading_allowance(scene, width, height, chamber, grad, tol)
    else:
        tol = grad_tolerance(scene, gradient, grad, shift=chart_shift(scene, width, height, chamber))
        extra = np.zeros(chamber.shape)
    d_image = np.abs(frame.image - image).max(axis=-1)
    excess = (np.abs(frame.grad - grad) - tol).max(axis=-1)
    second = field_bounds(scene.height_field, scene.k_u, scene.k_v)[1]
    for where, image_tol, what in ((~tangent & ~hit_differs, IMAGE_TOL, ""), (tangent, GRAZING_TOL, " (tangent)")):
        if not where.any():
            continue
        worst = float((d_image - extra)[where].max())
        if not worst <= image_tol:                       # also catches NaN
            failures.append(f"max |dI|{what} beyond the allowance = {worst:.3e} > {image_tol}")
        worst = float(excess[where].max())
        if not worst <= (0.0 if what == "" else GRAZING_TOL * second):
            failures.append(f"grad{what} differs beyond tolerance by up to {worst:.3e}")
    return failures


# --- the scenes: a pairwise covering array of the settings, and random scenes ---------------

BACKENDS = ("numba", "numpy", "drjit")


def require_backend(backend):
    """Skip a Dr.Jit case where its LLVM backend is missing, and fail it when CI=true."""
    why = backends.missing(backend)
    if why is not None:
        if in_ci():
            pytest.fail(why + " (CI=true: this test may not skip)")
        pytest.skip(why)


def assert_parity(scene, gradient, backend, sizes=SIZES):
    require_backend(backend)
    for width, height in sizes:
        assert parity_failures(scene, width, height, gradient, backend=backend) == [], (width, height)


#: Scenes that exercise what the default scene does not: name -> (Scene fields, the values of the
#: other settings it is drawn with, where it means something only with those).
VARIANTS = {
    # Sphere points are lit from below the floor plane only if the plane does not separate them.
    "light below the floor": (dict(lights=(PointLight((5.0, 5.0, 10.0)),
                                           PointLight((3.0, -2.0, -4.0), (0.5, 0.6, 0.7)))), dict(floor=(True,))),
    "black light skipped": (dict(lights=(PointLight((5.0, 5.0, 10.0), (0.0, 0.0, 0.0)), LIGHT_2)), {}),
    "no lights": (dict(lights=()), {}),
    "light inside sphere B": (dict(lights=(PointLight((0.5, 0.5, 1.3)), LIGHT_2)), dict(sphere_b=(True,))),
    # k_u = 7: the pole pixel of 17 x 20 has h_v != 0, so the frame there matters.
    "pole with nonzero gradient": (dict(k_u=7.0), dict(size=((17, 20),), beta=(0.35, 0.9, 1.5))),
    "non-integer frequencies": (dict(k_u=3.3, k_v=7.1), {}),
    "large eps": (dict(eps=0.25), dict(gradient=("central",))),
    "eps 0.05": (dict(eps=0.05), dict(gradient=("central",))),
    "camera close, sphere B moved": (dict(camera_z=2.5, radius_a=0.8, center_b=(-0.6, 0.2, 0.9), radius_b=0.4), {}),
    "saturated (clipping)": (dict(kd=1.0, ks=1.0, shininess=1.0, floor_tint=1.0,
                                  lights=(PointLight((5.0, 5.0, 10.0), (3.0, 3.0, 3.0)), LIGHT_2)), {}),
    "sphere B through the floor": (dict(center_b=(0.9, -0.3, 0.2), radius_b=0.5, floor_tint=0.0), {}),
}
#: The settings and their values (every registered field, derived from the records); the scene's
#: own settings first, so that a partial row can already be checked by `Scene`.
SETTINGS = OrderedDict(
    variant=("default", *VARIANTS), bump=("chart", "surface"), beta=(0.0, 0.35, 0.9, 1.5),
    field=tuple(F.FIELDS), model=MODELS, sphere_b=(True, False), floor=(True, False),
    gradient=GRADIENTS, size=SIZES, backend=BACKENDS)
_SCENE_SETTINGS = dict(field="height_field", bump="bump", beta="beta", model="model", sphere_b="sphere_b",
                       floor="floor")


def scene_of(row):
    """The Scene of a (complete or partial) row {setting: value}; raises InputError if refused."""
    fields, _ = VARIANTS.get(row.get("variant"), ({}, {}))
    return Scene(**{**fields, **{_SCENE_SETTINGS[k]: v for k, v in row.items() if k in _SCENE_SETTINGS}})


def admissible(values):
    """Whether a partial row (the first settings' values, in order) is admissible so far: the
    variant's requirements hold, and once the scene's settings are all known `Scene` accepts
    them (a surface bump needs beta below the radius)."""
    row = dict(zip(SETTINGS, values))
    _, needs = VARIANTS.get(row["variant"], ({}, {}))
    if any(k in row and row[k] not in allowed for k, allowed in needs.items()):
        return False
    return not set(_SCENE_SETTINGS) <= set(row) or _accepted(*(row[k] for k in ("variant", *_SCENE_SETTINGS)))


@functools.lru_cache(maxsize=None)
def _accepted(variant, *values):
    try:
        scene_of(dict(zip(("variant", *_SCENE_SETTINGS), (variant, *values))))
    except InputError:
        return False
    return True


def completion(fixed, prefix=()):
    """An admissible row (a dict) holding the values ``fixed`` {setting: value}, or None: depth
    first over `SETTINGS`, each prefix checked by `admissible`."""
    if len(prefix) == len(SETTINGS):
        return dict(zip(SETTINGS, prefix))
    key = list(SETTINGS)[len(prefix)]
    for value in (fixed[key],) if key in fixed else SETTINGS[key]:
        if admissible([*prefix, value]) and (row := completion(fixed, (*prefix, value))) is not None:
            return row
    return None


def pairs(row):
    return {(a, row[a], b, row[b]) for a, b in itertools.combinations(SETTINGS, 2)}


def covering_array():
    """The rows of a pairwise covering array of `SETTINGS` under `admissible`, as dicts:
    allpairspy's, then a row for each pair it left out (it stops at the first row that adds no
    pair, which under a filter can come before the last pair)."""
    rows = [dict(row._asdict()) for row in AllPairs(SETTINGS, filter_func=admissible)]
    seen = set().union(*map(pairs, rows))
    for a, b in itertools.combinations(SETTINGS, 2):
        for x, y in itertools.product(SETTINGS[a], SETTINGS[b]):
            if (a, x, b, y) not in seen and (row := completion({a: x, b: y})) is not None:
                rows.append(row)
                seen |= pairs(row)
    return rows


ROWS = covering_array()


@pytest.mark.parametrize("row", ROWS, ids=["-".join(map(str, r.values())).replace(" ", "_") for r in ROWS])
def test_covering_array_matches_reference(row):
    assert_parity(scene_of(row), row["gradient"], row["backend"], (row["size"],))


def test_the_covering_array_holds_every_admissible_pair():
    """Every pair of values of two settings that an admissible row can hold is in some row, and
    the array is a small fraction of the full product."""
    seen = set().union(*map(pairs, ROWS))
    missing = [(a, x, b, y) for a, b in itertools.combinations(SETTINGS, 2)
               for x, y in itertools.product(SETTINGS[a], SETTINGS[b])
               if (a, x, b, y) not in seen and completion({a: x, b: y}) is not None]
    assert missing == [], missing[:5]
    assert all(admissible(list(row.values())) for row in ROWS)
    assert len(ROWS) <= math.prod(map(len, SETTINGS.values())) / 500, len(ROWS)


def random_scene(rng):
    """A scene whose every number is drawn (within ranges the frames still show): geometry,
    lights, frequencies, amplitude, step; settings drawn as well."""
    while True:
        radius_a = rng.uniform(0.5, 1.5)
        bump = rng.choice(["chart", "surface"])
        lights = tuple(PointLight(tuple(rng.uniform([-8, -8, 1], [8, 8, 12])), tuple(rng.uniform(0.2, 1.0, 3)))
                       for _ in range(rng.integers(1, 3)))
        kw = dict(radius_a=radius_a, camera_z=rng.uniform(2.5, 5.0) * radius_a,
                  center_b=tuple(rng.uniform([-1, -1, 0], [1, 1, 2])), radius_b=rng.uniform(0.1, 0.6),
                  sphere_b=bool(rng.integers(2)), floor=bool(rng.integers(2)), lights=lights,
                  albedo_a=tuple(rng.uniform(0, 1, 3)), ka=rng.uniform(0, 0.3), kd=rng.uniform(0.2, 1.0),
                  ks=rng.uniform(0, 1), shininess=float(rng.choice([rng.uniform(1, 100), rng.integers(1, 64)])),
                  model=str(rng.choice(MODELS)), floor_tint=rng.uniform(0, 1),
                  height_field=str(rng.choice(list(F.FIELDS))), k_u=rng.uniform(0.5, 12.0), k_v=rng.uniform(0.5, 12.0),
                  beta=rng.uniform(0.0, 0.95 * radius_a if bump == "surface" else 1.5),
                  eps=10.0 ** rng.uniform(-7, math.log10(0.25)), bump=str(bump))
        try:
            return Scene(**kw)
        except InputError:                       # the camera inside sphere B: draw again
            continue


@pytest.mark.parametrize("seed", range(8))
def test_random_scenes_match_the_reference(seed):
    rng = np.random.default_rng([2026, 9, seed])
    scene = random_scene(rng)
    gradient, backend = str(rng.choice(GRADIENTS)), str(rng.choice(BACKENDS))
    assert_parity(scene, gradient, backend, (SIZES[seed % len(SIZES)],))


#: The pole frame's scene with a bump that shows there (the draft's chart normal, beta 1.5).
POLE_SCENE = Scene(**VARIANTS["pole with nonzero gradient"][0], beta=1.5, bump="chart")


def test_frame_sizes_reach_the_pole():
    """The 17 x 20 frame does put a pixel on the pole, as the module docstring claims."""
    width, height = 17, 20
    x, y = ref.pixel_point(Scene(), 8, 8, width, height)
    assert x == 0.0 and abs(y) < 1e-16
    _, _, _, grad = ref.render_reference(POLE_SCENE,
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


def _nudged(value, by):
    """``value`` (a Scene field's) with its first number scaled by 1 + ``by`` (or set to ``by`` where 0);
    None for a value without a number (a name, a flag)."""
    if isinstance(value, bool) or isinstance(value, str):
        return None
    if isinstance(value, float):
        return value * (1 + by) if value else by
    if isinstance(value, PointLight):
        return PointLight(_nudged(value.position, by), value.color)
    first = _nudged(value[0], by) if value else None
    return None if first is None else (first, *value[1:])


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(other=accepted_scenes(), name=st.sampled_from([f.name for f in dataclasses.fields(Scene)]),
       by=st.one_of(st.none(), st.floats(-10.0, -3.0).map(lambda e: 10.0**e)))
def test_parity_rejects_a_frame_of_any_one_field_changed(other, name, by):
    """The default scene's frame replaced by the frame of the scene with any one field changed (set to
    its value in any accepted scene, or its first number nudged by 1e-10 to 1e-3 relative): wherever
    the two frames differ (a chamber or a crease flag, a channel by more than 1e-9, a gradient component
    by more than 1e-9 relative) at more pixels than the grazing exemption may excuse, parity fails.
    Its allowances hide no change of the scene, however small."""
    scene = Scene()
    value = getattr(other, name) if by is None else _nudged(getattr(scene, name), by)
    assume(value is not None)
    try:
        changed = scene.replace(**{name: value})
    except ValueError:
        assume(False)
    right, wrong = render(scene, 24, 20), render(changed, 24, 20)
    differs = ((right.chamber != wrong.chamber) | (right.kink != wrong.kink)
               | (np.abs(right.image - wrong.image).max(axis=-1) > 1e-9)
               | (np.abs(right.grad - wrong.grad) > 1e-9 * (1 + np.abs(right.grad))).any(axis=-1))
    assume(np.count_nonzero(differs) > MAX_GRAZING)
    assert parity_failures(scene, 24, 20, "exact", frame=wrong), (name, value)


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
    scene = Scene(**VARIANTS["light below the floor"][0])
    assert any("|dI|" in f for f in parity_failures(scene, 24, 20, "exact"))


def test_parity_rejects_the_seeds_terminator_rule(monkeypatch):
    """The seed tests the light against the perturbed normal only (no geometric attached shadow)."""
    shade = ref.shade
    monkeypatch.setattr(ref, "shade", lambda scene, P, N, Ns, *rest: shade(scene, P, Ns, Ns, *rest))
    assert any("|dI|" in f for f in parity_failures(Scene(beta=1.5, bump="chart"), 24, 20, "exact"))


def test_parity_rejects_a_pole_cut_off_that_reaches_pixels(monkeypatch):
    """The reference with the fixed pair below sin(phi) = 0.3.  (The draft's cut-off, 1e-4, reaches one
    pixel of these frames, the pole pixel of 17 x 20, where its pair differs from the chart's only in
    e_theta's sign and h_u is 3e-15: tests/test_pole.py holds the magnified pole against mpmath.)"""
    monkeypatch.setattr(ref, "POLE_SIN_PHI", 0.3)
    assert any("|dI|" in f for f in parity_failures(POLE_SCENE, 17, 20, "exact"))


def test_parity_rejects_a_two_sided_quotient_at_the_pole(monkeypatch):
    """Dividing by 2 eps even where v was clamped (v = 1.3e-17 at the pole pixel)."""
    stencil = ref.stencil_v
    monkeypatch.setattr(ref, "stencil_v", lambda v, eps: stencil(v, eps)[:2] + (2.0 * eps,))
    scene = POLE_SCENE
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
