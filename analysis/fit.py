r"""Bayesian fit of the microcylinder model to a BRDF table: point estimate, then emcee.

Pipeline (:func:`fit`):

1. Mask the table (:class:`~analysis.likelihood.Likelihood`) and check that enough valid values
   remain for the free parameters.
2. Point estimate: L-BFGS-B on the negative log-posterior from several starts (the spec's start
   and seeded perturbations of it), with a gradient by forward differences evaluated as one
   batch; then a Laplace approximation (batched finite-difference Hessian) gives the scale of the
   starting ball.
3. ``ensembles`` independent emcee ensembles (different seeds), each with ``walkers`` walkers,
   a vectorized log-probability, moves: an independence Metropolis-Hastings step from a
   Student-t fitted to the Laplace approximation (:class:`LaplaceMove`, share ``laplace_move``,
   default 0.75, scaled down when the proposal is poor), refit at doubling steps to each
   ensemble's own chain as a mixture of Student-t components in coordinates warped per
   parameter towards a normal marginal (:func:`choose_warps`), mixed with DEMove (0.8 of the
   rest) and DESnookerMove (0.2), and an HDF5
   checkpoint ``DIR/chains_<k>.h5``. The ensembles run in lock-step threads whose model
   evaluations are stacked into one batch (:class:`LockStep`), split over ``threads`` worker
   threads.
4. Every ``check_every`` steps: discard the first ``burn_fraction`` of the chain; tau per
   ensemble (emcee, ``tol=0``) averaged over ensembles; converged when for every parameter
   (N - burn) / tau > ``min_ratio`` (50), tau changed by less than ``tau_tol`` (5%) since the
   previous check, and split R-hat across ensembles < ``rhat_max`` (1.01). Otherwise it stops at
   ``max_steps`` (or ``time_limit``) and says so.

Running :func:`fit` again with the same ``out_dir`` and the same configuration resumes from the
stored chains (``progress.json`` keeps the last check, so a finished fit is summarized again
without sampling more); a different configuration or an unreadable checkpoint is a
``ValueError`` before any sampling.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import hashlib
import json
import os
import threading
import time
from pathlib import Path
from typing import Callable, Mapping

import numpy as np
import emcee
import scipy.optimize

from analysis import diagnostics
from analysis.likelihood import Likelihood
from analysis.params import ParamSpec
from analysis.proposal import (MIXTURE_COMPONENTS, WARPS, LaplaceMove, choose_warps,
                               proposal_share)

__all__ = ["fit", "FitResult", "LogPosterior", "LockStep", "FabricModel", "point_estimate",
           "write_results", "CONFIG_FILE"]

CONFIG_FILE = "fit_config.json"

# ---------------------------------------------------------------------------- forward model
class FabricModel:
    """Forward model of a fabric at fixed direction pairs, batched over parameters.

    Wraps ``fab.prepare(wi, wo)``; the call takes the keyword arguments of ``prep.eval``
    (each (B..., 2), albedo (B..., 2, 3)) and optionally ``tangent_scale`` (B..., 2), a factor
    on each thread's tangent offsets. Scaled curves cannot be prepared once: that slow path
    rebuilds the fabric and its preparation for every batch row whose factors differ from 1.
    """

    def __init__(self, fab, wi, wo):
        self.fab = fab
        self.wi = np.asarray(wi, dtype=np.float64)
        self.wo = np.asarray(wo, dtype=np.float64)
        self.prep = fab.prepare(self.wi, self.wo)

    def __call__(self, tangent_scale=None, **kw) -> np.ndarray:
        if tangent_scale is None or np.all(np.asarray(tangent_scale) == 1.0):
            return self.prep.eval(**kw)
        ts = np.asarray(tangent_scale, dtype=np.float64)
        batch = ts.shape[:-1]
        flat_kw = {k: np.asarray(v).reshape((-1,) + np.shape(v)[len(batch):])
                   for k, v in kw.items()}
        out = np.empty((int(np.prod(batch)), self.wi.shape[0], 3))
        ts = ts.reshape(-1, 2)
        for b in range(ts.shape[0]):
            threads = tuple(
                th.replace(offsets=tuple(np.clip(np.asarray(th.offsets) * ts[b, j], -90, 90)))
                for j, th in enumerate(self.fab.threads))
            prep = self.fab.replace(threads=threads).prepare(self.wi, self.wo)
            out[b] = prep.eval(**{k: v[b] for k, v in flat_kw.items()})
        return out.reshape(batch + out.shape[1:])


# ---------------------------------------------------------------------------- posterior
class LogPosterior:
    """log prior + log likelihood, vectorized: theta (B, ndim) -> (B,).

    Parameters
    ----------
    spec : ParamSpec
    likelihood : Likelihood
    model : callable
        ``model(**kwargs) -> (B, n, 3)`` f_r in 1/sr, kwargs as :meth:`ParamSpec.model_kwargs`
        (plus ``tangent_scale`` when a tangent scale is free or not 1).
    """

    def __init__(self, spec: ParamSpec, likelihood: Likelihood, model: Callable):
        self.spec, self.lik, self.model = spec, likelihood, model
        self.n_evals = 0
        self._lock = threading.Lock()
        names = set(spec.free) | set(spec.ties)
        self.use_scale = "scale" in names or spec.params["scale"].default != 1.0
        self.use_noise = "log_noise" in names
        self.use_tangent = bool({"tangent_scale1", "tangent_scale2"} & names) or any(
            spec.params[f"tangent_scale{j}"].default != 1.0 for j in (1, 2))

    def predict(self, theta) -> np.ndarray:
        """Model f_r (B, n, 3) for internal theta (B, ndim), scale included."""
        theta = np.atleast_2d(np.asarray(theta, dtype=np.float64))
        v = self.spec.values(theta)
        kw = self.spec.model_kwargs(v)
        if self.use_tangent:
            kw["tangent_scale"] = np.stack([v["tangent_scale1"], v["tangent_scale2"]], -1)
        out = np.asarray(self.model(**kw), dtype=np.float64)
        if self.use_scale:
            out = out * v["scale"][:, None, None]
        return out

    def __call__(self, theta) -> np.ndarray:
        theta = np.atleast_2d(np.asarray(theta, dtype=np.float64))
        lp = self.spec.log_prior(theta)
        ok = np.isfinite(lp)
        out = np.full(theta.shape[0], -np.inf)
        if np.any(ok):
            th = theta[ok]
            v = self.spec.values(th)
            with np.errstate(all="ignore"):
                pred = self.predict(th)
                ll = self.lik(pred, log_noise=v["log_noise"] if self.use_noise else None)
            out[ok] = lp[ok] + ll
            with self._lock:
                self.n_evals += int(ok.sum())
        return out


class _Aborted(Exception):
    pass


class LockStep:
    """Stack the log-probability calls of several ensembles into one batched evaluation.

    Each ensemble runs in its own thread and calls :meth:`call`; when every active ensemble
    has a pending request, their walkers are concatenated, evaluated in ``threads`` chunks
    (numpy releases the GIL), and the results handed back. An ensemble that finishes calls
    :meth:`leave`; :meth:`abort` makes every waiting call raise (for interrupts).
    """

    def __init__(self, fn: Callable, n: int, threads: int = 1):
        self.fn, self.active = fn, n
        self.cond = threading.Condition()
        self.pending: dict[int, np.ndarray] = {}
        self.results: dict[int, np.ndarray] = {}
        self.generation = 0
        self.aborted = False
        self.error: BaseException | None = None
        self.pool = cf.ThreadPoolExecutor(threads) if threads > 1 else None
        self.threads = threads

    def _evaluate(self, x: np.ndarray) -> np.ndarray:
        if self.pool is None or x.shape[0] < 2 * self.threads:
            return self.fn(x)
        parts = np.array_split(x, self.threads)
        return np.concatenate(list(self.pool.map(self.fn, parts)))

    def _flush(self):
        keys = sorted(self.pending)
        xs = [self.pending[k] for k in keys]
        try:
            out = self._evaluate(np.concatenate(xs))
        except BaseException as exc:  # hand the error to every waiter
            self.error = exc
            out = None
        i = 0
        for k, x in zip(keys, xs):
            self.results[k] = None if out is None else out[i:i + len(x)]
            i += len(x)
        self.pending.clear()
        self.generation += 1
        self.cond.notify_all()

    def call(self, k: int, x: np.ndarray) -> np.ndarray:
        with self.cond:
            if self.aborted:
                raise _Aborted()
            self.pending[k] = np.asarray(x, dtype=np.float64)
            gen = self.generation
            if len(self.pending) >= self.active:
                self._flush()
            else:
                while self.generation == gen and not self.aborted:
                    self.cond.wait()
            if self.aborted:
                raise _Aborted()
            res = self.results.pop(k)
            if res is None:
                raise RuntimeError(f"model evaluation failed: {self.error!r}") from self.error
            return res

    def leave(self):
        with self.cond:
            self.active -= 1
            if self.pending and len(self.pending) >= self.active:
                self._flush()

    def join(self):
        with self.cond:
            self.active += 1

    def abort(self):
        with self.cond:
            self.aborted = True
            self.cond.notify_all()

    def close(self):
        if self.pool is not None:
            self.pool.shutdown(wait=True)


# ---------------------------------------------------------------------------- point estimate
def _fd_grad_batch(x, h, lower, upper):
    d = x.size
    pts = np.repeat(x[None], d + 1, axis=0)
    steps = np.where(x + h <= upper, h, -h)
    pts[np.arange(1, d + 1), np.arange(d)] += steps
    return pts, steps


def point_estimate(logpost: LogPosterior, starts: np.ndarray, maxiter: int = 300):
    """Maximum a posteriori estimate from several starts (L-BFGS-B, batched FD gradient).

    Parameters
    ----------
    logpost : LogPosterior
    starts : ndarray, shape (k, ndim)
        Internal coordinates of the starts.

    Returns
    -------
    best : ndarray (ndim,)
        Internal coordinates of the best optimum found.
    best_logp : float
    all_logp : list of float
        Final log-posterior of each start.
    """
    spec = logpost.spec
    lower, upper = spec.lower, spec.upper
    h = 1e-6 * spec.width
    big = 1e30

    def fun_grad(x):
        pts, steps = _fd_grad_batch(x, h, lower, upper)
        lp = logpost(pts)
        f0 = -lp[0]
        if not np.isfinite(f0):
            return big, np.zeros_like(x)
        fi = np.where(np.isfinite(lp[1:]), -lp[1:], f0 + 1e6 * np.abs(steps))
        return float(f0), (fi - f0) / steps

    results = []
    for s in np.atleast_2d(starts):
        if not np.isfinite(logpost(s[None])[0]):
            results.append((s, -np.inf))
            continue
        r = scipy.optimize.minimize(fun_grad, s, jac=True, method="L-BFGS-B",
                                    bounds=list(zip(lower, upper)),
                                    options={"maxiter": maxiter})
        results.append((r.x, -float(r.fun) if r.fun < big else -np.inf))
    i = int(np.argmax([r[1] for r in results]))
    return results[i][0], results[i][1], [r[1] for r in results]


def _laplace_cov(logpost: LogPosterior, x: np.ndarray) -> np.ndarray | None:
    """Covariance from a batched central finite-difference Hessian of -log p at x.

    Two passes: steps of 1e-4 of each parameter's range, then 0.2 posterior standard
    deviations from the first pass.
    """
    spec = logpost.spec
    width = spec.width
    cov = _hessian_cov(logpost, x, 1e-4 * width)
    if cov is None:
        return None
    h = np.minimum(0.2 * np.sqrt(np.diag(cov)), 1e-2 * width)
    return _hessian_cov(logpost, x, h) if np.all(h > 0) else cov


def _hessian_cov(logpost: LogPosterior, x: np.ndarray, h: np.ndarray):
    spec = logpost.spec
    d = x.size
    # keep the stencil inside the bounds
    x = np.clip(x, spec.lower + 2 * h, spec.upper - 2 * h)
    e = np.eye(d) * h
    pts = [x]
    for i in range(d):
        pts += [x + e[i], x - e[i]]
    for i in range(d):
        for j in range(i + 1, d):
            pts += [x + e[i] + e[j], x + e[i] - e[j], x - e[i] + e[j], x - e[i] - e[j]]
    f = -logpost(np.array(pts))
    if not np.all(np.isfinite(f)):
        return None
    H = np.empty((d, d))
    f0 = f[0]
    for i in range(d):
        H[i, i] = (f[1 + 2 * i] - 2 * f0 + f[2 + 2 * i]) / h[i] ** 2
    k = 1 + 2 * d
    for i in range(d):
        for j in range(i + 1, d):
            fpp, fpm, fmp, fmm = f[k:k + 4]
            H[i, j] = H[j, i] = (fpp - fpm - fmp + fmm) / (4 * h[i] * h[j])
            k += 4
    if not np.all(np.isfinite(H)):
        return None
    # Not positive definite (a parameter against a bound, a flat or rough direction): keep
    # the curvature where it is positive and cap every standard deviation at a tenth of the
    # parameter's range, so the proposal and the starting ball stay usable.
    width = spec.width
    Hs = H * np.outer(width, width)                       # in units of each range
    w, v = np.linalg.eigh(0.5 * (Hs + Hs.T))
    w = np.maximum(w, 100.0)                              # sd <= 0.1 range
    cov = (v / w) @ v.T * np.outer(width, width)
    try:
        np.linalg.cholesky(cov)
    except np.linalg.LinAlgError:
        return None
    return cov


def _initial_walkers(logpost, best, cov, nwalkers, rng, spec):
    width = spec.width
    d = best.size
    if cov is None:
        cov = np.diag((1e-3 * width) ** 2)
    out = np.empty((0, d))
    for shrink in (1.0, 0.3, 0.1, 0.03, 0.01, 1e-3, 1e-4):
        cand = rng.multivariate_normal(best, cov * shrink, size=4 * nwalkers)
        lp = logpost(cand)
        out = np.concatenate([out, cand[np.isfinite(lp)]])[:nwalkers]
        if len(out) >= nwalkers:
            return out
    raise RuntimeError("could not place the walkers around the point estimate: the "
                       "log-posterior is not finite near it")


# ---------------------------------------------------------------------------- results
@dataclasses.dataclass
class FitResult:
    """Everything a fit produced.

    Attributes
    ----------
    names, units : tuple of str
        Free parameters, in order.
    chains : ndarray (ensembles, steps, walkers, ndim)
        Post-burn-in samples in natural units.
    chains_internal : ndarray
        The same in the sampler's internal coordinates.
    summary : dict name -> dict
        median, lo68, hi68, lo95, hi95, tau, n_over_tau, rhat, ess, unit.
    converged : bool
    reason : str
        Why sampling stopped (criterion met, step limit, time limit).
    """

    names: tuple
    units: tuple
    chains: np.ndarray
    chains_internal: np.ndarray
    log_prob: np.ndarray
    summary: dict
    converged: bool
    reason: str
    steps: int
    burn: int
    walkers: int
    ensembles: int
    acceptance: list
    best: dict
    best_logp: float
    counts: dict
    timing: dict
    spec: ParamSpec = dataclasses.field(repr=False, default=None)
    logpost: LogPosterior = dataclasses.field(repr=False, default=None)

    def to_json(self) -> dict:
        """The JSON document written as ``results.json``."""
        doc = {n: {k: (float(v) if isinstance(v, (float, np.floating, int, np.integer)) else v)
                   for k, v in self.summary[n].items()} for n in self.names}
        doc["converged"] = bool(self.converged)
        doc["_fit"] = {
            "reason": self.reason, "steps": self.steps, "burn": self.burn,
            "walkers": self.walkers, "ensembles": self.ensembles,
            "acceptance_fraction": [float(a) for a in self.acceptance],
            "map": {k: float(v) for k, v in self.best.items()},
            "map_log_posterior": float(self.best_logp),
            "points": self.counts, "timing": self.timing,
            "ties": {k: list(v) for k, v in self.spec.ties.items()} if self.spec else {},
        }
        if self.logpost is not None:
            q = self.residuals()
            doc["_fit"]["quality"] = {"rms_residual": q["rms"],
                                      "rms_normalized": q["rms_normalized"],
                                      "values": int(q["residual"].size)}
        return doc

    def samples(self, flat: bool = True) -> np.ndarray:
        """Natural-unit samples, (N, ndim) when flat."""
        return self.chains.reshape(-1, len(self.names)) if flat else self.chains

    def residuals(self) -> dict:
        """How well the posterior median explains the table.

        Returns
        -------
        dict
            ``residual`` (n_used,): data minus model in the likelihood's space (log(1 + f_r
            cos theta_i) by default; log f_r for "relative") at the posterior median,
            ``normalized``: the same over the noise scale (the table's sigma propagated, with
            the fitted extra noise), and their root mean squares ``rms`` and
            ``rms_normalized`` (near 1 when the model explains the data to within its noise).
        """
        med = np.median(self.chains_internal.reshape(-1, len(self.names)), axis=0)
        lik = self.logpost.lik
        r = lik.y - lik.transform(self.logpost.predict(med[None]))[0]
        s2 = np.zeros_like(r) if lik.sigma_y2 is None else lik.sigma_y2
        if "log_noise" in self.names:
            s2 = s2 + np.exp(2 * self.spec.to_natural(med)[self.names.index("log_noise")])
        z = r / np.sqrt(s2)
        return {"residual": r, "normalized": z, "rms": float(np.sqrt(np.mean(r * r))),
                "rms_normalized": float(np.sqrt(np.mean(z * z)))}


def _atomic_write(path: Path, text: str):
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_text(text)
    os.replace(tmp, path)


def write_results(result: FitResult, out_dir, doc: Mapping | None = None) -> tuple[Path, Path]:
    """Write ``results.json`` (``doc``, default ``result.to_json()``) and ``results.csv`` into
    ``out_dir`` (atomically)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    jpath, cpath = out / "results.json", out / "results.csv"
    doc = result.to_json() if doc is None else doc
    _atomic_write(jpath, json.dumps(doc, indent=2, default=_json_default) + "\n")
    cols = ["median", "lo68", "hi68", "lo95", "hi95", "tau", "n_over_tau", "rhat", "ess", "unit"]
    lines = ["parameter," + ",".join(cols)]
    for n in result.names:
        s = result.summary[n]
        lines.append(n + "," + ",".join(
            s[c] if isinstance(s[c], str) else f"{float(s[c]):.8g}" for c in cols))
    lines.append(f"# converged,{str(result.converged).lower()},{result.reason}")
    _atomic_write(cpath, "\n".join(lines) + "\n")
    return jpath, cpath


