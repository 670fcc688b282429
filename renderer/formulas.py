"""Every bump-mapping formula the render kernel evaluates, written once as sympy objects.

This module is the single source of sphere A's mathematics (height fields,
gradients, stencil, crease band, chart, frame, perturbed normals, footprint);
the ray-sphere hit, the shadow test and the shading are written by hand in
renderer/kernel.py and renderer/js/render.js, held together by tests.  Nothing
imports it at render time: `renderer.codegen` prints each entry of
`FUNCTIONS` as a scalar Python function that numba compiles
(renderer/generated.py, which the kernel calls) and as a JavaScript function
of the §4 simulator (``formulas.js``, generated when the simulator is
bundled); tests/test_codegen.py regenerates both and compares.
proofs/ proves its theorems about these same objects.

What lives here (seed §2, §3 and Cell 1, with the project's corrections):

* the three height fields h(u, v) and their exact gradients (sympy's
  derivatives), and the ridges' crease band;
* the chart (u, v) of a unit normal N of sphere A, and sin(phi);
* the tangent frame (e_theta, e_phi) with its pole fallback;
* the perturbed normal of both bump modes ("chart": the seed's formula;
  "surface": the normal of the displaced sphere P = (R + beta h) N);
* the central-difference stencil (u wraps, v clamps with a one-sided quotient);
* the pixel footprint in (u, v), the step of ``gradient="footprint"``
  (pbrt-v4's bump-mapping rule).
"""

from __future__ import annotations

import sympy as sp

__all__ = [
    "u", "v", "k_u", "k_v", "HEIGHT", "GRADIENT", "RIDGE_FACTORS", "KINK_BAND",
    "KINK_BAND_HALF_WIDTH", "N_x", "N_y", "N_z", "sin_phi", "CHART", "POLE_SIN_PHI",
    "TANGENT_FRAME", "FALLBACK_FRAME", "beta", "R", "h", "h_u", "h_v", "BUMP", "PERTURBED_NORMAL",
    "eps_u", "eps_v", "u_p", "u_m", "v_p", "v_m", "STENCIL_POINTS", "CENTRAL", "FOOTPRINT",
    "FOOTPRINT_FALLBACK", "FOOTPRINT_MAX", "FOOTPRINT_LIMIT", "FUNCTIONS", "FIELD_CODES",
]

# ---------------------------------------------------------------- height fields
#: Chart coordinates and frequencies.  Real, so that d|f|/du = sign(f) f'.
u, v, k_u, k_v = sp.symbols("u v k_u k_v", real=True)

#: The ridges' two factors; their zero lines u = m/k_u, v = m/k_v are its creases.
RIDGE_FACTORS = (sp.sin(sp.pi * k_u * u), sp.sin(sp.pi * k_v * v))

#: The three height fields of seed §2.
HEIGHT = {
    "sine": RIDGE_FACTORS[0] * RIDGE_FACTORS[1],
    "ridges": sp.Abs(RIDGE_FACTORS[0] * RIDGE_FACTORS[1]),
    "rings": sp.sin(2 * sp.pi * k_v * v),
}
#: The kernel's integer code of each field (its order in `HEIGHT`).
FIELD_CODES = {name: i for i, name in enumerate(HEIGHT)}

#: (h_u, h_v) of each field: sympy's derivatives of `HEIGHT`.  For ridges
#: sign(f) f', which on the creases is one of the one-sided derivatives (or 0
#: where the float64 factor is exactly 0).
GRADIENT = {name: (sp.diff(f, u), sp.diff(f, v)) for name, f in HEIGHT.items()}

#: Half-width of the seed's crease band (seed Cell 1, ``height1``).
KINK_BAND_HALF_WIDTH = sp.Float(0.03)
#: The crease flag: within the band around a zero line of either factor.
#: Only ridges has creases; the other fields' flag is false.
KINK_BAND = {name: (sp.Or(sp.Abs(RIDGE_FACTORS[0]) < KINK_BAND_HALF_WIDTH,
                          sp.Abs(RIDGE_FACTORS[1]) < KINK_BAND_HALF_WIDTH)
                    if name == "ridges" else sp.false) for name in HEIGHT}

# ------------------------------------------------------------------------ chart
#: Components of sphere A's unit normal N = P / R, and sin(phi) = |(N_x, N_y)|.
N_x, N_y, N_z = sp.symbols("N_x N_y N_z", real=True)
sin_phi = sp.Symbol("sin_phi", nonnegative=True)

