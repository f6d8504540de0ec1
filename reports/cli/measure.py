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
import math

import gonio
import gonio.io
from analysis.budget import (MEASURE_BYTES_PER_PAIR, check_memory, format_bytes,
                             format_seconds, spec_pairs)
from analysis.folderlock import output_lock
from gonio import measure
from gonio.geometry import SPEC_HELP
from gonio.geomspec import from_spec
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


#: Seconds per BRDF evaluation with 32 tangent samples (about 10 us measured on 2 cores).
SECONDS_PER_EVALUATION = 1.2e-5


def _check_size(args, instrument, fabric) -> None:
    """Refuse a geometry that cannot fit in memory, before it is built; say how long a
    measurement of more than a few seconds will take."""
    n = spec_pairs(args.geometry)
    if n is None:
        return
    what = f"--geometry {args.geometry} ({n:.3g} pairs)"
    nbytes = n * MEASURE_BYTES_PER_PAIR
    check_memory(what, nbytes, "use a coarser step")
    points = instrument.n_source * instrument.n_detector      # no quadrature built
    seconds = n * points * SECONDS_PER_EVALUATION * fabric.options["tangent_samples"] / 32
    if seconds > 5:
        log.info(f"measure: {what} x {points} cone points: about {format_bytes(nbytes)} of "
                 f"memory and {format_seconds(seconds)}")


def run(args) -> int:
    """Measure and write; every check on the input happens before the measurement."""
    out = cliutil.check_output_suffix(args.output, gonio.io.WRITE_SUFFIXES)
    if not math.isfinite(args.rotation):
        raise ValueError(f"--rotation must be a finite angle in degrees; got {args.rotation}")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed must be a non-negative integer; got {args.seed}")
    instrument = instrument_from_args(args)
    src = cliutil.source_from_args(cliutil.fabric_argument(args), args)
    fabric = src.brdf
    _check_size(args, instrument, fabric)
    geometry = from_spec(args.geometry, rotation=math.radians(args.rotation))
    table = measure(fabric, geometry, instrument, seed=args.seed,
                    progress=cliutil.progress(args))
    if "name" not in table.meta["source"]:
        table.meta["source"]["name"] = src.label
    with output_lock(out, "measure", inside=False):   # removes a killed run's temporaries
        gonio.write(table, out)
    bad = int((~table.valid).any(axis=1).sum())
    note = f", {bad} with a negative or missing value" if bad else ""
    print(f"{src.label}: {len(table)} pairs on {geometry.spec} "
          f"(rotation {args.rotation:g} deg{note}) -> {out}")
    return 0
