"""Levenberg-Marquardt on renders, and the Laplace approximation at its optimum.

The free parameters live in flat coordinates ``u`` (the value, or its logarithm for a
log-uniform prior: where the prior is flat), boxed in by their prior bounds. ``pair(u)``
renders every image at ``u`` twice, with two independent seeds ``a`` and ``b``, and returns
both normalized residuals ``r = (render - image) / sd``. The loss is decorrelated:

    L(u) = sum(r_a * r_b) / 2,

an unbiased estimate, at every ``u``, of the loss of the noiseless render (the two renders'
Monte Carlo errors are independent, so their product averages to zero). The plain
``sum(r_a**2) / 2`` of one seed is not: it also holds the render's Monte Carlo variance,
which changes with the parameters, and its minimum is pulled toward parameters that render
with less noise (by several standard deviations of the answer at a few samples a pixel).
The same reason makes Mitsuba's ``prb`` use another seed for its adjoint pass.

Each seed keeps its random numbers from step to step (common random numbers), so a
difference of renders is the change of the render, not of its noise: the Jacobians are by
forward finite differences in ``u`` (steps of :data:`STEP` of each range, toward the inside).
The gradient is ``g = (J_a' r_b + J_b' r_a) / 2``, the Gauss-Newton matrix
``H = (J_a' J_a + J_b' J_b) / 2``; a step solves ``(H + lambda diag(H)) d = -g``, accepted
when the loss falls (lambda / 3), else lambda * 4. Converged when the Newton decrement
``g' H^-1 g / 2`` of the parameters not pressed against a bound falls below
:data:`DECREMENT` (the loss could fall by less than that much more, a small fraction of the
0.5 a one-sigma change costs).
"""

from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

__all__ = ["Solution", "levenberg_marquardt", "jacobian", "laplace", "STEP", "DECREMENT"]

#: Finite-difference step: this share of each parameter's range in flat coordinates.
STEP = 2e-3
#: Convergence: the Newton decrement (expected further fall of the loss) below this.
DECREMENT = 1e-3


@dataclasses.dataclass
class Solution:
    """Where the optimizer stopped: ``u``, the residual pair ``r`` and its Jacobians ``J``,
    ``converged`` and ``reason``, ``history`` (one dict a step: ``iteration``, ``loss``,
    ``u``, ``accepted``) and ``evaluations`` (calls of ``residuals``)."""

    u: np.ndarray
    r: tuple
    J: tuple
    converged: bool
    reason: str
    history: list
    evaluations: int


def jacobian(residuals: Callable, u, r, lo, hi) -> np.ndarray:
    """Forward differences of ``residuals`` at ``u`` (``r = residuals(u)``), each step
    :data:`STEP` of the range, taken toward the inside of ``[lo, hi]``; ``residuals`` may
    return a tuple of arrays (one Jacobian each)."""
    rs = r if isinstance(r, tuple) else (r,)
    Js = [np.empty((x.size, u.size)) for x in rs]
    for j in range(u.size):
        h = STEP * (hi[j] - lo[j])
        if u[j] + h > hi[j]:
            h = -h
        v = u.copy()
        v[j] += h
        rv = residuals(v)
        for J, x, y in zip(Js, rs, rv if isinstance(rv, tuple) else (rv,)):
            J[:, j] = (y - x) / h
    return tuple(Js) if isinstance(r, tuple) else Js[0]


class _State:
    """The loss, gradient and Gauss-Newton matrix at ``u`` (module notes)."""

    def __init__(self, pair, u, lo, hi):
        self.u = u
        self.r = pair(u)
        self.loss = 0.5 * float(self.r[0] @ self.r[1])

    def differentiate(self, pair, lo, hi):
        (ra, rb), (Ja, Jb) = self.r, jacobian(pair, self.u, self.r, lo, hi)
        self.J = (Ja, Jb)
        self.g = 0.5 * (Ja.T @ rb + Jb.T @ ra)
        self.H = 0.5 * (Ja.T @ Ja + Jb.T @ Jb)

    def decrement(self, lo, hi) -> float:
        """The Newton decrement over the parameters not held at a bound by the gradient."""
        u, g = self.u, self.g
        k = ~(((u <= lo) & (g > 0)) | ((u >= hi) & (g < 0)))
        if not k.any():
            return 0.0
        return 0.5 * float(g[k] @ np.linalg.lstsq(self.H[np.ix_(k, k)], g[k], rcond=None)[0])


