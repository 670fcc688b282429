"""The kernel's ray-sphere and shadow-segment tests against closed forms, and
the culling they decide.

The kernel culls by skipping what is off (tests/test_skips.py).  What decides every hit and
every shadow is two scalar functions of `renderer.kernel`, checked here on
random rays, spheres and segments against an independent route:

* `kernel.sphere_hit`: the nearest positive root of the ray quadratic,
  against mpmath at 40 digits, within the forward error bound of a float64
  solve (the same bound as tests/test_geometry_invariants.py);
* `kernel.segment_blocked`: whether the open segment from a point to a
  light meets a sphere, against the exact decision in rational arithmetic
  (`fractions`) on the same float64 inputs.

Cases decided within rounding of either answer (a tangent ray, a root at an
end of the segment) are left out, and at most a few per cent may be.  Each
check rejects a wrong variant.  A property then renders random scenes with
and without the skips, bit for bit.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from renderer import PointLight, Scene, kernel, render
from renderer import formulas as F

EPS = 2.0**-52
#: 40 digits: the float64 inputs are exact binary numbers and a grazing ray's
#: discriminant loses at most ~16 of them to cancellation.
MP_DPS = 40


def random_rays(rng, n=3000):
    """(x, y, e, cx, cy, cz, r): eyes on the z axis, spheres around, image points
    aimed at the sphere's silhouette and beyond (where a wrong root shows)."""
    e = rng.uniform(0.5, 12.0, n)
    C = rng.uniform(-3.0, 3.0, (n, 3))
    r = rng.uniform(0.05, 1.5, n)
    # Aim at the centre's image, offset by up to twice the sphere's apparent size.
    depth = e - C[:, 2]
    scale = np.where(depth != 0, e / depth, 1.0)
    spread = 2.0 * r * np.abs(scale) * rng.uniform(0.0, 1.0, n)
    ang = rng.uniform(0, 2 * np.pi, n)
    x = C[:, 0] * scale + spread * np.cos(ang)
    y = C[:, 1] * scale + spread * np.sin(ang)
    return list(zip(x, y, e, C[:, 0], C[:, 1], C[:, 2], r))


def mp_nearest_root(x, y, e, cx, cy, cz, r):
    """(t, tol) of the nearest positive root by mpmath, tol the float64 solve's
    forward error bound 4 eps (t + (b^2 + |a c|) / (a sqrt D)) (D: discriminant
    of a t^2 + 2 b t + c); (inf, 0) for a miss; None within rounding of tangency."""
    with mpmath.workdps(MP_DPS):
        x, y, e = mpmath.mpf(x), mpmath.mpf(y), mpmath.mpf(e)
        ox, oy, oz = -mpmath.mpf(cx), -mpmath.mpf(cy), e - mpmath.mpf(cz)
        a = x * x + y * y + e * e
        b = x * ox + y * oy - e * oz
        c = ox * ox + oy * oy + oz * oz - mpmath.mpf(r) ** 2
        D = b * b - a * c
        if abs(D) <= 8 * EPS * (b * b + abs(a * c)):
            return None
        if D < 0:
            return math.inf, 0.0
        root = mpmath.sqrt(D)
        for t in sorted(((-b - root) / a, (-b + root) / a)):
            if t > 0:
                if t <= 8 * EPS * (abs(b) + root) / a:      # a root within rounding of the eye
                    return None
                return float(t), float(4 * EPS * (t + (b * b + abs(a * c)) / (a * root)))
        return math.inf, 0.0


def hit_disagreements(fn, rays):
    """(disagreements, ambiguous) of ``fn(x, y, e, cx, cy, cz, r)`` against mpmath."""
    bad, ambiguous = [], 0
    for ray in rays:
        want = mp_nearest_root(*ray)
        if want is None:
            ambiguous += 1
            continue
        t, tol = want
        got = fn(*map(float, ray))
        if not (got == t if math.isinf(t) else abs(got - t) <= tol):
            bad.append((ray, got, t))
    return bad, ambiguous


def test_sphere_hit_is_the_nearest_positive_root():
    rays = random_rays(np.random.default_rng(20261122))
    bad, ambiguous = hit_disagreements(kernel.sphere_hit, rays)
    assert bad == [], bad[:3]
    assert ambiguous <= 0.02 * len(rays)
    hits = sum(math.isfinite(kernel.sphere_hit(*ray)) for ray in rays)
    assert 0.2 * len(rays) < hits < 0.8 * len(rays)         # both answers are exercised


