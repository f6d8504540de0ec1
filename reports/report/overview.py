"""The overview page (index.html): fabrics, lobes and albedo compared, masking terms,
reciprocity and sanity compared."""

from __future__ import annotations

from pathlib import Path

from reports.plots.common import FONT, series_styles
from reports.plots.albedo import plot_albedo
from reports.plots.lobes import plot_lobe_comparison
from reports.plots.masking import plot_masking_terms
from reports.prose import ALBEDO_KINDS, albedo_range, overview_sentence
from reports.report.markup import Markup, fmt, html, join, swatch, table, url
from reports.report.page import Page, new_figure
from reports.report.sec_energy import ALBEDO_PHI, EnergyData
from reports.report.sec_parameters import THREAD_FIELDS, THREAD_HEADER, parameters_of
from reports.report.sec_reciprocity import ReciprocityData
from reports.report.sec_sanity import SanityData
from reports.report.sections import FabricReport

__all__ = ["overview"]


def _fabrics(reports: list[FabricReport], colours: dict) -> Markup:
    rows = []
    for r in reports:
        params = parameters_of(r.fabric)
        name = html('{}<a href="{}">{}</a>', swatch(colours[r.name]), url(f"{r.name}.html"),
                    r.name)
        for j, t in enumerate(params["threads"]):
            rows.append([name if j == 0 else "", f"T{j + 1}"] +
                        [fmt(t[f]) for f in THREAD_FIELDS])
        if not params["threads"]:
            rows.append([name, "n/a"] + [""] * len(THREAD_FIELDS))
    return html('<section id="overview"><h2>Parameters</h2>{}</section>',
                table(["fabric", "thread", *THREAD_HEADER], rows))


def _lobes(p: Page, reports: list[FabricReport]) -> Markup:
    fabrics = {r.name: r.fabric for r in reports}
    out = [Markup('<section id="combined-lobes"><h2>Lobes compared</h2>')]
    for ti, phi in ((30.0, 0.0), (60.0, 0.0), (60.0, 90.0)):
        fig, ax = plot_lobe_comparison(fabrics, ti, phi, resolution=p.q["lobe"])
        out.append(p.figure(fig, f"lobes_ti{ti:g}_phi{phi:g}.png",
                            f"Luminance f_r (1/sr, log) of every fabric, θi = {ti:g}°, plane "
                            f"φ = {phi:g}°; each fabric in its own colour and line style."))
    return join(out) + Markup("</section>")


def _albedo(p: Page, reports: list[FabricReport]) -> Markup:
    have = {r.name: e for r in reports if (e := r.data(EnergyData)) is not None}
    out = [Markup('<section id="albedo-comparison"><h2>Albedos compared</h2>')]
    if not have:
        out.append(Markup('<p class="na">Not available: no fabric has energy results (the '
                          'energy section was not requested).</p></section>'))
        return join(out)
    modes = [m for m in ALBEDO_KINDS if all(m in e.curves() for e in have.values())]
    fig, axes = new_figure(2, len(modes), figsize=(11.0, 3.4 * len(modes) + 0.6))
    styles = series_styles(have)
    for row, mode in enumerate(modes):
        name, symbol, angle = ALBEDO_KINDS[mode]
        for j, phi in enumerate(ALBEDO_PHI):
            ax = axes[2 * row + j]
            for fab, e in have.items():
                value, error = e.curves()[mode]
                plot_albedo(e.theta_deg, value[:, j], error[:, j], quantity="luminance",
                            style=styles[fab], label=fab, ax=ax, legend=False,
                            title=f"{name} {symbol.split(' = ')[0]}, luminance, φ = {phi:g}°")
            ax.set_xlabel(f"{angle} (degrees)", fontsize=FONT["label"])
            ax.set_ylabel(f"{name} (unitless)", fontsize=FONT["label"])
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(len(have), 3),
               fontsize=FONT["small"], frameon=False)
    out.append(p.figure(fig, "albedo_comparison.png", "Rec. 709 luminance of both directional "
                        "albedos of every fabric: the furnace albedo ρ(wo) against θo (top) and "
                        "the directional reflectance ρ'(wi) against θi (bottom), the fixed "
                        "direction along the warp (left) and the weft (right); each fabric in "
                        "its own colour, line style and marker; the dotted line is 1."))
    out.append(html("<p>{}</p>", overview_sentence({n: e.findings() for n, e in have.items()})))
    rows = []
    for n, e in have.items():
        f = e.findings()
        row = [html("{}{}", swatch(styles[n]["color"]), n), albedo_range(e.value),
               "yes" if f["furnace"]["exceeds"] else "no"]
        if "reflectance" in f:
            d = f["reflectance"]
            row += [albedo_range(e.reflectance), f"{d['max']:.3f} at θi = {d['max_theta']:g}°",
                    f"from θi = {d['first']:g}°" if d["exceeds"] else "no"]
        rows.append(row)
    header = ["fabric", "furnace albedo ρ(wo), range", "ρ(wo) exceeds 1"]
    if "reflectance" in modes:
        header += ["reflectance ρ'(wi), range", "largest ρ'(wi)", "ρ'(wi) exceeds 1"]
    out.append(table(header, rows))
    return join(out) + Markup("</section>")


