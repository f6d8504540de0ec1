"""The ``microcyl fit-batch`` verb: fit many tables on Dask.

``microcyl fit-batch INPUT... --fabric PRESET [fit options] [--workers N | --scheduler ADDR]
-o DIR``, or ``--model lambert|charlie|ashikhmin|zeltner`` instead of ``--fabric``

Each table is fitted into ``DIR/<name>/`` (resumable); ``DIR/summary.csv`` and
``DIR/summary.json`` hold a row per table, and ``DIR/index.html`` links every fit's plots.
The work is :func:`analysis.batch.run_batch`; this module parses the arguments and prints.
"""

from __future__ import annotations

import logging
from pathlib import Path

from analysis.batch import jobs_from_inputs, run_batch
from reports.cli import lazy
from reports.cli import options as cliutil
from reports.report_batch import write_batch_page

__all__ = ["register", "run"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``fit-batch`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "fit-batch", help="fit many tables at once, on Dask (one machine or a cluster)",
        description="Fit every table named (files, globs, folders; CUReT abrdf.dat with "
                    "--sample), each into DIR/<name>/, on a Dask LocalCluster (one process "
                    "per core) or an existing scheduler. The same command run again resumes "
                    "unfinished fits and skips converged ones. A file NAME.toml beside a table "
                    "replaces --spec/--free/--tie (and, with a fabric key, --fabric) for it.")
    p.add_argument("inputs", nargs="+", metavar="INPUT", help="table files, globs or folders")
    cliutil.add_model_arguments(p)
    cliutil.add_fit_options(p)
    p.add_argument("--sample", default=None, metavar="all|N,N,...",
                   help="CUReT samples of an abrdf.dat input: all, or numbers or dataset "
                        "names (curet_07_velvet), comma-separated")
    p.add_argument("--rgl-step", type=float, default=None, metavar="DEG",
                   help="outgoing-direction step for RGL .bsdf inputs (default the reader's)")
    cliutil.add_cluster_options(p)
    p.add_argument("--no-plots", action="store_true", help="skip each fit's plots")
    cliutil.add_quiet_options(p)
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    cliutil.add_fabric_options(p)
    p.set_defaults(func=run)


def run(args) -> int:
    """Check everything, run the batch, print the counts; exit 1 when a table failed."""
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers must be >= 1; got {args.workers}")
    fab = cliutil.start_model(args)
    plots = None
    if not args.no_plots:
        plots = lazy.plots().fit_diagnostics.write_fit_plots
    out = cliutil.check_writable_dir(Path(args.output))
    free = args.free.split(",") if args.free and not args.free.endswith(".toml") else args.free
    jobs = jobs_from_inputs(
        args.inputs, preset=args.fabric, free=free, ties=cliutil.split_ties(args.tie),
        spec=args.spec, samples=cliutil.curet_samples_text(args.sample),
        fit=cliutil.fit_kwargs(args),
        fabric_options=getattr(fab, "options", {}), model=args.model,
        read_options={} if args.rgl_step is None else {"step": args.rgl_step},
        plots=plots)
    log.info(f"fit-batch: {len(jobs)} tables into {out}")
    summary = run_batch(jobs, out, workers=args.workers, scheduler=args.scheduler,
                        progress=cliutil.progress(args), notify=log.info,
                        page=write_batch_page)
    page = out / "index.html"
    c = summary.counts()
    print(f"{c.get('converged', 0)} converged, {c.get('not_converged', 0)} not converged, "
          f"{c.get('error', 0)} errors; summary: {out / 'summary.csv'}; page: {page}")
    return 1 if c.get("error") else 0