def _far_root(x, y, e, cx, cy, cz, r):
    """A wrong variant: the far root of the same quadratic."""
    a = x * x + y * y + e * e
    b = -x * cx - y * cy - e * (e - cz)
    c = cx * cx + cy * cy + (e - cz) ** 2 - r * r
    D = b * b - a * c
    return (-b + math.sqrt(D)) / a if D >= 0 and (-b + math.sqrt(D)) / a > 0 else math.inf


def _seed_constant_term(x, y, e, cx, cy, cz, r):
    """The seed's Cell 1 constant term |C|^2 - r^2 (for |E - C|^2 - r^2)."""
    a = x * x + y * y + e * e
    b = -x * cx - y * cy - e * (e - cz)
    c = cx * cx + cy * cy + cz * cz - r * r
    D = b * b - a * c
    return (-b - math.sqrt(D)) / a if D >= 0 and (-b - math.sqrt(D)) / a > 0 else math.inf


def test_the_hit_check_rejects_the_far_root_and_the_seeds_quadratic():
    rays = random_rays(np.random.default_rng(1), n=500)
    assert len(hit_disagreements(_far_root, rays)[0]) > 50
    assert len(hit_disagreements(_seed_constant_term, rays)[0]) > 50


def test_sphere_hit_near_the_silhouette_stays_on_the_sphere():
    """Rays within 1e-16 .. 1e-6 (relative) inside sphere A's silhouette: the
    hit points lie on the sphere to 1e-12 (the cancellation-free discriminant)."""
    e, R = 4.0, 1.0
    rho = e * R / math.sqrt(e * e - R * R) * (1 - np.logspace(-16, -6, 1000))
    theta = np.linspace(0, 2 * np.pi, 1000)
    off = []
    for x, y in zip(rho * np.cos(theta), rho * np.sin(theta)):
        t = kernel.sphere_hit(x, y, e, 0.0, 0.0, 0.0, R)
        if math.isfinite(t):
            off.append(abs(math.sqrt((t * x) ** 2 + (t * y) ** 2 + (e * (1 - t)) ** 2) - R))
    assert len(off) > 990 and max(off) < 1e-12


# --- shadow segments ---------------------------------------------------------------------

def random_segments(rng, n=3000):
    """(P, L, C, r): a point outside the sphere, a light anywhere outside it,
    half of the segments aimed through the sphere's neighbourhood."""
    out = []
    while len(out) < n:
        C, r = rng.uniform(-2, 2, 3), rng.uniform(0.1, 1.0)
        P = C + rng.normal(size=3) * rng.uniform(1.0, 3.0) * r
        if rng.random() < 0.5:
            through = C + rng.normal(size=3) * r * rng.uniform(0.0, 1.5)
            L = P + (through - P) * rng.uniform(0.3, 3.0)
        else:
            L = C + rng.normal(size=3) * rng.uniform(0.5, 6.0)
        if np.linalg.norm(P - C) > r * (1 + 1e-9) and np.linalg.norm(L - C) > r * (1 + 1e-9):
            out.append((tuple(map(float, P)), tuple(map(float, L)), tuple(map(float, C)), float(r)))
    return out


def exact_blocked(P, L, C, r):
    """Does a root s of |L - s w - C|^2 = r^2, w = L - P, lie in (0, 1)?  In
    rational arithmetic on the float64 inputs; None within 1e-9 of a root at an
    end of the segment or of tangency."""
    P, L, C = ([Fraction(float(v)) for v in a] for a in (P, L, C))
    r = Fraction(float(r))
    w = [l - p for l, p in zip(L, P)]
    m = [l - c for l, c in zip(L, C)]
    w2 = sum(v * v for v in w)
    g = sum(a * b for a, b in zip(w, m))
    k = sum(v * v for v in m) - r * r
    disc = g * g - w2 * k                  # roots s = (g +- sqrt(disc)) / w2
    if abs(disc) <= Fraction(1, 10**9) * (g * g + w2 * abs(k)):
        return None
    if disc < 0:
        return False
    root = math.sqrt(disc)                 # a float suffices away from the ends
    roots = [(float(g) - root) / float(w2), (float(g) + root) / float(w2)]
    if any(abs(s) < 1e-9 or abs(s - 1) < 1e-9 for s in roots):
        return None
    return any(0 < s < 1 for s in roots)


