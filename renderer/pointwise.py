"""The kernel's formulas evaluated on arrays of points, for proofs/, the book and tests.

Each function broadcasts its arguments, runs the compiled loop that
renderer/generated.py holds beside the kernel's scalar function, and reshapes:
the same machine code as a render, so a value here is the bits the renderer
uses at the same point (tests/test_codegen.py checks it against `render`).

Fields are named as in `renderer.Scene.height_field`: "sine", "ridges",
"rings".  Arguments are scalars or float64 arrays that broadcast together
(chart coordinates u, v in chart units, positions in scene units); results
are float64 arrays of the broadcast shape.  Every function raises ValueError
for an unknown field, TypeError for an argument that is not real numbers,
and ValueError for a value that is not finite or arguments that do not
broadcast, naming the argument (and the first bad value's flat index).
Source: the formulas of seed §2-§3 as corrected in `renderer.formulas`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import generated as G
from . import kernel
from .render import GBuffer, check_flag
from .scene import Scene

__all__ = ["height", "exact_gradient", "central_gradient", "kink_band", "chart", "tangent_frame",
           "footprint", "reach"]


def _field(name):
    if name not in G.FIELD_CODES:
        raise ValueError(f"height_field must be one of {tuple(G.FIELD_CODES)}, got {name!r}")
    return G.FIELD_CODES[name]


def _evaluate(loop, k, lead, names, args):
    """``loop`` over the broadcast ``args``: k arrays of the broadcast shape.

    Each argument must hold finite real numbers; TypeError or ValueError
    names the argument (``names``), the first bad value and its index."""
    arrays = [_real(name, a) for name, a in zip(names, args)]
    try:
        arrays = np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = ", ".join(f"{n} {a.shape}" for n, a in zip(names, arrays))
        raise ValueError(f"the arguments must broadcast to one shape, got {shapes}") from None
    shape = arrays[0].shape
    # Copies: numba warns on the read-only views broadcast_arrays returns.
    flat = [np.array(a, dtype=np.float64).reshape(-1) for a in arrays]
    out = np.empty((k, flat[0].size))
    loop(*lead, *flat, out)
    return [row.reshape(shape) for row in out]


def _real(name, value, low=None, high=None, high_open=False):
    """``value`` as a float64 array of finite numbers (in [low, high] or
    [low, high)); TypeError or ValueError naming ``name``, the first bad
    value and its flat index."""
    try:
        if np.iscomplexobj(value):          # asarray would drop the imaginary part with a warning
            raise TypeError
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be real numbers (a scalar or an array), got "
                        f"{type(value).__name__} {value!r:.60}") from None
    ok = np.isfinite(a)
    if low is not None:
        ok &= (a >= low) & ((a < high) if high_open else (a <= high))
    bad = np.flatnonzero(~ok)
    if bad.size:
        accepted = "finite" if low is None else f"in [{low:g}, {high:g}{')' if high_open else ']'}"
        raise ValueError(f"{name} must be {accepted}, got {float(a.reshape(-1)[bad[0]])!r} at flat index {bad[0]}")
    return a


def _triple(name, value):
    """``value`` as three components (x, y, z), or ValueError naming ``name``."""
    try:
        parts = tuple(value)
    except TypeError:
        parts = ()
    if len(parts) != 3:
        raise ValueError(f"{name} must have three components (x, y, z), got {value!r:.60}")
    return parts


_UV = ("u", "v", "k_u", "k_v")


def height(name, u, v, k_u, k_v):
    """h(u, v) of field ``name`` (`renderer.formulas.HEIGHT`).

    Parameters: ``u``, ``v`` float64 arrays (chart units, broadcastable), ``k_u``,
    ``k_v`` frequencies.  Returns a float64 array of the broadcast shape.
    Raises ValueError for an unknown ``name``.
    """
    return _evaluate(G.height_array, 1, (_field(name),), _UV, (u, v, k_u, k_v))[0]


def exact_gradient(name, u, v, k_u, k_v):
    """(h_u, h_v), sympy's derivative (`renderer.formulas.GRADIENT`); for ridges
    sign(f) f' (one of the one-sided derivatives on a crease, 0 where the
    float64 factor is exactly 0).  Two float64 arrays of the broadcast shape."""
    return tuple(_evaluate(G.exact_gradient_array, 2, (_field(name),), _UV, (u, v, k_u, k_v)))


#: Smallest step `central_gradient` accepts: the generated quotient multiplies
#: by 1 / (2 eps), which overflows for eps below about 2.8e-309.
MIN_STEP = 1e-300


def central_gradient(name, u, v, k_u, k_v, eps, eps_v=None):
    """Central differences (h_u, h_v) with step ``eps`` (and ``eps_v`` in v, default eps).

    u wraps modulo 1, v clamps to [0, 1] with a one-sided quotient where it
    clamps (`renderer.formulas.CENTRAL`, seed Cell 1 ``grad_numeric``).  ``u``,
    ``v`` in [0, 1]; steps in [`MIN_STEP`, 1), scalars or arrays (broadcast).

    Raises
    ------
    TypeError, ValueError
        As every function here; also a u or v outside [0, 1], a step outside
        [`MIN_STEP`, 1).
    """
    eps_v = eps if eps_v is None else eps_v
    # The stencil wraps u and clamps v on [0, 1], for steps below 1.
    u, v = _real("u", u, 0.0, 1.0), _real("v", v, 0.0, 1.0)
    eps, eps_v = _real("eps", eps, MIN_STEP, 1.0, True), _real("eps_v", eps_v, MIN_STEP, 1.0, True)
    return tuple(_evaluate(G.central_gradient_array, 2, (_field(name),), _UV + ("eps", "eps_v"),
                           (u, v, k_u, k_v, eps, eps_v)))


def kink_band(name, u, v, k_u, k_v):
    """The seed's crease flag (`renderer.formulas.KINK_BAND`): bool array of the broadcast shape."""
    return _evaluate(G.kink_band_array, 1, (_field(name),), _UV, (u, v, k_u, k_v))[0] != 0.0


