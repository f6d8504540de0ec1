r"""Colour of linear RGB quantities: luminance, albedo colours, CIEDE2000 (colour-science).

Every RGB value in microcyl (f_r, albedo A, renders) is *linear* RGB with the sRGB / Rec. 709
primaries and white point D65. Luminance is the Y row of colour-science's sRGB RGB -> XYZ
matrix (IEC 61966-2-1), Y = 0.2126 R + 0.7152 G + 0.0722 B: the Rec. ITU-R BT.709 luma
weights as that standard prints them. (colour-science's ``"ITU-R BT.709"`` colourspace derives
its matrix from the primaries instead, 0.212639 R + 0.715169 G + 0.072192 B: the same to 4e-5.)
"""

from __future__ import annotations

import numpy as np

from analysis.likelihood import is_grey

__all__ = ["LUMINANCE_WEIGHTS", "luminance", "albedo_colours", "albedo_delta_e",
           "colour_science"]


def colour_science():
    """colour-science, imported on use: ``import colour`` also loads its plotting package and
    matplotlib (about 1.5 s), which every ``microcyl`` verb would pay through this package."""
    import colour
    return colour


#: The luminance weights (R, G, B) of linear RGB: the Y row of the sRGB RGB -> XYZ matrix as
#: IEC 61966-2-1 prints it, which is colour-science's ``RGB_COLOURSPACES["sRGB"]`` row
#: (``tests/test_analysis_colour.py`` holds the two equal). Written here, not read from
#: colour-science on use, because ``import colour`` costs every verb that shows a luminance
#: about 1.3 s (it loads its plotting package and matplotlib).
LUMINANCE_WEIGHTS = np.array([0.2126, 0.7152, 0.0722])
LUMINANCE_WEIGHTS.setflags(write=False)


def luminance(rgb) -> np.ndarray:
    """Rec. 709 luminance Y = 0.2126 R + 0.7152 G + 0.0722 B of linear RGB.

    Parameters
    ----------
    rgb : array_like, shape (..., 3)
        Linear RGB, any unit (f_r in 1/sr gives Y in 1/sr).

    Returns
    -------
    numpy.ndarray, shape (...)
        Luminance, same unit as the input.

    Raises
    ------
    ValueError
        If the last axis does not have length 3.

    Notes
    -----
    Y = rgb @ :data:`LUMINANCE_WEIGHTS`, the weights from colour-science's sRGB colourspace.

    Examples
    --------
    >>> float(luminance([1.0, 1.0, 1.0]))
    1.0
    >>> float(luminance([0.0, 1.0, 0.0]))
    0.7152
    """
    arr = np.asarray(rgb, dtype=np.float64)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(f"rgb must have shape (..., 3); got {arr.shape}")
    return arr @ LUMINANCE_WEIGHTS


def albedo_colours(table, prediction):
    r"""Albedo colours (linear RGB) of a table and of a prediction, by the same estimator.

    rho = 2 pi mean over valid points of f_r cos(theta_o): the uniform-hemisphere Monte Carlo
    estimate of the directional albedo averaged over the table's incidences (unitless); the
    prediction (f_r in 1/sr at the table's pairs, (n, 3)) uses the same points and mask, so
    the two are comparable whatever the sampling. A grey table (R = G = B everywhere: CUReT)
    is compared with the grey of the prediction, the mean of its channels.

    Parameters
    ----------
    table : gonio.Table
        The measured table (f_r in 1/sr, or relative for CUReT).
    prediction : array_like, shape (n, 3)
        The model's f_r (1/sr) at the table's pairs.

    Returns
    -------
    measured, predicted : ndarray (3,)
        Albedo colours, unitless (relative for a relative table).

    Examples
    --------
    >>> from gonio.table import Table
    >>> t = Table([[0, 0, 1.0]], [[0, 0, 1.0]], [[0.1, 0.2, 0.3]])
    >>> m, p = albedo_colours(t, np.array([[0.1, 0.2, 0.3]]))
    >>> np.allclose(m, p), round(float(m[0]), 4)           # 2 pi 0.1
    (True, 0.6283)
    """
    prediction = np.asarray(prediction, dtype=np.float64)
    if is_grey(table.values):
        prediction = np.repeat(prediction.mean(axis=-1, keepdims=True), 3, axis=-1)
    valid = table.valid & np.isfinite(prediction)
    cos_o = np.clip(table.wo[:, 2], 0, None)[:, None]
    meas = np.where(valid, table.values, 0.0) * cos_o
    pred = np.where(valid, prediction, 0.0) * cos_o
    cnt = np.maximum(valid.sum(0), 1)
    return 2 * np.pi * meas.sum(0) / cnt, 2 * np.pi * pred.sum(0) / cnt


def albedo_delta_e(measured, predicted) -> float:
    """CIEDE2000 difference between two linear-sRGB colours (colour-science).

    Parameters
    ----------
    measured, predicted : array_like, shape (3,)
        Linear sRGB (negative channels are clipped to 0).

    Returns
    -------
    float
        Delta E 2000 of their CIE Lab colours (D65), unitless (about 1 is just noticeable).

    Examples
    --------
    >>> albedo_delta_e([0.2, 0.2, 0.2], [0.2, 0.2, 0.2])
    0.0
    >>> albedo_delta_e([0.2, 0.1, 0.05], [0.2, 0.2, 0.2]) > 5
    True
    """
    colour = colour_science()
    labs = [colour.XYZ_to_Lab(colour.sRGB_to_XYZ(np.clip(np.asarray(c, float), 0, None),
                                                 apply_cctf_decoding=False))
            for c in (measured, predicted)]
    return float(colour.delta_E(labs[0], labs[1], method="CIE 2000"))

