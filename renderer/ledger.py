"""Comparing the two pipelines: the §4 ledger and display helpers."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .render import SPHERE_A, Frame

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
    on_a = (numeric.chamber == SPHERE_A) & (symbolic.chamber == SPHERE_A)
    # |dI| on sphere A only, pixels in raster order.
    da = np.abs(numeric.image[on_a] - symbolic.image[on_a])
    band = symbolic.kink[on_a]

    def mean(m):
        return float(da[m].mean()) if m.any() else float("nan")

    with np.errstate(under="ignore"):       # a tiny |dI| squared rounds to 0, as it should
        rms = float(np.sqrt(np.mean(da**2))) if da.size else 0.0
    return Ledger(
        max_abs=float(da.max()) if da.size else 0.0,
        rms=rms,
        flips=int(np.count_nonzero(numeric.chamber != symbolic.chamber)),
        pixels_a=int(da.shape[0]),
        mean_abs_kink=mean(band),
        mean_abs_off_kink=mean(~band),
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
