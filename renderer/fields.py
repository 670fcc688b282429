"""Height fields h(u, v) on sphere A's chart, written once in sympy.

Seed §2 and §3 define three fields on the chart (u, v) in [0, 1]^2:

* sine   h = sin(pi k_u u) sin(pi k_v v)         smooth everywhere (the control)
* ridges h = |sin(pi k_u u) sin(pi k_v v)|       creased where either factor is 0
* rings  h = sin(2 pi k_v v)                     latitude bands, no u-dependence

`HEIGHT_EXPRS` holds the sympy expressions; everything numeric is generated
from them by ``sympy.lambdify``: the height itself (`height`, evaluated by the
central-difference pipeline) and its exact gradient (`exact_gradient`, sympy's
derivative with common subexpressions shared).  Nothing here is typed twice.

The height itself is evaluated with `renderer.detmath.sin`, not numpy's sine:
the central-difference quotient amplifies the last bit of h by 1/eps, and the
deterministic sine gives the same bits here and in the §4 simulator's
JavaScript (see `renderer.detmath`).  The exact gradient is not amplified and
uses numpy's sin and cos.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from . import detmath

__all__ = [
    "u", "v", "k_u", "k_v", "HEIGHT_EXPRS", "GRADIENT_EXPRS",
    "height", "exact_gradient", "kink_band", "KINK_BAND_HALF_WIDTH", "CentralStencil",
    "central_stencil",
]

#: Chart coordinates and frequencies.  Real, so that d|f|/du = sign(f) f'.
u, v, k_u, k_v = sp.symbols("u v k_u k_v", real=True)

_s1 = sp.sin(sp.pi * k_u * u)
_s2 = sp.sin(sp.pi * k_v * v)

#: The three height fields of seed §2, the single source of truth.
HEIGHT_EXPRS = {
    "sine": _s1 * _s2,
    "ridges": sp.Abs(_s1 * _s2),
    "rings": sp.sin(2 * sp.pi * k_v * v),
}

#: (h_u, h_v) for each field: sympy's derivatives of `HEIGHT_EXPRS`.
GRADIENT_EXPRS = {
    name: (sp.diff(h, u), sp.diff(h, v)) for name, h in HEIGHT_EXPRS.items()
}

#: Half-width of the seed's crease band: a ridges pixel is flagged when
#: |sin(pi k_u u)| < 0.03 or |sin(pi k_v v)| < 0.03 (seed Cell 1, ``height1``).
KINK_BAND_HALF_WIDTH = 0.03


#: lambdify's modules for the height and the crease factors: sin is deterministic.
HEIGHT_MODULES = [{"sin": detmath.sin}, "numpy"]


@lru_cache(maxsize=None)
def _height_fn(name):
    return sp.lambdify((u, v, k_u, k_v), HEIGHT_EXPRS[name], modules=HEIGHT_MODULES)


@lru_cache(maxsize=None)
def _ridge_factors_fn():
    return sp.lambdify((u, v, k_u, k_v), [_s1, _s2], modules=HEIGHT_MODULES)


#: The crease flag's first pass uses numpy's sine (see `kink_band`); a module
#: attribute, looked up on each call, so that a test can put a worse sine here.
_fast_sine = np.sin

#: Half-width of the margin around |sine| = `KINK_BAND_HALF_WIDTH` inside which
#: `kink_band` decides with the deterministic sine: numpy's and the
#: deterministic sine each lie within a few ulps (about 1e-17 at 0.03) of the
#: true sine, so outside the margin both give the same flag.
KINK_SINE_MARGIN = 1e-12


@lru_cache(maxsize=None)
def _ridge_factors_fast_fn():
    # The same printed code as _ridge_factors_fn (so the same sine arguments,
    # bit for bit), with numpy's sine.
    return sp.lambdify((u, v, k_u, k_v), [_s1, _s2],
                       modules=[{"sin": lambda x: _fast_sine(x)}, "numpy"])


@lru_cache(maxsize=None)
def _gradient_fn(name):
    return sp.lambdify((u, v, k_u, k_v), list(GRADIENT_EXPRS[name]), modules="numpy", cse=True)


def _check_name(name):
    if name not in HEIGHT_EXPRS:
        raise ValueError(f"height_field must be one of {tuple(HEIGHT_EXPRS)}, got {name!r}")


def height(name, uu, vv, ku, kv):
    """Evaluate the height field ``name`` at chart points.

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    uu, vv : ndarray of float64, broadcastable
        Chart coordinates (dimensionless, nominally in [0, 1]).
    ku, kv : float
        Frequencies k_u, k_v.

    Returns
    -------
    ndarray of float64 with the broadcast shape of ``uu`` and ``vv``.

    Raises
    ------
    ValueError
        If ``name`` is not a known field.
    """
    _check_name(name)
    h = _height_fn(name)(uu, vv, ku, kv)
    return np.broadcast_to(np.asarray(h, dtype=np.float64), np.broadcast(uu, vv).shape)


def exact_gradient(name, uu, vv, ku, kv):
    """The exact chart gradient (h_u, h_v), generated from the sympy field.

    For "ridges" the derivative of |f| is sign(f) f'.  The field is not
    differentiable on its zero lines u = m/k_u, v = m/k_v; there the result is
    0 only where the float64 sine is exactly 0 (e.g. the seam u = 0).  On a
    line such as u = 1/8 with k_u = 8, sin(pi) rounds to 1.2e-16, the sign is
    taken from that residue, and the result is one of the two one-sided
    derivatives.  The `kink_band` flag marks these pixels.

    Parameters
    ----------
    name : {"sine", "ridges", "rings"}
    uu, vv : ndarray of float64, broadcastable
    ku, kv : float

    Returns
    -------
    (h_u, h_v) : tuple of two float64 ndarrays of the broadcast shape.

    Raises
    ------
    ValueError
        If ``name`` is not a known field.
    """
    _check_name(name)
    shape = np.broadcast(uu, vv).shape
    hu, hv = _gradient_fn(name)(uu, vv, ku, kv)
    return (np.broadcast_to(np.asarray(hu, dtype=np.float64), shape),
            np.broadcast_to(np.asarray(hv, dtype=np.float64), shape))


def kink_band(name, uu, vv, ku, kv, factors=None):
    """The seed's crease flag: True within the band around the ridges' zero lines.

    Only the "ridges" field has creases; for the other fields the result is
    all False.  The band is |sin(pi k_u u)| < 0.03 or |sin(pi k_v v)| < 0.03
    (seed Cell 1).

    ``factors``: optionally the two sines sin(pi k_u u), sin(pi k_v v) at the
    same points, already computed by `renderer.detmath.sin` (the central
    stencil's, `CentralStencil.ridge_factors`); the flag is then read off them.

    The factors are computed first with numpy's sine (about six times as fast
    as `renderer.detmath.sin`).  Only where one of them lies within
    `KINK_SINE_MARGIN` of the band's edge, or is not finite, or where the
    arguments leave the range in which both sines are accurate, is the flag
    decided with the deterministic sine.  So the flag is the deterministic
    sine's everywhere, as in the §4 simulator.

    Returns
    -------
    ndarray of bool with the broadcast shape of ``uu`` and ``vv``.
    """
    _check_name(name)
    shape = np.broadcast(uu, vv).shape
    if name != "ridges":
        return np.zeros(shape, dtype=bool)
    if factors is not None:
        return np.broadcast_to(np.asarray(_band(*factors)), shape)
    uu, vv = np.broadcast_arrays(np.asarray(uu, dtype=np.float64), np.asarray(vv, dtype=np.float64))
    if uu.size == 0 or not _fast_sine_applies(uu, vv, ku, kv):
        return np.asarray(_band(*_ridge_factors_fn()(uu, vv, ku, kv)))
    s1, s2 = _ridge_factors_fast_fn()(uu, vv, ku, kv)
    flag = np.asarray(_band(s1, s2))
    # Where a factor lies within the margin of the band's edge (or is NaN),
    # numpy's sine could decide otherwise than the deterministic one: decide
    # there with the deterministic sine, at those points only.
    edge = KINK_BAND_HALF_WIDTH
    unsure = np.flatnonzero(~((np.abs(np.abs(s1) - edge) > KINK_SINE_MARGIN)
                              & (np.abs(np.abs(s2) - edge) > KINK_SINE_MARGIN)))
    if unsure.size:
        flat = flag.reshape(-1)
        flat[unsure] = _band(*_ridge_factors_fn()(uu.reshape(-1)[unsure], vv.reshape(-1)[unsure], ku, kv))
    return flag


def _band(s1, s2):
    return (np.abs(s1) < KINK_BAND_HALF_WIDTH) | (np.abs(s2) < KINK_BAND_HALF_WIDTH)


def _fast_sine_applies(uu, vv, ku, kv):
    """Whether every sine argument pi k u, pi k v is finite and inside the range
    where the deterministic sine is accurate (`detmath.REDUCTION_LIMIT`, with
    room to spare for the rounding of the product)."""
    limit = 0.5 * detmath.REDUCTION_LIMIT / np.pi
    with np.errstate(invalid="ignore", over="ignore"):
        big = max(abs(ku) * float(np.max(np.abs(uu))), abs(kv) * float(np.max(np.abs(vv))))
    return bool(np.isfinite(big) and big < limit)


#: The shifted chart points of the central-difference stencil.
u_p, u_m, v_p, v_m = sp.symbols("u_p u_m v_p v_m", real=True)


#: Largest number of points whose sines `_SineBatch` stacks into one call.
#: Measured here side by side when it was set (steady-state A/B runs, not a
#: committed benchmark): stacking four sines of 15,000 points (a 256^2 tile on
#: each of two threads) made the central frame 0.94-0.95 times as long; four of
#: 30,000 on one thread made it 1.09 times as long (the stacked temporaries no
#: longer fit the core's cache).
SINE_BATCH_MAX = 24576


class _SineBatch:
    """A list of assignments and outputs evaluated with all their sines in one call.

    The sines of ``assignments`` (``(symbol, expr)`` pairs in order) and of
    ``outputs`` are taken out: first the assignments free of sines and every
    sine's argument are evaluated (``_args``), then `detmath.sin` once on the
    stacked arguments, then the rest with each sine replaced by its row
    (``_rest``).  For up to `SINE_BATCH_MAX` points, one call on a (k, n)
    array instead of k calls on (n,) arrays: the same elementwise operations,
    so the same bits, with a k-th of the array operations (each of which
    takes the GIL back when tiles render on several threads).  Source: a
    rewrite of sympy's cse output; the sines' arguments and the other
    expressions print exactly as before.
    """

    def __init__(self, inputs, assignments, outputs):
        sines = []
        for expr in [e for _, e in assignments] + list(outputs):
            for atom in sorted(expr.atoms(sp.sin), key=sp.default_sort_key):
                if atom not in sines:
                    sines.append(atom)
        pre = [(sym, e) for sym, e in assignments if not e.has(sp.sin)]
        known = set(inputs) | {sym for sym, _ in pre}
        if any(not s.args[0].free_symbols <= known for s in sines):
            raise ValueError("a sine's argument depends on another sine")   # not in these fields
        rows = sp.symbols(f"_sin0:{len(sines)}", real=True)
        swap = dict(zip(sines, rows))
        post = [(sym, e.xreplace(swap)) for sym, e in assignments if e.has(sp.sin)]
        pre_symbols = [sym for sym, _ in pre]
        self._args = sp.lambdify(inputs, pre_symbols + [s.args[0] for s in sines], modules="numpy",
                                 cse=lambda exprs: (pre, exprs))
        self._rest = sp.lambdify(tuple(inputs) + tuple(pre_symbols) + rows,
                                 [e.xreplace(swap) for e in outputs], modules="numpy",
                                 cse=lambda exprs: (post, exprs))
        self._n_pre = len(pre)

    def __call__(self, *values):
        out = self._args(*values)
        pre, args = out[:self._n_pre], out[self._n_pre:]
        if args:
            args = np.broadcast_arrays(*args)
            if args[0].size <= SINE_BATCH_MAX:
                args = list(detmath.sin(np.stack(args)))
            else:
                args = [detmath.sin(a) for a in args]
        return self._rest(*values, *pre, *args)


class CentralStencil:
    """The four values h(u+, v), h(u-, v), h(u, v+), h(u, v-) of a central
    difference, generated from the sympy field as one function.

    sympy's common-subexpression elimination runs over the four shifted
    expressions together, so a factor that does not move with the shift is
    computed once: for sine and ridges sin(pi k_v v) serves h(u+-eps, v) and
    sin(pi k_u u) serves h(u, v+-eps) (6 sines instead of 8); for rings
    h(u+-eps, v) is one value (3 instead of 4).  The subexpressions free of the
    shifted points (``base``) do not depend on eps either, so an eps sweep
    computes them once (`renderer.sweep`).  The sines of each part are
    computed in one call (`_SineBatch`).  Every value is the same bits as
    `height` at the same point: the same operations on the same numbers
    (tests/test_fields.py checks it; the JavaScript evaluates h four times and
    matches too).
    """

    def __init__(self, name):
        _check_name(name)
        h = HEIGHT_EXPRS[name]
        quad = [h.subs(u, u_p), h.subs(u, u_m), h.subs(v, v_p), h.subs(v, v_m)]
        replacements, reduced = sp.cse(quad)
        base, rest = [], []
        for sym, expr in replacements:
            if expr.free_symbols <= {u, v, k_u, k_v} | {b for b, _ in base}:
                base.append((sym, expr))
            else:
                rest.append((sym, expr))
        self.name = name
        self.base_symbols = tuple(b for b, _ in base)
        # Where the ridges' two factors sin(pi k_u u), sin(pi k_v v) are among
        # the base values (as for sine and ridges): their positions.
        full, expanded = {}, []
        for sym, expr in base:
            full[sym] = expr.xreplace(full)
            expanded.append(full[sym])
        self._factor_rows = (tuple(expanded.index(f) for f in (_s1, _s2))
                             if _s1 in expanded and _s2 in expanded else None)
        self._base = _SineBatch((u, v, k_u, k_v), base, list(self.base_symbols))
        self._shifted = _SineBatch((u_p, u_m, v_p, v_m, u, v, k_u, k_v, *self.base_symbols), rest,
                                   reduced)

    def base(self, uu, vv, ku, kv):
        """The eps-free subexpressions at the stencil's centre (a list of arrays)."""
        return self._base(uu, vv, ku, kv)

    def ridge_factors(self, base):
        """(sin(pi k_u u), sin(pi k_v v)) out of ``base`` (the list `base`
        returned), or None if this field's base does not hold them.  The same
        bits as `kink_band`'s deterministic factors (tests/test_fields.py)."""
        if self._factor_rows is None:
            return None
        return tuple(base[i] for i in self._factor_rows)

    def values(self, up, um, vp, vm, uu, vv, ku, kv, base=None):
        """[h(u+, v), h(u-, v), h(u, v+), h(u, v-)], each broadcast to the centre's shape."""
        if base is None:
            base = self.base(uu, vv, ku, kv)
        shape = np.broadcast(uu, vv).shape
        return [np.broadcast_to(np.asarray(x, dtype=np.float64), shape)
                for x in self._shifted(up, um, vp, vm, uu, vv, ku, kv, *base)]


@lru_cache(maxsize=None)
def central_stencil(name):
    """The `CentralStencil` of field ``name`` (built once).

    Raises
    ------
    ValueError
        If ``name`` is not a known field.
    """
    return CentralStencil(name)
