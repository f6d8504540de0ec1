"""The figure-only sections: lobes, slices, hemisphere and 3-D lobe, shadowing and masking."""

from __future__ import annotations

import numpy as np

from analysis.views import (HemisphereView, compute_hemisphere, compute_lobes,
                            compute_masking_lobes)
from reports.plots.common import FONT
from reports.plots.halfdisc import snug_height
from reports.plots.hemisphere import draw_hemisphere
from reports.plots.lobe3d import plot_lobe_3d
from reports.plots.lobes import draw_lobe_planes
from reports.plots.masking import draw_masking_lobes
from reports.plots.slices import (plot_slice_image, plot_slice_theta_d, plot_slice_theta_h,
                                 plot_slice_theta_o)
from reports.report.markup import Markup, html, join
from reports.report.page import Page, new_figure, replace_3d
from reports.report.settings import Section, Unavailable

__all__ = ["can_unmask", "section_lobes", "section_slices", "section_hemisphere",
           "section_masking", "PLANES"]

#: Incidence angles of the lobe plots, degrees.
LOBE_THETAS = (0.0, 30.0, 60.0)
#: Planes of the lobe plots: azimuth from the warp, degrees.
PLANES = (0.0, 45.0, 90.0)


def can_unmask(fab) -> bool:
    """Whether ``fab.replace(masking=False)`` gives the BRDF with masking switched off.

    A :class:`brdf.Fabric` can; so can a user's model with such a ``replace`` (the brdf
    contract has no Protocol for it, so this is tried).
    """
    replace = getattr(fab, "replace", None)
    if not callable(replace):
        return False
    try:
        replace(masking=False)
    except (TypeError, ValueError):      # no such option (a baseline model: ValueError)
        return False
    return True


def section_lobes(p: Page) -> Section:
    """Polar lobes in the warp, diagonal and weft planes, linear, log and per channel, and
    their numbers as lobes.csv: one :class:`analysis.views.LobeView` (each curve evaluated
    once) that every figure draws and the CSV writes."""
    view = compute_lobes(p.fabric, LOBE_THETAS, PLANES, resolution=p.q["lobe"])
    fig, _ = draw_lobe_planes(view, scale="linear", normalize=True)
    out = [p.figure(fig, "lobes_linear.png",
                    "Luminance f_r, linear, each curve divided by its own peak (the peaks, in "
                    "1/sr, are in the legends) so that every incidence shows, in the planes "
                    "φ = 0° (warp), 45° and 90° (weft), for θi = 0°, 30°, 60°.")]
    fig, _ = draw_lobe_planes(view, scale="log")
    out.append(p.figure(fig, "lobes_log.png",
                        "Luminance f_r (1/sr, log, four decades below the peak) in the same "
                        "planes and incidences."))
    fig, _ = draw_lobe_planes(view.select(theta_i_deg=(30.0, 60.0)), quantity="rgb",
                              scale="linear")
    out.append(p.figure(fig, "lobes_rgb.png", "f_r per channel (red, green, blue curves), "
                        "linear, θi = 30° (solid) and 60° (dashed)."))
    link = p.csv("lobes.csv", *view.columns())
    return Section(join(out) + html("<p>Data (f_r in 1/sr, signed θo in degrees): {}</p>",
                                    link))


def section_slices(p: Page) -> Section:
    """Cartesian slices against θo, θh and θd, and θh × θd images (BRDF Explorer)."""
    fig, axes = new_figure(3, 1, figsize=(11.0, 3.3))
    plot_slice_theta_o(p.fabric, 30.0, 180.0, 0.0, resolution=p.q["lobe"], ax=axes[0], log=True)
    plot_slice_theta_h(p.fabric, 10.0, 90.0, 0.0, resolution=p.q["lobe"], ax=axes[1])
    plot_slice_theta_d(p.fabric, 0.0, 90.0, 0.0, resolution=p.q["lobe"], ax=axes[2])
    out = [p.figure(fig, "slices.png", "Cartesian slices, per channel in red, green and blue: "
                    "f_r against θo (θi = 30°, light on the −x side, view in the warp plane); "
                    "against θh (θd = 10°, φd = 90°, φh = 0); against θd (θh = 0, φd = 90°).")]
    fig, axes = new_figure(2, 1, figsize=(10.0, 4.0))
    for ax, phi_h in zip(axes, (0.0, 90.0)):
        plot_slice_image(p.fabric, 90.0, phi_h, resolution=p.q["image"], ax=ax)
    out.append(p.figure(fig, "slice_image.png", "Luminance f_r (1/sr, log) over θh × θd at "
                        "φd = 90°, with the half vector in the warp plane (φh = 0) and the weft "
                        "plane (φh = 90°)."))
    return Section(join(out))


