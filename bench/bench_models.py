"""Every model of a fit side by side: eval rate, and a fit to one CUReT fabric and one RGL felt.

For each model (every model of :data:`brdf.MODELS`: ``microcylinder`` and the baselines):

- the eval rate (pairs per second) of ``eval`` on random pairs, and of the batched
  ``prepare(wi, wo).eval`` a fit calls (parameter sets x pairs per second);
- its fit to ``curet_07_velvet`` (205 grey, relative values) and ``rgl_white_felt`` (the felt at
  ``--rgl-step`` degrees), as ``microcyl fit-measured --models`` runs them (the microcylinder
  from the dataset's preset and free set, a baseline with its default free set for the table):
  wall time, steps, convergence and the PSIS-LOO elpd +- se; then the models ranked per
  dataset (:func:`analysis.fit.compare.compare_fits`).

    .venv/bin/python bench/bench_models.py                       # everything (minutes)
    .venv/bin/python bench/bench_models.py --no-fits             # eval rates only
    .venv/bin/python bench/bench_models.py --max-steps 400 --datasets curet_07_velvet

Every number goes to stdout with the machine's load average; CHANGELOG.md records the runs.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

import brdf
from analysis.families import MICROCYLINDER, family, model_names
from analysis.fit import fit_fabric, fit_spec
from analysis.fit.compare import compare_fits
from analysis.measured import load_measured, measured_spec

SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def random_pairs(n, seed=0):
    rng = np.random.default_rng(seed)

    def hemi(k):
        ct = rng.uniform(0.05, 1.0, k)
        ph = rng.uniform(-np.pi, np.pi, k)
        st = np.sqrt(1 - ct * ct)
        return np.stack([st * np.cos(ph), st * np.sin(ph), ct], -1)
    return hemi(n), hemi(n)


def start(model):
    return brdf.fabric("velvet") if model == MICROCYLINDER else family(model).start()


def eval_rates(model, n=100_000, batch=64, n_batch=2000, repeats=3):
    """(eval pairs/s, prepared parameter-set x pairs/s), best of ``repeats``."""
    obj = start(model)
    wi, wo = random_pairs(n)
    t_eval = min(_timed(lambda: obj.eval(wi, wo)) for _ in range(repeats))
    fam = family(model)
    spec = fit_spec(obj)
    theta = np.random.default_rng(1).normal(0, 0.5, (batch, spec.ndim))
    kw = fam.model_kwargs(spec.values(theta))
    prep = obj.prepare(wi[:n_batch], wo[:n_batch])
    t_prep = min(_timed(lambda: prep.eval(**kw)) for _ in range(repeats))
    return n / t_eval, batch * n_batch / t_prep


def _timed(f):
    t0 = time.perf_counter()
    f()
    return time.perf_counter() - t0


def fit_one(dataset, model, table, out, max_steps, seed):
    """One fit as fit-measured runs it; (wall s, steps, converged, elpd, se)."""
    if model == MICROCYLINDER:
        spec, obj = measured_spec(dataset)
    else:
        obj = start(model)
        spec = fit_spec(obj, table=table)
    t0 = time.perf_counter()
    r = fit_fabric(table, obj, spec, out, max_steps=max_steps, seed=seed, progress=False)
    loo = r.loo.summary() if r.loo is not None else {"elpd": float("nan"), "se": float("nan")}
    return time.perf_counter() - t0, r.steps, r.converged, loo["elpd"], loo["se"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", default="all", help="all or comma-separated model names")
    ap.add_argument("--datasets", default="curet_07_velvet,rgl_white_felt")
    ap.add_argument("--max-steps", type=int, default=20000)
    ap.add_argument("--rgl-step", type=float, default=15.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--no-fits", action="store_true")
    ap.add_argument("--no-eval", action="store_true")
    ap.add_argument("--data", default=str(SHARED))
    args = ap.parse_args(argv)
    models = model_names() if args.models == "all" else tuple(args.models.split(","))
    print(f"{platform.machine()} {os.cpu_count()} cores, numpy {np.__version__}, load "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    if not args.no_eval:
        print(f"{'model':14s} {'eval pairs/s':>14s} {'prepared sets x pairs/s':>24s}")
        for m in models:
            e, p = eval_rates(m)
            print(f"{m:14s} {e:14.3g} {p:24.3g}")
    if args.no_fits:
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        for d in args.datasets.split(","):
            table = load_measured(d, args.data, rgl_step=args.rgl_step)
            print(f"\n{d}: {len(table)} pairs; --max-steps {args.max_steps}")
            print(f"{'model':14s} {'wall s':>8s} {'steps':>7s} {'converged':>9s} "
                  f"{'elpd':>10s} {'se':>7s}")
            folders = {}
            for m in models:
                folders[m] = Path(tmp) / f"{d}-{m}"
                w, steps, conv, elpd, se = fit_one(d, m, table, folders[m], args.max_steps,
                                                   args.seed)
                print(f"{m:14s} {w:8.1f} {steps:7d} {str(conv):>9s} {elpd:10.1f} {se:7.1f}",
                      flush=True)
            rows = compare_fits(list(folders.values()), names=list(folders))
            for r in rows:
                print(f"  rank {r['fit']:14s} d_elpd {r['d_elpd']:9.1f} +- {r['d_se']:.1f}")
    print(f"load at the end {', '.join(f'{x:.1f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
