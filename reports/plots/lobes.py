"""Lobe plots: polar lobes in a plane of incidence and a comparison of fabrics (the 3-D lobe
is in :mod:`reports.plots.lobe3d`).

A *plane of incidence* is the vertical plane at azimuth ``phi`` (0 = along the warp, 90 = along
the weft, 45 = the diagonal). The light sits on the negative side, wi at signed angle
-theta_i (azimuth phi + 180 degrees); the viewer sweeps the signed angle theta_o from -90 to
90 degrees, positive toward azimuth phi, so the mirror direction is at +theta_i.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, MaxNLocator

from analysis.views import LobeView, compute_lobes, finite_max, plane_directions
from reports.plots.common import (FONT, check_angle, check_quantity, finish, legend_outside,
                               new_axes, pow10_label, quantity_styles, series_styles,
                               series_style)
from reports.plots.halfdisc import HalfDiscAxes, snug_height

__all__ = ["plane_directions", "plot_polar_lobe", "plot_lobe_planes", "plot_lobe_comparison",
           "draw_polar_lobe", "draw_lobe_planes", "draw_lobe_comparison", "log_radius",
           "log_floor", "setup_polar", "plane_name", "lobe_peak"]


def log_radius(values, floor):
    """Radius of the log polar plot: log10(max(f, floor) / floor), 0 at the floor.

    Examples
    --------
    >>> log_radius(np.array([1.0, 10.0, 1e-9]), 0.1).tolist()
    [1.0, 2.0, 0.0]
    """
    return np.log10(np.maximum(np.asarray(values, dtype=np.float64), floor) / floor)


def log_floor(peak, decades):
    """The power of 10 at least ``decades`` below ``peak`` (1e-12 for a zero peak)."""
    if not peak > 0:
        return 1e-12
    return 10.0 ** np.floor(np.log10(peak) - decades)


def _radius(value, scale, floor) -> float:
    """The radius of ``value`` (1/sr) on ``scale``."""
    return float(log_radius(value, floor)) if scale == "log" else float(value)


def lobe_peak(brdfs, theta_i_deg, planes_deg, *, quantity="luminance", resolution=181,
              cosine=False) -> float:
    """The largest f_r (1/sr) that lobe panels of these BRDFs, incidences and planes draw:
    the ``peak`` that gives all panels of a figure one set of log decades.

    Parameters
    ----------
    brdfs : BRDF or mapping of str to BRDF
        Objects with ``.eval``.
    theta_i_deg, planes_deg : float or sequence of float
        Incidence angles and plane azimuths in degrees.
    quantity, resolution, cosine
        As in :func:`plot_polar_lobe`.

    Returns
    -------
    float
        f_r in 1/sr (times cos theta_o when ``cosine``); 0 when nothing is positive.
    """
    check_quantity(quantity)
    many = brdfs.values() if isinstance(brdfs, dict) else [brdfs]
    return max(compute_lobes(b, theta_i_deg, planes_deg, resolution=resolution,
                             cosine=cosine).peak(quantity) for b in many)


def setup_polar(ax, scale, floor, rmax, label="f_r (1/sr)"):
    """Half-disc polar axes (theta_o from -90 to 90 degrees, the normal up) with radial ticks
    in 8 pt: decades 10^k on a log scale (every other one when more than five), and the
    radial axis labelled ``label`` under the disc."""
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_thetamin(-90)
    ax.set_thetamax(90)
    ax.set_xticks(np.radians([-90, -60, -30, 0, 30, 60, 90]))
    ax.set_xticklabels(["−90°", "−60°", "−30°", "0°", "30°", "60°", "90°"])
    ax.tick_params(axis="both", labelsize=FONT["small"])
    ax.set_rlim(0, max(rmax, 1e-12) * 1.05)
    if scale == "log":
        shown = np.arange(0, int(np.floor(rmax * 1.05)) + 1)
        base = int(round(np.log10(floor)))
        every = 1 if len(shown) <= 4 else 2
        ax.set_rticks(shown)
        ax.set_yticklabels([pow10_label(base + k) if (shown[-1] - k) % every == 0 else ""
                            for k in shown])
        label = f"{label}, log scale"
    else:
        ax.yaxis.set_major_locator(MaxNLocator(3))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.2g}"))
    # r tick labels on the right edge, reading outward; the axis label under the centre
    ax.yaxis.set_tick_params(label1On=False, label2On=True)
    ax.annotate(f"radius: {label}", xy=(0.0, 0.0), xytext=(0.0, -19.0), ha="center",
                va="top", textcoords="offset points", fontsize=FONT["small"],
                annotation_clip=False)


def _check_scale(scale):
    if scale not in ("linear", "log"):
        raise ValueError(f"scale must be 'linear' or 'log'; got {scale!r}")


def plot_polar_lobe(brdf, theta_i_deg=(0.0, 30.0, 60.0), phi_deg=0.0, *, quantity="luminance",
                    scale="linear", decades=4.0, resolution=181, cosine=False, colour=None,
                    normalize=False, legend=True, peak=None, ax=None, filename=None,
                    title=None):
    """Polar plot of f_r in a plane of incidence, one curve per incidence angle.

    Parameters
    ----------
    brdf : object or str
        Anything with ``.eval(wi, wo) -> (..., 3)`` f_r in 1/sr, or a preset's name.
    theta_i_deg : float or sequence of float
        Incidence angles in degrees, each in [0, 90).
    phi_deg : float
        Azimuth of the plane in degrees: 0 along the warp, 90 along the weft.
    quantity : {"luminance", "rgb", "r", "g", "b"}
        "luminance" draws Rec. 709 luminance, one curve per theta_i; "rgb" draws the three
        channels in red, green and blue, one line style per theta_i.
    scale : {"linear", "log"}
        Radial scale. "log" plots log10(f / floor), clipped at 0, with floor the power of 10
        at least ``decades`` below the peak; tick labels are f_r values 10^k in 1/sr.
    decades : float
        Dynamic range of the log scale.
    resolution : int
        Number of theta_o samples over [-90, 90] degrees (at least 3).
    cosine : bool
        Plot f_r cos(theta_o) (the visible lobe) instead of f_r.
    colour : matplotlib colour, optional
        Colour of all luminance curves (line styles then tell the incidences apart); by
        default each incidence gets its own colour and line style (:func:`series_style`).
    normalize : bool
        Linear scale only: divide each curve by its own peak (unitless, 1 at the peak; the
        legend gives each peak in 1/sr), so lobes of very different heights all show.
    legend : bool
        Draw the legend under the plot (8 pt); :func:`plot_lobe_planes` draws one for all.
    peak : float, optional
        The f_r (1/sr) that sets the log floor and the radial limit, instead of this plot's
        own largest value: panels of one figure given the figure's peak
        (:func:`lobe_peak`) share their decades, limits and ticks.
    ax : matplotlib PolarAxes, optional
    filename : str or path, optional
        Save the figure there (atomically) when given.
    title : str, optional

    Returns
    -------
    (fig, ax)
        Each curve is a Line2D with x = signed theta_o in radians and y = the plotted value
        (f_r in 1/sr, its log radius, or f_r / its peak), and gid
        "lobe theta_i=<deg> <channel>".
    """
    _check_draw(scale, decades, normalize, quantity)
    check_angle("phi_deg", phi_deg, -360.0, 360.0)
    if ax is not None:                          # a wrong projection refused before work
        new_axes(ax, projection="halfdisc")
    view = compute_lobes(brdf, theta_i_deg, (phi_deg,), resolution=resolution, cosine=cosine)
    return draw_polar_lobe(view, phi_deg, quantity=quantity, scale=scale, decades=decades,
                           colour=colour, normalize=normalize, legend=legend, peak=peak,
                           ax=ax, filename=filename, title=title)


def _check_draw(scale, decades, normalize, quantity):
    _check_scale(scale)
    check_quantity(quantity)
    if not decades > 0:
        raise ValueError(f"decades must be positive; got {decades}")
    if normalize and scale == "log":
        raise ValueError("normalize applies to the linear scale only; got scale='log'")


def draw_polar_lobe(view: LobeView, phi_deg=None, *, quantity="luminance", scale="linear",
                    decades=4.0, colour=None, normalize=False, legend=True, peak=None, ax=None,
                    filename=None, title=None):
    """Draw the curves of one plane of a :class:`analysis.views.LobeView`, one per incidence
    (:func:`plot_polar_lobe` computes the view and calls this).

    Parameters
    ----------
    view : analysis.views.LobeView
    phi_deg : float, optional
        The plane drawn, one of ``view.planes_deg`` (default its first).
    quantity, scale, decades, colour, normalize, legend, peak, ax, filename, title
        As in :func:`plot_polar_lobe`.

    Returns
    -------
    (fig, ax)
        As :func:`plot_polar_lobe`.
    """
    _check_draw(scale, decades, normalize, quantity)
    phi_deg = view.planes_deg[0] if phi_deg is None else phi_deg
    fig, ax = new_axes(ax, projection="halfdisc", figsize=(5.0, 3.6))
    thetas, theta_o = view.theta_i_deg, view.theta_o_deg
    curves = view.curves(phi_deg, quantity)
    own = max(finite_max(c) for c in curves)
    floor = log_floor(own if peak is None else peak, decades)
    rmax = _draw_lobes(ax, thetas, theta_o, curves, quantity_styles(quantity, colour), colour,
                       floor if scale == "log" else None, normalize)
    if peak is not None and not normalize:
        rmax = max(rmax, _radius(peak, scale, floor))
    label = view.label
    setup_polar(ax, scale, floor, rmax, f"{label} / its peak (per curve)" if normalize
                 else f"{label} ({view.unit})")
    for ti in thetas:  # incident directions as arrows from the centre
        ax.annotate("", xy=(np.radians(-ti), rmax * 1.0), xytext=(0, 0),
                    arrowprops=dict(arrowstyle="<-", color="0.5", lw=0.8))
    what = "luminance" if quantity == "luminance" else quantity.upper()
    ax.set_title(title or f"{label} ({what}) in the plane φ = {float(phi_deg):g}°",
                 fontsize=FONT["title"])
    if legend:
        legend_outside(ax, "below", ncol=min(3, len(ax.get_lines())))
    return finish(fig, ax, filename)


def _draw_lobes(ax, thetas, theta_o, curves, styles, colour, floor, normalize=False) -> float:
    """One line per incidence and style (log radius above ``floor`` unless it is None, or
    divided by its peak when ``normalize``); return the largest radius drawn."""
    rmax = 0.0
    for n, (ti, f) in enumerate(zip(thetas, curves)):
        st = series_style(n)
        for k, col, suffix in styles:
            y = f[:, k] if f.ndim == 2 else f
            label = f"θi = {ti:g}°{suffix}"
            if normalize:
                top = float(np.nanmax(y)) if np.any(y > 0) else 1.0
                y = y / top
                label += f" (peak {top:.3g} 1/sr)"
            r = log_radius(y, floor) if floor is not None else y
            rmax = max(rmax, float(np.nanmax(r)))
            ls = st["ls"] if (len(styles) > 1 or colour is not None or k is None) else "-"
            if k is None and colour is None:
                col = st["color"]
            line, = ax.plot(np.radians(theta_o), r, ls=ls, color=col, lw=1.5, label=label)
            line.set_gid(f"lobe theta_i={ti:g} {'luminance' if k is None else 'rgb'[k]}")
    return rmax


def plot_lobe_planes(brdf, theta_i_deg=(0.0, 30.0, 60.0), planes_deg=(0.0, 45.0, 90.0), *,
                     fig=None, filename=None, **kwargs):
    """Polar lobes in several planes of incidence side by side (warp, 45 degrees, weft).

    Parameters
    ----------
    brdf : object with ``.eval``
    theta_i_deg : sequence of float
        Incidence angles in degrees.
    planes_deg : sequence of float
        Azimuths of the planes in degrees.
    fig : matplotlib Figure, optional
        Figure to draw into (its content is replaced); a new one when None.
    filename : str or path, optional
    **kwargs
        Passed to :func:`plot_polar_lobe` (quantity, scale, decades, resolution, cosine);
        ``peak`` defaults to the largest value of all panels (:func:`lobe_peak`), so that
        they share their radial limit and, on a log scale, their decades.

    Returns
    -------
    (fig, axes)
        axes is a list of PolarAxes, one per plane.
    """
    view = compute_lobes(brdf, theta_i_deg, planes_deg,
                         resolution=kwargs.pop("resolution", 181),
                         cosine=kwargs.pop("cosine", False))
    return draw_lobe_planes(view, fig=fig, filename=filename, **kwargs)


def draw_lobe_planes(view: LobeView, *, fig=None, filename=None, **kwargs):
    """Draw every plane of a :class:`analysis.views.LobeView` side by side, a panel each
    (:func:`plot_lobe_planes` computes the view and calls this).

    Parameters
    ----------
    view : analysis.views.LobeView
    fig, filename
        As in :func:`plot_lobe_planes`.
    **kwargs
        Passed to :func:`draw_polar_lobe` (quantity, scale, decades, normalize, colour);
        ``peak`` defaults to the view's (:meth:`analysis.views.LobeView.peak`), so that the
        panels share their radial limit and, on a log scale, their decades.

    Returns
    -------
    (fig, axes)
        axes is a list of PolarAxes, one per plane.
    """
    planes = view.planes_deg
    own = fig is None
    if own:
        # 3.9 in a panel: three fit a page column (12.2 in of 8 pt text at 12 px or more)
        fig = Figure(figsize=(3.9 * len(planes), 2.9), layout="constrained")
    else:
        fig.clear()
    axes = [fig.add_subplot(1, len(planes), n + 1, axes_class=HalfDiscAxes)
            for n in range(len(planes))]
    if not kwargs.get("normalize") and "peak" not in kwargs:      # one set of decades
        kwargs["peak"] = view.peak(check_quantity(kwargs.get("quantity", "luminance")))
    for ax, phi in zip(axes, planes):
        draw_polar_lobe(view, phi, ax=ax, legend=False,
                        title=f"plane φ = {float(phi):g}° ({plane_name(phi)})", **kwargs)
    if not kwargs.get("normalize"):
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncol=min(len(labels), 6),
                   fontsize=FONT["small"], frameon=False)
    else:  # each panel's own peaks
        for ax in axes:
            legend_outside(ax, "below", ncol=1)
    if own:
        snug_height(fig)
    return finish(fig, axes, filename)


def plane_name(phi_deg) -> str:
    """"warp", "weft" or "diagonal" for a plane's azimuth in degrees."""
    return {0.0: "warp", 90.0: "weft"}.get(float(phi_deg) % 180, "diagonal")


