"""The ``microcyl fit`` verb: Bayesian parameter estimation from a BRDF table.

``microcyl fit TABLE --fabric PRESET [--free eta1,kd1,...] [--tie eta2=eta1] -o DIR``
``microcyl fit TABLE --model lambert|... [--free base,...] -o DIR``

The preset gives the fixed values and the starting point (``--model microcylinder``, the
default); a baseline model (:mod:`brdf.baselines`) starts from its parameters' typical values
and takes no preset. Writes ``DIR/results.json`` and
``DIR/results.csv`` (medians, 68%/95% intervals, tau, R-hat, ESS, verdict), the plots, and the
checkpoint ``DIR/checkpoint.h5``; the same command run again resumes from it. The work is
:func:`analysis.fit.fit_fabric`; this module parses the arguments and prints.
"""

from __future__ import annotations

import sys
from pathlib import Path

from analysis.families import family
from analysis.fit import fit_fabric, fit_spec
from analysis.fit.fisher import suggest_for_file
from analysis.fit.workflow import check_fit_size
from analysis.fit.loo import HIGH_K
from analysis.fit.outputs import check_fit_folder
from gonio.terminal import shown
from reports.cli import lazy
from reports.cli import options as cliutil
from reports.fitwords import verdict_lines

__all__ = ["register", "run", "read_table", "format_summary", "format_information",
           "format_loo", "format_warnings"]


def read_table(path, sample=None):
    """Read a table with ``gonio.read`` (CUReT needs ``sample``; refused for another format)."""
    return cliutil.read_table(path, sample=sample)


