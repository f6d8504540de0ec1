"""The BRDF Explorer's cartesian slices and its theta_h x theta_d image slice.

Half/difference angles follow Rusinkiewicz (1998): theta_h, phi_h locate the half vector h,
theta_d, phi_d the incident direction in the frame whose pole is h
(:func:`reports.plots.common.half_diff_to_io`). For an anisotropic BRDF such as cloth, phi_h
matters too: every slice takes it (default 0, the half vector in the warp's plane).
Pairs with either direction below the horizon evaluate to 0 (the BRDF's own convention). The
cartesian slices stop at ``theta_max_deg`` (default 89.5 degrees) short of the horizon, where
wi and wo can both graze and the model's value is a limit it reaches only in round-off.
"""

from __future__ import annotations

import matplotlib
import matplotlib.colors as mcolors
import numpy as np

from analysis.views import (SliceImageView, SliceView, compute_slice_image,
                            compute_slice_theta_d, compute_slice_theta_h, compute_slice_theta_o)
from reports.plots.common import (FONT, check_quantity, finish, legend_outside, log_range,
                               new_axes, quantity_styles, shade_zero)
from reports.colour import line_colour

__all__ = ["plot_slice_theta_o", "plot_slice_theta_h", "plot_slice_theta_d",
           "plot_slice_image", "slice_image", "draw_slice", "draw_slice_image"]


def _draw(ax, x_deg, values, quantity, colour, log, gid, decades=6.0, label=None,
          style=None):
    """The curves of ``quantity``; on a log axis the y range covers the decades that hold the
    data (:func:`log_range`): a channel peaking many decades below the others stays drawn
    but under the axis, its legend entry giving its peak, and zeros are grey bands. ``label``
    and ``style`` (colour, ls) name and style a one-curve quantity (overlays of fabrics),
    whose y range then grows with every curve drawn on ``ax``."""
    styles = quantity_styles(quantity, colour)
    ys = [values[..., k] if values.ndim == 2 else values for k, _, _ in styles]
    peaks = [float(np.nanmax(y)) if np.any(np.isfinite(y)) else 0.0 for y in ys]
    lims, below = log_range(ys, decades)
    overlay = label is not None and len(styles) == 1
    for (k, col, suffix), y, peak, low in zip(styles, ys, peaks, below):
        name = label if overlay else ("luminance" if k is None else "RGB"[k])
        st = {"color": col, "ls": "-"}
        if overlay and style:
            st.update(style)
        if log and low and not overlay:
            name += f" (peak {peak:.2g} 1/sr, below the axis)"
        elif log and not overlay and np.any((y > 0) & (y < lims[0])):
            name += f" (off the axis below {lims[0]:.0e})"
        line, = ax.plot(x_deg, y, color=st["color"], ls=st["ls"], lw=1.5, label=name)
        line.set_gid(f"{gid} {'luminance' if k is None else 'rgb'[k]}")
    if log:
        if overlay:  # the range of every curve on the axes
            lims = log_range([l.get_ydata() for l in ax.get_lines() if l.get_gid()],
                             decades)[0]
        ax.set_yscale("log")
        ax.set_ylim(*lims)
        if not overlay:
            shade_zero(ax, x_deg, np.all([np.asarray(y) <= 0 for y in ys], axis=0))
    ax.set_ylabel("f_r (1/sr)", fontsize=FONT["label"])
    ax.tick_params(labelsize=FONT["small"])
    ax.grid(alpha=0.3)
    legend_outside(ax, "right")


