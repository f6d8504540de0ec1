"""What Dr.Jit's compilation adds to a Mitsuba render, with an empty kernel cache.

Usage: python bench/bench_mitsuba_compile.py [SCENE] [FABRIC ...] [--width W] [--height H]
    [--spp N]

Each fabric (default: velvet, linen_plain, silk_shot, a fitted-like velvet of three tangent
offsets) renders SCENE (default cylinder, 320 x 180, 4 spp, llvm_ad_rgb) twice in its own
process, one after another, all sharing one new, empty Dr.Jit cache (``HOME`` points at a
temporary folder). The first render of a process traces the scene and compiles its kernels
or finds them in the cache; the second reuses them. The difference is the cost of
compilation (first fabric) or of the cache (the others: the plugin's kernels take the
fabric's numbers as parameters, so every fabric with the same options shares them). Prints
both times for each fabric and the load average.
"""

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

CHILD = r"""
import sys, time
import brdf
from reports import mitsuba_render
from reports.mitsuba.plugin import fabric_from_dict
from reports.render.scenes import make_scene
scene, name, w, h, spp = sys.argv[1], sys.argv[2], *map(int, sys.argv[3:6])
fab = fabric_from_dict(eval(name)) if name.startswith("{") else brdf.fabric(name)
times = []
for _ in range(2):
    t0 = time.perf_counter()
    mitsuba_render.render_mitsuba(make_scene(scene), fab, width=w, height=h, spp=spp,
                                  progress=False, variant="llvm_ad_rgb")
    times.append(time.perf_counter() - t0)
print(f"{times[0]:.2f} {times[1]:.2f}")
"""

FITTED = repr({"fabric": "velvet", "offsets1": "-30, 10, 45", "lengths1": "1, 0.5",
               "eta2": 1.6, "gamma_s1": 9.0})


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scene", nargs="?", default="cylinder")
    p.add_argument("fabrics", nargs="*")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--height", type=int, default=180)
    p.add_argument("--spp", type=int, default=4)
    a = p.parse_args()
    fabrics = a.fabrics or ["velvet", "linen_plain", "silk_shot", FITTED]
    with tempfile.TemporaryDirectory() as home:
        env = dict(os.environ, HOME=home, PYTHONPATH=str(REPO))
        for name in fabrics:
            out = subprocess.run([sys.executable, "-c", CHILD, a.scene, name, str(a.width),
                                  str(a.height), str(a.spp)], env=env, cwd=REPO, capture_output=True,
                                 text=True, check=True)
            first, second = map(float, out.stdout.split())
            load = " ".join(f"{x:.2f}" for x in os.getloadavg())
            label = "fitted-like velvet" if name.startswith("{") else name
            print(f"{a.scene} {label} {a.width}x{a.height} spp={a.spp}: first render "
                  f"{first:.1f} s, second {second:.1f} s, compile or cache {first - second:.1f} s"
                  f"; load average {load}", flush=True)


if __name__ == "__main__":
    main()
