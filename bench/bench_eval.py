"""Throughput of Fabric.eval: thread-sample evaluations per second, and peak memory.

Thread-sample evaluations = pairs x tangent samples x threads (32 samples a thread, the
nominal count: identical samples evaluated once still count as the samples they stand for).
Single-threaded (BLAS limited to one thread), float64, 10^5 random pairs per preset; peak
memory of one call on 10^6 pairs measured with tracemalloc (NumPy reports its buffers there).

Run: .venv/bin/python bench/bench_eval.py [--pairs N] [--repeat R]
"""

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"

import argparse  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402

import numpy as np  # noqa: E402

import brdf  # noqa: E402


def hemisphere(n, rng):
    z = rng.uniform(0.0, 1.0, n)
    p = rng.uniform(-np.pi, np.pi, n)
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(p), r * np.sin(p), z], axis=-1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--memory-pairs", type=int, default=1_000_000)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    wi, wo = hemisphere(args.pairs, rng), hemisphere(args.pairs, rng)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"numpy {np.__version__}; single thread, float64, {args.pairs} pairs, best of "
          f"{args.repeat}")
    print(f"{'preset':34s} {'distinct samples':>16s} {'seconds':>8s} {'thread-samples/s':>17s}")
    worst = np.inf
    for name in brdf.PRESETS:
        fab = brdf.fabric(name)
        fab.eval(wi[:1000], wo[:1000])
        best = np.inf
        for _ in range(args.repeat):
            t = time.perf_counter()
            fab.eval(wi, wo)
            best = min(best, time.perf_counter() - t)
        rate = args.pairs * fab.options["tangent_samples"] * 2 / best
        worst = min(worst, rate)
        distinct = "+".join(str(c.ca.size) for c in fab.plan.threads)
        print(f"{name:34s} {distinct:>16s} {best:8.3f} {rate:17.3e}")
    print(f"slowest preset: {worst:.3e} thread-sample evaluations per second (target >= 1e7)")

    m = args.memory_pairs
    wi, wo = hemisphere(m, rng), hemisphere(m, rng)
    fab = brdf.fabric("linen_plain")
    tracemalloc.start()
    fab.eval(wi, wo)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    print(f"peak memory of eval on {m} pairs (excluding the inputs): {peak / 2**20:.1f} MiB "
          f"(target < 1024 MiB)")


if __name__ == "__main__":
    main()
