"""The report's page on fits to measured data (the output folder of ``microcyl fit-measured``).

One section per dataset: what was fitted (table, start preset, free parameters), the verdict
on convergence, the posterior table (median, 68% and 95% intervals, tau, R-hat, ESS), how well
the model explains the data (residual rms in the likelihood's space and in units of the noise,
CIEDE2000 between measured and predicted albedo colours, the PSIS-LOO elpd and the LOO-PIT
uniformity test) and the fit's figures: posterior-predictive lobes over the data points, the
residual map, the LOO-PIT histogram, the corner and the trace plots. Where several models
were fitted (``fit-measured --models``), a table per dataset ranks them (:func:`models_table`:
elpd, the difference to the best with its standard error, residual rms, adequacy) under one
sentence of verdict drawn from those numbers (:func:`models_verdict`).
"""

from __future__ import annotations

import os
from pathlib import Path

from analysis.fit.results import read_results
from analysis.measuredjson import has_microcylinder, load_measured_json, results_path
from gonio import atomic_write
from gonio.safenames import check_component, check_inside
from analysis.fit.loo import HIGH_K
from reports.fitwords import SEPARATION_SE, gap_sentence
from gonio.safeopen import MAX_FIGURE_BYTES, MAX_STATE_BYTES, copy_capped
from reports.safehtml import Markup, html, join, table, url

__all__ = ["read_measured", "measured_page", "PLOTS", "models_table", "models_verdict",
           "fit_verdict_html", "SEPARATION_SE"]

#: The figures of a fit, in page order, with captions.
PLOTS = {
    "lobes": "Posterior-predictive band (5-95%) and median of f_r cos(theta_o) in the plane of "
             "incidence, over the table's points in that plane.",
    "residuals": "Normalized residuals (data minus posterior-median model over the noise "
                 "scale) on the half-vector disk.",
    "adequacy": "Standardized residuals per point against angle (N(0, 1) where the model "
                "fits; forward and back scatter in two colours), the adequacy verdict and the "
                "warnings.",
    "pit": "LOO-PIT: each value's leave-one-out predictive CDF at the measured value (uniform "
           "when the predictive distributions are right; grey: 99% band of a bin under "
           "uniformity).",
    "corner": "Posterior marginals and pairs (corner).",
    "traces": "Traces of some walkers of every ensemble (after burn-in).",
}


def read_measured(folder) -> dict:
    """Read ``folder/measured.json`` and every ``results.json`` it names.

    measured.json is read through its schema (:mod:`analysis.measuredjson`): every dataset
    name a safe file name, every ``results`` path inside ``folder`` (links resolved), and the
    ``plots`` of each results.json safe file names of files inside ``folder``.

    Returns
    -------
    dict
        name -> entry of measured.json with ``results`` replaced by the results document,
        ``folder`` the dataset's folder (resolved), ``plot_files`` the checked
        ``{plot: path}`` of its results and ``data_files`` its results.json and results.csv.

    Raises
    ------
    ValueError
        The folder holds no readable ``measured.json``, or a field of it or of a
        results.json is out of its schema (the message names the file and the field).
    """
    folder = Path(folder)
    doc = load_measured_json(folder)
    source = folder / "measured.json"
    out = {}
    for name, entry in doc["datasets"].items():
        e = dict(entry)
        if not has_microcylinder(e):        # baseline models only: their numbers alone
            out[name] = dict(e, results=None, folder=None, plot_files={}, data_files=[])
            continue
        rpath = results_path(folder, name, e, source)
        e["results"] = read_results(rpath)
        e["folder"] = rpath.parent
        e["plot_files"] = _plot_files(e["results"], rpath)
        e["data_files"] = [check_inside(rpath.parent / f, rpath.parent, source=source,
                                        entry=f"datasets.{name}")
                           for f in ("results.json", "results.csv")
                           if os.path.lexists(rpath.parent / f)]
        out[name] = e
    return out


def _plot_files(doc: dict, rpath: Path) -> dict:
    """The ``plots`` of a results document: each a safe file name of a file beside it (links
    resolved)."""
    plots = doc.get("plots", {})
    if not isinstance(plots, dict):
        raise ValueError(f"{rpath}: plots must be an object; got {plots!r:.60}")
    out = {}
    for key, file in plots.items():
        check_component(file, source=rpath, entry=f"plots.{key}")
        check_inside(rpath.parent / file, rpath.parent, source=rpath, entry=f"plots.{key}")
        out[key] = rpath.parent / file
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


