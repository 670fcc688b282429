"""Comparing the two pipelines: the §4 ledger and display helpers."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from numba import njit

from .render import SPHERE_A, Frame
from .scene import Scene

__all__ = ["Ledger", "compare", "to_srgb", "SIMULATOR_SCENE", "DIFFERENCE_LOG_FLOOR", "DIFFERENCE_LINEAR_GAIN",
           "SLIDER_LOG_EPS", "CURVE_LOG_EPS"]

#: The scene the simulator opens on: the default `Scene()` (the draft's scene shaded with the
#: displaced sphere's normal, ``formulas.PERTURBED_NORMAL["surface"]``, the bump a reader
#: expects) with the sine field, the smooth field §3 has just derived; the draft's ridges and its
#: chart formula are one control away.
SIMULATOR_SCENE = Scene(height_field="sine")

#: The simulator's difference canvas (§4): log10 |difference| is drawn from this floor (black)
#: to 0 (white), about the rounding level of float64; the linear scale multiplies by the gain.
DIFFERENCE_LOG_FLOOR = -16
DIFFERENCE_LINEAR_GAIN = 100

#: The simulator's ε slider: log10 of its smallest and largest step (chart units), whole decades.
SLIDER_LOG_EPS = (-14, -1)
#: The steps of the simulator's U-curve, as log10 ε: every half decade of the slider, both ends
#: included.  `lab.accuracy.HALF_DECADES` measures the book's image-best step over them.
CURVE_LOG_EPS = tuple(SLIDER_LOG_EPS[0] + i / 2 for i in range(2 * (SLIDER_LOG_EPS[1] - SLIDER_LOG_EPS[0]) + 1))


@dataclass(frozen=True)
class Ledger:
    """Differences between a numeric and a symbolic frame (seed §4, Cell 3).

    Attributes
    ----------
    max_abs, rms : float
        Max and root-mean-square of |I_numeric - I_symbolic| over the colour
        channels of the pixels that are sphere A in both frames (0.0 when
        there are none).
    flips : int
        Pixels whose chamber code differs between the frames.
    pixels_a : int
        Number of pixels on sphere A in both frames.
    mean_abs_kink, mean_abs_off_kink : float
        Mean |dI| over the channels of those pixels on and off the symbolic
        frame's crease band.  A mean over no pixel is ``nan`` (numpy's mean
        of an empty array, and a float like the others, so that a census is
        an array of floats): mean_abs_kink is nan where the band holds no
        pixel of sphere A, always for a field without creases (sine, rings),
        which has none; mean_abs_off_kink where the band holds every one; both
        where pixels_a is 0.  Otherwise they are finite (the images are), so
        ``math.isnan`` tells exactly whether the set was empty.
    """

    max_abs: float
    rms: float
    flips: int
    pixels_a: int
    mean_abs_kink: float
    mean_abs_off_kink: float


def compare(numeric: Frame, symbolic: Frame) -> Ledger:
    """Ledger of two frames of the same size.

    The crease band is read from ``symbolic.kink``, so ``symbolic`` must be
    rendered with ``kink=True`` (the default).  A mean over an empty set of
    pixels is nan (see `Ledger`).

    Raises
    ------
    TypeError
        If either argument is not a `Frame`.
    ValueError
        If the frames differ in shape, an image, chamber or (symbolic) kink
        array is not (H, W, 3) float64, (H, W) uint8, (H, W) bool, or
        ``symbolic`` was rendered with ``kink=False`` (the message says to
        render it with ``kink=True``).
    """
    for name, frame in (("numeric", numeric), ("symbolic", symbolic)):
        if not isinstance(frame, Frame):
            raise TypeError(f"{name} must be a renderer Frame, got {type(frame).__name__}")
    if symbolic.kink is None:
        raise ValueError("symbolic has no crease band (rendered with kink=False); the ledger's "
                         "on/off-band means need it: render the symbolic frame with kink=True "
                         "(the default)")
    if numeric.image.shape != symbolic.image.shape:
        raise ValueError(
            f"frames must have the same shape, got {numeric.image.shape} and {symbolic.image.shape}"
        )
    shape = numeric.image.shape[:2]
    for name, frame in (("numeric", numeric), ("symbolic", symbolic)):
        for field, array, dims, dtype in (("image", frame.image, shape + (3,), np.float64),
                                          ("chamber", frame.chamber, shape, np.uint8),
                                          ("kink", frame.kink, shape, np.bool_)):
            if field == "kink" and name == "numeric":
                continue                      # only the symbolic frame's band is read
            if not isinstance(array, np.ndarray) or array.shape != dims or array.dtype != dtype:
                got = (f"{array.dtype} {array.shape}" if isinstance(array, np.ndarray)
                       else type(array).__name__)
                raise ValueError(f"{name}.{field} must be a {np.dtype(dtype)} array of shape {dims}, got {got}")
    arrays = [np.ascontiguousarray(a) for a in (numeric.image, symbolic.image, numeric.chamber,
                                                   symbolic.chamber, symbolic.kink)]
    top, sq, pixels, on, n_on, off, n_off, flips = ledger_sums(*arrays, SPHERE_A)
    entries = n_on + n_off
    return Ledger(
        max_abs=float(top),
        rms=math.sqrt(sq / entries) if entries else 0.0,
        flips=int(flips),
        pixels_a=int(pixels),
        mean_abs_kink=on / n_on if n_on else math.nan,
        mean_abs_off_kink=off / n_off if n_off else math.nan,
    )


@njit(cache=True, error_model="numpy")
def ledger_sums(num_image, sym_image, num_chamber, sym_chamber, band, sphere_a):
    """One pass over two frames for `renderer.compare`: over the pixels on
    sphere A (chamber code ``sphere_a``) in both, max |dI|, the sum of |dI|^2,
    the pixel count, the sum and count of |dI| on and off the crease ``band``
    (channel values); and the number of pixels whose chamber differs.  Images
    (H, W, C) float64, chambers (H, W) uint8, band (H, W) bool.  The code is an
    argument, not a global: numba's cache, invalidated by this file alone, would
    keep another file's constant as it was compiled."""
    top, sq, pixels, on, n_on, off, n_off, flips = 0.0, 0.0, 0, 0.0, 0, 0.0, 0, 0
    for j in range(num_chamber.shape[0]):
        for i in range(num_chamber.shape[1]):
            a, b = num_chamber[j, i], sym_chamber[j, i]
            flips += a != b
            if a != sphere_a or b != sphere_a:
                continue
            pixels += 1
            for c in range(num_image.shape[2]):
                d = abs(num_image[j, i, c] - sym_image[j, i, c])
                top, sq = max(top, d), sq + d * d
                if band[j, i]:
                    on, n_on = on + d, n_on + 1
                else:
                    off, n_off = off + d, n_off + 1
    return top, sq, pixels, on, n_on, off, n_off, flips


def to_srgb(linear):
    """Encode linear RGB in [0, 1] with the sRGB transfer curve (IEC 61966-2-1).

    Parameters
    ----------
    linear : ndarray of float64, any shape; negative values are clipped to 0.

    Returns
    -------
    ndarray of float64, same shape.
    """
    c = np.maximum(np.asarray(linear, dtype=np.float64), 0.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
