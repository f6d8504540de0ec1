"""The point estimate (L-BFGS-B from several starts) and the Laplace approximation at it.

Each gradient and each Hessian is one batched evaluation of the log-posterior (finite
differences as a batch of parameter sets), which the vectorized model evaluates at the cost of
a few single evaluations.
"""

from __future__ import annotations

import concurrent.futures as cf
import threading

import numpy as np
import scipy
import scipy.optimize

from analysis.fit.gradient import gradient_available, logpost_and_grad, rotation_cache
from analysis.param import INTERNAL_WIDTH

__all__ = ["point_estimate", "laplace_cov", "initial_walkers", "optimize_start", "GRADIENTS"]

#: The gradients the point estimate may use: ``"fd"`` (a batch of ndim + 1 evaluations, every
#: model), ``"analytic"`` (the kernel's automatic differentiation,
#: :mod:`analysis.fit.gradient`; finite differences where the model has none), ``"auto"``
#: (the default: :data:`AUTO_GRADIENT`).
GRADIENTS = ("auto", "fd", "analytic")
#: Orientations a circular parameter's search starts from: its start and each quarter turn.
CIRCLE_STARTS = 4
#: What ``"auto"`` means (the faster on ``bench/bench_sampler.py --start``; docs/benchmarks.rst).
AUTO_GRADIENT = "fd"
#: Dr.Jit's AD of one start at a time (its kernel uses the cores itself).
_AD_LOCK = threading.Lock()

#: SciPy's L-BFGS-B is C (re-entrant) from 1.15 on; before, Fortran with shared state.
_LBFGSB_THREAD_SAFE = tuple(int(v) for v in scipy.__version__.split(".")[:2]) >= (1, 15)


def _fd_grad_batch(x, h, lower, upper):
    d = x.size
    pts = np.repeat(x[None], d + 1, axis=0)
    steps = np.where(x + h <= upper, h, -h)
    pts[np.arange(1, d + 1), np.arange(d)] += steps
    return pts, steps


