"""What a fit produced (:class:`FitResult`) and its files: ``results.json`` and ``results.csv``.

``results.json`` (schema ``microcyl-fit``, version :data:`SCHEMA_VERSION`)::

    {"schema": "microcyl-fit", "schema_version": 2, "model": "microcylinder",
     "identifiability": ["grey table: base_g and base_b tied to base_r ...", ...],
     "converged": true, "reason": "converged at step 350: ...",
     "adequate": false, "adequate_reason": "residuals differ between ...",
     "warnings": [{"kind": "at_bound", "parameters": ["eta1"], "message": "..."}, ...],
     "parameters": {"kd1": {"median": ..., "lo68": ..., "hi68": ..., "lo95": ..., "hi95": ...,
                            "tau": ..., "n_over_tau": ..., "rhat": ..., "ess": ...,
                            "unit": "1"}, ...},
     "fit": {"steps", "burn", "walkers", "ensembles", "acceptance_fraction", "map",
             "map_log_posterior", "points", "ties", "timing", "proposal"},
     "quality": {"rms_residual", "rms_normalized", "values", and with the table:
                 "albedo_measured", "albedo_predicted", "albedo_delta_e2000" (null for a
                 grey table, "albedo_delta_e2000_reason" says why), "adequacy": the tests},
     "plots": {"corner": "corner.png", ...},
     "loo": {"elpd", "se", "p_loo", "pareto_k_max", "n_high_k"} (or null)}

``loo`` is the PSIS-LOO of the fit (:mod:`analysis.fit.loo`; its pointwise values in
``loo.npz``), ``quality["loo_pit"]`` the uniformity test of its LOO-PIT.

``model`` names the model fitted (:func:`analysis.families.model_names`; a file written
before models were named reads as ``microcylinder``), ``identifiability`` the choices its
default free set made for this table (:meth:`analysis.families.ModelFamily.default_free`;
empty when none). ``converged`` is the sampler's verdict; ``adequate`` (true, false or null) whether the model
describes the data (:mod:`analysis.fit.adequacy`); ``warnings`` what the answer cannot be
trusted for (:mod:`analysis.fit.trust`). Intervals are central (68%: 15.9-84.1 percentiles),
in each parameter's natural unit.
"""

from __future__ import annotations

import dataclasses
import html
import json
from pathlib import Path

import numpy as np

from analysis import diagnostics
from analysis.fit.circular import circular_natural
from analysis.params import INTERNAL_LIMIT
from analysis.fit.quality import residuals
from gonio import atomic_write
from gonio.csvcells import comment_text, text_cell
from gonio.jsonplain import plain
from gonio.statefields import FileFields, load_json

__all__ = ["FitResult", "write_results", "read_results", "summarize", "check_results",
           "SCHEMA_VERSION", "SUMMARY_COLUMNS"]

#: Version of the ``results.json`` layout.
SCHEMA_VERSION = 2
#: Columns of each parameter's summary (and of ``results.csv``).
SUMMARY_COLUMNS = ("median", "lo68", "hi68", "lo95", "hi95", "tau", "n_over_tau", "rhat",
                   "ess", "unit")
#: The columns that are always finite (the others may be NaN or infinite: a chain too short
#: for its autocorrelation time).
FINITE_COLUMNS = ("median", "lo68", "hi68", "lo95", "hi95")


