"""The ``microcyl fit`` verb: Bayesian parameter estimation from a BRDF table.

``microcyl fit TABLE --fabric PRESET [--free eta1,kd1,...] [--tie eta2=eta1] -o DIR``

The preset gives the fixed values and the starting point. Writes ``DIR/results.json`` and
``DIR/results.csv`` (medians, 68%/95% intervals, tau, R-hat, ESS, verdict), the plots, and the
checkpoint ``DIR/checkpoint.h5``; the same command run again resumes from it. The work is
:func:`analysis.fit.fit_fabric`; this module parses the arguments and prints.
"""

from __future__ import annotations

import sys
from pathlib import Path

import brdf
from analysis.fit import fit_fabric, fit_spec
from reports import cliutil

__all__ = ["register", "run", "read_table", "format_summary", "format_warnings"]


def read_table(path, sample=None):
    """Read a table with ``gonio.read`` (CUReT needs ``sample``; refused for another format)."""
    return cliutil.read_table(path, sample=sample)


def register(sub):
    """Add ``fit`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "fit", help="estimate model parameters from a BRDF table (emcee)",
        description="Fit the microcylinder model to a BRDF table: point estimate, then several "
                    "independent emcee ensembles until every parameter has N > 50 tau, tau is "
                    "stable and R-hat < 1.01, or a step limit. Resumes from DIR's checkpoints.")
    p.add_argument("table", metavar="TABLE", help="table file (.exr, .csv, .binary, .alta, "
                                                  ".bsdf, CUReT abrdf.dat with --sample)")
    p.add_argument("--fabric", required=True, metavar="PRESET",
                   help=f"preset giving fixed values and the start: {', '.join(brdf.PRESETS)}")
    cliutil.add_fit_options(p)
    p.add_argument("--sample", type=int, default=None, metavar="N",
                   help="CUReT sample number (for abrdf.dat)")
    p.add_argument("--no-plots", action="store_true", help="skip the plots")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    cliutil.add_fabric_options(p)
    p.set_defaults(func=run)


def _spec_from_args(args, fab):
    return fit_spec(fab, args.free, cliutil.split_ties(args.tie), args.spec)


def run(args) -> int:
    """Parse-level checks, then :func:`analysis.fit.fit_fabric`; print the summary."""
    if args.fabric not in brdf.PRESETS:
        raise ValueError(f"unknown fabric {args.fabric!r}; valid presets are "
                         f"{', '.join(brdf.PRESETS)}")
    fit_kw = cliutil.fit_kwargs(args)
    fab = cliutil.fabric_from_args(args.fabric, args)
    spec = _spec_from_args(args, fab)
    cliutil.reader_options(args.table, sample=args.sample)
    out = cliutil.check_writable_dir(Path(args.output))
    table = read_table(args.table, args.sample)
    plots = None
    if not args.no_plots:
        # lazy: fitplots loads matplotlib and corner (~1 s), which `microcyl --help` skips
        from reports.fitplots import write_fit_plots as plots
    result = fit_fabric(
        table, fab, spec, out, plots=plots, progress=not args.no_progress, **fit_kw,
        notify=lambda line: print(line, file=sys.stderr, flush=True),
        config_extra={"fabric": args.fabric, "options": fab.options, "sample": args.sample})
    print(format_summary(result))
    print(format_warnings(result))
    q = result.quality
    print(f"residuals at the posterior median: rms {q['rms_residual']:.4f} in the "
          f"likelihood's space, {q['rms_normalized']:.2f} in units of the noise")
    colour = (f"CIEDE2000 {q['albedo_delta_e2000']:.2f}" if q.get("albedo_delta_e2000")
              is not None else f"none ({q.get('albedo_delta_e2000_reason', 'not computed')})")
    print(f"albedo colour, measured vs predicted (posterior median): {colour}"
          + ("" if args.no_plots else f"; plots in {out}"))
    print(f"results: {out / 'results.json'}")
    return 0


def format_summary(result) -> str:
    """The fit's summary as a text table."""
    lines = [f"{'parameter':12s} {'median':>10s} {'68% interval':>23s} {'95% interval':>23s} "
             f"{'tau':>6s} {'N/tau':>7s} {'R-hat':>7s} {'ESS':>8s}"]
    for n in result.names:
        s = result.summary[n]
        lines.append(f"{n:12s} {s['median']:10.5g} [{s['lo68']:10.5g},{s['hi68']:10.5g}] "
                     f"[{s['lo95']:10.5g},{s['hi95']:10.5g}] {s['tau']:6.1f} "
                     f"{s['n_over_tau']:7.1f} {s['rhat']:7.4f} {s['ess']:8.0f}")
    c = result.counts
    lines.append(f"values used {c['used']} of {c['total']} (masked: {c['invalid_value']} NaN or "
                 f"negative, {c['below_horizon']} below horizon, {c['bad_sigma']} bad sigma)")
    lines.append(f"acceptance {min(result.acceptance):.2f}-{max(result.acceptance):.2f}; "
                 f"{result.ensembles} ensembles x {result.walkers} walkers x {result.steps} "
                 f"steps; wall {result.timing['wall_s']:.1f} s")
    if result.timing.get("resumed_from"):
        lines.append(f"resumed from the checkpoint at step {result.timing['resumed_from']}")
    lines.append(("CONVERGED: " if result.converged else "") + result.reason)
    return "\n".join(lines)


def format_warnings(result) -> str:
    """The adequacy verdict, then each warning, one line each (:mod:`analysis.fit.trust`)."""
    a = result.adequacy or {}
    verdict = {True: "ADEQUATE", False: "NOT ADEQUATE", None: "adequacy not checked"}
    lines = [f"{verdict[a.get('adequate')]}: {a.get('reason', 'not checked')}"]
    lines += [f"warning ({w['kind']}): {w['message']}" for w in result.warnings]
    return "\n".join(lines)
