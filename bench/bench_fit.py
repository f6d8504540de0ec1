"""Speed and validation of ``analysis.fit`` (the default fit, recovery, calibration, real data).

Default: the default fit -- a silk_crepe_de_chine table simulated by ``gonio.measure`` on the
``full:15:30`` grid (3,721 pairs; SNR 20 multiplicative noise plus a 1e-4 1/sr floor), the
default 8 free parameters (eta tied, area2 = 1 - area1), 4 ensembles -- and prints
log-probability evaluations per second, effective samples per second, and the wall time.

    .venv/bin/python bench/bench_fit.py                 # speed of the default fit
    .venv/bin/python bench/bench_fit.py --recovery      # silk, charmeuse, velvet: truth in 95%?
    .venv/bin/python bench/bench_fit.py --calibration 20  # coverage over 20 replicas
    .venv/bin/python bench/bench_fit.py --real          # RGL felts and CUReT fabrics
    .venv/bin/python bench/bench_fit.py --diagnostics   # warnings and adequacy, known truth
    .venv/bin/python bench/bench_fit.py --backends 2    # numpy vs drjit, interleaved

Every fit prints its adequacy verdict and its warnings (:mod:`analysis.fit.trust`).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import stats

import brdf
import gonio
from analysis.fit import FabricModel, fit
from analysis.measured import MEASURED, load_measured, measured_spec
from analysis.params import DEFAULT_FREE, DEFAULT_TIES, ParamSpec, defaults_from_fabric

SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "data"


def simulate(name, spec="full:15:30", snr=20.0, seed=0):
    fab = brdf.fabric(name)
    table = gonio.measure(fab, spec, gonio.Instrument(snr=snr, floor=1e-4), seed=seed,
                          progress=False)
    return table, fab


def run_fit(table, fab, free=DEFAULT_FREE, ties=DEFAULT_TIES, out=None, spec=None, **kw):
    spec = spec or ParamSpec(free, defaults=defaults_from_fabric(fab), ties=ties)
    model = FabricModel(fab, table.wi, table.wo)
    with tempfile.TemporaryDirectory() as tmp:
        return fit(table, spec, model, out_dir=out or tmp, **kw)


def print_trust(r, indent="   "):
    """The fit's adequacy verdict and each warning, one line each."""
    a = r.adequacy
    verdict = {True: "ADEQUATE", False: "NOT ADEQUATE", None: "adequacy not checked"}
    print(f"{indent}{verdict[a.get('adequate')]}: {a.get('reason')}")
    for w in r.warnings:
        print(f"{indent}warning ({w['kind']}): {w['message']}")


def diagnostics(args):
    """Warnings and adequacy on simulated tables whose truth is known (full:20:45, SNR 20):
    a parameter without effect (thread 2 covers nothing), a truth at its bound (kd1 = 0),
    the generating preset, and another preset."""
    silk = brdf.fabric("silk_crepe_de_chine")
    t1, t2 = silk.threads
    no_weft = silk.replace(threads=(t1, t2.replace(area=0.0)))
    kd0 = silk.replace(threads=(t1.replace(kd=0.0), t2))
    cases = [  # (title, data fabric, model fabric, free, expectation(result) -> bool)
        ("kd2 without effect (area2 = 0)", no_weft, no_weft, ("gamma_s1", "kd1", "kd2"),
         lambda r: _has(r, "not_informed", "kd2")),
        ("kd1 = 0, at its bound", kd0, kd0, ("gamma_s1", "kd1", "area1"),
         lambda r: _has(r, "at_bound", "kd1")),
        ("silk fitted as silk", silk, silk, ("eta1", "kd1", "gamma_s1", "gamma_v1", "area1"),
         lambda r: r.adequacy["adequate"] is True),
        ("silk fitted as linen_plain", silk, brdf.fabric("linen_plain"),
         ("eta1", "kd1", "gamma_s1", "gamma_v1", "area1"),
         lambda r: r.adequacy["adequate"] is False and _has(r, "misfit")),
    ]
    bad = 0
    for title, data, model, free, expect in cases:
        table = gonio.measure(data, "full:20:45", gonio.Instrument(snr=20.0, floor=1e-4),
                              seed=args.seed, progress=False)
        spec = ParamSpec(free, defaults=defaults_from_fabric(model),
                         ties=("area2=1-area1",) if "area1" in free else ())
        r = run_fit(table, model, spec=spec, seed=args.seed, progress=False,
                    max_steps=args.max_steps)
        ok = expect(r)
        bad += not ok
        print(f"{title}: {'as expected' if ok else 'NOT as expected'}; {r.reason} "
              f"({r.timing['wall_s']:.0f} s)", flush=True)
        print_trust(r)
    return 1 if bad else 0


def _has(r, kind, name=None):
    return any(w["kind"] == kind and (name is None or name in w["parameters"])
               for w in r.warnings)


