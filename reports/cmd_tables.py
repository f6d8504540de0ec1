"""Verbs about BRDF tables: ``convert`` and ``info``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import gonio
from analysis.folderlock import output_lock
from reports import cliutil


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
    _reader_options(q)
    q.set_defaults(func=run_info)


def _reader_options(p):
    p.add_argument("--sample", type=int, help="CUReT sample number 1..61 (for abrdf.dat)")
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
        gonio.write(table, args.output, **options)                 # .OUT.*.tmp
    print(f"wrote {len(table)} rows to {args.output}")
    return 0


def describe(table) -> str:
    """A few lines on what a table holds (used by ``microcyl info``)."""
    ang = np.degrees(table.angles)
    lines = [f"source: {table.meta.get('source', 'unknown')}",
             f"format: {table.meta.get('file_format', 'unknown')}",
             f"rows: {len(table)}",
             f"units: {table.meta.get('units', '1/sr')}"]
    valid = table.valid
    data = valid.any(axis=1)          # a MERL file lists its empty bins below the horizon too
    note = "" if data.all() else " (rows with data)"
    sel = ang[data] if data.any() else ang
    for k, name in enumerate(("theta_i", "phi_i", "theta_o", "phi_o")):
        lines.append(f"{name}: {sel[:, k].min():.4g} .. {sel[:, k].max():.4g} deg{note}")
    for c, name in enumerate("RGB"):
        v = table.values[valid[:, c], c]
        rng = f"{v.min():.6g} .. {v.max():.6g}" if v.size else "none valid"
        lines.append(f"{name}: {rng}")
    n_nan = int(np.count_nonzero(np.isnan(table.values)))
    n_neg = int(np.count_nonzero(table.values < 0))
    n_inf = int(np.count_nonzero(np.isinf(table.values)))
    lines.append(f"missing values: {int(np.count_nonzero(~valid))} of {valid.size} "
                 f"(NaN {n_nan}, negative {n_neg}, infinite {n_inf}); rows with any: "
                 f"{int(np.count_nonzero(~valid.all(axis=1)))}")
    lines.append("sigma: " + ("none" if table.sigma is None else
                              f"{np.nanmin(table.sigma):.6g} .. {np.nanmax(table.sigma):.6g}"))
    return "\n".join(lines)


def run_info(args):
    print(describe(_read(args, args.file)))
    return 0
