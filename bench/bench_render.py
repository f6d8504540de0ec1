"""Time the cylinder render at 1280 x 720 and 16 samples per pixel (the issue's budget: 2 min),
with the scene's sky (MIS of Fabric.sample and cosine directions) and without it, interleaved.

Usage: python bench/bench_render.py [FABRIC] [--width W] [--height H] [--spp N] [--workers N]
Prints the wall times and their ratio.  Other work on the machine slows it down: note the
load average printed beside the figures.
"""

import argparse
import os
import time

import numpy as np

import reports.render as R
from reports.scenes import make_scene


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("fabric", nargs="?", default="velvet")
    p.add_argument("--scene", default="cylinder")
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=720)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--masking", choices=("on", "off"), default="on")
    a = p.parse_args()
    import brdf
    fab = brdf.fabric(a.fabric, masking=a.masking == "on")
    scene = make_scene(a.scene)
    times = {}
    for label, sc in (("sky", scene), ("key light only", scene.replace(environment=None))):
        t0 = time.perf_counter()
        img = R.render(sc, fab, width=a.width, height=a.height, spp=a.spp, workers=a.workers,
                       progress=True)
        times[label] = dt = time.perf_counter() - t0
        load = os.getloadavg()
        print(f"{a.scene} {a.fabric} masking={a.masking} {a.width}x{a.height} spp={a.spp}, "
              f"{label}: {dt:.1f} s wall (budget 120 s); mean radiance "
              f"{float(np.mean(img)):.4g}; load average {load[0]:.2f} {load[1]:.2f} "
              f"{load[2]:.2f}; {len(os.sched_getaffinity(0))} cores")
    if scene.environment is not None:
        print(f"the sky costs {times['sky'] / times['key light only']:.2f} x the key light alone")


if __name__ == "__main__":
    main()
