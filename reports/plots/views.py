"""The figures of ``microcyl plot``: one view of several fabrics (or of a table) as panels of
the plot functions of :mod:`reports.plots`.

Each view takes ``fabrics`` (name -> BRDF, in legend order) and the options ``channel``
("luminance", "r", "g", "b" or "rgb"; None for the view's default), ``theta_i`` (degrees),
``planes`` (azimuths of the planes of incidence, degrees), ``scale`` ("log", "linear" or
"normalized") and ``resolution`` (None for the view's default), and returns a
constrained-layout Figure. Several fabrics overlay in one axes where the view is curves
(lobes, slices, albedo) and get a row each where it is an image (hemisphere, reciprocity) or a
comparison of its own (masking).
"""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib.figure import Figure

from analysis import albedo_curve
from analysis.views import (compute_lobes, compute_masking_lobes, compute_table_panel,
                            compute_table_scatter)
from reports.plots.common import FONT, series_styles
from reports.plots.halfdisc import HalfDiscAxes, snug_height
from reports.plots.albedo import plot_albedo
from reports.plots.fit import (draw_scatter_residuals, draw_table_models, draw_table_scatter,
                               table_panels)
from reports.plots.hemisphere import plot_hemisphere
from reports.plots.lobes import draw_lobe_comparison, plane_name, plot_lobe_planes
from reports.plots.masking import draw_masking_lobes
from reports.plots.reciprocity import plot_reciprocity_map
from reports.plots.slices import (plot_slice_image, plot_slice_theta_d, plot_slice_theta_h,
                                 plot_slice_theta_o)

__all__ = ["VIEW_FUNCTIONS", "lobes_view", "slices_view", "hemisphere_view", "masking_view",
           "albedo_view", "reciprocity_view", "table_view", "table_view_data", "table_view_panels",
           "table_scatter_view", "coverage_note", "MAX_WIDTH_IN"]


def _grid(nrows, ncols, panel, polar=False):
    """A constrained-layout figure of ``nrows`` x ``ncols`` axes, ``panel`` inches each
    (``polar``: half discs, :class:`reports.plots.halfdisc.HalfDiscAxes`)."""
    fig = Figure(figsize=(panel[0] * ncols, panel[1] * nrows), layout="constrained")
    kind = {"axes_class": HalfDiscAxes} if polar else {}
    axes = [[fig.add_subplot(nrows, ncols, r * ncols + c + 1, **kind)
             for c in range(ncols)] for r in range(nrows)]
    return fig, axes


def _figure_legend(fig, ax, ncol=None):
    """One legend for the whole figure, under the panels, 8 pt."""
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", frameon=False,
               fontsize=FONT["small"], ncol=ncol or min(len(labels), 4))


def lobes_view(fabrics, *, channel=None, theta_i=None, planes=None, scale="log",
               resolution=None):
    """Polar lobes: one fabric -> a panel per plane, a curve per incidence; several ->
    a panel per incidence (rows) and plane (columns), a curve per fabric."""
    theta_i = theta_i or (0.0, 30.0, 60.0)
    planes = planes or (0.0, 45.0, 90.0)
    quantity = channel or "luminance"
    res = resolution or 181
    if len(fabrics) == 1:
        (name, fab), = fabrics.items()
        fig, axes = plot_lobe_planes(fab, theta_i, planes, quantity=quantity, resolution=res,
                                     scale="linear" if scale == "normalized" else scale,
                                     normalize=scale == "normalized")
        fig.suptitle(f"{name}: f_r in the planes of incidence", fontsize=FONT["title"])
        return snug_height(fig)
    if quantity == "rgb":
        raise ValueError("--channel rgb draws one fabric only; give luminance, r, g or b "
                         "to overlay fabrics")
    if scale == "normalized":
        raise ValueError("--scale normalized draws one fabric only; give log or linear")
    fig, axes = _grid(len(theta_i), len(planes), (4.2, 2.7), polar=True)
    views = {name: compute_lobes(fab, theta_i, planes, resolution=res)
             for name, fab in fabrics.items()}
    peak = max(v.peak(quantity) for v in views.values())
    for row, ti in zip(axes, theta_i):
        for ax, phi in zip(row, planes):     # one peak: the same decades in every panel
            draw_lobe_comparison(views, ti, phi, scale=scale, quantity=quantity,
                                 legend=False, peak=peak, ax=ax)
    _figure_legend(fig, axes[0][0], ncol=3)
    return snug_height(fig)


