"""Shared helpers of the plot modules: axes, atomic saving, styles, quantities (BRDF
evaluation and the quantities' reduction are :mod:`analysis.views`', re-exported here).

Private to :mod:`reports`; the public plot functions live in ``reports/plot_*.py`` and are
gathered in :mod:`reports.plots`.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure
from matplotlib.transforms import ScaledTranslation

from analysis.views.common import (QUANTITIES, as_brdf, check_angle, check_quantity,
                                   eval_brdf, reduce_quantity)
from brdf.frames import half_diff_to_directions
from brdf.presets import PRESETS
from gonio.atomic import atomic_write
from reports.colour import CHANNEL_COLOURS
from reports.plots.halfdisc import HalfDiscAxes

__all__ = ["new_axes", "finish", "save_figure", "as_brdf", "eval_brdf", "reduce_quantity",
           "quantity_styles", "QUANTITIES", "check_quantity", "half_diff_to_io", "check_angle",
           "DPI", "FONT", "PALETTE", "series_style", "preset_style", "series_styles",
           "legend_outside", "log_range", "pow10_label", "shade_zero"]

#: Resolution of raster (PNG) figures, dots per inch.
DPI = 200
#: Font sizes in points: tick labels and legends (the smallest text of any figure), axis
#: labels, titles.
FONT = {"small": 8.0, "label": 9.0, "title": 9.5}
#: Okabe and Ito's colour-blind-safe palette (blue, vermilion, bluish green, reddish purple,
#: orange, sky blue, black), one colour per series.
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000")
_DASHES = ("-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)), (0, (8, 2)), (0, (1, 1)))
_MARKERS = ("o", "s", "^", "D", "v", "P", "X")


def series_style(n: int) -> dict:
    """Colour, line style and marker of the ``n``-th series of a figure: no two of the first
    seven share any of the three (colour-blind safe: :data:`PALETTE`).

    Examples
    --------
    >>> series_style(0)["color"], series_style(1)["ls"], series_style(2)["marker"]
    ('#0072B2', '--', '^')
    """
    n = int(n)
    return {"color": PALETTE[n % len(PALETTE)], "ls": _DASHES[n % len(_DASHES)],
            "marker": _MARKERS[n % len(_MARKERS)]}


def preset_style(name: str, n: int = 0) -> dict:
    """:func:`series_style` of a preset by its place in ``brdf.PRESETS`` (the same in every
    figure); another name takes the ``n``-th style after the presets'."""
    return series_style(PRESETS.index(name) if name in PRESETS else len(PRESETS) + n)


def series_styles(names) -> dict:
    """Name -> style for the series of one figure: a preset keeps :func:`preset_style`,
    another name (a fit, a user's model) takes the first style no preset of ``names`` has.

    Examples
    --------
    >>> st = series_styles(["linen_plain", "fit"])
    >>> st["linen_plain"]["color"] != st["fit"]["color"]
    True
    """
    names = list(names)
    used = {PRESETS.index(n) for n in names if n in PRESETS}
    free = (k for k in range(len(PRESETS) + len(names) + 1) if k not in used)
    return {n: preset_style(n) if n in PRESETS else series_style(next(free)) for n in names}


def legend_outside(ax, where="right", *, ncol=1, below_pt=34.0, **kw):
    """A legend beside the axes (``where`` "right") or ``below_pt`` points under it
    ("below": clear of the tick labels and axis label), in 8 pt, so it hides no data; a
    constrained-layout figure makes room for it."""
    if where not in ("right", "below"):
        raise ValueError(f"where must be 'right' or 'below'; got {where!r}")
    if where == "right":
        return ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=FONT["small"],
                         ncol=ncol, frameon=False, **kw)
    anchor, base = (0.5, 0.0), ax.transAxes
    if ax.name == "polar" and ax.get_thetamax() - ax.get_thetamin() <= 180.0 + 1e-9:
        # a half disc fills the middle of its square box: under the disc's centre (the
        # bottom of its flat edge), not under the box, which would leave a gap as high as
        # the disc's radius between them
        anchor, base = (0.0, 0.0), ax.transData
    shift = base + ScaledTranslation(0.0, -below_pt / 72.0, ax.figure.dpi_scale_trans)
    return ax.legend(loc="upper center", bbox_to_anchor=anchor, bbox_transform=shift,
                     fontsize=FONT["small"], ncol=ncol, frameon=False, **kw)