def chart(N_x, N_y, N_z):
    """(u, v, sin phi) of unit normals of sphere A (`renderer.formulas.CHART`)."""
    return tuple(_evaluate(G.chart_array, 3, (), ("N_x", "N_y", "N_z"), (N_x, N_y, N_z)))


def tangent_frame(N_x, N_y, N_z, sin_phi):
    """(e_theta, e_phi), each a triple of arrays, with the pole fallback
    (`renderer.formulas.TANGENT_FRAME`)."""
    c = _evaluate(G.tangent_frame_array, 6, (), ("N_x", "N_y", "N_z", "sin_phi"), (N_x, N_y, N_z, sin_phi))
    return tuple(c[:3]), tuple(c[3:])


def footprint(x, y, dx, dy, camera_z, P, N, e_theta, e_phi, radius, sin_phi):
    """(eps_u, eps_v), the pixel footprint in the chart (`renderer.formulas.FOOTPRINT`).

    ``x``, ``y``: pixel centres on the image plane; ``dx``, ``dy``: the pixel
    spacing; ``P``, ``N``, ``e_theta``, ``e_phi``: triples of arrays.
    """
    P, N, e_theta, e_phi = (_triple(n, t) for n, t in (("P", P), ("N", N), ("e_theta", e_theta),
                                                        ("e_phi", e_phi)))
    names = ("x", "y", "dx", "dy", "camera_z", "P_x", "P_y", "P_z", "N_x", "N_y", "N_z", "et_x", "et_y", "et_z",
             "ep_x", "ep_y", "ep_z", "radius", "sin_phi")
    return tuple(_evaluate(G.footprint_array, 2, (), names, (x, y, dx, dy, camera_z, *P, *N, *e_theta, *e_phi,
                                                             radius, sin_phi)))



def reach(scene, gbuffer, *, gate=False):
    """Which light reaches each pixel's hit point, by the kernel's own predicate.

    `renderer.kernel.reach` (the normal faces the light, the floor plane does
    not separate them, no blocker sphere cuts the segment) evaluated on the
    hit points and normals of ``gbuffer``, for every light of ``scene`` in
    order (lights of zero colour included): the masks the renderer shades
    with.  With ``gate`` also Ns . w > 0, the gate by which the kernel skips
    shadow rays where the light adds nothing (Ns: the bumped normal).

    Parameters
    ----------
    scene : Scene
        The scene ``gbuffer`` was made from.
    gbuffer : GBuffer
        From `renderer.gbuffer`.
    gate : bool, keyword-only

    Returns
    -------
    (n_lights, H, W) bool array (False where chamber is 0).

    Raises
    ------
    TypeError
        ``scene`` not a Scene, ``gbuffer`` not a GBuffer, ``gate`` not a bool.
    ValueError
        If ``gbuffer``'s chamber is not an (H, W) array or its P, N, Ns are not
        (H, W, 3) arrays of the same frame (the loop would read past them).
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a renderer.Scene, got {type(scene).__name__}")
    if not isinstance(gbuffer, GBuffer):
        raise TypeError(f"gbuffer must be a renderer.GBuffer, got {type(gbuffer).__name__}")
    chamber = np.asarray(gbuffer.chamber)
    if chamber.ndim != 2:
        raise ValueError(f"gbuffer.chamber must be an (H, W) array, got shape {chamber.shape}")
    for name in ("P", "N", "Ns"):
        shape = np.shape(getattr(gbuffer, name))
        if shape != chamber.shape + (3,):
            raise ValueError(f"gbuffer.{name} has shape {shape}, gbuffer.chamber {chamber.shape}: "
                             f"the arrays must be one frame's, {chamber.shape + (3,)}")
    prm, lights = kernel.params(scene, skip=False)
    out = np.zeros((lights.shape[0],) + gbuffer.chamber.shape, dtype=bool)
    _reach_rows(prm, lights, gbuffer.chamber, gbuffer.P, gbuffer.N, gbuffer.Ns, check_flag("gate", gate), out)
    return out


# Not cached: numba's cache would key this on pointwise.py alone, and keep the
# kernel's reach inlined as it was when first compiled after kernel.py changes.
@njit(error_model="numpy")
def _reach_rows(prm, lights, chamber, P, N, Ns, gate, out):
    s = kernel.unpack(prm)
    for j in range(chamber.shape[0]):
        for i in range(chamber.shape[1]):
            code = chamber[j, i]
            if code == kernel.BACKGROUND:
                continue
            p, n, ns = (P[j, i, 0], P[j, i, 1], P[j, i, 2]), (N[j, i, 0], N[j, i, 1], N[j, i, 2]), \
                (Ns[j, i, 0], Ns[j, i, 1], Ns[j, i, 2])
            for k in range(lights.shape[0]):
                out[k, j, i] = kernel.reach(s, (lights[k, 0], lights[k, 1], lights[k, 2]), p, n, code,
                                            True, gate, ns)[1]
