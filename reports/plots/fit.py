"""Model curves over measured table points in a plane of incidence, with error bars: one
model at several incidences, or several models (presets, fits) at one; and a table of
scattered pairs against models at every point (:func:`draw_table_scatter`)."""

from __future__ import annotations

import numpy as np

from analysis.views import (FitOverlayView, TablePanelView, TableScatterView,
                            compute_fit_overlay,
                            compute_table_panel, plane_incidences, plane_lights, plane_points,
                            table_panels, table_points)
from reports.plots.common import (FONT, finish, legend_outside, log_range, new_axes,
                               quantity_styles, series_styles)

__all__ = ["plane_points", "plane_lights", "plot_fit_overlay", "plot_table_models",
           "draw_table_models", "draw_fit_overlay", "plane_incidences", "table_panels",
           "table_points", "draw_table_scatter", "draw_scatter_residuals"]


def plot_fit_overlay(table, brdf, phi_deg=0.0, theta_i_deg=None, *, quantity="rgb",
                     tol_deg=2.0, resolution=181, log=False, max_incidences=4, ax=None,
                     filename=None, title=None):
    """Measured points (with error bars) and model curves against signed theta_o.

    Parameters
    ----------
    table : gonio.Table
        Measured f_r (1/sr), optional sigma; invalid values (NaN, negative) are skipped.
    brdf : object with ``.eval``
        The model drawn as curves through the same wi.
    phi_deg : float
        Azimuth of the plane of incidence in degrees.
    theta_i_deg : sequence of float, optional
        Incidences to show (degrees, matched within 0.5 degree); default the first
        ``max_incidences`` distinct incidences found in the plane.
    quantity : {"rgb", "luminance", "r", "g", "b"}
        "rgb": each channel in red, green and blue, one marker per incidence; "luminance":
        Rec. 709 luminance in black.
    tol_deg : float
        Azimuth tolerance for points in the plane, degrees.

    Returns
    -------
    (fig, ax)
        Model lines have gid "model theta_i=<deg> <channel>" (x signed theta_o in degrees,
        y f_r in 1/sr), measured points are errorbar containers whose data line has gid
        "data theta_i=<deg> <channel>".

    Raises
    ------
    ValueError
        If no valid table point lies in the plane.

    Notes
    -----
    Luminance sigma assumes independent channels: sqrt(sum_c w_c^2 sigma_c^2).
    """
    view = compute_fit_overlay(table, brdf, phi_deg, theta_i_deg, quantity=quantity,
                               tol_deg=tol_deg, resolution=resolution,
                               max_incidences=max_incidences)
    return draw_fit_overlay(view, log=log, ax=ax, filename=filename, title=title)


def draw_fit_overlay(view: FitOverlayView, *, log=False, ax=None, filename=None, title=None):
    """Draw a :class:`analysis.views.FitOverlayView` (:func:`plot_fit_overlay` computes one
    and calls this); the arguments and the result as :func:`plot_fit_overlay`'s."""
    fig, ax = new_axes(ax, figsize=(6.0, 4.0))
    for n, g in enumerate(view.groups):
        _draw_incidence(ax, n, g["theta_i"], view.quantity, view.x_model, g["model"], g["x"],
                        g["measured"], g["sigma"],
                        f", φi = {g['light'] % 360:g}°" if view.both_sides else "")
    phi_deg = view.phi_deg
    if log:
        ax.set_yscale("log")
    _cartesian_labels(ax)
    legend_outside(ax, "right")
    ax.set_title(title or f"model and measurement, plane φ = {phi_deg:g}°",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)


def _cartesian_labels(ax):
    ax.set_xlabel("signed θo (degrees; the light on the negative side)", fontsize=FONT["label"])
    ax.set_ylabel("f_r (1/sr)", fontsize=FONT["label"])
    ax.set_xlim(-90, 90)
    ax.set_xticks(np.arange(-90, 91, 30))
    ax.tick_params(labelsize=FONT["small"])
    ax.grid(alpha=0.3)


