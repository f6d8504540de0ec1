"""The "parameters" section: each thread's parameters, the options, f_r at standard geometries."""

from __future__ import annotations

import dataclasses
from typing import Any

from brdf import schema
from brdf.models import model_name
from brdf.protocols import Model, ThreadedBRDF
from reports.report.markup import fmt, html, plain_json, table
from reports.report.page import Page
from reports.report.settings import Section
from reports.standard import STANDARD_GEOMETRIES, standard_values

__all__ = ["ParametersData", "THREAD_FIELDS", "THREAD_HEADER", "parameters_of",
           "section_parameters"]

#: Thread attributes shown, in table order (the parameter schema's).
THREAD_FIELDS = schema.THREAD_FIELDS
#: Column headings of :data:`THREAD_FIELDS`, with units (gamma and offsets in degrees).
THREAD_HEADER = tuple(p.heading for p in schema.THREAD_PARAMS)


def parameters_of(fab) -> dict:
    """Plain data of a BRDF's threads (the :data:`THREAD_FIELDS`) and options.

    A BRDF without threads or options (a measured table, a user's analytic model) gives an
    empty list and dict; a registered model without threads (:data:`brdf.MODELS`: the
    baselines) adds ``model`` (its name) and ``values`` (its parameters by row, a colour as
    its three channels).
    """
    threads = [{f: plain_json(getattr(t, f, None)) for f in THREAD_FIELDS}
               for t in getattr(fab, "threads", ()) or ()]
    out = {"threads": threads, "options": plain_json(dict(getattr(fab, "options", {}) or {}))}
    if isinstance(fab, Model) and not isinstance(fab, ThreadedBRDF):
        out.update(model=model_name(fab),
                   values=plain_json(fab.param_schema().grouped(fab.values(), tuple)))
    return out


def _rows(model) -> list:
    """The rows (:class:`brdf.schema.ParamInfo`) of a model's flat parameters, in order, a
    colour once."""
    return [p.info for p in model.param_schema() if p.group is None or p.channel == 0]


@dataclasses.dataclass(frozen=True)
class ParametersData:
    """The parameters of a fabric and its f_r (1/sr, RGB) at the standard geometries."""

    parameters: dict
    standard_geometries: dict | None

    def summary(self) -> dict[str, Any]:
        """``parameters`` and (for a BRDF with threads) ``standard_geometries``."""
        out = {"parameters": self.parameters}
        if self.standard_geometries is not None:
            out["standard_geometries"] = self.standard_geometries
        return out


def section_parameters(p: Page) -> Section:
    """Thread table, options and f_r at :data:`reports.standard.STANDARD_GEOMETRIES`."""
    params = parameters_of(p.fabric)
    link = p.json("parameters.json", params)
    if "model" in params:
        values = standard_values(p.fabric)
        rows = [[q.name, ", ".join(fmt(x) for x in v) if isinstance(v, (list, tuple))
                 else fmt(v), q.unit, q.description]
                for q, v in zip(_rows(p.fabric), params["values"].values())]
        return Section(html("<p>The baseline model <b>{}</b> (not the microcylinder).</p>{}"
                            "<p>Data: {}</p>", params["model"],
                            table(["parameter", "value", "unit", "meaning"], rows), link),
                       ParametersData(params, values))
    if not params["threads"]:
        return Section(html("<p>This BRDF exposes no threads.</p><p>Data: {}</p>", link),
                       ParametersData(params, None))
    rows = [[f"T{j + 1}"] + [fmt(t[f]) for f in THREAD_FIELDS]
            for j, t in enumerate(params["threads"])]
    opts = ", ".join(f"{k} = {fmt(v)}" for k, v in params["options"].items()) or "n/a"
    values = standard_values(p.fabric)
    std = table(["geometry", "θi, φi (deg)", "θo, φo (deg)", "f_r R", "f_r G", "f_r B (1/sr)"],
                [[g[0], f"{g[1]:g}, {g[2]:g}", f"{g[3]:g}, {g[4]:g}"]
                 + [f"{v:.5g}" for v in values[g[0]]] for g in STANDARD_GEOMETRIES])
    return Section(html("{}<p>Options: {}</p><h3>f_r at standard geometries</h3>{}"
                        "<p>Data: {}</p>", table(["thread", *THREAD_HEADER], rows), opts, std,
                        link),
                   ParametersData(params, values))
