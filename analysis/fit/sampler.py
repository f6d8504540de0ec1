"""The sampling stage of a fit: ensembles run check by check, refit, checkpointed, judged.

:class:`FitSampler` owns the chains (:mod:`analysis.fit.ensemble`), their moves and
proposals (:mod:`analysis.fit.moves`) and the progress of the fit. :meth:`FitSampler.run`
advances every ensemble to the next check (every ``check_every`` steps, and at each point of
the refit schedule), refits the proposals due there, diagnoses the chains
(:mod:`analysis.fit.convergence`), writes the checkpoint (:mod:`analysis.fit.checkpoint`),
and stops when the criteria hold, at the step limit or at the time limit. Everything it
writes it writes from the calling thread, between runs of the ensembles.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import time

import numpy as np

from analysis.fit.convergence import Diagnosis, diagnose, finite_max, finite_min
from analysis.fit.ensemble import Chain, EnsembleRunner
from analysis.fit.moves import (EnsembleMoves, Proposal, initial_proposal, refit,
                                refit_schedule)
from analysis.fit.optimize import initial_walkers
from analysis.fit.proposal import LaplaceMove

__all__ = ["FitSampler", "FitInterrupted", "Outcome"]


class FitInterrupted(KeyboardInterrupt):
    """Ctrl-C during sampling, after the steps done were checkpointed; ``str()`` says where."""


@dataclasses.dataclass
class Outcome:
    """How sampling ended: the last diagnosis, the verdict, time and evaluations."""

    diagnosis: Diagnosis
    converged: bool
    reason: str
    sample_s: float
    evals: int
    refit_evals: int


class FitSampler:
    """The ensembles of one fit, from the point estimate or from a checkpoint.

    Parameters
    ----------
    logpost : LogPosterior
    opts : analysis.fit.driver.FitOptions
        Resolved options (walkers, adapt and threads set).
    best, cov : ndarray
        Point estimate and Laplace covariance (internal coordinates; cov may be None).
    rngs : list of numpy.random.Generator
        One per ensemble (starting walkers and random state).
    checkpoint : dict, optional
        From :meth:`analysis.fit.checkpoint.FitFolder.read_checkpoint`: continue from it.
    """

    def __init__(self, logpost, opts, best, cov, rngs, checkpoint=None):
        self.logpost, self.opts = logpost, opts
        self.schedule = refit_schedule(opts.adapt, opts.max_steps)
        self.proposal_info = {"adapt_schedule": self.schedule, "adaptations": []}
        self.tau_prev, self.recheck, self.next_refit, self.refit_evals = None, False, 0, 0
        self._last_check, self._tau_before = None, None
        if checkpoint is None:
            self._start(best, cov, rngs)
        else:
            self._restore(checkpoint)
        self.runner = EnsembleRunner(self.chains, logpost, threads=opts.threads)

    # ------------------------------------------------------------------ state
    def _start(self, best, cov, rngs):
        o = self.opts
        first, info = initial_proposal(self.logpost, best, cov, o.laplace_move, o.seed)
        self.proposal_info.update(info)
        self.proposals = [first] * o.ensembles
        self.chains = []
        for k in range(o.ensembles):
            random = np.random.RandomState(int(rngs[k].integers(2**31)))
            coords, lp = initial_walkers(self.logpost, best, cov, o.walkers, rngs[k])
            moves = EnsembleMoves(self.logpost.spec.ndim, first.move, first.share)
            self.chains.append(Chain(moves, random, coords, lp))

    def _restore(self, ckpt):
        o, prog = self.opts, ckpt["progress"]
        ens = ckpt["ensembles"]
        if len(ens) != o.ensembles or ens[0]["chain"].shape[1:] != (o.walkers,
                                                                    self.logpost.spec.ndim):
            raise ValueError(f"the checkpoint holds {len(ens)} ensembles of shape "
                             f"{ens[0]['chain'].shape[1:]}; this fit needs {o.ensembles} of "
                             f"({o.walkers}, {self.logpost.spec.ndim})")
        self.proposals, self.chains = [], []
        for doc in ens:
            p = doc["proposal"]
            prop = Proposal(LaplaceMove.from_state(p), float(p["attr:share"]),
                            p.get("draw_lw"), int(p["attr:last_kept"]))
            r = doc["rng"]
            rng_state = ("MT19937", r["keys"], int(r["attr:pos"]), int(r["attr:has_gauss"]),
                         float(r["attr:cached"]))
            moves = EnsembleMoves(self.logpost.spec.ndim, prop.move, prop.share)
            self.proposals.append(prop)
            self.chains.append(Chain.restore(moves, np.random.RandomState(), doc["chain"],
                                             doc["log_prob"], doc["accepted"], rng_state))
        self.proposal_info.update(prog["proposal"])
        self.next_refit = int(prog["next_refit"])
        steps = [c.steps for c in self.chains]
        checked = prog["checked_step"] is not None and all(s == prog["checked_step"]
                                                          for s in steps)
        self.recheck = checked
        self._last_check, self._tau_before = prog["checked_step"], prog["tau_before"]
        tau = prog["tau_before"] if checked else prog["tau_last"]
        self.tau_prev = None if tau is None else np.asarray(tau, dtype=np.float64)

    def _checkpoint(self, folder, checked_step, tau_before, tau_last):
        if folder is None:
            return
        ens = []
        for c, p in zip(self.chains, self.proposals):
            st = c.rng_state
            ens.append({
                "chain": c.chain(), "log_prob": c.log_prob(), "accepted": c.accepted,
                "rng": {"keys": st[1], "attr:pos": st[2], "attr:has_gauss": st[3],
                        "attr:cached": st[4]},
                "proposal": dict(p.move.state(), draw_lw=p.draw_lw,
                                 **{"attr:share": p.share, "attr:last_kept": p.last_kept})})
        progress = {"checked_step": checked_step, "next_refit": self.next_refit,
                    "tau_before": tau_before, "tau_last": tau_last,
                    "proposal": self.proposal_info}
        folder.write_checkpoint(progress, ens)

    @property
    def steps(self) -> int:
        """Steps every ensemble has made."""
        return min(c.steps for c in self.chains)

    # ------------------------------------------------------------------ refits
    def _refit_due(self):
        """Refit every ensemble at each schedule point reached, in order (in parallel over
        the ensembles: each refit depends only on its own chain)."""
        o = self.opts
        e0 = self.logpost.n_evals
        while self.next_refit < len(self.schedule) and self.schedule[self.next_refit] <= \
                self.steps:
            a = self.schedule[self.next_refit]

            def one(k):
                c = self.chains[k]
                return refit(self.logpost, self.proposals[k], c.chain(a // 2, a),
                             c.log_prob(a // 2, a), step=a, ensemble=k, seed=o.seed,
                             laplace_move=o.laplace_move)
            with cf.ThreadPoolExecutor(o.threads) as ex:
                done = list(ex.map(one, range(o.ensembles)))
            for k, (prop, record) in enumerate(done):
                self.proposals[k] = prop
                self.chains[k].moves.set_proposal(prop.move, prop.share)
                self.proposal_info["adaptations"].append(dict(record, ensemble=k))
            self.next_refit += 1
        self.refit_evals += self.logpost.n_evals - e0

    # ------------------------------------------------------------------ the loop
    def _next_target(self) -> int:
        n, o = self.steps, self.opts
        nxt = min([(n // o.check_every + 1) * o.check_every]
                  + [a for a in self.schedule if a > n])
        return min(o.max_steps, nxt)

    def _interrupted(self, folder) -> FitInterrupted:
        """Checkpoint the completed steps after Ctrl-C; the exception to raise."""
        tau = None if self.tau_prev is None else self.tau_prev.tolist()
        self._checkpoint(folder, self._last_check, self._tau_before, tau)
        where = "" if folder is None else f"; the checkpoint in {folder.path} resumes"
        return FitInterrupted(f"interrupted at step {self.steps}{where}")

    def run(self, folder, tick=None, t0: float | None = None, postfix=None) -> Outcome:
        """Sample until converged, ``max_steps`` or ``time_limit`` (seconds since ``t0``).

        ``tick(steps)`` reports progress; ``postfix(figures, diagnosis, converged)`` each
        check (its figures as texts, its :class:`Diagnosis` and verdict).
        """
        o, c = self.opts, self.opts.criteria
        t0 = time.perf_counter() if t0 is None else t0
        t_s0, e0, r0 = time.perf_counter(), self.logpost.n_evals, self.refit_evals
        try:
            while True:
                rechecked, self.recheck = self.recheck, False
                if not rechecked:
                    self.runner.run_to(self._next_target(), tick)
                    self._refit_due()
                diag = diagnose(self.chains, c.burn_fraction,
                                max(p.last_kept for p in self.proposals), o.threads)
                ok, why = diag.verdict(self.tau_prev, c)
                before = None if self.tau_prev is None else self.tau_prev.tolist()
                if not rechecked:       # a recheck repeats the check the checkpoint holds
                    self._checkpoint(folder, diag.step, before, diag.tau.tolist())
                self._tau_before = before
                self._last_check, dtau = diag.step, diag.tau_change(self.tau_prev)
                self.tau_prev = diag.tau
                if postfix is not None:
                    postfix({"min N/tau": f"{finite_min(diag.ratio):.1f}",
                             "dtau": f"{dtau:.3f}", "max R-hat": f"{finite_max(diag.rhat):.3f}"},
                            diag, ok)
                if ok:
                    break
                if diag.step >= o.max_steps:
                    why = f"NOT converged: step limit {o.max_steps} reached; {why}"
                    break
                if o.time_limit is not None and time.perf_counter() - t0 > o.time_limit:
                    why = (f"NOT converged: time limit {o.time_limit:g} s reached at step "
                           f"{diag.step}; {why}")
                    break
        except FitInterrupted:
            raise
        except KeyboardInterrupt:
            raise self._interrupted(folder) from None
        finally:
            self.runner.close()
        refits = self.refit_evals - r0
        return Outcome(diag, ok, why, time.perf_counter() - t_s0,
                       self.logpost.n_evals - e0 - refits, refits)