@dataclasses.dataclass
class FitResult:
    """Everything a fit produced.

    Attributes
    ----------
    names, units : tuple of str
        Free parameters, in order, and their units.
    chains : ndarray (ensembles, steps, walkers, ndim)
        Post-burn-in samples in natural units.
    chains_internal : ndarray
        The same in the sampler's internal coordinates.
    log_prob : ndarray (ensembles, steps, walkers)
    summary : dict name -> dict
        :data:`SUMMARY_COLUMNS` per parameter.
    converged : bool
    reason : str
        Why sampling stopped (criterion met, step limit, time limit).
    steps, burn : int
        Steps per ensemble, and those discarded.
    best : dict
        Point estimate (natural units); ``best_logp`` its log-posterior.
    counts : dict
        Values used and masked (:attr:`analysis.likelihood.Likelihood.counts`).
    timing : dict
        Seconds and evaluation counts.
    proposal : dict
        The independence proposal's initial share and every refit decision.
    quality : dict
        Residuals at the posterior median and, when the workflow had the table, the albedo
        colours and their CIEDE2000 difference (:mod:`analysis.fit.quality`).
    plots : dict
        Plot names -> file names, when plots were written.
    loo : analysis.fit.loo.Loo or None
        The PSIS-LOO, when the workflow computed it.
    adequacy : dict
        Whether the model describes the data (:func:`analysis.fit.adequacy.adequacy`):
        ``adequate`` (bool or None), ``reason``, the tests.
    warnings : list of dict
        ``{"kind", "parameters", "message"}`` each: what the fit cannot be trusted for
        (:mod:`analysis.fit.trust`; the PSIS-LOO's ``pareto_k``).
    """

    names: tuple
    units: tuple
    chains: np.ndarray
    chains_internal: np.ndarray
    log_prob: np.ndarray
    summary: dict
    converged: bool
    reason: str
    steps: int
    burn: int
    walkers: int
    ensembles: int
    acceptance: list
    best: dict
    best_logp: float
    counts: dict
    timing: dict
    proposal: dict = dataclasses.field(default_factory=dict)
    quality: dict = dataclasses.field(default_factory=dict)
    plots: dict = dataclasses.field(default_factory=dict)
    loo: object = dataclasses.field(repr=False, default=None)
    adequacy: dict = dataclasses.field(default_factory=dict)
    warnings: list = dataclasses.field(default_factory=list)
    spec: object = dataclasses.field(repr=False, default=None)
    logpost: object = dataclasses.field(repr=False, default=None)

    def samples(self, flat: bool = True) -> np.ndarray:
        """Natural-unit samples, (N, ndim) when flat."""
        return self.chains.reshape(-1, len(self.names)) if flat else self.chains

    def median_internal(self) -> np.ndarray:
        """Posterior median in internal coordinates (ndim,); a circular parameter's is its
        circular median (:mod:`analysis.fit.circular`), not the median of the internal values
        (which, for draws across the wrap, lies half a period away)."""
        flat = self.chains_internal.reshape(-1, len(self.names))
        med = np.median(flat, axis=0)
        circle = self.spec.circular if self.spec is not None else np.zeros(len(med), bool)
        if circle.any():
            x = np.median(circular_natural(self.spec, flat), axis=0)
            med[circle] = np.clip(self.spec.to_internal(x)[circle], -INTERNAL_LIMIT,
                                  INTERNAL_LIMIT)
        return med

    def residuals(self) -> dict:
        """Residuals at the posterior median (:func:`analysis.fit.quality.residuals`)."""
        return residuals(self)

    def __repr__(self) -> str:
        """The verdict, steps and each parameter's median and 95% interval (not the chains).

        ``FitResult(converged, 350 steps x 4 ensembles x 32 walkers, kd1=0.302 [0.29, 0.31],
        ..., 1 warning)``.
        """
        head = ("converged" if self.converged else "not converged") + \
            f", {self.steps} steps x {self.ensembles} ensembles x {self.walkers} walkers"
        params = ", ".join(f"{n}={_num(s['median'])} [{_num(s['lo95'])}, {_num(s['hi95'])}]"
                           for n, s in ((n, self.summary.get(n, {})) for n in self.names)
                           if {"median", "lo95", "hi95"} <= set(s))
        tail = f", {len(self.warnings)} warning{'s' * (len(self.warnings) != 1)}" \
            if self.warnings else ""
        return f"FitResult({head}, {params}{tail})"

    def _repr_html_(self) -> str:
        """The parameter table (median, 68% and 95% intervals, unit, tau, R-hat) for
        Jupyter, with the verdict and the warnings; every value escaped."""
        cols = ("median", "lo68", "hi68", "lo95", "hi95", "unit", "tau", "rhat")
        head = "".join(f"<th>{c}</th>" for c in ("parameter",) + cols)
        rows = "".join(
            f"<tr><th>{html.escape(str(n))}</th>" + "".join(
                f"<td>{html.escape(_num(self.summary.get(n, {}).get(c, '')))}</td>"
                for c in cols) + "</tr>" for n in self.names)
        verdict = html.escape(self.reason or ("converged" if self.converged
                                              else "not converged"))
        warns = "".join(f"<li>{html.escape(str(w.get('message', w)))}</li>" if
                        isinstance(w, dict) else f"<li>{html.escape(str(w))}</li>"
                        for w in self.warnings)
        return (f"<table><caption>FitResult ({verdict})</caption><thead><tr>{head}</tr></thead>"
                f"<tbody>{rows}</tbody></table>" + (f"<ul>{warns}</ul>" if warns else ""))

    def to_json(self) -> dict:
        """The ``results.json`` document (see the module notes)."""
        quality = dict(self.quality)
        if self.logpost is not None and "rms_residual" not in quality:
            q = self.residuals()
            quality.update(rms_residual=q["rms"], rms_normalized=q["rms_normalized"],
                           values=int(q["residual"].size))
        if self.adequacy:
            quality["adequacy"] = self.adequacy
        doc = {
            "schema": "microcyl-fit", "schema_version": SCHEMA_VERSION,
            "model": "microcylinder" if self.spec is None else self.spec.model,
            "identifiability": [] if self.spec is None else list(self.spec.notes),
            "converged": bool(self.converged), "reason": self.reason,
            "adequate": self.adequacy.get("adequate"),
            "adequate_reason": self.adequacy.get("reason", "not checked"),
            "warnings": [dict(w) for w in self.warnings],
            "parameters": {n: dict(self.summary[n]) for n in self.names},
            "fit": {"steps": self.steps, "burn": self.burn, "walkers": self.walkers,
                    "ensembles": self.ensembles,
                    "acceptance_fraction": [float(a) for a in self.acceptance],
                    "map": dict(self.best), "map_log_posterior": float(self.best_logp),
                    "points": dict(self.counts), "timing": dict(self.timing),
                    "ties": ({k: list(v) for k, v in self.spec.ties.items()}
                             if self.spec is not None else {}),
                    "proposal": self.proposal},
            "quality": quality, "plots": dict(self.plots),
            "loo": None if self.loo is None else self.loo.summary()}
        return plain(doc)


