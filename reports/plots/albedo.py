"""Directional albedo against theta, with error bars."""

from __future__ import annotations

import numpy as np

from analysis import AlbedoCurve, AlbedoResult
from reports.plots.common import (FONT, check_quantity, finish, legend_outside, new_axes,
                               quantity_styles)
from reports.colour import REC709_WEIGHTS, luminance

__all__ = ["plot_albedo"]


def plot_albedo(theta_deg, albedo, error=None, *, quantity="rgb", colour=None, label=None,
                style=None, legend=True, ax=None, filename=None, title=None):
    """Albedo rho(theta) with error bars, and the line rho = 1.

    Parameters
    ----------
    theta_deg : array_like, shape (n,)
        Polar angles in degrees.
    albedo : array_like, shape (n,) or (n, 3), or analysis.AlbedoResult or AlbedoCurve
        Unitless albedo; a result of ``analysis.albedo`` (or ``analysis.albedo_curve`` over
        one azimuth) is accepted in its place.
    error : array_like, optional
        One standard error per value (same shape as ``albedo``); taken from the result's
        ``.error`` when ``albedo`` is a result.
    quantity : {"rgb", "luminance", "r", "g", "b"}
        "rgb" draws red, green and blue curves; "luminance" one curve in ``colour`` (e.g. the
        fabric's sRGB colour). Grey (n,) input is drawn as given whatever the quantity.
    label : str, optional
        Prefix of the legend labels (e.g. a fabric name).
    style : dict, optional
        Colour, line style and marker of a grey or luminance curve (e.g.
        :func:`reports.plots.common.preset_style` of the fabric, so that every fabric of an
        overlay differs in all three); overrides ``colour``.
    legend : bool
        Draw the legend beside the axes (8 pt).

    Returns
    -------
    (fig, ax)
        One errorbar container per curve; its Line2D (gid "albedo <label> <channel>") holds
        x = theta in degrees, y = albedo.

    Notes
    -----
    Luminance error is propagated assuming independent channels:
    sigma_Y = sqrt(sum_c w_c^2 sigma_c^2) with the Rec. 709 weights w.
    """
    check_quantity(quantity)
    if isinstance(albedo, (AlbedoResult, AlbedoCurve)):
        if error is None:
            error = albedo.error
        albedo = albedo.value
    theta = np.asarray(theta_deg, dtype=np.float64).reshape(-1)
    val = np.asarray(albedo, dtype=np.float64)
    err = None if error is None else np.asarray(error, dtype=np.float64)
    if val.shape[0] != theta.shape[0] or val.ndim not in (1, 2) or (
            val.ndim == 2 and val.shape[1] != 3):
        raise ValueError(f"albedo must have shape ({theta.shape[0]},) or ({theta.shape[0]}, 3); "
                         f"got {val.shape}")
    if err is not None and err.shape != val.shape:
        raise ValueError(f"error must have the shape of albedo {val.shape}; got {err.shape}")
    fig, ax = new_axes(ax)
    if val.ndim == 1:
        series = [(val, err, colour or "black", "")]
    elif quantity == "luminance":
        e = None if err is None else np.sqrt((err ** 2) @ (REC709_WEIGHTS ** 2))
        series = [(luminance(val), e, colour or "black", " luminance")]
    else:
        series = [(val[:, k], None if err is None else err[:, k], col, suffix)
                  for k, col, suffix in quantity_styles(quantity)]
    prefix = label or "albedo"
    for y, e, col, suffix in series:
        st = {"color": col, "ls": "-", "marker": "o"}
        if style is not None and len(series) == 1:
            st.update(style)
        cont = ax.errorbar(theta, y, yerr=e, color=st["color"], ls=st["ls"], lw=1.4,
                           capsize=2, ms=4, mfc="none",
                           marker=st["marker"] if theta.size <= 30 else None,
                           label=f"{prefix}{suffix}")
        channel = suffix.strip().lower() if suffix.strip() else "grey"
        cont.lines[0].set_gid(f"albedo {prefix} {channel if channel in 'rgb' else channel}")
    _decorate(ax, legend, title)
    return finish(fig, ax, filename)


def _decorate(ax, legend, title):
    """The line albedo = 1 (once), labels with units, 8 pt ticks, the legend, the title."""
    if not any(line.get_gid() == "unit" for line in ax.get_lines()):
        ref = ax.axhline(1.0, color="0.5", ls=":", lw=1.0)
        ref.set_gid("unit")
    ax.set_xlabel("θ (degrees)", fontsize=FONT["label"])
    ax.set_ylabel("directional albedo (unitless)", fontsize=FONT["label"])
    ax.set_xlim(0, 90)
    ax.tick_params(labelsize=FONT["small"])
    ax.grid(alpha=0.3)
    if legend:
        legend_outside(ax, "right")
    ax.set_title(title or "directional albedo", fontsize=FONT["title"])