def log_range(series, decades: float = 6.0):
    """The log axis of curves (values in 1/sr, one array a series): whole decades from the
    largest value down ``decades``, or only down to the smallest positive value drawn when
    that is nearer, and which series peak below the axis (to be drawn apart or noted, never
    stretching it).

    Returns
    -------
    (lo, hi) : tuple of float
        Powers of ten.
    below : numpy.ndarray of bool
        True for series whose peak is under ``lo`` (or none of whose values is positive).

    Examples
    --------
    >>> lims, below = log_range([[0.3, 0.01], [0.02, 0.001], [1e-18, 0.0]], 6)
    >>> lims, below.tolist()
    ((0.001, 1.0), [False, False, True])
    """
    arrays = [np.asarray(v, dtype=np.float64).ravel() for v in series]
    peaks = np.array([np.nanmax(a, initial=0.0) for a in arrays])
    if not np.any(peaks > 0):
        return (1e-3, 1.0), np.ones(peaks.shape, bool)
    hi = float(np.ceil(np.log10(peaks.max())))
    lo = hi - float(np.ceil(decades))
    below = ~(peaks >= 10.0 ** lo)
    kept = np.concatenate([a[np.isfinite(a) & (a > 0)] for a, b in zip(arrays, below) if not b])
    lo = max(lo, float(np.floor(np.log10(kept.min()))))
    return (10.0 ** lo, 10.0 ** max(hi, lo + 1.0)), below


def shade_zero(ax, x, zero, *, label="f_r = 0"):
    """Grey bands over the runs of ``x`` where ``zero`` (bool, per sample) holds, labelled
    once (``label``) for the legend: zero has no place on a log axis, so it is shown apart."""
    zero = np.asarray(zero, bool)
    x = np.asarray(x, dtype=np.float64)
    if not zero.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate([[0], zero.astype(int), [0]])))
    step = (x[-1] - x[0]) / max(len(x) - 1, 1)
    for n, (a, b) in enumerate(zip(edges[::2], edges[1::2] - 1)):
        ax.axvspan(x[a] - step / 2, x[b] + step / 2, color="0.88", hatch="//", ec="0.7",
                   lw=0, label=label if n == 0 else None, zorder=0)


def pow10_label(exponent: int) -> str:
    """Mathtext label 10^k of a decade (``"$10^{-3}$"``)."""
    return f"$10^{{{int(exponent)}}}$"


def new_axes(ax=None, *, projection=None, figsize=(5.0, 4.0)):
    """Return ``(fig, ax)``: ``ax`` and its figure, or a new figure with one axes.

    Parameters
    ----------
    ax : matplotlib Axes, optional
        Axes to draw into. Its projection must match ``projection``.
    projection : str, optional
        "polar", "halfdisc" (polar, theta_o from -90 to 90 degrees in a box of the half
        disc's shape: :class:`reports.plots.halfdisc.HalfDiscAxes`), "3d" or None
        (cartesian) for a new axes; a given ``ax`` for "halfdisc" may be any polar axes.
    figsize : tuple of float
        Size in inches of a new figure.
    """
    if ax is not None:
        name = getattr(ax, "name", "rectilinear")
        want = {None: "rectilinear", "halfdisc": "polar"}.get(projection, projection)
        if name != want:
            raise ValueError(f"ax must have projection {want!r}; got {name!r}")
        return ax.figure, ax
    fig = (plt.figure(figsize=figsize, layout="constrained") if _use_pyplot()
           else Figure(figsize=figsize, layout="constrained"))
    kind = ({"axes_class": HalfDiscAxes} if projection == "halfdisc"
            else {"projection": projection})
    ax = fig.add_subplot(1, 1, 1, **kind)
    return fig, ax


def _use_pyplot() -> bool:
    # Figures made through pyplot show up in notebooks; under a non-interactive backend a
    # bare Figure avoids pyplot's global figure list (no leaks in long reports).
    backend = matplotlib.get_backend().lower()
    return not (backend == "agg" or backend.endswith("backend_agg") or backend in ("pdf", "svg"))


def save_figure(fig, filename, dpi: int = DPI) -> Path:
    """Save ``fig`` to ``filename`` atomically (temporary file in the same folder, then
    ``os.replace``); the format comes from the file's suffix: PNG at ``dpi`` dots per inch,
    PDF and SVG as vector graphics.

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


def finish(fig, ax, filename=None, *, dpi: int = DPI):
    """Save when ``filename`` is given; return ``(fig, ax)``."""
    if filename is not None:
        save_figure(fig, filename, dpi=dpi)
    return fig, ax


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