def levenberg_marquardt(pair: Callable, u0, lo, hi, *, max_iter: int = 30,
                        on_step: Callable | None = None, history=None) -> Solution:
    """Minimize the decorrelated loss of ``pair(u) -> (r_a, r_b)`` over the box
    ``[lo, hi]`` (module notes).

    ``on_step(entry)`` is called at the start (``entry["start"]`` true) and after each step
    (progress, checkpoints); ``history`` continues an earlier run's (its steps are counted
    on).

    Examples
    --------
    >>> t = np.linspace(0, 1, 20)
    >>> f = lambda u: (u[0] * np.exp(-u[1] * t) - 2.0 * np.exp(-3.0 * t)) / 0.01
    >>> s = levenberg_marquardt(lambda u: (f(u), f(u)), np.array([1.0, 1.0]), np.zeros(2),
    ...                         np.full(2, 10.0))
    >>> s.converged, np.round(s.u, 4).tolist()
    (True, [2.0, 3.0])
    """
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    history = list(history or [])
    st = _State(pair, np.clip(np.asarray(u0, float), lo, hi), lo, hi)
    st.differentiate(pair, lo, hi)
    evals, lam, start = 1 + st.u.size, 1e-2, len(history)
    entry = {"iteration": start, "loss": st.loss, "u": st.u.tolist(), "accepted": True,
             "lambda": lam, "start": True}
    history.append(entry)
    if on_step is not None:
        on_step(entry)
    for it in range(start, start + max_iter):
        dec = st.decrement(lo, hi)
        if dec < DECREMENT:
            return Solution(st.u, st.r, st.J, True, f"converged at step {it}: the loss could "
                            f"fall by {dec:.2g} more (below {DECREMENT:g})", history, evals)
        H = st.H
        d = np.linalg.lstsq(H + lam * np.diag(np.diag(H) + 1e-12), -st.g, rcond=None)[0]
        new = _State(pair, np.clip(st.u + d, lo, hi), lo, hi)
        evals += 1
        accepted = new.loss < st.loss
        if accepted:
            st, lam = new, max(lam / 3.0, 1e-7)
            st.differentiate(pair, lo, hi)
            evals += st.u.size
        else:
            lam *= 4.0
        entry = {"iteration": it + 1, "loss": st.loss, "u": st.u.tolist(),
                 "accepted": accepted, "lambda": lam}
        history.append(entry)
        if on_step is not None:
            on_step(entry)
        if lam > 1e10:
            return Solution(st.u, st.r, st.J, False, f"stopped at step {it + 1}: no step "
                            f"lowers the loss (lambda {lam:.2g})", history, evals)
    return Solution(st.u, st.r, st.J, False, f"stopped at the step limit ({start + max_iter}) "
                    f"before converging", history, evals)


def laplace(J, prior_sd, scale: float = 1.0, v=None) -> np.ndarray:
    """The covariance of the flat coordinates at the optimum.

    The data's information is the sandwich ``F = H M^+ H / scale`` of the estimating equation
    ``g = 0``: ``H = J'J`` (``J`` the two seeds' mean Jacobian), ``M`` the covariance of
    ``J' r`` for ``r`` the normalized residuals of the two renders' mean,
    ``sum_p J_p' v_p J_p`` for ``v`` of shape (n / 3, 3, 3), the covariance of each pixel's
    three channels (``J_p`` its three rows), whose Monte Carlo errors are correlated (``H``
    where ``v`` is None: independent residuals of variance 1); ``scale`` the residuals'
    variance in units of the noise model's. To it is added a Gaussian
    of the prior's sd standing in for the flat prior (it keeps a parameter the images cannot
    see at about the prior's spread instead of an infinite one); the covariance is the
    inverse of the sum.

    Examples
    --------
    >>> J = np.array([[2.0, 0.0], [0.0, 0.0]])
    >>> np.round(np.sqrt(np.diag(laplace(J, np.array([1.0, 0.3])))), 4).tolist()
    [0.4472, 0.3]

    One pixel's three channels, each moving as the parameter does: independent errors tell
    the parameter to 1 / sqrt(3); one error shared by the three (a correlation of 1), to 1.

    >>> J, prior = np.ones((3, 1)), np.array([1e6])
    >>> [round(float(np.sqrt(laplace(J, prior, v=c[None])[0, 0])), 4)
    ...  for c in (np.eye(3), np.ones((3, 3)))]
    [0.5774, 1.0]
    """
    J = np.asarray(J, float)
    H = J.T @ J
    if v is None:
        M = H
    else:
        Jp = J.reshape(len(v), 3, J.shape[1])
        M = np.einsum("pci,pcd,pdj->ij", Jp, np.asarray(v, float), Jp, optimize=True)
    F = H @ np.linalg.pinv(M, rcond=1e-12, hermitian=True) @ H / scale
    return np.linalg.inv(F + np.diag(1.0 / np.asarray(prior_sd, float) ** 2))