def _masking(p: Page) -> Markup:
    fig, ax = plot_masking_terms(resolution=max(p.q["lobe"], 61))
    return html('<section id="masking"><h2>Shadowing, masking and reweighting terms</h2>'
                "{}</section>",
                p.figure(fig, "masking_terms.png", "M(φ) = max(cos φ, 0) (and P(ψ), the same "
                         "form), the blend u with σu = 20°, and the paired weight M(wi, wo) "
                         "against φo for φi = 0°, 30°, 60° (the model page of the documentation, "
                         "docs/guide/model.rst)."))


def _reciprocity(reports: list[FabricReport]) -> Markup:
    recs = {r.name: d.maps for r in reports if (d := r.data(ReciprocityData)) is not None}
    if not recs:
        return Markup("")
    return html('<section id="reciprocity-comparison"><h2>Reciprocity compared</h2>'
                "{}</section>",
                table(["fabric", "warp plane median", "warp plane max", "weft plane median",
                       "weft plane max"],
                      [[n, f"{r['warp']['median']:.3g}", f"{r['warp']['max']:.3g}",
                        f"{r['weft']['median']:.3g}", f"{r['weft']['max']:.3g}"]
                       for n, r in recs.items()]))


def _sanity(reports: list[FabricReport]) -> Markup:
    have = {r.name: d for r in reports if (d := r.data(SanityData)) is not None}
    if not have:
        return Markup("")
    rows = [[n, len(d.result.checks), sum(c["n"] for c in d.result.checks), d.n_failing,
             "yes" if d.result.ok else "no"] for n, d in have.items()]
    return html('<section id="sanity-comparison"><h2>Sanity compared</h2>{}</section>',
                table(["fabric", "checks", "evaluations", "failing", "all pass"], rows))


def overview(root: Path, reports: list[FabricReport], sections, q: dict,
             colours: dict | None = None) -> Markup:
    """The body of index.html; its figures go to ``root/overview``.

    Parameters
    ----------
    root : Path
        The (temporary) report folder.
    reports : list of FabricReport
        Every fabric as built, in page order.
    sections : sequence of str
        The per-fabric sections requested.
    q : dict
        Resolutions (a value of :data:`reports.report.QUALITIES`).
    colours : dict, optional
        Fabric name -> its plot colour (default :func:`series_styles` of the names).
    """
    p = Page(root, "overview", None, q)
    if colours is None:
        colours = {n: st["color"] for n, st in series_styles([r.name for r in reports]).items()}
    return (_fabrics(reports, colours) + _lobes(p, reports) + _albedo(p, reports) + _masking(p)
            + _reciprocity(reports) + _sanity(reports)
            + html('<p>Sections per fabric: {}. Data: <a href="summary.json">summary.json</a>.'
                   "</p>", ", ".join(sections)))