def _colour_and_lobe3d(p: Page, view: HemisphereView) -> Markup:
    """The sRGB colour of f_r(wo) at θi = 45° (``view``) beside the 3-D lobe."""
    peak = view.peak()
    exposure = float(np.log2(0.7 / peak)) if peak > 0 else 0.0
    fig, axes = new_figure(2, 1, figsize=(10.0, 4.2))
    fig.get_layout_engine().set(w_pad=0.25)   # room the 3-D axes' layout leaves out
    draw_hemisphere(view, quantity="srgb", exposure=exposure, ax=axes[0],
                    title=f"f_r(wo) colour, sRGB, exposure {exposure:+.1f} stops")
    plot_lobe_3d(p.fabric, 45.0, 0.0, resolution=p.q["lobe3d"], ax=replace_3d(fig, axes[1]))
    return p.figure(fig, "lobe3d.png", "Left: the colour of f_r(wo) (θi = 45°, φi = 0), "
                    "linear RGB encoded to sRGB by colour-science, exposure set so the "
                    "peak luminance shows at 0.7. Right: the 3-D lobe, radius = luminance "
                    "f_r cos θo (1/sr).")


def section_hemisphere(p: Page) -> Section:
    """f_r over the viewing hemisphere for three lights, its colour, and the 3-D lobe; the
    light at 45° along the warp evaluated once for its luminance and its colour."""
    views = [compute_hemisphere(p.fabric, ti, phi, p.q["hemi"])
             for ti, phi in ((45.0, 0.0), (45.0, 90.0), (60.0, 45.0))]
    fig, axes = new_figure(3, 1, figsize=(11.0, 3.6))
    for ax, view in zip(axes, views):
        draw_hemisphere(view, ax=ax)
    out = [p.figure(fig, "hemisphere.png", "Luminance f_r(wo) (1/sr, log colour scale) over "
                    "the viewing hemisphere, equal-area projection (+x warp, +y weft), for the "
                    "light at θi = 45° along the warp, 45° along the weft, and 60° at φ = 45°; "
                    "black: more than four decades below the peak; grey: f_r = 0 (where the "
                    "colour bar says so).")]
    out.append(_colour_and_lobe3d(p, views[0]))
    return Section(join(out))


def section_masking(p: Page) -> Section:
    """Lobes with shadowing and masking on and off, at θi = 60° and 80°.

    Raises
    ------
    Unavailable
        For a BRDF without ``replace(masking=False)`` (a measured table, a user's model).
    """
    if not can_unmask(p.fabric):
        raise Unavailable("this BRDF has no replace(masking=...)")
    view = compute_masking_lobes(p.fabric, (60.0, 80.0), PLANES, resolution=p.q["lobe"])
    out = []
    for ti, scale, stem, caption in (
            (60.0, "log", "masking_lobes.png", "Luminance f_r (1/sr, log) at θi = 60° with "
             "shadowing and masking on (solid, blue) and off (dashed, vermilion), in the planes "
             "φ = 0° (warp), 45° and 90° (weft)."),
            (80.0, "log", "masking_lobes_grazing.png", "The same at grazing incidence "
             "θi = 80°.")):
        fig, axes = new_figure(3, 1, figsize=(11.0, 3.0), polar=True)
        for ax, phi in zip(axes, PLANES):
            draw_masking_lobes(view, ti, phi, ax=ax, scale=scale, legend=False)
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=FONT["small"],
                   frameon=False)
        out.append(p.figure(snug_height(fig), stem, caption))
    out.append(Markup('<p>The terms M, P and u themselves are drawn on the <a href='
                      '"index.html#masking">overview page</a>.</p>'))
    return Section(join(out))
