"""The report's page on fits to measured data (the output folder of ``microcyl fit-measured``).

One section per dataset: what was fitted (table, start preset, free parameters), the verdict
on convergence, the posterior table (median, 68% and 95% intervals, tau, R-hat, ESS), how well
the model explains the data (residual rms in the likelihood's space and in units of the noise,
CIEDE2000 between measured and predicted albedo colours) and the fit's figures: posterior-
predictive lobes over the data points, the residual map, the corner and the trace plots.
"""

from __future__ import annotations

import html
import json
import shutil
from pathlib import Path

from analysis.fit.results import read_results

__all__ = ["read_measured", "measured_page", "PLOTS"]

#: The figures of a fit, in page order, with captions.
PLOTS = {
    "lobes": "Posterior-predictive band (5-95%) and median of f_r cos(theta_o) in the plane of "
             "incidence, over the table's points in that plane.",
    "residuals": "Normalized residuals (data minus posterior-median model over the noise "
                 "scale) on the half-vector disk.",
    "adequacy": "Standardized residuals per point against angle (N(0, 1) where the model "
                "fits; forward and back scatter in two colours), the adequacy verdict and the "
                "warnings.",
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
    if v is None:
        return "-"
    try:
        return format(float(v), fmt)
    except (TypeError, ValueError):
        return str(v)


def _table(header, rows) -> str:
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def overview_table(measured: dict) -> str:
    """One row per dataset: preset, size, verdicts, warnings, residuals, colour difference."""
    rows = []
    for name, e in measured.items():
        q = e.get("quality", {})
        doc = e.get("results") or {}
        kinds = sorted({str(w.get("kind")) for w in doc.get("warnings") or []
                        if isinstance(w, dict)})
        rows.append([name, e.get("preset", "-"), e.get("values_used", "-"),
                     "yes" if e.get("converged") else "NO", e.get("steps", "-"),
                     {True: "yes", False: "NO"}.get(doc.get("adequate"), "-"),
                     ", ".join(kinds) or "-",
                     _f(q.get("rms_residual"), ".3f"), _f(q.get("rms_normalized"), ".2f"),
                     _f(e.get("albedo_delta_e2000"), ".1f")])
    return _table(["dataset", "start preset", "values", "converged", "steps", "adequate",
                   "warnings", "residual rms", "normalized rms", "albedo ΔE2000"], rows)


def _trust(doc: dict) -> str:
    """A fit's adequacy verdict and its warnings, escaped."""
    head = {True: "adequate", False: "NOT adequate"}.get(doc.get("adequate"), "adequacy unknown")
    items = "".join(f"<li>{html.escape(str(w.get('kind')))}: "
                    f"{html.escape(str(w.get('message')))}</li>"
                    for w in doc.get("warnings") or [] if isinstance(w, dict))
    return (f"<p><b>{head}</b>: {html.escape(str(doc.get('adequate_reason', 'not checked')))}"
            f"</p>" + (f"<ul>{items}</ul>" if items else "<p>No warnings.</p>"))


def measured_page(root: Path, measured: dict, folder: str = "measured") -> tuple[str, dict]:
    """Write the figures of every fit under ``root/folder/NAME/`` and return the page body
    and its summary (JSON-ready).

    Parameters
    ----------
    root : path
        The report's (temporary) root folder.
    measured : dict
        From :func:`read_measured`.
    """
    body = ['<p>The model fitted to measured fabrics with <code>microcyl fit-measured</code> '
            '(each from its closest preset; the free parameters are shared by both threads). '
            'The residual rms is taken in the likelihood\'s space, log(1 + f_r cos θ<sub>i</sub>); '
            'the normalized rms is in units of the noise the fit found (near 1 when the model '
            'explains the data to within it). ΔE2000 compares the albedo colours of the data and '
            'of the posterior-median model over the same directions (none for grey tables: '
            'they hold no colour). <i>Adequate</i> says whether the model describes the data '
            'to within its noise (posterior predictive tests of the residuals); the warnings '
            'say which answers the data do not support (parameters at a bound, not informed, '
            'correlated).</p>', overview_table(measured)]
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
            figs.append(f'<figure><img src="{html.escape(rel)}" alt="{html.escape(key)}">'
                        f"<figcaption>{html.escape(caption)}</figcaption></figure>")
        for data in ("results.json", "results.csv"):
            if (Path(e["folder"]) / data).is_file():
                shutil.copyfile(Path(e["folder"]) / data, dest / data)
        verdict = "converged" if e.get("converged") else "NOT converged"
        q = e.get("quality", {})
        body.append(
            f'<section id="{html.escape(name)}" class="measured"><h2>{html.escape(name)}: '
            f"{html.escape(e.get('title', ''))}</h2>"
            f"<p>Table: {html.escape(str(e.get('source', '')))}; {e.get('pairs', '-')} pairs, "
            f"{e.get('values_used', '-')} values used. Start preset "
            f"<b>{html.escape(str(e.get('preset', '')))}</b>; ties: "
            f"{html.escape(', '.join(e.get('ties', [])))}.</p>"
            f"<p><b>{verdict}</b>: {html.escape(str(e.get('reason', '')))}</p>"
            + _trust(doc) +
            f"<p>Residual rms {_f(q.get('rms_residual'), '.4f')} (normalized "
            f"{_f(q.get('rms_normalized'), '.2f')}); albedo ΔE2000 "
            f"{_f(e.get('albedo_delta_e2000'), '.2f')}. Data: "
            f'<a href="{folder}/{html.escape(name)}/results.json">results.json</a>, '
            f'<a href="{folder}/{html.escape(name)}/results.csv">results.csv</a>.</p>'
            + _table(["parameter", "median", "68%", "95%", "unit", "τ", "R-hat", "ESS"], rows)
            + "".join(figs) + "</section>")
        summary[name] = {"converged": bool(e.get("converged")), "reason": e.get("reason"),
                         "adequate": doc.get("adequate"), "warnings": doc.get("warnings", []),
                         "quality": q, "albedo_delta_e2000": e.get("albedo_delta_e2000"),
                         "parameters": {k: {f: res[k].get(f) for f in
                                            ("median", "lo68", "hi68", "lo95", "hi95", "tau",
                                             "rhat", "ess")} for k in params},
                         "figures": len(figs)}
    return "".join(body), summary
