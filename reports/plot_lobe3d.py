"""The 3-D lobe: the surface r(wo) wo over the upper hemisphere for a fixed light."""

from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.ticker import MaxNLocator

from brdf.frames import from_angles
from reports._plotting import FONT, check_angle, eval_brdf, finish, new_axes
from reports.colour import luminance

__all__ = ["plot_lobe_3d"]


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
    check_angle("theta_i_deg", theta_i_deg, 0.0, 89.999)
    nt, npf = (int(v) for v in resolution)
    if nt < 2 or npf < 3:
        raise ValueError(f"resolution must be at least (2, 3); got {resolution}")
    fig, ax = new_axes(ax, projection="3d", figsize=(5.0, 4.5))
    t = np.radians(np.linspace(0.0, 90.0, nt))
    p = np.radians(np.linspace(0.0, 360.0, npf))
    T, P = np.meshgrid(t, p, indexing="ij")
    wo = from_angles(T, P)
    wi = from_angles(np.radians(theta_i_deg), np.radians(phi_i_deg))
    r = luminance(eval_brdf(brdf, wi, wo))
    if cosine:
        r = r * np.cos(T)
    X, Y, Z = (r * wo[..., k] for k in range(3))
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
