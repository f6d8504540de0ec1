"""Verbs about BRDF tables: ``convert`` and ``info``."""

from __future__ import annotations

import json
import logging
from pathlib import Path

import gonio
from analysis.folderlock import output_lock
from analysis.tablefacts import table_facts
from gonio.terminal import shown
from reports.cli import options as cliutil

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``convert`` and ``info`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser("convert", help="convert a BRDF table between formats",
                       description="Convert a BRDF table; formats from the suffixes "
                                   "(.exr .csv .binary .alta; read also .bsdf and CUReT "
                                   "abrdf.dat with --sample).")
    p.add_argument("input", metavar="IN")
    p.add_argument("output", metavar="OUT")
    p.add_argument("--alta-param", metavar="NAME",
                   help="ALTA #PARAM_IN for an .alta OUT: COS_TH, SPHERICAL_TL_PL_TV_PV, "
                        "RUSIN_TH_PH_TD_PD, RUSIN_TH_TD_PD or CARTESIAN (default: COS_TH for "
                        "back-scatter rows, else SPHERICAL_TL_PL_TV_PV)")
    _reader_options(p)
    p.set_defaults(func=run_convert)
    q = sub.add_parser("info", help="what a BRDF table holds",
                       description="Print a table's source, size, angle ranges (degrees), "
                                   "value ranges and missing values.")
    q.add_argument("file", metavar="FILE")
    q.add_argument("--json", action="store_true", help="print the facts as JSON (scripts)")
    _reader_options(q)
    q.set_defaults(func=run_info)


def _reader_options(p):
    p.add_argument("--sample", type=cliutil.curet_sample_arg, metavar="N|NAME",
                   help="CUReT sample (for abrdf.dat): its number 1..61 or its dataset's "
                        "name (curet_07_velvet)")
    p.add_argument("--step", type=float, help="RGL .bsdf: outgoing grid step in degrees")
    p.add_argument("--stride", type=int, help="MERL .binary: take every STRIDE-th bin")


def _read(args, path):
    return cliutil.read_table(path, sample=args.sample, step=args.step, stride=args.stride)


def run_convert(args):
    options = {}
    if getattr(args, "alta_param", None):
        if not str(args.output).lower().endswith(".alta"):
            raise ValueError("--alta-param applies to an .alta output only")
        options["param"] = args.alta_param
    table = _read(args, args.input)
    with output_lock(Path(args.output), "convert", inside=False):  # removes a killed run's
        gonio.write(table, args.output, **options)                 # .microcyl-OUT.*.tmp
    log.info(f"wrote {len(table)} rows to {args.output}")
    return 0


def describe(table) -> str:
    """A few lines on what a table holds (:func:`analysis.tablefacts.table_facts`, used by
    ``microcyl info``); the text of its metadata through :func:`gonio.terminal.shown`."""
    f = table_facts(table)
    note = "" if f["angles_over"] == "all rows" else " (rows with data)"
    lines = [f"source: {gonio.meta_text(f['source'])}", f"format: {shown(f['format'])}",
             f"rows: {f['rows']}",
             f"units: {shown(f['units'])}"]
    lines += [f"{k}: {lo:.4g} .. {hi:.4g} deg{note}" for k, (lo, hi) in f["angles_deg"].items()]
    lines += [f"{k}: " + ("none valid" if r is None else f"{r[0]:.6g} .. {r[1]:.6g}")
              for k, r in f["values"].items()]
    m = f["missing"]
    lines.append(f"missing values: {m['values']} of {m['of']} (NaN {m['nan']}, negative "
                 f"{m['negative']}, infinite {m['infinite']}); rows with any: "
                 f"{m['rows_with_any']}")
    lines.append("sigma: " + ("none" if f["sigma"] is None else
                              f"{f['sigma'][0]:.6g} .. {f['sigma'][1]:.6g}"))
    return "\n".join(lines)


def run_info(args):
    table = _read(args, args.file)
    if args.json:
        print(json.dumps(gonio.plain(table_facts(table), nonfinite="null"), indent=1))
    else:
        print(describe(table))
    return 0