def plot_table_models(table, models, theta_i_deg, phi_deg=0.0, *, light_deg=None,
                      quantity="luminance", tol_deg=2.0, resolution=181, log=True,
                      decades=6.0, legend=True, ax=None, filename=None, title=None):
    """A measured table at one incidence in a plane (black circles with error bars) against
    models, each curve in its own colour and line style (:func:`series_styles`), evaluated
    with the light where it was measured (:func:`table_points`); each model's value at
    each measured point's own directions is a small filled marker on its curve.

    Parameters
    ----------
    table : gonio.Table
        Measured f_r (1/sr); invalid values are skipped.
    models : mapping of str to BRDF
        Label -> object with ``.eval`` (a preset, a fitted fabric).
    theta_i_deg : float
        Incidence in degrees, matched within 0.5 degree to the table's.
    phi_deg : float
        Azimuth of the plane of incidence in degrees.
    light_deg : float, optional
        The light's azimuth, degrees (:func:`table_points`).
    quantity : {"luminance", "r", "g", "b"}
        What of f_r is drawn.
    log, decades : bool, float
        Log axis over the decades that hold the data (:func:`log_range`); measured zeros
        sit on the lower edge as open triangles labelled "f_r = 0".

    Returns
    -------
    (fig, ax)
        The measured points' Line2D has gid "data", each model's curve "model <label>" and
        its values at the measured points "model points <label>" (x signed theta_o in
        degrees, + away from the light, y f_r in 1/sr).
    """
    panel = compute_table_panel(table, models, theta_i_deg, phi_deg, light_deg,
                                quantity=quantity, tol_deg=tol_deg, resolution=resolution)
    return draw_table_models(panel, log=log, decades=decades, legend=legend, ax=ax,
                             filename=filename, title=title)


def draw_table_models(panel: TablePanelView, *, log=True, decades=6.0, legend=True, ax=None,
                      filename=None, title=None):
    """Draw a :class:`analysis.views.TablePanelView` (:func:`plot_table_models` computes one
    and calls this); the arguments and the result as :func:`plot_table_models`'s."""
    pts, curves, x_model = panel.points, panel.curves, panel.x_model
    quantity, theta_i_deg, tol_deg = panel.quantity, panel.theta_i_deg, panel.tol_deg
    fig, ax = new_axes(ax, figsize=(6.0, 3.8))
    x, y, err = pts["x"], pts["measured"], pts["sigma"]
    styles = series_styles(curves)
    for name, c in curves.items():
        st = styles[name]
        line, = ax.plot(x_model, c, color=st["color"], ls=st["ls"], lw=1.5, label=name)
        line.set_gid(f"model {name}")
        dots, = ax.plot(x, pts["models"][name], ls="", marker=".", ms=3.5, color=st["color"],
                        label="_nolegend_", zorder=2.5)
        dots.set_gid(f"model points {name}")
    cont = ax.errorbar(x, y, yerr=err, ls="", marker="o", ms=4, mfc="none", color="k",
                       capsize=1.5, label="measured", zorder=3)
    cont.lines[0].set_gid("data")
    if log:
        (lo, hi), _ = log_range([y, *curves.values()], decades)
        ax.set_yscale("log")
        ax.set_ylim(lo, hi)
        if np.any(y <= 0):
            ax.plot(x[y <= 0], np.full(int(np.sum(y <= 0)), lo), ls="", marker="v",
                    mfc="none", color="k", ms=5, clip_on=False, label="measured f_r = 0")
    _cartesian_labels(ax)
    if legend:
        legend_outside(ax, "right")
    what = "luminance" if quantity == "luminance" else f"{quantity.upper()} channel"
    where = ("at the normal" if pts["theta_i"] <= tol_deg
             else f"at φi = {pts['light'] % 360:g}°")
    ax.set_title(title or f"θi = {float(theta_i_deg):g}°, light {where}, {what}",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)


def _draw_incidence(ax, n, t, quantity, x_model, model, to, meas, err, where=""):
    """Model lines and measured points (``to`` signed theta_o, degrees) of incidence ``t``,
    the ``n``-th drawn, one per style of ``quantity``; ``where`` ends the labels."""
    markers = "osD^v<>"
    order = np.argsort(to)
    for k, col, suffix in quantity_styles(quantity):
        channel = "luminance" if k is None else "rgb"[k]
        y = model[:, k] if model.ndim == 2 else model
        line, = ax.plot(x_model, y, color=col, lw=1.0, ls=["-", "--", ":", "-."][n % 4],
                        label=f"model θi = {t:g}°{where}{suffix}")
        line.set_gid(f"model theta_i={t:g} {channel}")
        ym = (meas[:, k] if meas.ndim == 2 else meas)[order]
        em = None if err is None else (err[:, k] if err.ndim == 2 else err)[order]
        cont = ax.errorbar(to[order], ym, yerr=em, color=col, ls="",
                           marker=markers[n % len(markers)], ms=3.5, mfc="none",
                           capsize=1.5, label=f"data θi = {t:g}°{where}{suffix}")
        cont.lines[0].set_gid(f"data theta_i={t:g} {channel}")


