"""The ``microcyl fit-images`` verb: a fabric's parameters from photographs.

    microcyl fit-images IMAGE.exr... --fabric START --free P1,P2,... -o DIR
        [--scene FILE]... [--shot-noise K] [--read-noise S] [--spp N] [--seed N]
        [--rendered] [--mc-seeds 4] [--max-steps 30] [--workers N] [--no-plots]
        [--no-progress] [-q]

Each IMAGE (linear RGB OpenEXR) comes with the scene it shows: ``IMAGE.scene.json`` beside it
(``microcyl render`` writes one) or ``--scene FILE`` (once for every image, or once an image,
in order). The fit renders each scene with the engine, size and samples its file names
(``--spp`` replaces the samples), two seeds an image: ``--seed`` and ``--seed`` + 104729
(default: the file's seed + 1, so no render reuses the image's random numbers). With
``--rendered`` the images are renders of their scene files (a test with the truth known): their
own Monte Carlo noise, at the file's samples a pixel, joins the noise model. The work is
:func:`analysis.imagefit.fit_images` (method, noise model, ``results.json``); this module reads
the inputs, passes the renderer in, and prints the summary.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

from analysis.imagefit import NoiseModel, Observation, fit_images
from gonio.terminal import shown
from reports.cli import lazy
from reports.cli import options as cliutil

__all__ = ["register", "run", "format_summary"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``fit-images`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "fit-images", help="estimate a fabric's parameters from rendered or photographed "
                           "images of known scenes",
        description="Fit free parameters of a microcylinder fabric to linear RGB images of "
                    "known scenes (IMAGE.scene.json): Levenberg-Marquardt on renders of two "
                    "independent seeds, intervals from the Laplace approximation under a "
                    "noise model of camera shot and read noise and the render's Monte Carlo "
                    "noise.")
    p.add_argument("images", nargs="+", metavar="IMAGE", help="linear RGB OpenEXR images")
    p.add_argument("--fabric", required=True, metavar="START",
                   help="the start and the fixed values: a preset, a fit folder or a fabric "
                        "file")
    p.add_argument("--free", required=True, metavar="NAMES",
                   help="comma-separated free parameters (kd1,gamma_s1,...; albedo1 is its "
                        "three channels)")
    p.add_argument("--scene", action="append", default=None, metavar="FILE",
                   help="scene file (once for all images, or once an image); default "
                        "IMAGE.scene.json beside each image")
    p.add_argument("--shot-noise", type=float, default=0.0, metavar="K",
                   help="camera shot noise: variance per unit of linear value (0)")
    p.add_argument("--read-noise", type=float, default=0.0, metavar="S",
                   help="camera read noise: sd in linear units (0)")
    p.add_argument("--spp", type=int, default=None, help="samples per pixel of the fit's "
                                                         "renders (the scene file's)")
    p.add_argument("--seed", type=int, default=None,
                   help="seed of the fit's renders (the scene file's + 1)")
    p.add_argument("--rendered", action="store_true",
                   help="the images are renders of their scene files at the files' samples "
                        "a pixel (a test with the truth known), not photographs: their own "
                        "Monte Carlo noise joins the noise model")
    p.add_argument("--mc-seeds", type=int, default=4, metavar="K",
                   help="renders of independent seeds for the Monte Carlo noise (4)")
    p.add_argument("--max-steps", type=int, default=30, metavar="N",
                   help="optimizer steps at most (30)")
    p.add_argument("--workers", type=int, default=1,
                   help="processes of each built-in render (1)")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    cliutil.add_quiet_options(p)
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    p.set_defaults(func=run)


def _scene_files(args) -> list[Path]:
    if args.scene is None:
        return [lazy.renderer().scenefile.scene_file_path(i) for i in args.images]
    if len(args.scene) == 1:
        return [Path(args.scene[0])] * len(args.images)
    if len(args.scene) != len(args.images):
        raise ValueError(f"--scene: given {len(args.scene)} times for {len(args.images)} "
                         f"images; give it once, or once an image")
    return [Path(s) for s in args.scene]


def _observations(args) -> list:
    """Each image read with its scene (the render's settings in ``Observation.scene``)."""
    rend = lazy.renderer()
    if args.spp is not None:
        rend.engine.check_size(1, 1, args.spp)
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be a non-negative integer")
    if args.workers < 1:
        raise ValueError(f"--workers {args.workers}: must be at least 1")
    scenes = [rend.scenefile.read_scene_file(f) for f in _scene_files(args)]
    obs = []
    for path, sf in zip(args.images, scenes):
        image = rend.imageio.read_exr(path)
        st = sf.settings
        if image.shape[:2] != (st["height"], st["width"]):
            raise ValueError(f"{path}: {image.shape[1]} x {image.shape[0]} pixels, its scene "
                             f"{st['width']} x {st['height']}")
        spp = st["spp"] if args.spp is None else args.spp
        job = (sf.scene, st["engine"], st["width"], st["height"], spp, st["variant"],
               st["max_depth"])
        seed = st["seed"] + 1 if args.seed is None else args.seed
        image_mc = spp / st["spp"] if args.rendered else 0.0
        obs.append(Observation(Path(path).name, image, job, seed, image_mc))
    return obs


def _renderer(workers):
    """``render(job, fabric, seed)`` of :func:`analysis.imagefit.fit_images`."""
    files = lazy.renderer().files

    def render(job, fabric, seed):
        scene, engine, width, height, spp, variant, max_depth = job
        return files.render_image(scene, fabric, engine=engine, width=width, height=height,
                                  spp=spp, seed=seed, workers=workers, variant=variant,
                                  max_depth=max_depth)
    return render


def format_summary(doc) -> str:
    """The parameters' medians and 95% intervals, the verdict and the noise, as lines."""
    lines = [f"{'parameter':<12} {'median':>10} {'95% interval':>24}  unit"]
    for name, p in doc["parameters"].items():
        lines.append(f"{name:<12} {p['median']:>10.4g} [{p['lo95']:>10.4g}, {p['hi95']:>10.4g}]"
                     f"  {p['unit']}")
    n = doc["noise"]
    lines.append(f"{doc['reason']}; chi2 {n['chi2']:.6g} against {n['chi2_expected']:.6g} "
                 f"expected from the noise model (ratio {n['chi2_ratio']:.3f}); "
                 f"{doc['fit']['renders']} renders in {doc['fit']['seconds']:.1f} s")
    lines += [f"warning ({w['kind']}): {w['message']}" for w in doc["warnings"]]
    return "\n".join(lines)


def run(args) -> int:
    """Check the inputs, fit, print the summary; return 0."""
    fabric = cliutil.source_from_args(args.fabric, args, what="--fabric").brdf
    noise = NoiseModel(args.shot_noise, args.read_noise)
    out = cliutil.check_writable_dir(Path(args.output))
    obs = _observations(args)
    plots = None if args.no_plots else lazy.plots().imagefit.write_plots
    doc = fit_images(obs, fabric, args.free, out, render=_renderer(args.workers), noise=noise,
                     mc_seeds=args.mc_seeds, max_iter=args.max_steps, plots=plots,
                     progress=cliutil.progress(args),
                     log=lambda line: args.quiet or print(shown(line), file=sys.stderr,
                                                          flush=True))
    print(shown(format_summary(doc), lines=True))
    log.info(f"wrote {out / 'results.json'}")
    return 0