def slices_view(fabrics, *, channel=None, theta_i=None, planes=None, scale="log",
                resolution=None):
    """BRDF Explorer slices: one fabric -> its θh × θd image and the slices against θo, θh
    and θd (per channel by default); several -> the three slices overlaid, one curve each."""
    ti = (theta_i or (30.0,))[0]
    phi = (planes or (0.0,))[0]
    res = resolution or 181
    log = scale == "log"
    one = len(fabrics) == 1
    quantity = channel or ("rgb" if one else "luminance")
    if quantity == "rgb" and not one:
        raise ValueError("--channel rgb draws one fabric only; give luminance, r, g or b "
                         "to overlay fabrics")
    fig, axes = _grid(2, 2, (5.4, 3.6))
    styles = series_styles(fabrics)
    for name, fab in fabrics.items():
        kw = dict(quantity=quantity, log=log, resolution=res)
        if not one:
            kw.update(label=name, style=styles[name])
        plot_slice_theta_o(fab, ti, phi + 180.0, phi, ax=axes[0][1], **kw)
        plot_slice_theta_h(fab, 10.0, 90.0, phi, ax=axes[1][0], **kw)
        plot_slice_theta_d(fab, 0.0, 90.0, phi, ax=axes[1][1], **kw)
    name, fab = next(iter(fabrics.items()))
    plot_slice_image(fab, 90.0, phi, resolution=min(res, 120), ax=axes[0][0],
                     log=log, title=f"{name}: φd = 90°, φh = {phi:g}°")
    if not one:
        for ax in (axes[0][1], axes[1][0]):
            ax.get_legend().remove()
    return fig


def hemisphere_view(fabrics, *, channel=None, theta_i=None, planes=None, scale="log",
                    resolution=None):
    """f_r(wo) over the hemisphere: a row per fabric, a panel per incidence, the light in
    the first plane (luminance; ``channel`` other than luminance is refused)."""
    if channel not in (None, "luminance"):
        raise ValueError(f"--channel for 'hemisphere' must be luminance; got {channel!r}")
    theta_i = theta_i or (45.0,)
    phi = (planes or (0.0,))[0]
    fig, axes = _grid(len(fabrics), len(theta_i), (4.4, 4.0))
    for row, (name, fab) in zip(axes, fabrics.items()):
        for ax, ti in zip(row, theta_i):
            plot_hemisphere(fab, ti, phi, log=scale == "log", resolution=resolution or 101,
                            ax=ax, title=f"{name}: θi = {ti:g}°, φi = {phi:g}°")
    return fig


def masking_view(fabrics, *, channel=None, theta_i=None, planes=None, scale="log",
                 resolution=None):
    """Lobes with masking on and off: a row per fabric and incidence, a panel per plane."""
    if channel not in (None, "luminance"):
        raise ValueError(f"--channel for 'masking' must be luminance; got {channel!r}")
    theta_i = theta_i or (60.0,)
    planes = planes or (0.0,)
    rows = [(name, fab, ti) for name, fab in fabrics.items() for ti in theta_i]
    fig, axes = _grid(len(rows), len(planes), (4.2, 2.9), polar=True)
    views = {name: compute_masking_lobes(fab, theta_i, planes, resolution=resolution or 181)
             for name, fab in fabrics.items()}
    for row, (name, fab, ti) in zip(axes, rows):
        for ax, phi in zip(row, planes):
            draw_masking_lobes(views[name], ti, phi, legend=False, ax=ax,
                               scale="log" if scale == "log" else "linear",
                               title=f"{name}: θi = {ti:g}°, φ = {phi:g}° "
                                     f"({plane_name(phi)})")
    _figure_legend(fig, axes[0][0])
    return snug_height(fig)


def albedo_view(fabrics, *, channel=None, theta_i=None, planes=None, scale="log",
                resolution=None):
    """Directional albedo against θo, a panel per plane (wo's azimuth), a curve per fabric
    (luminance or one channel; per channel for one fabric with ``channel`` "rgb")."""
    planes = planes or (0.0,)
    quantity = channel or "luminance"
    if quantity == "rgb" and len(fabrics) > 1:
        raise ValueError("--channel rgb draws one fabric only; give luminance, r, g or b "
                         "to overlay fabrics")
    theta = np.linspace(0.0, 87.0, resolution or 30)
    fig, axes = _grid(1, len(planes), (5.0, 3.6))
    styles = series_styles(fabrics)
    for name, fab in fabrics.items():
        res = albedo_curve(fab, theta, np.asarray(planes, dtype=np.float64), tol=2e-3)
        for j, (ax, phi) in enumerate(zip(axes[0], planes)):
            value, error = res.value[:, j], res.error[:, j]
            if quantity in ("r", "g", "b"):
                k = "rgb".index(quantity)
                value, error = value[:, k], error[:, k]
            plot_albedo(theta, value, error, quantity="rgb" if quantity == "rgb" else "luminance",
                        label=name, style=styles[name], legend=False, ax=ax,
                        title=f"albedo ({quantity}), wo at φ = {phi:g}° ({plane_name(phi)})")
    for ax in axes[0]:
        ax.set_xlabel("θo (degrees)", fontsize=FONT["label"])
    _figure_legend(fig, axes[0][0], ncol=3)
    return fig