def point_estimate(logpost, starts: np.ndarray, maxiter: int = 300, threads: int = 1,
                   gradient: str = "auto"):
    """Maximum a posteriori estimate from several starts (L-BFGS-B, batched FD gradient or
    the kernel's analytic one).

    Parameters
    ----------
    logpost : LogPosterior
    starts : ndarray, shape (k, ndim)
        Internal coordinates of the starts.
    threads : int
        Starts optimized at once (each independent of the others: same result for any value).
    gradient : {"auto", "fd", "analytic"}
        See :data:`GRADIENTS`; "analytic" falls back to "fd" for a model without derivatives.

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

    def fun_grad(x, bad):
        pts, steps = _fd_grad_batch(x, h, lower, upper)
        lp = logpost(pts)
        f0 = -lp[0]
        if not np.isfinite(f0):
            return bad, np.zeros_like(x)
        fi = np.where(np.isfinite(lp[1:]), -lp[1:], f0 + 1e6 * np.abs(steps))
        return float(f0), (fi - f0) / steps

    if gradient not in GRADIENTS:
        raise ValueError(f"gradient must be one of {', '.join(GRADIENTS)}; got {gradient!r}")
    if gradient == "auto":
        gradient = AUTO_GRADIENT
    analytic = gradient == "analytic" and gradient_available(logpost)

    def fun_grad_ad(x, bad, cache):
        with _AD_LOCK:
            r = logpost_and_grad(logpost, x, cache)
        if r is None:                       # no kernel at this point (tangent scales)
            return fun_grad(x, bad)
        lp, g = r
        return (bad, np.zeros_like(x)) if not np.isfinite(lp) else (-lp, -g)

    def one(s):
        f_start = -float(logpost(s[None])[0])
        if not np.isfinite(f_start):
            return s, -np.inf
        # a point that cannot be evaluated must look worse than the start, however poor the
        # start (a log-posterior of -1e43 made the bounds, where it is -inf, look better)
        bad = big + 10.0 * abs(f_start)
        fg, args = (fun_grad_ad, (bad, rotation_cache(logpost))) if analytic else (fun_grad,
                                                                                    (bad,))
        r = scipy.optimize.minimize(fg, s, args=args, jac=True, method="L-BFGS-B",
                                    bounds=list(zip(lower, upper)),
                                    options={"maxiter": maxiter})
        if not (np.isfinite(r.fun) and r.fun < bad and r.fun <= f_start):
            return s, -f_start                  # never a point worse than the start
        return r.x, -float(r.fun)

    starts = np.atleast_2d(starts)
    if threads > 1 and _LBFGSB_THREAD_SAFE:
        with cf.ThreadPoolExecutor(threads) as ex:
            results = list(ex.map(one, starts))
    else:
        results = [one(s) for s in starts]
    i = int(np.argmax([r[1] for r in results]))
    return results[i][0], results[i][1], [r[1] for r in results]


def laplace_cov(logpost, x: np.ndarray) -> np.ndarray | None:
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


def _hessian_cov(logpost, x: np.ndarray, h: np.ndarray):
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


def initial_walkers(logpost, best, cov, nwalkers, rng) -> tuple[np.ndarray, np.ndarray]:
    """``nwalkers`` starting positions (internal coordinates) drawn around ``best`` from the
    Laplace covariance ``cov`` (a tiny ball without one), shrunk until enough of them have a
    finite log-posterior.

    Returns
    -------
    coords : ndarray (nwalkers, ndim)
    log_prob : ndarray (nwalkers,)
    """
    width = logpost.spec.width
    if cov is None:
        cov = np.diag((1e-3 * width) ** 2)
    xs, lps = np.empty((0, best.size)), np.empty(0)
    for shrink in (1.0, 0.3, 0.1, 0.03, 0.01, 1e-3, 1e-4):
        cand = rng.multivariate_normal(best, cov * shrink, size=4 * nwalkers)
        lo, hi = logpost.spec.lower, logpost.spec.upper    # reflected at the bounds: a
        cand = np.where(cand > hi, 2 * hi - cand, cand)    # point estimate on a bound
        cand = np.where(cand < lo, 2 * lo - cand, cand)    # keeps its walkers inside
        lp = logpost(cand)
        ok = np.isfinite(lp)
        xs = np.concatenate([xs, cand[ok]])[:nwalkers]
        lps = np.concatenate([lps, lp[ok]])[:nwalkers]
        if len(xs) >= nwalkers:
            return xs, lps
    raise RuntimeError("could not place the walkers around the point estimate: the "
                       "log-posterior is not finite near it; check that the fabric matches "
                       "the table, widen the bounds of parameters at a bound ([bounds] of "
                       "--spec) or fit other parameters (--free)")


def optimize_start(logpost, n_starts: int, rng, threads: int = 1,
                   gradient: str = "auto") -> tuple[np.ndarray, float, np.ndarray | None]:
    """Point estimate from the spec's start and ``n_starts - 1`` perturbations of it (5% of
    each parameter's internal range, from ``rng``), and, where a parameter is circular (a
    fabric's ``rotation``, :meth:`analysis.params.ParamSpec.period`), the start turned by
    each 1/:data:`CIRCLE_STARTS` of the period (a local search from one orientation finds the
    mode nearest it, not the best); then the Laplace covariance there; ``gradient`` as
    :func:`point_estimate`.

    Returns
    -------
    best : ndarray (ndim,)
        Internal coordinates of the optimum.
    best_logp : float
    cov : ndarray (ndim, ndim) or None
        Laplace covariance in internal coordinates (None where the Hessian is unusable).

    Raises
    ------
    ValueError
        When the log-posterior is not finite at the start.
    """
    spec = logpost.spec
    start = spec.start()
    if not np.isfinite(logpost(start[None])[0]):
        raise ValueError(f"the log-posterior is not finite at the start "
                         f"{dict(zip(spec.free, spec.to_natural(start).tolist()))}: the "
                         f"model cannot be evaluated there or gives the table zero "
                         f"probability; check that the fabric matches the table, set start "
                         f"values inside the bounds ([start] of --spec), or try --likelihood "
                         f"relative or student-t")
    starts = [start]
    for _ in range(max(0, n_starts - 1)):
        starts.append(np.clip(start + rng.normal(scale=0.05 * spec.width), spec.lower,
                              spec.upper))
    circle = spec.circular           # an angle on a circle: the start turned by quarters too
    for k in range(1, CIRCLE_STARTS if circle.any() else 1):
        starts.append(np.where(circle, start + k * INTERNAL_WIDTH / CIRCLE_STARTS, start))
    best, best_logp, _ = point_estimate(logpost, np.array(starts), threads=threads,
                                        gradient=gradient)
    return best, best_logp, laplace_cov(logpost, best)
