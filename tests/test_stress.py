"""Stress tests: where floating point hurts.

Each test states what it found; the numbers are asserted against bounds that a
wrong renderer would break.
"""

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from renderer import GRADIENTS, Scene, gbuffer, kernel, pointwise, render
from renderer.formulas import POLE_SIN_PHI

from . import scalar_reference as ref

POLE_SIN_PHI = float(POLE_SIN_PHI)


def fallback_pixels(scene, width, height):
    g = gbuffer(scene, width, height)
    a = g.chamber == 1
    _, _, sin_phi = pointwise.chart(g.N[..., 0], g.N[..., 1], g.N[..., 2])
    return int(np.count_nonzero(a & (sin_phi <= POLE_SIN_PHI)))


def test_pole_fallback_engages_only_at_the_pole_itself():
    # Pixel centres land on x = 0 for odd widths and within an ulp of y = 0 when (j + 1/2)/H = 0.425,
    # e.g. H = 20, j = 8: the centre ray passes the pole by 6e-17, sin(phi) is about 1e-17, and the
    # chart's frame is evaluated there (the draft's cut-off, 1e-4, took the fixed pair).
    g = gbuffer(Scene(), 21, 20)
    sin_phi = float(np.hypot(*g.N[8, 10, :2]))
    assert 0.0 < sin_phi < 1e-15 and g.chamber[8, 10] == 1
    for w, h in ((21, 20), (256, 256), (255, 255), (128, 96), (512, 512)):
        assert fallback_pixels(Scene(), w, h) == 0
    for gradient in GRADIENTS:
        frame = render(Scene(height_field="sine", beta=1.5, bump="chart"), 21, 20, gradient=gradient)
        assert np.isfinite(frame.image).all() and np.isfinite(frame.grad).all()


def test_size_of_the_jump_across_the_fallback():
    """N' from the fallback basis against the regular frame just outside the
    threshold, for the same gradient: the jump is O(beta |grad|), not small.
    N' is tests/scalar_reference.py's seed §3 formula (`perturb`, chart bump)."""
    phi = 1.0001 * POLE_SIN_PHI
    N = np.array([[np.sin(phi)], [0.0], [np.cos(phi)]])
    _, _, sin_phi = pointwise.chart(*N)
    reg = pointwise.tangent_frame(*N, sin_phi)
    fb = pointwise.tangent_frame(*N, np.array([0.0]))
    assert sin_phi[0] > POLE_SIN_PHI                   # the regular frame, just outside the cut-off
    hu, hv, beta = 1.0, 0.5, 0.35

    def shading_normal(frame):
        e_th, e_ph = (tuple(float(c[0]) for c in e) for e in frame)
        return np.array(ref.perturb(tuple(N[:, 0]), e_th, e_ph, hu, hv, beta))

    jump = np.linalg.norm(shading_normal(reg) - shading_normal(fb))
    assert jump > 0.1             # a real discontinuity (confessed in §7), not rounding


@pytest.mark.parametrize("kwargs", [
    dict(beta=100.0, bump="chart"), dict(beta=100.0, height_field="sine", bump="chart"), dict(k_u=1e3, k_v=1e3),
    dict(camera_z=1.0 + 1e-9), dict(camera_z=1.0 + 1e-9, center_b=(3.0, 3.0, 0.5)),
    dict(eps=1e-16), dict(eps=1e-16, height_field="sine"), dict(eps=0.25), dict(shininess=1e4),
])
@pytest.mark.parametrize("gradient", GRADIENTS)
def test_extreme_valid_scenes_render_finite_unit_normals(kwargs, gradient):
    scene = Scene(**kwargs)
    frame = render(scene, 48, 40, gradient=gradient)
    assert np.isfinite(frame.image).all() and frame.image.min() >= 0 and frame.image.max() <= 1
    g = gbuffer(scene, 48, 40, gradient=gradient)
    hit = g.chamber > 0
    assert np.abs(np.linalg.norm(g.Ns[hit], axis=-1) - 1).max() < 1e-12


def test_one_by_one_and_thin_frames():
    for w, h in ((1, 1), (1, 300), (300, 1)):
        frame = render(Scene(), w, h)
        assert frame.image.shape == (h, w, 3) and np.isfinite(frame.image).all()


