"""analysis.diagnostics against emcee's estimator and the textbook split R-hat."""

import warnings

import emcee
import numpy as np
import pytest

from analysis.diagnostics import autocorr_time, split_rhat


def _ar1(rng, shape, rho):
    """AR(1) series along axis 0 (tau = (1 + rho) / (1 - rho))."""
    x = np.empty(shape)
    x[0] = rng.normal(size=shape[1:])
    eps = rng.normal(size=shape) * np.sqrt(1 - rho * rho)
    for t in range(1, shape[0]):
        x[t] = rho * x[t - 1] + eps[t]
    return x


@pytest.mark.parametrize("shape, rho", [((300, 8, 3), 0.5), ((2000, 20, 9), 0.9),
                                        ((777, 30, 2), 0.0), ((4097, 3, 1), 0.95),
                                        ((5, 2, 2), 0.3)])
def test_autocorr_time_is_emceees_estimator(shape, rho):
    x = _ar1(np.random.default_rng(shape[0]), shape, rho) + 3.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        want = emcee.autocorr.integrated_time(x, tol=0, quiet=True)
    np.testing.assert_allclose(autocorr_time(x), want, rtol=1e-12, atol=0)


def test_autocorr_time_of_an_ar1_series_is_its_theoretical_value():
    rho = 0.8                                   # tau = 1.8 / 0.2 = 9 steps
    tau = autocorr_time(_ar1(np.random.default_rng(4), (20000, 16, 1), rho))[0]
    assert abs(tau - 9.0) < 0.6


def test_a_walker_that_never_moved_gives_nan_for_its_parameter_only():
    x = np.random.default_rng(2).normal(size=(500, 6, 2))
    x[:, 2, 1] = 1.0
    tau = autocorr_time(x)
    assert np.isfinite(tau[0]) and np.isnan(tau[1])


def _textbook_rhat(c):
    """Gelman et al. (BDA3, 11.4) on the split halves, each pooled over its walkers, in
    extended precision (two-pass variances)."""
    m, n = c.shape[:2]
    half = n // 2
    chains = [e[:half].reshape(-1, c.shape[-1]) for e in c] + \
             [e[n - half:].reshape(-1, c.shape[-1]) for e in c]
    out = []
    for k in range(c.shape[-1]):
        draws = [ch[:, k].astype(np.longdouble) for ch in chains]
        nn = len(draws[0])
        means = np.array([np.mean(d) for d in draws])
        w = np.mean([np.var(d, ddof=1) for d in draws])
        b = nn * np.var(means, ddof=1)
        out.append(np.sqrt(((nn - 1) / nn * w + b / nn) / w))
    return np.array(out, dtype=np.float64)


def test_split_rhat_is_the_textbook_formula():
    rng = np.random.default_rng(7)
    c = rng.normal(size=(4, 301, 5, 3)) + np.array([0.0, 0.1, 0.0, 0.3])[:, None, None, None]
    c[..., 2] *= 1e-4                           # a narrow posterior far from 0: the sums of
    c[..., 2] += 5e4                            # squares must not cancel
    np.testing.assert_allclose(split_rhat(c), _textbook_rhat(c), rtol=1e-10)


def test_diagnose_in_threads_gives_each_ensembles_own_tau():
    """``diagnose(threads=2)`` computes the ensembles' tau in threads: each is that
    ensemble's own emcee estimate (not another's, not reordered), the mean as with one."""
    from analysis.fit.convergence import diagnose

    class Stored:                       # a Chain's reading interface over stored arrays
        def __init__(self, x):
            self.x, self.steps = x, x.shape[0]

        def chain(self, a, b):
            return self.x[a:b]

        def log_prob(self, a, b):
            return np.zeros((b - a, self.x.shape[1]))

    rng = np.random.default_rng(7)
    chains = [Stored(_ar1(rng, (1500, 10, 2), rho)) for rho in (0.0, 0.5, 0.8, 0.95)]
    one, two = diagnose(chains, 0.2), diagnose(chains, 0.2, threads=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        want = [emcee.autocorr.integrated_time(c.x[300:], tol=0, quiet=True) for c in chains]
    np.testing.assert_allclose(two.taus, want, rtol=1e-12, atol=0)
    assert np.array_equal(two.taus, one.taus) and np.array_equal(two.tau, one.tau)
    assert np.all(np.diff(two.taus[:, 0]) > 0)          # tau grows with rho, in order
