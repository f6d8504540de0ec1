r"""PSIS-LOO of a fit (ArviZ): the expected log predictive density of each value of the table
had the fit not seen it, its Pareto-k diagnostic, and the LOO-PIT of each value.

One observation is one value the likelihood uses (a channel of a direction pair; a pair of a
grey table). Over S posterior draws thinned evenly from the fit's chains (:data:`MAX_DRAWS`;
fewer for tables of more than :data:`CELL_BUDGET` / :data:`MAX_DRAWS` values, down to
:data:`MIN_DRAWS`, and fewer still when memory is short: 12 bytes a draw and value), the
log-likelihood of each value, log p(y_i | theta_s), is evaluated
(:meth:`analysis.fit.posterior.LogPosterior.pointwise`) and carried to the density of the
table's value f_r by the residual space's Jacobian (:attr:`analysis.likelihood.Likelihood.
log_jacobian`), so that fits of one table under different ``--likelihood`` compare. Then, as
``arviz.loo`` does (Vehtari, Gelman & Gabry 2017; Vehtari et al. 2024):

    log w_is = arviz.psislw(-log p(y_i | theta_s), r_eff)    (normalized over s)
    elpd_i   = log sum_s exp(log w_is + log p(y_i | theta_s))
    elpd = sum_i elpd_i,   se = sqrt(n var_i(elpd_i)),
    p_loo = sum_i [log (1/S sum_s p(y_i | theta_s)) - elpd_i]

with r_eff = min(1, mean ESS / S) from the fit's effective sample sizes. ``arviz.psislw`` is
called once (in blocks of values, which bounds its memory) and its weights serve both the elpd
and the LOO-PIT,

    PIT_i = sum_s w_is F(y_i | theta_s),

the leave-one-out predictive CDF at the measured value (uniform on [0, 1] when the model's
predictive distribution is right; a U shape: the noise is underestimated; a hump:
overestimated; a slope: a bias). Its
uniformity is tested by Kolmogorov-Smirnov. A value whose Pareto k exceeds the threshold of
its sample size, :func:`k_threshold` (min(1 - 1 / log10 S, 0.7), as ``arviz.loo`` judges k),
has an unreliable elpd_i (the fit leans on it heavily); they are counted and warned of.

``arviz`` is imported on use (it loads matplotlib: a second the command line need not pay),
and its once-a-day FutureWarning on import is silenced here.
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
import warnings
from pathlib import Path

import numpy as np

from analysis.lazy import stats

from analysis.budget import memory_limit
from gonio import atomic_write
from gonio.safenpz import load_npz

__all__ = ["Loo", "psis_loo", "psis_pointwise", "thin_draws", "draws_for", "load_loo",
           "import_arviz", "k_threshold", "LOO_FILE", "MAX_DRAWS", "MIN_DRAWS", "CELL_BUDGET",
           "HIGH_K"]

# ArviZ announces its refactor with a FutureWarning on import, once a day: not ours to show
warnings.filterwarnings("ignore", message=r"\s*ArviZ is undergoing a major refactor",
                        category=FutureWarning)

#: The file of a fit's pointwise LOO values (beside ``results.json``).
LOO_FILE = "loo.npz"
_LOO_ARRAYS = ("elpd_i", "pareto_k", "pit", "point", "channel", "p_loo", "draws", "reff",
               "table")
#: Posterior draws the log-likelihood is evaluated at, at most.
MAX_DRAWS = 400
#: ... and at least (unless the chains or the memory hold fewer): with fewer, the Pareto k
#: of each value rests on a tail of fewer than 40 draws (S / 5).
MIN_DRAWS = 200
#: Draws x values held at once (a float64 log-likelihood and a float32 CDF each): 288 MB.
CELL_BUDGET = 24_000_000
#: Draws at the least, whatever the memory.
_FLOOR_DRAWS = 50
#: The largest Pareto k threshold, whatever the draws (Vehtari et al. 2017); the threshold of
#: S draws is :func:`k_threshold` (0.62 at S = 400).
HIGH_K = 0.7
#: Values per block of the PSIS (arviz.psislw's temporaries) and of the model evaluation.
_BLOCK_VALUES = 20_000
_EVAL_CELLS = 2_000_000


#: Bokeh's modules that arviz (0.23) imports on import only to copy two docstrings into its
#: own (``arviz/plots/backends/__init__.py``, ``_copy_docstring``, which takes an ImportError
#: for an empty docstring): about 0.65 s of CPU a process that fits or compares.
_BOKEH_FOR_DOCSTRINGS = ("bokeh.plotting", "bokeh.models")


def import_arviz():
    """The ``arviz`` module, imported on first use (it loads matplotlib.pyplot: about a
    second), its import-time FutureWarning silenced (see above), and without the Bokeh
    modules it would import for docstrings (:data:`_BOKEH_FOR_DOCSTRINGS`, blocked while
    arviz imports; imported later, as by the explorer, they load as usual)."""
    if "arviz" in sys.modules:
        return sys.modules["arviz"]
    blocked = [m for m in _BOKEH_FOR_DOCSTRINGS if m not in sys.modules]
    for m in blocked:
        sys.modules[m] = None           # an import of m raises ImportError meanwhile
    try:
        import arviz
    finally:
        for m in blocked:
            if sys.modules.get(m, 0) is None:
                del sys.modules[m]
    return arviz


def k_threshold(draws: int) -> float:
    """The Pareto k above which a value's elpd is unreliable, given the ``draws`` (S) the
    PSIS smoothed: min(1 - 1 / log10 S, :data:`HIGH_K`).

    Notes
    -----
    The formula of ``arviz.loo`` (arviz 0.23.4, ``arviz/stats/stats.py``: ``good_k =
    min(1 - 1 / np.log10(n_samples), 0.7)``), after Vehtari et al. 2024, "Pareto smoothed
    importance sampling", JMLR 25(72), section 3.2.4: with S draws a tail of fewer values
    estimates k less well, and the PSIS estimate is reliable only below 1 - 1 / log10 S.
    Fewer than 11 draws give a threshold of 0 or less (no k is trusted).

    Examples
    --------
    >>> round(k_threshold(400), 3), k_threshold(10**5)
    (0.616, 0.7)
    """
    s = int(draws)
    if s <= 1:
        return 0.0
    return float(min(1.0 - 1.0 / math.log10(s), HIGH_K))


@dataclasses.dataclass
class Loo:
    """The PSIS-LOO of a fit.

    Attributes
    ----------
    elpd_i, pareto_k, pit : ndarray (n,)
        Per used value: expected log predictive density (log of 1/sr), Pareto k, LOO-PIT.
    point, channel : ndarray (n,) of int
        The table row and channel of each value.
    p_loo : float
        The effective number of parameters.
    draws : int
        Posterior draws evaluated.
    reff : float
        Relative efficiency of the draws (ESS / draws, at most 1).
    table : str
        The digest of the table (:func:`analysis.fit.checkpoint.table_digest`).
    """

    elpd_i: np.ndarray
    pareto_k: np.ndarray
    pit: np.ndarray
    point: np.ndarray
    channel: np.ndarray
    p_loo: float
    draws: int
    reff: float
    table: str = ""

    @property
    def elpd(self) -> float:
        """Sum of the pointwise elpd."""
        return float(np.sum(self.elpd_i))

    @property
    def se(self) -> float:
        """Standard error of :attr:`elpd`: sqrt(n var(elpd_i))."""
        return float(math.sqrt(self.elpd_i.size * np.var(self.elpd_i)))

    @property
    def k_threshold(self) -> float:
        """The Pareto k threshold of :attr:`draws` (:func:`k_threshold`)."""
        return k_threshold(self.draws)

    @property
    def n_high_k(self) -> int:
        """Values whose Pareto k exceeds :attr:`k_threshold`."""
        return int(np.sum(self.pareto_k > self.k_threshold))

    def summary(self) -> dict:
        """``results.json``'s ``loo``: elpd, se, p_loo, pareto_k_max, n_high_k and the
        k_threshold it counts above (with the draws)."""
        return {"elpd": self.elpd, "se": self.se, "p_loo": float(self.p_loo),
                "pareto_k_max": float(np.max(self.pareto_k)), "n_high_k": self.n_high_k,
                "k_threshold": self.k_threshold, "draws": int(self.draws)}

    def pit_test(self) -> dict:
        """``quality["loo_pit"]``: the Kolmogorov-Smirnov test of the LOO-PIT against the
        uniform distribution (statistic, p-value), the number of values, and the share of
        values outside the central 95% of their predictive distribution (0.05 expected)."""
        ks = stats.kstest(self.pit, "uniform")
        outside = float(np.mean((self.pit < 0.025) | (self.pit > 0.975)))
        return {"ks_statistic": float(ks.statistic), "ks_pvalue": float(ks.pvalue),
                "values": int(self.pit.size), "outside_95": outside}

    def warnings(self) -> list[dict]:
        """``results.json`` warnings of kind ``pareto_k`` (none when every k is low)."""
        n = self.n_high_k
        if n == 0:
            return []
        return [{"kind": "pareto_k", "parameters": [],
                 "message": f"PSIS-LOO: {n} of {self.pareto_k.size} values have Pareto k > "
                            f"{self.k_threshold:.2f} (the threshold of {self.draws} draws; "
                            f"largest {np.max(self.pareto_k):.2f}); the fit leans "
                            f"on them so heavily that their leave-one-out densities, and so "
                            f"the elpd, are unreliable (outliers, or a model that misses "
                            f"them)"}]

    def save(self, folder) -> Path:
        """Write ``folder/loo.npz`` (atomically) and return its path."""
        path = Path(folder) / LOO_FILE
        with atomic_write(path, "wb") as fh:
            np.savez(fh, elpd_i=self.elpd_i, pareto_k=self.pareto_k, pit=self.pit,
                     point=self.point, channel=self.channel, p_loo=float(self.p_loo),
                     draws=int(self.draws), reff=float(self.reff), table=str(self.table))
        return path


def load_loo(folder) -> Loo:
    """Read ``folder/loo.npz``.

    Raises
    ------
    ValueError
        Missing, a link or not a regular file, or not a fit's LOO file: a member missing, of
        the wrong shape or type, or larger than it may be (declared sizes are checked before
        anything is inflated, :func:`gonio.safenpz.load_npz`); the message names the file.
    """
    path = Path(folder) / LOO_FILE
    if not os.path.lexists(path):
        raise ValueError(f"{path}: not found (a fit made before PSIS-LOO was added? run the "
                         f"same `microcyl fit` again: it resumes and writes it)")
    d = load_npz(path, _LOO_ARRAYS, what="a fit's LOO file")   # sizes checked, then read
    try:
        n = d["elpd_i"].shape
        ok = (len(n) == 1 and n[0] > 0 and all(d[k].shape == n for k in
                                                 ("pareto_k", "pit", "point", "channel"))
              and all(d[k].dtype.kind == "f" for k in ("elpd_i", "pareto_k", "pit"))
              and all(d[k].dtype.kind in "iu" for k in ("point", "channel"))
              and np.all(np.isfinite(d["elpd_i"])) and d["table"].dtype.kind == "U")
        if not ok:
            raise ValueError("arrays of the wrong shape or type")
        return Loo(d["elpd_i"].astype(np.float64), d["pareto_k"].astype(np.float64),
                   d["pit"].astype(np.float64), d["point"].astype(np.int64),
                   d["channel"].astype(np.int64), float(d["p_loo"]), int(d["draws"]),
                   float(d["reff"]), str(d["table"]))
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ValueError(f"{path}: not a readable LOO file ({exc})") from None


def thin_draws(result, max_draws: int = MAX_DRAWS) -> np.ndarray:
    """At most ``max_draws`` posterior draws (internal coordinates), evenly spaced over the
    fit's flattened chains (ensembles, steps, walkers), first and last included."""
    flat = result.chains_internal.reshape(-1, len(result.names))
    if flat.shape[0] <= max_draws:
        return flat.copy()
    return flat[np.linspace(0, flat.shape[0] - 1, max_draws).round().astype(np.int64)]