#: (u, v, sin phi) of a unit normal (seed Cell 1, ``chartA1``): u = (theta + pi)
#: / 2 pi with theta = atan2(N_y, N_x), v = phi / pi.  phi = atan2(sin phi, N_z),
#: not the seed's acos(N_z), which loses half the digits near the poles.
CHART = ((sp.atan2(N_y, N_x) + sp.pi) / (2 * sp.pi),
         sp.atan2(sp.sqrt(N_x**2 + N_y**2), N_z) / sp.pi,
         sp.sqrt(N_x**2 + N_y**2))

# ---------------------------------------------------------------- tangent frame
#: Below this sin(phi) the frame is the fixed basis (seed Cell 1; seed §7 item 4).
POLE_SIN_PHI = sp.Float(1e-4)
#: The fixed basis used at the poles: e_theta = (1, 0, 0), e_phi = (0, 1, 0).
FALLBACK_FRAME = (1, 0, 0, 0, 1, 0)
_frame = (-N_y / sin_phi, N_x / sin_phi, sp.Float(0),
          N_z * N_x / sin_phi, N_z * N_y / sin_phi, -sin_phi)
#: (e_theta, e_phi) = (dN/dtheta / sin phi, dN/dphi), six components, with the
#: pole fallback (seed §3).
TANGENT_FRAME = tuple(sp.Piecewise((c, sin_phi > POLE_SIN_PHI), (sp.Float(f), True))
                      for c, f in zip(_frame, FALLBACK_FRAME))

# ------------------------------------------------------------- perturbed normal
beta, R, h, h_u, h_v = sp.symbols("beta R h h_u h_v", real=True)
e_theta = sp.symbols("et_x et_y et_z", real=True)
e_phi = sp.symbols("ep_x ep_y ep_z", real=True)
_w = -beta / (R + beta * h)
#: Coefficients (b_u, b_v) of M = N + b_u e_theta + b_v e_phi, per bump mode.
#: "chart": the seed's N' formula.  "surface": the normal of P = (R + beta h) N,
#: with h_theta = h_u / 2 pi and h_phi = h_v / pi (theorem bump-vs-displacement);
#: sin(phi) is floored at the pole cut-off, where the chart frame is replaced.
BUMP = {
    "chart": (beta * h_u, beta * h_v),
    "surface": (_w * h_u / (2 * sp.pi * sp.Max(sin_phi, POLE_SIN_PHI)), _w * h_v / sp.pi),
}
#: N' = M / |M| per bump mode, a function of N, the frame, the gradient and
#: (surface) h, R and sin(phi).
PERTURBED_NORMAL = {}
for _mode, (_bu, _bv) in BUMP.items():
    _M = [n + _bu * a + _bv * b for n, a, b in zip((N_x, N_y, N_z), e_theta, e_phi)]
    _norm = sp.sqrt(sum(m * m for m in _M))
    PERTURBED_NORMAL[_mode] = tuple(m / _norm for m in _M)

# ------------------------------------------------------ central-difference stencil
eps_u, eps_v = sp.symbols("eps_u eps_v", positive=True)
u_p, u_m, v_p, v_m = sp.symbols("u_p u_m v_p v_m", real=True)
#: The stencil's sample points for u, v in [0, 1] and steps in (0, 1): u wraps
#: (one exact subtraction or addition: the chart is periodic in u), v clamps
#: to [0, 1] (seed Cell 1, ``grad_numeric``).
STENCIL_POINTS = (
    (u_p, sp.Piecewise((u + eps_u - 1, u + eps_u >= 1), (u + eps_u, True))),
    (u_m, sp.Piecewise((u - eps_u + 1, u - eps_u < 0), (u - eps_u, True))),
    (v_p, sp.Min(1, v + eps_v)),
    (v_m, sp.Max(0, v - eps_v)),
)
#: Where v clamps the quotient is one-sided, divided by the clamped distance.
_den_v = sp.Piecewise((v_p - v_m, sp.Or(v + eps_v > 1, v - eps_v < 0)), (2 * eps_v, True))
#: Central differences (h_u, h_v) of each field in terms of the stencil points.
CENTRAL = {name: ((f.subs(u, u_p) - f.subs(u, u_m)) / (2 * eps_u),
                  (f.subs(v, v_p) - f.subs(v, v_m)) / _den_v) for name, f in HEIGHT.items()}