def speed(args):
    table, fab = simulate("silk_crepe_de_chine", seed=args.seed)
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.1f}; table: {len(table)} pairs, silk_crepe_de_chine")
    cpu0, faults0 = time.process_time(), resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    r = run_fit(table, fab, seed=args.seed, progress=not args.quiet)
    cpu = time.process_time() - cpu0
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults0
    t = r.timing
    print(f"free parameters: {len(r.names)} ({', '.join(r.names)}); "
          f"{r.ensembles} ensembles x {r.walkers} walkers; values used {r.counts['used']}")
    print(f"verdict: {r.reason}")
    print(f"log-probability evaluations per second: {t['evals_per_s']:.0f} "
          f"({t['log_prob_evals']} in {t['sample_s']:.1f} s of sampling)")
    print(f"proposal refits: {t['refit_evals']} evaluations; kept at "
          f"{[a['step'] for a in r.proposal['adaptations'] if a.get('kept')]}")
    print(f"effective samples per second (smallest ESS over parameters): {t['ess_per_s']:.1f}")
    print(f"wall time of the default fit: {t['wall_s']:.1f} s (point estimate "
          f"{t['optimize_s']:.1f} s); max tau {max(s['tau'] for s in r.summary.values()):.1f} "
          f"steps, min N/tau {min(s['n_over_tau'] for s in r.summary.values()):.0f}")
    print(f"CPU time of the fit: {cpu:.1f} s (all threads; less sensitive to a busy machine "
          f"than the wall time), {faults} minor page faults")
    print_trust(r, indent="")
    return 0 if r.converged and t["wall_s"] < 300 else 1


