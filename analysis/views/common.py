"""What every view shares: evaluating a BRDF on directions, reducing RGB to a quantity, and
checking the angles and quantities a view is asked for."""

from __future__ import annotations

import numpy as np

from analysis.colour import luminance
from brdf.presets import PRESETS, fabric

__all__ = ["QUANTITIES", "check_quantity", "check_angle", "check_resolution", "as_brdf", "eval_brdf",
           "reduce_quantity", "finite_max"]

#: What a view can show of an RGB f_r: its Rec. 709 luminance, each channel, or one channel.
QUANTITIES = ("luminance", "rgb", "r", "g", "b")


def check_quantity(quantity: str) -> str:
    """``quantity`` when it is one of :data:`QUANTITIES`, else a ValueError naming it."""
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {', '.join(QUANTITIES)}; got {quantity!r}")
    return quantity


def check_angle(name: str, value, lo: float, hi: float) -> np.ndarray:
    """``value`` (degrees) as float64 when every element is finite and in [lo, hi]."""
    arr = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)) or np.any(arr < lo) or np.any(arr > hi):
        raise ValueError(f"{name} must be in [{lo:g}, {hi:g}] degrees; got {value!r}")
    return arr


def check_resolution(resolution, least: int) -> int:
    """``resolution`` as an int when it is at least ``least``."""
    if int(resolution) < least:
        raise ValueError(f"resolution must be at least {least}; got {resolution}")
    return int(resolution)


def as_brdf(brdf, name: str = "brdf"):
    """What a view evaluates: ``brdf`` itself when it has ``eval(wi, wo)`` (a
    :class:`brdf.Fabric`, a fit's model, a table), the preset's fabric when it is a name of
    :data:`brdf.PRESETS`.

    Raises
    ------
    ValueError
        A string that names no preset (the presets are listed).
    TypeError
        Anything else, naming ``name`` and the type.

    Examples
    --------
    >>> as_brdf("velvet").name
    'velvet'
    """
    if isinstance(brdf, str):
        if brdf not in PRESETS:
            raise ValueError(f"{name} must be a preset ({', '.join(PRESETS)}) or a BRDF with "
                             f"eval(wi, wo); got {brdf!r}")
        return fabric(brdf)
    if not callable(getattr(brdf, "eval", None)):
        raise TypeError(f"{name} must be a preset name or a BRDF with eval(wi, wo) (e.g. a "
                        f"brdf.Fabric); got {type(brdf).__name__}")
    return brdf


def eval_brdf(brdf, wi, wo) -> np.ndarray:
    """``brdf.eval(wi, wo)`` broadcast to a common shape, as float64 (..., 3) in 1/sr;
    ``brdf`` may name a preset (:func:`as_brdf`).

    Examples
    --------
    >>> class Half:
    ...     def eval(self, wi, wo):
    ...         return np.full(wi.shape, 0.5)
    >>> eval_brdf(Half(), [0.0, 0.0, 1.0], np.zeros((2, 4, 3))).shape
    (2, 4, 3)
    """
    brdf = as_brdf(brdf)
    wi = np.asarray(wi, dtype=np.float64)
    wo = np.asarray(wo, dtype=np.float64)
    shape = np.broadcast_shapes(wi.shape, wo.shape)
    wi = np.broadcast_to(wi, shape)
    wo = np.broadcast_to(wo, shape)
    flat = np.asarray(brdf.eval(wi.reshape(-1, 3), wo.reshape(-1, 3)), dtype=np.float64)
    return flat.reshape(shape[:-1] + (3,))


def reduce_quantity(values: np.ndarray, quantity: str) -> np.ndarray:
    """(..., 3) RGB -> (...,) luminance or one channel, or (..., 3) unchanged for "rgb".

    Examples
    --------
    >>> reduce_quantity(np.array([[0.1, 0.2, 0.3]]), "g").tolist()
    [0.2]
    """
    check_quantity(quantity)
    if quantity == "luminance":
        return luminance(values)
    if quantity == "rgb":
        return values
    return values[..., "rgb".index(quantity)]


def finite_max(values) -> float:
    """The largest finite value (0 when there is none).

    Examples
    --------
    >>> finite_max([1.0, np.inf, np.nan, 3.0]), finite_max([np.nan])
    (3.0, 0.0)
    """
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    return float(v.max()) if v.size else 0.0