# ------------------------------------------------------------------- footprint
x, y, dx, dy, camera_z = sp.symbols("x y dx dy camera_z", real=True)
P = sp.symbols("P_x P_y P_z", real=True)
#: pbrt-v4's fallback step where the footprint is 0 (or undefined), and the
#: largest step the stencil accepts (u +- eps stays a quarter period apart).
FOOTPRINT_FALLBACK, FOOTPRINT_MAX = sp.Float(0.0005), sp.Float(0.25)
#: pbrt-v4 clamps |du/dx| to 1e8 and zeroes a non-finite one (at the pole
#: sin phi = 0, or a ray grazing the tangent plane); here a footprint that is
#: not below 1e8 (or is NaN) takes the fallback step.
FOOTPRINT_LIMIT = sp.Float(1e8)


def _ray_differential(sx, sy):
    """dp: where the ray through the neighbouring pixel (x + sx, y + sy) meets
    the tangent plane at P, minus P (pbrt-v4, ``ComputeDifferentials``)."""
    d = (x + sx, y + sy, -camera_z)
    E = (0, 0, camera_z)
    t = sum(n * (p - e) for n, p, e in zip((N_x, N_y, N_z), P, E)) / \
        sum(n * c for n, c in zip((N_x, N_y, N_z), d))
    return [e + t * c - p for e, c, p in zip(E, d, P)]


def _footprint():
    # dP/du = 2 pi R sin(phi) e_theta and dP/dv = pi R e_phi are orthogonal, so
    # pbrt's least-squares solve for du/dx reduces to one projection each.
    steps = []
    for axis, scale in ((e_theta, 2 * sp.pi * R * sin_phi), (e_phi, sp.pi * R)):
        d = [sum(a * c for a, c in zip(axis, _ray_differential(*s))) / scale
             for s in ((dx, 0), (0, dy))]
        half = (sp.Abs(d[0]) + sp.Abs(d[1])) / 2
        # Min left unevaluated: sympy would try to order its arguments (0.2 s at every import), and
        # the printed code is the same.
        steps.append(sp.Piecewise((sp.Min(half, FOOTPRINT_MAX, evaluate=False),
                                   sp.And(half > 0, half < FOOTPRINT_LIMIT)), (FOOTPRINT_FALLBACK, True)))
    return tuple(steps)


#: (eps_u, eps_v): half the sum of |du/dx| and |du/dy| (likewise v), the
#: pixel's footprint in the chart (pbrt-v4, ``BumpMap``: du = 0.5 (|dudx| +
#: |dudy|), 0.0005 where that is 0), the fallback also where it is not below
#: `FOOTPRINT_LIMIT`, and at most 0.25.  The neighbours are the next column
#: (x + dx) and, dy being the row spacing, the row above (y + dy); pbrt takes
#: the row below, the same footprint to first order.
FOOTPRINT = _footprint()

#: What the generator prints: name -> (arguments, outputs).  A per-field entry
#: maps each field to its outputs and becomes one function with the field's
#: code (`FIELD_CODES`) as first argument.
_UV = (u, v, k_u, k_v)
_N = (N_x, N_y, N_z)
FUNCTIONS = {
    "height": (_UV, {n: (f,) for n, f in HEIGHT.items()}),
    "exact_gradient": (_UV, GRADIENT),
    "central_gradient": (_UV + (eps_u, eps_v), CENTRAL),
    "kink_band": (_UV, {n: (f,) for n, f in KINK_BAND.items()}),
    "chart": (_N, CHART),
    "tangent_frame": (_N + (sin_phi,), TANGENT_FRAME),
    "perturbed_normal_chart": (_N + e_theta + e_phi + (h_u, h_v, beta),
                               PERTURBED_NORMAL["chart"]),
    "perturbed_normal_surface": (_N + e_theta + e_phi + (h_u, h_v, beta, h, R, sin_phi),
                                 PERTURBED_NORMAL["surface"]),
    "footprint": ((x, y, dx, dy, camera_z) + P + _N + e_theta + e_phi + (R, sin_phi), FOOTPRINT),
}
#: Assignments printed before a function's outputs (the stencil's points).
PRELUDE = {"central_gradient": STENCIL_POINTS}
