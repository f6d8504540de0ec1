"""``fit``: options checked up front, point estimate, sampling, the result.

BLAS is held to one thread for the whole fit (threadpoolctl): the fit's own threads already
use the cores, and a multi-threaded BLAS inside each of them (the proposal's triangular solves,
the EM fits) fights them for the cores.
"""

from __future__ import annotations

import dataclasses
import math
import os
import time
from typing import Callable, Mapping

import numpy as np
from threadpoolctl import threadpool_limits

from analysis.budget import FIT_BYTES_PER_VALUE, check_memory, format_seconds
from analysis.fit.checkpoint import FitFolder, table_digest
from analysis.fit.circular import circular_natural
from analysis.fit.convergence import Criteria
from analysis.fit.optimize import optimize_start
from analysis.fit.posterior import LogPosterior
from analysis.fit.progress import fit_progress
from analysis.fit.results import FitResult, summarize
from analysis.fit.sampler import FitSampler
from analysis.fit.trust import assess
from analysis.likelihood import Likelihood
from analysis.params import INTERNAL_LIMIT, ParamSpec

__all__ = ["fit", "FitOptions", "MAX_ENSEMBLES", "CONFIG_VERSION", "estimate_time", "estimate_fit_time",
           "with_nuisance"]

#: A fit that may take this many seconds or more says so before it starts (``notify``).
ESTIMATE_MIN_S = 10.0
#: Version of the sampler's configuration; a folder fitted by another version is refused.
CONFIG_VERSION = 8

#: Most ensembles of a fit: R-hat needs a few; each is a group of the one checkpoint.
MAX_ENSEMBLES = 64

#: The precisions the model may shade in while sampling (``fit(shading=...)``).
SHADINGS = ("float32", "float64")


@dataclasses.dataclass(frozen=True)
class FitOptions:
    """Options of :func:`fit` (see its parameters); :meth:`resolve` checks and completes them."""

    likelihood: str = "gaussian"
    nu: float = 4.0
    ensembles: int = 4
    walkers: int | None = None
    seed: int = 0
    max_steps: int = 20000
    check_every: int = 50
    criteria: Criteria = Criteria()
    n_starts: int = 4
    laplace_move: float = 0.75
    adapt: int | None = None
    threads: int | None = None
    time_limit: float | None = None
    shading: str = "float32"

    def check(self) -> "FitOptions":
        """The options that need no free set checked by their command-line names (the one rule
        of ``fit``, ``fit-batch`` and :meth:`resolve`): ``self``, or a ValueError naming one.

        Examples
        --------
        >>> FitOptions(ensembles=3, walkers=10).check().ensembles
        3
        >>> FitOptions(ensembles=1).check()
        Traceback (most recent call last):
        ...
        ValueError: --ensembles must be an integer in 2..64 (R-hat is computed across them); got 1
        """
        checks = [
            (self.seed >= 0, "--seed", self.seed, "a non-negative integer"),
            (2 <= self.ensembles <= MAX_ENSEMBLES, "--ensembles", self.ensembles,
             f"an integer in 2..{MAX_ENSEMBLES} (R-hat is computed across them)"),
            (self.walkers is None or self.walkers >= 2, "--walkers", self.walkers,
             "an even integer >= 2 x the number of free parameters"),
            (self.max_steps >= 1, "--max-steps", self.max_steps, "a positive integer"),
            (self.check_every >= 1, "--check-every", self.check_every, "a positive integer"),
            (self.time_limit is None or 0 < self.time_limit < math.inf, "--time-limit",
             self.time_limit, "a positive finite number of seconds"),
            (0 < self.nu < math.inf, "--nu", self.nu,
             "a positive finite number of degrees of freedom"),
        ]
        for ok, option, value, allowed in checks:
            if not ok:
                raise ValueError(f"{option} must be {allowed}; got {value}")
        return self

    def resolve(self, ndim: int) -> "FitOptions":
        """Checked (:meth:`check`, then for ``ndim`` free parameters), defaults filled in."""
        self.check()
        walkers = self.walkers
        if walkers is None:
            walkers = 2 * ndim + 2
            walkers += walkers % 2
        adapt = self.adapt
        if adapt is None:
            adapt = 2 * self.check_every if self.laplace_move > 0 else 0
        checks = [
            (walkers >= 2 * ndim and walkers % 2 == 0,
             f"walkers (--walkers) must be an even number >= 2 x ndim = {2 * ndim} ({ndim} "
             f"free parameters, log_noise and scale included); got {walkers}"),
            (0 <= self.laplace_move <= 1, f"laplace_move must be in [0, 1]; got "
                                          f"{self.laplace_move}"),
            (adapt >= 0 and not (adapt and self.laplace_move <= 0),
             f"adapt must be >= 0, and 0 when laplace_move is 0; got {adapt}"),
            (self.n_starts >= 1, f"n_starts must be >= 1; got {self.n_starts}"),
            (self.threads is None or self.threads >= 1,
             f"threads must be >= 1; got {self.threads}"),
            (self.shading in SHADINGS,
             f"shading must be one of {', '.join(SHADINGS)}; got {self.shading!r}"),
        ]
        for ok, message in checks:
            if not ok:
                raise ValueError(message)
        return dataclasses.replace(self, walkers=walkers, adapt=adapt,
                                   threads=self.threads or min(2, os.cpu_count() or 1))

    def config(self, spec: ParamSpec, table, lik: Likelihood, extra=None) -> dict:
        """What a checkpoint must match to be resumed (everything that changes the chains)."""
        return {"version": CONFIG_VERSION, "model": spec.model, "spec": spec.describe(),
                "likelihood": self.likelihood, "nu": self.nu, "ensembles": self.ensembles,
                "walkers": self.walkers, "seed": self.seed, "table": table_digest(table),
                "n_used": lik.n_used, "laplace_move": self.laplace_move, "adapt": self.adapt,
                "check_every": self.check_every,
                **({"extra": dict(extra)} if extra else {})}


