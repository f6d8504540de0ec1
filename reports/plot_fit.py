"""Model curves over measured table points in a plane of incidence, with error bars: one
model at several incidences, or several models (presets, fits) at one."""

from __future__ import annotations

import numpy as np

from reports._plotting import (FONT, check_quantity, eval_brdf, finish, legend_outside,
                               log_range, new_axes, quantity_styles, series_styles,
                               reduce_quantity)
from reports.colour import REC709_WEIGHTS
from reports.plot_lobes import plane_directions

__all__ = ["plane_points", "plane_lights", "plot_fit_overlay", "plot_table_models",
           "plane_incidences", "table_panels", "table_points"]


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
        Rows in the plane.
    theta_i_deg : numpy.ndarray
        Incidence angle (unsigned) of each row, degrees.
    theta_o_deg : numpy.ndarray
        Signed viewing angle of each row, degrees, positive away from the light (toward
        azimuth phi when the light is at phi + 180, toward phi + 180 when it is at phi):
        the light always on the negative side. Which side the light was really on is
        :func:`plane_lights`'s; a model drawn over these points must be evaluated with
        the light there (a fabric need not be symmetric under the half turn).
    """
    idx, ti, so, _ = _plane_rows(table, phi_deg, tol_deg)
    return idx, ti, so


def plane_lights(table, phi_deg=0.0, tol_deg=2.0) -> np.ndarray:
    """The light's azimuth (degrees: ``phi_deg`` or ``phi_deg + 180``, the latter for a
    light within the tolerance of the pole) of each row :func:`plane_points` returns, in
    its order."""
    _, _, _, flip = _plane_rows(table, phi_deg, tol_deg)
    return np.where(flip, float(phi_deg), float(phi_deg) + 180.0)


def _plane_rows(table, phi_deg, tol_deg):
    """index, theta_i (deg), signed theta_o (deg, + away from the light) and whether the
    light is at phi (True) rather than phi + 180, of the rows in the plane."""
    ang = np.asarray(table.angles)
    tol = np.radians(tol_deg)
    phi = np.radians(phi_deg)
    si = _signed(ang[:, 0], ang[:, 1], phi, tol)
    so = _signed(ang[:, 2], ang[:, 3], phi, tol)
    # Light on the positive side: the signed angles measured from the other end of the
    # plane, so that the light is on the negative side (the model is evaluated there).
    flip = si > tol
    si = np.where(flip, -si, si)
    so = np.where(flip, -so, so)
    keep = np.isfinite(si) & np.isfinite(so)
    idx = np.nonzero(keep)[0]
    return idx, np.degrees(np.abs(si[idx])), np.degrees(so[idx]), flip[idx]


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
    ti, to, values, sigma, light, _ = _plane_data(table, phi_deg, tol_deg)
    distinct = np.unique(np.round(ti * 2.0) / 2.0)
    wanted = distinct[:max_incidences] if theta_i_deg is None else np.atleast_1d(theta_i_deg)
    fig, ax = new_axes(ax, figsize=(6.0, 4.0))
    x_model = np.linspace(-90.0, 90.0, int(resolution))
    groups = [(t, lt) for t in wanted for lt in np.unique(light[np.abs(ti - t) <= 0.5])]
    both = len({lt for _, lt in groups}) > 1
    for n, (t, lt) in enumerate(groups):
        sel = (np.abs(ti - t) <= 0.5) & (light == lt)
        # the light where it was: the curve runs through the plane away from it
        wi, wo = plane_directions(float(np.mean(ti[sel])), x_model, lt + 180.0)
        model = reduce_quantity(eval_brdf(brdf, wi, wo), quantity)
        err = None if sigma is None else _reduce_sigma(sigma[sel], quantity)
        _draw_incidence(ax, n, t, quantity, x_model, model, to[sel],
                        reduce_quantity(values[sel], quantity), err,
                        f", φi = {lt % 360:g}°" if both else "")
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


def plane_incidences(table, phi_deg=0.0, tol_deg=2.0) -> np.ndarray:
    """The distinct incidence angles (degrees, to 0.5 degree) of a table's valid points in
    the plane ``phi_deg``; raises ``ValueError`` when the plane holds none."""
    ti = _plane_data(table, phi_deg, tol_deg)[0]
    return np.unique(np.round(ti * 2.0) / 2.0)


def table_panels(table, theta_i_deg=None, phi_deg=0.0, tol_deg=2.0) -> list:
    """The panels of a table against models in the plane ``phi_deg``: a ``(theta_i, light)``
    pair (degrees; ``light`` the light's azimuth, ``phi_deg`` or ``phi_deg + 180``) for each
    incidence of ``theta_i_deg`` (default the first three in the plane) and each side the
    light was measured from; a ValueError names an incidence the plane does not hold."""
    ti, _, _, _, light, _ = _plane_data(table, phi_deg, tol_deg)
    have = np.unique(np.round(ti * 2.0) / 2.0)
    wanted = have[:3] if theta_i_deg is None else np.atleast_1d(theta_i_deg)
    out = []
    for t in wanted:
        sel = np.abs(ti - float(t)) <= 0.5
        if not sel.any():
            raise ValueError(f"theta_i must be one of the table's incidences in the plane "
                             f"phi = {phi_deg:g} degrees ({', '.join(f'{h:g}' for h in have)})"
                             f"; got {float(t):g}")
        out += [(float(t), float(lt)) for lt in np.unique(light[sel])[::-1]]
    return out


def table_points(table, models, theta_i_deg, phi_deg=0.0, light_deg=None, *,
                 quantity="luminance", tol_deg=2.0):
    """The measured points of one panel and every model at each point's own directions.

    Parameters
    ----------
    table : gonio.Table
    models : mapping of str to BRDF
        Label -> object with ``.eval``.
    theta_i_deg, phi_deg : float
        Incidence (matched within 0.5 degree) and plane azimuth, degrees.
    light_deg : float, optional
        The light's azimuth (``phi_deg`` or ``phi_deg + 180``, degrees); default the side
        that holds points (``phi_deg + 180`` when both do).
    quantity : {"luminance", "r", "g", "b"}

    Returns
    -------
    dict
        ``rows`` (table rows, by signed theta_o), ``x`` (signed theta_o, degrees, + away from
        the light), ``theta_i`` (mean incidence, degrees), ``light`` (degrees), ``measured``
        (f_r, 1/sr), ``sigma`` (1/sr or None) and ``models`` (label -> f_r at the rows, 1/sr:
        the model evaluated at the measured wi and wo, nothing turned or mirrored).
    """
    check_quantity(quantity)
    if quantity == "rgb":
        raise ValueError("quantity must be 'luminance', 'r', 'g' or 'b' to compare models; "
                         "got 'rgb'")
    ti, to, values, sigma, light, idx = _plane_data(table, phi_deg, tol_deg)
    sel = np.abs(ti - float(theta_i_deg)) <= 0.5
    if not sel.any():
        have = ", ".join(f"{t:g}" for t in np.unique(np.round(ti * 2.0) / 2.0))
        raise ValueError(f"theta_i must be one of the table's incidences in the plane "
                         f"phi = {phi_deg:g} degrees ({have}); got {float(theta_i_deg):g}")
    if light_deg is None:
        light_deg = float(np.max(light[sel]))
    sel &= np.isclose(light, float(light_deg))
    if not sel.any():
        raise ValueError(f"no point of theta_i = {float(theta_i_deg):g} degrees has the light "
                         f"at phi = {float(light_deg):g} degrees")
    order = np.argsort(to[sel])
    rows = idx[sel][order]
    wi, wo = np.asarray(table.wi)[rows], np.asarray(table.wo)[rows]
    return {"rows": rows, "x": to[sel][order], "theta_i": float(np.mean(ti[sel])),
            "light": float(light_deg),
            "measured": reduce_quantity(values[sel][order], quantity),
            "sigma": None if sigma is None else _reduce_sigma(sigma[sel][order], quantity),
            "models": {name: reduce_quantity(eval_brdf(m, wi, wo), quantity)
                       for name, m in dict(models).items()}}


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
    pts = table_points(table, models, theta_i_deg, phi_deg, light_deg, quantity=quantity,
                       tol_deg=tol_deg)
    fig, ax = new_axes(ax, figsize=(6.0, 3.8))
    x, y, err = pts["x"], pts["measured"], pts["sigma"]
    x_model = np.linspace(-90.0, 90.0, int(resolution))
    # the light where it was measured: wi at azimuth light, the curve away from it
    wi, wo = plane_directions(pts["theta_i"], x_model, pts["light"] + 180.0)
    curves = {name: reduce_quantity(eval_brdf(m, wi, wo), quantity)
              for name, m in dict(models).items()}
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


def _plane_data(table, phi_deg, tol_deg):
    """The valid table points in the plane ``phi_deg``: (theta_i, signed theta_o (degrees),
    f_r, sigma or None, the light's azimuth (degrees), their rows in the table)."""
    idx, ti, to, flip = _plane_rows(table, phi_deg, tol_deg)
    values = np.asarray(table.values, dtype=np.float64)[idx]
    valid = np.asarray(table.valid)[idx].all(axis=1)
    idx, ti, to, values, flip = idx[valid], ti[valid], to[valid], values[valid], flip[valid]
    if idx.size == 0:
        raise ValueError(f"table has no valid points in the plane phi = {phi_deg:g} degrees "
                         f"(tolerance {tol_deg:g} degrees)")
    sigma = None if table.sigma is None else np.asarray(table.sigma, float)[idx]
    light = np.where(flip, float(phi_deg), float(phi_deg) + 180.0)
    return ti, to, values, sigma, light, idx


def _reduce_sigma(sigma, quantity):
    """sigma (n, 3) of f_r reduced to ``quantity``; luminance with independent channels."""
    if quantity == "luminance":
        return np.sqrt((sigma ** 2) @ (REC709_WEIGHTS ** 2))
    return reduce_quantity(sigma, quantity)


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
