"""What a Dask worker runs for one table: :func:`run_job`, which returns the table's row."""

from __future__ import annotations

import time
from pathlib import Path

from analysis.batch.jobs import BatchJob, read_job_table
from analysis.fit.driver import estimate_fit_time
from analysis.families import family
from analysis.fit.posterior import forward_model
from analysis.fit.workflow import fit_fabric
from gonio.terminal import shown

__all__ = ["run_job", "estimate_job", "result_row", "error_row"]


def run_job(job: BatchJob, out_dir) -> dict:
    """Fit one table into ``out_dir/<job.name>`` and return its summary row.

    The table is read here (on the worker). The fit resumes from the folder's checkpoint when
    there is one (a rerun, or a task rescheduled after its worker died), uses one thread (a
    batch runs one fit per core) and shows no progress bar. Any error becomes a row with
    status ``error`` and the error in one line: the batch goes on.

    Parameters
    ----------
    job : BatchJob
    out_dir : path
        The batch's folder.

    Returns
    -------
    dict
        ``name``, ``status`` (converged, not_converged or error), ``error``, ``steps``,
        ``wall_s`` (seconds), ``path``, ``sample``, ``preset``, ``reason``, ``folder``,
        ``elpd`` and ``elpd_se`` (PSIS-LOO; None without it), ``adequate`` (the fit's adequacy
        verdict: true, false or None), ``warnings`` (each warning's kind and parameters,
        ``"; "``-separated), and ``<parameter>_median``,
        ``_lo95``, ``_hi95`` of every free parameter.
    """
    t0 = time.perf_counter()
    folder = Path(out_dir) / job.name
    try:
        table = read_job_table(job)
        fab = job.fabric()
        spec = job.param_spec(fab, table)
        fit_kw = dict(job.fit)
        fit_kw.setdefault("threads", 1)
        extra = job.config_extra
        if extra is None and not family(job.model).presets:
            extra = {"sample": job.sample}
        elif extra is None:
            extra = {"fabric": job.preset, "options": fab.options, "sample": job.sample}
        result = fit_fabric(table, fab, spec, folder, plots=job.plots, progress=False,
                            table_file=job.path,
                            config_extra=extra, **fit_kw)
    except Exception as exc:        # noqa: BLE001 - the batch records it and goes on
        return error_row(job, exc, time.perf_counter() - t0)
    return result_row(job, result, time.perf_counter() - t0)


def estimate_job(job: BatchJob) -> tuple[float, str]:
    """The estimated time of :func:`run_job`'s fit of ``job`` from scratch, as a worker runs
    it (one thread): :func:`analysis.fit.driver.estimate_fit_time`'s (seconds at most, line).
    Reads the table; raises what reading it or the fit's checks raise."""
    table = read_job_table(job)
    fab = job.fabric()
    fit_kw = dict(job.fit)
    fit_kw.setdefault("threads", 1)
    return estimate_fit_time(table, job.param_spec(fab, table),
                             forward_model(fab, table.wi, table.wo), **fit_kw)


def _base(job: BatchJob) -> dict:
    return {"name": job.name, "status": "", "error": "", "steps": 0, "wall_s": 0.0,
            "path": job.path, "sample": job.sample, "preset": job.preset, "reason": "",
            "folder": job.name, "model": job.model}


def result_row(job: BatchJob, result, wall_s: float) -> dict:
    """The row of a finished fit (converged or not)."""
    row = _base(job)
    row.update(status="converged" if result.converged else "not_converged",
               steps=int(result.steps), wall_s=round(float(wall_s), 3), reason=result.reason,
               resumed_from=int(result.timing.get("resumed_from", 0)),
               adequate=result.adequacy.get("adequate"),
               warnings="; ".join(f"{w['kind']} {','.join(w['parameters'])}".strip()
                                  for w in result.warnings))
    loo = None if result.loo is None else result.loo.summary()
    row.update(elpd=None if loo is None else loo["elpd"],
               elpd_se=None if loo is None else loo["se"])
    for name in result.names:
        s = result.summary[name]
        row[f"{name}_median"] = float(s["median"])
        row[f"{name}_lo95"] = float(s["lo95"])
        row[f"{name}_hi95"] = float(s["hi95"])
    return row


def error_row(job: BatchJob, exc: BaseException, wall_s: float = 0.0) -> dict:
    """The row of a table whose fit failed: the error in one line, naming the file."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    named = (job.path, Path(job.path).name)
    if not any(n in text or shown(n) in text for n in named):     # a FormatError: escaped
        text = f"{job.path}: {text}"
    row = _base(job)
    row.update(status="error", error=f"{type(exc).__name__}: {text}",
               wall_s=round(float(wall_s), 3))
    return row
