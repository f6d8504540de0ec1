"""Time Fabric.sample on every preset and report its weights.

For each preset, viewers at theta_o = 0, 30, 60, 85 and 89 degrees (azimuths 0, 45, 90, 135,
180): samples per second (sample draws, evaluates the pdf and f_r), the largest weight
f_r cos(theta_i) / pdf seen, the mean weight (the Monte Carlo albedo) and the share of draws
that land below the surface (weight 0). Run: ``.venv/bin/python bench/bench_sampling.py``
(optional arguments: samples per viewer, default 200000; ``nomask`` to sample the variant
without masking).
"""

from __future__ import annotations

import sys
import time

import numpy as np

import brdf

VIEWS = [(0.0, 0.0), (30.0, 45.0), (60.0, 90.0), (85.0, 135.0), (85.0, 180.0), (89.0, 180.0)]


def main(n: int = 200_000, **options) -> None:
    rng = np.random.default_rng(0)
    print(f"Fabric.sample, {n} samples per viewer, options {options or 'default'}")
    print(f"  {'preset':32s} {'samples/s':>10s} {'max weight':>10s} {'at theta_o':>10s} "
          f"{'below':>6s}")
    for name in brdf.PRESETS:
        fab = brdf.fabric(name, **options)
        worst, where, below, dt = 0.0, None, [], 0.0
        for theta, phi in VIEWS:
            wo = brdf.directions.from_angles(np.radians(theta), np.radians(phi))
            u = rng.random((n, 2))
            t0 = time.perf_counter()
            wi, weight, _ = fab.sample(wo, u)
            dt += time.perf_counter() - t0
            if weight.max() > worst:
                worst, where = float(weight.max()), theta
            below.append(float(np.mean(wi[:, 2] <= 0)))
        rate = n * len(VIEWS) / dt
        print(f"  {name:32s} {rate:10.3g} {worst:10.2f} {where:10g} "
              f"{min(below):.2f}-{max(below):.2f}")


if __name__ == "__main__":
    args = sys.argv[1:]
    opts = {"masking": False} if "nomask" in args else {}
    nums = [a for a in args if a.isdigit()]
    main(int(nums[0]) if nums else 200_000, **opts)
