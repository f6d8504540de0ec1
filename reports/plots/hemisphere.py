"""Hemisphere heat map of f_r(wo) for a fixed wi, in Lambert's azimuthal equal-area projection.

A viewing direction at polar angle theta and azimuth phi sits at radius
rho = sqrt(2) sin(theta / 2) (1 at the horizon) and angle phi in the unit disc: equal solid
angles cover equal areas, so the picture shows where the reflected energy goes. +x (right) is
the warp, +y (up) the weft.
"""

from __future__ import annotations

import matplotlib
import matplotlib.colors as mcolors
import numpy as np

from analysis.views import HemisphereView, compute_hemisphere, equal_area_grid, equal_area_xy
from reports.plots.common import FONT, finish, legend_outside, new_axes
from reports.colour import luminance, to_srgb

__all__ = ["equal_area_grid", "equal_area_xy", "hemisphere_image", "plot_hemisphere",
           "draw_hemisphere"]


def hemisphere_image(brdf, theta_i_deg=45.0, phi_i_deg=0.0, resolution=101):
    """RGB f_r (1/sr) over the equal-area disc for the light at (theta_i, phi_i) degrees
    (:func:`analysis.views.compute_hemisphere`'s ``rgb``).

    Returns
    -------
    values : numpy.ndarray, shape (resolution, resolution, 3)
        f_r; NaN outside the disc.
    """
    return compute_hemisphere(brdf, theta_i_deg, phi_i_deg, resolution).rgb


def plot_hemisphere(brdf, theta_i_deg=45.0, phi_i_deg=0.0, *, quantity="luminance", log=True,
                    decades=4.0, cosine=False, exposure=0.0, resolution=101, ax=None,
                    filename=None, title=None):
    """Heat map of f_r(wo) over the viewing hemisphere (equal-area projection).

    Parameters
    ----------
    brdf : object with ``.eval``
    theta_i_deg, phi_i_deg : float
        Direction of the light in degrees.
    quantity : {"luminance", "srgb"}
        "luminance": Rec. 709 luminance in a colour map with a colour bar in 1/sr (zeros
        inside the disc grey, values below the log floor black);
        "srgb": the RGB value itself, times ``2**exposure`` and encoded as sRGB through
        colour-science (no colour bar; values above 1 clip).
    log : bool
        Logarithmic colour scale over ``decades`` below the peak (luminance only).
    cosine : bool
        Show f_r cos(theta_o) instead of f_r.
    resolution : int
        Pixels per side.

    Returns
    -------
    (fig, ax)
        ``ax.images[0].get_array()`` is the plotted image: luminance in 1/sr (masked outside
        the disc) or the sRGB image. The light's direction and its mirror are marked.
    """
    _check_hemisphere_quantity(quantity)
    view = compute_hemisphere(brdf, theta_i_deg, phi_i_deg, resolution)
    return draw_hemisphere(view, quantity=quantity, log=log, decades=decades, cosine=cosine,
                           exposure=exposure, ax=ax, filename=filename, title=title)


def _check_hemisphere_quantity(quantity):
    if quantity not in ("luminance", "srgb"):
        raise ValueError(f"quantity must be 'luminance' or 'srgb'; got {quantity!r}")


def draw_hemisphere(view: HemisphereView, *, quantity="luminance", log=True, decades=4.0,
                    cosine=False, exposure=0.0, ax=None, filename=None, title=None):
    """Draw a :class:`analysis.views.HemisphereView` (:func:`plot_hemisphere` computes one
    and calls this); the arguments and the result as :func:`plot_hemisphere`'s."""
    _check_hemisphere_quantity(quantity)
    theta_i_deg, phi_i_deg = view.theta_i_deg, view.phi_i_deg
    values = view.values(cosine)
    fig, ax = new_axes(ax, figsize=(5.0, 4.2))
    extent = (-1, 1, -1, 1)
    if quantity == "luminance":
        _luminance_image(fig, ax, luminance(values), log, decades, cosine)
    else:
        rgb = to_srgb(np.nan_to_num(values), exposure=exposure)
        alpha = np.isfinite(values[..., 0]).astype(float)[..., None]
        ax.imshow(np.concatenate([rgb, alpha], axis=-1), origin="lower", extent=extent,
                  interpolation="nearest")
    t = np.linspace(0, 2 * np.pi, 361)
    ax.plot(np.cos(t), np.sin(t), color="0.4", lw=0.8)
    for deg in (30, 60):
        r = np.sqrt(2.0) * np.sin(np.radians(deg) / 2.0)
        ax.plot(r * np.cos(t), r * np.sin(t), color="0.6", lw=0.5, ls=":")
    wi = view.wi
    xi, yi = equal_area_xy(wi)
    xm, ym = equal_area_xy(wi * np.array([-1.0, -1.0, 1.0]))
    ax.plot([xi], [yi], marker="*", color="#56B4E9", mec="k", mew=0.5, ms=10, ls="",
            label="light wi")
    ax.plot([xm], [ym], marker="P", color="#56B4E9", mec="k", mew=0.5, ms=8, ls="",
            label="mirror of wi")
    ax.set_xlim(-1.05, 1.05)
    ax.set_ylim(-1.05, 1.05)
    ax.set_aspect("equal")
    # two lines: on one, the label is wider than the disc and runs under the colour bar
    ax.set_xlabel("x: warp\n(equal-area disc, 1 = horizon)", fontsize=FONT["label"])
    ax.set_ylabel("y: weft", fontsize=FONT["label"])
    ax.tick_params(labelsize=FONT["small"])
    legend_outside(ax, "below", ncol=2)
    ax.set_title(title or f"f_r(wo), θi = {theta_i_deg:g}°, φi = {phi_i_deg:g}°",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)


def _luminance_image(fig, ax, lum, log, decades, cosine):
    """The luminance image (masked outside the disc) and its colour bar; zeros inside the
    disc grey and named on the colour bar, values below the log floor black."""
    img = np.ma.masked_invalid(lum)
    peak = float(img.max()) if img.count() and img.max() > 0 else 1.0
    norm = (mcolors.LogNorm(vmin=peak * 10.0 ** (-decades), vmax=peak, clip=False) if log
            else mcolors.Normalize(vmin=0.0, vmax=peak))
    cmap = matplotlib.colormaps["inferno"].with_extremes(bad=(1, 1, 1, 0), under="black")
    ax.imshow(img, origin="lower", extent=(-1, 1, -1, 1), norm=norm, cmap=cmap,
              interpolation="nearest")
    zero = np.isfinite(lum) & ~(lum > 0)
    if zero.any():
        ax.imshow(np.where(zero[..., None], [0.8, 0.8, 0.8, 1.0], 0.0), origin="lower",
                  extent=(-1, 1, -1, 1), interpolation="nearest")
    label = "luminance f_r cos θo (1/sr)" if cosine else "luminance f_r (1/sr)"
    cb = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax,
                      extend="min" if log else "neither")
    cb.set_label(label + ("\ngrey: f_r = 0" if zero.any() else ""), fontsize=FONT["label"])
    cb.ax.tick_params(labelsize=FONT["small"])
