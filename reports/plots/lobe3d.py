"""The 3-D lobe: the surface r(wo) wo over the upper hemisphere for a fixed light."""

from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.ticker import MaxNLocator

from analysis.views import Lobe3DView, compute_lobe_3d
from reports.plots.common import FONT, finish, new_axes

__all__ = ["plot_lobe_3d", "draw_lobe_3d"]


def plot_lobe_3d(brdf, theta_i_deg=45.0, phi_i_deg=0.0, *, cosine=True, resolution=(30, 60),
                 ax=None, filename=None, title=None):
    """3-D lobe: the surface r(wo) wo over the upper hemisphere for a fixed wi.

    Parameters
    ----------
    brdf : object with ``.eval``
    theta_i_deg, phi_i_deg : float
        Direction of the light in degrees.
    cosine : bool
        r = luminance(f_r) cos(theta_o) when True (the visible lobe), luminance(f_r) when False;
        in 1/sr.
    resolution : (int, int)
        Samples in theta_o over [0, 90] and in phi_o over [0, 360] degrees.
    ax : Axes3D, optional
    filename : str or path, optional

    Returns
    -------
    (fig, ax)
        The surface is ``ax.collections[0]``; its z extent is the largest r cos(theta_o).
    """
    view = compute_lobe_3d(brdf, theta_i_deg, phi_i_deg, cosine=cosine, resolution=resolution)
    return draw_lobe_3d(view, ax=ax, filename=filename, title=title)


def draw_lobe_3d(view: Lobe3DView, *, ax=None, filename=None, title=None):
    """Draw a :class:`analysis.views.Lobe3DView` (:func:`plot_lobe_3d` computes one and
    calls this); the arguments and the result as :func:`plot_lobe_3d`'s."""
    fig, ax = new_axes(ax, projection="3d", figsize=(5.0, 4.5))
    r, wi, cosine = view.r, view.wi, view.cosine
    theta_i_deg, phi_i_deg = view.theta_i_deg, view.phi_i_deg
    X, Y, Z = view.xyz
    norm = matplotlib.colors.Normalize(0.0, max(float(np.nanmax(r)), 1e-12))
    facecolors = matplotlib.colormaps["viridis"](norm(r))
    ax.plot_surface(X, Y, Z, facecolors=facecolors, rstride=1, cstride=1, linewidth=0,
                    antialiased=False, shade=False)
    ext = max(float(np.nanmax(np.abs([X, Y, Z]))), 1e-12)
    ax.plot([0, wi[0] * ext], [0, wi[1] * ext], [0, wi[2] * ext], color="orange", lw=1.5,
            label="wi")
    ax.set_xlim(-ext, ext)
    ax.set_ylim(-ext, ext)
    ax.set_zlim(0, ext)
    ax.set_xlabel("x: warp", fontsize=FONT["label"], labelpad=12)
    ax.set_ylabel("y: weft", fontsize=FONT["label"], labelpad=12)
    ax.set_zlabel("z", fontsize=FONT["label"], labelpad=10)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(3))
    ax.tick_params(labelsize=FONT["small"], pad=1)
    what = "luminance f_r cos θo" if cosine else "luminance f_r"
    sm = matplotlib.cm.ScalarMappable(norm=norm, cmap="viridis")
    fig.colorbar(sm, ax=ax, shrink=0.7, pad=0.12, label=f"{what} (1/sr)")
    ax.set_title(title or f"3-D lobe, θi = {float(theta_i_deg):g}°, φi = {float(phi_i_deg):g}°"
                 f"\n(x, y, z: r wo, r in 1/sr)", fontsize=FONT["title"])
    return finish(fig, ax, filename)
