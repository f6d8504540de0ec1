"""Colour of RGB quantities for plots: linear RGB -> sRGB, and Rec. 709 luminance.

Every RGB value in microcyl (f_r, albedo A, renders) is *linear* RGB with the sRGB / Rec. 709
primaries and white point D65. This module is the one place where such a value becomes a colour
on screen: the encoding goes through colour-science (``colour.cctf_encoding`` with the sRGB
inverse EOTF), imported on first use (:func:`analysis.colour.colour_science`). Luminance is
:func:`analysis.colour.luminance` (re-exported here), the one definition of the Rec. 709
weights.
"""

from __future__ import annotations

import numpy as np

from analysis.colour import LUMINANCE_WEIGHTS, colour_science, luminance

__all__ = ["REC709_WEIGHTS", "luminance", "to_srgb", "display_colour", "fabric_colour",
           "line_colour", "CHANNEL_COLOURS"]

#: Rec. 709 luminance weights (R, G, B): :data:`analysis.colour.LUMINANCE_WEIGHTS`.
REC709_WEIGHTS = LUMINANCE_WEIGHTS

#: Matplotlib colours of the three channels when RGB curves are drawn per channel.
CHANNEL_COLOURS = ("tab:red", "tab:green", "tab:blue")


def to_srgb(rgb, exposure: float = 0.0, normalize: bool = False) -> np.ndarray:
    """Encode linear RGB as display sRGB in [0, 1] through colour-science.

    Parameters
    ----------
    rgb : array_like, shape (..., 3)
        Linear RGB (sRGB primaries, D65).
    exposure : float, optional
        Exposure in stops: the linear values are multiplied by ``2**exposure`` first.
    normalize : bool, optional
        If True, divide by the largest channel value (after exposure) first, so the
        brightest value maps to 1 (a colour swatch of the hue, not of the level).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Non-linear sRGB in [0, 1]; values outside [0, 1] in linear light are clipped.

    Notes
    -----
    ``colour.cctf_encoding(np.clip(2**exposure * rgb, 0, 1), function="sRGB")``: the piecewise
    sRGB curve 12.92 x below 0.0031308, 1.055 x^(1/2.4) - 0.055 above.

    Examples
    --------
    >>> to_srgb([0.0, 0.5, 1.0]).round(4).tolist()
    [0.0, 0.7354, 1.0]
    >>> round(float(to_srgb([0.1, 0.2, 0.4], normalize=True)[2]), 12)
    1.0
    """
    arr = np.asarray(rgb, dtype=np.float64)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(f"rgb must have shape (..., 3); got {arr.shape}")
    if not np.isfinite(exposure):
        raise ValueError(f"exposure must be finite; got {exposure}")
    arr = np.where(np.isfinite(arr), arr, 0.0) * 2.0 ** exposure
    if normalize:
        peak = np.max(arr, axis=-1, keepdims=True)
        arr = np.divide(arr, peak, out=np.zeros_like(arr), where=peak > 0)
    encoded = colour_science().cctf_encoding(np.clip(arr, 0.0, 1.0), function="sRGB")
    return np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0)


def display_colour(rgb) -> tuple[float, float, float]:
    """A matplotlib colour (sRGB tuple) showing the hue of a linear RGB value.

    Parameters
    ----------
    rgb : array_like, shape (3,)
        Linear RGB, any scale (normalized so its largest channel is 1).

    Returns
    -------
    tuple of float
        (r, g, b) in [0, 1], sRGB-encoded. Black input gives mid grey.

    Examples
    --------
    >>> display_colour([0.2, 0.0, 0.0])
    (1.0, 0.0, 0.0)
    """
    arr = np.asarray(rgb, dtype=np.float64).reshape(3)
    if not np.any(arr > 0):
        return (0.5, 0.5, 0.5)
    return tuple(float(c) for c in to_srgb(arr, normalize=True))


def fabric_colour(fabric) -> tuple[float, float, float]:
    """The sRGB display colour of a fabric: its area-weighted thread albedo, normalized.

    Parameters
    ----------
    fabric : object
        Anything with ``.threads``, each thread with ``.albedo`` (RGB) and ``.area``. Objects
        without threads get mid grey.

    Returns
    -------
    tuple of float
        (r, g, b) sRGB in [0, 1].

    Notes
    -----
    The colour of sum_j a_j A_j, encoded by :func:`display_colour`. The surface reflection is
    colourless and is left out, so this is the hue of the volume term.
    """
    threads = getattr(fabric, "threads", None)
    if not threads:
        return (0.5, 0.5, 0.5)
    total = np.zeros(3)
    for t in threads:
        total += float(getattr(t, "area", 1.0)) * np.asarray(getattr(t, "albedo"), float).reshape(3)
    return display_colour(total)


def line_colour(fabric, max_luminance: float = 0.2) -> tuple[float, float, float]:
    """The fabric's hue, darkened for lines on white paper.

    Parameters
    ----------
    fabric : object
        As in :func:`fabric_colour`.
    max_luminance : float
        Largest linear luminance of the colour: the normalized linear albedo c (largest
        channel 1) is scaled by min(1, max_luminance / Y(c)) before the sRGB encoding.

    Returns
    -------
    tuple of float
        (r, g, b) sRGB in [0, 1].

    Examples
    --------
    >>> class T:
    ...     albedo, area = (0.5, 0.0, 0.0), 1.0
    >>> class F:
    ...     threads = (T(),)
    >>> line_colour(F())
    (1.0, 0.0, 0.0)
    """
    threads = getattr(fabric, "threads", None)
    if not threads:
        return (0.3, 0.3, 0.3)
    total = np.zeros(3)
    for t in threads:
        total += float(getattr(t, "area", 1.0)) * np.asarray(getattr(t, "albedo"), float).reshape(3)
    if not np.any(total > 0):
        return (0.3, 0.3, 0.3)
    c = np.clip(total, 0.0, None) / np.max(total)
    c = c * min(1.0, max_luminance / float(luminance(c)))
    return tuple(float(v) for v in to_srgb(c))
