"""Masking views: the same lobe with shadowing/masking on and off, and the terms M, P and u.

MODEL.md: M(w) = max(cos(phi), 0) with phi the azimuth about the thread;
M(wi, wo) = (1 - u(phi_d)) M(wi) M(wo) + u(phi_d) min(M(wi), M(wo));
u(x) = exp(-x^2 / (2 sigma_u^2)), sigma_u = 20 degrees. P(w) = max(cos(psi), 0) with the same
pairing over psi_d (the visible-length reweighting).
"""

from __future__ import annotations

import numpy as np

from analysis.views import MaskingLobesView, compute_masking_lobes, masking_terms
from reports.plots.common import FONT, PALETTE, finish, legend_outside, new_axes, series_style
from reports.plots.lobes import log_floor, setup_polar, log_radius

__all__ = ["plot_masking_lobes", "plot_masking_terms", "masking_terms", "draw_masking_lobes"]


def plot_masking_terms(pair_with_deg=(0.0, 30.0, 60.0), *, resolution=361, ax=None,
                       filename=None, title=None):
    """M(phi) = P(psi) = max(cos, 0), u(x) and the paired weight M(wi, wo), against angle.

    Parameters
    ----------
    pair_with_deg : sequence of float
        For each value phi_i (degrees) a dashed curve of the paired weight M(wi, wo) against
        phi_o.
    resolution : int
        Samples over [-180, 180] degrees.

    Returns
    -------
    (fig, ax)
        Lines with gid "M", "u" and "pair phi_i=<deg>"; x in degrees.
    """
    if int(resolution) < 3:
        raise ValueError(f"resolution must be at least 3; got {resolution}")
    fig, ax = new_axes(ax, figsize=(8.0, 3.6))
    x = np.linspace(-180.0, 180.0, int(resolution))
    base = masking_terms(x)
    line, = ax.plot(x, base["M"], color="k", lw=1.8, label="M(φ) = P(ψ) = max(cos, 0)")
    line.set_gid("M")
    line, = ax.plot(x, base["u"], color=PALETTE[5], lw=1.4, ls=(0, (1, 1)),
                    label="u(x), σu = 20°")
    line.set_gid("u")
    for n, other in enumerate(np.atleast_1d(pair_with_deg)):
        t = masking_terms(x, other)
        st = series_style(n + 1)
        line, = ax.plot(x, t["pair"], ls=st["ls"], lw=1.4, color=st["color"],
                        label=f"M(wi, wo) against φo,\nφi = {float(other):g}°")
        line.set_gid(f"pair phi_i={float(other):g}")
    ax.set_xlabel("angle about the thread (degrees)", fontsize=FONT["label"])
    ax.set_ylabel("weight (unitless)", fontsize=FONT["label"])
    ax.set_xlim(-180, 180)
    ax.set_xticks(np.arange(-180, 181, 60))
    ax.set_ylim(-0.02, 1.05)
    ax.tick_params(labelsize=FONT["small"])
    ax.grid(alpha=0.3)
    legend_outside(ax, "right")
    ax.set_title(title or "shadowing/masking M, reweighting P and the blend u",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)


def plot_masking_lobes(brdf, theta_i_deg=60.0, phi_deg=0.0, *, scale="linear", decades=4.0,
                       resolution=181, legend=True, ax=None, filename=None, title=None):
    """The same polar lobe (luminance) with masking on (solid) and off (dashed).

    Parameters
    ----------
    brdf : object with ``.eval`` and ``.replace(masking=False)``
        The fabric as given is drawn as "masking on" (its own setting when it has
        ``.options``), the variant ``brdf.replace(masking=False)`` as "masking off".
    theta_i_deg, phi_deg : float
        Incidence angle and plane azimuth in degrees.
    legend : bool
        Draw the legend under the plot (8 pt).

    Returns
    -------
    (fig, ax)
        Lines with gid "masking on" and "masking off", x = signed theta_o (radians),
        y = luminance f_r (1/sr) or its log radius.

    Raises
    ------
    ValueError
        If the BRDF has no ``replace`` accepting ``masking``.
    """
    view = compute_masking_lobes(brdf, theta_i_deg, phi_deg, resolution=resolution)
    return draw_masking_lobes(view, theta_i_deg, phi_deg, scale=scale, decades=decades,
                              legend=legend, ax=ax, filename=filename, title=title)


def draw_masking_lobes(view: MaskingLobesView, theta_i_deg, phi_deg, *, scale="linear",
                       decades=4.0, legend=True, ax=None, filename=None, title=None):
    """Draw one panel (incidence and plane, degrees) of a
    :class:`analysis.views.MaskingLobesView`; the other arguments and the result as
    :func:`plot_masking_lobes`, which computes the view and calls this."""
    fig, ax = new_axes(ax, projection="halfdisc", figsize=(5.0, 3.6))
    curves = view.curves(phi_deg, theta_i_deg)
    theta_o = view.on.theta_o_deg
    peak = max(float(np.nanmax(c)) for c in curves.values())
    floor = log_floor(peak, decades)
    rmax = 0.0
    for n, (name, y) in enumerate(curves.items()):
        r = log_radius(y, floor) if scale == "log" else y
        rmax = max(rmax, float(np.nanmax(r)))
        st = series_style(n)
        line, = ax.plot(np.radians(theta_o), r, color=st["color"], ls=st["ls"], lw=1.5,
                        label=name)
        line.set_gid(name)
    setup_polar(ax, scale, floor, rmax, "luminance f_r (1/sr)")
    if legend:
        legend_outside(ax, "below", ncol=2)
    ax.set_title(title or f"θi = {float(theta_i_deg):g}°, plane φ = {float(phi_deg):g}°",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)
