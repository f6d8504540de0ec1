"""The independence proposal of the fit: a mixture of Student-t in warped coordinates.

:class:`LaplaceMove` is an emcee move (independence Metropolis-Hastings) whose proposal is a
mixture of multivariate Student-t components, first the Laplace approximation at the point
estimate, later mixtures fitted to the chain (:meth:`LaplaceMove.from_samples`) in coordinates
warped per parameter towards a normal marginal (:func:`warp`, :func:`choose_warps`).
:func:`proposal_quality` judges a proposal and :func:`share_from_quality` gives its share of the
moves. Used by :mod:`analysis.fit.moves`.
"""

from __future__ import annotations

import emcee
import numpy as np
import scipy.linalg
import scipy.special

__all__ = ["LaplaceMove", "warp", "unwarp", "choose_warps", "proposal_quality",
           "share_from_quality", "draw_log_weights", "ess_fraction",
           "expected_acceptance", "WARPS", "MIXTURE_COMPONENTS"]


#: Numbers of mixture components tried when the independence proposal is refit to a chain.
MIXTURE_COMPONENTS = (1, 2, 4, 8)

#: Maps of one internal coordinate u = logit(q) into the proposal's space: the identity,
#: log q and -log(1 - q) (see :func:`choose_warps`).
WARPS = ("logit", "log", "log1m")


def warp(u, warps) -> tuple[np.ndarray, np.ndarray]:
    r"""Internal coordinates u (n, d) -> proposal coordinates v (n, d) and log |dv/du| (n,).

    Per coordinate, by ``warps[i]`` (an index into :data:`WARPS`): 0 keeps v = u = logit q;
    1 gives v = log q = -softplus(-u), with dv/du = 1 - q; 2 gives v = -log(1 - q) =
    softplus(u), with dv/du = q. The log warp pulls a long tail towards the lower bound
    (q -> 0) in, the log1m one a tail towards the upper bound.

    Examples
    --------
    >>> v, lj = warp(np.array([[0.0, 0.0, 0.0]]), [0, 1, 2])
    >>> np.round(v, 6).tolist(), round(float(lj[0]), 6)     # log 1/2, 2 log 1/2
    ([[0.0, -0.693147, 0.693147]], -1.386294)
    """
    u = np.atleast_2d(np.asarray(u, dtype=np.float64))
    k = np.asarray(warps)
    v = u.copy()
    lj = np.zeros(u.shape[0])
    m = k == 1
    if m.any():
        v[:, m] = -np.logaddexp(0.0, -u[:, m])
        lj -= np.logaddexp(0.0, u[:, m]).sum(axis=1)
    m = k == 2
    if m.any():
        v[:, m] = np.logaddexp(0.0, u[:, m])
        lj -= np.logaddexp(0.0, -u[:, m]).sum(axis=1)
    return v, lj