def with_nuisance(spec: ParamSpec, lik: Likelihood) -> ParamSpec:
    """``spec`` plus ``log_noise`` when the table has no sigma and ``scale`` for relative
    data, unless already free."""
    extra = []
    if not lik.has_sigma and "log_noise" not in spec.free:
        extra.append("log_noise")
    if lik.relative_data and "scale" not in spec.free:
        extra.append("scale")
    if not extra:
        return spec
    return spec.with_free(extra)


def _check_points(lik: Likelihood, ndim: int):
    if lik.n_used <= ndim:
        c = lik.counts
        raise ValueError(
            f"table has {lik.n_used} valid values for {ndim} free parameters (need more than "
            f"{ndim}); masked: {c['invalid_value']} NaN/negative, {c['below_horizon']} below "
            f"the horizon, {c['bad_sigma']} with bad sigma, {c['zero_value']} zero")


def fit(table, spec: ParamSpec, model: Callable, *, likelihood: str = "gaussian",
        nu: float = 4.0, ensembles: int = 4, walkers: int | None = None, seed: int = 0,
        max_steps: int = 20000, check_every: int = 50, min_ratio: float = 50.0,
        tau_tol: float = 0.05, rhat_max: float = 1.01, burn_fraction: float = 0.2,
        n_starts: int = 4, laplace_move: float = 0.75, adapt: int | None = None,
        threads: int | None = None, out_dir=None, time_limit: float | None = None,
        progress: bool | Callable = True, config_extra: Mapping | None = None,
        notify: Callable[[str], None] | None = None, shading: str = "float32") -> FitResult:
    """Fit the free parameters of ``spec`` to ``table``; see :mod:`analysis.fit`.

    Parameters
    ----------
    table : gonio.Table-like
        The measurements (f_r in 1/sr, or relative when its meta says so).
    spec : ParamSpec
        Free, fixed and tied parameters. ``log_noise`` is added to the free set when the table
        has no sigma; ``scale`` when the table's meta says its values are relative.
    model : callable
        ``model(**kwargs) -> (B, n, 3)`` f_r (1/sr) at the table's pairs, e.g.
        :class:`~analysis.fit.posterior.FabricModel`.
    likelihood : {"gaussian", "relative", "student-t"}
    ensembles : int
        Independent ensembles (>= 2 for R-hat).
    walkers : int, optional
        Walkers per ensemble (>= 2 x ndim; default 2 x ndim + 2, even).
    seed : int
        Seeds the optimizer starts and every ensemble (via SeedSequence).
    max_steps, check_every : int
        Step limit per ensemble; steps between convergence checks (also the checkpoints).
    min_ratio, tau_tol, rhat_max, burn_fraction : float
        Convergence criteria (:mod:`analysis.fit.convergence`).
    laplace_move : float
        Largest share of the independence move (0 turns it off).
    adapt : int, optional
        First refit of the independence proposal (then doubling; default ``2 * check_every``,
        0 never; :func:`analysis.fit.moves.refit`).
    threads : int, optional
        Threads sharing each batched evaluation (default min(2, cores)).
    out_dir : path, optional
        Folder of ``fit_config.json`` and ``checkpoint.h5``; a fit resumes there.
    time_limit : float, optional
        Seconds after which sampling stops (checked at each convergence check).
    progress : bool or callable
        A tqdm bar (True; total the steps expected at convergence, re-estimated at each check;
        a line a check on a pipe or file: :mod:`analysis.fit.progress`), none (False), or
        ``progress(steps)`` called about every 0.25 s.
    config_extra : mapping, optional
        Also recorded in (and matched against) the stored configuration.
    notify : callable, optional
        ``notify(line)`` gets the fit's estimated time before it starts when that may be
        ``ESTIMATE_MIN_S`` or more (:func:`estimate_time`; not on a resume), and a point
        estimate that ends on bounds.
    shading : {"float32", "float64"}
        Precision of the model's shading while sampling (when ``model`` has ``with_dtype``,
        as :class:`~analysis.fit.posterior.FabricModel`): float32 shades twice as fast, f_r
        off by a few 1e-6 relative, far below the log-likelihood's noise; the point estimate,
        Laplace step and predictions use float64. Not stored: a checkpoint resumes under either.

    Returns
    -------
    FitResult
        With ``adequacy`` and ``warnings`` (:func:`analysis.fit.trust.assess`: does the model
        describe the table, what the posterior cannot tell).

    Raises
    ------
    ValueError
        Too few valid values for the free parameters, bad options, more memory than there is
        (the estimate in the message), a checkpoint of another configuration, a corrupt
        checkpoint, or a point estimate whose log-posterior is not finite (nothing written):
        all before sampling starts.
    FitInterrupted
        On Ctrl-C during sampling, after checkpointing the steps done (a KeyboardInterrupt).
    """
    opts = FitOptions(likelihood=likelihood, nu=nu, ensembles=ensembles, walkers=walkers,
                      seed=seed, max_steps=max_steps, check_every=check_every,
                      criteria=Criteria(min_ratio, tau_tol, rhat_max, burn_fraction),
                      n_starts=n_starts, laplace_move=laplace_move, adapt=adapt,
                      threads=threads, time_limit=time_limit, shading=shading)
    return _run(table, spec, model, opts, out_dir, progress, config_extra, notify)


