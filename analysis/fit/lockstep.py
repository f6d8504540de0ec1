"""Lock-step batching: the log-probability calls of several ensembles as one evaluation."""

from __future__ import annotations

import concurrent.futures as cf
import threading
from typing import Callable

import numpy as np

__all__ = ["LockStep", "Aborted"]


class Aborted(Exception):
    """Raised in an ensemble thread whose pending evaluation was abandoned (interrupt)."""


class LockStep:
    """Stack the log-probability calls of several ensembles into one batched evaluation.

    Each ensemble runs in its own thread and calls :meth:`call`; when every active ensemble
    has a pending request, their walkers are concatenated, evaluated in ``threads`` chunks
    (numpy releases the GIL), and the results handed back. An ensemble that finishes calls
    :meth:`leave`; :meth:`abort` makes every waiting call raise (for interrupts).
    """

    def __init__(self, fn: Callable, n: int, threads: int = 1):
        self.fn, self.active = fn, n
        self.cond = threading.Condition()
        self.pending: dict[int, np.ndarray] = {}
        self.results: dict[int, np.ndarray] = {}
        self.generation = 0
        self.aborted = False
        self.error: BaseException | None = None
        self.pool = cf.ThreadPoolExecutor(threads) if threads > 1 else None
        self.threads = threads

    def _evaluate(self, x: np.ndarray) -> np.ndarray:
        if self.pool is None or x.shape[0] < 2 * self.threads:
            return self.fn(x)
        parts = np.array_split(x, self.threads)
        return np.concatenate(list(self.pool.map(self.fn, parts)))

    def _flush(self):
        keys = sorted(self.pending)
        xs = [self.pending[k] for k in keys]
        try:
            out = self._evaluate(np.concatenate(xs))
        except BaseException as exc:  # hand the error to every waiter
            self.error = exc
            out = None
        i = 0
        for k, x in zip(keys, xs):
            self.results[k] = None if out is None else out[i:i + len(x)]
            i += len(x)
        self.pending.clear()
        self.generation += 1
        self.cond.notify_all()

    def call(self, k: int, x: np.ndarray) -> np.ndarray:
        """Log-probabilities of ensemble ``k``'s rows ``x``, evaluated with the others'."""
        with self.cond:
            if self.aborted:
                raise Aborted()
            self.pending[k] = np.asarray(x, dtype=np.float64)
            gen = self.generation
            if len(self.pending) >= self.active:
                self._flush()
            else:
                while self.generation == gen and not self.aborted:
                    self.cond.wait()
            if self.aborted:
                raise Aborted()
            res = self.results.pop(k)
            if res is None:
                raise RuntimeError(f"model evaluation failed: {self.error!r}") from self.error
            return res

    def leave(self):
        """An ensemble is done: flush the others' requests if they were waiting for it."""
        with self.cond:
            self.active -= 1
            if self.pending and len(self.pending) >= self.active:
                self._flush()

    def reset(self, n: int):
        """Start a new run with ``n`` active ensembles (after :meth:`leave` or :meth:`abort`)."""
        with self.cond:
            self.active, self.aborted, self.error = n, False, None
            self.pending.clear()
            self.results.clear()

    def abort(self):
        """Make every waiting and every later :meth:`call` raise :class:`Aborted`."""
        with self.cond:
            self.aborted = True
            self.cond.notify_all()

    def close(self):
        """Shut the evaluation pool down."""
        if self.pool is not None:
            self.pool.shutdown(wait=True)


