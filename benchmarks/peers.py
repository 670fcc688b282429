"""The speed peers: the chapter's scene written once as a plain branch-free array program.

What a user of Dr.Jit or JAX would write by hand, with none of the project's
code: the draft's scene (`renderer.DRAFT_SCENE`: ridges field, chart bump,
Blinn-Phong, two lights, sphere B, checker floor), a textbook ray-sphere
quadratic, central differences or the exact gradient of the ridges field, and
a frame per call returned as a NumPy (H, W, 3) float64 array.  The same
function runs on Dr.Jit's LLVM backend and on JAX (``jax.jit``, XLA CPU)
through a six-entry namespace.  `benchmarks/bench_peers.py` times it beside
`renderer.render`; it checks first that each peer draws the project's image
(within its ``AGREEMENT``), so the two are timed on the same per-pixel work.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np


def drjit_namespace():
    """The namespace over Dr.Jit's LLVM Float64 arrays, or None without the backend."""
    from renderer.backends import drjit_llvm
    llvm = drjit_llvm()
    if llvm is None:
        return None
    import drjit as dr
    F = llvm.Float64
    # dr.select of two Python floats is a single-precision array: constants enter as Float64.
    where = lambda m, a, b: dr.select(m, F(a) if isinstance(a, float) else a, F(b) if isinstance(b, float) else b)  # noqa: E731
    return SimpleNamespace(name="drjit", F=F, sin=dr.sin, cos=dr.cos, sqrt=dr.sqrt, atan2=dr.atan2,
                           where=where, abs=dr.abs, minimum=dr.minimum, maximum=dr.maximum,
                           sign=dr.sign, sum=None, eval=dr.eval, dr=dr)


def jax_namespace():
    """The namespace over jax.numpy float64 arrays (x64 switched on for the process)."""
    import jax
    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp
    return SimpleNamespace(name="jax", F=jnp.asarray, sin=jnp.sin, cos=jnp.cos, sqrt=jnp.sqrt, atan2=jnp.arctan2,
                           where=jnp.where, abs=jnp.abs, minimum=jnp.minimum, maximum=jnp.maximum,
                           sign=jnp.sign, eval=None, jax=jax)


