r"""Bayesian D-optimal selection of pairs: greedy with rank-r updates, then an exchange pass.

The criterion of a design D (a set of candidate pairs) is the expected log determinant of the
posterior precision in the Laplace approximation,

.. math::

    \Phi(D) = \frac1K \sum_{k=1}^K \log\det\Big(A_{0,k} + \sum_{p \in D} \tilde J_{kp}^T
              \tilde J_{kp}\Big),

with :math:`\tilde J_{kp}` the whitened Jacobian of pair p at draw k (r rows, r = 3 for RGB,
1 for grey: :mod:`analysis.planning.information`) and :math:`A_{0,k}` the starting precision:
the fit's prior information (1/3 per internal coordinate,
:data:`analysis.fit.fisher.PRIOR_INFORMATION`) plus, with ``--from``, the information of the pairs already measured.

**Greedy.** Each step adds the candidate of largest gain; by the matrix determinant lemma
the gain of p is :math:`\frac1K\sum_k \log\det(I_r + \tilde J_{kp} A_k^{-1} \tilde J_{kp}^T)`,
computed for every candidate at once (O(K M r d^2) for M candidates, d free parameters)
and then lazily (a gain only falls as the design grows: :func:`greedy`), and
:math:`A_k^{-1}` is updated by the Woodbury identity (a rank-r update). A pair is taken at most once (an operator measures distinct configurations).

**Exchange.** Then each chosen pair in turn is removed (a rank-r downdate) and the best
candidate of a pool (itself included; the pool the :data:`EXCHANGE_POOL` candidates of
largest gain at the greedy design) put in its place: a Fedorov exchange pass, which never lowers
:math:`\Phi` and repairs the greedy's early choices. One pass, so the result is the same
for the same input (no time limit decides).
"""

from __future__ import annotations

import numpy as np

__all__ = ["greedy", "exchange", "expected_log_det", "expected_covariance", "LAZY_BATCH",
           "EXCHANGE_POOL"]

#: Candidates whose gains a step of the lazy greedy recomputes at once.
LAZY_BATCH = 64
#: Candidates an exchange pass may swap in: those of largest gain at the greedy design.
EXCHANGE_POOL = 2048


def _logdet_small(g: np.ndarray) -> np.ndarray:
    """log det(I + g) of (..., r, r) symmetric non-negative g; closed forms for r <= 3."""
    r = g.shape[-1]
    a = g + np.eye(r)
    if r == 1:
        det = a[..., 0, 0]
    elif r == 3:
        det = (a[..., 0, 0] * (a[..., 1, 1] * a[..., 2, 2] - a[..., 1, 2] * a[..., 2, 1])
               - a[..., 0, 1] * (a[..., 1, 0] * a[..., 2, 2] - a[..., 1, 2] * a[..., 2, 0])
               + a[..., 0, 2] * (a[..., 1, 0] * a[..., 2, 1] - a[..., 1, 1] * a[..., 2, 0]))
    else:
        return np.linalg.slogdet(a)[1]
    return np.log(np.maximum(det, 1e-300))


def _gains(jac: np.ndarray, a_inv: np.ndarray):
    """Expected gain (M,) of adding each candidate, and J A^-1 (K, M, r, d)."""
    k, m, r, d = jac.shape
    ja = (jac.reshape(k, m * r, d) @ a_inv).reshape(k, m, r, d)
    g = np.einsum("kmid,kmjd->kmij", ja, jac)
    return _logdet_small(g).mean(axis=0), ja


def _update(a_inv: np.ndarray, ja_p: np.ndarray, jac_p: np.ndarray, sign: float) -> np.ndarray:
    """Woodbury: (A + sign J^T J)^-1 from A^-1 (K, d, d), J A^-1 and J (K, r, d) of one pair."""
    r = jac_p.shape[-2]
    inner = np.eye(r) + sign * ja_p @ np.swapaxes(jac_p, -1, -2)      # (K, r, r)
    corr = np.swapaxes(ja_p, -1, -2) @ np.linalg.solve(inner, ja_p)
    out = a_inv - sign * corr
    return 0.5 * (out + np.swapaxes(out, -1, -2))