def reciprocity_view(fabrics, *, channel=None, theta_i=None, planes=None, scale="log",
                     resolution=None):
    """Relative reciprocity error over (θo, θi): a row per fabric, a panel per plane (wi at
    φ + 180°, wo at φ)."""
    if channel not in (None, "luminance", "rgb"):
        raise ValueError(f"--channel for 'reciprocity' must be luminance or rgb; "
                         f"got {channel!r}")
    planes = planes or (0.0,)
    fig, axes = _grid(len(fabrics), len(planes), (4.6, 3.9))
    for row, (name, fab) in zip(axes, fabrics.items()):
        for ax, phi in zip(row, planes):
            plot_reciprocity_map(fab, phi + 180.0, phi, resolution=resolution or 45,
                                 quantity=channel or "luminance", ax=ax)
            ax.set_title(f"{name}, plane φ = {phi:g}°\n{ax.get_title().splitlines()[-1]}",
                         fontsize=FONT["title"])
    return fig


#: The widest a figure of ``plot`` grows by itself: panels wrap into rows beyond this many
#: inches (3,000 pixels at the default 200 dpi, room left for the margins).
MAX_WIDTH_IN = 14.0
_TABLE_PANEL = (4.4, 3.4)
_SCATTER_PANEL = (4.6, 4.2)


