"""The Dr.Jit backend against the NumPy kernel: single-thread float64 ``Fabric.eval`` on
every preset, and a fit's batched ``Prepared.eval``, as ratios drjit/numpy of their rates.

Both backends run in this one process, interleaved (numpy, drjit, numpy, drjit, ...) so that
the load of a shared machine falls on both alike; each figure is the median over
``--rounds`` rounds of the CPU time of one call (after a warm-up call that compiles the
Dr.Jit kernel). Single-threaded: NumPy's BLAS through threadpoolctl, Dr.Jit's pool by
``dr.set_thread_count(1)``; then the batched eval again with Dr.Jit on every core (wall
time; NumPy's kernel has one thread); and a batch with a rotation per set (a fit that frees
the rotation). The machine and its load average are printed with the figures.

With ``--rst FILE`` the figures are also written as a reStructuredText fragment (the one
``docs/benchmarks.rst`` includes: ``docs/bench_backend.inc``), its sentences made from the
measured values.

Run: DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \
     .venv/bin/python bench/bench_backend.py [--pairs N] [--rounds R] [--batch B] [--rst F]
"""

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"

import argparse  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

import brdf  # noqa: E402
import gonio  # noqa: E402
from brdf import jit  # noqa: E402
from gonio.atomic import atomic_write  # noqa: E402


_clock = time.process_time


def _cpu(fn) -> float:
    """Seconds of ``fn()``: CPU time of the process (single-threaded runs), or wall time
    once Dr.Jit runs on several threads (``_clock``)."""
    t0 = _clock()
    fn()
    return _clock() - t0


def interleaved(calls: dict, rounds: int) -> dict:
    """Median seconds of each of ``calls`` ((backend, label) -> function), run in turn."""
    times = {key: [] for key in calls}
    for key, fn in calls.items():         # warm-up: compiles the Dr.Jit kernel
        with_backend(key[0], fn)
    for _ in range(rounds):
        for key, fn in calls.items():
            times[key].append(with_backend(key[0], lambda: _cpu(fn)))
    return {key: statistics.median(t) for key, t in times.items()}


def with_backend(name, fn):
    """``fn()`` with MICROCYL_BACKEND set to ``name``."""
    os.environ[jit.BACKEND_ENV] = name
    try:
        return fn()
    finally:
        del os.environ[jit.BACKEND_ENV]


def hemisphere(rng, n):
    v = rng.normal(size=(n, 3))
    v[:, 2] = np.abs(v[:, 2])
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def bench_eval(pairs, rounds):
    rng = np.random.default_rng(0)
    wi, wo = hemisphere(rng, pairs), hemisphere(rng, pairs)
    out = {}
    for name in brdf.PRESETS:
        fab = brdf.fabric(name)
        t = interleaved({(b, ""): (lambda: fab.eval(wi, wo)) for b in ("numpy", "drjit")},
                        rounds)
        t = {b: v for (b, _), v in t.items()}
        out[name] = t
        print(f"eval  {name:32s} {pairs} pairs  numpy {t['numpy'] * 1e3:8.1f} ms  drjit "
              f"{t['drjit'] * 1e3:8.1f} ms  ratio {t['numpy'] / t['drjit']:5.1f}x", flush=True)
    return out


def walkers(fab, batch):
    """A fit's batch: each parameter of each thread spread by a few percent about the
    fabric's (gamma_v no longer 2 gamma_s: the NumPy kernel's one-exp shortcut is off, as
    in a fit that frees both)."""
    rng = np.random.default_rng(1)
    spread = lambda v: np.asarray(v) * rng.uniform(0.95, 1.05, (batch,) + np.shape(v))  # noqa: E731
    th = fab.threads
    kw = {name: spread([getattr(t, name) for t in th])
          for name in ("kd", "gamma_s", "gamma_v", "albedo")}
    kw["eta"] = 1.0 + spread([t.eta - 1.0 for t in th])
    kw["area"] = spread([t.area for t in th]) * 0.95
    return kw


def bench_prepared(batch, rounds, fabrics):
    out = {}
    for name in fabrics:
        fab = brdf.fabric(name)
        tab = gonio.measure(fab, "full:15:30", gonio.Instrument(snr=20, floor=1e-4), seed=0,
                            progress=False)
        kw = walkers(fab, batch)
        preps = {b: with_backend(b, lambda: fab.prepare(tab.wi, tab.wo))
                 for b in ("numpy", "drjit")}
        t = interleaved({(b, dt): (lambda p=p, dt=dt: p.eval(**kw, dtype=dt))
                         for b, p in preps.items() for dt in ("float64", "float32")}, rounds)
        out[name] = t
        n64, d64 = t["numpy", "float64"], t["drjit", "float64"]
        n32, d32 = t["numpy", "float32"], t["drjit", "float32"]
        print(f"batch {name:28s} {len(tab.wi)} pairs x {batch} sets  float64 numpy "
              f"{n64 * 1e3:6.1f} ms drjit {d64 * 1e3:6.1f} ms ratio {n64 / d64:4.1f}x;  "
              f"float32 numpy {n32 * 1e3:6.1f} ms drjit {d32 * 1e3:6.1f} ms ratio "
              f"{n32 / d32:4.1f}x", flush=True)
    return out