_MEMORY = r"""
import json, sys
import numpy as np
from renderer import Scene, render

def status(key):
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) * 1024 for line in f if line.startswith(key + ":"))

render(Scene(), 8, 8)                       # the compiled kernel loaded (or compiled)
n, scratch = int(sys.argv[1]), sys.argv[2] == "1"
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")                            # reset the peak (VmHWM) to the current resident set:
before = status("VmRSS")                    # a compilation's peak before this point does not count
frame = render(Scene(), n, n)
if scratch:                                 # the wrong variant: one frame-sized scratch image
    work = np.ones((n, n, 3))
    work += 1.0
arrays = (frame.image, frame.chamber, frame.kink, frame.grad)
for a in arrays:                            # make every page of the outputs resident (zeros the
    a.view(np.uint8).reshape(-1)[::4096] = 0    # kernel never wrote are not), so they are all counted
outputs = sum(a.nbytes for a in arrays)
print(json.dumps(status("VmHWM") - before - outputs))
"""
#: Working memory allowed beyond the outputs: half of one frame-sized float32
#: channel at 2048^2 (16 MiB), a hundred times what a render gains (about 80 kB).
WORKING_MEMORY = 8 * 2**20


def _peak_growth(n, scratch):
    """Peak resident memory a fresh process gains rendering an n x n frame, beyond its outputs."""
    result = subprocess.run([sys.executable, "-c", _MEMORY, str(n), "1" if scratch else "0"], check=True,
                            capture_output=True, text=True, timeout=600, cwd=Path(__file__).parents[1])
    return json.loads(result.stdout)


def test_2048_frame_in_bounded_memory():
    """The outputs are allocated once and the kernel writes each pixel into
    them: the process's peak grows by the outputs (42 bytes per pixel with
    kink and grad) and little more.  A render that kept one scratch image
    of the frame's size would be refused by the same measurement."""
    assert _peak_growth(2048, scratch=False) < WORKING_MEMORY
    assert _peak_growth(2048, scratch=True) > WORKING_MEMORY


def test_grazing_rays_at_the_silhouette_stay_on_the_surface():
    """Rays within a hair of sphere A's silhouette: hit points still on the sphere."""
    e, R = 4.0, 1.0
    rho_sil = e * R / np.sqrt(e * e - R * R)
    theta = np.linspace(0, 2 * np.pi, 1000)
    rho = rho_sil * (1 - np.logspace(-16, -6, 1000))
    x, y = rho * np.cos(theta), rho * np.sin(theta)
    t = np.array([kernel.sphere_hit(a, b, e, 0.0, 0.0, 0.0, R) for a, b in zip(x, y)])
    hit = np.isfinite(t)
    assert hit.mean() > 0.99
    P = np.stack([t[hit] * x[hit], t[hit] * y[hit], e * (1 - t[hit])], axis=-1)
    assert np.abs(np.linalg.norm(P, axis=-1) - R).max() < 1e-12


@settings(max_examples=80, deadline=None)
@given(k=st.one_of(st.integers(1, 16).map(float), st.floats(1.0, 16.0)), k_other=st.floats(1.0, 16.0),
       component=st.sampled_from((0, 1)), which=st.floats(0.0, 1.0), other=st.floats(0.02, 0.98))
