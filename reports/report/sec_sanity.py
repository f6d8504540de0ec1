"""The "sanity" section: the violation scan of :func:`analysis.sanity_scan` as a table."""

from __future__ import annotations

import dataclasses
from typing import Any

import brdf
from analysis import SanityResult, sanity_scan
from reports.report.markup import Markup, html, join, table
from reports.report.page import Page
from reports.report.settings import Section

__all__ = ["SanityData", "DIRECTION_SETS", "check_passes", "section_sanity"]

#: What each direction set of :func:`analysis.sanity.edge_pairs` holds (angles in degrees).
DIRECTION_SETS = {
    "grazing_i": "light at grazing θi from 89° to 90°, viewer at θo up to 85°",
    "grazing_o": "the same with light and viewer exchanged",
    "both_grazing": "light and viewer both at grazing angles",
    "phi_d_near_pi": "opposite azimuths, φd within 1e-9° to 0.1° of 180°",
    "retro": "wi = wo, θ from 0 to 90°",
    "mirror": "wo the mirror direction of wi",
    "along_tangent_i": "light along a thread tangent (offsets −90° to 90°)",
    "along_tangent_o": "viewer along a thread tangent",
    "tangent_pairs": "light and viewer both along thread tangents",
    "below_horizon": "a direction below the horizon: f_r must be 0",
}


def check_passes(c: dict) -> bool:
    """Whether one check of a :class:`analysis.SanityResult` found nothing wrong."""
    return not (c["n_nonfinite"] or c["n_negative"] or c["warnings"]
                or c.get("n_nonzero_below_horizon"))


def _cell(c: dict) -> str:
    if check_passes(c):
        return "ok"
    parts = [f"{c['n_nonfinite']} non-finite" if c["n_nonfinite"] else "",
             f"{c['n_negative']} negative" if c["n_negative"] else "",
             f"{c.get('n_nonzero_below_horizon')} non-zero below horizon"
             if c.get("n_nonzero_below_horizon") else "",
             f"{len(c['warnings'])} warnings" if c["warnings"] else ""]
    return "FAIL: " + ", ".join(x for x in parts if x)


@dataclasses.dataclass(frozen=True)
class SanityData:
    """The sanity scan of one fabric.

    Attributes
    ----------
    result : analysis.SanityResult
        Every check: parameter set, direction set, evaluations and violations.
    """

    result: SanityResult

    @property
    def n_failing(self) -> int:
        """How many checks found a violation."""
        return sum(not check_passes(c) for c in self.result.checks)

    def summary(self) -> dict[str, Any]:
        """``sanity``: whether every check passes, and the counts."""
        return {"sanity": {"ok": self.result.ok, "n_checks": len(self.result.checks),
                           "n_evaluations": sum(c["n"] for c in self.result.checks),
                           "n_failing": self.n_failing}}


def _matrix(checks: list) -> Markup:
    """Parameter sets (rows) by direction sets (columns): "ok" or what failed."""
    dirs = list(dict.fromkeys(c["directions"] for c in checks if c["directions"] is not None))
    rows: dict[str, list] = {}
    for c in checks:
        row = rows.setdefault(c["params"], [c["params"]] + [""] * len(dirs))
        if c["directions"] is None:
            row[1] = f"refused: {c.get('refused', '')}"
        else:
            row[1 + dirs.index(c["directions"])] = _cell(c)
    return table(["parameter set"] + dirs, list(rows.values()))


def section_sanity(p: Page) -> Section:
    """The scan's verdict, its table of checks, the direction sets explained, sanity.json."""
    # edge parameter sets only for a brdf.Fabric: they are made with Fabric.replace(threads=)
    res = sanity_scan(p.fabric, parameters=isinstance(p.fabric, brdf.Fabric))
    data = SanityData(res)
    link = p.json("sanity.json", res.to_dict())
    n_eval = sum(c["n"] for c in res.checks)
    verdict = ("every check passes" if res.ok else
               f"{data.n_failing} of {len(res.checks)} checks find a violation")
    legend = join(html("<li><b>{}</b>: {}</li>", k, v) for k, v in DIRECTION_SETS.items())
    return Section(html(
        "<p>f_r evaluated {} times on {} (parameter set, direction set) "
        "checks built for the edges of the domain (analysis.sanity_scan, as "
        "<code>microcyl sanity</code>): a NaN, infinite or negative value, a RuntimeWarning, "
        "or a non-zero value below the horizon is a violation. Result: "
        "<b>{}</b>.</p>{}<p>Direction sets:</p><ul>{}</ul><p>Data: {}</p>",
        n_eval, len(res.checks), verdict, _matrix(res.checks), legend, link), data)
