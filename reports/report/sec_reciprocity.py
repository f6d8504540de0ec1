"""The "reciprocity" section: maps of |f(wi,wo) - f(wo,wi)| / max and statistics over pairs."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from analysis import reciprocity
from analysis.views import compute_reciprocity
from reports.plots.reciprocity import draw_reciprocity_map
from reports.report.markup import Markup, fmt, html, join, plain_json, table
from reports.report.page import Page, new_figure
from reports.report.settings import Section

__all__ = ["ReciprocityData", "MAP_PLANES", "section_reciprocity"]

#: The maps: (phi_i, phi_o in degrees, label): light and viewer on opposite sides of a plane.
MAP_PLANES = ((180.0, 0.0, "warp"), (270.0, 90.0, "weft"))
_STATS = ("median", "p95", "max")


@dataclasses.dataclass(frozen=True)
class ReciprocityData:
    """Reciprocity of one fabric (relative errors, dimensionless in [0, 1]).

    Attributes
    ----------
    maps : dict
        Plane label -> ``phi_i_deg``, ``phi_o_deg``, ``theta_deg``, ``error`` (the map),
        ``median`` and ``max``.
    stats : dict
        ``median``, ``p95`` and ``max`` over random pairs (:func:`analysis.reciprocity`).
    """

    maps: dict
    stats: dict

    def summary(self) -> dict[str, Any]:
        """``reciprocity_maps`` (median and max per plane) and ``reciprocity`` (the stats)."""
        return {"reciprocity_maps": {k: {"median": v["median"], "max": v["max"]}
                                     for k, v in self.maps.items()},
                "reciprocity": self.stats}


def _maps(p: Page) -> tuple[dict, Markup]:
    maps = {}
    fig, axes = new_figure(2, 1, figsize=(10.0, 4.0))
    for ax, (pi, po, label) in zip(axes, MAP_PLANES):
        view = compute_reciprocity(p.fabric, pi, po, p.q["recip"])
        err = view.error
        maps[label] = {"phi_i_deg": pi, "phi_o_deg": po, "theta_deg": view.theta_deg,
                       "error": err, "median": float(np.median(err)), "max": float(np.max(err))}
        draw_reciprocity_map(view, ax=ax)
    return maps, p.figure(fig, "reciprocity.png", "Relative reciprocity error of the luminance "
                          "|f(wi,wo) − f(wo,wi)| / max over θi × θo, light and viewer on "
                          "opposite sides of the warp plane (left) and the weft plane (right).")


def section_reciprocity(p: Page) -> Section:
    """The two maps, reciprocity.json, and :func:`analysis.reciprocity` over random pairs."""
    maps, fig = _maps(p)
    link = p.json("reciprocity.json", maps)
    rows = [[k, f"{v['median']:.3g}", f"{v['max']:.3g}"] for k, v in maps.items()]
    res = reciprocity(p.fabric)
    stats = {k: plain_json(getattr(res, k)) for k in _STATS}
    out = [fig, table(["plane", "median error", "max error"], rows),
           html("<p>Data: {}</p>", link),
           html("<p>Over random pairs (analysis.reciprocity): {}</p>",
                ", ".join(f"{k} {fmt(v)}" for k, v in stats.items()))]
    return Section(join(out), ReciprocityData(maps, stats))