def psis_pointwise(log_lik, cdf=None, reff: float = 1.0) -> dict:
    """PSIS-LOO from a matrix of pointwise log-likelihoods (see the module notes).

    Parameters
    ----------
    log_lik : array_like, shape (S, n)
        log p(y_i | theta_s) over S posterior draws.
    cdf : array_like, shape (S, n), optional
        F(y_i | theta_s), the predictive CDF at each value; gives the LOO-PIT.
    reff : float
        Relative efficiency of the draws (ESS / S).

    Returns
    -------
    dict
        ``elpd_i``, ``pareto_k``, ``lppd_i`` (log of the mean predictive density), and
        ``pit`` (NaN without ``cdf``), each (n,). A value whose log-likelihood is the same at
        every draw (no free parameter changes its prediction) has equal weights and an exact
        elpd_i: its k is 0 (``arviz.psislw`` finds no tail to fit there and says inf).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> ll = -0.5 * (rng.normal(size=(1000, 1)) - rng.normal(size=(1, 5))) ** 2
    >>> out = psis_pointwise(ll)
    >>> bool(np.all(out["elpd_i"] <= out["lppd_i"]))
    True
    """
    az = import_arviz()
    ll = np.asarray(log_lik, dtype=np.float64)
    s, n = ll.shape
    elpd, k, lppd = np.empty(n), np.empty(n), np.empty(n)
    pit = np.full(n, np.nan)
    for a in range(0, n, _BLOCK_VALUES):
        block = ll[:, a:a + _BLOCK_VALUES].T                        # (values, draws)
        b = slice(a, a + block.shape[0])
        with np.errstate(over="ignore", under="ignore", divide="ignore"):
            lw, kb = az.psislw(-block, reff)
            lw = np.asarray(lw, dtype=np.float64)
            kb = np.asarray(kb, dtype=np.float64)
            # the same log-likelihood at every draw: equal weights, an exact elpd_i; arviz
            # finds no tail to fit and says inf
            kb[np.ptp(block, axis=1) <= 1e-12 * (1.0 + np.max(np.abs(block), axis=1))] = 0.0
            k[b] = kb
            elpd[b] = _logsumexp_rows(lw + block)
            lppd[b] = _logsumexp_rows(block) - math.log(s)
            if cdf is not None:
                f = np.asarray(cdf[:, b], dtype=np.float64).T
                pit[b] = np.clip(np.sum(np.exp(lw) * f, axis=1), 0.0, 1.0)
    return {"elpd_i": elpd, "pareto_k": k, "lppd_i": lppd, "pit": pit}


