"""The kernel's formulas evaluated on arrays of points, for proofs/, the book and tests.

Each function broadcasts its arguments, runs the compiled loop that
renderer/generated.py holds beside the kernel's scalar function, and reshapes:
the same machine code as a render, so a value here is the bits the renderer
uses at the same point (tests/test_codegen.py checks it against `render`).

A height field is given as `renderer.Scene.height_field` takes it (a registered name, one of
`renderer.formulas.FIELDS`; a `renderer.formulas.HeightField`; or a reader's expression in
u, v, k_u, k_v, `renderer.formulas.field`), and evaluated by its compiled code
(`renderer.fieldcode.compiled`).  Arguments are real scalars or arrays that broadcast together (as
`renderer.validate.real_array` accepts them: integer or floating, not bool);
results are float64 arrays of the broadcast shape.

Each argument has an accepted range (`RANGES`), chosen so that every output is
finite; a value outside it, a non-finite one or an integer too large for a
float raises ValueError naming the argument, the range and the first bad
value's flat index; an argument that is not real numbers raises TypeError; an
unknown field or arguments that do not broadcast raise ValueError (all are
`renderer.validate.InputError`).
Source: the formulas of seed §2-§3 as corrected in `renderer.formulas`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import fieldcode, kernel
from . import formulas as F
from . import generated as G
from .render import GBuffer
from .scene import COORDINATE, FREQUENCY, RADIUS, UNIT, Scene
from .validate import InvalidType, InvalidValue, _shown, flag, real_array

__all__ = ["height", "exact_gradient", "central_gradient", "kink_band", "chart", "tangent_frame",
           "footprint", "reach", "RANGES", "RANGES_CENTRAL", "RANGES_FRAME", "MIN_STEP"]

#: Smallest step `central_gradient` accepts: the generated quotient multiplies
#: by 1 / (2 eps), which overflows for eps below about 2.8e-309.
MIN_STEP = 1e-300

#: The range each argument accepts (keyword arguments of `renderer.validate.real_array`).
#: Chart coordinates u, v: [-1, 2], the chart [0, 1] and one chart width beyond each edge,
#: where a difference stencil or a derivative routine around a chart point samples h
#: (`central_gradient`: [0, 1], where its stencil wraps u and clamps v).  Frequencies and
#: radii: `renderer.Scene`'s.  Steps: [`MIN_STEP`, 1) (below 1 the stencil wraps u once).
#: Everything else (positions, normals and tangents, sin phi, pixel coordinates and
#: spacing, camera_z): `Scene`'s coordinates, [-1e6, 1e6], whose squares stay far from
#: overflow (the footprint's quotients by sin phi that overflow take its fallback step).
RANGES = {"u": dict(low=-1.0, high=2.0), "v": dict(low=-1.0, high=2.0), "k_u": FREQUENCY, "k_v": FREQUENCY,
          "eps": dict(low=MIN_STEP, high=1.0, high_open=True), "radius": RADIUS}
#: `central_gradient`'s ranges: its chart coordinates in [0, 1].
RANGES_CENTRAL = {**RANGES, "u": UNIT, "v": UNIT, "eps_v": RANGES["eps"]}
#: `tangent_frame`'s ranges: N and sin phi are a unit normal's, [-1.5, 1.5] leaving room for
#: rounding.  The frame divides by sin phi down to `formulas.POLE_SIN_PHI` (2^-1022), so
#: |N_z N_x| / sin phi stays below 2.25 * 2^1022, under the largest float64 (2^1024).
UNIT_NORMAL = dict(low=-1.5, high=1.5)
RANGES_FRAME = {**RANGES, "N_x": UNIT_NORMAL, "N_y": UNIT_NORMAL, "N_z": UNIT_NORMAL, "sin_phi": UNIT_NORMAL}


def _field(name):
    return fieldcode.compiled(F.field(name))


# The loops that call a field's compiled function (`renderer.fieldcode.compiled`) through its pointer.
@njit(cache=True, error_model="numpy")
def _scalar_loop(fn, u, v, k_u, k_v, out):
    for i in range(out.shape[1]):
        out[0, i] = fn(u[i], v[i], k_u[i], k_v[i])


@njit(cache=True, error_model="numpy")
def _sample_loop(fn, u, v, k_u, k_v, out):
    for i in range(out.shape[1]):
        out[0, i], out[1, i], out[2, i], out[3, i] = fn(u[i], v[i], k_u[i], k_v[i])


@njit(cache=True, error_model="numpy")
def _central_loop(fn, u, v, k_u, k_v, eps_u, eps_v, out):
    for i in range(out.shape[1]):
        out[0, i], out[1, i], out[2, i], out[3, i] = fn(u[i], v[i], k_u[i], k_v[i], eps_u[i], eps_v[i])


def _evaluate(loop, k, lead, names, args, ranges=RANGES):
    """``loop`` over the broadcast ``args``: k arrays of the broadcast shape.

    Each argument is validated (`renderer.validate.real_array`) in its range,
    ``ranges[name]`` or else `COORDINATE`'s."""
    arrays = [real_array(name, a, **ranges.get(name, COORDINATE)) for name, a in zip(names, args)]
    try:
        arrays = np.broadcast_arrays(*arrays)
    except ValueError:
        shapes = ", ".join(f"{n} {a.shape}" for n, a in zip(names, arrays))
        raise InvalidValue(f"the arguments must broadcast to one shape, got {shapes}") from None
    shape = arrays[0].shape
    # Copies: numba warns on the read-only views broadcast_arrays returns.
    flat = [np.array(a, dtype=np.float64).reshape(-1) for a in arrays]
    out = np.empty((k, flat[0].size))
    loop(*lead, *flat, out)
    return [row.reshape(shape) for row in out]


