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
from reports.report.sec_renders import RendersData
from reports.report.sec_sanity import SanityData
from reports.report.sections import FabricReport

__all__ = ["PEAK_GRID", "peak_fr", "card", "cards", "thumbnail"]

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


def thumbnail(root: Path, r: FabricReport) -> str | None:
    """The report-relative path of the fabric's first render, or None when it has none."""
    d = r.data(RendersData)
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


def card(root: Path, r: FabricReport, colour) -> Markup:
    """One fabric's card: render thumbnail, peak f_r, both albedos' ranges, reciprocity
    median, sanity verdict and a link to its page."""
    href = url(f"{r.name}.html")
    thumb = thumbnail(root, r)
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
    rows.append(("reciprocity error", _NONE if med is None else
                 html("median {:.3g} <small>(random pairs)</small>", med), ""))
    san = r.data(SanityData)
    if san is None:
        rows.append(("sanity", _NONE, ""))
    elif san.result.ok:
        rows.append(("sanity", f"all {len(san.result.checks)} checks pass", "verdict ok"))
    else:
        rows.append(("sanity", f"{san.n_failing} of {len(san.result.checks)} checks fail",
                     "verdict bad"))
    missing = [run.name for run in r.runs if run.status != "ok"]
    if missing:
        rows.append(("not built", ", ".join(missing), "na"))
    dl = join(html('<dt>{}</dt><dd class="{}">{}</dd>', k, cls, v) for k, v, cls in rows)
    return html('<article class="card" id="fabric-{name}">{img}<div class="body">'
                '<h3>{sw}<a href="{href}">{name}</a></h3><dl>{dl}</dl></div></article>',
                name=r.name, img=img, sw=swatch(colour), href=href, dl=dl)


def cards(root: Path, reports: list[FabricReport], colours: dict) -> Markup:
    """The overview's grid of cards (``colours``: name -> the fabric's plot colour)."""
    return html('<section id="fabrics"><h2>Fabrics at a glance</h2><div class="cards">{}'
                "</div></section>", join(card(root, r, colours[r.name]) for r in reports))
