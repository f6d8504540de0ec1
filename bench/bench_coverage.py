"""Coverage of the fit's 95% intervals against the exact Gaussian answer on the same tables.

The configuration of ``bench/bench_plan.py`` (issue 31): 120 pairs (uniform, or planned by
``analysis.plan``), an instrument of SNR 20 with a 1e-4 1/sr floor, largest theta 80 degrees,
5 degrees between the cones, the default 8 free parameters (eta tied, area2 = 1 - area1).

For each noise seed the table is simulated (``gonio.measure``) and fitted
(``analysis.fit.fit``, the fit of ``microcyl fit``), and the same table is given to an oracle:
the maximum-likelihood estimate linearized at the truth, theta_hat - theta_0 = I^-1 J^T
Sigma^-1 (f - f_0), with J the model's Jacobian at the truth (central differences), Sigma the
table's sigma (the noise's true std) and I = J^T Sigma^-1 J. Its z = (theta_hat - theta_0) /
sqrt(diag I^-1) is exactly N(0, 1) under the noise model, whatever the design, so its misses
(|z| > 1.96) are what honest 95% intervals miss on these very tables. The fit's own z (median
minus truth over the posterior sd) is printed beside it: a defect of the fit (likelihood,
sampler, intervals) shows as fit misses the oracle does not have, or as a difference of the
two z. ``--null`` prints the distribution of the number of misses of honest intervals over a
batch (the parameters of one fit are correlated, which widens it beyond the binomial).

    .venv/bin/python bench/bench_coverage.py --replicas 30                # silk and velvet
    .venv/bin/python bench/bench_coverage.py --replicas 24 --design planned
    .venv/bin/python bench/bench_coverage.py --oracle-only 300 --design planned
    .venv/bin/python bench/bench_coverage.py --null 6
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np

import brdf
import gonio
from analysis.fit import FabricModel, fit
from analysis.fit.posterior import LogPosterior
from analysis.likelihood import Likelihood
from analysis.params import DEFAULT_FREE, DEFAULT_TIES, ParamSpec, defaults_from_fabric
from analysis.planning import plan, uniform_pairs
from gonio.layouts import pairs_from_angles

INSTRUMENT = gonio.Instrument(snr=20.0, floor=1e-4, max_theta=80.0, min_separation=5.0)
Z95 = 1.959964


def design(fab, design_name, n):
    """The pairs (a Geometry) of a uniform or planned design of n pairs."""
    if design_name == "planned":
        p = plan(fab, DEFAULT_FREE, n, ties=DEFAULT_TIES, instrument=INSTRUMENT, seed=0)
        wi, wo = p.wi, p.wo
    else:
        wi, wo = uniform_pairs(n, INSTRUMENT, max_theta=np.radians(80), seed=11)
    ti, pi_ = brdf.frames.to_angles(wi)
    to, po = brdf.frames.to_angles(wo)
    return pairs_from_angles(*np.degrees(np.stack([ti, pi_, to, po], -1)).T, degrees=True)


class Oracle:
    """The linearized maximum-likelihood estimate at the truth (module notes)."""

    def __init__(self, fab, geo):
        self.truth = defaults_from_fabric(fab)
        self.spec = ParamSpec(DEFAULT_FREE, defaults=self.truth, ties=DEFAULT_TIES)
        table = gonio.measure(fab, geo, INSTRUMENT, seed=0, progress=False)
        th0 = self.spec.to_internal(np.array([self.truth[n] for n in self.spec.free]))
        d = th0.size
        h = 1e-4 * self.spec.width
        pts = np.repeat(th0[None], 2 * d + 1, axis=0)
        pts[1 + 2 * np.arange(d), np.arange(d)] += h
        pts[2 + 2 * np.arange(d), np.arange(d)] -= h
        post = LogPosterior(self.spec, Likelihood(table), FabricModel(fab, table.wi, table.wo))
        pred = post.predict(pts)
        nat = self.spec.to_natural(pts)
        dx = nat[1::2][np.arange(d), np.arange(d)] - nat[2::2][np.arange(d), np.arange(d)]
        self.f0 = pred[0]
        self.sigma = INSTRUMENT.sigma(self.f0)
        self.jac = (pred[1::2] - pred[2::2]) / dx[:, None, None]       # natural units
        self.info = np.einsum("knc,lnc,nc->kl", self.jac, self.jac, self.sigma ** -2)
        cov = np.linalg.inv(self.info)
        self.sd = np.sqrt(np.diag(cov))
        self.corr = cov / np.outer(self.sd, self.sd)

    def z(self, values) -> np.ndarray:
        score = np.einsum("knc,nc->k", self.jac, (values - self.f0) / self.sigma ** 2)
        return np.linalg.solve(self.info, score) / self.sd


def one_fit(fab, geo, oracle, seed):
    """(fit z, fit misses, oracle z, converged, wall s) of one noisy table."""
    table = gonio.measure(fab, geo, INSTRUMENT, seed=seed, progress=False)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        r = fit(table, oracle.spec, FabricModel(fab, table.wi, table.wo), out_dir=tmp,
                seed=3, progress=False)
    x = r.samples()
    names = oracle.spec.free
    truth = np.array([oracle.truth[n] for n in names])
    z = (np.median(x, axis=0) - truth) / x.std(axis=0)
    miss = np.array([not (r.summary[n]["lo95"] <= oracle.truth[n] <= r.summary[n]["hi95"])
                     for n in names])
    return z, miss, oracle.z(table.values), r.converged, time.perf_counter() - t0


def coverage(args):
    tot_fit = tot_oracle = tot = 0
    for name in args.presets.split(","):
        fab = brdf.fabric(name)
        geo = design(fab, args.design, args.pairs)
        oracle = Oracle(fab, geo)
        rows = []
        for k in range(args.replicas):
            z, miss, oz, conv, wall = one_fit(fab, geo, oracle, seed=args.first_seed + k)
            rows.append((z, miss, oz))
            print(f"{name} seed {args.first_seed + k}: converged {conv}, {wall:.1f} s, misses "
                  f"fit {int(miss.sum())} oracle {int((np.abs(oz) > Z95).sum())}, "
                  f"max |fit z - oracle z| {np.abs(z - oz).max():.2f} (load "
                  f"{os.getloadavg()[0]:.1f})", flush=True)
        z, miss, oz = (np.array(a) for a in zip(*rows))
        print(f"{name}, {args.design} {args.pairs} pairs, {args.replicas} seeds: fit missed "
              f"{int(miss.sum())}/{miss.size}, oracle {int((np.abs(oz) > Z95).sum())}; per "
              f"parameter ({', '.join(oracle.spec.free)}) fit {miss.sum(0).tolist()}; mean "
              f"fit z - oracle z {np.round((z - oz).mean(0), 2).tolist()}, sd "
              f"{np.round((z - oz).std(0), 2).tolist()}")
        tot_fit += int(miss.sum())
        tot_oracle += int((np.abs(oz) > Z95).sum())
        tot += miss.size
    print(f"all: fit missed {tot_fit}/{tot}, the oracle {tot_oracle}/{tot} (nominal "
          f"{0.05 * tot:.1f})")
    return 0


def oracle_only(args):
    for name in args.presets.split(","):
        fab = brdf.fabric(name)
        geo = design(fab, args.design, args.pairs)
        oracle = Oracle(fab, geo)
        z = np.array([oracle.z(gonio.measure(fab, geo, INSTRUMENT, seed=s,
                                             progress=False).values)
                      for s in range(args.first_seed, args.first_seed + args.oracle_only)])
        print(f"{name}, {args.design} {args.pairs} pairs, {len(z)} seeds: oracle |z| > 1.96 "
              f"{(np.abs(z) > Z95).mean():.4f} (per parameter "
              f"{np.round((np.abs(z) > Z95).mean(0), 3).tolist()}), sd of z "
              f"{np.round(z.std(0), 3).tolist()}")
    return 0


def null(args):
    """Misses of honest 95% intervals over a batch of ``args.null`` fits per preset."""
    rng = np.random.default_rng(args.first_seed)
    total = 0
    for name in args.presets.split(","):
        fab = brdf.fabric(name)
        corr = Oracle(fab, design(fab, args.design, args.pairs)).corr
        d = corr.shape[0]
        z = rng.multivariate_normal(np.zeros(d), corr, size=(100_000, args.null))
        total = total + (np.abs(z) > Z95).sum(axis=(1, 2))
        print(f"{name}: largest |correlation| of the estimates "
              f"{np.abs(corr[np.triu_indices(d, 1)]).max():.3f}")
    n = args.null * d * len(args.presets.split(","))
    q = np.quantile(total, [0.005, 0.025, 0.975, 0.995])
    print(f"misses in {n} intervals ({args.null} fits a preset): mean {total.mean():.2f}, sd "
          f"{total.std():.2f} (binomial {np.sqrt(n * 0.05 * 0.95):.2f}); 95% range "
          f"[{q[1]:.0f}, {q[2]:.0f}], 99% [{q[0]:.0f}, {q[3]:.0f}]")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--presets", default="silk_crepe_de_chine,velvet")
    ap.add_argument("--design", choices=("uniform", "planned"), default="uniform")
    ap.add_argument("--pairs", type=int, default=120)
    ap.add_argument("--replicas", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--oracle-only", type=int, default=0, metavar="SEEDS")
    ap.add_argument("--null", type=int, default=0, metavar="FITS")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()}, cpus {os.cpu_count()}", flush=True)
    if args.oracle_only:
        return oracle_only(args)
    if args.null:
        return null(args)
    return coverage(args)


if __name__ == "__main__":
    sys.exit(main())