def _triple(name, value):
    """``value`` as three components (x, y, z): a tuple, a list or an array whose first axis has
    length 3; TypeError for another kind (a set, bytes, a generator), ValueError for another
    length, each naming ``name``."""
    if not isinstance(value, (tuple, list, np.ndarray)) or (isinstance(value, np.ndarray) and value.ndim == 0):
        raise InvalidType(f"{name} must be three components (x, y, z): a tuple, list or array, "
                          f"got {_shown(value, 60)}")
    if len(value) != 3:
        raise InvalidValue(f"{name} must have three components (x, y, z), got {len(value)}: {_shown(value, 60)}")
    return tuple(value)


_UV = ("u", "v", "k_u", "k_v")


def height(name, u, v, k_u, k_v):
    """h(u, v) of field ``name`` (its `renderer.formulas.HeightField.expr`).

    Parameters
    ----------
    name : str, HeightField or sympy expression
        The height field (`renderer.formulas.field`).
    u, v : array_like of float in [-1, 2]
        Chart coordinates (chart units), broadcast together with ``k_u``, ``k_v``.
    k_u, k_v : array_like of float in (0, 1e3]
        Frequencies (periods over the chart).

    Returns
    -------
    ndarray of float64, the broadcast shape (in [-1, 1] for the built-in fields).

    Raises
    ------
    TypeError, ValueError
        As the module says (`RANGES`).
    """
    return _evaluate(_scalar_loop, 1, (_field(name).height,), _UV, (u, v, k_u, k_v))[0]


def exact_gradient(name, u, v, k_u, k_v):
    """(h_u, h_v), sympy's derivative (its `renderer.formulas.HeightField.gradient`).

    For ridges sign(f) f' (one of the one-sided derivatives on a crease, 0
    where the float64 factor is exactly 0).  Arguments as `height`; returns
    two float64 arrays of the broadcast shape (per chart unit); raises as `height`.
    """
    return tuple(_evaluate(_sample_loop, 4, (_field(name).exact,), _UV, (u, v, k_u, k_v))[1:3])


def central_gradient(name, u, v, k_u, k_v, eps, eps_v=None):
    """Central differences (h_u, h_v) with step ``eps`` (and ``eps_v`` in v, default eps).

    u wraps modulo 1, v clamps to [0, 1] with a one-sided quotient where it
    clamps (`renderer.formulas.CENTRAL`, seed Cell 1 ``grad_numeric``).

    Parameters
    ----------
    name, k_u, k_v
        As `height`.
    u, v : array_like of float in [0, 1]
        Chart coordinates (the stencil wraps u and clamps v on [0, 1]).
    eps, eps_v : array_like of float in [`MIN_STEP`, 1)
        Steps (chart units), broadcast with the rest.

    Returns
    -------
    (h_u, h_v) : two float64 arrays of the broadcast shape.

    Raises
    ------
    TypeError, ValueError
        As the module says (`RANGES`; u, v in [0, 1] here).
    """
    eps_v = eps if eps_v is None else eps_v
    return tuple(_evaluate(_central_loop, 4, (_field(name).central,), _UV + ("eps", "eps_v"),
                           (u, v, k_u, k_v, eps, eps_v), RANGES_CENTRAL)[1:3])


