"""The ``microcyl export`` verb: a fabric for a renderer, with the fidelity of the export.

``microcyl export FABRIC --to openpbr|materialx|gltf|blender|mitsuba -o FILE``

FABRIC is any fabric source (:func:`analysis.sources.resolve`): a preset, a fit folder of any
model, an exported file. ``--to`` picks the target (default: the one that writes FILE's
suffix: .json/.xml Mitsuba's ``microcylinder`` dictionary or element, .mtlx OpenPBR,
.gltf/.glb glTF, .blend/.py Blender: a .blend where a Python with ``bpy`` can be reached,
else its script, said so). For every target but Mitsuba the target's sheen model is
projected from the source over a stated grid, for a fit folder its medians and ``--draws``
posterior draws; FILE.fidelity.json beside FILE says how closely the export follows the source
and where it cannot, and the terminal shows the same
(:func:`analysis.export.workflow.export_fabric`). The suffix and folder are checked before
anything is read.
"""

from __future__ import annotations

import logging

from analysis.export import TARGETS, HemisphereGrid, target_for, target_named
from analysis.export.projection import OBJECTIVES
from analysis.export.workflow import DEFAULT_DRAWS, export_fabric
from gonio.terminal import shown
from reports.cli import options as cliutil

__all__ = ["register", "run"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``export`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "export", help="write a fabric for a renderer (Mitsuba, OpenPBR, MaterialX, glTF, "
                       "Blender) with the export's fidelity",
        description="Write a fabric for a renderer: the Mitsuba 3 BSDF 'microcylinder' "
                    "(JSON dictionary or XML element), or the renderer's sheen model projected "
                    "from the fabric by least squares (OpenPBR fuzz and MaterialX sheen_bsdf "
                    "as .mtlx, glTF KHR_materials_sheen as .gltf/.glb, a Blender Principled "
                    "BSDF as .blend, built by bpy where MICROCYL_BLENDER_PYTHON names a Python "
                    "with bpy (or bpy imports here, or blender is on the PATH; else its "
                    "script is written, said so), or its script as .py). "
                    "FILE.fidelity.json beside FILE holds the fidelity of the export "
                    "(relative L2 error, albedos, CIEDE2000 of a lit patch) and what the "
                    "target cannot follow.")
    cliutil.add_fabric_argument(p)
    cliutil.add_fabric_options(p)
    p.add_argument("--to", choices=list(TARGETS), default=None,
                   help="target (default: the one that writes FILE's suffix; .mtlx: openpbr)")
    p.add_argument("-o", "--output", required=True, metavar="FILE",
                   help="file to write: " + "; ".join(
                       f"{t.name} {'/'.join(t.suffixes)}" for t in TARGETS.values()))
    p.add_argument("--draws", type=int, default=DEFAULT_DRAWS, metavar="N",
                   help="posterior draws of a fit folder to project (0: the medians only; "
                        "default %(default)s)")
    p.add_argument("--grid", default="9x12", metavar="THETAxPHI",
                   help="directions per hemisphere of the projection and fidelity grid: "
                        "polar x azimuth bins (default %(default)s)")
    p.add_argument("--objective", choices=list(OBJECTIVES), default="cos_cos",
                   help="what the projection fits: f_r cos(theta_i) cos(theta_o) (cos_cos, the "
                        "quantity whose error is reported) or f_r cos(theta_o) (cos_o)")
    p.add_argument("--albedo-scale", type=float, default=None, metavar="K",
                   help="multiply the source's f_r by K before projecting: a fit of a "
                        "relative table (CUReT) has no absolute level, and the export says "
                        "what it assumed (the directional albedo at normal incidence); K = "
                        "the cloth's measured albedo / that one")
    p.add_argument("--seed", type=int, default=0, help="seed of the draws (default 0)")
    p.set_defaults(func=run)


def _grid(text: str) -> HemisphereGrid:
    try:
        nt, npf = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise ValueError(f"--grid {text!r}: expected THETAxPHI, two integers such as "
                         f"9x12") from None
    try:
        return HemisphereGrid(nt, npf)
    except ValueError as exc:
        raise ValueError(f"--grid {text!r}: {exc}") from None


def run(args) -> int:
    """Check the output and options, resolve the fabric, export it, print its fidelity."""
    tgt = target_named(args.to) if args.to else target_for(args.output)
    out = cliutil.check_output_suffix(args.output, tgt.suffixes)
    grid = _grid(args.grid)
    src = cliutil.source_from_args(cliutil.fabric_argument(args), args)
    res = export_fabric(src, tgt.name, out, grid=grid, draws=args.draws, seed=args.seed,
                       objective=args.objective, albedo_scale=args.albedo_scale)
    log.info("wrote %s and %s", res.path, res.fidelity_path)
    if src.kind == "fit":
        med = src.median
        verdict = ("converged" if med.converged
                   else "NOT converged (medians of an unfinished fit)")
        print(shown(f"{med.preset or src.model}: medians of {', '.join(med.free)} "
                    f"({verdict}) -> {out}"))
    else:
        print(shown(f"{src.label} ({src.kind})"))
    for line in res.lines():
        print(shown(line))
    print(shown(f"fidelity -> {res.fidelity_path}"))
    return 0