def _interval(p: dict, level: str) -> str:
    """``[lo, hi]`` of a parameter's interval at ``level`` ("68" or "95"); "-" where absent."""
    return f"[{_f(p.get('lo' + level))}, {_f(p.get('hi' + level))}]"


def _elpd(loo) -> str:
    """``elpd ± se`` of a ``loo`` entry of results.json, "-" without one."""
    if not isinstance(loo, dict) or loo.get("elpd") is None:
        return "-"
    return f"{_f(loo.get('elpd'), '.1f')} ± {_f(loo.get('se'), '.1f')}"


def overview_table(measured: dict) -> Markup:
    """One row per dataset: preset, size, verdicts, warnings, residuals, colour difference,
    elpd."""
    rows = []
    for name, e in measured.items():
        if e.get("results") is None:
            continue
        q = e.get("quality", {})
        doc = e.get("results") or {}
        kinds = sorted({str(w.get("kind")) for w in doc.get("warnings") or []
                        if isinstance(w, dict)})
        rows.append([name, e.get("preset", "-"), e.get("values_used", "-"),
                     "yes" if e.get("converged") else "NO", e.get("steps", "-"),
                     {True: "yes", False: "NO"}.get(doc.get("adequate"), "-"),
                     ", ".join(kinds) or "-",
                     _f(q.get("rms_residual"), ".3f"), _f(q.get("rms_normalized"), ".2f"),
                     _f(e.get("albedo_delta_e2000"), ".1f"), _elpd(e.get("loo"))])
    return table(["dataset", "start preset", "values", "converged", "steps", "adequate",
                  "warnings", "residual rms", "normalized rms", "albedo ΔE2000",
                  "elpd (PSIS-LOO)"], rows)


def _loo_sentence(doc: dict) -> str:
    """The PSIS-LOO and LOO-PIT of one fit in a sentence (plain text), or nothing."""
    loo = doc.get("loo")
    if not isinstance(loo, dict):
        return ""
    text = (f"PSIS-LOO elpd {_elpd(loo)} (p_loo {_f(loo.get('p_loo'), '.1f')}; Pareto k "
            f"max {_f(loo.get('pareto_k_max'), '.2f')}, {_f(loo.get('n_high_k'), '.0f')} "
            f"values above {_f(loo.get('k_threshold', HIGH_K), '.2f')}).")
    pit = (doc.get("quality") or {}).get("loo_pit")
    if isinstance(pit, dict):
        text += f" LOO-PIT uniformity: Kolmogorov-Smirnov p = {_f(pit.get('ks_pvalue'), '.2g')}."
    return text


def fit_verdict_html(doc: dict) -> Markup:
    """A fit's adequacy verdict and its warnings (from its results document), escaped: the
    measured page's and the batch page's."""
    head = {True: "adequate", False: "NOT adequate"}.get(doc.get("adequate"), "adequacy unknown")
    items = join(html("<li>{}: {}</li>", w.get("kind"), w.get("message"))
                 for w in doc.get("warnings") or [] if isinstance(w, dict))
    return (html("<p><b>{}</b>: {}</p>", head, doc.get("adequate_reason", "not checked"))
            + (html("<ul>{}</ul>", items) if items else Markup("<p>No warnings.</p>")))


