"""The page of a batch fit: ``DIR/index.html`` from ``DIR/summary.json`` and each fit's files.

One table row per fit (status, error, steps, wall time, the median and 95% interval of every
free parameter), and for each fit its plots (corner, posterior predictive, ...) as linked
thumbnails; every link is relative, so the folder can be moved or served as it is.
"""

from __future__ import annotations

import html
import json
from pathlib import Path

from analysis.batch.summary import SUMMARY_CSV, SUMMARY_JSON, BatchSummary
from analysis.fit.results import read_results
from gonio import atomic_write

__all__ = ["write_batch_page", "PAGE", "CAPTIONS"]

PAGE = "index.html"

_CSS = """body{font-family:system-ui,sans-serif;margin:2em;max-width:1400px}
table{border-collapse:collapse;font-size:14px}td,th{border:1px solid #ccc;padding:3px 7px}
th{background:#f0f0f0}td.num{text-align:right;font-variant-numeric:tabular-nums}
.converged{color:#176}.not_converged{color:#a60}.error{color:#b00}
.plots{display:grid;grid-template-columns:repeat(auto-fill,minmax(260px,1fr));gap:10px}
.plots img{width:100%;border:1px solid #ddd}figure{margin:0}figcaption{font-size:13px}"""


#: Captions of the fit plots (reports.fitplots) by name.
CAPTIONS = {"corner": "posterior (corner plot)",
            "lobes": "posterior predictive: 5-95% band of f_r cos(theta_o) over the data",
            "residuals": "residuals at the posterior median", "traces": "chains (traces)",
            "pit": "LOO-PIT histogram (uniform when the predictive distributions are right)"}


def _params(rows) -> list[str]:
    """Free-parameter names over all rows, in order of appearance."""
    out = []
    for r in rows:
        out += [k[:-7] for k in r if k.endswith("_median") and k[:-7] not in out]
    return out


def _cell(row, name) -> str:
    if f"{name}_median" not in row or row[f"{name}_median"] is None:
        return "<td></td>"
    m, lo, hi = (row[f"{name}_{k}"] for k in ("median", "lo95", "hi95"))
    return f'<td class="num">{m:.4g} <small>[{lo:.4g}, {hi:.4g}]</small></td>'


def _table(rows, names) -> str:
    head = "".join(f"<th>{html.escape(n)}</th>" for n in
                   ["table", "status", "steps", "wall (s)"] + [f"{p} median [95%]"
                                                                for p in names])
    body = []
    for r in rows:
        name = html.escape(r["name"])
        link = (f'<a href="#{name}">{name}</a>' if r["status"] != "error" else name)
        status = html.escape(r["status"]) + (f"<br><small>{html.escape(r['error'])}</small>"
                                             if r.get("error") else "")
        body.append(f'<tr><td>{link}</td><td class="{html.escape(r["status"])}">{status}</td>'
                    f'<td class="num">{r.get("steps", "")}</td><td class="num">'
                    f'{float(r.get("wall_s") or 0):.0f}</td>'
                    + "".join(_cell(r, p) for p in names) + "</tr>")
    return f"<table><tr>{head}</tr>{''.join(body)}</table>"


def _fit_section(out: Path, row) -> str:
    """One fit: its verdict and its plots, linked."""
    folder = out / row["folder"]
    name = html.escape(row["name"])
    try:
        doc = read_results(folder / "results.json")
    except ValueError as exc:
        return f'<h3 id="{name}">{name}</h3><p>{html.escape(str(exc))}</p>'
    figs = []
    for what, file in sorted(doc.get("plots", {}).items()):
        rel = f"{row['folder']}/{file}"
        if (out / rel).exists():
            figs.append(f'<figure><a href="{html.escape(rel)}"><img src="{html.escape(rel)}" '
                        f'alt="{html.escape(what)} of {name}" loading="lazy"></a>'
                        f"<figcaption>{html.escape(CAPTIONS.get(what, what))}</figcaption></figure>")
    plots = f'<div class="plots">{"".join(figs)}</div>' if figs else "<p>no plots</p>"
    return (f'<h3 id="{name}">{name}</h3><p>{html.escape(doc.get("reason", ""))} &middot; '
            f'<a href="{html.escape(row["folder"])}/results.json">results.json</a> &middot; '
            f'<code>{html.escape(str(row.get("path", "")))}</code></p>{plots}')


def write_batch_page(out_dir) -> Path:
    """Write ``out_dir/index.html`` for the batch in ``out_dir``; returns its path.

    Raises
    ------
    ValueError
        ``out_dir`` holds no batch summary (naming the folder).
    """
    out = Path(out_dir)
    if not (out / SUMMARY_JSON).exists():
        raise ValueError(f"{out}: not a batch folder (no {SUMMARY_JSON}; run microcyl "
                         f"fit-batch -o {out} first)")
    summary = BatchSummary(out)
    rows = summary.ordered()
    counts = ", ".join(f"{v} {k.replace('_', ' ')}" for k, v in sorted(summary.counts().items()))
    sections = "".join(_fit_section(out, r) for r in rows if r["status"] != "error")
    doc = (f"<!doctype html><html><head><meta charset='utf-8'><meta name='viewport' "
           f"content='width=device-width, initial-scale=1'><title>microcyl batch: "
           f"{html.escape(out.name)}</title><style>{_CSS}</style></head><body>"
           f"<h1>Batch fit: {html.escape(out.name)}</h1><p>{len(rows)} tables: {counts}. "
           f"Data: <a href='{SUMMARY_CSV}'>{SUMMARY_CSV}</a>, <a href='{SUMMARY_JSON}'>"
           f"{SUMMARY_JSON}</a>.</p>{_table(rows, _params(rows))}<h2>Fits</h2>{sections}"
           f"<script type='application/json' id='summary'>"
           f"{html.escape(json.dumps(summary.counts()))}</script></body></html>")
    with atomic_write(out / PAGE, "w") as f:
        f.write(doc)
    return out / PAGE
