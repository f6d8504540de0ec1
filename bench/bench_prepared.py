"""Throughput of Prepared.eval: parameter sets shaded per second, for batches of B sets.

The pairs are those of a "full:15:30" virtual measurement (3721 pairs); the batch's sets
differ in eta (a fit's walkers). Single-threaded (BLAS limited to one thread), float64 and
float32 shading (``Prepared.eval(dtype=...)``, what a fit samples with) interleaved, with
their ratio; each figure is the rate in CPU time over ``--seconds`` of repeated calls after
one warm-up call (CPU time: less disturbed by other work on a shared machine).

Run: .venv/bin/python bench/bench_prepared.py [--seconds T] [--fabrics NAME ...]
"""

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import brdf  # noqa: E402
import gonio  # noqa: E402


def rate(prep, batch, seconds, dtype=np.float64):
    """Parameter sets per CPU second of ``prep.eval`` with a batch of ``batch`` sets."""
    rng = np.random.default_rng(0)
    kw = dict(eta=1.4 + rng.normal(0, .01, (batch, 2)), kd=np.full((batch, 2), .3),
              gamma_s=np.full((batch, 2), 5.), gamma_v=np.full((batch, 2), 10.))
    kw["dtype"] = dtype
    prep.eval(**kw)
    t0 = time.process_time()
    n = 0
    while time.process_time() - t0 < seconds:
        prep.eval(**kw)
        n += batch
    return n / (time.process_time() - t0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=1.5)
    ap.add_argument("--fabrics", nargs="+", default=["silk_crepe_de_chine", "linen_plain"])
    ap.add_argument("--batches", nargs="+", type=int, default=[1, 9, 36, 72])
    args = ap.parse_args()
    for name in args.fabrics:
        fab = brdf.fabric(name)
        t = gonio.measure(fab, "full:15:30", gonio.Instrument(snr=20, floor=1e-4), seed=0,
                          progress=False)
        prep = fab.prepare(t.wi, t.wo)
        for b in args.batches:
            r64 = rate(prep, b, args.seconds)
            r32 = rate(prep, b, args.seconds, np.float32)
            print(f"{name:22s} pairs {len(t.wi):5d}  B {b:3d}  float64 {r64:7.1f} sets/s  "
                  f"float32 {r32:7.1f} sets/s  ({r32 / r64:.2f}x)", flush=True)


if __name__ == "__main__":
    main()