def kink_band(name, u, v, k_u, k_v):
    """The seed's crease flag (`renderer.formulas.KINK_BAND`): a bool array of the
    broadcast shape; arguments and errors as `height`."""
    return _evaluate(_scalar_loop, 1, (_field(name).kink,), _UV, (u, v, k_u, k_v))[0] != 0.0


def chart(N_x, N_y, N_z):
    """(u, v, sin phi) of unit normals of sphere A (`renderer.formulas.CHART`).

    ``N_x``, ``N_y``, ``N_z``: array_like in [-1e6, 1e6] (broadcast).  Returns three
    float64 arrays; raises as the module says.
    """
    return tuple(_evaluate(G.chart_array, 3, (), ("N_x", "N_y", "N_z"), (N_x, N_y, N_z)))


def tangent_frame(N_x, N_y, N_z, sin_phi):
    """(e_theta, e_phi), each a triple of float64 arrays: the chart's frame wherever
    sin phi > `renderer.formulas.POLE_SIN_PHI` (2^-1022), the fixed basis at or below it
    (`renderer.formulas.TANGENT_FRAME`).

    All arguments array_like in [-1.5, 1.5] (`RANGES_FRAME`: a unit normal N and its
    sin phi, broadcast); raises as the module says.
    """
    c = _evaluate(G.tangent_frame_array, 6, (), ("N_x", "N_y", "N_z", "sin_phi"), (N_x, N_y, N_z, sin_phi),
                  RANGES_FRAME)
    return tuple(c[:3]), tuple(c[3:])


def footprint(x, y, dx, dy, camera_z, P, N, e_theta, e_phi, radius, sin_phi):
    """(eps_u, eps_v), the pixel footprint in the chart (`renderer.formulas.FOOTPRINT`).

    Parameters
    ----------
    x, y : array_like
        Pixel centres on the image plane (scene units).
    dx, dy : array_like
        The pixel spacing (scene units).
    camera_z : array_like
    P, N, e_theta, e_phi : triples (x, y, z) of array_like
        Hit points, unit normals and the tangent frame.
    radius : array_like in [1e-6, 1e6]
        Sphere A's radius.
    sin_phi : array_like

    All but ``radius`` in [-1e6, 1e6]; everything broadcasts together.

    Returns
    -------
    (eps_u, eps_v) : two float64 arrays of the broadcast shape, chart units.

    Raises
    ------
    TypeError, ValueError
        As the module says; TypeError also for a P, N, e_theta or e_phi that is
        not a tuple, list or array (a set, bytes, a generator), ValueError for
        one that is not three components.
    """
    P, N, e_theta, e_phi = (_triple(n, t) for n, t in (("P", P), ("N", N), ("e_theta", e_theta),
                                                        ("e_phi", e_phi)))
    names = ("x", "y", "dx", "dy", "camera_z", *(f"{n}[{i}]" for n in ("P", "N", "e_theta", "e_phi") for i in range(3)),
             "radius", "sin_phi")
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
        raise InvalidType(f"scene must be a renderer.Scene, got {type(scene).__name__}")
    if not isinstance(gbuffer, GBuffer):
        raise InvalidType(f"gbuffer must be a renderer.GBuffer, got {type(gbuffer).__name__}")
    chamber = np.asarray(gbuffer.chamber)
    if chamber.ndim != 2:
        raise InvalidValue(f"gbuffer.chamber must be an (H, W) array, got shape {chamber.shape}")
    for name in ("P", "N", "Ns"):
        shape = np.shape(getattr(gbuffer, name))
        if shape != chamber.shape + (3,):
            raise InvalidValue(f"gbuffer.{name} has shape {shape}, gbuffer.chamber {chamber.shape}: "
                               f"the arrays must be one frame's, {chamber.shape + (3,)}")
    prm, lights = kernel.params(scene, skip=False)
    out = np.zeros((lights.shape[0],) + gbuffer.chamber.shape, dtype=bool)
    kernel.reach_rows(prm, lights, gbuffer.chamber, gbuffer.P, gbuffer.N, gbuffer.Ns, flag("gate", gate), out)
    return out