def register(sub):
    """Add ``fit`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "fit", help="estimate model parameters from a BRDF table (emcee)",
        description="Fit the microcylinder model (or a baseline model, --model) to a BRDF "
                    "table: point estimate, then several "
                    "independent emcee ensembles until every parameter has N > 50 tau, tau is "
                    "stable and R-hat < 1.01, or a step limit. Resumes from DIR's checkpoints.")
    p.add_argument("table", metavar="TABLE", help="table file (.exr, .csv, .binary, .alta, "
                                                  ".bsdf, CUReT abrdf.dat with --sample)")
    cliutil.add_model_arguments(p)
    cliutil.add_fit_options(p)
    p.add_argument("--sample", type=cliutil.curet_sample_arg, default=None, metavar="N|NAME",
                   help="CUReT sample (for abrdf.dat): its number (7) or its dataset's name "
                        "(curet_07_velvet, as fit-measured names it)")
    p.add_argument("--no-plots", action="store_true", help="skip the plots")
    cliutil.add_quiet_options(p)
    p.add_argument("--suggest", action="store_true",
                   help="sample nothing: print what the table can tell of each candidate "
                        "parameter (the --free given, else the default set plus albedo1 and "
                        "albedo2 on an RGB table) from the Fisher information at the start "
                        "point (Cramér-Rao sd against the prior's, confounded pairs) and a "
                        "suggested --free list, then exit; -o is not needed")
    p.add_argument("-o", "--output", default=None, metavar="DIR",
                   help="output folder (required unless --suggest)")
    cliutil.add_fabric_options(p)
    p.set_defaults(func=run)


def _spec_from_args(args, fab, table=None):
    return fit_spec(fab, args.free, cliutil.split_ties(args.tie), args.spec, table=table)


def _config_extra(args, fab) -> dict:
    """What the fit records of its start (and matches on resume)."""
    if not family(args.model).presets:
        return {"sample": args.sample}
    return {"fabric": args.fabric, "options": fab.options, "sample": args.sample}


def run(args) -> int:
    """Parse-level checks, then :func:`analysis.fit.fit_fabric`; print the summary."""
    fab = cliutil.start_model(args)
    fit_kw = cliutil.fit_kwargs(args)
    if args.suggest:
        return _suggest(args, fit_kw, fab)
    if args.output is None:
        raise ValueError("-o/--output DIR is required (unless --suggest)")
    spec = _spec_from_args(args, fab)
    check_fit_size(args.table, spec, args.walkers,
                   **cliutil.reader_options(args.table, sample=args.sample))
    out = cliutil.check_writable_dir(Path(args.output))
    check_fit_folder(out, args.table)       # files it did not write, or the table: refused
    table = read_table(args.table, args.sample)
    spec = _spec_from_args(args, fab, table)     # a baseline's default free set: the table's
    plots = None
    if not args.no_plots:
        plots = lazy.plots().fit_diagnostics.write_fit_plots
    result = fit_fabric(
        table, fab, spec, out, plots=plots, table_file=args.table,
        progress=cliutil.progress(args), **fit_kw,
        notify=lambda line: print(shown(line), file=sys.stderr, flush=True),
        config_extra=_config_extra(args, fab))
    print(f"model: {spec.model}" + "".join(f"; {n}" for n in spec.notes))
    print(shown(format_summary(result), lines=True))
    print(shown(format_warnings(result), lines=True))
    q = result.quality
    print(f"residuals at the posterior median: rms {q['rms_residual']:.4f} in the "
          f"likelihood's space, {q['rms_normalized']:.2f} in units of the noise")
    colour = (f"CIEDE2000 {q['albedo_delta_e2000']:.2f}" if q.get("albedo_delta_e2000")
              is not None else f"none ({q.get('albedo_delta_e2000_reason', 'not computed')})")
    print(f"albedo colour, measured vs predicted (posterior median): {colour}"
          + ("" if args.no_plots else f"; plots in {out}"))
    if result.loo is not None:
        print(format_loo(result.loo.summary(), q.get("loo_pit")))
    print(f"results: {out / 'results.json'}")
    return 0


def _suggest(args, fit_kw, fab) -> int:
    """``--suggest``: :func:`analysis.fit.fisher.suggest_for_file`, printed; no sampling,
    nothing written."""
    given = cliutil.reader_options(args.table, sample=args.sample)
    report, kept = suggest_for_file(args.table, fab, args.free, cliutil.split_ties(args.tie),
                                    args.spec, read_options=given,
                                    likelihood=fit_kw["likelihood"], nu=fit_kw["nu"])
    print(shown(format_information(report, kept, args.table), lines=True))
    return 0


def format_information(report, ties, table_name) -> str:
    """``--suggest``'s text: a row per candidate (start, Cramér-Rao sd, prior sd, ratio,
    verdict), the confounded pairs and the suggested ``--free`` (with its ties)."""
    lines = [f"what {table_name} can tell of each candidate parameter: Fisher information "
             f"at the start ({report.n_used} values)",
             f"{'parameter':12s} {'start':>10s} {'+- (unit)':>16s} {'CR sd':>9s} "
             f"{'prior sd':>9s} {'ratio':>7s}  verdict"]
    for n, sd, prior, nat in zip(report.names, report.cr_sd, report.prior_sd,
                                 report.natural_sd):
        unit = report.units[n]
        lines.append(f"{n:12s} {report.start[n]:10.4g} {nat:9.2g} {unit[:6]:6s} {sd:9.3g} "
                     f"{prior:9.3g} {sd / prior:7.3f}  {report.verdict(n)}")
    lines.append(f"(CR sd and prior sd in the fit's internal logit coordinates, where the flat "
                 f"prior has sd {report.prior_sd[0]:.3g}; +- the CR sd in the parameter's "
                 f"unit at the start; informed: ratio < {report.informed_ratio:g}, well "
                 f"informed: < {0.2 * report.informed_ratio:g})")
    if report.confounded:
        lines.append("confounded (|correlation| > 0.95): " + "; ".join(
            f"{a} ~ {b} ({c:+.3f})" for a, b, c in report.confounded))
    else:
        lines.append("confounded (|correlation| > 0.95): none")
    not_told = [n for n in report.names if report.verdict(n) == "not informed"]
    if not_told:
        lines.append("not informed with every candidate free: " + ", ".join(not_told))
    left = [n for n in report.names if n not in report.suggested]
    if report.suggested:
        tie = ("" if not ties else " --tie " + ",".join(f"{t}={s}" for t, s in ties.items()))
        lines.append("with " + (f"{', '.join(left)} fixed at the start, " if left else "")
                     + "these are each informed and no two confounded:")
        lines.append(f"suggested: --free {','.join(report.suggested)}{tie}")
    else:
        lines.append("suggested: none of the candidates is informed by this table")
    return "\n".join(lines)


def format_loo(loo: dict, pit: dict | None = None) -> str:
    """One line: the PSIS-LOO of a fit (``results.json``'s ``loo``) and its LOO-PIT test.

    Examples
    --------
    >>> print(format_loo({"elpd": 812.34, "se": 20.1, "p_loo": 3.2, "pareto_k_max": 0.41,
    ...                   "n_high_k": 0}, {"ks_pvalue": 0.31, "values": 450}))
    PSIS-LOO: elpd 812.3 ± 20.1 (p_loo 3.2; Pareto k max 0.41, 0 values above 0.70);
    LOO-PIT uniformity over 450 values: KS p = 0.31
    """
    k = loo.get("k_threshold", HIGH_K)          # a file written before it was recorded: 0.7
    line = (f"PSIS-LOO: elpd {loo['elpd']:.1f} ± {loo['se']:.1f} (p_loo {loo['p_loo']:.1f}; "
            f"Pareto k max {loo['pareto_k_max']:.2f}, {loo['n_high_k']} values above {k:.2f})")
    if pit:
        line += (f"; LOO-PIT uniformity over {pit['values']} values: KS p = "
                 f"{pit['ks_pvalue']:.2g}")
    return line


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
    """The adequacy verdict, then each warning, one line each (:mod:`analysis.fit.trust`;
    the words of :func:`reports.fitwords.verdict_lines`, which fit-measured prints too)."""
    a = result.adequacy or {}
    return "\n".join(verdict_lines(a.get("adequate"), a.get("reason"), result.warnings))
