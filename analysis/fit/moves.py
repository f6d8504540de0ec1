r"""The moves of each ensemble and the refits of its independence proposal.

Each ensemble has one :class:`EnsembleMoves`, an emcee :class:`~emcee.moves.Move` that at
every step picks one of its moves with its own weights, through emcee's public interface
(``propose(model, state)``): differential evolution (:class:`~emcee.moves.DEMove`, 0.8 of
the rest) and its snooker variant (0.2 of the rest), and the independence Metropolis-Hastings
move :class:`~analysis.fit.proposal.LaplaceMove` with the share
:func:`~analysis.fit.proposal.share_from_quality` gives it. The pick uses the ensemble's
random state, so a resumed ensemble repeats it.

:func:`refit` fits candidate proposals to an ensemble's chain at a point of the refit schedule
(:func:`refit_schedule`) and decides whether one replaces the current one. The log weights of
the current proposal's draws are kept with it (:class:`Proposal`): they depend on the proposal
only, so a refit scores only the new candidate.
"""

from __future__ import annotations

import dataclasses

import emcee
import numpy as np

from analysis.fit.proposal import (MIXTURE_COMPONENTS, WARPS, LaplaceMove, choose_warps,
                                   draw_log_weights, ess_fraction, expected_acceptance,
                                   share_from_quality)

__all__ = ["EnsembleMoves", "Proposal", "initial_proposal", "refit", "refit_schedule",
           "DRAWS"]

#: Draws from a proposal that are scored (one log-posterior evaluation each) to judge it.
DRAWS = 256


class EnsembleMoves(emcee.moves.Move):
    """One step of an ensemble: one move chosen among DE, DE snooker and the independence move.

    Parameters
    ----------
    ndim : int
        Number of free parameters.
    proposal : LaplaceMove
        The independence move (its components may later be replaced in place).
    share : float
        Probability of the independence move (0 to 1); DE and snooker share the rest 0.8 : 0.2.

    Examples
    --------
    >>> m = EnsembleMoves(2, LaplaceMove(np.zeros(2), np.eye(2)), 0.5)
    >>> np.round(m.weights, 2).tolist()
    [0.4, 0.1, 0.5]
    """

    def __init__(self, ndim: int, proposal: LaplaceMove, share: float):
        self.moves = [emcee.moves.DEMove(gamma0=2.38 / np.sqrt(2 * ndim)),
                      emcee.moves.DESnookerMove(), proposal]
        self.set_share(share)

    @property
    def proposal(self) -> LaplaceMove:
        """The independence move."""
        return self.moves[2]

    def set_proposal(self, proposal: LaplaceMove, share: float):
        """Replace the independence move and its share."""
        self.moves[2] = proposal
        self.set_share(share)

    def set_share(self, share: float):
        """Give the independence move probability ``share``, the DE moves the rest."""
        share = float(share)
        if not 0.0 <= share <= 1.0:
            raise ValueError(f"share must be in [0, 1]; got {share}")
        self.share = share
        self.weights = np.array([0.8 * (1 - share), 0.2 * (1 - share), share])

    def propose(self, model, state):
        """emcee's Move interface: pick a move with ``model.random``, let it propose."""
        i = model.random.choice(len(self.moves), p=self.weights)
        return self.moves[i].propose(model, state)


@dataclasses.dataclass
class Proposal:
    """An ensemble's current independence proposal and what is known of it.

    Attributes
    ----------
    move : LaplaceMove
    share : float
        Its share of the moves.
    draw_lw : ndarray (DRAWS,) or None
        Log weights log p - log q of draws from it (None when it was never scored).
    last_kept : int
        Step of the last refit that replaced it (0 for the initial proposal).
    """

    move: LaplaceMove
    share: float
    draw_lw: np.ndarray | None = None
    last_kept: int = 0


def refit_schedule(adapt: int, max_steps: int) -> list[int]:
    """Refit points ``adapt, 2 adapt, 4 adapt, ...`` below ``max_steps`` (none when adapt is 0).

    Examples
    --------
    >>> refit_schedule(100, 1000)
    [100, 200, 400, 800]
    """
    out = []
    while 0 < adapt * 2 ** len(out) < max_steps:
        out.append(adapt * 2 ** len(out))
    return out