def _scene(xp, x, y, s, gradient):
    """Linear RGB (three arrays) of the pixels at image-plane points (x, y)."""
    e = s.camera_z

    def hit(cx, cy, cz, r):              # nearest t > 0 of E + t (x, y, -e) on a sphere, or inf
        ox, oy, oz = -cx, -cy, e - cz
        a = x * x + y * y + e * e
        b = x * ox + y * oy - e * oz
        c = ox * ox + oy * oy + oz * oz - r * r
        disc = b * b - a * c
        root = xp.sqrt(xp.maximum(disc, 0.0))
        t0, t1 = (-b - root) / a, (-b + root) / a
        t = xp.where(t0 > 0.0, t0, t1)
        return xp.where((disc >= 0.0) & (t > 0.0), t, math.inf)

    ta, tb = hit(0.0, 0.0, 0.0, s.radius_a), hit(*s.center_b, s.radius_b)
    on_b = tb < ta
    t = xp.minimum(ta, tb)
    on_floor = t > 1.0
    t = xp.minimum(t, 1.0)
    on_a = ~on_b & ~on_floor
    px, py, pz = t * x, t * y, e * (1.0 - t)
    cb = s.center_b
    cx, cy, cz = xp.where(on_b, cb[0], 0.0), xp.where(on_b, cb[1], 0.0), xp.where(on_b, cb[2], 0.0)
    r = xp.where(on_b, s.radius_b, s.radius_a)
    nx, ny, nz = (px - cx) / r, (py - cy) / r, (pz - cz) / r
    nx, ny, nz = xp.where(on_floor, 0.0, nx), xp.where(on_floor, 0.0, ny), xp.where(on_floor, 1.0, nz)
    # Sphere A: chart, frame, gradient of the ridges field |sin(pi k_u u) sin(pi k_v v)|, chart bump.
    sp = xp.sqrt(nx * nx + ny * ny)
    u = (xp.atan2(ny, nx) + math.pi) / (2 * math.pi)
    v = xp.atan2(sp, nz) / math.pi
    inv = 1.0 / xp.maximum(sp, 2.0**-1022)
    pole = sp > 2.0**-1022          # the chart's frame down to float64's smallest normal, as the renderer
    etx, ety = xp.where(pole, -ny * inv, 1.0), xp.where(pole, nx * inv, 0.0)
    epx, epy, epz = xp.where(pole, nz * nx * inv, 0.0), xp.where(pole, nz * ny * inv, 1.0), xp.where(pole, -sp, 0.0)
    au, av = math.pi * s.k_u, math.pi * s.k_v
    if gradient == "exact":
        fu, fv = xp.sin(au * u), xp.sin(av * v)
        sg = xp.sign(fu * fv)
        hu, hv = sg * au * xp.cos(au * u) * fv, sg * av * fu * xp.cos(av * v)
    else:
        ep = s.eps
        h = lambda uu, vv: xp.abs(xp.sin(au * uu) * xp.sin(av * vv))  # noqa: E731
        up, um = u + ep, u - ep
        up, um = xp.where(up >= 1.0, up - 1.0, up), xp.where(um < 0.0, um + 1.0, um)
        vp, vm = xp.minimum(v + ep, 1.0), xp.maximum(v - ep, 0.0)
        hu = (h(up, v) - h(um, v)) / (2 * ep)
        hv = (h(u, vp) - h(u, vm)) / (vp - vm)
    mx, my, mz = nx + s.beta * (hu * etx + hv * epx), ny + s.beta * (hu * ety + hv * epy), nz + s.beta * hv * epz
    m = 1.0 / xp.sqrt(mx * mx + my * my + mz * mz)
    snx, sny, snz = xp.where(on_a, mx * m, nx), xp.where(on_a, my * m, ny), xp.where(on_a, mz * m, nz)
    # Albedo: sphere A, sphere B, or the checker floor.
    light = xp.sin(math.pi * x) * xp.sin(math.pi * y) >= 0.0
    base = xp.where(light, 0.85, 0.15)
    rg = base * (1.0 - s.floor_tint)
    alb = [xp.where(on_floor, f, xp.where(on_b, b, a)) for f, a, b in zip((rg, rg, base), s.albedo_a, s.albedo_b)]
    vx, vy, vz = -px, -py, e - pz
    vn = 1.0 / xp.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx * vn, vy * vn, vz * vn
    rgb = [s.ka * c + 0.0 * x for c in s.ambient]
    for light_ in s.lights:
        (lx, ly, lz), color = light_.position, light_.color
        wx, wy, wz = lx - px, ly - py, lz - pz
        w2 = wx * wx + wy * wy + wz * wz
        wn = 1.0 / xp.sqrt(w2)
        ux, uy, uz = wx * wn, wy * wn, wz * wn
        lit = (nx * wx + ny * wy + nz * wz > 0.0) & ~(~on_floor & (pz > 0.0) & (lz < 0.0))
        for (bx, by, bz), br, blocker in (((0.0, 0.0, 0.0), s.radius_a, ~on_a), (s.center_b, s.radius_b, ~on_b)):
            dx, dy, dz = lx - bx, ly - by, lz - bz
            k = dx * dx + dy * dy + dz * dz - br * br
            g = wx * dx + wy * dy + wz * dz
            lit = lit & ~(blocker & (g > 0.0) & (g < w2) & (g * g >= w2 * k))
        mu = snx * ux + sny * uy + snz * uz
        hx, hy, hz = ux + vx, uy + vy, uz + vz
        hn = 1.0 / xp.sqrt(hx * hx + hy * hy + hz * hz)
        c = xp.minimum(xp.maximum((snx * hx + sny * hy + snz * hz) * hn, 0.0), 1.0)
        c2 = c * c
        c4 = c2 * c2
        c8 = c4 * c4
        c16 = c8 * c8
        spec = c16 * c16 * s.ks
        on = lit & (mu > 0.0)
        rgb = [acc + xp.where(on, col * (mu * s.kd * a + spec), 0.0) for acc, col, a in zip(rgb, color, alb)]
    return [xp.minimum(xp.maximum(c, 0.0), 1.0) for c in rgb]


def renderer_for(xp, scene, width, height, gradient):
    """A function of no arguments returning the (H, W, 3) float64 frame, the peer on ``xp``.

    Dr.Jit: one call traces the program and evaluates it in one compiled kernel
    (cached after the first); JAX: the program is ``jax.jit``-compiled once.
    """
    from renderer.render import image_plane
    xs, ys = image_plane(scene.radius_a, scene.camera_z, width, height)
    X, Y = np.meshgrid(xs, ys)
    if xp.name == "jax":
        jx, jy = xp.F(X.ravel()), xp.F(Y.ravel())
        fn = xp.jax.jit(lambda a, b: xp.jax.numpy.stack(_scene(xp, a, b, scene, gradient), axis=-1))
        return lambda: np.asarray(fn(jx, jy)).reshape(height, width, 3)
    dx, dy = xp.F(X.ravel()), xp.F(Y.ravel())

    def frame():
        rgb = _scene(xp, dx, dy, scene, gradient)
        xp.eval(rgb)
        return np.stack([np.asarray(c) for c in rgb], axis=-1).reshape(height, width, 3)
    return frame

