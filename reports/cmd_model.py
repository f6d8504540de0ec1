"""Verbs about the model itself: ``fabrics``, ``eval``, ``report``."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import brdf
from reports import cliutil

#: Standard geometries of the summary: (label, theta_i, phi_i, theta_o, phi_o), degrees.
STANDARD_GEOMETRIES = (
    ("normal", 0.0, 0.0, 0.0, 0.0),
    ("specular 30 warp", 30.0, 0.0, 30.0, 180.0),
    ("specular 30 weft", 30.0, 90.0, 30.0, 270.0),
    ("specular 60 warp", 60.0, 0.0, 60.0, 180.0),
    ("retro 45 warp", 45.0, 0.0, 45.0, 0.0),
    ("oblique 60/30 at 45", 60.0, 45.0, 30.0, 225.0),
)


def register(sub):
    """Add ``fabrics``, ``eval`` and ``report`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser("fabrics", help="list the presets and their parameters",
                       description="List the paper's six fabrics (Table II) and their "
                                   "parameters (gamma and offsets in degrees).")
    p.set_defaults(func=run_fabrics)

    p = sub.add_parser("eval", help="evaluate f_r of a preset at one pair of directions",
                       description="Print the RGB BRDF f_r (1/sr, no cosine) of a preset at "
                                   "one (wi, wo) pair given by polar angle and azimuth in "
                                   "degrees (azimuth from the warp, +x).")
    p.add_argument("fabric", metavar="FABRIC", help=f"one of {', '.join(brdf.PRESETS)}")
    p.add_argument("--wi", type=cliutil.parse_angle_pair, required=True, metavar="THETA,PHI",
                   help="direction toward the light, degrees")
    p.add_argument("--wo", type=cliutil.parse_angle_pair, required=True, metavar="THETA,PHI",
                   help="direction toward the viewer, degrees")
    cliutil.add_fabric_options(p)
    p.set_defaults(func=run_eval)

    p = sub.add_parser("report", help="write the report (summary.json and printed table)",
                       description="The main job: evaluate every preset at standard "
                                   "geometries and write DIR/summary.json.")
    p.add_argument("--fabric", action="append", metavar="NAME", choices=brdf.PRESETS,
                   help="limit to these presets (repeatable; default all)")
    p.add_argument("-o", "--output", default="report", metavar="DIR",
                   help="output folder (default ./report)")
    p.set_defaults(func=run_report)


def _check_fabric(name: str) -> None:
    if name not in brdf.PRESETS:
        raise ValueError(f"unknown fabric {name!r}; valid presets are {', '.join(brdf.PRESETS)}")


def format_fabrics_table(names=brdf.PRESETS) -> str:
    """The presets' parameters as a text table (gamma and offsets in degrees)."""
    head = (f"{'fabric':31s} {'thr':3s} {'eta':>6s} {'albedo (R, G, B)':>24s} {'kd':>4s} "
            f"{'g_s':>5s} {'g_v':>5s} {'area':>5s}  offsets / lengths")
    lines = [head, "-" * len(head)]
    for name in names:
        for j, t in enumerate(brdf.preset_threads(name), 1):
            alb = ", ".join(f"{a:.4g}" for a in t.albedo)
            off = ", ".join(f"{o:g}" for o in t.offsets)
            lng = ", ".join(f"{x:g}" for x in t.lengths)
            lines.append(f"{name if j == 1 else '':31s} T{j:<2d} {t.eta:6.3f} {alb:>24s} "
                         f"{t.kd:4.2f} {t.gamma_s:5.1f} {t.gamma_v:5.1f} {t.area:5.2f}  "
                         f"[{off}] / [{lng}]")
    return "\n".join(lines)


def run_fabrics(args):
    print(format_fabrics_table())
    return 0


def run_eval(args):
    _check_fabric(args.fabric)
    fab = cliutil.fabric_from_args(args.fabric, args)
    wi = brdf.directions.from_angles(*np.radians(args.wi))
    wo = brdf.directions.from_angles(*np.radians(args.wo))
    f = fab.eval(wi, wo)
    print(f"f_r [1/sr]  R {f[0]:.9g}  G {f[1]:.9g}  B {f[2]:.9g}")
    return 0


def summary(names=brdf.PRESETS) -> dict:
    """f_r of each preset at the standard geometries, with the parameters used."""
    out = {"units": {"f_r": "1/sr", "angles": "degrees"}, "geometries": [], "fabrics": {}}
    for label, ti, pi_, to, po in STANDARD_GEOMETRIES:
        out["geometries"].append({"label": label, "theta_i": ti, "phi_i": pi_,
                                  "theta_o": to, "phi_o": po})
    angles = np.radians([g[1:] for g in STANDARD_GEOMETRIES])
    wi = brdf.directions.from_angles(angles[:, 0], angles[:, 1])
    wo = brdf.directions.from_angles(angles[:, 2], angles[:, 3])
    for name in names:
        fab = brdf.fabric(name)
        f = fab.eval(wi, wo)
        out["fabrics"][name] = {
            "parameters": fab.as_dict(),
            "f_r": {g[0]: [float(v) for v in row] for g, row in zip(STANDARD_GEOMETRIES, f)},
        }
    return out


def run_report(args):
    names = tuple(dict.fromkeys(args.fabric)) if args.fabric else brdf.PRESETS
    out_dir = cliutil.check_writable_dir(Path(args.output))
    data = summary(names)
    cliutil.atomic_write_json(out_dir / "summary.json", data)
    labels = [g[0] for g in STANDARD_GEOMETRIES]
    print(f"{'fabric':31s} " + " ".join(f"{lab:>20s}" for lab in labels))
    print(" " * 32 + " ".join(f"{'f_r luminance 1/sr':>20s}" for _ in labels))
    for name in names:
        vals = data["fabrics"][name]["f_r"]
        lum = [0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2] for v in vals.values()]
        print(f"{name:31s} " + " ".join(f"{x:20.6g}" for x in lum))
    print(f"wrote {out_dir / 'summary.json'}")
    return 0