def measured_page(root: Path, measured: dict, folder: str = "measured") -> tuple[Markup, dict]:
    """Write the figures of every fit under ``root/folder/NAME/`` and return the page body
    and its summary (JSON-ready).

    Parameters
    ----------
    root : path
        The report's (temporary) root folder.
    measured : dict
        From :func:`read_measured`.

    Raises
    ------
    ValueError
        A figure or data file that is now a link, not a regular file, or larger than it may
        be (:data:`gonio.safeopen.MAX_FIGURE_BYTES`): each is copied from one descriptor
        (:func:`gonio.safeopen.copy_capped`), never by name after an earlier check.
    """
    body = [Markup(
        '<p>The model fitted to measured fabrics with <code>microcyl fit-measured</code> '
        '(each from its closest preset; the free parameters are shared by both threads). '
        'The residual rms is taken in the likelihood\'s space, log(1 + f_r cos θ<sub>i</sub>); '
        'the normalized rms is in units of the noise the fit found (near 1 when the model '
        'explains the data to within it). ΔE2000 compares the albedo colours of the data and '
        'of the posterior-median model over the same directions (none for grey tables: '
        'they hold no colour). <i>Adequate</i> says whether the model describes the data '
        'to within its noise (posterior predictive tests of the residuals); the warnings '
        'say which answers the data do not support (parameters at a bound, not informed, '
        'correlated). The elpd is the expected log predictive density of the table\'s values '
        'had the fit not seen each (PSIS-LOO; higher is better): it compares fits of one '
        'table, not datasets, and <code>microcyl compare</code> ranks such fits.</p>'),
        overview_table(measured)]
    summary = {}
    for name, e in measured.items():
        if e.get("results") is None:
            body.append(html('<section id="{}" class="measured"><h2>{}: {}</h2>{}</section>',
                             name, name, e.get("title", ""), _models_part(e)))
            summary[name] = {"models": e.get("models", {})}
            continue
        doc = e["results"]
        res = doc.get("parameters", {})
        params = list(res)
        rows = [[k, _f(res[k].get("median")), _interval(res[k], "68"), _interval(res[k], "95"),
                 res[k].get("unit", ""), _f(res[k].get("tau"), ".1f"),
                 _f(res[k].get("rhat"), ".4f"), _f(res[k].get("ess"), ".0f")] for k in params]
        dest = check_inside(root / folder / name, root)     # name: a safe component
        dest.mkdir(parents=True, exist_ok=True)
        figs = []
        for key, caption in PLOTS.items():
            src = e["plot_files"].get(key)
            if src is None or not os.path.lexists(src):     # a link or FIFO: _copy names it
                continue
            _copy(src, check_inside(dest / src.name, root), MAX_FIGURE_BYTES, "a fit's figure")
            rel = f"{folder}/{name}/{src.name}"
            figs.append(html('<figure><img src="{}" alt="{}"><figcaption>{}</figcaption>'
                             "</figure>", url(rel), key, caption))
        for src in e["data_files"]:
            _copy(src, check_inside(dest / src.name, root), MAX_STATE_BYTES, "a fit's results")
        verdict = "converged" if e.get("converged") else "NOT converged"
        q = e.get("quality", {})
        body.append(_section(folder, name, e, verdict, rows, figs,
                             fit_verdict_html(doc) + _models_part(e)))
        summary[name] = {"converged": bool(e.get("converged")), "reason": e.get("reason"),
                         "adequate": doc.get("adequate"), "warnings": doc.get("warnings", []),
                         "quality": q, "albedo_delta_e2000": e.get("albedo_delta_e2000"),
                         "loo": doc.get("loo"),
                         "parameters": {k: {f: res[k].get(f) for f in
                                            ("median", "lo68", "hi68", "lo95", "hi95", "tau",
                                             "rhat", "ess")} for k in params},
                         "figures": len(figs)}
        if "models" in e:
            summary[name]["models"] = e["models"]
    return join(body), summary


def _copy(src: Path, dest: Path, max_bytes: int, what: str) -> None:
    """Copy ``src`` to ``dest`` from one descriptor (:func:`gonio.safeopen.copy_capped`):
    a link, a FIFO or a file larger than ``max_bytes`` (a sparse one included) is refused by
    name, whatever it was when the report started, and nothing is left at ``dest``."""
    with atomic_write(dest, "wb") as fh:
        copy_capped(src, fh, max_bytes=max_bytes, what=what)


def _ranked(models: dict) -> list[tuple[str, dict]]:
    """The models by rank (unranked ones last, by name)."""
    return sorted(((m, e) for m, e in models.items() if isinstance(e, dict)),
                  key=lambda me: (me[1].get("rank") is None, me[1].get("rank") or 0, me[0]))


def _names(items) -> str:
    names = [m for m, _ in items]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def models_verdict(models: dict, compare_error: str | None = None) -> str:
    """Sentences from the ranking of a dataset's models (plain text): the gap from the best
    to each other model in the words of ``microcyl compare``
    (:func:`reports.fitwords.gap_sentence`: within :data:`SEPARATION_SE` se the data cannot
    separate them; a close call says why), and which fits did not converge.

    Examples
    --------
    >>> models_verdict({"charlie": {"rank": 1, "d_elpd": 0.0, "d_se": 0.0},
    ...                 "lambert": {"rank": 2, "d_elpd": 12.0, "d_se": 3.0}})
    'charlie is preferred over lambert by 12.0 ± 3.0 (4.0 se).'
    >>> print(models_verdict({"a": {"rank": 1, "d_elpd": 0.0, "d_se": 0.0},
    ...                       "b": {"rank": 2, "d_elpd": 1.0, "d_se": 2.0, "converged": False}}))
    The data cannot separate a and b (difference 1.0 ± 2.0, within 2 se). (b did not converge: its elpd may still change.)
    """
    ranked = [(m, e) for m, e in _ranked(models) if e.get("rank") is not None]
    if compare_error:
        return f"The models were not ranked: {compare_error}"
    if len(ranked) < 2:
        return "Fewer than two models have a PSIS-LOO: nothing to rank."
    best = ranked[0][0]
    text = " ".join(gap_sentence(best, m, e.get("d_elpd"), e.get("d_se"),
                                 block_se=e.get("d_se_block"), lag1=e.get("d_lag1")) + "."
                    for m, e in ranked[1:])
    stuck = [(m, e) for m, e in ranked if e.get("converged") is False]
    if stuck:
        text += (f" ({_names(stuck)} did not converge: {'its' if len(stuck) == 1 else 'their'}"
                 f" elpd may still change.)")
    return text


