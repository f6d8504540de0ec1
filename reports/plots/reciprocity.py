"""Reciprocity error maps over a (theta_i, theta_o) grid at fixed azimuths."""

from __future__ import annotations

import numpy as np

from analysis.views import ReciprocityView, compute_reciprocity
from reports.plots.common import FONT, finish, new_axes

__all__ = ["reciprocity_map", "plot_reciprocity_map", "draw_reciprocity_map"]


def reciprocity_map(brdf, phi_i_deg=180.0, phi_o_deg=0.0, resolution=45, quantity="luminance"):
    """Relative reciprocity error on a grid of incidence and viewing angles.

    Parameters
    ----------
    brdf : object with ``.eval``
    phi_i_deg, phi_o_deg : float
        Fixed azimuths of wi and wo in degrees (default: the plane of incidence along the warp,
        light and viewer on opposite sides).
    resolution : int
        Cells per axis; cell centres at theta = (k + 1/2) 90 / resolution degrees.
    quantity : {"luminance", "rgb"}
        "luminance" compares Rec. 709 luminances; "rgb" takes the largest error over the
        three channels.

    Returns
    -------
    theta_deg : numpy.ndarray, shape (resolution,)
    error : numpy.ndarray, shape (resolution, resolution)
        error[i, o] = :func:`analysis.reciprocity.relative_asymmetry` of f(wi, wo) and
        f(wo, wi) (unitless, 0 where both are 0, NaN where one is not finite), rows theta_i,
        columns theta_o.
    """
    view = compute_reciprocity(brdf, phi_i_deg, phi_o_deg, resolution, quantity)
    return view.theta_deg, view.error


def plot_reciprocity_map(brdf=None, phi_i_deg=180.0, phi_o_deg=0.0, *, theta_deg=None,
                         error=None, resolution=45, quantity="luminance", ax=None,
                         filename=None, title=None):
    """Image of the relative reciprocity error over (theta_o, theta_i).

    Either ``brdf`` (the map is computed by :func:`reciprocity_map`) or precomputed
    ``theta_deg`` and ``error`` (shape (n, n), rows theta_i) are given.

    Returns
    -------
    (fig, ax)
        ``ax.images[0].get_array()`` is the error map (rows theta_i, columns theta_o),
        unitless in [0, 1]; the colour bar is labelled.
    """
    if error is None:
        if brdf is None:
            raise ValueError("plot_reciprocity_map needs brdf or theta_deg and error")
        view = compute_reciprocity(brdf, phi_i_deg, phi_o_deg, resolution, quantity)
    else:
        error = np.asarray(error, dtype=np.float64)
        if error.ndim != 2 or error.shape[0] != error.shape[1]:
            raise ValueError(f"error must be a square (n, n) map; got {error.shape}")
        if theta_deg is None:
            n = error.shape[0]
            theta_deg = (np.arange(n) + 0.5) * 90.0 / n
        view = ReciprocityView(np.asarray(theta_deg, dtype=np.float64), error, phi_i_deg,
                               phi_o_deg, quantity)
    return draw_reciprocity_map(view, ax=ax, filename=filename, title=title)


def draw_reciprocity_map(view: ReciprocityView, *, ax=None, filename=None, title=None):
    """Draw a :class:`analysis.views.ReciprocityView` (:func:`plot_reciprocity_map` computes
    or wraps one and calls this); the arguments and the result as its."""
    theta_deg, error = view.theta_deg, view.error
    phi_i_deg, phi_o_deg = view.phi_i_deg, view.phi_o_deg
    step = theta_deg[1] - theta_deg[0] if theta_deg.size > 1 else 90.0
    lo, hi = theta_deg[0] - step / 2, theta_deg[-1] + step / 2
    fig, ax = new_axes(ax, figsize=(5.0, 4.2))
    im = ax.imshow(error, origin="lower", extent=(lo, hi, lo, hi), vmin=0.0, vmax=1.0,
                   cmap="viridis", interpolation="nearest")
    cb = fig.colorbar(im, ax=ax)
    cb.set_label("|f(wi,wo) − f(wo,wi)| / max\n(unitless; 0 where both are 0)",
                 fontsize=FONT["label"])
    cb.ax.tick_params(labelsize=FONT["small"])
    ax.set_xlabel("θo (degrees)", fontsize=FONT["label"])
    ax.set_ylabel("θi (degrees)", fontsize=FONT["label"])
    ax.tick_params(labelsize=FONT["small"])
    found = view.finite_stats()
    stats = f"median {found[0]:.3g}, max {found[1]:.3g}" if found else "no data"
    ax.set_title(title or f"reciprocity error, φi = {phi_i_deg:g}°, φo = {phi_o_deg:g}°\n"
                 f"({stats})", fontsize=FONT["title"])
    return finish(fig, ax, filename)
