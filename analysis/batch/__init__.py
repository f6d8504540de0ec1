"""Batch fits of many tables on Dask (``microcyl fit-batch``).

One table, one fit, one folder ``DIR/<name>/`` (its checkpoints, results and plots), one Dask
task. The parts:

1. :mod:`~analysis.batch.jobs` -- what to fit: :class:`BatchJob` (a table, its preset, its free
   parameters and fit options; plain data, sent to the workers) and :func:`jobs_from_inputs`
   (files, globs, folders and CUReT samples; a ``NAME.toml`` beside a table overrides the
   batch's spec for it) and :func:`~analysis.batch.jobs.table_names` (each table's folder
   name, a safe file name, from the set of tables, not their order).
2. :mod:`~analysis.batch.worker` -- :func:`run_job`, what a worker runs: read the table there,
   fit it into its folder (resuming from its checkpoint), return one summary row; a failure
   becomes a row with its one-line error.
3. :mod:`~analysis.batch.summary` -- :class:`BatchSummary`, the rows of ``summary.csv`` and
   ``summary.json``, written atomically by the client alone.
4. :mod:`~analysis.batch.engine` -- :func:`run_batch`: a ``LocalCluster`` (one process per
   core, one thread each) or an existing scheduler; submits the jobs not already converged,
   gathers the rows as the fits end, one progress bar over tables.

Files: each fit writes only its own folder, from the one thread of its worker; the client
alone writes the summaries. A worker that dies has its task rescheduled by Dask, and the fit
resumes from the checkpoint it left. Workers must see the same file system as the client
(trivially so on one machine; a shared folder on a cluster).
"""

from analysis.lazy import lazy_getattr

#: Names loaded on first use, with their modules (:mod:`analysis.lazy`): the engine and the
#: jobs load the fit and with it emcee and scipy.stats (about 0.5 s), which a reader of a
#: batch's summary (``report --batch``, ``report --fabric``) does not need.
_LAZY = {name: f"analysis.batch.{module}" for module, names in {
    "engine": ("BatchInterrupted", "run_batch"),
    "jobs": ("BatchJob", "jobs_from_inputs", "parse_samples", "read_job_table"),
    "summary": ("SUMMARY_CSV", "SUMMARY_JSON", "BatchSummary"), "worker": ("run_job",),
}.items() for name in names}
__getattr__ = lazy_getattr(__name__, _LAZY, globals())

__all__ = ["BatchJob", "jobs_from_inputs", "parse_samples", "read_job_table", "run_job",
           "run_batch", "BatchSummary", "BatchInterrupted", "SUMMARY_CSV", "SUMMARY_JSON"]