def _check_memory(opts: FitOptions, ndim: int, n_used: int) -> None:
    """Refuse a fit whose chains or batched evaluations cannot fit in memory."""
    chains = opts.ensembles * opts.walkers * opts.max_steps * (ndim + 2) * 8
    check_memory(f"the chains of {opts.ensembles} ensembles x {opts.walkers} walkers x "
                 f"{opts.max_steps} steps (--ensembles, --walkers, --max-steps)", chains,
                 "lower --walkers, --ensembles or --max-steps")
    batch = opts.walkers * n_used * FIT_BYTES_PER_VALUE * opts.threads
    check_memory(f"evaluating {opts.walkers} walkers (--walkers) at {n_used} values",
                 batch, "lower --walkers")


def estimate_time(logpost, opts: FitOptions, n_used: int,
                  optimize: bool) -> tuple[float, str]:
    """One line: the time of a step (a batch of ``walkers / 2`` evaluations timed, twice for
    each ensemble, shared by the threads), of ``max_steps`` steps, and of the point estimate (a batch of ndim + 1
    evaluations, the finite-difference gradient, timed: ~100 iterations a start); returns
    (the seconds at most, the line)."""
    def timed(k):
        batch = np.repeat(logpost.spec.start()[None], k, axis=0)
        t0 = time.perf_counter()
        logpost(batch)
        return time.perf_counter() - t0

    # a step moves each ensemble's walkers in two halves; the threads share the ensembles
    timed(1)                                            # the first call warms caches
    step = 2 * timed(opts.walkers // 2) * opts.ensembles / min(opts.threads, opts.ensembles)
    line = (f"fit: {n_used} values, {logpost.spec.ndim} free parameters; about "
            f"{format_seconds(step) if step >= 1 else f'{step:.2g} s'} a step "
            f"({opts.ensembles} ensembles x {opts.walkers} walkers), so up to "
            f"{format_seconds(step * opts.max_steps)} for --max-steps {opts.max_steps} "
            f"(convergence usually stops it sooner; --time-limit bounds it)")
    est = 0.0
    if optimize:
        est = timed(logpost.spec.ndim + 1) * opts.n_starts * 100
        line += f"; the point estimate first, about {format_seconds(est)}"
    return est + step * opts.max_steps, line


def estimate_fit_time(table, spec: ParamSpec, model: Callable,
                      **fit_kw) -> tuple[float, str]:
    """:func:`estimate_time` of the fit that ``fit(table, spec, model, **fit_kw)`` would
    run from scratch (point estimate included), with its checks and no folder touched.

    Parameters
    ----------
    table, spec, model
        As :func:`fit`.
    **fit_kw
        Options of :func:`fit`; those that do not change the time (convergence criteria,
        ``out_dir``, ``progress``, ``notify``...) are ignored.

    Returns
    -------
    (float, str)
        The seconds at most (``max_steps`` steps and the point estimate) and the line.

    Raises
    ------
    ValueError
        As :func:`fit`'s checks before sampling (too few values, bad options, memory).
    """
    names = {f.name for f in dataclasses.fields(FitOptions)} - {"criteria"}
    opts = FitOptions(**{k: v for k, v in fit_kw.items() if k in names})
    lik, spec, opts, logpost = _checked(table, spec, model, opts)
    with threadpool_limits(limits=1, user_api="blas"):
        return estimate_time(_for_sampling(logpost, model, opts), opts, lik.n_used, True)


def _checked(table, spec: ParamSpec, model, opts: FitOptions):
    """The checks before any work: (likelihood, spec with its nuisance parameters, resolved
    options, log-posterior), or the ValueError of the first that fails."""
    lik = Likelihood(table, kind=opts.likelihood, nu=opts.nu)
    spec = with_nuisance(spec, lik)
    _check_points(lik, spec.ndim)
    opts = opts.resolve(spec.ndim)
    _check_memory(opts, spec.ndim, lik.n_used)
    return lik, spec, opts, LogPosterior(spec, lik, model)


def _for_sampling(logpost: LogPosterior, model, opts: FitOptions) -> LogPosterior:
    """The log-posterior the sampling evaluates: ``logpost`` with the model shading in
    float32 when ``opts.shading`` asks for it and the model offers ``with_dtype``."""
    if opts.shading == "float32" and hasattr(model, "with_dtype"):
        return logpost.with_model(model.with_dtype(np.float32))
    return logpost


def _check_start(spec: ParamSpec, best, best_logp: float, notify=None) -> None:
    """A point estimate the walkers can start from, or a ValueError saying what to change;
    ``notify`` is told of parameters that ended on a bound."""
    at_bound = [n for n, u in zip(spec.free, best)      # a circular one has no bound
                if abs(u) >= 0.99 * INTERNAL_LIMIT and spec.period(n) is None
                and not (u > 0 and n in spec.folds)]                # nor a fold
    if notify is not None and at_bound:
        notify(f"fit: the point estimate lies on the bound of {', '.join(at_bound)} "
               f"(log-posterior {best_logp:.4g}); if most are, the fabric may not match the "
               f"table")
    if not np.isfinite(best_logp):
        at = dict(zip(spec.free, np.round(spec.to_natural(best), 6).tolist()))
        raise ValueError(f"the point estimate has log-posterior {best_logp} (at {at}): the "
                         f"model cannot describe this table from the start; check that the "
                         f"fabric matches the table, fit fewer or other parameters (--free), "
                         f"or try --likelihood relative or student-t")


def _run(table, spec, model, opts: FitOptions, out_dir, progress, config_extra,
         notify=None) -> FitResult:
    """:func:`fit` once its options are gathered: checks, start, sampling, result."""
    t0 = time.perf_counter()
    lik, spec, opts, logpost = _checked(table, spec, model, opts)
    sampling = _for_sampling(logpost, model, opts)
    config = opts.config(spec, table, lik, config_extra)
    folder = None if out_dir is None else FitFolder(out_dir)
    start = None if folder is None else folder.read_start(config)
    ckpt = None if start is None else folder.read_checkpoint(config)
    if start is not None and ckpt is None and not np.isfinite(start["best_logp"]):
        start = None                   # a failed start of an older version: estimate again
    rng_opt, *rngs = [np.random.default_rng(s)
                      for s in np.random.SeedSequence(opts.seed).spawn(opts.ensembles + 1)]
    with threadpool_limits(limits=1, user_api="blas"):
        if notify is not None and ckpt is None:
            seconds, line = estimate_time(sampling, opts, lik.n_used, start is None)
            if seconds >= ESTIMATE_MIN_S:
                notify(line)
        if start is None:
            best, best_logp, cov = optimize_start(logpost, opts.n_starts, rng_opt, opts.threads)
            _check_start(spec, best, best_logp, notify)
        else:
            best, best_logp, cov = start["best"], start["best_logp"], start["cov"]
        t_opt = time.perf_counter() - t0
        sampler = FitSampler(sampling, opts, best, cov, rngs, ckpt)
        if start is None and folder is not None:    # only a start the walkers could use
            folder.write_start(config, best, best_logp, cov)
        resumed = sampler.steps if ckpt is not None else 0
        with fit_progress(progress, opts, sampler.steps) as (tick, postfix):
            out = sampler.run(folder, tick, t0, postfix)
    result = _result(spec, lik, logpost, opts, sampler, out, best, best_logp,
                     {"wall_s": time.perf_counter() - t0, "optimize_s": t_opt,
                      "resumed_from": resumed})
    return assess(result, table)          # adequacy and warnings (analysis.fit.trust)


def _result(spec, lik, logpost, opts, sampler, out, best, best_logp, timing) -> FitResult:
    diag = out.diagnosis
    summary = summarize(spec, diag)
    ess_min = min(s["ess"] for s in summary.values())
    timing.update(sample_s=out.sample_s, log_prob_evals=int(out.evals),
                  refit_evals=int(out.refit_evals),
                  evals_per_s=out.evals / out.sample_s if out.sample_s > 0 else float("nan"),
                  ess_per_s=ess_min / out.sample_s if out.sample_s > 0 else float("nan"))
    return FitResult(
        names=spec.free, units=spec.units, chains=circular_natural(spec, diag.chains),
        chains_internal=diag.chains, log_prob=diag.log_prob, summary=summary,
        converged=out.converged, reason=out.reason, steps=diag.step, burn=diag.burn,
        walkers=opts.walkers, ensembles=opts.ensembles,
        acceptance=[float(np.mean(c.acceptance_fraction)) for c in sampler.chains],
        best=dict(zip(spec.free, spec.to_natural(best).tolist())), best_logp=best_logp,
        counts=dict(lik.counts), timing=timing, proposal=sampler.proposal_info, spec=spec,
        logpost=logpost)