def plot_slice_theta_o(brdf, theta_i_deg=30.0, phi_i_deg=180.0, phi_o_deg=0.0, *,
                       quantity="rgb", log=False, resolution=181, theta_max_deg=89.5, ax=None,
                       filename=None, title=None, label=None, style=None):
    """f_r against theta_o at fixed wi and viewing azimuth phi_o.

    Parameters
    ----------
    brdf : object with ``.eval``
    theta_i_deg, phi_i_deg : float
        The light's direction in degrees (default: 30 degrees, on the -x side).
    phi_o_deg : float
        Azimuth of the viewer in degrees.
    quantity : {"rgb", "luminance", "r", "g", "b"}
        "rgb" draws three curves in red, green and blue; "luminance" one curve in the fabric's
        sRGB colour.
    log : bool
        Logarithmic y axis.
    resolution : int
        Samples of theta_o over [0, theta_max_deg] degrees.
    theta_max_deg : float
        End of the swept angle in degrees (all three cartesian slices take it).
    label, style : str, dict, optional
        For a one-curve ``quantity`` (luminance or one channel): the legend label and the
        colour and line style (``{"color": ..., "ls": ...}``) of the curve, to overlay several
        fabrics on one axes (all three cartesian slices take them).

    Returns
    -------
    (fig, ax)
        Lines have x = theta_o in degrees and y = f_r in 1/sr; gid "theta_o <channel>".
    """
    check_quantity(quantity)
    view = compute_slice_theta_o(brdf, theta_i_deg, phi_i_deg, phi_o_deg,
                                resolution=resolution, theta_max_deg=theta_max_deg)
    return draw_slice(view, quantity=quantity, colour=line_colour(brdf), log=log, ax=ax,
                      filename=filename, title=title, label=label, style=style)


def plot_slice_theta_h(brdf, theta_d_deg=10.0, phi_d_deg=90.0, phi_h_deg=0.0, *,
                       quantity="rgb", log=True, resolution=181, theta_max_deg=89.5, ax=None,
                       filename=None, title=None, label=None, style=None):
    """f_r against theta_h in [0, theta_max_deg] at fixed theta_d, phi_d and phi_h (degrees).

    Returns
    -------
    (fig, ax)
        Lines have x = theta_h in degrees and y = f_r in 1/sr; gid "theta_h <channel>".
    """
    check_quantity(quantity)
    view = compute_slice_theta_h(brdf, theta_d_deg, phi_d_deg, phi_h_deg,
                                resolution=resolution, theta_max_deg=theta_max_deg)
    return draw_slice(view, quantity=quantity, colour=line_colour(brdf), log=log, ax=ax,
                      filename=filename, title=title, label=label, style=style)


def plot_slice_theta_d(brdf, theta_h_deg=0.0, phi_d_deg=90.0, phi_h_deg=0.0, *,
                       quantity="rgb", log=True, resolution=181, theta_max_deg=89.5, ax=None,
                       filename=None, title=None, label=None, style=None):
    """f_r against theta_d in [0, theta_max_deg] at fixed theta_h, phi_d and phi_h (degrees).

    Returns
    -------
    (fig, ax)
        Lines have x = theta_d in degrees and y = f_r in 1/sr; gid "theta_d <channel>".
    """
    check_quantity(quantity)
    view = compute_slice_theta_d(brdf, theta_h_deg, phi_d_deg, phi_h_deg,
                                resolution=resolution, theta_max_deg=theta_max_deg)
    return draw_slice(view, quantity=quantity, colour=line_colour(brdf), log=log, ax=ax,
                      filename=filename, title=title, label=label, style=style)


def draw_slice(view: SliceView, *, quantity="rgb", colour=None, log=True, ax=None,
               filename=None, title=None, label=None, style=None):
    """Draw a :class:`analysis.views.SliceView` (the ``plot_slice_*`` functions compute
    one and call this); ``colour`` is the luminance curve's (default black), the other
    arguments and the result as :func:`plot_slice_theta_o`'s."""
    check_quantity(quantity)
    fig, ax = new_axes(ax)
    _draw(ax, view.x_deg, view.values(quantity), quantity, colour, log, view.axis,
          label=label, style=style)
    ax.set_xlabel(f"{_SYMBOL[view.axis]} (degrees)", fontsize=FONT["label"])
    ax.set_title(title or view.caption, fontsize=FONT["title"])
    return finish(fig, ax, filename)


_SYMBOL = {"theta_o": "θo", "theta_h": "θh", "theta_d": "θd"}