def _num(value) -> str:
    """A summary entry for display: a number to 4 significant digits, text as it is."""
    return f"{value:.4g}" if isinstance(value, (int, float, np.floating)) else str(value)


def summarize(spec, diag) -> dict:
    """Per free parameter: median, 68% / 95% intervals (natural units), tau, N/tau, R-hat, ESS
    and unit, from a :class:`~analysis.fit.convergence.Diagnosis`."""
    natural = circular_natural(spec, diag.chains)     # one mode across a wrap
    summ = diagnostics.interval_summary(natural)
    ess = diagnostics.ess(diag.chains, diag.taus)
    out = {}
    for i, n in enumerate(spec.free):
        out[n] = {k: float(summ[k][i]) for k in summ}
        out[n].update(tau=float(diag.tau[i]), n_over_tau=float(diag.kept / diag.tau[i]),
                      rhat=float(diag.rhat[i]), ess=float(ess[i]), unit=spec.params[n].unit)
        if spec.period(n) is not None:          # circular: no bound, an interval may wrap
            out[n]["period"] = spec.period(n)
    return out


def write_results(result: FitResult, out_dir) -> tuple[Path, Path]:
    """Write ``results.json`` and ``results.csv`` into ``out_dir``, each atomically.

    Returns
    -------
    json_path, csv_path : Path
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    jpath, cpath = out / "results.json", out / "results.csv"
    with atomic_write(jpath, "w") as fh:
        fh.write(json.dumps(result.to_json(), indent=2) + "\n")
    lines = ["parameter," + ",".join(SUMMARY_COLUMNS)]
    for n in result.names:
        s = result.summary[n]
        lines.append(text_cell(n) + "," + ",".join(
            text_cell(s[c]) if isinstance(s[c], str) else f"{float(s[c]):.8g}"
            for c in SUMMARY_COLUMNS))
    lines.append(f"# converged,{str(result.converged).lower()},"
                 f"{comment_text(str(result.reason))}")
    with atomic_write(cpath, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return jpath, cpath


def read_results(path) -> dict:
    """Read a ``results.json`` into the current layout (schema version 2).

    Files of the first layout (parameters at the top level, the rest under ``_fit``) are
    converted. Every field a reader uses is checked (:func:`check_results`).

    Returns the document; raises ``ValueError`` naming the file (and the field) when it is not
    a fit's results.
    """
    path = Path(path)
    doc = load_json(path, "fit's results.json")
    if not isinstance(doc, dict):
        raise ValueError(f"{path}: not a fit's results.json (not a JSON object)")
    if doc.get("schema") != "microcyl-fit":
        doc = _from_first_layout(path, doc)
    return check_results(doc, path)


def _from_first_layout(path, doc: dict) -> dict:
    f = FileFields(path)
    old = f.mapping(doc, "_fit", default={})
    report = f.mapping(old, "report", "_fit", default={})
    quality = dict(f.mapping(old, "quality", "_fit", default={}))
    quality.update({k: v for k, v in report.items() if k.startswith("albedo")})
    plots = f.mapping(report, "plots", "_fit.report", default={})
    for k, v in plots.items():
        f.string(plots, k, "_fit.report.plots")
    return {"schema": "microcyl-fit", "schema_version": 1,
            "converged": doc.get("converged"), "reason": old.get("reason", ""),
            "parameters": {k: v for k, v in doc.items()
                           if isinstance(v, dict) and "median" in v},
            "fit": {k: v for k, v in old.items() if k not in ("quality", "report", "reason")},
            "quality": quality,
            "plots": {k: Path(v).name for k, v in plots.items()}}


def check_results(doc: dict, path) -> dict:
    """``doc`` (a results document read from ``path``) with every field a reader uses checked
    for type, shape and finiteness: ``converged``, ``reason``, each parameter's
    :data:`SUMMARY_COLUMNS` (only ``median`` required), ``fit.points``, ``quality`` and
    ``plots``.

    Raises
    ------
    ValueError
        ``PATH: FIELD must be ...; got ...`` for the first bad field.
    """
    f = FileFields(path)
    f.boolean(doc, "converged", none=True)
    f.string(doc, "reason", default="")
    doc.setdefault("model", "microcylinder")        # written before models were named
    f.string(doc, "model")
    params = f.mapping(doc, "parameters")
    for name in params:
        where = f"parameters.{name}"
        f.mapping(params, name, "parameters")
        for col in SUMMARY_COLUMNS:
            if col == "unit":
                f.string(params[name], col, where, default="")
            elif col == "median":
                f.number(params[name], col, where)
            elif col in FINITE_COLUMNS:        # absent from a hand-written file; finite if given
                f.number(params[name], col, where, default=None)
            else:
                f.number(params[name], col, where, finite=False, default=None, none=True)
    fit = f.mapping(doc, "fit", default={})
    points = f.mapping(fit, "points", "fit", default={})
    for k in points:
        f.integer(points, k, "fit.points", lo=0)
    for k in ("steps", "burn", "walkers", "ensembles"):
        f.integer(fit, k, "fit", lo=0, default=None, none=True)
    quality = f.mapping(doc, "quality", default={})
    for k in ("rms_residual", "rms_normalized", "albedo_delta_e2000"):
        f.number(quality, k, "quality", finite=False, default=None, none=True)
    f.integer(quality, "values", "quality", lo=0, default=None, none=True)
    for k in ("albedo_measured", "albedo_predicted"):
        f.array(quality, k, "quality", shape=(3,), finite=False, default=None, none=True)
    plots = f.mapping(doc, "plots", default={})
    for k in plots:
        f.string(plots, k, "plots")
    return doc