def blocked_by(fn, P, L, C, r):
    w = [l - p for l, p in zip(L, P)]
    w2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
    return bool(fn(w[0], w[1], w[2], w2, L, C[0], C[1], C[2], r))


def shadow_disagreements(fn, segments):
    bad, ambiguous = [], 0
    for seg in segments:
        want = exact_blocked(*seg)
        if want is None:
            ambiguous += 1
        elif blocked_by(fn, *seg) != want:
            bad.append((seg, want))
    return bad, ambiguous


def test_segment_blocked_is_the_exact_decision():
    segments = random_segments(np.random.default_rng(7))
    bad, ambiguous = shadow_disagreements(kernel.segment_blocked, segments)
    assert bad == [], bad[:3]
    assert ambiguous <= 0.02 * len(segments)
    blocked = sum(bool(exact_blocked(*s)) for s in segments)
    assert 0.2 * len(segments) < blocked < 0.8 * len(segments)


def _line_test(wx, wy, wz, w2, L, cx, cy, cz, r):
    """A wrong variant: the line meets the sphere (no check that it is between P and L)."""
    g = wx * (L[0] - cx) + wy * (L[1] - cy) + wz * (L[2] - cz)
    k = (L[0] - cx) ** 2 + (L[1] - cy) ** 2 + (L[2] - cz) ** 2 - r * r
    return g * g >= w2 * k


def test_the_shadow_check_rejects_the_infinite_line():
    assert len(shadow_disagreements(_line_test, random_segments(np.random.default_rng(8), 500))[0]) > 20


def test_a_light_inside_a_sphere_is_blocked_from_outside_points():
    C, r = (0.5, 0.5, 1.3), 0.32
    assert blocked_by(kernel.segment_blocked, (3.0, 0.0, 0.0), (0.5, 0.5, 1.31), C, r)
    assert not blocked_by(kernel.segment_blocked, (3.0, 0.0, 0.0), (0.5, 0.5, 1.7), C, r)


# --- random scenes: the skipping path gives the reference path's bits ----------------------

@st.composite
def scenes(draw):
    rb = draw(st.floats(0.05, 0.8))
    cb = (draw(st.floats(-2.0, 2.0)), draw(st.floats(-2.0, 2.0)), draw(st.floats(-0.5, 2.5)))
    lights = tuple(PointLight((draw(st.floats(-8, 8)), draw(st.floats(-8, 8)), draw(st.floats(-3, 12))),
                              draw(st.sampled_from([(1.0, 0.7, 0.5), (0.0, 0.0, 0.0)])))
                   for _ in range(draw(st.integers(1, 3))))
    kw = dict(center_b=cb, radius_b=rb, lights=lights, camera_z=draw(st.floats(2.5, 8.0)),
              sphere_b=draw(st.booleans()), floor=draw(st.booleans()),
              height_field=draw(st.sampled_from(tuple(F.FIELDS))),
              beta=draw(st.sampled_from([0.0, 0.35, 1.5])), model=draw(st.sampled_from(["blinn", "phong"])),
              bump=draw(st.sampled_from(["chart", "surface"])))
    if kw["bump"] == "surface":
        kw["beta"] = min(kw["beta"], 0.9)
    try:
        return Scene(**kw)
    except ValueError:               # e.g. the camera inside sphere B
        return Scene()


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=scenes(), gradient=st.sampled_from(["exact", "central", "footprint"]),
       kink=st.booleans(), grad=st.booleans())
def test_random_scenes_render_the_same_bits_with_and_without_skips(scene, gradient, kink, grad):
    fast = render(scene, 41, 33, gradient=gradient, kink=kink, grad=grad)
    full = render(scene, 41, 33, gradient=gradient, kink=kink, grad=grad, skip=False)
    for name in ("image", "chamber", "kink", "grad"):
        a, b = getattr(fast, name), getattr(full, name)
        assert (a is None and b is None) or a.tobytes() == b.tobytes(), name
