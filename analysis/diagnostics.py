r"""Convergence diagnostics for several independent emcee ensembles.

- tau: emcee's integrated autocorrelation time of each ensemble (averaged over its walkers,
  ``emcee.autocorr.integrated_time`` with ``tol=0``), per parameter, in steps.
- R-hat (Gelman-Rubin, split): each ensemble is one chain (all its walkers pooled at each
  step); each chain is split into halves, so m = 2 x ensembles chains of n draws. With chain
  means mu_k and variances s_k^2 (pooled over walkers and steps),
  W = mean_k s_k^2, B/n = var_k(mu_k) (ddof=1), var+ = (n-1)/n W + B/n, R-hat = sqrt(var+ / W).
  Walkers of one ensemble are never treated as separate chains: they are not independent.
- ESS: sum over ensembles of (steps x walkers) / tau.
"""

from __future__ import annotations

import numpy as np
import emcee

__all__ = ["autocorr_time", "split_rhat", "ess", "interval_summary"]


def autocorr_time(chain) -> np.ndarray:
    """Integrated autocorrelation time per parameter of one ensemble.

    Parameters
    ----------
    chain : array_like, shape (steps, walkers, ndim)

    Returns
    -------
    ndarray, shape (ndim,)
        tau in steps (emcee's estimator, no length check: ``tol=0``).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> x = rng.normal(size=(2000, 8, 1))
    >>> bool(0.5 < autocorr_time(x)[0] < 1.5)
    True
    """
    chain = np.asarray(chain, dtype=np.float64)
    # a walker that never moved in the window has no autocorrelation: tau is NaN (not converged)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(emcee.autocorr.integrated_time(chain, tol=0, quiet=True),
                          dtype=np.float64)


def split_rhat(chains) -> np.ndarray:
    """Split R-hat across ensembles.

    Parameters
    ----------
    chains : array_like, shape (ensembles, steps, walkers, ndim)

    Returns
    -------
    ndarray, shape (ndim,)
        Gelman-Rubin potential scale reduction (1 at convergence).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> same = rng.normal(size=(4, 400, 6, 2))
    >>> bool(np.all(split_rhat(same) < 1.01))
    True
    >>> shifted = same + np.arange(4)[:, None, None, None]
    >>> bool(np.all(split_rhat(shifted) > 1.5))
    True
    """
    c = np.asarray(chains, dtype=np.float64)
    m, n = c.shape[:2]
    half = n // 2
    if half < 2:
        return np.full(c.shape[-1], np.nan)
    parts = np.concatenate([c[:, :half], c[:, n - half:]], axis=0)  # (2m, half, w, d)
    flat = parts.reshape(parts.shape[0], -1, parts.shape[-1])       # (2m, half*w, d)
    nd = flat.shape[1]
    means = flat.mean(axis=1)
    w = flat.var(axis=1, ddof=1).mean(axis=0)
    b_over_n = means.var(axis=0, ddof=1)
    var_plus = (nd - 1) / nd * w + b_over_n
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sqrt(var_plus / w)


def ess(chains, taus) -> np.ndarray:
    """Effective sample size per parameter: sum_k steps x walkers / tau_k.

    Parameters
    ----------
    chains : array_like, shape (ensembles, steps, walkers, ndim)
    taus : array_like, shape (ensembles, ndim)
    """
    c = np.asarray(chains)
    taus = np.asarray(taus, dtype=np.float64)
    return (c.shape[1] * c.shape[2] / np.maximum(taus, 1.0)).sum(axis=0)


def interval_summary(samples) -> dict[str, np.ndarray]:
    """Median and central 68% / 95% intervals of samples (..., ndim), over all leading axes.

    Returns
    -------
    dict
        ``median``, ``lo68``, ``hi68``, ``lo95``, ``hi95``, each (ndim,).

    Examples
    --------
    >>> s = np.random.default_rng(2).normal(size=(200000, 1))
    >>> r = interval_summary(s)
    >>> round(float(r["hi68"][0]), 1), round(float(r["lo95"][0]), 1)
    (1.0, -2.0)
    """
    s = np.asarray(samples, dtype=np.float64)
    s = s.reshape(-1, s.shape[-1])
    q = np.percentile(s, [50, 15.865525, 84.134475, 2.5, 97.5], axis=0)
    return dict(zip(("median", "lo68", "hi68", "lo95", "hi95"), q))
