"""Camera, ray intersection, chart and tangent frame: everything that depends on
geometry alone (seed Cell 1, ``render_numeric_bump`` up to the gradient).

Array conventions: a batch of n rays or points is a set of float64 arrays of
shape (n,), one per coordinate, or (n, 3) where stated.  A miss is t = inf,
never an exception (pbrt-v4 style).
"""

from __future__ import annotations

import math

import numpy as np

from . import detmath

__all__ = [
    "POLE_SIN_PHI", "WINDOW_OFFSET", "WINDOW_MARGIN",
    "image_plane", "sphere_hit", "chart", "tangent_frame", "segment_hits_sphere",
    "projected_bounds", "BOUNDS_MARGIN",
]

#: Below this value of sin(phi) the chart frame is replaced by a fixed basis
#: (seed Cell 1, ``tangent_frame``; the fallback is confessed in seed §7 item 4).
POLE_SIN_PHI = 1e-4
#: The image window is shifted down by this fraction of its half-height (seed Cell 1).
WINDOW_OFFSET = 0.15
#: The window's half-width is this multiple of sphere A's silhouette radius (seed Cell 1).
WINDOW_MARGIN = 1.25


def image_plane(radius_a, camera_z, width, height, zoom=1.0):
    """Pixel centres on the image plane z = 0.

    The half-width of the window is 1.25 times the radius e R / sqrt(e^2 - R^2)
    of sphere A's silhouette on z = 0, and the window is shifted down by 0.15
    of that half-width (seed Cell 1).  Column i and row j map to

        x_i = half (2 (i + 1/2) / width - 1),
        y_j = half (1 - 2 (j + 1/2) / height) - 0.15 half,

    both divided by ``zoom`` (>= 1): the window is magnified about the optical
    axis x = y = 0, where sphere A's pole is seen (the §4 simulator's "magnify
    the pole").  ``zoom = 1`` is the seed's window, bit for bit.

    Returns
    -------
    x : (width,) float64, y : (height,) float64
        World coordinates (scene units) of the pixel centres; row 0 is the top.
    """
    half = WINDOW_MARGIN * camera_z * radius_a / math.sqrt(camera_z**2 - radius_a**2)
    i = np.arange(width, dtype=np.float64)
    j = np.arange(height, dtype=np.float64)
    x = half * (2.0 * (i + 0.5) / width - 1.0) / zoom
    y = (half * (1.0 - 2.0 * (j + 0.5) / height) - WINDOW_OFFSET * half) / zoom
    return x, y


#: Relative widening of `projected_bounds`' box: rays or shadow rays this far
#: outside the exact cone miss the sphere by a margin about 1e8 times larger
#: than the rounding error of `sphere_hit` and `segment_hits_sphere`.
BOUNDS_MARGIN = 1e-7


def projected_bounds(apex, center, radius):
    """Box on the plane z = 0 holding the central projection of a sphere from ``apex``.

    A line through the apex A meets the sphere (C, r) exactly when it lies in
    the cone tangent to the sphere, and the cone cuts z = 0 in a conic.  Its
    extent in x is fixed by the two tangent planes through A that contain the
    y direction: the plane x - A_x = m (A_z - z) is at distance r from C when

        m^2 (D^2 - r^2) - 2 m c D + c^2 - r^2 = 0,  c = C_x - A_x, D = A_z - C_z,

    so x = A_x + m A_z at the two roots m = (c D +- r sqrt(c^2 + D^2 - r^2)) /
    (D^2 - r^2); likewise in y.  Used to intersect only the rays (apex = the
    eye) or trace only the floor's shadow rays (apex = a light) that can meet
    the sphere; the box is widened by `BOUNDS_MARGIN` of its size and distance.

    Parameters
    ----------
    apex, center : sequences of 3 floats (scene units); radius : float > 0

    Returns
    -------
    (x_min, x_max, y_min, y_max) : four floats, or None when the sphere is not
    wholly below the apex (A_z - C_z <= r) or the apex is not above z = 0:
    then the projection is unbounded or the cone opens upward, and the caller
    must test every point.

    Raises
    ------
    ValueError
        If ``radius`` is not a finite number > 0.

    Source: derived here from the planes through the apex tangent to the
    sphere (the cone of seed Cell 1's rays and shadow rays, not in the seed);
    tests/test_culling.py checks it against `sphere_hit` and
    `segment_hits_sphere` on random spheres.
    """
    if not (math.isfinite(radius) and radius > 0.0):
        raise ValueError(f"radius must be a finite number > 0, got {radius!r}")
    D = apex[2] - center[2]
    den = D * D - radius * radius
    if not (D > radius and den > 0.0 and apex[2] > 0.0):
        return None
    out = []
    for axis in (0, 1):
        c = center[axis] - apex[axis]
        root = radius * math.sqrt(c * c + den)
        lo, hi = (c * D - root) / den, (c * D + root) / den
        a, b = apex[axis] + lo * apex[2], apex[axis] + hi * apex[2]
        pad = BOUNDS_MARGIN * (abs(a) + abs(b) + (hi - lo) * apex[2] + abs(apex[axis]) + apex[2])
        out += [a - pad, b + pad]
    return tuple(out)