def plot_lobe_comparison(brdfs, theta_i_deg=30.0, phi_deg=0.0, *, scale="log", decades=4.0,
                         resolution=181, quantity="luminance", legend=True, peak=None,
                         ax=None, filename=None, title=None):
    """Luminance lobes of several BRDFs in one polar plot, each in its own colour and line
    style (:func:`reports.plots.common.series_styles`: a preset's style is the same in every
    figure).

    Parameters
    ----------
    brdfs : mapping of str to BRDF
        Name -> object with ``.eval``; the curve's label is the name.
    theta_i_deg, phi_deg : float
        Incidence angle and plane azimuth in degrees.
    scale, decades, resolution
        As in :func:`plot_polar_lobe`; the log floor is common to all curves.
    quantity : {"luminance", "r", "g", "b"}
        What of f_r is drawn.
    legend : bool
        Draw the legend under the plot (8 pt).
    peak : float, optional
        As in :func:`plot_polar_lobe`: the figure's peak f_r (1/sr), for shared decades.

    Returns
    -------
    (fig, ax)
        One Line2D per BRDF with gid "lobe <name>".
    """
    _check_scale(scale)
    if check_quantity(quantity) == "rgb":
        raise ValueError("quantity must be 'luminance', 'r', 'g' or 'b'; got 'rgb'")
    if ax is not None:                          # a wrong projection refused before work
        new_axes(ax, projection="halfdisc")
    views = {name: compute_lobes(b, theta_i_deg, phi_deg, resolution=resolution)
             for name, b in dict(brdfs).items()}
    return draw_lobe_comparison(views, theta_i_deg, phi_deg, scale=scale, decades=decades,
                                quantity=quantity, legend=legend, peak=peak, ax=ax,
                                filename=filename, title=title)


