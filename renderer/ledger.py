"""Comparing the two pipelines: the §4 ledger and display helpers."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .kernel import ledger_sums
from .render import Frame

__all__ = ["Ledger", "compare", "to_srgb"]


@dataclass(frozen=True)
class Ledger:
    """Differences between a numeric and a symbolic frame (seed §4, Cell 3).

    Attributes
    ----------
    max_abs, rms : float
        Max and root-mean-square of |I_numeric - I_symbolic| over the colour
        channels of the pixels that are sphere A in both frames.
    flips : int
        Pixels whose chamber code differs between the frames.
    pixels_a : int
        Number of pixels on sphere A in both frames.
    mean_abs_kink, mean_abs_off_kink : float
        Mean |dI| on and off the crease band (nan where a set is empty).
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
    rendered with ``kink=True`` (the default).

    Raises
    ------
    TypeError
        If either argument is not a `Frame`.
    ValueError
        If the frames differ in shape, or ``symbolic`` was rendered with
        ``kink=False`` (the message says to render it with ``kink=True``).
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
    arrays = [np.ascontiguousarray(a) for a in (numeric.image, symbolic.image, numeric.chamber,
                                                   symbolic.chamber, symbolic.kink)]
    top, sq, pixels, on, n_on, off, n_off, flips = ledger_sums(*arrays)
    entries = n_on + n_off
    return Ledger(
        max_abs=float(top),
        rms=math.sqrt(sq / entries) if entries else 0.0,
        flips=int(flips),
        pixels_a=int(pixels),
        mean_abs_kink=on / n_on if n_on else math.nan,
        mean_abs_off_kink=off / n_off if n_off else math.nan,
    )


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