def bench_rotated(batch, rounds, name="velvet"):
    """A fit that frees the rotation: ``fab.forward(...)`` called with a rotation per set
    (``Prepared.eval_rotated``), float64."""
    fab = brdf.fabric(name)
    tab = gonio.measure(fab, "full:15:30", gonio.Instrument(snr=20, floor=1e-4), seed=0,
                        progress=False)
    kw = walkers(fab, batch)
    kw["rotation"] = np.random.default_rng(2).uniform(-90.0, 90.0, batch)
    fwds = {b: with_backend(b, lambda: fab.forward(tab.wi, tab.wo)) for b in ("numpy", "drjit")}
    t = interleaved({(b, ""): (lambda f=f: f(**kw)) for b, f in fwds.items()}, rounds)
    t = {b: v for (b, _), v in t.items()}
    print(f"rotated {name:26s} {len(tab.wi)} pairs x {batch} sets, a rotation each  float64 "
          f"numpy {t['numpy'] * 1e3:6.1f} ms drjit {t['drjit'] * 1e3:6.1f} ms ratio "
          f"{t['numpy'] / t['drjit']:4.1f}x", flush=True)
    return {name: t}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=20000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--fabrics", nargs="+", default=["silk_crepe_de_chine", "linen_plain"])
    ap.add_argument("--rst", help="also write the figures as a reStructuredText fragment")
    args = ap.parse_args()
    ok, why = jit.available()
    if not ok:
        raise SystemExit(f"Dr.Jit does not run here: {why}")
    import drjit as dr  # the benchmark's own: brdf.jit has loaded it already
    dr.set_thread_count(1)
    machine = (f"{_cpu_name()}, {os.cpu_count()} cores, Dr.Jit {dr.__version__}, LLVM "
               f"{'.'.join(map(str, dr.detail.llvm_version()))}")
    load0 = os.getloadavg()[0]
    print(f"{machine}; load average {load0:.2f}", flush=True)
    with threadpool_limits(1):
        evals = bench_eval(args.pairs, args.rounds)
        batches = bench_prepared(args.batch, args.rounds, args.fabrics)
        rotated = bench_rotated(args.batch, args.rounds)
        cores = os.cpu_count()
        dr.set_thread_count(cores)
        print(f"-- Dr.Jit on {cores} threads (NumPy still one); wall time, not CPU time:",
              flush=True)
        global _clock
        _clock = time.perf_counter
        threaded = bench_prepared(args.batch, args.rounds, args.fabrics)
    load1 = os.getloadavg()[0]
    print(f"load average after: {load1:.2f}")
    if args.rst:
        text = rst(machine, (load0, load1), args, evals, batches, rotated, threaded, cores)
        with atomic_write(args.rst, "w") as f:
            f.write(text)


def _cpu_name() -> str:
    """The CPU's model name (Linux), else the architecture."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _span(ratios) -> str:
    lo, hi = min(ratios), max(ratios)
    return f"{lo:.1f}x" if f"{lo:.1f}" == f"{hi:.1f}" else f"{lo:.1f}x to {hi:.1f}x"


def rst(machine, loads, args, evals, batches, rotated, threaded, cores) -> str:
    """The figures as a reStructuredText fragment; every sentence from the values."""
    ratio = lambda t, a="numpy", b="drjit": t[a] / t[b]  # noqa: E731
    ev = {name: ratio(t) for name, t in evals.items()}
    met = [n for n, r in ev.items() if r >= 3.0]
    b64 = {n: t["numpy", "float64"] / t["drjit", "float64"] for n, t in batches.items()}
    b32 = {n: t["numpy", "float32"] / t["drjit", "float32"] for n, t in batches.items()}
    th64 = {n: t["numpy", "float64"] / t["drjit", "float64"] for n, t in threaded.items()}
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    lines = [
        ".. generated by bench/bench_backend.py --rst; do not edit by hand",
        "",
        f"Measured {when} on {machine}, load average {loads[0]:.1f} before and "
        f"{loads[1]:.1f} after; median CPU time of {args.rounds} interleaved rounds, one "
        "thread each (numpy / drjit time, larger is faster on Dr.Jit):",
        "",
        f"- ``Fabric.eval``, float64, {args.pairs} random pairs: "
        + ", ".join(f"{n} {r:.1f}x" for n, r in ev.items())
        + f"; the target 3x met on {len(met)} preset{'s' * (len(met) != 1)} of {len(ev)}"
        + ("." if len(met) == len(ev) else
           f" (not on {', '.join(n for n in ev if n not in met)})."),
        f"- the fit's batched ``Prepared.eval`` ({args.batch} parameter sets x 3,721 pairs): "
        "float64 " + ", ".join(f"{n} {r:.1f}x" for n, r in b64.items())
        + ("; the target 10x met." if min(b64.values()) >= 10 else
           f"; the target 10x missed ({_span(b64.values())}).")
        + " float32 (a fit's sampling) " + ", ".join(f"{n} {r:.1f}x" for n, r in b32.items())
        + ".",
        f"- a fit that frees the rotation ({args.batch} sets, a rotation each, 3,721 pairs, "
        "float64: NumPy prepares each set's pairs, Dr.Jit runs one fused kernel): "
        + ", ".join(f"{n} {ratio(t):.1f}x" for n, t in rotated.items()) + ".",
        f"- the same batch with Dr.Jit on {cores} threads (NumPy on one; wall time, on the "
        "shared machine): float64 " + ", ".join(f"{n} {r:.1f}x" for n, r in th64.items())
        + ".",
        "",
    ]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