def draw_lobe_comparison(views, theta_i_deg, phi_deg, *, scale="log", decades=4.0,
                         quantity="luminance", legend=True, peak=None, ax=None, filename=None,
                         title=None):
    """Draw the curve at ``theta_i_deg`` in the plane ``phi_deg`` (degrees) of each
    :class:`analysis.views.LobeView` of ``views`` (name -> view, the name the curve's
    label); the other arguments and the result as :func:`plot_lobe_comparison`."""
    _check_scale(scale)
    if check_quantity(quantity) == "rgb":
        raise ValueError("quantity must be 'luminance', 'r', 'g' or 'b'; got 'rgb'")
    fig, ax = new_axes(ax, projection="halfdisc", figsize=(5.6, 3.7))
    data = {name: v.curve(phi_deg, theta_i_deg, quantity) for name, v in views.items()}
    own = max((finite_max(v) for v in data.values()), default=0.0)
    floor = log_floor(own if peak is None else peak, decades)
    rmax = 0.0 if peak is None else _radius(peak, scale, floor)
    styles = series_styles(data)
    for name, y in data.items():
        r = log_radius(y, floor) if scale == "log" else y
        rmax = max(rmax, float(np.nanmax(r)))
        st = styles[name]
        line, = ax.plot(np.radians(views[name].theta_o_deg), r, color=st["color"],
                        ls=st["ls"], lw=1.5, label=name)
        line.set_gid(f"lobe {name}")
    setup_polar(ax, scale, floor, rmax, f"{_what(quantity)} f_r (1/sr)")
    ax.set_title(title or f"θi = {float(theta_i_deg):g}°, plane φ = {float(phi_deg):g}° "
                 f"({plane_name(phi_deg)})", fontsize=FONT["title"])
    if legend:
        legend_outside(ax, "below", ncol=2)
    return finish(fig, ax, filename)


def _what(quantity) -> str:
    return "luminance" if quantity == "luminance" else f"{quantity.upper()} channel"
