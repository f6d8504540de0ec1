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

from analysis.lazy import autocorr, fft

__all__ = ["autocorr_time", "split_rhat", "ess", "interval_summary"]


#: Series (one walker's one parameter) transformed per FFT call in :func:`autocorr_time`:
#: about 64 MiB of spectra for chains of 16,000 steps.
_ACF_SERIES = 256


def autocorr_time(chain) -> np.ndarray:
    """Integrated autocorrelation time per parameter of one ensemble.

    emcee's estimator (``emcee.autocorr.integrated_time`` with ``tol=0``: the normalized
    autocorrelation of each walker's series by FFT, averaged over the walkers, summed up to
    emcee's ``auto_window`` with c = 5), computed with real FFTs (scipy.fft, zero-padded to
    a fast length >= 2 n - 1 rather than emcee's power of two >= 2 n: the same linear
    autocorrelation) over blocks of series instead of emcee's loop of one complex FFT per
    walker and parameter. Faster at long chains, whose checks took a third of a long fit;
    the same values to rounding (``tests/test_analysis_diagnostics.py``).

    Parameters
    ----------
    chain : array_like, shape (steps, walkers, ndim)

    Returns
    -------
    ndarray, shape (ndim,)
        tau in steps; NaN for a parameter with a walker that never moved in the window.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> x = rng.normal(size=(2000, 8, 1))
    >>> bool(0.5 < autocorr_time(x)[0] < 1.5)
    True
    """
    x = np.asarray(chain, dtype=np.float64)
    n, w, d = x.shape
    size = fft.next_fast_len(2 * n - 1, real=True)   # >= 2n - 1: no wrap-around
    series = np.ascontiguousarray((x - x.mean(axis=0)).transpose(1, 2, 0))    # (w, d, n)
    f = np.zeros((d, n))                      # sum over walkers of each normalized acf
    step = max(1, _ACF_SERIES // max(d, 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        for k0 in range(0, w, step):
            spec = fft.rfft(series[k0:k0 + step], n=size, axis=-1)
            power = np.square(spec.real)          # |F|^2 (a complex product is 10x slower)
            power += np.square(spec.imag)
            acf = fft.irfft(power, n=size, axis=-1)[..., :n]
            acf /= acf[..., :1]
            f += acf.sum(axis=0)
        taus = (2.0 * np.cumsum(f / w, axis=-1) - 1.0).T                     # (n, d)
    out = np.empty(d)
    for k in range(d):
        col = taus[:, k]
        out[k] = col[autocorr.auto_window(col, 5)] if np.all(np.isfinite(col)) \
            else np.nan
    return out


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
    d = c.shape[-1]
    c = c - c[0, 0, 0]          # about centred (one draw of each parameter): no cancellation
    # the two halves of each chain, each pooled over steps and walkers: (2m, half * w, d)
    parts = [c[:, :half].reshape(m, -1, d), c[:, n - half:].reshape(m, -1, d)]
    nd = parts[0].shape[1]
    means = np.concatenate([p.mean(axis=1) for p in parts])              # (2m, d)
    # sums of squared deviations by one product per part (no centred copy of the chains)
    ss = np.concatenate([np.einsum("knd,knd->kd", p, p) for p in parts]) - nd * means ** 2
    w = (ss / (nd - 1)).mean(axis=0)
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
