"""The ``plan`` verb: which (wi, wo) pairs to measure, chosen for the free parameters.

Example::

    microcyl plan --fabric velvet --free kd1,gamma_s1,gamma_v1 --budget 60 --snr 30 \\
        --max-theta 80 --min-separation 5 -o plan.csv
    microcyl measure velvet --geometry pairs:plan.csv --snr 30 -o measured.csv

Writes the plan file (:mod:`analysis.planning.workflow`: a pairs CSV in measurement order
with a header naming the fabric, the free parameters and the expected sd of each) and its
figure beside it (``plan.png``: :func:`reports.plots.plan.draw_plan`); prints the expected
sds of the plan and of uniform designs of N and 3N pairs. Angles in degrees.
"""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from analysis.planning import DEFAULT_CANDIDATES, DEFAULT_DRAWS, MAX_BUDGET
from analysis.planning.draws import MAX_DRAWS
from analysis.planning.workflow import plan_file
from gonio.geometry import SPEC_HELP
from gonio.terminal import shown
from reports.cli import lazy
from reports.cli import options as cliutil
from reports.cli.instrument import add_instrument_options, instrument_from_args

__all__ = ["register", "run"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add the ``plan`` verb to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "plan", help="choose the (wi, wo) pairs to measure for the free parameters",
        description="Choose the (wi, wo) pairs that tell most about the free parameters "
                    "(Bayesian D-optimality over draws of the parameters: a local prior about "
                    "a preset, or a fit folder's posterior), write them as a pairs CSV that "
                    "`measure --geometry pairs:FILE` reads, in an order that limits arm "
                    "travel, with the figure beside it (FILE.png).",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    cliutil.add_fabric_argument(p)
    p.add_argument("-o", "--output", required=True, metavar="FILE.csv",
                   help="the plan file to write (its figure goes beside it, .png)")
    g = p.add_argument_group("plan")
    g.add_argument("--free", default=None, metavar="NAMES",
                   help="free parameters, comma-separated (default: the fit's default set, "
                        "eta1,kd1,kd2,gamma_s1,gamma_v1,gamma_s2,gamma_v2,area1 with "
                        "eta2=eta1, area2=1-area1)")
    g.add_argument("--tie", action="append", default=None, metavar="A=B",
                   help="tie A to B (A=B or A=1-B), as `microcyl fit --tie`; repeatable")
    g.add_argument("--budget", type=int, required=True, metavar="N",
                   help=f"pairs to choose, 1..{MAX_BUDGET}")
    g.add_argument("--candidates", default=None, metavar="GEOMETRY",
                   help=f"pairs to choose from (default {DEFAULT_CANDIDATES}): {SPEC_HELP}")
    g.add_argument("--from", dest="from_table", default=None, metavar="TABLE",
                   help="a table already measured: plan the next N pairs after it")
    g.add_argument("--draws", type=int, default=DEFAULT_DRAWS, metavar="K",
                   help=f"draws of the parameters the criterion averages over (default "
                        f"{DEFAULT_DRAWS}, at most {MAX_DRAWS})")
    i = add_instrument_options(p)
    i.add_argument("--grey", action="store_true",
                   help="the instrument reads one grey (luminance) value a pair, not R, G, B")
    i.add_argument("--seed", type=int, default=0,
                   help="seed of the draws and of the uniform designs (default 0)")
    cliutil.add_quiet_options(p)
    cliutil.add_fabric_options(p)
    p.set_defaults(func=run)


def _check(args) -> Path:
    """Every option checked before any work; the output path."""
    out = cliutil.check_output_suffix(args.output, (".csv",))
    if not 1 <= args.budget <= MAX_BUDGET:
        raise ValueError(f"--budget must be a number of pairs in 1..{MAX_BUDGET}; got "
                         f"{args.budget}")
    if not 1 <= args.draws <= MAX_DRAWS:
        raise ValueError(f"--draws must be in 1..{MAX_DRAWS}; got {args.draws}")
    if args.seed < 0:
        raise ValueError(f"--seed must be a non-negative integer; got {args.seed}")
    if args.snr is None and not args.floor:
        raise ValueError("plan needs the instrument's noise: give --snr (and/or --floor)")
    return out


def _print(p, csv: Path, png: Path) -> None:
    n = p.budget
    what = "fit posterior" if p.source == "posterior" else "local prior"
    after = f" after {p.n_measured} measured" if p.n_measured else ""
    print(shown(f"{p.fabric}: {n} pairs{after} chosen from {p.n_candidates} candidates "
                f"({p.candidates}), {p.draws} draws of the {what} -> {csv}, {png}"))
    head = ("parameter", "unit", "plan", f"uniform {n}", f"uniform {3 * n}")
    rows = [(r["parameter"], r["unit"], f"{r['plan']:.4g}", f"{r['uniform']:.4g}",
             f"{r['uniform3']:.4g}") for r in p.table()]
    widths = [max(len(h), *(len(r[k]) for r in rows)) for k, h in enumerate(head)]
    print("expected posterior sd (Laplace approximation, mean over the draws):")
    for r in (head,) + tuple(rows):
        print("  " + "  ".join(c.ljust(w) if k < 2 else c.rjust(w)
                               for k, (c, w) in enumerate(zip(r, widths))))
    c = p.criterion
    print(f"expected log det of the posterior precision: plan {c['plan']:.2f}, uniform {n} "
          f"{c['uniform']:.2f}, uniform {3 * n} {c['uniform3']:.2f}")


def run(args) -> int:
    """Check the options, plan, write the CSV and its figure, print the expected sds."""
    out = _check(args)
    instrument = instrument_from_args(args)
    src = cliutil.source_from_args(cliutil.fabric_argument(args), args, what="--fabric")
    measured = None if args.from_table is None else cliutil.read_table(args.from_table)
    ties = cliutil.split_ties(args.tie) if args.tie else None
    p, csv = plan_file(src, args.free, args.budget, out, instrument=instrument, ties=ties,
                       candidates=args.candidates, measured=measured, draws=args.draws,
                       seed=args.seed, grey=args.grey, progress=cliutil.progress(args))
    png = csv.with_suffix(".png")
    lazy.plots().plan.draw_plan(p, filename=png)
    _print(p, csv, png)
    return 0
