r"""When a fit has converged: tau, N / tau, the change of tau and split R-hat at each check.

At a check the first ``burn_fraction`` of every chain is discarded (at least up to the last
kept proposal refit, at most half); tau per ensemble (emcee, ``tol=0``) is averaged over the
ensembles. The fit has converged when for every parameter (N - burn) / tau > ``min_ratio``,
tau changed by less than ``tau_tol`` (relative) since the previous check, and split R-hat
across ensembles is below ``rhat_max`` (:mod:`analysis.diagnostics`).
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses

import numpy as np

from analysis import diagnostics

__all__ = ["Criteria", "Diagnosis", "diagnose", "finite_min", "finite_max", "expected_steps"]


@dataclasses.dataclass(frozen=True)
class Criteria:
    """The convergence criteria (see the module notes)."""

    min_ratio: float = 50.0
    tau_tol: float = 0.05
    rhat_max: float = 1.01
    burn_fraction: float = 0.2


@dataclasses.dataclass
class Diagnosis:
    """The state of the chains at one check.

    Attributes
    ----------
    step : int
        Steps every ensemble has made.
    burn : int
        Steps discarded.
    chains : ndarray (ensembles, step - burn, walkers, ndim)
    log_prob : ndarray (ensembles, step - burn, walkers)
    taus : ndarray (ensembles, ndim)
        tau of each ensemble, steps.
    tau, rhat : ndarray (ndim,)
        Mean tau over ensembles (steps) and split R-hat.
    """

    step: int
    burn: int
    chains: np.ndarray
    log_prob: np.ndarray
    taus: np.ndarray
    tau: np.ndarray
    rhat: np.ndarray

    @property
    def kept(self) -> int:
        """Steps after the burn-in."""
        return self.step - self.burn

    @property
    def ratio(self) -> np.ndarray:
        """(N - burn) / tau per parameter."""
        return self.kept / self.tau

    def tau_change(self, tau_prev) -> float:
        """Largest relative change of tau since ``tau_prev`` (inf without one)."""
        if tau_prev is None:
            return float("inf")
        return float(np.max(np.abs(self.tau - np.asarray(tau_prev)) / self.tau))

    def verdict(self, tau_prev, c: Criteria) -> tuple[bool, str]:
        """Whether the criteria hold, and why (one line)."""
        ratio, dtau = self.ratio, self.tau_change(tau_prev)
        if (np.all(ratio > c.min_ratio) and dtau < c.tau_tol
                and np.all(self.rhat < c.rhat_max)):
            return True, (f"converged at step {self.step}: N/tau > {c.min_ratio:g} for every "
                          f"parameter (min {ratio.min():.1f}), tau changed {100 * dtau:.1f}% "
                          f"< {100 * c.tau_tol:g}% since the last check, R-hat < "
                          f"{c.rhat_max:g}")
        stuck = ("; tau undefined for some parameter (a walker did not move)"
                 if np.any(~np.isfinite(self.tau)) else "")
        return False, (f"min N/tau {finite_min(ratio):.1f} (need > {c.min_ratio:g}), tau "
                       f"change {100 * dtau:.1f}% (need < {100 * c.tau_tol:g}%), max R-hat "
                       f"{finite_max(self.rhat):.3f} (need < {c.rhat_max:g}){stuck}")


def finite_min(x) -> float:
    """Smallest finite value of x, NaN when there is none (no warning)."""
    x = np.asarray(x, dtype=np.float64)
    x = x[np.isfinite(x)]
    return float(x.min()) if x.size else float("nan")


def finite_max(x) -> float:
    """Largest finite value of x, NaN when there is none (no warning)."""
    x = np.asarray(x, dtype=np.float64)
    x = x[np.isfinite(x)]
    return float(x.max()) if x.size else float("nan")


def diagnose(chains, burn_fraction: float, last_refit: int = 0,
             threads: int = 1) -> Diagnosis:
    """Diagnose :class:`~analysis.fit.ensemble.Chain` objects at their common step count.

    The burn-in is ``max(burn_fraction N, min(last_refit, N / 2))`` steps. With ``threads``
    > 1 the ensembles' tau are computed in that many threads (their FFTs release the GIL;
    the values are the same): a long fit's checks, which run while its ensembles wait, were
    a sixth of its wall time.
    """
    n = min(c.steps for c in chains)
    burn = max(int(burn_fraction * n), min(last_refit, n // 2))
    x = np.stack([c.chain(burn, n) for c in chains])             # (m, steps, w, d)
    lp = np.stack([c.log_prob(burn, n) for c in chains])
    if threads > 1 and len(x) > 1:
        with cf.ThreadPoolExecutor(min(threads, len(x))) as ex:
            taus = np.stack(list(ex.map(diagnostics.autocorr_time, x)))
    else:
        taus = np.stack([diagnostics.autocorr_time(c) for c in x])
    return Diagnosis(step=n, burn=burn, chains=x, log_prob=lp, taus=taus,
                     tau=taus.mean(axis=0), rhat=diagnostics.split_rhat(x))


def expected_steps(diag: Diagnosis, c: Criteria, check_every: int, max_steps: int,
                   converged: bool = False) -> int:
    """The step count at which the fit is expected to converge, from the tau of this check
    (this check's step when ``converged``):
    the first check (a multiple of ``check_every``) where N - burn > ``min_ratio`` x the
    largest tau, the burn-in being ``burn_fraction`` N or, while it is longer, this check's;
    at least the next check when this one has not converged; at most ``max_steps``
    (also without a finite tau).

    Notes
    -----
    N/tau > r needs N (1 - b) > r tau with a burn-in of b N, or N > burn + r tau with the
    refit's burn-in, so N = max(r tau / (1 - b), burn + r tau); tau is re-estimated at each
    check (it usually grows as the chains lengthen), and so is this total.

    Examples
    --------
    >>> import numpy as np
    >>> d = Diagnosis(step=100, burn=20, chains=None, log_prob=None, taus=None,
    ...               tau=np.array([4.0, 10.0]), rhat=np.array([1.2, 1.1]))
    >>> expected_steps(d, Criteria(), 50, 20000)      # 50 x 10 / 0.8 = 625 -> 650
    650
    >>> expected_steps(d, Criteria(), 50, 600)
    600
    """
    if converged:
        return int(diag.step)
    tau = np.asarray(diag.tau, dtype=np.float64)
    if tau.size == 0 or not np.all(np.isfinite(tau)):
        return int(max_steps)
    need = c.min_ratio * float(tau.max())
    n = max(need / (1.0 - c.burn_fraction), diag.burn + need, diag.step + 1)
    every = max(int(check_every), 1)
    n = int((np.floor(n / every) + 1) * every)     # the rule is N/tau > r, strictly
    return int(min(max(n, diag.step), max_steps))
