"""The ``microcyl fit-measured`` verb: fit the model to the measured fabrics of the data folder.

``microcyl fit-measured [NAME ...] [--data DIR] -o DIR``

Fits every dataset of :data:`analysis.measured.MEASURED` (or the ones named) with its own
start preset and free parameters, each into ``DIR/NAME/`` exactly as ``microcyl fit`` would
(checkpoints, ``results.json``, plots), and writes ``DIR/measured.json``: per dataset, the
verdict, the residuals and the albedo colour difference. Run again, it resumes unfinished fits
and re-summarizes finished ones without sampling. ``microcyl report --measured DIR`` shows them.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from reports import cliutil

__all__ = ["register", "run", "fit_measured", "SUMMARY_FILE"]

#: The summary written beside the per-dataset folders.
SUMMARY_FILE = "measured.json"


def register(sub):
    """Add ``fit-measured`` to the ``microcyl`` sub-parsers."""
    from analysis.measured import MEASURED
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
    p.add_argument("--no-plots", action="store_true")
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    p.set_defaults(func=run)


def fit_measured(names=None, out_dir="fits", *, data_dir=None, seed: int = 0,
                 max_steps: int = 20000, time_limit: float | None = None,
                 rgl_step: float = 15.0, plots: bool = True, progress: bool = True,
                 echo=print) -> dict:
    """Fit measured datasets; write ``out_dir/NAME/`` and ``out_dir/measured.json``.

    Parameters
    ----------
    names : sequence of str, optional
        Keys of :data:`analysis.measured.MEASURED` (default all).
    out_dir : path
        Output folder; existing fits there are resumed.
    data_dir : path, optional
        The measured-data folder (default :func:`analysis.measured.default_data_dir`).
    seed, max_steps, time_limit
        Passed to :func:`analysis.fit.fit` (time limit per dataset, seconds).
    rgl_step : float
        Outgoing step for sampling the RGL files, degrees.
    plots, progress : bool
    echo : callable
        Called with one line per finished dataset.

    Returns
    -------
    dict
        The ``measured.json`` document: ``{"datasets": {name: {...}}}``; each entry's
        ``wall_s`` is the time of the run that wrote it (a resumed fit counts only its last
        run, a finished one only the re-summary).

    Raises
    ------
    ValueError
        An unknown dataset name (before any fit).
    FileNotFoundError
        A missing data file (before any fit).
    """
    from analysis.measured import MEASURED, load_measured, measured_spec
    from gonio import atomic_write
    from reports.cmd_fit import fit_and_write
    names = list(names) if names else list(MEASURED)
    bad = [n for n in names if n not in MEASURED]
    if bad:
        raise ValueError(f"unknown measured dataset {bad[0]!r}; valid: {', '.join(MEASURED)}")
    tables = {n: load_measured(n, data_dir, rgl_step=rgl_step) for n in names}
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    spath = out / SUMMARY_FILE
    for n in names:
        d = MEASURED[n]
        spec, fab = measured_spec(n)
        t0 = time.perf_counter()
        result, res = fit_and_write(
            tables[n], fab, spec, out / n, plots=plots, seed=seed, max_steps=max_steps,
            time_limit=time_limit, progress=progress,
            config_extra={"dataset": n, "preset": d.preset, "rgl_step": rgl_step})
        entry = {
            "title": d.title, "preset": d.preset, "source": str(tables[n].meta.get("source", "")),
            "pairs": len(tables[n]), "values_used": result.counts["used"],
            "free": list(result.names), "ties": list(d.ties),
            "converged": bool(result.converged), "reason": result.reason,
            "steps": result.steps, "wall_s": round(time.perf_counter() - t0, 2),
            "quality": res["_fit"]["quality"],
            "albedo_delta_e2000": res["_fit"].get("report", {}).get("albedo_delta_e2000"),
            "results": f"{n}/results.json",
        }
        # read just before writing: another fit-measured run may have added its datasets
        doc = _read_summary(spath)
        doc["datasets"][n] = entry
        with atomic_write(spath, "w") as fh:
            fh.write(json.dumps(doc, indent=2) + "\n")
        echo(f"{n}: {'converged' if result.converged else 'NOT converged'} after "
             f"{result.steps} steps (this run {entry['wall_s']:.0f} s); residual rms "
             f"{entry['quality']['rms_residual']:.3f}"
             + (f", albedo CIEDE2000 {entry['albedo_delta_e2000']:.1f}"
                if entry["albedo_delta_e2000"] is not None else ""))
    return doc


def _read_summary(path: Path) -> dict:
    """The summary document at ``path`` ({"datasets": {}} when missing or unreadable)."""
    try:
        doc = json.loads(path.read_text()) if path.exists() else {}
    except ValueError:
        doc = {}
    if not isinstance(doc, dict):
        doc = {}
    doc.setdefault("datasets", {})
    return doc


def run(args) -> int:
    out = cliutil.check_writable_dir(Path(args.output))
    doc = fit_measured(args.names, out, data_dir=args.data, seed=args.seed,
                       max_steps=args.max_steps, time_limit=args.time_limit,
                       rgl_step=args.rgl_step, plots=not args.no_plots,
                       progress=not args.no_progress)
    names = args.names or list(doc["datasets"])
    bad = [n for n in names if not doc["datasets"][n]["converged"]]
    print(f"{len(names) - len(bad)} of {len(names)} fits converged; summary: "
          f"{out / SUMMARY_FILE}")
    return 1 if bad else 0
