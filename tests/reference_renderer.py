"""An independent, slow, scalar renderer: one pixel at a time, `math` only.

Written from the seed's equations (Cells 1 and 3, §3) with the corrections
recorded in the book's errata, and deliberately unlike renderer/: plain
per-pixel functions, the textbook quadratic formula, hand-written gradients.
It shares no code with the renderer; it reads only the fields of a Scene.
It is the check the vectorized renderer is compared against.
"""

from __future__ import annotations

import math

PI = math.pi
POLE = 1e-4          # frame fallback threshold, seed Cell 1
BAND = 0.03          # crease band half-width, seed Cell 1


def pixel_ray(scene, i, j, width, height):
    """Image-plane point (x, y) of pixel (i, j): seed Cell 1's window."""
    e, R = scene.camera_z, scene.radius_a
    half = 1.25 * e * R / math.sqrt(e * e - R * R)
    x = half * (2 * (i + 0.5) / width - 1)
    y = half * (1 - 2 * (j + 0.5) / height) - 0.15 * half
    return x, y


def ray_sphere(x, y, e, C, r):
    """Smallest positive t with |E + t (x, y, -e) - C| = r, or None."""
    d = (x, y, -e)
    o = (-C[0], -C[1], e - C[2])          # E - C
    a = d[0] ** 2 + d[1] ** 2 + d[2] ** 2
    b = 2 * (d[0] * o[0] + d[1] * o[1] + d[2] * o[2])
    c = o[0] ** 2 + o[1] ** 2 + o[2] ** 2 - r * r
    disc = b * b - 4 * a * c
    if disc < 0:
        return None
    s = math.sqrt(disc)
    # Avoid cancellation: the root of larger magnitude first, the other from c/(a t).
    q = -0.5 * (b + s) if b >= 0 else -0.5 * (b - s)
    roots = sorted(t for t in (q / a, c / q if q != 0 else math.inf) if t > 0)
    return roots[0] if roots else None


def h_value(field, u, v, ku, kv):
    if field == "sine":
        return math.sin(PI * ku * u) * math.sin(PI * kv * v)
    if field == "ridges":
        return abs(math.sin(PI * ku * u) * math.sin(PI * kv * v))
    return math.sin(2 * PI * kv * v)


def h_gradient_exact(field, u, v, ku, kv):
    """Hand-written closed forms of seed §3."""
    s1, c1 = math.sin(PI * ku * u), math.cos(PI * ku * u)
    s2, c2 = math.sin(PI * kv * v), math.cos(PI * kv * v)
    if field == "sine":
        return PI * ku * c1 * s2, PI * kv * s1 * c2
    if field == "ridges":
        p = s1 * s2
        sigma = 1.0 if p > 0 else (-1.0 if p < 0 else 0.0)
        return PI * ku * c1 * s2 * sigma, PI * kv * s1 * c2 * sigma
    return 0.0, 2 * PI * kv * math.cos(2 * PI * kv * v)


def h_gradient_central(field, u, v, ku, kv, eps):
    """Central differences: u periodic, v clamped with a one-sided quotient at the border."""
    hu = (h_value(field, (u + eps) % 1.0, v, ku, kv)
          - h_value(field, (u - eps) % 1.0, v, ku, kv)) / (2 * eps)
    if v + eps > 1.0 or v - eps < 0.0:
        vp, vm = min(1.0, v + eps), max(0.0, v - eps)
        hv = (h_value(field, u, vp, ku, kv) - h_value(field, u, vm, ku, kv)) / (vp - vm)
    else:
        hv = (h_value(field, u, v + eps, ku, kv) - h_value(field, u, v - eps, ku, kv)) / (2 * eps)
    return hu, hv


def blocked_by_sphere(P, L, C, r):
    """Seed Cell 1's sign logic: a root of the segment quadratic in (0, 1)."""
    seg = [L[k] - P[k] for k in range(3)]
    pc = [P[k] - C[k] for k in range(3)]
    a = sum(s * s for s in seg)
    if a == 0:
        return False
    b = sum(pc[k] * seg[k] for k in range(3))
    c = sum(p * p for p in pc) - r * r
    disc = b * b - a * c
    if disc < 0:
        return False
    s = math.sqrt(disc)
    return any(0 < root < 1 for root in ((-b - s) / a, (-b + s) / a))


