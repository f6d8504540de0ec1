"""Exposure of a render: automatic from the cloth's pixels, or given in stops or as a scale.

A render is linear radiance; its PNG shows it multiplied by ``2 ** stops`` and clipped to
[0, 1] before the sRGB encoding (:func:`reports.render.imageio.encode_srgb`). The automatic exposure
(:func:`auto_exposure`, the default of ``microcyl render`` and of the report) looks at the
cloth alone, so that a dark fabric is not exposed for the bright floor beside it: of the
pixels whose primary hit is metered cloth (a coverage mask from the renderer: the fraction of
a pixel's samples that first hit it, at least one half), the :data:`PERCENTILE` th
percentile of their brightest channel, ``max(R, G, B)``, is mapped to :data:`TARGET`; only
1 % of those pixels then clip in any channel. Metered cloth is all of it but the cylinder's
caps (:func:`reports.render.pixelsamples.metered`): the cameras see the top cap nearly
edge-on, where velvet glows with its grazing sheen, and metered on it the cylinder's side
and its rim came out a stop too dark (velvet: +3.0 against +3.95 stops); metered on the
side, the rim shows bright, as a photographer exposes for the subject and lets an edge-on
highlight clip. Without cloth in view, the non-zero pixels of the whole image stand in.

``--exposure`` (:func:`parse_exposure`) overrides it: ``auto``, a number of stops (``1.5``,
``-2``: the PNG is ``2 ** stops`` times the linear values), or a scale with an ``x`` suffix
(``4x``, ``0.25x``: the PNG is that many times the linear values, ``log2(scale)`` stops).
The EXR keeps the linear radiance unscaled and records the exposure in its header
(:func:`exr_attributes`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Exposure", "auto_exposure", "parse_exposure", "exr_attributes", "PERCENTILE",
           "TARGET", "MAX_STOPS"]

#: The percentile of the cloth's brightest channel that the automatic exposure maps to TARGET.
PERCENTILE = 99.0
#: Where that percentile lands, linear (sRGB-encoded about 0.95).
TARGET = 0.9
#: Largest abs(stops) accepted: 2**64 already saturates any f_r.
MAX_STOPS = 64.0


@dataclass(frozen=True)
class Exposure:
    """An exposure: ``stops`` (the PNG is ``2 ** stops`` times the linear values), how it was
    chosen (``auto`` or ``manual``) and, for ``auto``, the reference value mapped to TARGET
    and the number of pixels it was taken from (``cloth`` says whether they were cloth)."""

    stops: float
    mode: str = "manual"
    reference: float = float("nan")
    pixels: int = 0
    cloth: bool = False

    @property
    def scale(self) -> float:
        """``2 ** stops``."""
        return 2.0 ** self.stops

    def describe(self) -> str:
        """One line: the stops and how they were chosen.

        Examples
        --------
        >>> Exposure(2.0).describe()
        'exposure +2.00 stops (x4), given'
        """
        how = "given" if self.mode == "manual" else (
            f"auto: the {PERCENTILE:g}th percentile of max(R, G, B) over "
            f"{self.pixels} {'cloth' if self.cloth else 'non-zero'} pixels, "
            f"{self.reference:.4g}, shown at {TARGET:g}")
        return f"exposure {self.stops:+.2f} stops (x{self.scale:.4g}), {how}"


def _brightest(rgb) -> np.ndarray:
    a = np.asarray(rgb, dtype=np.float64)
    if a.ndim != 3 or a.shape[2] < 3:
        raise ValueError(f"image of shape {a.shape} must be (height, width, 3)")
    return np.nan_to_num(a[..., :3].max(axis=-1), nan=0.0, posinf=0.0, neginf=0.0)


def auto_exposure(rgb, cloth=None, percentile: float = PERCENTILE,
                  target: float = TARGET) -> Exposure:
    """The exposure that shows the cloth's ``percentile`` th brightest channel at ``target``.

    Parameters
    ----------
    rgb : (height, width, 3) array_like
        Linear radiance.
    cloth : (height, width) array_like, optional
        Fraction of each pixel's samples whose primary hit is cloth; pixels of at least 0.5
        count. None, or no such pixel with a non-zero value: the non-zero pixels of the image.
    percentile, target : float
        The percentile (0 to 100) and the linear value it is mapped to.

    Returns
    -------
    Exposure
        ``mode="auto"``; 0 stops for an all-black image.

    Examples
    --------
    >>> img = np.zeros((10, 10, 3)); img[:, :5] = 0.1; img[:, 5:] = 5.0   # cloth, floor
    >>> mask = np.zeros((10, 10)); mask[:, :5] = 1.0
    >>> e = auto_exposure(img, mask)
    >>> round(e.scale * 0.1, 6), e.cloth, e.pixels
    (0.9, True, 50)
    """
    v = _brightest(rgb)
    sel = None
    if cloth is not None:
        c = np.asarray(cloth, dtype=np.float64)
        if c.shape != v.shape:
            raise ValueError(f"cloth mask of shape {c.shape} must be the image's {v.shape}")
        sel = (c >= 0.5) & (v > 0)
    is_cloth = sel is not None and bool(sel.any())
    if not is_cloth:
        sel = v > 0
    if not sel.any():
        return Exposure(0.0, "auto", 0.0, 0, False)
    ref = float(np.percentile(v[sel], percentile))
    stops = float(np.clip(math.log2(target / ref), -MAX_STOPS, MAX_STOPS))
    return Exposure(stops, "auto", ref, int(sel.sum()), is_cloth)


def parse_exposure(text) -> float | None:
    """``--exposure``: None for ``auto``, else stops from a number of stops or an ``x`` scale.

    Examples
    --------
    >>> parse_exposure("auto") is None, parse_exposure("1.5"), parse_exposure("4x")
    (True, 1.5, 2.0)
    >>> parse_exposure("0x")
    Traceback (most recent call last):
    ...
    ValueError: --exposure '0x': the scale must be a positive number
    """
    s = str(text).strip().lower()
    if s == "auto":
        return None
    scale = s.endswith("x")
    try:
        value = float(s[:-1] if scale else s)
    except ValueError:
        raise ValueError(f"--exposure {text!r}: must be auto, a number of stops (1.5, -2) or "
                         f"a scale with an x (4x, 0.25x)") from None
    if scale:
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"--exposure {text!r}: the scale must be a positive number")
        value = math.log2(value)
    if not (math.isfinite(value) and abs(value) <= MAX_STOPS):
        raise ValueError(f"--exposure {text!r}: must be within [-{MAX_STOPS:g}, "
                         f"{MAX_STOPS:g}] stops")
    return value


def exr_attributes(exposure: Exposure) -> dict:
    """Header attributes of an EXR that record ``exposure`` (its pixels stay linear).

    Examples
    --------
    >>> [k.replace("microcyl_exposure", "") for k in sorted(exr_attributes(Exposure(1.0)))]
    ['', '_mode', '_scale', '_stops']
    """
    return {"microcyl_exposure_stops": float(exposure.stops),
            "microcyl_exposure_scale": float(exposure.scale),
            "microcyl_exposure_mode": exposure.mode,
            "microcyl_exposure": exposure.describe()}
