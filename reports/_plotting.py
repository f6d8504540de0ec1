"""Shared helpers of the plot modules: axes, atomic saving, BRDF evaluation, quantities.

Private to :mod:`reports`; the public plot functions live in ``reports/plot_*.py`` and are
gathered in :mod:`reports.plots`.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from brdf.frames import half_diff_to_directions
from gonio.atomic import atomic_write
from reports.colour import CHANNEL_COLOURS, luminance

__all__ = ["new_axes", "finish", "save_figure", "eval_brdf", "reduce_quantity",
           "quantity_styles", "QUANTITIES", "check_quantity", "half_diff_to_io", "check_angle"]

#: What a plot can show of an RGB f_r: its Rec. 709 luminance, each channel, or one channel.
QUANTITIES = ("luminance", "rgb", "r", "g", "b")


def new_axes(ax=None, *, projection=None, figsize=(5.0, 4.0)):
    """Return ``(fig, ax)``: ``ax`` and its figure, or a new figure with one axes.

    Parameters
    ----------
    ax : matplotlib Axes, optional
        Axes to draw into. Its projection must match ``projection``.
    projection : str, optional
        "polar", "3d" or None (cartesian) for a new axes.
    figsize : tuple of float
        Size in inches of a new figure.
    """
    if ax is not None:
        name = getattr(ax, "name", "rectilinear")
        want = projection or "rectilinear"
        if name != want:
            raise ValueError(f"ax must have projection {want!r}; got {name!r}")
        return ax.figure, ax
    fig = plt.figure(figsize=figsize) if _use_pyplot() else Figure(figsize=figsize)
    ax = fig.add_subplot(1, 1, 1, projection=projection)
    return fig, ax


def _use_pyplot() -> bool:
    # Figures made through pyplot show up in notebooks; under a non-interactive backend a
    # bare Figure avoids pyplot's global figure list (no leaks in long reports).
    backend = matplotlib.get_backend().lower()
    return not (backend == "agg" or backend.endswith("backend_agg") or backend in ("pdf", "svg"))


def save_figure(fig, filename, dpi: int = 110) -> Path:
    """Save ``fig`` to ``filename`` atomically (temporary file in the same folder, then
    ``os.replace``); the format comes from the file's suffix.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    path = Path(filename)
    fmt = path.suffix.lstrip(".").lower() or "png"
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format=fmt, dpi=dpi, bbox_inches="tight")
    return path


def finish(fig, ax, filename=None, *, dpi: int = 110):
    """Save when ``filename`` is given; return ``(fig, ax)``."""
    if filename is not None:
        save_figure(fig, filename, dpi=dpi)
    return fig, ax


def check_quantity(quantity: str) -> str:
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {', '.join(QUANTITIES)}; got {quantity!r}")
    return quantity


def check_angle(name: str, value, lo: float, hi: float) -> np.ndarray:
    arr = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)) or np.any(arr < lo) or np.any(arr > hi):
        raise ValueError(f"{name} must be in [{lo:g}, {hi:g}] degrees; got {value!r}")
    return arr


def eval_brdf(brdf, wi, wo) -> np.ndarray:
    """``brdf.eval(wi, wo)`` broadcast to a common shape, as float64 (..., 3) in 1/sr."""
    wi = np.asarray(wi, dtype=np.float64)
    wo = np.asarray(wo, dtype=np.float64)
    shape = np.broadcast_shapes(wi.shape, wo.shape)
    wi = np.broadcast_to(wi, shape)
    wo = np.broadcast_to(wo, shape)
    flat = np.asarray(brdf.eval(wi.reshape(-1, 3), wo.reshape(-1, 3)), dtype=np.float64)
    return flat.reshape(shape[:-1] + (3,))


def reduce_quantity(values: np.ndarray, quantity: str) -> np.ndarray:
    """(..., 3) RGB -> (...,) luminance or one channel, or (..., 3) unchanged for "rgb"."""
    check_quantity(quantity)
    if quantity == "luminance":
        return luminance(values)
    if quantity == "rgb":
        return values
    return values[..., "rgb".index(quantity)]


def quantity_styles(quantity: str, colour=None):
    """[(channel index or None, colour, label suffix)] for the curves of ``quantity``.

    Per-channel curves ("rgb", "r", "g", "b") are drawn in red, green and blue; luminance
    in ``colour`` (the fabric's own sRGB colour, or black).
    """
    check_quantity(quantity)
    if quantity == "rgb":
        return [(k, CHANNEL_COLOURS[k], " " + "RGB"[k]) for k in range(3)]
    if quantity == "luminance":
        return [(None, colour or "black", "")]
    k = "rgb".index(quantity)
    return [(k, CHANNEL_COLOURS[k], " " + "RGB"[k])]


def half_diff_to_io(theta_h, theta_d, phi_d, phi_h=0.0):
    """Rusinkiewicz half/difference angles (radians) -> (wi, wo), each (..., 3):
    :func:`brdf.frames.half_diff_to_directions` with the plots' argument order."""
    return half_diff_to_directions(theta_h, phi_h, theta_d, phi_d)
