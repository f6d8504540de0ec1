"""The page of a batch fit: ``DIR/index.html`` from ``DIR/summary.json`` and each fit's files.

One table row per fit (status, error, steps, wall time, the median and 95% interval of every
free parameter), and for each fit its verdict (adequacy and warnings) and its plots (corner, posterior predictive, ...) as linked
thumbnails; every link is relative, so the folder can be moved or served as it is. Every value
read from summary.json or a results.json reaches the page through :mod:`reports.safehtml`.
"""

from __future__ import annotations

from pathlib import Path

from analysis.batch.summary import SUMMARY_CSV, SUMMARY_JSON, BatchSummary
from analysis.fit.results import read_results
from gonio import atomic_write
from gonio.safenames import check_component, check_inside
from reports.report_measured import fit_verdict_html
from reports.safehtml import Markup, html, join, json_script, text, url

__all__ = ["write_batch_page", "PAGE", "CAPTIONS"]

PAGE = "index.html"

_CSS = Markup("""body{font-family:system-ui,sans-serif;margin:2em;max-width:1400px}
table{border-collapse:collapse;font-size:14px}td,th{border:1px solid #ccc;padding:3px 7px}
th{background:#f0f0f0}td.num{text-align:right;font-variant-numeric:tabular-nums}
.converged{color:#176}.not_converged{color:#a60}.error{color:#b00}
.plots{display:grid;grid-template-columns:repeat(auto-fill,minmax(260px,1fr));gap:10px}
.plots img{width:100%;border:1px solid #ddd}figure{margin:0}figcaption{font-size:13px}""")


#: Captions of the fit plots (reports.plots.fit_diagnostics) by name.
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


def _cell(row, name) -> Markup:
    if any(row.get(f"{name}_{k}") is None for k in ("median", "lo95", "hi95")):
        return Markup("<td></td>")
    m, lo, hi = (row[f"{name}_{k}"] for k in ("median", "lo95", "hi95"))
    return html('<td class="num">{:.4g} <small>[{:.4g}, {:.4g}]</small></td>', m, lo, hi)


def _table(rows, names) -> Markup:
    head = join(html("<th>{}</th>", n) for n in
                ["table", "status", "steps", "wall (s)"] + [f"{p} median [95%]" for p in names])
    body = []
    for r in rows:
        name, status = r["name"], r["status"]
        link = html('<a href="#{}">{}</a>', url(name), name) if status != "error" else text(name)
        error = html("<br><small>{}</small>", r["error"]) if r.get("error") else Markup("")
        body.append(html('<tr><td>{}</td><td class="{}">{}{}</td><td class="num">{}</td>'
                         '<td class="num">{:.0f}</td>{}</tr>', link, status, status, error,
                         r.get("steps", ""), r.get("wall_s") or 0,
                         join(_cell(r, p) for p in names)))
    return html("<table><tr>{}</tr>{}</table>", head, join(body))


def _fit_section(out: Path, row) -> Markup:
    """One fit: its verdict and its plots, linked. The row's folder and the plots of its
    results.json are safe names inside ``out`` (links resolved), else a ValueError."""
    source = out / SUMMARY_JSON
    folder = check_inside(out / row["folder"], out, source=source,
                          entry=f"the folder of {row['name']}")
    name = row["name"]
    try:
        doc = read_results(folder / "results.json")
    except ValueError as exc:
        return html('<h3 id="{}">{}</h3><p>{}</p>', name, name, exc)
    plots = doc.get("plots", {})
    if not isinstance(plots, dict):
        raise ValueError(f"{folder / 'results.json'}: plots must be an object; got "
                         f"{plots!r:.60}")
    figs = []
    for what, file in sorted(plots.items()):
        check_component(file, source=folder / "results.json", entry=f"plots.{what}")
        rel = f"{row['folder']}/{file}"
        if check_inside(out / rel, folder, source=folder / "results.json",
                        entry=f"plots.{what}").exists():
            figs.append(html('<figure><a href="{rel}"><img src="{rel}" alt="{what} of {name}" '
                             'loading="lazy"></a><figcaption>{caption}</figcaption></figure>',
                             rel=url(rel), what=what, name=name,
                             caption=CAPTIONS.get(what, what)))
    plots = (html('<div class="plots">{}</div>', join(figs)) if figs
             else Markup("<p>no plots</p>"))
    return html('<h3 id="{}">{}</h3><p>{} &middot; <a href="{}">results.json</a> &middot; '
                "<code>{}</code></p>{}{}", name, name, doc.get("reason", ""),
                url(f"{row['folder']}/results.json"), row.get("path", ""),
                fit_verdict_html(doc), plots)


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
    counts = ", ".join(f"{v} {str(k).replace('_', ' ')}"
                       for k, v in sorted(summary.counts().items(), key=lambda kv: str(kv[0])))
    sections = join(_fit_section(out, r) for r in rows if r["status"] != "error")
    doc = html("<!doctype html><html><head><meta charset='utf-8'><meta name='viewport' "
               "content='width=device-width, initial-scale=1'><title>microcyl batch: "
               "{name}</title><style>{css}</style></head><body>"
               "<h1>Batch fit: {name}</h1><p>{n} tables: {counts}. "
               "Data: <a href='{csv}'>{csv}</a>, <a href='{json}'>{json}</a>.</p>{table}"
               "<h2>Fits</h2>{sections}{data}</body></html>", name=out.name, css=_CSS,
               n=len(rows), counts=counts, csv=SUMMARY_CSV, json=SUMMARY_JSON,
               table=_table(rows, _params(rows)), sections=sections,
               data=json_script(summary.counts(), "summary"))
    with atomic_write(out / PAGE, "w") as f:
        f.write(str(doc))
    return out / PAGE