def _pareto(e: dict) -> str:
    """``k max (n above threshold)`` of a model's entry, "-" without one."""
    if e.get("pareto_k_max") is None:
        return "-"
    return (f"{_f(e['pareto_k_max'], '.2f')} ({_f(e.get('n_high_k'), '.0f')} > "
            f"{_f(e.get('k_threshold', HIGH_K), '.2f')})")


def models_table(models: dict) -> Markup:
    """The models of one dataset, best first: elpd ± se, the difference to the best ± its
    se (and in se), residual rms (likelihood space, normalized), Pareto k, adequate, the
    kinds of its warnings, converged."""
    rows = []
    for m, e in _ranked(models):
        d, se = e.get("d_elpd"), e.get("d_se")
        diff = "-" if d is None else (f"{_f(d, '.1f')} ± {_f(se, '.1f')}"
                                      + (f" ({float(d) / float(se):.1f} se)" if se else ""))
        if e.get("rank") == 1:
            diff = "best"
        kinds = sorted({str(w.get("kind")) for w in e.get("warnings") or []
                        if isinstance(w, dict)})
        rows.append([_f(e.get("rank"), ".0f"), m, _elpd(e), diff,
                     _f(e.get("rms_residual"), ".4f"), _f(e.get("rms_normalized"), ".2f"),
                     _pareto(e), {True: "yes", False: "NO"}.get(e.get("adequate"), "-"),
                     ", ".join(kinds) or ("-" if "warnings" not in e else "none"),
                     "yes" if e.get("converged") else "NO", e.get("error") or ""])
    return table(["rank", "model", "elpd (PSIS-LOO)", "best − this", "residual rms",
                  "normalized rms", "Pareto k max (values above)", "adequate", "warnings",
                  "converged", "error"], rows)


def _models_part(e: dict) -> Markup:
    """A dataset's models: the verdict, the table and each model's identifiability notes."""
    models = e.get("models")
    if not isinstance(models, dict) or not models:
        return Markup("")
    notes = join(html("<li>{}: {}</li>", m, n) for m, me in _ranked(models)
                 for n in me.get("identifiability") or [])
    return (html("<h3>Models</h3><p><b>{}</b></p>",
                 models_verdict(models, e.get("compare_error")))
            + models_table(models)
            + (html("<p>Identifiability choices:</p><ul>{}</ul>", notes) if notes else
               Markup("")))


def _section(folder: str, name: str, e: dict, verdict: str, rows, figs, trust) -> Markup:
    """One dataset's ``<section>``: what was fitted, the verdicts (``trust``: adequacy and
    warnings), the fit's quality, its posterior table and figures; every value from
    measured.json through the template."""
    q = e.get("quality", {})
    ties = e.get("ties", [])
    return html(
        '<section id="{name}" class="measured"><h2>{name}: {title}</h2>'
        "<p>Table: {source}; {pairs} pairs, {values} values used. Start preset "
        "<b>{preset}</b>; ties: {ties}.</p><p><b>{verdict}</b>: {reason}</p>{trust}"
        "<p>Residual rms {rms} (normalized {rms_n}); albedo ΔE2000 {de}. {loo} Data: "
        '<a href="{data}/results.json">results.json</a>, '
        '<a href="{data}/results.csv">results.csv</a>.</p>{table}{figs}</section>',
        name=name, title=e.get("title", ""), source=e.get("source", ""),
        pairs=e.get("pairs", "-"), values=e.get("values_used", "-"),
        preset=e.get("preset", ""),
        ties=", ".join(map(str, ties)) if isinstance(ties, (list, tuple)) else ties,
        verdict=verdict, reason=e.get("reason", ""), trust=trust, rms=_f(q.get("rms_residual"), ".4f"),
        rms_n=_f(q.get("rms_normalized"), ".2f"), de=_f(e.get("albedo_delta_e2000"), ".2f"),
        loo=_loo_sentence(e.get("results") or {}),
        data=url(f"{folder}/{name}"),
        table=table(["parameter", "median", "68%", "95%", "unit", "τ", "R-hat", "ESS"], rows),
        figs=join(figs))