def greedy(jac, a0, budget: int, *, progress=None) -> list[int]:
    """The greedy choice of ``budget`` distinct candidates (module notes), lazily evaluated.

    Parameters
    ----------
    jac : ndarray (K, M, r, d)
        Whitened Jacobians of the candidates at the K draws.
    a0 : ndarray (K, d, d)
        The starting precision at each draw (positive definite).
    budget : int
        Pairs to choose, at most M.
    progress : callable, optional
        Called with 1 after each choice.

    Returns
    -------
    list of int
        Candidate indices in the order chosen.

    Notes
    -----
    The gain of a candidate never grows as the design grows (A only gains positive
    semi-definite terms, so :math:`\tilde J A^{-1} \tilde J^T` shrinks at every draw): a
    gain computed earlier is an upper bound. Each step recomputes the gains of the
    :data:`LAZY_BATCH` candidates of largest bound until the largest bound is a fresh gain,
    which is then the largest gain of all (Minoux's lazy greedy): the choice of the full
    scan at a fraction of its cost.

    Examples
    --------
    >>> jac = np.zeros((1, 3, 1, 2)); jac[0, :, 0] = [[1, 0], [0, 2], [1, 1]]
    >>> greedy(jac, np.eye(2)[None], 2)  # gains log 5; then log 2.2 (pair 2) over log 2
    [1, 2]
    """
    a_inv = np.linalg.inv(np.asarray(a0, dtype=np.float64))
    chosen: list[int] = []
    bound = _gains(jac, a_inv)[0]
    fresh = np.zeros(bound.size, bool)
    for _ in range(budget):
        fresh[:] = False
        while True:
            b = int(np.argmax(bound))
            if fresh[b]:
                break
            k = min(LAZY_BATCH, bound.size)
            idx = np.sort(np.argpartition(-bound, k - 1)[:k])
            idx = idx[np.isfinite(bound[idx])]
            bound[idx] = _gains(jac[:, idx], a_inv)[0]
            fresh[idx] = True
        a_inv = _update(a_inv, jac[:, b] @ a_inv, jac[:, b], 1.0)
        chosen.append(b)
        bound[b] = -np.inf
        if progress is not None:
            progress(1)
    return chosen


def exchange(jac, a0, chosen, *, pool: int = EXCHANGE_POOL, progress=None) -> list[int]:
    """One Fedorov exchange pass over ``chosen`` (module notes): each pair in turn replaced
    by the best candidate of the pool, when that raises the criterion.

    The pool is the ``pool`` candidates not chosen of largest gain at the greedy design
    (one full scan), so that a pass costs N scans of the pool rather than of every
    candidate; a swap is made only when it raises the criterion, so the pass never lowers it.

    Returns
    -------
    list of int
        The design, the i-th entry the pair now in the i-th place.
    """
    chosen = list(chosen)
    a = np.asarray(a0, dtype=np.float64) + _information(jac[:, chosen])
    a_inv = np.linalg.inv(a)
    gain = _gains(jac, a_inv)[0]
    gain[chosen] = -np.inf
    k = min(pool, int(np.isfinite(gain).sum()))
    if k == 0:
        return chosen
    others = np.sort(np.argpartition(-gain, k - 1)[:k])
    for i, p in enumerate(list(chosen)):
        a_inv = _update(a_inv, jac[:, p] @ a_inv, jac[:, p], -1.0)        # p removed
        cand = np.concatenate([[p], others])
        g = _gains(jac[:, cand], a_inv)[0]
        j = int(np.argmax(g))
        q = p if g[j] <= g[0] * (1 + 1e-12) else int(cand[j])
        a_inv = _update(a_inv, jac[:, q] @ a_inv, jac[:, q], 1.0)
        if q != p:
            others[others == q] = p
            others.sort()
        chosen[i] = q
        if progress is not None:
            progress(1)
    return chosen


def _information(jac_design: np.ndarray) -> np.ndarray:
    """sum over pairs and rows of J^T J: (K, d, d) of (K, N, r, d)."""
    flat = jac_design.reshape(jac_design.shape[0], -1, jac_design.shape[-1])
    return np.einsum("kni,knj->kij", flat, flat)


def expected_log_det(a0, jac_design) -> float:
    """:math:`\\Phi`: the mean over draws of log det(A0 + the design's information)."""
    a = np.asarray(a0, dtype=np.float64) + _information(np.asarray(jac_design))
    return float(np.mean(np.linalg.slogdet(a)[1]))


def expected_covariance(a0, jac_design) -> np.ndarray:
    """The expected posterior covariance (d, d) in the Laplace approximation: the mean over
    draws of (A0 + the design's information)^-1."""
    a = np.asarray(a0, dtype=np.float64) + _information(np.asarray(jac_design))
    return np.mean(np.linalg.inv(a), axis=0)