def slice_image(brdf, phi_d_deg=90.0, phi_h_deg=0.0, resolution=90):
    """Luminance of f_r on the theta_h x theta_d grid at fixed phi_d, phi_h.

    Parameters
    ----------
    brdf : object with ``.eval``
    phi_d_deg, phi_h_deg : float
        Difference and half azimuths in degrees.
    resolution : int
        Cells per axis; cell centres at (k + 1/2) 90 / resolution degrees.

    Returns
    -------
    theta_deg : numpy.ndarray, shape (resolution,)
        Cell centres in degrees (the same for both axes).
    image : numpy.ndarray, shape (resolution, resolution)
        Luminance f_r in 1/sr, rows = theta_d, columns = theta_h.
    """
    view = compute_slice_image(brdf, phi_d_deg, phi_h_deg, resolution)
    return view.theta_deg, view.image


def plot_slice_image(brdf, phi_d_deg=90.0, phi_h_deg=0.0, *, log=True, decades=4.0,
                     resolution=90, ax=None, filename=None, title=None):
    """The Explorer's image slice: luminance f_r over theta_h (x) and theta_d (y).

    Parameters
    ----------
    brdf : object with ``.eval``
    phi_d_deg, phi_h_deg : float
        Fixed azimuths in degrees.
    log : bool
        Logarithmic colour scale over ``decades`` below the peak; values below it black,
        zeros grey (and the colour bar's label says so).
    resolution : int
        Cells per axis.

    Returns
    -------
    (fig, ax)
        ``ax.images[0].get_array()`` is the luminance image in 1/sr (rows theta_d from 0 at
        the bottom, columns theta_h), as :func:`slice_image` returns it.
    """
    return draw_slice_image(compute_slice_image(brdf, phi_d_deg, phi_h_deg, resolution),
                            log=log, decades=decades, ax=ax, filename=filename, title=title)


def draw_slice_image(view: SliceImageView, *, log=True, decades=4.0, ax=None, filename=None,
                     title=None):
    """Draw a :class:`analysis.views.SliceImageView` (:func:`plot_slice_image` computes one
    and calls this); the arguments and the result as :func:`plot_slice_image`'s."""
    img, phi_d_deg, phi_h_deg = view.image, view.phi_d_deg, view.phi_h_deg
    fig, ax = new_axes(ax, figsize=(5.0, 4.2))
    peak = float(np.nanmax(img)) if np.any(img > 0) else 1.0
    norm = (mcolors.LogNorm(vmin=peak * 10.0 ** (-decades), vmax=peak, clip=False) if log
            else mcolors.Normalize(vmin=0.0, vmax=peak))
    im = ax.imshow(np.ma.masked_where(~(img > 0), img), origin="lower", extent=(0, 90, 0, 90),
                   norm=norm, cmap=_CMAP(), interpolation="nearest", aspect="equal")
    zero = " (grey: f_r = 0)" if np.any(~(img > 0)) else ""
    # the bar in an inset just right of the image (axes coordinates: it follows the image
    # box, which aspect="equal" shrinks; a bar stealing space from the axes would sit where
    # the axes were, leaving a gap)
    cax = ax.inset_axes([1.04, 0.0, 0.05, 1.0])
    cb = fig.colorbar(im, cax=cax, extend="min" if log else "neither")
    cb.set_label(f"luminance f_r (1/sr){zero}", fontsize=FONT["label"])
    cb.ax.tick_params(labelsize=FONT["small"])
    ax.set_xlabel("θh (degrees)", fontsize=FONT["label"])
    ax.set_ylabel("θd (degrees)", fontsize=FONT["label"])
    ax.tick_params(labelsize=FONT["small"])
    ax.set_title(title or f"φd = {phi_d_deg:g}°, φh = {phi_h_deg:g}°", fontsize=FONT["title"])
    return finish(fig, ax, filename)


def _CMAP():
    # zeros (masked) grey, values below the log floor black
    return matplotlib.colormaps["magma"].with_extremes(bad="0.8", under="black")