def _one_backend(backend, seed):
    """The default fit in a fresh process under ``MICROCYL_BACKEND=backend``: its JSON."""
    env = dict(os.environ, MICROCYL_BACKEND=backend)
    out = subprocess.run([sys.executable, __file__, "--json", "--seed", str(seed)], env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def backends(args):
    """The default fit under each backend, alternately (``--backends`` rounds): wall and CPU
    time ratios, and the quantiles compared in units of their Monte Carlo error."""
    runs = {"numpy": [], "drjit": []}
    for r in range(args.backends):
        for b in (("numpy", "drjit") if r % 2 == 0 else ("drjit", "numpy")):
            doc = _one_backend(b, args.seed)
            runs[b].append(doc)
            print(f"round {r} {b:6s}: wall {doc['wall_s']:6.1f} s, CPU {doc['cpu_s']:6.1f} s, "
                  f"{doc['steps']} steps, load {doc['load']:.1f}; {doc['reason']}", flush=True)
    med = {b: {k: float(sorted(d[k] for d in v)[len(v) // 2]) for k in ("wall_s", "cpu_s")}
           for b, v in runs.items()}
    print(f"numpy / drjit (medians of {args.backends}): wall "
          f"{med['numpy']['wall_s'] / med['drjit']['wall_s']:.2f}x, CPU "
          f"{med['numpy']['cpu_s'] / med['drjit']['cpu_s']:.2f}x; load average now "
          f"{os.getloadavg()[0]:.1f}")
    a, b = runs["numpy"][0]["summary"], runs["drjit"][0]["summary"]
    worst = 0.0
    for n in a:
        for q in ("lo95", "median", "hi95"):
            # the Monte Carlo se of a quantile, roughly sd x sqrt(1/ESS) x a factor 1.25 to
            # 2 (median to 2.5%); the two fits' errors combined
            sd = (a[n]["hi68"] - a[n]["lo68"]) / 2
            se = 2.0 * sd * np.hypot(1 / np.sqrt(a[n]["ess"]), 1 / np.sqrt(b[n]["ess"]))
            z = abs(a[n][q] - b[n][q]) / se
            worst = max(worst, z)
        print(f"   {n:10s} median numpy {a[n]['median']:10.5g} drjit {b[n]['median']:10.5g}; "
              f"95% [{a[n]['lo95']:.5g}, {a[n]['hi95']:.5g}] vs [{b[n]['lo95']:.5g}, "
              f"{b[n]['hi95']:.5g}]")
    print(f"largest quantile difference: {worst:.2f} Monte Carlo standard errors "
          f"({'within' if worst < 3 else 'NOT within'} 3)")
    return 0


def as_json(args):
    """The default fit, one JSON line (for :func:`backends`)."""
    table, fab = simulate("silk_crepe_de_chine", seed=args.seed)
    cpu0, load = time.process_time(), os.getloadavg()[0]
    r = run_fit(table, fab, seed=args.seed, progress=False)
    print(json.dumps({"wall_s": r.timing["wall_s"], "cpu_s": time.process_time() - cpu0,
                      "steps": r.steps, "load": load, "reason": r.reason,
                      "backend": brdf.jit.backend(), "summary": r.summary}))
    return 0


def recovery(args):
    bad = 0
    for name in ("silk_crepe_de_chine", "polyester_satin_charmeuse", "velvet"):
        table, fab = simulate(name, seed=args.seed)
        truth = defaults_from_fabric(fab)
        r = run_fit(table, fab, seed=args.seed, progress=False)
        inside = [r.summary[n]["lo95"] <= truth[n] <= r.summary[n]["hi95"] for n in r.names]
        bad += sum(not i for i in inside)
        print(f"{name}: {sum(inside)}/{len(inside)} truths inside their 95% interval; "
              f"{r.reason} ({r.timing['wall_s']:.0f} s)")
        for n, ok in zip(r.names, inside):
            s = r.summary[n]
            print(f"   {n:10s} truth {truth[n]:9.5g}  median {s['median']:9.5g}  95% "
                  f"[{s['lo95']:9.5g}, {s['hi95']:9.5g}] {'' if ok else '  <-- outside'}")
        print_trust(r)
    return 0


def calibration(args):
    """Coverage of the 68% and 95% intervals over replicas (silk, 5 free parameters)."""
    free = ("eta1", "kd1", "gamma_s1", "gamma_v1", "area1")
    hits68 = hits95 = total = 0
    t0 = time.perf_counter()
    for rep in range(args.calibration):
        table, fab = simulate("silk_crepe_de_chine", spec="full:20:45", seed=1000 + rep)
        truth = defaults_from_fabric(fab)
        r = run_fit(table, fab, free=free, seed=rep, progress=False)
        for n in r.names:
            s = r.summary[n]
            hits68 += s["lo68"] <= truth[n] <= s["hi68"]
            hits95 += s["lo95"] <= truth[n] <= s["hi95"]
            total += 1
        print(f"replica {rep}: converged {r.converged}, adequate "
              f"{r.adequacy.get('adequate')}, {len(r.warnings)} warnings, running coverage 68% "
              f"{hits68 / total:.3f}, 95% {hits95 / total:.3f} ({time.perf_counter() - t0:.0f} s)",
              flush=True)
    ok = True
    for p, h in ((0.6827, hits68), (0.95, hits95)):
        lo, hi = stats.binom.interval(0.99, total, p)
        inside = lo <= h <= hi
        ok &= inside
        print(f"coverage of the {100 * p:.0f}% intervals: {h}/{total} = {h / total:.3f}; "
              f"99% binomial range [{lo / total:.3f}, {hi / total:.3f}]: "
              f"{'consistent' if inside else 'NOT consistent'}")
    print("note: the parameters of one replica are correlated, so the binomial range is a "
          "rough guide")
    return 0 if ok else 1


def real(args):
    """Fits of the measured datasets (analysis.measured): verdict, residuals, time."""
    if not SHARED.is_dir():
        print(f"measured data not found at {SHARED}")
        return 1
    out_root = Path(args.out or tempfile.mkdtemp(prefix="microcyl-real-"))
    bad = 0
    for name, d in MEASURED.items():
        if args.only and d.kind != args.only:
            continue
        table = load_measured(name, SHARED)
        spec, fab = measured_spec(name)
        r = fit(table, spec, FabricModel(fab, table.wi, table.wo), seed=0, progress=False,
                max_steps=args.max_steps, time_limit=args.time_limit, out_dir=out_root / name)
        kept = [a["step"] for a in r.proposal["adaptations"] if a.get("kept")]
        print(f"{name} (from {d.preset}): {len(table)} pairs, {r.counts['used']} values; "
              f"rms residual (log space) {r.residuals()['rms']:.3f}; "
              f"{r.timing['wall_s']:.0f} s, {r.timing['evals_per_s']:.0f} evals/s; proposal "
              f"refits kept at {kept}; {r.reason}", flush=True)
        print("   " + ", ".join(f"{n}={r.summary[n]['median']:.4g}" for n in r.names))
        print_trust(r)
        bad += not r.converged
    print(f"chains and configs in {out_root}; {bad} not converged")
    return 1 if bad else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--recovery", action="store_true")
    ap.add_argument("--calibration", type=int, default=0, metavar="REPLICAS")
    ap.add_argument("--real", action="store_true")
    ap.add_argument("--diagnostics", action="store_true",
                    help="warnings and adequacy of fits whose truth is known")
    ap.add_argument("--max-steps", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", choices=("rgl", "curet"), default=None,
                    help="with --real: only these tables")
    ap.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                    help="with --real: per fit")
    ap.add_argument("--out", default=None)
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument("--backends", type=int, default=0, metavar="ROUNDS",
                    help="the default fit under MICROCYL_BACKEND=numpy and drjit, alternately")
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.json:
        return as_json(args)
    if args.backends:
        return backends(args)
    if args.recovery:
        return recovery(args)
    if args.calibration:
        return calibration(args)
    if args.real:
        return real(args)
    if args.diagnostics:
        return diagnostics(args)
    return speed(args)


if __name__ == "__main__":
    sys.exit(main())
