"""Time Fabric.sample on every preset and count its draws below the horizon.

For each preset, viewers at theta_o = 0, 10, ..., 80, 85 and 89 degrees, each at azimuths 0,
45, 90, 135 and 180: samples per second (sample draws, evaluates the pdf and f_r), the
largest weight f_r cos(theta_i) / pdf seen, the share of draws that land at or below the
surface (weight 0: counted, wi_z <= 0), its worst viewer and its mean over the viewers, and
the relative variance of the weight's luminance-free mean channel, var(w) / E[w]^2, at the
viewer where it is largest (the Monte Carlo albedo's noise: its standard error is
sqrt(relvar / n)). Run: ``.venv/bin/python bench/bench_sampling.py`` (optional arguments:
samples per viewer, default 20000; ``nomask`` to sample the variant without masking).
"""

from __future__ import annotations

import sys
import time

import numpy as np

import brdf

THETAS = (0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 85.0, 89.0)
PHIS = (0.0, 45.0, 90.0, 135.0, 180.0)


def main(n: int = 20_000, **options) -> None:
    rng = np.random.default_rng(0)
    print(f"Fabric.sample, {n} samples per viewer, {len(THETAS) * len(PHIS)} viewers, "
          f"options {options or 'default'}")
    print(f"  {'preset':32s} {'samples/s':>10s} {'max weight':>10s} {'below: worst':>12s} "
          f"{'at theta_o':>10s} {'mean':>6s} {'relvar: worst':>13s} {'at theta_o':>10s}")
    for name in brdf.PRESETS:
        fab = brdf.fabric(name, **options)
        worst, below, relvar, dt = 0.0, [], [], 0.0
        for theta in THETAS:
            for phi in PHIS:
                wo = brdf.directions.from_angles(np.radians(theta), np.radians(phi))
                u = rng.random((n, 2))
                t0 = time.perf_counter()
                wi, weight, _ = fab.sample(wo, u)
                dt += time.perf_counter() - t0
                worst = max(worst, float(weight.max()))
                below.append((float(np.mean(wi[:, 2] <= 0)), theta))
                w = weight.mean(axis=1)
                relvar.append((float(w.var() / max(w.mean() ** 2, 1e-300)), theta))
        rate = n * len(below) / dt
        (b, bt), (r, rt) = max(below), max(relvar)
        bt = f"{bt:g}" if b > 0 else "-"
        print(f"  {name:32s} {rate:10.3g} {worst:10.2f} {b:12.3f} {bt:>10s} "
              f"{np.mean([x for x, _ in below]):6.3f} {r:13.2f} {rt:10g}")


if __name__ == "__main__":
    args = sys.argv[1:]
    opts = {"masking": False} if "nomask" in args else {}
    nums = [a for a in args if a.isdigit()]
    main(int(nums[0]) if nums else 20_000, **opts)
