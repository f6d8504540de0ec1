"""Time the cylinder render at 1280 x 720 and 16 samples per pixel (the issue's budget: 2 min)
with the built-in renderer and with Mitsuba 3 (llvm_ad_rgb, path tracing, 8 bounces),
interleaved, and Fabric.sample's throughput.

Usage: python bench/bench_render.py [FABRIC] [--width W] [--height H] [--spp N] [--workers N]
    [--rounds R] [--sky]
Prints the wall time of each render, the median of each engine and their ratio; Mitsuba's
first render is timed apart (it traces the scene and has LLVM compile the kernel, unless
Dr.Jit's cache in ~/.drjit holds it). ``--sky`` times the built-in renderer with the scene's
sky and without it instead. Other work on the machine slows it down: note the load average
printed beside the figures.
"""

import argparse
import os
import time

import numpy as np

import brdf
import reports.render.engine as R
from reports.mitsuba import render as mitsuba_render
from reports.render.scenes import make_scene


def _stamp():
    load = os.getloadavg()
    return (f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; "
            f"{len(os.sched_getaffinity(0))} cores")


def sampler_rate(fab, n=200_000) -> float:
    """Fabric.sample draws per second (draw, pdf and f_r) for a viewer at 30 degrees."""
    wo = brdf.directions.from_angles(np.radians(30.0), np.radians(45.0))
    u = np.random.default_rng(0).random((n, 2))
    t0 = time.perf_counter()
    fab.sample(wo, u)
    return n / (time.perf_counter() - t0)


def _timed(fn):
    t0 = time.perf_counter()
    img = fn()
    return time.perf_counter() - t0, float(np.mean(img))


def engines(a, fab, scene):
    """Built-in and Mitsuba renders of the same scene, interleaved."""
    kw = dict(width=a.width, height=a.height, spp=a.spp, workers=a.workers)
    variant = mitsuba_render.pick_variant(a.variant)
    head = f"{a.scene} {a.fabric} masking={a.masking} {a.width}x{a.height} spp={a.spp}"
    builtin = lambda: R.render(scene, fab, progress=False, **kw)  # noqa: E731
    mitsuba = lambda: mitsuba_render.render_mitsuba(  # noqa: E731
        scene, fab, variant=variant, progress=False, **kw)
    dt, mean = _timed(mitsuba)
    print(f"{head}, mitsuba {variant} first render (tracing, compile or cache): {dt:.1f} s; "
          f"{_stamp()}", flush=True)
    times = {"builtin": [], "mitsuba": []}
    for r in range(a.rounds):
        for label, fn in (("builtin", builtin), ("mitsuba", mitsuba)):
            dt, mean = _timed(fn)
            times[label].append(dt)
            print(f"{head}, round {r + 1}, {label}: {dt:.1f} s wall; mean radiance {mean:.4g}; "
                  f"{_stamp()}", flush=True)
    tb, tm = (float(np.median(times[k])) for k in ("builtin", "mitsuba"))
    print(f"median: built-in {tb:.1f} s (direct light + sky), mitsuba {variant} {tm:.1f} s "
          f"(8 bounces); built-in / mitsuba = {tb / tm:.2f}")


def sky(a, fab, scene):
    """The built-in renderer with the scene's sky and without it."""
    times = {}
    for label, sc in (("sky", scene), ("key light only", scene.replace(environment=None))):
        dt, mean = _timed(lambda: R.render(sc, fab, width=a.width, height=a.height, spp=a.spp,
                                           workers=a.workers, progress=True))
        times[label] = dt
        print(f"{a.scene} {a.fabric} masking={a.masking} {a.width}x{a.height} spp={a.spp}, "
              f"{label}: {dt:.1f} s wall (budget 120 s); mean radiance {mean:.4g}; {_stamp()}")
    if scene.environment is not None:
        print(f"the sky costs {times['sky'] / times['key light only']:.2f} x the key light alone")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("fabric", nargs="?", default="velvet")
    p.add_argument("--scene", default="cylinder")
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=720)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--rounds", type=int, default=2)
    p.add_argument("--variant", default=None, help="Mitsuba variant (llvm_ad_rgb where it runs)")
    p.add_argument("--masking", choices=("on", "off"), default="on")
    p.add_argument("--sky", action="store_true", help="the sky's cost in the built-in renderer")
    a = p.parse_args()
    fab = brdf.fabric(a.fabric, masking=a.masking == "on")
    scene = make_scene(a.scene)
    print(f"Fabric.sample ({a.fabric}, viewer at 30 degrees): {sampler_rate(fab):.3g} samples/s; "
          f"{_stamp()}", flush=True)
    if a.sky:
        sky(a, fab, scene)
    else:
        engines(a, fab, scene)


if __name__ == "__main__":
    main()