def unwarp(v, warps) -> np.ndarray:
    """Inverse of :func:`warp`: proposal coordinates v (n, d) -> internal u (n, d); rows that
    lie outside the image of the map (v >= 0 for log, v <= 0 for log1m) are NaN."""
    v = np.atleast_2d(np.asarray(v, dtype=np.float64))
    k = np.asarray(warps)
    u = v.copy()
    bad = np.zeros(v.shape[0], dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        m = k == 1
        if m.any():
            bad |= np.any(~(v[:, m] < 0), axis=1)
            u[:, m] = v[:, m] - np.log(-np.expm1(v[:, m]))
        m = k == 2
        if m.any():
            bad |= np.any(~(v[:, m] > 0), axis=1)
            u[:, m] = v[:, m] + np.log(-np.expm1(-v[:, m]))
    bad |= ~np.all(np.isfinite(u), axis=1)
    u[bad] = np.nan
    return u


def choose_warps(x) -> np.ndarray:
    r"""Per coordinate of samples x (n, d), the map of :data:`WARPS` under which the marginal
    is most nearly Gaussian: the largest profile log-likelihood of a normal fitted to v,
    :math:`-\tfrac{n}{2}\log \widehat{\mathrm{var}}(v) + \sum \log |dv/du|` (Box and Cox's
    criterion). Returns an int array (d,).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> q = np.exp(rng.normal(-3.0, 0.5, (4000, 1)))         # log-normal, near q = 0
    >>> u = np.log(q) - np.log1p(-q)
    >>> choose_warps(np.concatenate([u, -u, rng.normal(size=(4000, 1))], axis=1)).tolist()
    [1, 2, 0]
    """
    x = np.atleast_2d(np.asarray(x, dtype=np.float64))
    n, d = x.shape
    out = np.zeros(d, dtype=int)
    for i in range(d):
        best = -np.inf
        for k in range(len(WARPS)):
            v, lj = warp(x[:, i:i + 1], [k])
            var = float(np.var(v))
            ll = -0.5 * n * np.log(var) + lj.sum() if var > 0 else -np.inf
            if ll > best:
                best, out[i] = ll, k
    return out


class LaplaceMove(emcee.moves.MHMove):
    r"""Independence Metropolis-Hastings move from a fixed mixture of multivariate Student-t.

    The proposal

    .. math:: q(x) = \sum_k w_k\, t_{df}(x;\ \mu_k,\ s^2 \Sigma_k)

    does not depend on the current position and is fixed while it is used, so the move keeps
    the posterior invariant with the Hastings factor log q(x) - log q(x'). The components live
    in warped coordinates v = w(x) (:func:`warp`, per coordinate the identity, log q or
    -log(1 - q)), so that q(x) = q_v(w(x)) |dw/dx|; a draw outside the image of w is a
    proposal of zero target density and is rejected. One component is
    the Laplace approximation at the point estimate; :meth:`from_samples` fits several
    (Gaussian-mixture EM on chain samples), which follows the skewed and curved posteriors of
    real measurements (parameters against a bound, brightness traded against k_d) far better
    than one ellipsoid. Where q covers the posterior the move is accepted often and each
    accepted draw is independent of the last, which cuts the autocorrelation time; the DE
    moves mixed with it handle the rest.

    Parameters
    ----------
    mean : array_like, shape (d,) or (K, d)
    cov : array_like, shape (d, d) or (K, d, d)
    df : float
        Degrees of freedom of every component (heavy tails keep p/q bounded).
    scale : float
        Factor s on every component's standard deviations.
    weights : array_like, shape (K,), optional
        Mixture weights (default equal).
    warps : array_like of int, shape (d,), optional
        The map of each coordinate (:data:`WARPS`; default all 0, the identity); ``mean`` and
        ``cov`` are in the warped coordinates.
    """

    def __init__(self, mean, cov, df: float = 5.0, scale: float = 1.2, weights=None,
                 warps=None):
        means = np.atleast_2d(np.asarray(mean, dtype=np.float64))
        covs = np.asarray(cov, dtype=np.float64)
        covs = covs[None] if covs.ndim == 2 else covs
        k = means.shape[0]
        if covs.shape != (k, means.shape[1], means.shape[1]):
            raise ValueError(f"cov must have shape (K, d, d) = ({k}, {means.shape[1]}, "
                             f"{means.shape[1]}); got {covs.shape}")
        w = np.full(k, 1.0 / k) if weights is None else np.asarray(weights, dtype=np.float64)
        self.df = float(df)
        self.warps = (np.zeros(means.shape[1], dtype=int) if warps is None
                      else np.asarray(warps, dtype=int))
        self._set(means, np.linalg.cholesky(covs * scale ** 2), w / w.sum())
        super().__init__(self._propose, ndim=means.shape[1])

    def _set(self, means, chols, weights):
        self.means, self.chols, self.weights = means, chols, weights
        self._logw = np.log(weights) - np.log(np.diagonal(chols, axis1=1, axis2=2)).sum(axis=1)
        # inverse factors: each log q is then one small matrix product per component
        self._inv = np.linalg.inv(chols)

    @property
    def n_components(self) -> int:
        return self.means.shape[0]

    def state(self) -> dict:
        """The proposal as plain arrays (for checkpoints): means, chols, weights, warps, df."""
        return {"means": self.means, "chols": self.chols, "weights": self.weights,
                "warps": self.warps, "df": np.float64(self.df)}

    @classmethod
    def from_state(cls, state) -> "LaplaceMove":
        """The proposal saved by :meth:`state`, bit for bit."""
        move = cls.__new__(cls)
        move.df = float(np.asarray(state["df"]))
        move.warps = np.asarray(state["warps"], dtype=int)
        move._set(np.asarray(state["means"], dtype=np.float64),
                  np.asarray(state["chols"], dtype=np.float64),
                  np.asarray(state["weights"], dtype=np.float64))
        emcee.moves.MHMove.__init__(move, move._propose, ndim=move.means.shape[1])
        return move

    @classmethod
    def from_samples(cls, x, components: int, rng, *, ridge=None, df: float = 5.0,
                     scale: float = 1.2, iters: int = 60, warps=None,
                     tol: float = 1e-3) -> "LaplaceMove | None":
        """Fit ``components`` components to samples x (n, d) by Gaussian-mixture EM.

        The fit is made in the coordinates ``warp(x, warps)`` (default the identity). Seeds by
        k-means++ from ``rng``; ``ridge`` (d,) is added to every covariance's diagonal.
        Components left with fewer than 2 d samples' weight are dropped; EM stops after
        ``iters`` iterations or when the mean log-likelihood per sample gains less than
        ``tol``. Returns None when the
        samples are too few (< 5 d per component) or degenerate.
        """
        x = np.asarray(x, dtype=np.float64)
        n, d = x.shape
        warps = np.zeros(d, dtype=int) if warps is None else np.asarray(warps, dtype=int)
        x = warp(x, warps)[0]
        if n < 5 * d * components:
            return None
        ridge = np.zeros(d) if ridge is None else np.asarray(ridge, dtype=np.float64)
        cov0 = np.cov(x.T).reshape(d, d) + np.diag(ridge)
        if components == 1:
            try:
                return cls(x.mean(axis=0), cov0, df=df, scale=scale, warps=warps)
            except np.linalg.LinAlgError:
                return None
        # k-means++ seeds in the whitened space
        try:
            lw = np.linalg.cholesky(cov0)
        except np.linalg.LinAlgError:
            return None
        z = scipy.linalg.solve_triangular(lw, (x - x.mean(axis=0)).T, lower=True).T
        centres = [z[rng.integers(n)]]
        for _ in range(components - 1):
            d2 = np.min([((z - c) ** 2).sum(axis=1) for c in centres], axis=0)
            if not d2.sum() > 0:          # every point on a centre: no second component
                return None
            centres.append(z[rng.choice(n, p=d2 / d2.sum())])
        resp = np.exp(-0.5 * np.array([((z - c) ** 2).sum(axis=1) for c in centres]))
        resp /= np.maximum(resp.sum(axis=0), 1e-300)
        ll_prev = -np.inf
        for _ in range(iters):
            nk = resp.sum(axis=1)
            keep = nk > 2 * d
            resp, nk = resp[keep], nk[keep]
            w = nk / n
            mu = resp @ x / nk[:, None]
            dx = x[None] - mu[:, None]                              # (K, n, d)
            covs = ((resp[:, :, None] * dx).transpose(0, 2, 1) @ dx) / nk[:, None, None] \
                + np.diag(ridge)
            try:
                c = np.linalg.cholesky(covs)
            except np.linalg.LinAlgError:
                return None
            zz = np.linalg.inv(c) @ dx.transpose(0, 2, 1)          # (K, d, n)
            logp = (np.log(w) - np.log(np.diagonal(c, axis1=1, axis2=2)).sum(axis=1))[:, None] \
                - 0.5 * (zz * zz).sum(axis=1)
            top = logp.max(axis=0)
            norm = top + np.log(np.exp(logp - top).sum(axis=0))
            resp = np.exp(logp - norm)
            ll = float(np.mean(norm))
            if ll - ll_prev < tol:        # EM converged (mean log-likelihood per sample)
                break
            ll_prev = ll
        try:
            return cls(mu, covs, df=df, scale=scale, weights=w, warps=warps)
        except np.linalg.LinAlgError:
            return None

    def logq(self, x) -> np.ndarray:
        """log q(x) up to a constant, x (n, d) in internal coordinates."""
        x, logjac = warp(x, self.warps)
        out = np.empty((self.n_components, x.shape[0]))
        for j in range(self.n_components):
            z = self._inv[j] @ (x - self.means[j]).T
            out[j] = self._logw[j] - 0.5 * (self.df + x.shape[1]) * np.log1p(
                (z * z).sum(axis=0) / self.df)
        return scipy.special.logsumexp(out, axis=0) + logjac

    def sample(self, n: int, random) -> np.ndarray:
        """n draws from q in internal coordinates, (n, d); ``random`` a NumPy Generator or
        RandomState. Draws outside the image of the warp are rows of NaN."""
        d = self.means.shape[1]
        if self.n_components == 1:
            comp = np.zeros(n, dtype=int)
        else:
            comp = random.choice(self.n_components, size=n, p=self.weights)
        z = random.standard_normal((n, d))
        z = np.einsum("nij,nj->ni", self.chols[comp], z)
        w = random.chisquare(self.df, n) / self.df
        return unwarp(self.means[comp] + z / np.sqrt(w)[:, None], self.warps)

    def _propose(self, x0, random):
        x1 = self.sample(x0.shape[0], random)
        bad = np.isnan(x1[:, 0])
        x1[bad] = x0[bad]                 # a proposal outside the support: rejected
        factor = self.logq(x0) - self.logq(x1)
        factor[bad] = -np.inf
        return x1, factor


def proposal_quality(logpost, move: "LaplaceMove", rng, n: int = 256, chain=None,
                     chain_logp=None) -> float:
    r"""How good the independence proposal q is, from n draws y ~ q and w = p / q.

    Parameters
    ----------
    logpost : callable
        Vectorized log-posterior, internal coordinates (n, d) -> (n,).
    move : LaplaceMove
        The proposal.
    rng : numpy.random.Generator
        Source of the draws.
    n : int
        Number of draws (each costs one log-posterior evaluation).
    chain, chain_logp : array_like, optional
        Posterior samples (m, d) and their log-posterior values (m,).

    Returns
    -------
    float
        Without ``chain``: the importance-sampling ESS fraction
        :math:`(\sum w)^2 / (n \sum w^2)`, 1 for a perfect proposal, near 0 for a poor one.
        With ``chain``: the move's expected acceptance rate at stationarity,
        :math:`\mathrm{mean}_{x, y} \min(1, w(y) / w(x))` over the chain's x and the draws y.
        This also sees what the ESS misses: posterior regions that q under-covers, where a
        walker would stick. Draws outside the proposal's support count as rejected (w = 0).
    """
    lw = draw_log_weights(logpost, move, rng, n)
    if chain is not None:
        return expected_acceptance(move, lw, chain, chain_logp)
    return ess_fraction(lw)


def draw_log_weights(logpost, move: "LaplaceMove", rng, n: int = 256) -> np.ndarray:
    """log w = log p - log q (up to constants) of n draws y ~ q, -inf for draws outside the
    proposal's support or of zero posterior density: (n,). Costs n log-posterior evaluations;
    the result stays valid as long as the proposal does (it does not depend on the chain)."""
    y = move.sample(n, rng)
    ok = ~np.isnan(y[:, 0])
    lw = np.full(n, -np.inf)
    if ok.any():
        with np.errstate(invalid="ignore"):
            lw[ok] = logpost(y[ok]) - move.logq(y[ok])
    return np.where(np.isfinite(lw), lw, -np.inf)


def ess_fraction(lw) -> float:
    r"""Importance-sampling ESS fraction :math:`(\sum w)^2 / (n \sum w^2)` of log weights."""
    lw = np.asarray(lw, dtype=np.float64)
    if not np.any(np.isfinite(lw)):
        return 0.0
    w = np.exp(lw - np.max(lw))
    return float(w.sum() ** 2 / (lw.size * (w * w).sum()))


def expected_acceptance(move: "LaplaceMove", lw_draws, chain, chain_logp) -> float:
    r"""Expected acceptance of the independence move at stationarity,
    :math:`\mathrm{mean}_{x, y} \min(1, w(y) / w(x))`, from the log weights of draws
    (:func:`draw_log_weights`) and posterior samples x (m, d) with their log-posterior (m,)."""
    lw = np.asarray(lw_draws, dtype=np.float64)
    if not np.any(np.isfinite(lw)):
        return 0.0
    lwx = np.asarray(chain_logp, dtype=np.float64) - move.logq(chain)
    lwx = lwx[np.isfinite(lwx)]
    if lwx.size == 0:
        return 0.0
    return float(np.mean(np.exp(np.minimum(0.0, lw[None, :] - lwx[:, None]))))


def share_from_quality(frac: float, laplace_move: float) -> float:
    """The independence move's share for a proposal of quality ``frac``: ``laplace_move``
    scaled by ``frac / 0.2``, within [0.05, ``laplace_move``]."""
    share = laplace_move * min(1.0, frac / 0.2) if np.isfinite(frac) else 0.0
    return max(share, 0.05)