def sphere_hit(x, y, camera_z, center, radius):
    """Nearest positive ray parameter t of rays from the eye through (x, y, 0).

    The ray is P(t) = E + t d with E = (0, 0, camera_z) and d = (x, y, -camera_z),
    so t = 1 is the image (and floor) plane.  The quadratic a t^2 + 2 b t + c = 0
    is solved with the cancellation-free pair q = -(b + sign(b) sqrt(b^2 - a c)),
    t = q / a and t = c / q (pbrt-v4, "stable quadratic roots").

    Parameters
    ----------
    x, y : float64 arrays of broadcastable shapes
        Image-plane coordinates of the rays: (n,) and (n,), or a row of
        columns (m,) and a column of rows (k, 1) for a (k, m) block of pixels
        (each value is then computed once per row or column; the results are
        the same bits as for the flattened block).
    camera_z : float
    center : sequence of 3 floats
    radius : float > 0

    Returns
    -------
    t : float64 array of the broadcast shape of x and y
        Nearest root with t > 0, or inf where the ray misses.
    """
    ocx, ocy, ocz = 0.0 - center[0], 0.0 - center[1], camera_z - center[2]
    a = x * x + y * y + camera_z * camera_z
    b = x * ocx + y * ocy - camera_z * ocz
    c = ocx * ocx + ocy * ocy + ocz * ocz - radius * radius
    # Discriminant from the distance of the centre to the ray's line,
    # b^2 - a c = a (r^2 - |oc - (b / a) d|^2): no cancellation of two large
    # squares when the camera is far away (Haines et al., Ray Tracing Gems,
    # ch. 7, "Precision improvements for ray/sphere intersection").
    f = b / a
    lx, ly, lz = ocx - f * x, ocy - f * y, ocz + f * camera_z
    disc = a * (radius * radius - (lx * lx + ly * ly + lz * lz))
    t = np.full(disc.shape, np.inf)
    idx = np.flatnonzero(disc >= 0.0)
    if idx.size == 0:
        return t
    bi = b.reshape(-1)[idx]
    q = -(bi + np.copysign(np.sqrt(disc.reshape(-1)[idx]), bi))
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = q / a.reshape(-1)[idx]
        t1 = c / q
    near = np.fmin(t0, t1)
    far = np.fmax(t0, t1)
    t.reshape(-1)[idx] = np.where(near > 0.0, near, np.where(far > 0.0, far, np.inf))
    return t


