"""The ``microcyl fit-measured`` verb: fit the model to the measured fabrics of the data folder.

``microcyl fit-measured [NAME ...] [--data DIR] [--models all|lambert,...] -o DIR``

Fits every dataset of :data:`analysis.measured.MEASURED` (or the ones named) with its own
start preset and free parameters, each into ``DIR/NAME/`` exactly as ``microcyl fit`` would
(checkpoints, ``results.json``, plots), and writes ``DIR/measured.json``: per dataset, the
verdict, the residuals and the albedo colour difference. Run again, it resumes unfinished fits
and re-summarizes finished ones without sampling. ``microcyl report --measured DIR`` shows them.
With ``--models``, each dataset is fitted by each model named (``DIR/NAME-MODEL/`` for a
baseline model) and the models are ranked by PSIS-LOO in measured.json
(:mod:`analysis.measuredmodels`).
"""

from __future__ import annotations

from pathlib import Path

from analysis.families import model_names
from analysis.measured import MEASURED, SUMMARY_FILE, fit_measured
from analysis.measuredmodels import fit_folder, parse_models
from reports.cli import lazy
from reports.cli import options as cliutil
from reports.fitwords import verdict_lines

__all__ = ["register", "run"]


def register(sub):
    """Add ``fit-measured`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "fit-measured", help="fit the model to the measured felts and CUReT fabrics",
        description="Fit the microcylinder model to the RGL felts and the CUReT fabric samples "
                    "(each from its closest preset; see analysis.measured), each into its own "
                    "folder of DIR, resumable; DIR/measured.json summarizes them.")
    p.add_argument("names", nargs="*", metavar="NAME",
                   help=f"datasets (default all): {', '.join(MEASURED)}")
    p.add_argument("--data", default=None, metavar="DIR",
                   help="measured-data folder (default $MICROCYL_DATA or ../shared/data)")
    p.add_argument("--max-steps", type=int, default=20000, metavar="N",
                   help="step limit per ensemble (default 20000)")
    p.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                   help="per dataset")
    p.add_argument("--rgl-step", type=float, default=15.0, metavar="DEG",
                   help="outgoing-direction step when sampling an RGL file (default 15)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--models", default=None, metavar="all|MODEL,...",
                   help=f"the models fitted to each dataset: all, or comma-separated of "
                        f"{', '.join(model_names())} (default microcylinder alone); "
                        f"measured.json then ranks them by PSIS-LOO")
    cliutil.add_cluster_options(p)
    p.add_argument("--no-plots", action="store_true")
    cliutil.add_quiet_options(p)
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    p.set_defaults(func=run)


def run(args) -> int:
    """Fit the named (or all) measured datasets; exit 1 when one did not converge."""
    models = parse_models(args.models)
    out = cliutil.check_writable_dir(Path(args.output))
    plots = None
    if not args.no_plots:
        plots = lazy.plots().fit_diagnostics.write_fit_plots
    doc = fit_measured(args.names, out, data_dir=cliutil.data_dir(args.data),
                       seed=args.seed,
                       max_steps=args.max_steps, time_limit=args.time_limit,
                       rgl_step=args.rgl_step, plots=plots, progress=cliutil.progress(args),
                       echo=print, workers=args.workers, scheduler=args.scheduler,
                       models=args.models)
    names = args.names or list(doc["datasets"])
    for n in names:
        entry = doc["datasets"][n]
        fits = ([(n, entry)] if args.models is None else
                [(fit_folder(n, m), entry["models"][m]) for m in models])
        for folder, e in fits:
            print(f"{folder}: " + ("converged" if e.get("converged") else "NOT converged")
                  + "; " + "\n  ".join(verdict_lines(e.get("adequate"),
                                                      e.get("adequate_reason"),
                                                      e.get("warnings"))))
    if args.models is None:
        bad = [n for n in names if not doc["datasets"][n]["converged"]]
        print(f"{len(names) - len(bad)} of {len(names)} fits converged; summary: "
              f"{out / SUMMARY_FILE}")
        return 1 if bad else 0
    fits = [(n, m, doc["datasets"][n]["models"][m]) for n in names for m in models]
    bad = [fit_folder(n, m) for n, m, e in fits if not e.get("converged")]
    print(f"{len(fits) - len(bad)} of {len(fits)} fits converged"
          + (f" (not: {', '.join(bad)})" if bad else "") + f"; summary: {out / SUMMARY_FILE}")
    return 1 if bad else 0
