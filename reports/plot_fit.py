"""Model curves over measured table points in a plane of incidence, with error bars: one
model at several incidences, or several models (presets, fits) at one."""

from __future__ import annotations

import numpy as np

from reports._plotting import (FONT, check_quantity, eval_brdf, finish, legend_outside,
                               log_range, new_axes, quantity_styles, series_styles,
                               reduce_quantity)
from reports.colour import REC709_WEIGHTS
from reports.plot_lobes import plane_directions

__all__ = ["plane_points", "plot_fit_overlay", "plot_table_models", "plane_incidences"]


def _signed(theta, phi, phi_plane, tol):
    """Signed angle (radians) of directions in the plane at phi_plane, NaN off the plane."""
    d = np.angle(np.exp(1j * (phi - phi_plane)))
    fwd = np.abs(d) <= tol
    back = np.abs(np.abs(d) - np.pi) <= tol
    near_pole = theta <= tol
    s = np.full(theta.shape, np.nan)
    s[fwd | near_pole] = theta[fwd | near_pole]
    s[back & ~near_pole] = -theta[back & ~near_pole]
    return s


def plane_points(table, phi_deg=0.0, tol_deg=2.0):
    """Rows of a table that lie in the plane of incidence at azimuth ``phi_deg``.

    Parameters
    ----------
    table : gonio.Table
    phi_deg : float
        Azimuth of the plane in degrees.
    tol_deg : float
        Azimuth tolerance in degrees (directions within tol of the pole always count).

    Returns
    -------
    index : numpy.ndarray of int
        Rows in the plane, with the light on the negative side (signed theta_i <= 0).
    theta_i_deg : numpy.ndarray
        Incidence angle (unsigned) of each row, degrees.
    theta_o_deg : numpy.ndarray
        Signed viewing angle of each row, degrees (positive toward azimuth phi).
    """
    ang = np.asarray(table.angles)
    tol = np.radians(tol_deg)
    phi = np.radians(phi_deg)
    si = _signed(ang[:, 0], ang[:, 1], phi, tol)
    so = _signed(ang[:, 2], ang[:, 3], phi, tol)
    # Light on the positive side: mirror the pair so the light is on the negative side.
    flip = si > tol
    si = np.where(flip, -si, si)
    so = np.where(flip, -so, so)
    keep = np.isfinite(si) & np.isfinite(so)
    idx = np.nonzero(keep)[0]
    return idx, np.degrees(np.abs(si[idx])), np.degrees(so[idx])


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
    check_quantity(quantity)
    ti, to, values, sigma = _plane_data(table, phi_deg, tol_deg)
    distinct = np.unique(np.round(ti * 2.0) / 2.0)
    wanted = distinct[:max_incidences] if theta_i_deg is None else np.atleast_1d(theta_i_deg)
    fig, ax = new_axes(ax, figsize=(6.0, 4.0))
    x_model = np.linspace(-90.0, 90.0, int(resolution))
    for n, t in enumerate(wanted):
        sel = np.abs(ti - t) <= 0.5
        if not sel.any():
            continue
        wi, wo = plane_directions(float(np.mean(ti[sel])), x_model, phi_deg)
        model = reduce_quantity(eval_brdf(brdf, wi, wo), quantity)
        err = None if sigma is None else _reduce_sigma(sigma[sel], quantity)
        _draw_incidence(ax, n, t, quantity, x_model, model, to[sel],
                        reduce_quantity(values[sel], quantity), err)
    if log:
        ax.set_yscale("log")
    _cartesian_labels(ax)
    legend_outside(ax, "right")
    ax.set_title(title or f"model and measurement, plane φ = {phi_deg:g}°",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)


def _cartesian_labels(ax):
    ax.set_xlabel("signed θo (degrees; light on the negative side)", fontsize=FONT["label"])
    ax.set_ylabel("f_r (1/sr)", fontsize=FONT["label"])
    ax.set_xlim(-90, 90)
    ax.set_xticks(np.arange(-90, 91, 30))
    ax.tick_params(labelsize=FONT["small"])
    ax.grid(alpha=0.3)


def plane_incidences(table, phi_deg=0.0, tol_deg=2.0) -> np.ndarray:
    """The distinct incidence angles (degrees, to 0.5 degree) of a table's valid points in
    the plane ``phi_deg``; raises ``ValueError`` when the plane holds none."""
    ti = _plane_data(table, phi_deg, tol_deg)[0]
    return np.unique(np.round(ti * 2.0) / 2.0)