def table_view(table, models, *, channel=None, theta_i=None, planes=None, scale="log",
               resolution=None, source=None, panels=None, notes=()):
    """A measured table against models in the first plane: a panel per incidence (default:
    every incidence in the plane) and per side the light was measured from, each
    model evaluated with the light there (:func:`reports.plots.fit.table_points`); points
    with error bars and a curve per model. Panels wrap into rows so that the figure is at
    most :data:`MAX_WIDTH_IN` wide. ``source`` names the table in the title (default its
    ``meta["source"]`` when that is a short text). ``panels`` are the panels'
    :class:`analysis.views.TablePanelView` when computed already (:func:`table_view_panels`,
    whose numbers :func:`table_view_data` writes), else they are computed here. ``notes``
    are lines put under the title (what was left out: :func:`coverage_note`; a fit's
    verdict)."""
    phi = (planes or (0.0,))[0]
    quantity = channel or "luminance"
    if panels is None:
        panels = table_view_panels(table, models, channel=channel, theta_i=theta_i,
                                   planes=planes, resolution=resolution)
    ncols = max(1, min(len(panels), int(MAX_WIDTH_IN // _TABLE_PANEL[0])))
    nrows = -(-len(panels) // ncols)
    fig = Figure(figsize=(_TABLE_PANEL[0] * ncols, _TABLE_PANEL[1] * nrows),
                 layout="constrained")
    axes = [fig.add_subplot(nrows, ncols, k + 1) for k in range(len(panels))]
    for k, (ax, panel) in enumerate(zip(axes, panels)):
        draw_table_models(panel, log=scale == "log", legend=False, ax=ax)
        if k % ncols:
            ax.set_ylabel("")
        if k < len(panels) - ncols:
            ax.set_xlabel("")
    _figure_legend(fig, axes[0])
    what = "luminance" if quantity == "luminance" else f"{quantity.upper()} channel"
    _title(fig, f"{_table_name(table, source)}: measured f_r ({what}) and models in the plane "
                f"φ = {phi:g}° ({plane_name(phi)})", notes, _TABLE_PANEL[0] * ncols)
    return fig


def _title(fig, title: str, notes, width_in: float) -> None:
    """The figure's title, then each note, wrapped to the figure's width."""
    lines = [ln for text in (title, *[n for n in notes if n])
             for ln in textwrap.wrap(text, width=int(13 * width_in))]
    fig.suptitle("\n".join(lines), fontsize=FONT["title"])


def table_scatter_view(table, models, *, channel=None, scale="log", source=None, view=None,
                       notes=()):
    """A table of scattered pairs against models at every valid point: measured against
    each model's f_r at the same pair (:func:`reports.plots.fit.draw_table_scatter`), then
    each model's residuals on the half-vector disk
    (:func:`reports.plots.fit.draw_scatter_residuals`); panels wrap into rows within
    :data:`MAX_WIDTH_IN`. ``view`` is the :class:`analysis.views.TableScatterView` when
    computed already, ``notes`` lines under the title."""
    if view is None:
        view = compute_table_scatter(table, models, quantity=channel or "luminance")
    n = 1 + len(view.models)
    ncols = max(1, min(n, int(MAX_WIDTH_IN // _SCATTER_PANEL[0])))
    nrows = -(-n // ncols)
    fig = Figure(figsize=(_SCATTER_PANEL[0] * ncols, _SCATTER_PANEL[1] * nrows),
                 layout="constrained")
    axes = [fig.add_subplot(nrows, ncols, k + 1) for k in range(n)]
    draw_table_scatter(view, log=scale == "log", legend=False, ax=axes[0])
    for ax, name in zip(axes[1:], view.models):
        draw_scatter_residuals(view, name, ax=ax)
    _figure_legend(fig, axes[0], ncol=3)
    what = "luminance" if view.quantity == "luminance" else f"{view.quantity.upper()} channel"
    _title(fig, f"{_table_name(table, source)}: measured f_r ({what}) and models at every "
                f"measured pair (scattered pairs: no plane of incidence holds a lobe)",
           notes, _SCATTER_PANEL[0] * ncols)
    return fig


def coverage_note(cov) -> str | None:
    """What a view of a table left out, in one line (None when it drew every point), from
    an :class:`analysis.views.TableCoverage`.

    Examples
    --------
    >>> from analysis.views import TableCoverage
    >>> print(coverage_note(TableCoverage(rows=10, valid=9, drawn=5, off_plane=3,
    ...                                   phi_deg=0.0, tol_deg=2.0)))
    drew 5 of 10 points; left out: 3 off the plane φ = 0° (±2°), 1 invalid (NaN or negative)
    """
    if cov.complete:
        return None
    parts = []
    if cov.off_plane:
        parts.append(f"{cov.off_plane} off the plane φ = {cov.phi_deg:g}° (±{cov.tol_deg:g}°)")
    if cov.at_other_incidences:
        parts.append(f"{cov.at_other_incidences} at the incidences not asked for (θi = "
                     + ", ".join(f"{t:g}" for t in cov.other_incidences) + "°)")
    if cov.invalid:
        parts.append(f"{cov.invalid} invalid (NaN or negative)")
    return f"drew {cov.drawn} of {cov.rows} points; left out: " + ", ".join(parts)


def table_view_panels(table, models, *, channel=None, theta_i=None, planes=None,
                      resolution=None, curves=True) -> list:
    """The panels :func:`table_view` draws, each a :class:`analysis.views.TablePanelView`
    (every model evaluated once at the measured points and, with ``curves``, once along the
    plane at ``resolution`` angles, default 181)."""
    phi = (planes or (0.0,))[0]
    return [compute_table_panel(table, models, ti, phi, light, quantity=channel or "luminance",
                                resolution=(resolution or 181) if curves else None)
            for ti, light in table_panels(table, theta_i, phi)]


def _table_name(table, source) -> str:
    """What the title calls a table: ``source``, else its meta's source when that is a
    short text, else "table"."""
    if source:
        return str(source)
    meta = getattr(table, "meta", None) or {}
    name = meta.get("source") if isinstance(meta, dict) else None
    return name if isinstance(name, str) and 0 < len(name) <= 60 else "table"


def table_view_data(table, models, *, channel=None, theta_i=None, planes=None,
                    panels=None) -> list:
    """What :func:`table_view` draws at the measured points, one row per point and curve:
    ``(curve, theta_i, phi_i, theta_o, phi_o, f_r)``, curve ``"measured"`` or a model's
    label, the angles of the measured point in degrees (phi in (-180, 180]), f_r in 1/sr
    (the measured value, or the model's at that point's own directions). ``panels`` are
    those the figure drew (:func:`table_view_panels`), else the points are computed here."""
    if panels is None:
        panels = table_view_panels(table, models, channel=channel, theta_i=theta_i,
                                   planes=planes, curves=False)
    angles = np.degrees(np.asarray(table.angles))
    return [row for panel in panels for row in panel.rows(angles)]


#: View name -> figure builder (``table`` takes a table and models instead of fabrics).
VIEW_FUNCTIONS = {"lobes": lobes_view, "slices": slices_view, "hemisphere": hemisphere_view,
                  "masking": masking_view, "albedo": albedo_view,
                  "reciprocity": reciprocity_view, "table": table_view}
