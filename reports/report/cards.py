"""The overview's cards: one per fabric, with its render, its key numbers and a link.

Every number on a card comes from a section's data (:class:`FabricReport`) or, for the peak
f_r, from :func:`peak_fr` on a fixed grid; a number whose section was not built shows "—".
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reports.colour import luminance
from reports.prose import albedo_range
from reports.report.markup import Markup, html, join, swatch, url
from reports.report.sec_energy import EnergyData
from reports.report.sec_reciprocity import ReciprocityData
from reports.report.folder import write_file
from reports.report.sec_fit import NO_FIT
from reports.report.sec_renders import RendersData, png_bytes
from reports.report.sec_sanity import SanityData
from reports.report.sections import FabricReport
from reports.report.settings import TITLES

__all__ = ["PEAK_GRID", "peak_fr", "card", "cards", "thumbnail", "card_exposure"]

#: The grid of :func:`peak_fr`, degrees: theta_i, phi_i, theta_o, phi_o.
PEAK_GRID = (np.array([0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0]), np.array([0.0, 90.0]),
             np.arange(0.0, 89.0, 4.0), np.arange(0.0, 360.0, 15.0))
_NONE = "—"


def _dirs(theta_deg, phi_deg) -> np.ndarray:
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def peak_fr(fabric) -> dict:
    """The largest luminance f_r (1/sr) over :data:`PEAK_GRID` and where it is.

    Returns
    -------
    dict
        ``value`` (1/sr) and ``theta_i``, ``phi_i``, ``theta_o``, ``phi_o`` (degrees).

    Examples
    --------
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         return np.full(np.broadcast_shapes(wi.shape, wo.shape), 0.5 / np.pi)
    >>> round(peak_fr(Lambert())["value"], 6)
    0.159155
    """
    ti, pi, to, po = np.meshgrid(*PEAK_GRID, indexing="ij")
    f = luminance(np.asarray(fabric.eval(_dirs(ti, pi), _dirs(to, po)), dtype=np.float64))
    f = np.where(np.isfinite(f), f, -np.inf)
    k = np.unravel_index(int(np.argmax(f)), f.shape)
    return {"value": float(f[k]), "theta_i": float(ti[k]), "phi_i": float(pi[k]),
            "theta_o": float(to[k]), "phi_o": float(po[k])}


def card_exposure(reports: list[FabricReport]) -> float | None:
    """The one exposure (stops) of every card's thumbnail: the lowest of the fabrics' own
    automatic exposures of their first render (the brightest fabric's), so that no card's
    cloth or background blows out and the cards' brightness compares; None without renders.

    Each fabric's page exposes its renders for its own cloth (a dark velvet brightened);
    side by side, cards so exposed would show that velvet as bright as a satin and its grey
    background blown to white.
    """
    stops = []
    for r in reports:
        d = r.data(RendersData)
        if d is not None and d.thumbnail is not None and d.renders:
            stops.append(float(next(iter(d.renders.values()))["exposure"]))
    return min(stops) if stops else None


def thumbnail(root: Path, r: FabricReport, stops: float | None = None) -> str | None:
    """The report-relative path of the fabric's card image: its first render at ``stops``
    (:func:`card_exposure`), written to ``overview/card_NAME.png``; without its linear
    image or ``stops``, the first render's PNG as its page shows it; None without renders."""
    d = r.data(RendersData)
    if d is not None and d.thumbnail is not None and stops is not None:
        rel = f"overview/card_{r.name}.png"
        (root / "overview").mkdir(exist_ok=True)
        write_file(root / rel, png_bytes(d.thumbnail, stops))
        return rel
    for stem in getattr(d, "renders", None) or {}:
        rel = f"{r.name}/render_{stem}.png"
        if (root / rel).is_file():
            return rel
    return None


def _albedo_rows(e: EnergyData | None) -> list:
    if e is None:
        return [("furnace albedo ρ(wo)", _NONE, ""), ("reflectance ρ'(wi)", _NONE, ""),
                ("energy", _NONE, "")]
    f = e.findings()
    rows = [("furnace albedo ρ(wo)", albedo_range(e.value),
             "bad" if f["furnace"]["exceeds"] else "")]
    if "reflectance" in f:
        d = f["reflectance"]
        rows.append(("reflectance ρ'(wi)", albedo_range(e.reflectance),
                     "bad" if d["exceeds"] else ""))
    bad = any(d["exceeds"] for d in f.values())
    rows.append(("energy", e.verdict(), "verdict bad" if bad else "verdict ok"))
    return rows


def card(root: Path, r: FabricReport, colour, stops: float | None = None) -> Markup:
    """One fabric's card: render thumbnail (at ``stops``, every card's one exposure), peak
    f_r, both albedos' ranges, reciprocity median, sanity verdict, the sections that could
    not be built and why (not the fit's when no fit was given), and a link to its page."""
    href = url(f"{r.name}.html")
    thumb = thumbnail(root, r, stops)
    img = (html('<a class="thumb" href="{}"><img src="{}" alt="render of {}" loading="lazy">'
                "</a>", href, url(thumb), r.name) if thumb else
           html('<a class="thumb" href="{}"></a>', href))
    peak = peak_fr(r.fabric)
    rows = [("peak f_r (luminance)", html("{:.3g} sr⁻¹ <small>(θi {:g}°, φi {:g}°; θo {:g}°, "
                                          "φo {:g}°)</small>", peak["value"], peak["theta_i"],
                              peak["phi_i"], peak["theta_o"], peak["phi_o"]), "")]
    rows += _albedo_rows(r.data(EnergyData))
    rec = r.data(ReciprocityData)
    med = None if rec is None else rec.stats.get("median")
    by_design = ("not reciprocal by design" if getattr(r.fabric, "reciprocal", None) is False
                 else "reciprocal by design"
                 if getattr(r.fabric, "reciprocal", None) else "")
    rows.append(("reciprocity error", _NONE if med is None else
                 html("median {:.3g} <small>(the relative difference |f(wi, wo) − f(wo, wi)|"
                      " / max of the two, random pairs{}{})</small>", med,
                      "; " if by_design else "", by_design), ""))
    san = r.data(SanityData)
    if san is None:
        rows.append(("sanity", _NONE, ""))
    elif san.result.ok:
        rows.append(("sanity", f"all {len(san.result.checks)} checks pass", "verdict ok"))
    else:
        rows.append(("sanity", f"{san.n_failing} of {len(san.result.checks)} checks fail",
                     "verdict bad"))
    for run in r.runs:          # a section that could not be built, and why
        if run.status != "ok" and run.status != f"not available: {NO_FIT}":
            rows.append((f"{TITLES.get(run.name, run.name)} section",
                         run.status.replace("not available: ", "not built: ", 1), "na"))
    dl = join(html('<dt>{}</dt><dd class="{}">{}</dd>', k, cls, v) for k, v, cls in rows)
    return html('<article class="card" id="fabric-{name}">{img}<div class="body">'
                '<h3>{sw}<a href="{href}">{name}</a></h3><dl>{dl}</dl></div></article>',
                name=r.name, img=img, sw=swatch(colour), href=href, dl=dl)


def cards(root: Path, reports: list[FabricReport], colours: dict) -> Markup:
    """The overview's grid of cards (``colours``: name -> the fabric's plot colour)."""
    stops = card_exposure(reports)
    note = (html("<p>Every card's render is shown at one exposure, {:+.1f} stops (the lowest of "
                 "the fabrics' automatic exposures), so their brightness compares; each "
                 "fabric's page exposes its renders for its own cloth.</p>", stops)
            if stops is not None and len(reports) > 1 else "")
    return html('<section id="fabrics"><h2>Fabrics at a glance</h2>{}<div class="cards">{}'
                "</div></section>", note,
                join(card(root, r, colours[r.name], stops) for r in reports))
