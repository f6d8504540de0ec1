"""Do the kernel's gradients pay in a fit? The start point and the sampler, measured.

``--start``: the point estimate (:func:`analysis.fit.optimize.optimize_start`, 4 starts of
L-BFGS-B) with the batched finite-difference gradient against the analytic one
(:mod:`analysis.fit.gradient`), interleaved, ``--rounds`` times: seconds and the
log-posterior reached.

Default: the present sampler (``analysis.fit.fit``: DE, snooker and the adapted independence
move) against a gradient sampler, preconditioned MALA (Metropolis-adjusted Langevin, the
Laplace covariance as mass matrix, step size tuned to 0.574 acceptance over the first fifth,
``--chains`` chains), each given the same sampling time, in effective samples per second
(smallest over the parameters, ESS = draws / tau as :func:`analysis.diagnostics.ess`); the
medians of the two are printed side by side.

    .venv/bin/python bench/bench_sampler.py --start                  # the default fit
    .venv/bin/python bench/bench_sampler.py --start --data rgl_white_felt
    .venv/bin/python bench/bench_sampler.py                          # samplers, default fit
    .venv/bin/python bench/bench_sampler.py --data rgl_white_felt
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import brdf
import gonio
from analysis import diagnostics
from analysis.fit import FabricModel, fit
from analysis.fit.driver import with_nuisance
from analysis.fit.gradient import logpost_and_grad, rotation_cache
from analysis.fit.optimize import optimize_start
from analysis.fit.posterior import LogPosterior
from analysis.likelihood import Likelihood
from analysis.measured import load_measured, measured_spec
from analysis.params import DEFAULT_FREE, DEFAULT_TIES, ParamSpec, defaults_from_fabric

SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def problem(data: str):
    """(table, spec, model) of the default fit (``data == "default"``) or a measured set."""
    if data == "default":
        fab = brdf.fabric("silk_crepe_de_chine")
        table = gonio.measure(fab, "full:15:30", gonio.Instrument(snr=20.0, floor=1e-4),
                              seed=0, progress=False)
        spec = ParamSpec(DEFAULT_FREE, defaults=defaults_from_fabric(fab), ties=DEFAULT_TIES)
    else:
        table = load_measured(data, SHARED)
        spec, fab = measured_spec(data)
    return table, spec, FabricModel(fab, table.wi, table.wo)


def posterior(table, spec, model) -> LogPosterior:
    lik = Likelihood(table)
    return LogPosterior(with_nuisance(spec, lik), lik, model)


def start(args):
    lp = posterior(*problem(args.data))
    print(f"{args.data}: {lp.spec.ndim} free ({', '.join(lp.spec.free)}); load average "
          f"{os.getloadavg()[0]:.1f}")
    optimize_start(lp, 1, np.random.default_rng(0), gradient="analytic")   # compile, warm
    res = {"fd": [], "analytic": []}
    for r in range(args.rounds):
        for g in (("fd", "analytic") if r % 2 == 0 else ("analytic", "fd")):
            t0 = time.perf_counter()
            best, best_lp, cov = optimize_start(lp, 4, np.random.default_rng(args.seed),
                                                threads=2, gradient=g)
            dt = time.perf_counter() - t0
            res[g].append((dt, best_lp))
            print(f"  round {r} {g:8s}: {dt:6.1f} s, log-posterior {best_lp:.6f}", flush=True)
    tf = np.median([t for t, _ in res["fd"]])
    ta = np.median([t for t, _ in res["analytic"]])
    print(f"median time fd {tf:.1f} s, analytic {ta:.1f} s: analytic/fd = {ta / tf:.2f}; best "
          f"log-posterior fd {max(v for _, v in res['fd']):.6f}, analytic "
          f"{max(v for _, v in res['analytic']):.6f}; load average {os.getloadavg()[0]:.1f}")
    return 0


def mala(lp, x0, cov, seconds, chains, rng):
    """Preconditioned MALA, ``chains`` chains for ``seconds``: (draws (n, chains, ndim) after
    the tuning fifth, acceptance, sampling seconds after tuning, gradient calls)."""
    L = np.linalg.cholesky(cov)
    Linv = np.linalg.inv(L)
    d = x0.size
    caches = [rotation_cache(lp) for _ in range(chains)]
    xs = x0 + (L @ rng.normal(size=(d, chains))).T * 0.1
    state = [logpost_and_grad(lp, x, c) for x, c in zip(xs, caches)]
    eps, t0, draws, acc, n_grad = 1.0 / d ** (1 / 6), time.perf_counter(), [], [], 0
    t_tune, k = None, 0
    while time.perf_counter() - t0 < seconds:
        tuning = time.perf_counter() - t0 < 0.2 * seconds
        row, a_row = [], []
        for i in range(chains):
            x, (f, g) = xs[i], state[i]
            mean = x + 0.5 * eps ** 2 * cov @ g
            y = mean + eps * L @ rng.normal(size=d)
            fy, gy = logpost_and_grad(lp, y, caches[i])
            n_grad += 1
            back = y + 0.5 * eps ** 2 * cov @ gy
            lq_fwd = -0.5 * np.sum((Linv @ (y - mean)) ** 2) / eps ** 2
            lq_back = -0.5 * np.sum((Linv @ (x - back)) ** 2) / eps ** 2
            a = min(1.0, np.exp(min(0.0, fy + lq_back - f - lq_fwd))) if np.isfinite(fy) else 0
            if rng.random() < a:
                xs[i], state[i] = y, (fy, gy)
            row.append(xs[i].copy())
            a_row.append(a)
        k += 1
        if tuning:
            eps *= np.exp((np.mean(a_row) - 0.574) / np.sqrt(k))
        else:
            if t_tune is None:
                t_tune = time.perf_counter()
            draws.append(row)
            acc.append(np.mean(a_row))
    return np.array(draws), float(np.mean(acc)), time.perf_counter() - t_tune, n_grad, eps


def samplers(args):
    table, spec, model = problem(args.data)
    print(f"{args.data}: load average {os.getloadavg()[0]:.1f}", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        r = fit(table, spec, model, out_dir=tmp, seed=args.seed, progress=False,
                max_steps=args.max_steps)
    t = r.timing
    print(f"present sampler: {r.reason}; sampling {t['sample_s']:.1f} s, "
          f"{t['log_prob_evals']} evaluations, smallest ESS "
          f"{min(s['ess'] for s in r.summary.values()):.0f}: {t['ess_per_s']:.2f} ESS/s",
          flush=True)
    lp = posterior(table, spec, model)
    best, _, cov = optimize_start(lp, 4, np.random.default_rng(args.seed), threads=2)
    seconds = min(t["sample_s"], args.mala_seconds)
    draws, acc, sample_s, n_grad, eps = mala(lp, best, cov, seconds, args.chains,
                                             np.random.default_rng(args.seed))
    tau = diagnostics.autocorr_time(draws)
    ess = draws.shape[0] * draws.shape[1] / np.maximum(tau, 1.0)
    print(f"MALA: {args.chains} chains, {draws.shape[0]} steps after tuning in "
          f"{sample_s:.1f} s, {n_grad} gradients ({n_grad / seconds:.1f}/s), step "
          f"{eps:.3f}, acceptance {acc:.2f}, max tau {tau.max():.1f}; smallest ESS "
          f"{ess.min():.0f}: {ess.min() / sample_s:.2f} ESS/s (the chain is short of 50 tau "
          f"where ESS < {50 * args.chains})")
    med = np.median(lp.spec.to_natural(draws.reshape(-1, draws.shape[-1])), axis=0)
    for n, m in zip(r.names, med):
        s = r.summary[n]
        print(f"   {n:10s} present {s['median']:10.5g} [{s['lo68']:.5g}, {s['hi68']:.5g}]"
              f"   MALA {m:10.5g}")
    print(f"ESS/s MALA / present = {ess.min() / sample_s / t['ess_per_s']:.3f}; load average "
          f"{os.getloadavg()[0]:.1f}")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--start", action="store_true", help="the point estimate, fd vs analytic")
    ap.add_argument("--data", default="default",
                    help="'default' (the default fit of bench_fit.py) or a measured dataset")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--chains", type=int, default=4)
    ap.add_argument("--mala-seconds", type=float, default=300.0)
    ap.add_argument("--max-steps", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    return start(args) if args.start else samplers(args)


if __name__ == "__main__":
    sys.exit(main())
