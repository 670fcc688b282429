"""The renderer's own per-pixel outputs against mpmath, for the theorems' checks.

A theorem about `renderer.formulas` says what the kernel should compute; this
module asks what it did.  For seeded random sphere-A pixels of G-buffers of
the default scene (`renderer.gbuffer`: a full frame, two frames zoomed onto the
pole, one of them inside the seed's pole cut-off sin phi <= 1e-4, and the pixels next to a
crease of a field with creases: `SOURCES`), the renderer's chart (u, v), gradient
(exact and central) and shading normal N' (both bump modes) of any registered
field (`renderer.formulas.FIELDS`) are compared with the same sympy objects
evaluated by mpmath at 30 digits, from the renderer's own inputs at that pixel
(N for the chart; u, v for the gradient; N, its frame and the gradient for N').
A wrong formula in the kernel's glue code (arguments swapped, a component
dropped, a wrong step) refutes the theorem that uses it.

Tolerances (absolute): `TOLERANCE`, a few float64 roundings of each output at
its scale; the central difference also carries the rounding of h divided by
the step (4 u |h| / eps) and of its abscissae (|h_u| u / eps).
"""

from __future__ import annotations

from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

from renderer import Scene, gbuffer
from renderer import formulas as F
from renderer.render import SPHERE_A
from renderer.ucurve import UNIT_ROUNDOFF

__all__ = ["pixels", "chart_error", "gradient_error", "normal_error", "footprint_error", "worst_of", "TOLERANCE",
           "PER_FIELD"]

#: Pixels drawn per field, a third from each source (full frame, pole ring at zoom 300 and 3e4; crease
#: neighbours as well for a field with creases): >= 200 outside the seed's pole cut-off, the 3e4 frame being inside it.
PER_FIELD = 300
#: Crease neighbours (a field with creases): the full frame's sphere-A pixels where a crease factor f
#: (`HeightField.crease_factors`) has |f| < sin(pi CREASE_BAND): for the ridges field's factors
#: sin(pi k_u u), sin(pi k_v v), those within CREASE_BAND / k_u of a zero line u = m / k_u, or
#: CREASE_BAND / k_v of v = m / k_v, a twentieth of a ridge's width about it.
CREASE_BAND = 0.05
#: Where each source's pixels lie, by sin(phi) = |(N_x, N_y)| on sphere A: (source, zoom, lowest, highest).
#: The pole frames are centred on the pole: at zoom 300 every pixel within 5e-3 of it, some inside the
#: seed's fallback radius sin phi = 1e-4 (the renderer keeps the chart's frame there); at zoom 3e4
#: every pixel within 5e-5, all inside it.
SOURCES = (("frame", 1.0, 5e-3, 1.0), ("pole-300", 300.0, 0.0, 5e-3), ("pole-3e4", 3e4, 0.0, 5e-5))
DIGITS = 30
UNIT = UNIT_ROUNDOFF
#: Absolute tolerances of the outputs at their scale (chart units; gradient per k; unit normal).
TOLERANCE = {"chart": 16 * UNIT, "gradient": 64 * UNIT, "normal": 64 * UNIT}


@lru_cache(maxsize=None)
def _frames(field, gradient, bump):
    """G-buffers of the default scene (``field``, a `HeightField`; ``gradient``, ``bump``) with sphere A's
    radius 0.8, not 1, so that a factor R lost anywhere shows, one per `SOURCES`: 128², and the pole at
    zoom 300 and 3e4 (48²)."""
    scene = Scene(height_field=field.name, bump=bump, beta=0.35 if bump == "chart" else 0.3, radius_a=0.8)
    return scene, [gbuffer(scene, 48 if zoom > 1 else 128, 48 if zoom > 1 else 128, gradient=gradient, zoom=zoom)
                   for _, zoom, _, _ in SOURCES]