def initial_proposal(logpost, best, cov, laplace_move: float, seed: int) -> tuple[Proposal, dict]:
    """The Laplace approximation at the point estimate as the first proposal.

    Its share is :func:`share_from_quality` of its importance-sampling ESS fraction over
    :data:`DRAWS` draws; without a usable covariance it is a narrow Student-t of share 0, so
    that the first refit can replace it.

    Returns
    -------
    proposal : Proposal
    info : dict
        ``share`` and ``importance_ess_fraction`` (JSON-ready).
    """
    spec = logpost.spec
    if cov is None or laplace_move <= 0:
        move = LaplaceMove(best, np.diag((1e-2 * spec.width) ** 2))
        return Proposal(move, 0.0), {"share": 0.0, "importance_ess_fraction": None}
    move = LaplaceMove(best, cov)
    lw = draw_log_weights(logpost, move, np.random.default_rng(seed), DRAWS)
    frac = ess_fraction(lw)
    share = share_from_quality(frac, laplace_move)
    return Proposal(move, share, lw), {"share": share, "importance_ess_fraction": frac}


def _candidates(x, xt, spec, seed, k, a):
    """The best candidate fitted to x by held-out mean log q on xt, or None."""
    ndim = x.shape[1]
    best, score = None, -np.inf
    chosen = choose_warps(x)
    for warps in [np.zeros(ndim, dtype=int)] + ([chosen] if chosen.any() else []):
        for n_comp in MIXTURE_COMPONENTS:
            cand = LaplaceMove.from_samples(x, n_comp, np.random.default_rng([seed, k, a, n_comp]),
                                            ridge=(1e-9 * spec.width) ** 2, warps=warps)
            if cand is None:
                continue
            with np.errstate(invalid="ignore"):
                sc = float(np.mean(cand.logq(xt)))
            if np.isfinite(sc) and sc > score:
                best, score = cand, sc
    return best


def refit(logpost, current: Proposal, chain, log_prob, *, step: int, ensemble: int, seed: int,
          laplace_move: float) -> tuple[Proposal, dict]:
    """Refit an ensemble's independence proposal to its chain over steps a/2 to a.

    Mixtures of :data:`MIXTURE_COMPONENTS` components, in internal and in warped coordinates
    (:func:`choose_warps`), are fitted to the even-numbered walkers; the one with the largest
    mean log q on (up to 2048 samples of) the odd-numbered ones is scored on :data:`DRAWS` of
    its own draws and replaces the current proposal when its expected acceptance rate there is
    more than 10% above the current one's (or the current one has share 0). Deterministic given
    the chain, the seed, the ensemble and the step.

    Parameters
    ----------
    chain : ndarray (steps, walkers, ndim)
        Steps a/2 to a of the ensemble, internal coordinates.
    log_prob : ndarray (steps, walkers)

    Returns
    -------
    proposal : Proposal
        The new one, or ``current`` itself.
    record : dict
        The decision, JSON-ready.
    """
    spec, ndim, a = logpost.spec, chain.shape[-1], step
    x = chain[:, 0::2].reshape(-1, ndim)
    xt, lpt = chain[:, 1::2].reshape(-1, ndim), log_prob[:, 1::2].reshape(-1)
    pick = np.random.default_rng([seed, ensemble, a, 1]).permutation(len(xt))[:2048]
    xt, lpt = xt[pick], lpt[pick]
    x = x[np.random.default_rng([seed, ensemble, a, 2]).permutation(len(x))[:16384]]
    cand = _candidates(x, xt, spec, seed, ensemble, a)
    if cand is None:
        return current, {"step": a, "kept": False}
    lw = draw_log_weights(logpost, cand, np.random.default_rng([seed, ensemble, a]), DRAWS)
    frac = expected_acceptance(cand, lw, xt, lpt)
    frac_now = (float("nan") if current.draw_lw is None else
                expected_acceptance(current.move, current.draw_lw, xt, lpt))
    better = np.isfinite(frac) and (not np.isfinite(frac_now) or frac > 1.1 * frac_now
                                    or current.share == 0)
    if not better:
        return current, {"step": a, "kept": False, "acceptance": frac, "current": frac_now}
    share = share_from_quality(frac, laplace_move)
    return Proposal(cand, share, lw, a), {
        "step": a, "kept": True, "share": share, "acceptance": frac,
        "components": cand.n_components, "warps": [WARPS[i] for i in cand.warps],
        "previous": frac_now}
