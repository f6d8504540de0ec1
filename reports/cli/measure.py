"""The ``measure`` verb: measure a preset fabric on a geometry and write the table.

Example::

    microcyl measure velvet --geometry full:10 --snr 50 --seed 1 -o velvet.exr
    microcyl measure silk_shot --geometry plane:weft:5 --cone-detector 1.5 --masking off -o s.csv
    microcyl measure velvet --geometry pairs:plan.csv --max-theta 80 --min-separation 5 -o v.csv

The instrument's options (noise, cones, limits) are :mod:`reports.cli.instrument`'s; a
geometry with pairs out of the instrument's reach is refused before any work.

Angles on the command line are in degrees (cone half-angles, ``--rotation``, geometry specs).
"""

from __future__ import annotations

import argparse
import logging

import gonio
import gonio.io
from analysis.measurejob import measure_to_file
from gonio.geometry import SPEC_HELP
from gonio.terminal import shown
from reports.cli import options as cliutil
from reports.cli.instrument import add_instrument_options, instrument_from_args

__all__ = ["register", "run"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add the ``measure`` verb to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "measure", help="measure a fabric on a geometry through a virtual instrument",
        description="Measure a fabric on a geometry through a virtual "
                    "gonioreflectometer (finite source and detector cones, noise) and write "
                    "the table (format from the output suffix: .exr, .csv, .binary).",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    cliutil.add_fabric_argument(p)
    p.add_argument("-o", "--output", required=True, metavar="FILE",
                   help=f"output table ({', '.join(gonio.io.WRITE_SUFFIXES)})")
    g = p.add_argument_group("geometry")
    g.add_argument("--geometry", default="full:10", metavar="SPEC",
                   help=f"default full:10; one of {SPEC_HELP}")
    g.add_argument("--rotation", type=float, default=0.0, metavar="DEG",
                   help="sample azimuth on the stage, degrees (the warp points there)")
    i = add_instrument_options(p)
    i.add_argument("--seed", type=int, default=None, help="seed of the noise")
    cliutil.add_quiet_options(p)
    cliutil.add_fabric_options(p, rotation=False)
    p.set_defaults(func=run, fabric_rotation=False)     # --rotation turns the stage


def run(args) -> int:
    """Measure and write; every check on the input happens before the measurement."""
    out = cliutil.check_output_suffix(args.output, gonio.io.WRITE_SUFFIXES)
    instrument = instrument_from_args(args)
    src = cliutil.source_from_args(cliutil.fabric_argument(args), args)
    table, geometry, out = measure_to_file(src.brdf, src.label, args.geometry, out, instrument,
                                           rotation_deg=args.rotation, seed=args.seed,
                                           progress=cliutil.progress(args), notify=log.info)
    bad = int((~table.valid).any(axis=1).sum())
    note = f", {bad} with a negative or missing value" if bad else ""
    print(shown(f"{src.label}: {len(table)} pairs on {geometry.spec} "
                f"(rotation {args.rotation:g} deg{note}) -> {out}"))
    return 0
