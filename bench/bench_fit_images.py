"""What a camera tells against what an instrument tells: ``fit-images`` against ``measure`` +
``fit`` on one hidden fabric.

The hidden fabric is linen_plain with thread 1's kd, gamma_s and gamma_v moved (0.45, 8 deg,
30 deg; the start, linen_plain, has 0.3, 12, 24). The camera: six images (cylinder and
curtain, three light directions each, :func:`reports.render.truthset.write_truth_images`,
128 x 72 at 16 samples a pixel, shot noise 1e-4 a unit, read noise 0.002), fitted by
``microcyl fit-images`` at 4 samples a pixel. The instrument: ``microcyl measure`` of the same
fabric on the ``full:15:30`` grid at SNR 20, fitted by ``microcyl fit`` (emcee) with the same
free parameters. Each runs as a user runs it (a subprocess); the script prints each
parameter's truth, median and 95% interval from either, the intervals' widths and their
ratio, the wall times and the machine's load.

    .venv/bin/python bench/bench_fit_images.py [--free kd1,gamma_s1,gamma_v1] [--keep DIR]
    .venv/bin/python bench/bench_fit_images.py --coverage 20 [--engine mitsuba]

``--coverage N``: N image sets of independent noise (the cylinder alone, 64 x 36, images at 8
samples a pixel or ``--image-spp``, the fit's at 4, ``--mc-seeds`` 3), each fitted in this
process with kd1 and gamma_s1 free; prints how often each truth fell inside its 68% and 95%
intervals.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import brdf
from analysis.fabricfile import write_fabric_file
from reports.render.truthset import write_truth_images

#: The hidden values (any of them may be freed with --free).
TRUTH = {"kd1": 0.45, "gamma_s1": 8.0, "gamma_v1": 30.0, "albedo1_g": 0.3}
SHOT, READ = 1e-4, 0.002


def _run(argv) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "reports", *argv, "-q"], check=True)
    return time.perf_counter() - t0


def coverage(n: int, engine: str, work: Path, image_spp: int = 8,
             mc_seeds: int = 3, first: int = 0) -> None:
    """The intervals' coverage over ``n`` image sets (module notes)."""
    from analysis.imagefit import NoiseModel, Observation, fit_images
    from reports.render.files import render_image
    from reports.render.imageio import read_exr
    from reports.render.scenefile import read_scene_file, scene_file_path

    truth = {"kd1": 0.45, "gamma_s1": 8.0}
    fabric = brdf.fabric("linen_plain").with_values(truth)
    variant, depth = ("llvm_ad_rgb", 2) if engine == "mitsuba" else (None, None)

    fit_spp = 4

    def render(scene, fab, seed):
        return render_image(scene, fab, engine=engine, width=64, height=36, spp=fit_spp, seed=seed,
                            workers=1, variant=variant, max_depth=depth)

    hits = {k: [0, 0] for k in truth}
    t0 = time.perf_counter()
    for rep in range(first, first + n):
        folder = work / f"set{rep}"
        folder.mkdir(parents=True, exist_ok=True)
        paths = write_truth_images(folder, fabric, width=64, height=36, spp=image_spp,
                                   shot=SHOT, read=READ, seed=1000 + 10 * rep, scenes=("cylinder",),
                                   engine=engine, variant=variant)
        obs = [Observation(p.name, read_exr(p), read_scene_file(scene_file_path(p)).scene,
                           1001 + 10 * rep + k, fit_spp / image_spp) for k, p in enumerate(paths)]
        doc = fit_images(obs, brdf.fabric("linen_plain"), "kd1,gamma_s1", folder / "fit",
                         render=render, noise=NoiseModel(SHOT, READ), mc_seeds=mc_seeds)
        line = []
        for k, true in truth.items():
            p = doc["parameters"][k]
            hits[k][0] += p["lo68"] < true < p["hi68"]
            hits[k][1] += p["lo95"] < true < p["hi95"]
            z = (p["median"] - true) / (0.5 * (p["hi68"] - p["lo68"]))
            line.append(f"{k} {p['median']:.4g} ({z:+.2f} sd)")
        print(f"set {rep}: " + ", ".join(line) + f"; chi2 ratio "
              f"{doc['noise']['chi2_ratio']:.3f}", flush=True)
    print(f"{engine}, images at {image_spp} spp, {mc_seeds} Monte Carlo seeds: {n} image "
          f"sets ({first} to {first + n - 1}) in {time.perf_counter() - t0:.0f} s, "
          f"load {os.getloadavg()[0]:.1f}")
    for k, (h68, h95) in hits.items():
        print(f"{k}: inside the 68% interval {h68} of {n}, the 95% interval {h95} of {n}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--free", default="kd1,gamma_s1,gamma_v1")
    ap.add_argument("--geometry", default="full:15:30")
    ap.add_argument("--snr", default="20")
    ap.add_argument("--fit-time-limit", default="600", help="microcyl fit's --time-limit")
    ap.add_argument("--keep", default=None, help="folder for the files (default: temporary)")
    ap.add_argument("--coverage", type=int, default=0, metavar="N",
                    help="instead: the intervals' coverage over N image sets")
    ap.add_argument("--engine", default="builtin", choices=("builtin", "mitsuba"),
                    help="--coverage's renderer (builtin)")
    ap.add_argument("--image-spp", type=int, default=8, help="--coverage's images' spp (8)")
    ap.add_argument("--mc-seeds", type=int, default=3, help="--coverage's fits' (3)")
    ap.add_argument("--first-set", type=int, default=0,
                    help="--coverage's first image set (its noise's seeds): 0")
    args = ap.parse_args()
    if args.coverage:
        coverage(args.coverage, args.engine,
                 Path(args.keep or tempfile.mkdtemp(prefix="bench_fit_images_")),
                 args.image_spp, args.mc_seeds, args.first_set)
        return 0
    free = args.free.split(",")
    truth = {k: TRUTH[k] for k in free}
    work = Path(args.keep or tempfile.mkdtemp(prefix="bench_fit_images_"))
    work.mkdir(parents=True, exist_ok=True)
    fabric = brdf.fabric("linen_plain").with_values(truth)
    print(f"load before: {os.getloadavg()[0]:.1f} (1 min), {os.cpu_count()} cores; "
          f"files in {work}")
    t0 = time.perf_counter()
    (work / "images").mkdir(exist_ok=True)
    images = write_truth_images(work / "images", fabric, spp=16, shot=SHOT, read=READ, seed=5)
    t_images = time.perf_counter() - t0
    t_camera = _run(["fit-images", *map(str, images), "--fabric", "linen_plain", "--free",
                     args.free, "--shot-noise", str(SHOT), "--read-noise", str(READ),
                     "--spp", "4", "--rendered", "-o", str(work / "camera")])
    write_fabric_file(work / "hidden.json", fabric)
    t_measure = _run(["measure", str(work / "hidden.json"), "--geometry", args.geometry,
                      "--snr", args.snr, "--seed", "5", "-o", str(work / "table.csv")])
    t_instrument = _run(["fit", str(work / "table.csv"), "--fabric", "linen_plain", "--free",
                         args.free, "--time-limit", args.fit_time_limit, "--no-plots",
                         "-o", str(work / "instrument")])
    cam = json.loads((work / "camera" / "results.json").read_text())
    ins = json.loads((work / "instrument" / "results.json").read_text())
    print(f"load after: {os.getloadavg()[0]:.1f}")
    print(f"camera: 6 images 128 x 72, rendered in {t_images:.0f} s; fit-images "
          f"{t_camera:.0f} s ({cam['fit']['renders']} renders, converged "
          f"{cam['converged']}, chi2 ratio {cam['noise']['chi2_ratio']:.3f})")
    print(f"instrument: measure {args.geometry} SNR {args.snr} in {t_measure:.0f} s; fit "
          f"{t_instrument:.0f} s (converged {ins['converged']}: {ins['reason']})")
    print(f"{'parameter':<10} {'truth':>7} | {'camera median [95%]':>28} {'width':>8} | "
          f"{'instrument median [95%]':>28} {'width':>8} | camera/instrument width")
    for name, true in truth.items():
        c, i = cam["parameters"][name], ins["parameters"][name]
        wc, wi = c["hi95"] - c["lo95"], i["hi95"] - i["lo95"]
        inside = ("in" if c["lo95"] < true < c["hi95"] else "OUT",
                  "in" if i["lo95"] < true < i["hi95"] else "OUT")
        print(f"{name:<10} {true:>7.4g} | {c['median']:>8.4g} [{c['lo95']:>7.4g}, "
              f"{c['hi95']:>7.4g}] {inside[0]:>3} {wc:>8.3g} | {i['median']:>8.4g} "
              f"[{i['lo95']:>7.4g}, {i['hi95']:>7.4g}] {inside[1]:>3} {wi:>8.3g} | "
              f"{wc / wi:.3g}")
    for who, doc in (("camera", cam), ("instrument", ins)):
        for w in doc["warnings"]:
            print(f"{who} warning ({w['kind']}): {w['message']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