def unit(w):
    n = math.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
    return [w[0] / n, w[1] / n, w[2] / n]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def shade(scene, P, N, Ns, albedo, blockers, floor_blocks):
    E = (0.0, 0.0, scene.camera_z)
    col = [scene.ka * a for a in scene.ambient]
    view = unit([E[k] - P[k] for k in range(3)])
    for light in scene.lights:
        if not any(light.color):
            continue
        L = light.position
        w = [L[k] - P[k] for k in range(3)]
        if dot(N, w) <= 0:                       # attached shadow, geometric normal
            continue
        if floor_blocks and P[2] * L[2] < 0:     # the floor plane separates P and L
            continue
        if any(blocked_by_sphere(P, L, C, r) for C, r in blockers):
            continue
        wh = unit(w)
        mu = dot(Ns, wh)
        if mu <= 0:
            continue                            # no Lambert and no lobe
        if scene.model == "blinn":
            spec = max(0.0, dot(Ns, unit([wh[k] + view[k] for k in range(3)]))) ** scene.shininess
        else:
            r_ = [2 * mu * Ns[k] - wh[k] for k in range(3)]
            spec = max(0.0, dot(r_, view)) ** scene.shininess
        for k in range(3):
            col[k] += light.color[k] * (scene.kd * albedo[k] * mu + scene.ks * spec)
    return [min(1.0, max(0.0, c)) for c in col]


def render_pixel(scene, i, j, width, height, gradient="exact"):
    """(rgb, chamber, kink, (h_u, h_v)) of one pixel."""
    e = scene.camera_z
    x, y = pixel_ray(scene, i, j, width, height)
    hits = []                                           # (t, code); A before B before floor
    tA = ray_sphere(x, y, e, (0.0, 0.0, 0.0), scene.radius_a)
    if tA is not None:
        hits.append((tA, 1))
    if scene.sphere_b:
        tB = ray_sphere(x, y, e, scene.center_b, scene.radius_b)
        if tB is not None:
            hits.append((tB, 2))
    if scene.floor:
        hits.append((1.0, 3))
    if not hits:
        return [0.0, 0.0, 0.0], 0, False, (0.0, 0.0)
    t, code = min(hits, key=lambda h: (h[0], h[1]))
    P = (t * x, t * y, e * (1 - t))
    A = ((0.0, 0.0, 0.0), scene.radius_a)
    B = (scene.center_b, scene.radius_b)
    kink, grad = False, (0.0, 0.0)
    if code == 1:
        N = [P[k] / scene.radius_a for k in range(3)]
        sin_phi = math.hypot(N[0], N[1])
        u = (math.atan2(N[1], N[0]) + PI) / (2 * PI)
        v = math.atan2(sin_phi, N[2]) / PI
        f, ku, kv = scene.height_field, scene.k_u, scene.k_v
        if gradient == "exact":
            grad = h_gradient_exact(f, u, v, ku, kv)
        else:
            grad = h_gradient_central(f, u, v, ku, kv, scene.eps)
        if f == "ridges":
            kink = abs(math.sin(PI * ku * u)) < BAND or abs(math.sin(PI * kv * v)) < BAND
        if scene.beta == 0:
            Ns = N
        else:
            if sin_phi > POLE:
                et = [-N[1] / sin_phi, N[0] / sin_phi, 0.0]
                ep = [N[2] * N[0] / sin_phi, N[2] * N[1] / sin_phi, -sin_phi]
            else:
                et, ep = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]
            if scene.bump == "chart":
                a_u, a_v = scene.beta * grad[0], scene.beta * grad[1]
            else:   # exact normal of the displaced sphere (R + beta h) N
                w = -scene.beta / (scene.radius_a + scene.beta * h_value(f, u, v, ku, kv))
                a_u = w * grad[0] / (2 * PI * max(sin_phi, POLE))
                a_v = w * grad[1] / PI
            Ns = unit([N[k] + a_u * et[k] + a_v * ep[k] for k in range(3)])
        rgb = shade(scene, P, N, Ns, scene.albedo_a, [B] if scene.sphere_b else [], scene.floor)
    elif code == 2:
        N = [(P[k] - scene.center_b[k]) / scene.radius_b for k in range(3)]
        rgb = shade(scene, P, N, N, scene.albedo_b, [A], scene.floor)
    else:
        base = 0.85 if math.sin(PI * P[0]) * math.sin(PI * P[1]) >= 0 else 0.15
        tint = 1 - scene.floor_tint
        rgb = shade(scene, P, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], (base * tint, base * tint, base),
                    [A, B] if scene.sphere_b else [A], False)
    return rgb, code, kink, grad


def render_reference(scene, width, height, *, gradient="exact"):
    """Render per pixel; returns (image, chamber, kink, grad) as nested lists [j][i]."""
    image, chamber, kink, grad = [], [], [], []
    for j in range(height):
        rows = [render_pixel(scene, i, j, width, height, gradient) for i in range(width)]
        image.append([r[0] for r in rows])
        chamber.append([r[1] for r in rows])
        kink.append([r[2] for r in rows])
        grad.append([list(r[3]) for r in rows])
    return image, chamber, kink, grad
