"""Time the directional albedo curves of all six presets (theta 0..90 in 1-degree steps).

Prints the wall time (target: under 60 s on the 2-core machine), the evaluation rate, the
largest error bound and the quadrature levels used. Run: ``.venv/bin/python bench/bench_albedo.py``
(optional arguments: number of worker processes, azimuth in degrees).
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

import brdf
from analysis.albedo import run_tasks
from analysis.energy import directions_grid


def main(workers: int = 2, phi_deg: float = 0.0) -> None:
    theta = np.arange(0.0, 91.0, 1.0)                     # 0..90 degrees, 91 angles
    dirs = directions_grid(theta, [phi_deg]).reshape(-1, 3)
    tasks = [(brdf.fabric(name), dirs, {}) for name in brdf.PRESETS]
    t0 = time.perf_counter()
    res = run_tasks(tasks, workers)
    dt = time.perf_counter() - t0
    evals = sum(r[2] for r in res)
    err = max(float(r[1].max()) for r in res)
    print(f"albedo curves: {len(brdf.PRESETS)} presets x {theta.size} theta at phi = {phi_deg:g} "
          f"deg, {workers} workers on {os.cpu_count()} cores: {dt:.1f} s wall "
          f"({evals / dt:.3g} BRDF evals/s, {evals / (len(tasks) * theta.size):.0f} evals per "
          f"albedo; largest error bound {err:.1e}; load average {os.getloadavg()[0]:.1f})")
    for name, (v, e, _) in zip(brdf.PRESETS, res):
        k = int(np.argmax(v.max(axis=1)))
        print(f"  {name:32s} max {v.max():.4f} +- {e.reshape(-1)[np.argmax(v)]:.1e} at theta = "
              f"{theta[k]:g} deg; max error {e.max():.1e}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2,
         float(sys.argv[2]) if len(sys.argv) > 2 else 0.0)
