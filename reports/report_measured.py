"""The report's page on fits to measured data (the output folder of ``microcyl fit-measured``).

One section per dataset: what was fitted (table, start preset, free parameters), the verdict
on convergence, the posterior table (median, 68% and 95% intervals, tau, R-hat, ESS), how well
the model explains the data (residual rms in the likelihood's space and in units of the noise,
CIEDE2000 between measured and predicted albedo colours) and the fit's figures: posterior-
predictive lobes over the data points, the residual map, the corner and the trace plots.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from analysis.fit.results import read_results
from reports.safehtml import Markup, html, join, table, url

__all__ = ["read_measured", "measured_page", "PLOTS"]

#: The figures of a fit, in page order, with captions.
PLOTS = {
    "lobes": "Posterior-predictive band (5-95%) and median of f_r cos(theta_o) in the plane of "
             "incidence, over the table's points in that plane.",
    "residuals": "Normalized residuals (data minus posterior-median model over the noise "
                 "scale) on the half-vector disk.",
    "corner": "Posterior marginals and pairs (corner).",
    "traces": "Traces of some walkers of every ensemble (after burn-in).",
}


def read_measured(folder) -> dict:
    """Read ``folder/measured.json`` and every ``results.json`` it names.

    Returns
    -------
    dict
        name -> entry of measured.json with ``results`` replaced by the results document and
        ``folder`` the dataset's folder.

    Raises
    ------
    ValueError
        The folder holds no readable ``measured.json`` (the message names it).
    """
    folder = Path(folder)
    path = folder / "measured.json"
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        datasets = doc["datasets"]
    except FileNotFoundError:
        raise ValueError(f"{path}: not found; run `microcyl fit-measured -o {folder}` first") \
            from None
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"{path}: unreadable ({exc})") from None
    out = {}
    for name, entry in datasets.items():
        e = dict(entry)
        rpath = folder / e.get("results", f"{name}/results.json")
        e["results"] = read_results(rpath)
        e["folder"] = rpath.parent
        out[name] = e
    return out


def _f(v, fmt=".4g") -> str:
    """A number as text (``-`` for None); anything else as its text, escaped where it is
    put on the page."""
    if v is None:
        return "-"
    try:
        return format(float(v), fmt)
    except (TypeError, ValueError):
        return str(v)


def overview_table(measured: dict) -> Markup:
    """One row per dataset: preset, size, verdict, residuals, colour difference."""
    rows = []
    for name, e in measured.items():
        q = e.get("quality", {})
        rows.append([name, e.get("preset", "-"), e.get("values_used", "-"),
                     "yes" if e.get("converged") else "NO", e.get("steps", "-"),
                     _f(q.get("rms_residual"), ".3f"), _f(q.get("rms_normalized"), ".2f"),
                     _f(e.get("albedo_delta_e2000"), ".1f")])
    return table(["dataset", "start preset", "values", "converged", "steps",
                  "residual rms", "normalized rms", "albedo ΔE2000"], rows)


def measured_page(root: Path, measured: dict, folder: str = "measured") -> tuple[Markup, dict]:
    """Write the figures of every fit under ``root/folder/NAME/`` and return the page body
    and its summary (JSON-ready).

    Parameters
    ----------
    root : path
        The report's (temporary) root folder.
    measured : dict
        From :func:`read_measured`.
    """
    body = [Markup(
        '<p>The model fitted to measured fabrics with <code>microcyl fit-measured</code> '
        '(each from its closest preset; the free parameters are shared by both threads). '
        'The residual rms is taken in the likelihood\'s space, log(1 + f_r cos θ<sub>i</sub>); '
        'the normalized rms is in units of the noise the fit found (near 1 when the model '
        'explains the data to within it). ΔE2000 compares the albedo colours of the data and '
        'of the posterior-median model over the same directions (for grey tables, the grey '
        'levels).</p>'), overview_table(measured)]
    summary = {}
    for name, e in measured.items():
        doc = e["results"]
        res = doc.get("parameters", {})
        params = list(res)
        rows = [[k, _f(res[k]["median"]), f"[{_f(res[k]['lo68'])}, {_f(res[k]['hi68'])}]",
                 f"[{_f(res[k]['lo95'])}, {_f(res[k]['hi95'])}]", res[k].get("unit", ""),
                 _f(res[k].get("tau"), ".1f"), _f(res[k].get("rhat"), ".4f"),
                 _f(res[k].get("ess"), ".0f")] for k in params]
        dest = root / folder / name
        dest.mkdir(parents=True, exist_ok=True)
        figs = []
        plots = doc.get("plots", {})
        for key, caption in PLOTS.items():
            src = plots.get(key)
            if src is None:
                continue
            src = Path(e["folder"]) / Path(src).name
            if not src.is_file():
                continue
            shutil.copyfile(src, dest / src.name)
            rel = f"{folder}/{name}/{src.name}"
            figs.append(html('<figure><img src="{}" alt="{}"><figcaption>{}</figcaption>'
                             "</figure>", url(rel), key, caption))
        for data in ("results.json", "results.csv"):
            if (Path(e["folder"]) / data).is_file():
                shutil.copyfile(Path(e["folder"]) / data, dest / data)
        verdict = "converged" if e.get("converged") else "NOT converged"
        q = e.get("quality", {})
        body.append(_section(folder, name, e, verdict, rows, figs))
        summary[name] = {"converged": bool(e.get("converged")), "reason": e.get("reason"),
                         "quality": q, "albedo_delta_e2000": e.get("albedo_delta_e2000"),
                         "parameters": {k: {f: res[k].get(f) for f in
                                            ("median", "lo68", "hi68", "lo95", "hi95", "tau",
                                             "rhat", "ess")} for k in params},
                         "figures": len(figs)}
    return join(body), summary


def _section(folder: str, name: str, e: dict, verdict: str, rows, figs) -> Markup:
    """One dataset's ``<section>``: what was fitted, the verdict, the fit's quality, its
    posterior table and figures; every value from measured.json through the template."""
    q = e.get("quality", {})
    ties = e.get("ties", [])
    return html(
        '<section id="{name}" class="measured"><h2>{name}: {title}</h2>'
        "<p>Table: {source}; {pairs} pairs, {values} values used. Start preset "
        "<b>{preset}</b>; ties: {ties}.</p><p><b>{verdict}</b>: {reason}</p>"
        "<p>Residual rms {rms} (normalized {rms_n}); albedo ΔE2000 {de}. Data: "
        '<a href="{data}/results.json">results.json</a>, '
        '<a href="{data}/results.csv">results.csv</a>.</p>{table}{figs}</section>',
        name=name, title=e.get("title", ""), source=e.get("source", ""),
        pairs=e.get("pairs", "-"), values=e.get("values_used", "-"),
        preset=e.get("preset", ""),
        ties=", ".join(map(str, ties)) if isinstance(ties, (list, tuple)) else ties,
        verdict=verdict, reason=e.get("reason", ""), rms=_f(q.get("rms_residual"), ".4f"),
        rms_n=_f(q.get("rms_normalized"), ".2f"), de=_f(e.get("albedo_delta_e2000"), ".2f"),
        data=url(f"{folder}/{name}"),
        table=table(["parameter", "median", "68%", "95%", "unit", "τ", "R-hat", "ESS"], rows),
        figs=join(figs))
