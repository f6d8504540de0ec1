"""The "fit" section: the posterior summary of a ``microcyl fit`` of the fabric, its verdicts
(converged, adequate) and its warnings."""

from __future__ import annotations

import dataclasses
from typing import Any

from analysis.fit.results import read_results
from reports.report.markup import Markup, fmt, html, table
from reports.report.page import Page
from reports.report.settings import Section, Unavailable

#: Why the fit section is not built when no fit was given for the fabric (the usual case:
#: the overview's cards leave it out).
NO_FIT = ("no fitting results for this fabric (run `microcyl fit` and pass its results.json "
          "with --fit)")

__all__ = ["FitData", "section_fit"]

_COLUMNS = ("median", "lo68", "hi68", "lo95", "hi95", "tau", "rhat", "ess")


@dataclasses.dataclass(frozen=True)
class FitData:
    """The results document of a fit (:func:`analysis.fit.results.read_results`)."""

    results: dict

    def summary(self) -> dict[str, Any]:
        """``fit``: the results document."""
        return {"fit": self.results}


def section_fit(p: Page) -> Section:
    """Per parameter: median, 68 % and 95 % intervals, τ, R-hat, ESS; convergence, adequacy
    and the warnings (:mod:`analysis.fit.trust`).

    Raises
    ------
    Unavailable
        When no ``results.json`` was given for the fabric, or it cannot be read.
    """
    if p.fit_results is None:
        raise Unavailable(NO_FIT)
    try:
        data = read_results(p.fit_results)
    except ValueError as exc:
        raise Unavailable(str(exc)) from None
    rows = [[k] + [fmt(v.get(f)) for f in _COLUMNS] for k, v in data["parameters"].items()]
    return Section(html("<p>Model: {}</p>", str(data.get("model", "microcylinder")))
                   + table(["parameter", "median", "lo68", "hi68", "lo95", "hi95", "τ", "R-hat",
                          "ESS"], rows)
                   + html("<p>Converged: {}</p>", fmt(data.get("converged")))
                   + _trust(data), FitData(data))


def _trust(data: dict) -> Markup:
    """The adequacy verdict and the warnings (every value escaped)."""
    out = html("<p>Adequate (the model describes the data): {} — {}</p>",
               fmt(data.get("adequate")), data.get("adequate_reason", "not checked"))
    warnings = data.get("warnings") or []
    if not isinstance(warnings, list):
        return out
    rows = [[str(w.get("kind", "")), ", ".join(map(str, w.get("parameters") or [])),
             str(w.get("message", ""))] for w in warnings if isinstance(w, dict)]
    return out + (table(["warning", "parameters", "message"], rows) if rows
                  else Markup("<p>No warnings.</p>"))
