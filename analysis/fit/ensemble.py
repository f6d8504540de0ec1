"""The ensembles of a fit and the runner that advances them together.

A :class:`Chain` is one emcee ensemble: its walkers, its moves (an
:class:`~analysis.fit.moves.EnsembleMoves`), its random state and every step so far, kept in
memory. :class:`EnsembleRunner` advances several chains to a target step, one thread each,
their log-probability calls stacked by a :class:`~analysis.fit.lockstep.LockStep` into one
batched evaluation per round.

Threading rule: an ensemble thread only computes and appends to its own chain. Its step count
(:attr:`Chain.steps`, an int written by that thread alone, last in each step) is what the
calling thread reads for progress. No file is touched here.
"""

from __future__ import annotations

import concurrent.futures as cf
from typing import Callable, Sequence

import emcee
import numpy as np

from analysis.fit.lockstep import Aborted, LockStep

__all__ = ["Chain", "EnsembleRunner"]


class Chain:
    """One ensemble of walkers, advanced with emcee's moves through the public Move interface.

    Parameters
    ----------
    moves : emcee.moves.Move
        Proposes one step for all walkers (``propose(model, state)``).
    random : numpy.random.RandomState
        The ensemble's random state (emcee's moves use the legacy interface).
    coords : ndarray (walkers, ndim)
        Starting positions, internal coordinates.
    log_prob : ndarray (walkers,)
        Their log-posterior.

    Attributes
    ----------
    steps : int
        Steps taken so far.
    accepted : ndarray (walkers,)
        Accepted proposals per walker.
    log_prob_fn : callable
        Vectorized log-posterior (n, ndim) -> (n,) used for the proposals; set by the runner.
    """

    def __init__(self, moves, random: np.random.RandomState, coords, log_prob):
        self.moves, self.random = moves, random
        self.state = emcee.State(np.array(coords, dtype=np.float64),
                                 log_prob=np.array(log_prob, dtype=np.float64))
        w, d = self.state.coords.shape
        self._chain = np.empty((64, w, d))
        self._log_prob = np.empty((64, w))
        self.accepted = np.zeros(w)
        self.rng_state = random.get_state()
        self.log_prob_fn: Callable | None = None
        self.steps = 0

    @classmethod
    def restore(cls, moves, random, chain, log_prob, accepted, rng_state) -> "Chain":
        """A chain continuing after the stored steps ``chain`` (n, w, d), ``log_prob`` (n, w)."""
        self = cls(moves, random, chain[-1], log_prob[-1])
        n = chain.shape[0]
        self._grow(n)
        self._chain[:n], self._log_prob[:n] = chain, log_prob
        self.accepted = np.array(accepted, dtype=np.float64)
        self.random.set_state(rng_state)
        self.rng_state = self.random.get_state()
        self.steps = n
        return self

    def _compute(self, coords):
        return np.asarray(self.log_prob_fn(coords), dtype=np.float64), None

    def _grow(self, n: int):
        if n > self._chain.shape[0]:
            cap = max(n, 2 * self._chain.shape[0])
            for name in ("_chain", "_log_prob"):
                old = getattr(self, name)
                new = np.empty((cap,) + old.shape[1:])
                new[:self.steps] = old[:self.steps]
                setattr(self, name, new)

    def step(self):
        """One step of every walker (the ensemble's random state picks the move)."""
        model = emcee.model.Model(None, self._compute, map, self.random)
        state, accepted = self.moves.propose(model, self.state)
        self._grow(self.steps + 1)
        self._chain[self.steps] = state.coords
        self._log_prob[self.steps] = state.log_prob
        self.accepted += accepted
        self.state = emcee.State(state.coords, log_prob=state.log_prob)
        self.rng_state = self.random.get_state()
        self.steps += 1                   # last: the count the progress reader sees

    def run(self, target: int):
        """Step until ``steps == target``."""
        while self.steps < target:
            self.step()

    def chain(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Steps ``start`` to ``stop`` (default all): (n, walkers, ndim), a view."""
        stop = self.steps if stop is None else min(stop, self.steps)
        return self._chain[start:stop]

    def log_prob(self, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Log-posterior of steps ``start`` to ``stop``: (n, walkers), a view."""
        stop = self.steps if stop is None else min(stop, self.steps)
        return self._log_prob[start:stop]

    @property
    def acceptance_fraction(self) -> np.ndarray:
        """Accepted fraction of proposals per walker."""
        return self.accepted / max(self.steps, 1)


class EnsembleRunner:
    """Advance several chains to a step, in lock-step threads with batched evaluations.

    Parameters
    ----------
    chains : sequence of Chain
    log_prob : callable
        Vectorized log-posterior (n, ndim) -> (n,), thread-safe.
    threads : int
        Worker threads that share each batched evaluation.
    """

    def __init__(self, chains: Sequence[Chain], log_prob: Callable, threads: int = 1):
        self.chains = list(chains)
        self.lock = LockStep(log_prob, len(self.chains), threads=threads)
        for k, c in enumerate(self.chains):
            c.log_prob_fn = (lambda x, k=k: self.lock.call(k, x))

    @property
    def steps(self) -> int:
        """Steps every chain has completed (read from memory, safe at any time)."""
        return min(c.steps for c in self.chains)

    def _job(self, chain: Chain, target: int):
        try:
            chain.run(target)
        finally:
            self.lock.leave()

    def run_to(self, target: int, tick: Callable[[int], None] | None = None,
               poll: float = 0.25):
        """Advance every chain to ``target`` steps.

        ``tick(steps)`` is called from this thread about every ``poll`` seconds with
        :attr:`steps`. A KeyboardInterrupt abandons the steps in flight (each chain keeps its
        completed steps and the random state after them) and is re-raised.
        """
        jobs = [c for c in self.chains if c.steps < target]
        self.lock.reset(len(jobs))
        futs: list[cf.Future] = []
        with cf.ThreadPoolExecutor(max(1, len(jobs))) as ex:
            try:
                # submitted inside the try: a Ctrl-C while a job's thread starts must abort
                # the jobs already started (they would wait for the others forever)
                for c in jobs:
                    futs.append(ex.submit(self._job, c, target))
                while cf.wait(futs, timeout=poll)[1]:
                    if tick is not None:
                        tick(self.steps)
            except BaseException:
                self.lock.abort()
                cf.wait(futs)
                raise
        if tick is not None:
            tick(self.steps)
        for f in futs:
            exc = f.exception()
            if exc is not None and not isinstance(exc, Aborted):
                raise exc

    def close(self):
        """Stop the evaluation threads."""
        self.lock.close()
