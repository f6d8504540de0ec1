"""Masking views: the same lobe with shadowing/masking on and off, and the terms M, P and u.

MODEL.md: M(w) = max(cos(phi), 0) with phi the azimuth about the thread;
M(wi, wo) = (1 - u(phi_d)) M(wi) M(wo) + u(phi_d) min(M(wi), M(wo));
u(x) = exp(-x^2 / (2 sigma_u^2)), sigma_u = 20 degrees. P(w) = max(cos(psi), 0) with the same
pairing over psi_d (the visible-length reweighting).
"""

from __future__ import annotations

import numpy as np

from brdf import terms
from reports._plotting import (FONT, PALETTE, eval_brdf, finish, legend_outside, new_axes,
                               series_style)
from reports.colour import luminance
from reports.plot_lobes import _log_floor, _setup_polar, log_radius, plane_directions

__all__ = ["plot_masking_lobes", "plot_masking_terms", "masking_terms"]


def masking_terms(angle_deg, pair_with_deg=0.0):
    """M (= P) of one direction, u, and the paired weight, against an angle in degrees.

    Parameters
    ----------
    angle_deg : array_like
        Azimuth about the thread (phi for M, psi for P) in degrees.
    pair_with_deg : float
        The other direction's angle in degrees, for the paired weight.

    Returns
    -------
    dict of numpy.ndarray
        "M": max(cos(angle), 0); "u": u(angle); "pair": pair weight of (angle, pair_with) with
        difference angle - pair_with, from :func:`brdf.terms.u` and
        :func:`brdf.terms.pair_weight`.

    Examples
    --------
    >>> t = masking_terms([0.0, 20.0, 90.0])
    >>> np.round(t["u"], 4).tolist()
    [1.0, 0.6065, 0.0]
    """
    x = np.radians(np.asarray(angle_deg, dtype=np.float64))
    other = np.radians(float(pair_with_deg))
    m = np.maximum(np.cos(x), 0.0)
    m_other = np.maximum(np.cos(other), 0.0) * np.ones_like(x)
    delta = np.angle(np.exp(1j * (x - other)))  # wrap into (-pi, pi]
    u = np.asarray(terms.u(x), dtype=np.float64)
    pair = np.asarray(terms.pair_weight(m, m_other, delta), dtype=np.float64)
    return {"M": m, "u": u, "pair": pair}


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
    replace = getattr(brdf, "replace", None)
    if replace is None:
        raise ValueError(f"brdf must have .replace(masking=...) for masking views; "
                         f"got {type(brdf).__name__}")
    on = replace(masking=True)
    off = replace(masking=False)
    fig, ax = new_axes(ax, projection="polar", figsize=(5.0, 3.6))
    theta_o = np.linspace(-90.0, 90.0, int(resolution))
    wi, wo = plane_directions(theta_i_deg, theta_o, phi_deg)
    curves = {"masking on": luminance(eval_brdf(on, wi, wo)),
              "masking off": luminance(eval_brdf(off, wi, wo))}
    peak = max(float(np.nanmax(c)) for c in curves.values())
    floor = _log_floor(peak, decades)
    rmax = 0.0
    for n, (name, y) in enumerate(curves.items()):
        r = log_radius(y, floor) if scale == "log" else y
        rmax = max(rmax, float(np.nanmax(r)))
        st = series_style(n)
        line, = ax.plot(np.radians(theta_o), r, color=st["color"], ls=st["ls"], lw=1.5,
                        label=name)
        line.set_gid(name)
    _setup_polar(ax, scale, floor, rmax, "luminance f_r (1/sr)")
    if legend:
        legend_outside(ax, "below", ncol=2)
    ax.set_title(title or f"θi = {float(theta_i_deg):g}°, plane φ = {float(phi_deg):g}°",
                 fontsize=FONT["title"])
    return finish(fig, ax, filename)
