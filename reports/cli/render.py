"""The ``microcyl render`` verb: render a scene of cloth to OpenEXR and PNG.

    microcyl render SCENE FABRIC [--masking on|off] [--reweighting on|off]
        [--tangent-samples N] [--tangent-sampling midpoint|control_points]
        [--transmission half_angle|longitudinal] [--gap incident|outgoing] [--rotation DEG]
        [--width 1280] [--height 720] [--spp 16] [--exposure auto|STOPS|SCALEx] [--seed 0]
        [--light-radius R] [--workers N] [--engine builtin|mitsuba] [--variant V]
        [--max-depth N] [--no-progress] [-q] -o out.exr

FABRIC (positional or ``--fabric``) is a preset, a ``microcyl fit`` output folder (the fabric
of its posterior medians, as ``microcyl export`` writes it), such an exported ``.json`` or
``.xml`` file, or a measured ``.bsdf`` or ``.binary`` table (built-in engine)
(:func:`analysis.sources.resolve`); the variant options given change a fabric further.
``-o out.exr`` writes the float32 linear EXR and an sRGB PNG beside it (``out.png``);
``-o out.png`` writes the PNG only.  The PNG's exposure is automatic by default (the 99th
percentile of the cloth's pixels shown at 0.9, :mod:`reports.render.exposure`); ``--exposure 1.5``
gives it in stops (2**1.5 times the linear values), ``--exposure 4x`` as a scale; the EXR stays
linear and records the exposure in its header (``microcyl_exposure_stops``, ...).  Every
argument is checked (scene, fabric and its options, size, output folder, engine and variant)
before rendering starts.
Beside the image goes ``out.scene.json`` (:mod:`reports.render.scenefile`: geometry, camera,
lights, exposure, integrator, spp, seed, engine and the fabric with every parameter);
``microcyl render --scene out.scene.json -o again.exr`` renders the same image again (the
options given, and a FABRIC, replace the file's).
``--engine mitsuba`` renders the same scene in Mitsuba 3 (:mod:`reports.mitsuba.render`: the
``microcylinder`` BSDF, the path integrator with ``--max-depth`` bounces, ``--variant``
llvm_ad_rgb where LLVM works, else scalar_rgb).
"""

from __future__ import annotations

import dataclasses
import logging
import math
from pathlib import Path

import brdf
from reports.cli import lazy
from reports.cli import options as cliutil
from reports.mitsuba import render as mitsuba_render
from reports.render.lights import PointLight
from reports.render.scenes import make_scene