def plot_table_models(table, models, theta_i_deg, phi_deg=0.0, *, quantity="luminance",
                      tol_deg=2.0, resolution=181, log=True, decades=6.0, legend=True,
                      ax=None, filename=None, title=None):
    """A measured table at one incidence in a plane (black circles with error bars) against
    models, each curve in its own colour and line style (:func:`series_styles`).

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
    quantity : {"luminance", "r", "g", "b"}
        What of f_r is drawn.
    log, decades : bool, float
        Log axis over the decades that hold the data (:func:`log_range`); measured zeros
        sit on the lower edge as open triangles labelled "f_r = 0".

    Returns
    -------
    (fig, ax)
        The measured points' Line2D has gid "data", each model's "model <label>" (x signed
        theta_o in degrees, y f_r in 1/sr).
    """
    check_quantity(quantity)
    if quantity == "rgb":
        raise ValueError("quantity must be 'luminance', 'r', 'g' or 'b' to compare models; "
                         "got 'rgb'")
    ti, to, values, sigma = _plane_data(table, phi_deg, tol_deg)
    sel = np.abs(ti - float(theta_i_deg)) <= 0.5
    if not sel.any():
        have = ", ".join(f"{t:g}" for t in np.unique(np.round(ti * 2.0) / 2.0))
        raise ValueError(f"theta_i must be one of the table's incidences in the plane "
                         f"phi = {phi_deg:g} degrees ({have}); got {float(theta_i_deg):g}")
    fig, ax = new_axes(ax, figsize=(6.0, 3.8))
    order = np.argsort(to[sel])
    x, y = to[sel][order], reduce_quantity(values[sel], quantity)[order]
    err = None if sigma is None else _reduce_sigma(sigma[sel], quantity)[order]
    x_model = np.linspace(-90.0, 90.0, int(resolution))
    wi, wo = plane_directions(float(np.mean(ti[sel])), x_model, phi_deg)
    curves = {name: reduce_quantity(eval_brdf(m, wi, wo), quantity)
              for name, m in dict(models).items()}
    styles = series_styles(curves)
    for name, c in curves.items():
        st = styles[name]
        line, = ax.plot(x_model, c, color=st["color"], ls=st["ls"], lw=1.5, label=name)
        line.set_gid(f"model {name}")
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
    ax.set_title(title or f"θi = {float(theta_i_deg):g}°, plane φ = {phi_deg:g}°, {what}",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)


def _plane_data(table, phi_deg, tol_deg):
    """theta_i, signed theta_o (degrees), f_r and sigma (or None) of the valid table points
    in the plane ``phi_deg``."""
    idx, ti, to = plane_points(table, phi_deg, tol_deg)
    values = np.asarray(table.values, dtype=np.float64)[idx]
    valid = np.asarray(table.valid)[idx].all(axis=1)
    idx, ti, to, values = idx[valid], ti[valid], to[valid], values[valid]
    if idx.size == 0:
        raise ValueError(f"table has no valid points in the plane phi = {phi_deg:g} degrees "
                         f"(tolerance {tol_deg:g} degrees)")
    sigma = None if table.sigma is None else np.asarray(table.sigma, float)[idx]
    return ti, to, values, sigma


def _reduce_sigma(sigma, quantity):
    """sigma (n, 3) of f_r reduced to ``quantity``; luminance with independent channels."""
    if quantity == "luminance":
        return np.sqrt((sigma ** 2) @ (REC709_WEIGHTS ** 2))
    return reduce_quantity(sigma, quantity)


def _draw_incidence(ax, n, t, quantity, x_model, model, to, meas, err):
    """Model lines and measured points (``to`` signed theta_o, degrees) of incidence ``t``,
    the ``n``-th drawn, one per style of ``quantity``."""
    markers = "osD^v<>"
    order = np.argsort(to)
    for k, col, suffix in quantity_styles(quantity):
        channel = "luminance" if k is None else "rgb"[k]
        y = model[:, k] if model.ndim == 2 else model
        line, = ax.plot(x_model, y, color=col, lw=1.0, ls=["-", "--", ":", "-."][n % 4],
                        label=f"model θi = {t:g}°{suffix}")
        line.set_gid(f"model theta_i={t:g} {channel}")
        ym = (meas[:, k] if meas.ndim == 2 else meas)[order]
        em = None if err is None else (err[:, k] if err.ndim == 2 else err)[order]
        cont = ax.errorbar(to[order], ym, yerr=em, color=col, ls="",
                           marker=markers[n % len(markers)], ms=3.5, mfc="none",
                           capsize=1.5, label=f"data θi = {t:g}°{suffix}")
        cont.lines[0].set_gid(f"data theta_i={t:g} {channel}")