def chart(Nx, Ny, Nz):
    """Sphere-A chart (u, v) of unit normals (seed Cell 1, ``chartA1``).

    u = (theta + pi) / (2 pi) with theta = atan2(N_y, N_x), and v = phi / pi with
    phi the polar angle from +z.  phi is computed as atan2(sin phi, N_z) with
    sin phi = sqrt(N_x^2 + N_y^2): the seed's acos(N_z) loses half the digits
    near the pole, where acos has an infinite derivative.  atan2 is
    `renderer.detmath.atan2` and the square root is taken of the sum of
    squares (not hypot), so that (u, v) are the same bits in the §4
    simulator's JavaScript: the central differences amplify their last bit.

    Returns
    -------
    u, v : float64 arrays in [0, 1], the shape of the inputs.
    sin_phi : float64 array, sqrt(N_x^2 + N_y^2).
    """
    sin_phi = np.sqrt(Nx * Nx + Ny * Ny)
    # Both angles in one call (half the array operations' overhead).
    theta, phi = detmath.atan2(np.stack((Ny, sin_phi)), np.stack((Nx, Nz)))
    uu = (theta + np.pi) / (2.0 * np.pi)
    vv = phi / np.pi
    return uu, vv, sin_phi


def tangent_frame(Nx, Ny, Nz, sin_phi):
    """The chart's orthonormal tangent pair (seed §3) with its pole fallback.

        e_theta = (-N_y, N_x, 0) / sin phi,
        e_phi   = (N_z N_x, N_z N_y, -sin^2 phi) / sin phi,

    equal to dN/dtheta / sin phi and dN/dphi.  Where sin phi <= 1e-4 the frame
    is replaced by the seed's fixed basis e_theta = (1, 0, 0), e_phi = (0, 1, 0)
    (seed Cell 1; seed §7 item 4).

    Returns
    -------
    e_theta, e_phi : triples of (n,) float64 arrays (x, y, z components)
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / sin_phi
        zx = Nz * inv
        e_theta = (-Ny * inv, Nx * inv, np.zeros_like(Nx))
        e_phi = (zx * Nx, zx * Ny, -sin_phi)
    # The few pixels at the pole get the fixed basis (indexing, not np.where
    # over every pixel).
    pole = np.flatnonzero(~(sin_phi > POLE_SIN_PHI))
    if pole.size:
        for arr, value in zip(e_theta + e_phi, (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)):
            arr[pole] = value
    return e_theta, e_phi


def segment_hits_sphere(wx, wy, wz, w2, L, center, radius):
    """Shadow predicate: does the segment from a point P to the light L meet a sphere?

    With u = P - L (the caller passes w = L - P = -u and w2 = |w|^2) and
    d = C - L, the segment is L + tau u, tau in (0, 1), and meets the sphere
    where tau^2 |u|^2 - 2 tau (u . d) + |d|^2 - r^2 = 0.  For a light and a
    point both outside the sphere the roots share a sign and the point lies
    outside the root interval, so a root falls in (0, 1) exactly when

        (u . d)^2 >= |u|^2 (|d|^2 - r^2)   (the ray from L meets the sphere),
        0 < u . d < |u|^2                  (ahead of L, and the chord ends before P).

    A light inside the sphere is blocked from every outside point; a light on
    the sphere is blocked where the chord from it, tau = 2 (u . d) / |u|^2, ends
    before P.  This is the
    seed's quadratic "sign logic" test (seed Cell 1, ``shadowed1``) solved once
    per light instead of once per point; it depends on geometry only.

    Parameters
    ----------
    wx, wy, wz : (n,) float64   components of L - P
    w2 : (n,) float64           |L - P|^2
    L : sequence of 3 floats    light position
    center : sequence of 3 floats, radius : float

    Returns
    -------
    (n,) bool
    """
    dx, dy, dz = L[0] - center[0], L[1] - center[1], L[2] - center[2]
    k = dx * dx + dy * dy + dz * dz - radius * radius
    if k < 0.0:
        return np.ones(wx.shape, dtype=bool)
    g = wx * dx + wy * dy + wz * dz          # = u . d
    if k == 0.0:
        # Light on the sphere: roots tau = 0 (the light, excluded) and tau = 2 g / |u|^2.
        return (g > 0.0) & (2.0 * g < w2)
    blocked = (g > 0.0) & (g < w2)
    idx = np.flatnonzero(blocked)
    gi = g[idx]
    blocked[idx] = gi * gi >= w2[idx] * k
    return blocked