def _logsumexp_rows(x) -> np.ndarray:
    """log sum exp over the last axis of a finite (or -inf) array (scipy's logsumexp is
    several times slower on large arrays)."""
    m = np.max(x, axis=-1, keepdims=True)
    m = np.where(np.isfinite(m), m, 0.0)
    return np.log(np.sum(np.exp(x - m), axis=-1)) + m[..., 0]


def draws_for(n_values: int, max_draws: int = MAX_DRAWS) -> int:
    """The draws :func:`psis_loo` evaluates for a table of ``n_values`` used values: up to
    ``max_draws``, fewer past :data:`CELL_BUDGET` cells (not under :data:`MIN_DRAWS`), and
    within half of the memory available (:func:`analysis.budget.memory_limit`; never under 50).

    Examples
    --------
    >>> draws_for(1000), draws_for(10**6) >= 50
    (400, True)
    """
    n = max(int(n_values), 1)
    draws = min(int(max_draws), max(MIN_DRAWS, CELL_BUDGET // n))
    by_memory = memory_limit()[0] // 2 // (12 * n)
    return int(max(min(draws, by_memory), min(_FLOOR_DRAWS, int(max_draws))))


def psis_loo(result, table_digest: str = "", max_draws: int = MAX_DRAWS) -> Loo:
    """The PSIS-LOO of a :class:`~analysis.fit.results.FitResult` (see the module notes).

    Parameters
    ----------
    result : FitResult
        With its log-posterior (``result.logpost``), as :func:`analysis.fit.fit` returns it.
    table_digest : str
        Recorded with the values (compare refuses fits of different tables).
    max_draws : int
        Posterior draws to evaluate, at most.

    Returns
    -------
    Loo
    """
    lik = result.logpost.lik
    n = lik.n_used
    theta = thin_draws(result, draws_for(n, max_draws))
    s = theta.shape[0]
    ll = np.empty((s, n))
    cdf = np.empty((s, n), dtype=np.float32)
    pairs = max(1, lik.mask.shape[0] * 3)
    step = max(1, _EVAL_CELLS // pairs)
    for a in range(0, s, step):
        ll[a:a + step], cdf[a:a + step] = result.logpost.pointwise(theta[a:a + step], cdf=True)
    ll += lik.log_jacobian
    ess = [v.get("ess", np.nan) for v in result.summary.values()]
    ess_mean = float(np.nanmean(ess)) if np.any(np.isfinite(ess)) else float(s)
    reff = float(min(1.0, max(ess_mean / s, 1.0 / s)))
    out = psis_pointwise(ll, cdf, reff)
    return Loo(elpd_i=out["elpd_i"], pareto_k=out["pareto_k"], pit=out["pit"],
               point=np.asarray(lik.pt, dtype=np.int64),
               channel=np.asarray(lik.ch, dtype=np.int64),
               p_loo=float(np.sum(out["lppd_i"] - out["elpd_i"])), draws=s, reff=reff,
               table=str(table_digest))
