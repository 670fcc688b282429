"""The kernel's formulas evaluated on arrays of points, for proofs/, the book and tests.

Each function broadcasts its arguments, runs the compiled loop that
renderer/generated.py holds beside the kernel's scalar function, and reshapes:
the same machine code as a render, so a value here is the bits the renderer
uses at the same point (tests/test_codegen.py checks it against `render`).

Fields are named as in `renderer.Scene.height_field`: "sine", "ridges", "rings".
"""

from __future__ import annotations

import numpy as np

from . import generated as G

__all__ = ["height", "exact_gradient", "central_gradient", "kink_band", "chart", "tangent_frame",
           "footprint"]


def _field(name):
    if name not in G.FIELD_CODES:
        raise ValueError(f"height_field must be one of {tuple(G.FIELD_CODES)}, got {name!r}")
    return G.FIELD_CODES[name]


def _evaluate(loop, k, lead, args):
    """``loop`` over the broadcast ``args``: k arrays of the broadcast shape."""
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in args))
    shape = arrays[0].shape
    # Copies: numba warns on the read-only views broadcast_arrays returns.
    flat = [np.array(a, dtype=np.float64).reshape(-1) for a in arrays]
    out = np.empty((k, flat[0].size))
    loop(*lead, *flat, out)
    return [row.reshape(shape) for row in out]


def height(name, u, v, k_u, k_v):
    """h(u, v) of field ``name`` (`renderer.formulas.HEIGHT`).

    Parameters: ``u``, ``v`` float64 arrays (chart units, broadcastable), ``k_u``,
    ``k_v`` frequencies.  Returns a float64 array of the broadcast shape.
    Raises ValueError for an unknown ``name``.
    """
    return _evaluate(G.height_array, 1, (_field(name),), (u, v, k_u, k_v))[0]


def exact_gradient(name, u, v, k_u, k_v):
    """(h_u, h_v), sympy's derivative (`renderer.formulas.GRADIENT`); for ridges
    sign(f) f' (one of the one-sided derivatives on a crease, 0 where the
    float64 factor is exactly 0).  Two float64 arrays of the broadcast shape."""
    return tuple(_evaluate(G.exact_gradient_array, 3, (_field(name),), (u, v, k_u, k_v))[:2])


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
    ValueError
        An unknown ``name``, or a step outside [`MIN_STEP`, 1) or not finite.
    """
    eps_v = eps if eps_v is None else eps_v
    for label, e in (("eps", eps), ("eps_v", eps_v)):
        e = np.asarray(e, dtype=np.float64)
        if not np.all((e >= MIN_STEP) & (e < 1.0)):
            raise ValueError(f"{label} must be in [{MIN_STEP:g}, 1), got {e if e.ndim else float(e)!r}")
    return tuple(_evaluate(G.central_gradient_array, 3, (_field(name),), (u, v, k_u, k_v, eps, eps_v))[:2])


def kink_band(name, u, v, k_u, k_v):
    """The seed's crease flag (`renderer.formulas.KINK_BAND`): bool array of the broadcast shape."""
    return _evaluate(G.kink_band_array, 1, (_field(name),), (u, v, k_u, k_v))[0] != 0.0


def chart(N_x, N_y, N_z):
    """(u, v, sin phi) of unit normals of sphere A (`renderer.formulas.CHART`)."""
    return tuple(_evaluate(G.chart_array, 3, (), (N_x, N_y, N_z)))


def tangent_frame(N_x, N_y, N_z, sin_phi):
    """(e_theta, e_phi), each a triple of arrays, with the pole fallback
    (`renderer.formulas.TANGENT_FRAME`)."""
    c = _evaluate(G.tangent_frame_array, 6, (), (N_x, N_y, N_z, sin_phi))
    return tuple(c[:3]), tuple(c[3:])


def footprint(x, y, dx, dy, camera_z, P, N, e_theta, e_phi, radius, sin_phi):
    """(eps_u, eps_v), the pixel footprint in the chart (`renderer.formulas.FOOTPRINT`).

    ``x``, ``y``: pixel centres on the image plane; ``dx``, ``dy``: the pixel
    spacing; ``P``, ``N``, ``e_theta``, ``e_phi``: triples of arrays.
    """
    return tuple(_evaluate(G.footprint_array, 2, (), (x, y, dx, dy, camera_z, *P, *N, *e_theta, *e_phi,
                                                      radius, sin_phi)))
