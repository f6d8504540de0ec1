"""Verbs about the model itself: ``fabrics``, ``eval``, ``report``."""

from __future__ import annotations

import json
import logging
import os
import shlex
import sys
from pathlib import Path

import numpy as np

import brdf
import gonio
from analysis import sources
from analysis.folderlock import output_lock
from analysis.fit.results import read_results
from gonio.terminal import shown
from reports.cli import lazy
from reports.cli import options as cliutil
from reports.report_batch import write_batch_page
from reports.standard import STANDARD_GEOMETRIES, standard_luminance

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``fabrics``, ``eval`` and ``report`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser("fabrics", help="list the presets and their parameters",
                       description="List the paper's six fabrics (Table II) and their "
                                   "parameters (gamma and offsets in degrees).")
    p.add_argument("--json", action="store_true",
                   help="print the presets as JSON (scripts; gamma and offsets in degrees)")
    p.set_defaults(func=run_fabrics)

    p = sub.add_parser("eval", help="evaluate f_r of a fabric at one pair of directions",
                       description="Print the RGB BRDF f_r (1/sr, no cosine) of FABRIC at "
                                   "one (wi, wo) pair given by polar angle and azimuth in "
                                   "degrees (azimuth from the warp, +x).")
    cliutil.add_fabric_argument(p, tables=True)
    p.add_argument("--wi", type=cliutil.parse_angle_pair, required=True, metavar="THETA,PHI",
                   help="direction toward the light, degrees")
    p.add_argument("--wo", type=cliutil.parse_angle_pair, required=True, metavar="THETA,PHI",
                   help="direction toward the viewer, degrees")
    p.add_argument("--json", action="store_true", help="print the result as JSON (scripts)")
    cliutil.add_fabric_options(p)
    p.set_defaults(func=run_eval)

    p = sub.add_parser("report", help="write the HTML report on the presets (the main job)",
                       description="The main job: a self-contained HTML report on every "
                                   "preset (parameters, lobes, slices, masking, energy, "
                                   "reciprocity, renders, fits) in DIR/index.html, with its "
                                   "data in DIR/summary.json; prints f_r at standard "
                                   "geometries.")
    p.add_argument("--fabric", action="append", metavar="FABRIC",
                   help="limit to these fabrics (repeatable; default every preset): "
                        + sources.accepted())
    p.add_argument("-o", "--output", default="report", metavar="DIR",
                   help="output folder (default ./report); replaced whole by the next run")
    p.add_argument("--quality", choices=("default", "high", "fast"), default="default",
                   help="figure and render resolution: default (renders 448 x 252 at 16 "
                        "spp, Mitsuba's 640 x 360), high (1280 x 720, finer figures, "
                        "slower) or fast (previews)")
    cliutil.add_engine_option(p, "the renders", deprecated=("--render-engine",))
    p.add_argument("--fit", action="append", metavar="FABRIC=RESULTS",
                   help="show a fit's results.json in FABRIC's page (repeatable)")
    p.add_argument("--measured", default=None, metavar="DIR",
                   help="add the fits of `microcyl fit-measured -o DIR` (page measured.html)")
    p.add_argument("--batch", default=None, metavar="DIR",
                   help="write the page of `microcyl fit-batch -o DIR` (DIR/index.html) "
                        "instead of the presets' report")
    cliutil.add_quiet_options(p)
    p.set_defaults(func=run_report)


def format_fabrics_table(names=brdf.PRESETS) -> str:
    """The presets' parameters as a text table: one row a thread, one column a parameter of
    :data:`brdf.schema.THREAD_PARAMS` (headed with its unit: gamma and offsets in degrees)."""
    params = brdf.schema.THREAD_PARAMS
    rows = [["fabric", "thr"] + [p.heading for p in params]]
    for name in names:
        for j, t in enumerate(brdf.preset_threads(name), 1):
            rows.append([name if j == 1 else "", f"T{j}"]
                        + [p.text(getattr(t, p.name)) for p in params])
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    # Text columns (fabric, thread, sequences) to the left, numbers to the right.
    left = [True, True] + [p.kind == "sequence" for p in params]
    lines = ["  ".join(c.ljust(w) if lft else c.rjust(w)
                       for c, w, lft in zip(r, widths, left)).rstrip() for r in rows]
    lines.insert(1, "-" * max(len(line) for line in lines))
    return "\n".join(lines)


def fabrics_document(names=brdf.PRESETS) -> dict:
    """The presets as plain data: per fabric its threads' parameters (the schema's names;
    gamma and offsets in degrees) and the units."""
    params = brdf.schema.THREAD_PARAMS
    return {"units": {p.name: p.unit for p in params},
            "fabrics": {n: [{p.name: gonio.plain(getattr(t, p.name)) for p in params}
                            for t in brdf.preset_threads(n)] for n in names}}


def run_fabrics(args):
    if args.json:
        print(json.dumps(fabrics_document(), indent=1))
    else:
        print(format_fabrics_table())
    return 0


def run_eval(args):
    name = cliutil.fabric_argument(args)
    src = cliutil.source_from_args(name, args, tables=True)
    wi = brdf.directions.from_angles(*np.radians(args.wi))
    wo = brdf.directions.from_angles(*np.radians(args.wo))
    f = np.asarray(src.brdf.eval(wi, wo), dtype=np.float64).reshape(3)
    if args.json:
        options = gonio.plain(src.brdf.options) if src.is_fabric else None
        print(json.dumps({"fabric": name, "kind": src.kind, "wi_deg": list(args.wi),
                          "wo_deg": list(args.wo), "f_r": [float(x) for x in f],
                          "unit": "1/sr", "options": options}))
        return 0
    print(f"f_r [1/sr]  R {f[0]:.9g}  G {f[1]:.9g}  B {f[2]:.9g}")
    return 0


def run_report(args):
    build_report = lazy.report()
    if args.batch is not None:
        with output_lock(Path(args.batch), "report"):    # the batch folder's own lock
            log.info(f"wrote the batch page {write_batch_page(args.batch)}")
        return 0
    chosen = sources.resolve_all(dict.fromkeys(args.fabric or brdf.PRESETS), what="--fabric")
    names = tuple(s.label for s in chosen)
    fits = {}
    for item in args.fit or ():
        name, sep, path = item.partition("=")
        if not sep or name not in names:
            raise ValueError(f"--fit must be FABRIC=PATH/results.json with FABRIC one of "
                             f"{', '.join(names)}; got {item!r}")
        if not os.path.lexists(path):   # a link or a FIFO: read_results names it
            raise ValueError(f"--fit {item!r}: no such file {path!r}")
        read_results(path)          # a damaged file: one line naming it and the field
        fits[name] = path
    for s in chosen:                # a fit folder given as --fabric: its own fit section
        if s.kind == "fit" and s.label not in fits:
            fits[s.label] = str(s.path / "results.json")
    fabrics = [s.label if s.kind == "preset" else (s.label, s.brdf) for s in chosen]
    index = build_report(fabrics, args.output, progress=cliutil.progress(args),
                         quality=args.quality,
                         fit_results=fits, measured=args.measured,
                         render_engine=args.engine,
                         command=shlex.join(["microcyl", *sys.argv[1:]]))
    labels = [g[0] for g in STANDARD_GEOMETRIES]
    print(f"{'luminance f_r (1/sr)':31s} " + " ".join(f"{lab:>19s}" for lab in labels))
    for name, src in zip(names, chosen):
        lum = standard_luminance(src.brdf)
        print(f"{shown(name):31s} " + " ".join(f"{x:19.6g}" for x in lum))
    log.info(f"wrote {index} (data: {index.parent / 'summary.json'})")
    return 0