def test_points_exactly_on_a_crease(k, k_other, component, which, other):
    """A point on a crease of ridges (u = m / k_u, or v = m / k_v, as float64 represents them; the
    other coordinate off its own creases), at any frequencies: the crease flag is set, the exact
    gradient's component across the crease is 0 or one side's slope, and the central quotient,
    straddling the kink, averages the two sides to about 0.  The creases inside the chart, and u = 0
    and 1 where k_u is a whole number (u wraps; at another k_u the seam is a jump, not a crease;
    v = 0 and 1 are the poles, where the quotient is one-sided)."""
    ku, kv = (k, k_other) if component == 0 else (k_other, k)
    wraps = component == 0 and k.is_integer()
    m = round(which * k) if wraps else 1 + round(which * (math.ceil(k) - 2))
    crease = m / k
    assume(wraps or 1e-3 < crease < 1 - 1e-3)
    u, v = (np.array([crease]), np.array([other])) if component == 0 else (np.array([other]), np.array([crease]))
    assume(abs(math.sin(math.pi * (kv, ku)[component] * other)) > 0.3)
    # |h| on either side: ridges is |sine|, so its one-sided slopes are +- sine's there
    # (tests/scalar_reference.py's closed form of seed §3).
    one_sided = abs(ref.grad_exact("sine", u[0], v[0], ku, kv)[component])
    exact = pointwise.exact_gradient("ridges", u, v, ku, kv)[component][0]
    fd = pointwise.central_gradient("ridges", u, v, ku, kv, 1e-4)[component][0]
    assert pointwise.kink_band("ridges", u, v, ku, kv)[0]
    # The exact form returns 0 where the float sine is exactly 0, else one side.
    assert exact == 0.0 or abs(abs(exact) - one_sided) < 1e-9 * one_sided
    assert abs(fd) < 1e-6 * one_sided
    # A twentieth of a crease's spacing off it, both give that side's slope (|sine|'s, within the
    # quotient's truncation error).
    off = crease + (0.05 if crease < 0.5 else -0.05) / k
    u, v = (np.array([off]), v) if component == 0 else (u, np.array([off]))
    slope = abs(ref.grad_exact("sine", u[0], v[0], ku, kv)[component])
    for got, rtol in ((pointwise.exact_gradient("ridges", u, v, ku, kv), 1e-12),
                      (pointwise.central_gradient("ridges", u, v, ku, kv, 1e-4), 1e-5)):
        assert abs(abs(got[component][0]) - slope) < rtol * slope


def test_shading_goes_continuously_to_zero_at_the_terminator():
    """Sphere B (no bump), one light, Lambert only: every pixel equals
    kd albedo color max(0, N.w_hat) or 0 (cast shadow); none is lit with
    N.w <= 0, and pixels within 1e-3 of the terminator are within 1e-3 of black."""
    light = Scene().lights[0]
    scene = Scene(lights=(light,), ka=0.0, ks=0.0, beta=0.0)
    g = gbuffer(scene, 200, 200)
    image = render(scene, 200, 200).image
    b = g.chamber == 2
    w = np.asarray(light.position) - g.P[b]
    cos = np.einsum("ij,ij->i", g.N[b], w / np.linalg.norm(w, axis=-1, keepdims=True))
    lambert = scene.kd * np.asarray(scene.albedo_b)[None, :] * np.maximum(cos, 0)[:, None]
    got = image[b]
    lit = np.any(got > 0, axis=-1)
    assert np.allclose(got[lit], lambert[lit], rtol=0, atol=1e-15)
    assert not np.any(lit & (cos <= 0))
    near = (cos > 0) & (cos < 1e-3)
    assert np.all(got[near] < 1e-3)


def test_grazing_rays_at_sphere_b_silhouette_stay_on_the_surface():
    """Rays through points just inside sphere B's silhouette circle (the tangent
    points seen from the eye): hit points on the sphere to 1e-12 relative."""
    scene = Scene()
    e = scene.camera_z
    C, r = np.asarray(scene.center_b), scene.radius_b
    E = np.array([0.0, 0.0, e])
    axis = E - C
    dist2 = axis @ axis
    centre = C + r * r * axis / dist2                        # silhouette circle centre
    radius = r * np.sqrt(1 - r * r / dist2)
    a = np.cross(axis, [1.0, 0.0, 0.0]); a /= np.linalg.norm(a)
    b = np.cross(axis, a); b /= np.linalg.norm(b)
    alpha = np.linspace(0, 2 * np.pi, 500)
    shrink = 1 - np.logspace(-15, -6, 500)
    Q = centre + (radius * shrink)[:, None] * (np.cos(alpha)[:, None] * a + np.sin(alpha)[:, None] * b)
    x, y = Q[:, 0] * e / (e - Q[:, 2]), Q[:, 1] * e / (e - Q[:, 2])
    t = np.array([kernel.sphere_hit(a, b, e, *scene.center_b, r) for a, b in zip(x, y)])
    hit = np.isfinite(t)
    assert hit.mean() > 0.95
    P = np.stack([t[hit] * x[hit], t[hit] * y[hit], e * (1 - t[hit])], axis=-1)
    assert np.abs(np.linalg.norm(P - C, axis=-1) - r).max() < 1e-12 * r