def _json_default(o):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    return str(o)


# ---------------------------------------------------------------------------- checkpoints
def _table_digest(table) -> str:
    h = hashlib.sha256()
    for a in (table.wi, table.wo, table.values, table.sigma):
        h.update(b"none" if a is None else np.ascontiguousarray(a, dtype=np.float64).tobytes())
    return h.hexdigest()[:16]


def _open_backend(path: Path, nwalkers: int, ndim: int):
    """Open an existing checkpoint, or raise a ValueError naming the file."""
    try:
        backend = emcee.backends.HDFBackend(str(path))
        if not backend.initialized:
            raise ValueError("no chain group in it")
        shape = backend.shape
        it = backend.iteration
        if it > 0:
            backend.get_last_sample()
    except (OSError, KeyError, ValueError, AttributeError) as exc:
        raise ValueError(f"{path}: corrupt or unreadable checkpoint ({exc}); delete it (or "
                         f"the whole output folder) to start again") from None
    if shape != (nwalkers, ndim):
        raise ValueError(f"{path}: checkpoint holds {shape[0]} walkers x {shape[1]} "
                         f"parameters, this fit needs {nwalkers} x {ndim}")
    return backend


# ---------------------------------------------------------------------------- main entry
def fit(table, spec: ParamSpec, model: Callable, *, likelihood: str = "gaussian",
        nu: float = 4.0, ensembles: int = 4, walkers: int | None = None, seed: int = 0,
        max_steps: int = 20000, check_every: int = 50, min_ratio: float = 50.0,
        tau_tol: float = 0.05, rhat_max: float = 1.01, burn_fraction: float = 0.2,
        n_starts: int = 4, laplace_move: float = 0.75, adapt: int | None = None,
        threads: int | None = None, out_dir=None,
        time_limit: float | None = None, progress: bool = True,
        config_extra: Mapping | None = None) -> FitResult:
    """Fit the free parameters of ``spec`` to ``table``; see the module notes.

    Parameters
    ----------
    table : gonio.Table-like
        The measurements (f_r in 1/sr, or relative when its meta says so).
    spec : ParamSpec
        Free, fixed and tied parameters. ``log_noise`` is added to the free set when the table
        has no sigma; ``scale`` when the table's meta says its values are relative.
    model : callable
        ``model(**kwargs) -> (B, n, 3)`` at the table's pairs, e.g. :class:`FabricModel`.
    likelihood : {"gaussian", "relative", "student-t"}
    ensembles : int
        Independent ensembles (>= 2 for R-hat).
    walkers : int, optional
        Walkers per ensemble (>= 2 x ndim; default 2 x ndim + 2, even).
    seed : int
        Seeds the optimizer starts and every ensemble (via SeedSequence).
    max_steps : int
        Step limit per ensemble.
    laplace_move : float
        Largest share of the independence move (0 turns it off).
    adapt : int, optional
        First of the steps ``adapt``, ``2 adapt``, ``4 adapt``, ... (doubling, below
        ``max_steps``) at which each ensemble may refit its independence proposal to the
        second half of its own chain so far, as a mixture of 1, 2, 4 or 8 Student-t
        components (:data:`MIXTURE_COMPONENTS`), in internal coordinates and in coordinates
        warped per parameter (:func:`choose_warps`), fitted to half the walkers; the one
        with the largest mean log density on the other half is taken (default
        ``2 * check_every``; 0 for never). A refit is kept only when it raises the expected
        acceptance rate of the move on that half by more than 10%. The burn-in is at least the
        step of the last kept refit, up to half the chain; every kernel used leaves the
        posterior invariant and each depends only on the chain before it, and the number of
        refits is finite.
    out_dir : path, optional
        Folder for ``fit_config.json`` and the checkpoints ``chains_<k>.h5``; resumes there.
    time_limit : float, optional
        Seconds after which sampling stops (checked at each convergence check).

    Returns
    -------
    FitResult

    Raises
    ------
    ValueError
        Too few valid values for the free parameters, bad options, a checkpoint made with
        another configuration, or a corrupt checkpoint: all before sampling starts.
    """
    t0 = time.perf_counter()
    lik = Likelihood(table, kind=likelihood, nu=nu)
    extra = []
    if not lik.has_sigma and "log_noise" not in spec.free:
        extra.append("log_noise")
    if lik.relative_data and "scale" not in spec.free:
        extra.append("scale")
    if extra:
        spec = ParamSpec(list(spec.free) + extra,
                         defaults={n: p.default for n, p in spec.params.items()},
                         ties=spec.ties,
                         bounds={n: (p.lo, p.hi) for n, p in spec.params.items()},
                         priors={n: p.prior for n, p in spec.params.items()})
    ndim = spec.ndim
    if lik.n_used <= ndim:
        c = lik.counts
        raise ValueError(
            f"table has {lik.n_used} valid values for {ndim} free parameters (need more than "
            f"{ndim}); masked: {c['invalid_value']} NaN/negative, {c['below_horizon']} below "
            f"the horizon, {c['bad_sigma']} with bad sigma, {c['zero_value']} zero")
    if ensembles < 2:
        raise ValueError(f"ensembles must be >= 2 (R-hat is computed across them); got "
                         f"{ensembles}")
    if walkers is None:
        walkers = 2 * ndim + 2
        walkers += walkers % 2
    if walkers < 2 * ndim:
        raise ValueError(f"walkers must be >= 2 x ndim = {2 * ndim}; got {walkers}")
    if max_steps < 1 or check_every < 1:
        raise ValueError(f"max_steps and check_every must be >= 1; got {max_steps}, "
                         f"{check_every}")
    if adapt is None:
        adapt = 2 * check_every if laplace_move > 0 else 0
    if adapt < 0 or (adapt and laplace_move <= 0):
        raise ValueError(f"adapt must be >= 0, and 0 when laplace_move is 0; got {adapt}")
    threads = threads or min(2, os.cpu_count() or 1)
    logpost = LogPosterior(spec, lik, model)

    config = {
        "version": 6, "spec": spec.describe(), "likelihood": likelihood, "nu": nu,
        "ensembles": ensembles, "walkers": walkers, "seed": seed,
        "table": _table_digest(table), "n_used": lik.n_used,
        "laplace_move": laplace_move, "adapt": adapt,
        **({"extra": dict(config_extra)} if config_extra else {}),
    }
    out = Path(out_dir) if out_dir is not None else None
    backends = [None] * ensembles
    state = None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        cpath = out / CONFIG_FILE
        if cpath.exists():
            try:
                stored = json.loads(cpath.read_text())
                stored_cfg = stored["config"]
            except (ValueError, KeyError) as exc:
                raise ValueError(f"{cpath}: corrupt fit configuration ({exc}); delete the "
                                 f"folder to start again") from None
            if json.loads(json.dumps(config, default=_json_default)) != stored_cfg:
                diff = sorted(k for k in set(config) | set(stored_cfg)
                              if json.loads(json.dumps(config.get(k), default=_json_default))
                              != stored_cfg.get(k))
                raise ValueError(f"{out} holds a fit with another configuration (differs in: "
                                 f"{', '.join(diff)}); use another output folder or delete it")
            state = stored
        for k in range(ensembles):
            p = out / f"chains_{k}.h5"
            if p.exists():
                if state is None:
                    raise ValueError(f"{p}: checkpoint without {CONFIG_FILE}; delete it to "
                                     f"start again")
                backends[k] = _open_backend(p, walkers, ndim)
            else:
                backends[k] = emcee.backends.HDFBackend(str(p))

    ss = np.random.SeedSequence(seed)
    rng_opt, *rng_ens = [np.random.default_rng(s) for s in ss.spawn(ensembles + 1)]
    if state is not None and "best" in state:
        best = np.asarray(state["best"], dtype=np.float64)
        best_logp = float(state["best_logp"])
        cov = None if state.get("cov") is None else np.asarray(state["cov"])
    else:
        start = spec.start()
        lp0 = logpost(start[None])[0]
        if not np.isfinite(lp0):
            raise ValueError(f"the log-posterior is not finite at the start "
                             f"{dict(zip(spec.free, spec.to_natural(start).tolist()))}; "
                             f"check the bounds, ties and the table")
        width = spec.width
        starts = [start]
        for _ in range(max(0, n_starts - 1)):
            s = start + rng_opt.normal(scale=0.05 * width)
            starts.append(np.clip(s, spec.lower, spec.upper))
        best, best_logp, _ = point_estimate(logpost, np.array(starts))
        cov = _laplace_cov(logpost, best)
        if out is not None:
            _atomic_write(out / CONFIG_FILE, json.dumps(
                {"config": config, "best": best.tolist(), "best_logp": best_logp,
                 "cov": None if cov is None else cov.tolist()},
                indent=1, default=_json_default))
    t_opt = time.perf_counter() - t0

    laplace_info = {"share": 0.0, "importance_ess_fraction": None}
    share = 0.0
    if cov is not None and laplace_move > 0:
        share, frac = proposal_share(logpost, LaplaceMove(best, cov), laplace_move,
                                     np.random.default_rng(seed))
        laplace_info = {"share": share, "importance_ess_fraction": frac}
    # doubling: the proposal keeps up with chains that explore a long ridge slowly
    schedule = []
    while 0 < adapt * 2 ** len(schedule) < max_steps:
        schedule.append(adapt * 2 ** len(schedule))
    laplace_info["adapt_schedule"] = schedule
    last_adapt = [0] * ensembles          # step of each ensemble's last kept refit
    laplace_moves = [None] * ensembles

    def make_moves(k):
        # one set per ensemble: emcee's DE moves set attributes in setup(), not thread-safe
        g0 = 2.38 / np.sqrt(2 * ndim)
        moves = [(emcee.moves.DEMove(gamma0=g0), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
        if laplace_move <= 0:
            return moves
        # present even without a usable Laplace covariance (weight 0) so that it can adapt
        lm = LaplaceMove(best, cov if cov is not None else
                         np.diag((1e-2 * spec.width) ** 2))
        laplace_moves[k] = lm
        return [(m, w * (1 - share)) for m, w in moves] + [(lm, share)]

    def adapt_moves(k, a):
        """Refit ensemble k's independence proposal at step ``a`` to its own chain over steps
        a/2 to a: mixtures of :data:`MIXTURE_COMPONENTS` components, in internal and in warped
        coordinates (:func:`choose_warps`), fitted to the even-numbered walkers; the one with
        the largest mean log q on the odd-numbered ones (held out) is compared with the current
        proposal by their expected acceptance rates there and kept if clearly better.
        Deterministic given the stored chain, so a resumed fit repeats every decision
        exactly."""
        s = samplers[k]
        # read only steps a/2 to a from the checkpoint (a resumed fit replays early refits)
        chain = s.get_chain(discard=a // 2)[:a - a // 2]
        lps = s.get_log_prob(discard=a // 2)[:a - a // 2]
        x = chain[:, 0::2].reshape(-1, ndim)
        xt, lpt = chain[:, 1::2].reshape(-1, ndim), lps[:, 1::2].reshape(-1)
        pick = np.random.default_rng([seed, k, a, 1]).permutation(len(xt))[:2048]
        xt, lpt = xt[pick], lpt[pick]
        x = x[np.random.default_rng([seed, k, a, 2]).permutation(len(x))[:16384]]
        move, score = None, -np.inf
        chosen = choose_warps(x)
        for warps in [np.zeros(ndim, dtype=int)] + ([chosen] if chosen.any() else []):
            for K in MIXTURE_COMPONENTS:
                cand = LaplaceMove.from_samples(x, K, np.random.default_rng([seed, k, a, K]),
                                                ridge=(1e-9 * spec.width) ** 2, warps=warps)
                if cand is None:
                    continue
                with np.errstate(invalid="ignore"):
                    sc = float(np.mean(cand.logq(xt)))
                if np.isfinite(sc) and sc > score:
                    move, score = cand, sc
        lm = laplace_moves[k]
        if move is None:
            return {"step": a, "kept": False}
        sh, frac = proposal_share(logpost, move, laplace_move,
                                  np.random.default_rng([seed, k, a]), xt, lpt)
        _, frac_now = proposal_share(logpost, lm, laplace_move,
                                     np.random.default_rng([seed, k, a]), xt, lpt)
        s_weights = np.array(s._weights, dtype=np.float64)
        if not (np.isfinite(frac) and (not np.isfinite(frac_now) or frac > 1.1 * frac_now
                                       or s_weights[-1] == 0)):
            return {"step": a, "kept": False, "acceptance": frac, "current": frac_now}
        lm.copy_from(move)
        w = s_weights
        w[:-1] = w[:-1] / max(w[:-1].sum(), 1e-300) * (1 - sh)
        w[-1] = sh
        s._weights = w / w.sum()
        last_adapt[k] = a
        return {"step": a, "kept": True, "share": sh, "acceptance": frac,
                "components": move.n_components, "warps": [WARPS[i] for i in move.warps],
                "previous": frac_now}

    lock = LockStep(logpost, ensembles, threads=threads)
    samplers = []
    for k in range(ensembles):
        s = emcee.EnsembleSampler(walkers, ndim, (lambda x, k=k: lock.call(k, x)),
                                  moves=make_moves(k), vectorize=True, backend=backends[k])
        # emcee's wrapper prints a traceback for any exception (interrupts included); the
        # errors are reported by fit's caller instead
        s.log_prob_fn = (lambda x, k=k: lock.call(k, x))
        if s.iteration == 0:
            s.random_state = np.random.RandomState(
                rng_ens[k].integers(2**31)).get_state()
            s._init = _initial_walkers(logpost, best, cov, walkers, rng_ens[k], spec)
        samplers.append(s)

    def run_to(target):
        lock.active = 0
        jobs = [k for k, s in enumerate(samplers) if s.iteration < target]
        lock.active = len(jobs)

        def job(k):
            s = samplers[k]
            try:
                init = getattr(s, "_init", None) if s.iteration == 0 else None
                s._init = None
                s.run_mcmc(init, target - s.iteration, progress=False)
            finally:
                lock.leave()

        with cf.ThreadPoolExecutor(max(1, len(jobs))) as ex:
            futs = [ex.submit(job, k) for k in jobs]
            try:
                while True:
                    done, pending = cf.wait(futs, timeout=0.25)
                    if bar is not None:
                        bar.n = min(s.iteration for s in samplers)
                        bar.refresh()
                    if not pending:
                        break
            except KeyboardInterrupt:
                lock.abort()
                cf.wait(futs)
                raise
            for f in futs:
                exc = f.exception()
                if exc is not None and not isinstance(exc, _Aborted):
                    raise exc

    laplace_info["adaptations"] = []
    adapt_evals = [0]
    next_adapt = [0]                      # index into schedule of the next refit point

    def maybe_adapt():
        """Refit every ensemble at each schedule point reached (all of them, in order, when a
        resumed fit starts: the decisions replay exactly from the stored chains)."""
        e0 = logpost.n_evals
        n = min(s.iteration for s in samplers)
        try:
            while next_adapt[0] < len(schedule) and schedule[next_adapt[0]] <= n:
                a = schedule[next_adapt[0]]
                for k in range(ensembles):
                    laplace_info["adaptations"].append(dict(adapt_moves(k, a), ensemble=k))
                next_adapt[0] += 1
        finally:
            adapt_evals[0] += logpost.n_evals - e0

    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=max_steps, desc="emcee", unit="step", leave=False,
                   initial=min(s.iteration for s in samplers))
    t_s0 = time.perf_counter()
    evals0 = logpost.n_evals
    tau_prev = None
    reason, converged = "", False
    diag = None
    ppath = None if out is None else out / "progress.json"
    try:
        target = min(s.iteration for s in samplers)
        # resuming right after a check: reuse its tau, and check before sampling more
        recheck = False
        if ppath is not None and ppath.exists() and target > 0 and \
                all(s.iteration == target for s in samplers):
            try:
                prog = json.loads(ppath.read_text())
                if prog.get("step") == target:
                    tp = prog.get("tau_prev")
                    tau_prev = None if tp is None else np.asarray(tp, dtype=np.float64)
                    recheck = True
            except (ValueError, KeyError):
                pass
        maybe_adapt()
        while True:
            if not recheck:
                nxt = (target // check_every + 1) * check_every
                nxt = min([nxt] + [a for a in schedule if a > target])
                target = min(max_steps, nxt)
                run_to(target)
                maybe_adapt()
            recheck = False
            diag = _diagnose(samplers, burn_fraction, max(last_adapt))
            tau = diag["tau"]
            if ppath is not None:   # lets a resumed run repeat this check's verdict
                _atomic_write(ppath, json.dumps(
                    {"step": int(target), "tau": tau.tolist(),
                     "tau_prev": None if tau_prev is None else tau_prev.tolist()},
                    default=_json_default))
            n_eff_len = diag["steps"]
            ratio = n_eff_len / tau
            dtau = np.inf if tau_prev is None else np.max(np.abs(tau - tau_prev) / tau)
            tau_prev = tau
            ok = (np.all(ratio > min_ratio) and dtau < tau_tol
                  and np.all(diag["rhat"] < rhat_max))
            if bar is not None:
                bar.set_postfix({"min N/tau": f"{ratio.min():.1f}", "dtau": f"{dtau:.3f}",
                                 "max R-hat": f"{np.nanmax(diag['rhat']):.3f}"})
            if ok:
                converged = True
                reason = (f"converged at step {target}: N/tau > {min_ratio:g} for every "
                          f"parameter (min {ratio.min():.1f}), tau changed {100 * dtau:.1f}% "
                          f"< {100 * tau_tol:g}% since the last check, R-hat < {rhat_max:g}")
                break
            stuck = ("; tau undefined for some parameter (a walker did not move)"
                     if np.any(~np.isfinite(tau)) else "")
            why = (f"min N/tau {np.nanmin(ratio):.1f} (need > {min_ratio:g}), tau change "
                   f"{100 * dtau:.1f}% (need < {100 * tau_tol:g}%), max R-hat "
                   f"{np.nanmax(diag['rhat']):.3f} (need < {rhat_max:g}){stuck}")
            if target >= max_steps:
                reason = f"NOT converged: step limit {max_steps} reached; {why}"
                break
            if time_limit is not None and time.perf_counter() - t0 > time_limit:
                reason = f"NOT converged: time limit {time_limit:g} s reached at step {target}; {why}"
                break
    finally:
        if bar is not None:
            bar.close()
        lock.close()
    t_sample = time.perf_counter() - t_s0
    n_evals = logpost.n_evals - evals0 - adapt_evals[0]

    internal = diag["chains"]
    natural = spec.to_natural(internal)
    summ = diagnostics.interval_summary(natural)
    ess = diagnostics.ess(internal, diag["taus"])
    summary = {}
    for i, n in enumerate(spec.free):
        summary[n] = {k: float(summ[k][i]) for k in summ}
        summary[n].update(tau=float(diag["tau"][i]),
                          n_over_tau=float(diag["steps"] / diag["tau"][i]),
                          rhat=float(diag["rhat"][i]), ess=float(ess[i]),
                          unit=spec.params[n].unit)
    wall = time.perf_counter() - t0
    timing = {"wall_s": wall, "optimize_s": t_opt, "sample_s": t_sample,
              "log_prob_evals": int(n_evals),
              "evals_per_s": n_evals / t_sample if t_sample > 0 else float("nan"),
              "ess_per_s": float(np.min(ess) / t_sample) if t_sample > 0 else float("nan"),
              "laplace_move": laplace_info, "adapt_evals": int(adapt_evals[0])}
    return FitResult(
        names=spec.free, units=spec.units, chains=natural, chains_internal=internal,
        log_prob=diag["log_prob"], summary=summary, converged=converged, reason=reason,
        steps=int(min(s.iteration for s in samplers)), burn=int(diag["burn"]),
        walkers=walkers, ensembles=ensembles,
        acceptance=[float(np.mean(s.acceptance_fraction)) for s in samplers],
        best=dict(zip(spec.free, spec.to_natural(best).tolist())), best_logp=best_logp,
        counts=dict(lik.counts), timing=timing, spec=spec, logpost=logpost)


def _diagnose(samplers, burn_fraction, last_adapt=0):
    n = min(s.iteration for s in samplers)
    burn = max(int(burn_fraction * n), min(last_adapt, n // 2))
    chains = np.stack([s.get_chain()[burn:n] for s in samplers])   # (m, steps, w, d)
    logp = np.stack([s.get_log_prob()[burn:n] for s in samplers])
    taus = np.stack([diagnostics.autocorr_time(c) for c in chains])
    return {"chains": chains, "log_prob": logp, "taus": taus, "tau": taus.mean(axis=0),
            "rhat": diagnostics.split_rhat(chains), "steps": n - burn, "burn": burn}