def draw_table_scatter(view: TableScatterView, *, log=True, legend=True, ax=None,
                       filename=None, title=None):
    """Measured f_r (x, with its sigma as error bars) against every model's at the same
    pair (y) for every valid point of a :class:`analysis.views.TableScatterView`, and the
    line model = measured; log axes by default (points not positive are left out of a log
    axis and counted in the title). Returns ``(fig, ax)``."""
    fig, ax = new_axes(ax, figsize=(5.0, 4.6))
    x, err = view.measured, view.sigma
    styles = series_styles(view.models)
    shown = np.ones(x.size, bool)
    for name, y in view.models.items():
        ok = (x > 0) & (y > 0) if log else np.isfinite(y)
        shown &= ok
        cont = ax.errorbar(x[ok], y[ok], xerr=None if err is None else err[ok], ls="",
                           marker="o", ms=3.5, mfc="none", color=styles[name]["color"],
                           elinewidth=0.6, capsize=0, label=name)
        cont.lines[0].set_gid(f"points {name}")
    values = np.concatenate([x, *view.models.values()])
    values = values[np.isfinite(values) & ((values > 0) if log else True)]
    lo, hi = (float(values.min()), float(values.max())) if values.size else (1e-3, 1.0)
    if log:
        ax.set_xscale("log")
        ax.set_yscale("log")
        lo, hi = lo / 1.5, hi * 1.5
    ax.plot([lo, hi], [lo, hi], color="0.5", lw=0.8, ls="--", label="model = measured")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    what = "luminance" if view.quantity == "luminance" else f"{view.quantity.upper()} channel"
    ax.set_xlabel(f"measured f_r, {what} (1/sr)", fontsize=FONT["label"])
    ax.set_ylabel("model f_r at the same pair (1/sr)", fontsize=FONT["label"])
    hidden = int(x.size - shown.sum())
    ax.set_title(title or (f"{x.size} points" + (f" ({hidden} not positive: not on the log "
                                                  f"axes)" if hidden else "")),
                 fontsize=FONT["title"])
    if legend:
        legend_outside(ax, "right")
    return finish(fig, ax, filename)


def draw_scatter_residuals(view: TableScatterView, name: str, *, ax=None, filename=None,
                           title=None):
    """Model ``name``'s residuals at every point of a :class:`analysis.views.TableScatterView`
    on the half-vector disk (h_x, h_y), a diverging colour scale symmetric about 0 (to the
    98th percentile of |residual|, at least 3 for normalized residuals). Returns
    ``(fig, ax)``."""
    fig, ax = new_axes(ax, figsize=(5.0, 4.4))
    r, what = view.residuals(name)
    ok = np.isfinite(r)
    normalized = what.startswith("normalized")
    lim = float(np.percentile(np.abs(r[ok]), 98)) if ok.any() else 1.0
    lim = max(lim, 3.0) if normalized else max(lim, 1e-3)
    sc = ax.scatter(view.half[ok, 0], view.half[ok, 1], c=r[ok], cmap="RdBu_r", vmin=-lim,
                    vmax=lim, s=14, edgecolors="0.3", linewidths=0.3)
    fig.colorbar(sc, ax=ax, label=what)
    t = np.linspace(0.0, 2.0 * np.pi, 181)
    ax.plot(np.cos(t), np.sin(t), color="k", lw=0.5)
    ax.set_aspect("equal")
    ax.set_xlim(-1.05, 1.05)
    ax.set_ylim(-1.05, 1.05)
    ax.set_xlabel("h_x (warp; unit half vector)", fontsize=FONT["label"])
    ax.set_ylabel("h_y (weft)", fontsize=FONT["label"])
    rms = float(np.sqrt(np.mean(r[ok] ** 2))) if ok.any() else float("nan")
    ax.set_title(title or f"{name}: rms {rms:.2g} over {int(ok.sum())} points",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)