__all__ = ["register", "run"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``render`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "render", help="render a scene of cloth (curtain, cylinder, sphere, patch)",
        description="Render a scene of cloth shaded with the microcylinder BRDF to a float32 "
                    "OpenEXR (linear RGB) and an sRGB PNG.")
    p.add_argument("scene", metavar="SCENE", nargs="?", default=None,
                   help="curtain, cylinder, sphere or patch (none with --scene)")
    p.add_argument("--scene", dest="scene_file", default=None, metavar="FILE",
                   help="render the scene of a scene file (IMAGE.scene.json, written beside "
                        "every render); the options given replace its settings, a FABRIC its "
                        "fabric")
    cliutil.add_fabric_argument(p, tables=True)
    cliutil.add_fabric_options(p)
    p.add_argument("--width", type=int, default=None, help="pixels, at most 1280 (1280)")
    p.add_argument("--height", type=int, default=None, help="pixels, at most 720 (720)")
    p.add_argument("--spp", type=int, default=None, help="samples per pixel (16)")
    p.add_argument("--exposure", default=None, metavar="E",
                   help="PNG exposure: auto (the 99th percentile of the cloth's pixels shown "
                        "at 0.9), stops (1.5: 2**1.5 times the linear values) or a scale "
                        "(4x) (auto); recorded in the EXR's header")
    p.add_argument("--seed", type=int, default=None, help="random seed (0)")
    p.add_argument("--light-radius", type=float, default=None, metavar="R",
                   help="turn the scene's point light into a disc of this radius")
    p.add_argument("--workers", type=int, default=None, help="processes (all cores)")
    cliutil.add_engine_option(p)
    p.add_argument("--variant", default=None, metavar="V",
                   help="Mitsuba variant: llvm_ad_rgb, scalar_rgb or cuda_ad_rgb (llvm_ad_rgb "
                        "where LLVM works, else scalar_rgb); --engine mitsuba only")
    p.add_argument("--max-depth", type=int, default=None, metavar="N",
                   help="longest light path, 2 = direct light only, -1 unbounded (8); "
                        "--engine mitsuba only")
    cliutil.add_quiet_options(p)
    p.add_argument("-o", "--output", required=True, metavar="FILE",
                   help="out.exr (writes out.png beside it) or out.png")
    p.set_defaults(func=run)


#: The engines of ``--engine`` (auto: mitsuba where it runs, else builtin).
ENGINES = cliutil.ENGINE_CHOICES


def _engine_options(args, fabric):
    """Check ``--engine``, ``--variant`` and ``--max-depth`` (``auto`` resolved to an engine,
    in ``args.engine``, by :func:`reports.mitsuba.render.auto_engine`); return the Mitsuba variant and depth (None,
    None for the built-in engine)."""
    if args.engine not in ENGINES:
        raise ValueError(f"--engine {args.engine!r}: must be one of {', '.join(ENGINES)}")
    if args.engine == "auto":
        args.engine = mitsuba_render.auto_engine(fabric)
    if args.engine == "builtin":
        for name in ("variant", "max_depth"):
            if getattr(args, name) is not None:
                raise ValueError(f"--{name.replace('_', '-')}: only with --engine mitsuba "
                                 f"(the built-in renderer computes direct light alone)")
        return None, None
    max_depth = 8 if args.max_depth is None else args.max_depth
    if not (max_depth == -1 or 1 <= max_depth <= 1024):
        raise ValueError(f"--max-depth {max_depth}: must be -1 (unbounded) or 1 to 1024")
    if not isinstance(fabric, brdf.Fabric):
        raise ValueError("--engine mitsuba renders a brdf.Fabric only")
    try:
        variant = mitsuba_render.pick_variant(args.variant)
    except ImportError as exc:
        raise ValueError(str(exc)) from None
    return variant, max_depth


#: The render settings of a scene file a command line may replace, and their defaults.
SETTINGS = {"width": 1280, "height": 720, "spp": 16, "seed": 0, "variant": None,
            "max_depth": None}


def _scene_and_fabric(args):
    """The scene to render and its fabric text or object: from SCENE and FABRIC, or from
    ``--scene FILE`` (its settings filling in the options not given, in ``args``)."""
    if args.scene_file is None:
        if args.scene is None:
            raise ValueError("SCENE is required (curtain, cylinder, sphere or patch), or "
                             "--scene FILE")
        for key, default in SETTINGS.items():
            if getattr(args, key) is None and default is not None:
                setattr(args, key, default)
        args.exposure = "auto" if args.exposure is None else args.exposure
        return make_scene(args.scene), cliutil.fabric_argument(args)
    if args.scene is not None:
        if args.fabric is not None:
            raise ValueError(f"SCENE {args.scene!r}: give no scene name with --scene "
                             f"{args.scene_file}")
        args.fabric, args.scene = args.scene, None      # the one positional is FABRIC
    sf = lazy.renderer().scenefile.read_scene_file(args.scene_file)
    for key in SETTINGS:
        if getattr(args, key) is None:
            setattr(args, key, sf.settings[key])
    if args.engine == cliutil.DEFAULT_ENGINE:       # the file's engine, unless another given
        args.engine = sf.settings["engine"]
    if args.exposure is None:
        stops = sf.settings["exposure_stops"]
        args.exposure = "auto" if stops is None else repr(stops)
    if args.fabric is None and args.fabric_option is None:
        if sf.fabric is None:
            raise ValueError(f"{args.scene_file}: its fabric is a measured table, not recorded "
                             f"in the file; give FABRIC")
        if cliutil.fabric_options(args):
            raise ValueError("the variant options (--masking, ...) change a FABRIC given; the "
                             "scene file's fabric has every parameter already")
        return sf.scene, sf.fabric
    return sf.scene, cliutil.fabric_argument(args)


def run(args):
    """Check every argument, render, write the files; return 0."""
    built_in = lazy.renderer()
    exposure, imageio = built_in.exposure, built_in.imageio
    scene, fabric = _scene_and_fabric(args)
    built_in.engine.check_size(args.width, args.height, args.spp)
    stops = exposure.parse_exposure(args.exposure)
    if args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be a non-negative integer")
    out = Path(args.output)
    suffix = out.suffix.lower()
    if suffix not in (".exr", ".png"):
        raise ValueError(f"-o {args.output}: the output must end in .exr or .png")
    imageio.check_output(out)
    if isinstance(fabric, str):
        fabric = cliutil.source_from_args(fabric, args, tables=True).brdf
    if args.light_radius is not None:
        if not (args.light_radius >= 0 and math.isfinite(args.light_radius)):
            raise ValueError(f"--light-radius {args.light_radius}: must be >= 0")
        if not isinstance(scene.light, PointLight):
            raise ValueError(f"--light-radius: scene {scene.name!r} has a directional light")
        scene = scene.replace(light=dataclasses.replace(scene.light, radius=args.light_radius))
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers {args.workers}: must be at least 1")
    variant, max_depth = _engine_options(args, fabric)
    expo, written = built_in.files.render_to_files(
        scene, fabric, out, stops=stops, engine=args.engine, width=args.width,
        height=args.height, spp=args.spp, seed=args.seed, workers=args.workers,
        progress=cliutil.progress(args), variant=variant, max_depth=max_depth)
    log.info(f"{expo.describe()}; wrote " + ", ".join(str(w) for w in written))
    return 0
