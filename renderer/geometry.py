"""Camera, ray intersection, chart and tangent frame: everything that depends on
geometry alone (seed Cell 1, ``render_numeric_bump`` up to the gradient).

Array conventions: a batch of n rays or points is a set of float64 arrays of
shape (n,), one per coordinate, or (n, 3) where stated.  A miss is t = inf,
never an exception (pbrt-v4 style).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "POLE_SIN_PHI", "WINDOW_OFFSET", "WINDOW_MARGIN",
    "image_plane", "sphere_hit", "chart", "tangent_frame", "segment_hits_sphere",
]

#: Below this value of sin(phi) the chart frame is replaced by a fixed basis
#: (seed Cell 1, ``tangent_frame``; the fallback is confessed in seed §7 item 4).
POLE_SIN_PHI = 1e-4
#: The image window is shifted down by this fraction of its half-height (seed Cell 1).
WINDOW_OFFSET = 0.15
#: The window's half-width is this multiple of sphere A's silhouette radius (seed Cell 1).
WINDOW_MARGIN = 1.25


def image_plane(radius_a, camera_z, width, height):
    """Pixel centres on the image plane z = 0.

    The half-width of the window is 1.25 times the radius e R / sqrt(e^2 - R^2)
    of sphere A's silhouette on z = 0, and the window is shifted down by 0.15
    of that half-width (seed Cell 1).  Column i and row j map to

        x_i = half (2 (i + 1/2) / width - 1),
        y_j = half (1 - 2 (j + 1/2) / height) - 0.15 half.

    Returns
    -------
    x : (width,) float64, y : (height,) float64
        World coordinates (scene units) of the pixel centres; row 0 is the top.
    """
    half = WINDOW_MARGIN * camera_z * radius_a / math.sqrt(camera_z**2 - radius_a**2)
    i = np.arange(width, dtype=np.float64)
    j = np.arange(height, dtype=np.float64)
    x = half * (2.0 * (i + 0.5) / width - 1.0)
    y = half * (1.0 - 2.0 * (j + 0.5) / height) - WINDOW_OFFSET * half
    return x, y


def sphere_hit(x, y, camera_z, center, radius):
    """Nearest positive ray parameter t of rays from the eye through (x, y, 0).

    The ray is P(t) = E + t d with E = (0, 0, camera_z) and d = (x, y, -camera_z),
    so t = 1 is the image (and floor) plane.  The quadratic a t^2 + 2 b t + c = 0
    is solved with the cancellation-free pair q = -(b + sign(b) sqrt(b^2 - a c)),
    t = q / a and t = c / q (pbrt-v4, "stable quadratic roots").

    Parameters
    ----------
    x, y : (n,) float64
        Image-plane coordinates of the rays.
    camera_z : float
    center : sequence of 3 floats
    radius : float > 0

    Returns
    -------
    t : (n,) float64
        Nearest root with t > 0, or inf where the ray misses.
    """
    ocx, ocy, ocz = 0.0 - center[0], 0.0 - center[1], camera_z - center[2]
    a = x * x + y * y + camera_z * camera_z
    b = x * ocx + y * ocy - camera_z * ocz
    c = ocx * ocx + ocy * ocy + ocz * ocz - radius * radius
    disc = b * b - a * c
    hit = disc >= 0.0
    sq = np.sqrt(np.where(hit, disc, 0.0))
    q = -(b + np.copysign(sq, b))
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = q / a
        t1 = c / q
    near = np.fmin(t0, t1)
    far = np.fmax(t0, t1)
    t = np.where(near > 0.0, near, np.where(far > 0.0, far, np.inf))
    return np.where(hit, t, np.inf)


def chart(Nx, Ny, Nz):
    """Sphere-A chart (u, v) of unit normals (seed Cell 1, ``chartA1``).

    u = (theta + pi) / (2 pi) with theta = atan2(N_y, N_x), and v = phi / pi with
    phi the polar angle from +z.  phi is computed as atan2(sin phi, N_z) with
    sin phi = hypot(N_x, N_y): the seed's acos(N_z) loses half the digits near
    the pole, where acos has an infinite derivative.

    Returns
    -------
    u, v : float64 arrays in [0, 1], the shape of the inputs.
    sin_phi : float64 array, hypot(N_x, N_y).
    """
    sin_phi = np.hypot(Nx, Ny)
    uu = (np.arctan2(Ny, Nx) + np.pi) / (2.0 * np.pi)
    vv = np.arctan2(sin_phi, Nz) / np.pi
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
    e_theta, e_phi : (n, 3) float64
    """
    regular = sin_phi > POLE_SIN_PHI
    s = np.where(regular, sin_phi, 1.0)
    zero = np.zeros_like(Nx)
    e_theta = np.stack([np.where(regular, -Ny / s, 1.0),
                        np.where(regular, Nx / s, 0.0), zero], axis=-1)
    e_phi = np.stack([np.where(regular, Nz * Nx / s, 0.0),
                      np.where(regular, Nz * Ny / s, 1.0),
                      np.where(regular, -sin_phi, 0.0)], axis=-1)
    return e_theta, e_phi


def segment_hits_sphere(P, L, center, radius):
    """Shadow predicate: does the open segment from P to the light L meet a sphere?

    Solves |P + s (L - P) - C|^2 = r^2 for s with the stable root pair and
    reports a blocker when a root lies in the open interval (0, 1) (seed Cell
    1, ``shadowed1``; "sign logic").  Depends on geometry only.

    Parameters
    ----------
    P : (n, 3) float64   surface points
    L : (3,) float64     light position
    center : (3,) float64, radius : float

    Returns
    -------
    (n,) bool
    """
    seg = L[None, :] - P
    pc = P - center[None, :]
    a = np.einsum("ij,ij->i", seg, seg)
    b = np.einsum("ij,ij->i", pc, seg)
    c = np.einsum("ij,ij->i", pc, pc) - radius * radius
    disc = b * b - a * c
    ok = (disc >= 0.0) & (a > 0.0)
    sq = np.sqrt(np.where(ok, disc, 0.0))
    q = -(b + np.copysign(sq, b))
    with np.errstate(divide="ignore", invalid="ignore"):
        s0 = q / a
        s1 = c / q
    inside = ((s0 > 0.0) & (s0 < 1.0)) | ((s1 > 0.0) & (s1 < 1.0))
    return ok & inside