def crease_neighbours(field, uv, k_u, k_v):
    """Whether each chart point (``uv``, float64 (..., 2)) is next to a crease of ``field`` (a
    `HeightField`): where one of its crease factors f has |f| < sin(pi `CREASE_BAND`) (bool,
    ``uv``'s shape less its last axis; all False for a field without creases)."""
    near = np.zeros(uv.shape[:-1], dtype=bool)
    for f in field.crease_factors:
        value = sp.lambdify((F.u, F.v), f.xreplace({F.k_u: k_u, F.k_v: k_v}), modules="numpy")(uv[..., 0], uv[..., 1])
        near |= np.abs(value) < np.sin(np.pi * CREASE_BAND)
    return near


def pixels(field, gradient="exact", bump="chart", seed=0):
    """The sampled sphere-A pixels as a dict of arrays (one row per pixel):
    N, Ns, P (k, 3), uv, grad (k, 2), xy (k, 4: the pixel centre x, y and
    the spacings dx, dy), and source (k,: the `SOURCES` name of the G-buffer the
    pixel is from, or "crease" for the crease neighbours), from the full frame,
    the two pole frames and (a field with creases) the crease neighbours of the full frame
    (`crease_neighbours`); and the `Scene`.  ``field``: a name of `formulas.FIELDS`."""
    record = F.FIELDS[field]
    scene, frames = _frames(record, gradient, bump)
    rng = np.random.default_rng(seed)
    picked = {name: [] for name in ("N", "Ns", "uv", "grad", "P", "xy", "source")}
    for (source, *_), g in zip(SOURCES, frames):
        X, Y = np.meshgrid(g.x, g.y)
        spacing = (g.x[1] - g.x[0], g.y[0] - g.y[1])
        g = dict(N=g.N, Ns=g.Ns, uv=g.uv, grad=g.grad, P=g.P, chamber=g.chamber,
                 xy=np.stack([X, Y, np.full(X.shape, spacing[0]), np.full(X.shape, spacing[1])], axis=-1))
        on_a = g["chamber"] == SPHERE_A
        where = [(source, np.flatnonzero(on_a))]
        if source == "frame" and record.crease_factors:
            where.append(("crease", np.flatnonzero(on_a & crease_neighbours(record, g["uv"], scene.k_u, scene.k_v))))
        for name, idx in where:
            take = rng.choice(idx, size=min(PER_FIELD // 3, idx.size), replace=False)
            for key in picked:
                picked[key].append(np.full((take.size, 1), name) if key == "source"
                                   else g[key].reshape(-1, g[key].shape[-1])[take])
    return scene, {name: np.concatenate(rows)[:, 0] if name == "source" else np.concatenate(rows)
                   for name, rows in picked.items()}


def worst_of(check, cases):
    """(largest error, pixels compared, fields covered) of ``check(*case)`` -> (error, count) over
    ``cases``, each case's first item a field's name; covered: the fields with pixels compared."""
    results = [check(*case) for case in cases]
    covered = tuple(dict.fromkeys(case[0] for case, (_, n) in zip(cases, results) if n > 0))
    return max(err for err, _ in results), sum(n for _, n in results), covered


@lru_cache(maxsize=None)
def _mp(exprs, args):
    """One mpmath function of ``args`` returning every expression of ``exprs``, their common
    subexpressions computed once (``cse``)."""
    return sp.lambdify(args, list(exprs), modules="mpmath", cse=True)


def _eval(exprs, args, rows):
    """Each expression of ``exprs`` at each row of float64 ``rows`` (columns = ``args``), in mpmath."""
    fn = _mp(tuple(exprs), tuple(args))
    out = np.empty((rows.shape[0], len(exprs)))
    with mpmath.workdps(DIGITS):
        for i, row in enumerate(rows):
            out[i] = [float(x) for x in fn(*[mpmath.mpf(float(x)) for x in row])]
    return out


def chart_error(field, corrupt=None):
    """Worst |uv - CHART(N)| over the sampled pixels (``corrupt``: a function applied to
    the renderer's uv first, to show the check failing on a wrong kernel)."""
    _, px = pixels(field)
    uv = px["uv"] if corrupt is None else corrupt(px["uv"])
    ref = _eval(F.CHART[:2], (F.N_x, F.N_y, F.N_z), px["N"])
    return float(np.max(np.abs(uv - ref))), uv.shape[0]


def gradient_error(field, gradient, corrupt=None):
    """Worst |grad - reference| / bound over the sampled pixels: the exact gradient
    against the field's `HeightField.gradient`, central against its `HeightField.central` (stencil
    included) at the scene's eps, and footprint against the central difference at each pixel's own steps
    (each pixel held to the bound its own smaller step gives), all at the renderer's own (u, v); and the
    count.  A value <= 1 is within tolerance."""
    record = F.FIELDS[field]
    scene, px = pixels(field, gradient)
    grad = px["grad"] if corrupt is None else corrupt(px["grad"])
    consts = {F.k_u: scene.k_u, F.k_v: scene.k_v}
    if gradient == "exact":
        exprs = [e.xreplace(consts) for e in record.gradient]
        ref = _eval(exprs, (F.u, F.v), px["uv"])
        bound = TOLERANCE["gradient"] * F.gradient_scale(scene.k_u, scene.k_v, record)
    elif gradient == "footprint":
        # The steps from formulas.FOOTPRINT at the pixel (its frame from TANGENT_FRAME), then the central difference.
        # sin(phi) and the frame enter as arguments, evaluated from CHART and TANGENT_FRAME first:
        # substituted into FOOTPRINT, they would make sympy re-decide each Max it meets (seconds).
        n_sin = np.hstack([px["N"], _eval([F.CHART[2]], (F.N_x, F.N_y, F.N_z), px["N"])])
        n_sin_frame = np.hstack([n_sin, _eval(F.TANGENT_FRAME, (F.N_x, F.N_y, F.N_z, F.sin_phi), n_sin)])
        footprint = [e.xreplace({F.R: scene.radius_a, F.camera_z: scene.camera_z}) for e in F.FOOTPRINT]
        steps = _eval(footprint, (F.N_x, F.N_y, F.N_z, F.sin_phi) + F.e_theta + F.e_phi + tuple(F.P)
                      + (F.x, F.y, F.dx, F.dy), np.hstack([n_sin_frame, px["P"], px["xy"]]))
        exprs = [e.xreplace(dict(F.STENCIL_POINTS)).xreplace(consts) for e in record.central]
        ref = _eval(exprs, (F.u, F.v, F.eps_u, F.eps_v), np.hstack([px["uv"], steps]))
        scale = F.gradient_scale(scene.k_u, scene.k_v, record)
        bound = TOLERANCE["gradient"] * scale + 4 * UNIT * (1 + scale) / steps.min(axis=1, keepdims=True)
    else:
        stencil = dict(F.STENCIL_POINTS)
        exprs = [e.xreplace(stencil).xreplace({F.eps_u: scene.eps, F.eps_v: scene.eps, **consts})
                 for e in record.central]
        ref = _eval(exprs, (F.u, F.v), px["uv"])
        scale = F.gradient_scale(scene.k_u, scene.k_v, record)
        bound = TOLERANCE["gradient"] * scale + 4 * UNIT * (1 + scale) / scene.eps
    return float(np.max(np.abs(grad - ref) / bound)), grad.shape[0]


def normal_error(field, bump, corrupt=None):
    """Worst |Ns - PERTURBED_NORMAL[bump]| over the sampled pixels, the formula fed the
    renderer's N, the frame of N (`formulas.TANGENT_FRAME`, fallback included), its
    gradient and h at its (u, v); and the count.  ``corrupt`` is applied to the
    gradient (k, 2) the reference is fed: a kernel that used it so would differ."""
    scene, px = pixels(field, "exact", bump)
    Ns = px["Ns"]
    sin_phi = F.CHART[2]
    frame = [c.xreplace({F.sin_phi: sin_phi}) for c in F.TANGENT_FRAME]
    normal = sp.Matrix(F.PERTURBED_NORMAL[bump]).xreplace(
        {**dict(zip(F.e_theta + F.e_phi, frame)), F.sin_phi: sin_phi, F.R: scene.radius_a, F.beta: scene.beta,
         F.h: F.FIELDS[field].expr.xreplace({F.k_u: scene.k_u, F.k_v: scene.k_v})})
    args = (F.N_x, F.N_y, F.N_z, F.h_u, F.h_v, F.u, F.v)
    grad = px["grad"] if corrupt is None else corrupt(px["grad"])
    ref = _eval(list(normal), args, np.hstack([px["N"], grad, px["uv"]]))
    return float(np.max(np.abs(Ns - ref))), Ns.shape[0]


def footprint_error(half, size=96):
    """Worst relative difference between the kernel's footprint steps
    (`formulas.FOOTPRINT` through `renderer.pointwise.footprint`) and pbrt-v4's
    bump rule written here: the rays through the next column and row meet the
    tangent plane at P (``ComputeDifferentials``), (du/dx, dv/dx) and (du/dy,
    dv/dy) solve the 2x2 least squares against dP/du = 2 pi R sin(phi) e_theta,
    dP/dv = pi R e_phi (the chart's rates, theorem `chart`), and du = ``half``
    (|du/dx| + |du/dy|) (``BumpMap``), 0.0005 where that is 0 (``BumpMap``) or not
    below 1e8 (``ComputeDifferentials`` clamps to 1e8), and at most 0.25 (the stencil's
    quarter period): constants written here, not read from `formulas`, so that a changed
    one there is a difference here; over the sphere-A pixels of the default frame (size²)
    and of a pole zoom, with sphere A's radius 0.8 (not 1, so that a lost factor R
    shows); and the count."""
    from renderer import pointwise
    scene = Scene(radius_a=0.8)
    e, R = scene.camera_z, scene.radius_a
    fallback, cap, limit = 0.0005, 0.25, 1e8
    worst, count = 0.0, 0
    for zoom in (1.0, 300.0):
        g = gbuffer(scene, size, size, zoom=zoom)
        on_a = g.chamber == SPHERE_A
        X, Y = np.meshgrid(g.x, g.y)
        x, y, P, N = X[on_a], Y[on_a], g.P[on_a], g.N[on_a]
        dx, dy = g.x[1] - g.x[0], g.y[0] - g.y[1]
        sin_phi = np.hypot(N[:, 0], N[:, 1])
        et, ep = (np.stack(t, axis=1) for t in pointwise.tangent_frame(N[:, 0], N[:, 1], N[:, 2], sin_phi))
        dpdu, dpdv = (2 * np.pi * R * sin_phi)[:, None] * et, np.pi * R * ep
        E = np.array([0.0, 0.0, e])
        deriv = []
        for sx, sy in ((dx, 0.0), (0.0, dy)):
            d = np.stack([x + sx, y + sy, np.full(x.shape, -e)], axis=1)
            t = np.einsum("ij,ij->i", N, P - E) / np.einsum("ij,ij->i", N, d)
            dp = E + t[:, None] * d - P
            A = np.stack([dpdu, dpdv], axis=2)                       # (k, 3, 2)
            deriv.append((np.linalg.pinv(A) @ dp[:, :, None])[:, :, 0])       # least squares, per pixel
        steps = []
        for k in range(2):
            s = half * (np.abs(deriv[0][:, k]) + np.abs(deriv[1][:, k]))
            steps.append(np.where((s > 0) & (s < limit), np.minimum(s, cap), fallback))
        got = pointwise.footprint(x, y, dx, dy, e, P.T, N.T, et.T, ep.T, R, sin_phi)
        for want, have in zip(steps, got):
            worst = max(worst, float(np.max(np.abs(have - want) / want)))
        count += int(x.size)
    # At the pole (sin phi = 0) u's footprint is infinite, so its step is the fallback; no pixel centre of
    # a frame lands there.
    one, pole = np.zeros(1), np.array([[0.0], [0.0], [R]])
    du = pointwise.footprint(one, one, 1e-3, -1e-3, e, pole, pole / R, np.array([[1.0], [0.0], [0.0]]),
                             np.array([[0.0], [1.0], [0.0]]), R, one)[0]
    worst = max(worst, float(abs(du[0] - fallback) / fallback))
    return worst, count + 1
