"""A fit's progress: a bar whose total is the step count expected at convergence, or one
line a check on a pipe.

The total is re-estimated from tau at each check (:func:`analysis.fit.convergence.
expected_steps`), so the bar's ETA follows what the convergence rule will need rather than
``--max-steps``; to a pipe or a file (not a terminal) a fit writes one plain line a check
(:func:`check_line`), never carriage returns.
"""

from __future__ import annotations

import contextlib
import time

from analysis.budget import format_seconds
from analysis.fit.convergence import expected_steps, finite_max, finite_min
from gonio.progress import interactive, progress_bar, progress_line

__all__ = ["fit_progress", "check_line"]


@contextlib.contextmanager
def fit_progress(progress, opts, initial: int = 0):
    """(tick, postfix) callables for the sampler (``opts`` a resolved
    :class:`~analysis.fit.driver.FitOptions`): the caller's ``progress(steps)`` when it is
    callable, nothing when False; when True, a tqdm bar on a terminal, whose total is the
    step count expected at convergence (:func:`expected_steps`, re-estimated from tau at
    each check; unknown, with no ETA, before the first), and on a pipe or a file one line
    a check (:func:`check_line`) and no carriage returns."""
    if callable(progress):
        yield progress, None
        return
    if not progress:
        yield None, None
        return

    def expected(diag, ok):
        return expected_steps(diag, opts.criteria, opts.check_every, opts.max_steps, ok)

    if not interactive():
        # the start's estimate of a step (estimate_time: one batch timed, before any load)
        # is replaced by the time of the steps run so far, re-measured at each check
        t0 = time.perf_counter()

        def line(d, diag, ok):
            run = diag.step - initial
            per_step = (time.perf_counter() - t0) / run if run > 0 else None
            progress_line(check_line(diag, expected(diag, ok), opts.max_steps, ok,
                                     seconds_per_step=per_step))
        yield None, line
        return
    bar = progress_bar(None, desc="emcee", unit="step", initial=initial)

    def tick(steps):
        bar.n = steps
        bar.refresh()

    def postfix(d, diag, ok):
        bar.total = expected(diag, ok)
        bar.set_postfix(d, refresh=True)
    try:
        yield tick, postfix
    finally:
        bar.close()


def check_line(diag, total: int, max_steps: int, converged: bool = False,
               seconds_per_step: float | None = None) -> str:
    """One line of a fit's progress at a check (for a pipe or a log): the step, the largest
    tau, the smallest N/tau and the step count expected at convergence; with
    ``seconds_per_step`` (the time of the steps run so far, measured), the time a step took
    and the time left to that total at that pace.

    Examples
    --------
    >>> import numpy as np
    >>> from analysis.fit.convergence import Diagnosis
    >>> d = Diagnosis(step=100, burn=20, chains=None, log_prob=None, taus=None,
    ...               tau=np.array([4.0, 10.0]), rhat=np.array([1.2, 1.1]))
    >>> for part in check_line(d, 650, 20000).split(", "):
    ...     print(part)
    emcee: step 100
    tau 10.0 steps (largest)
    N/tau 8.0 (smallest)
    expected total 650 of at most 20000 steps
    >>> check_line(d, 650, 20000, seconds_per_step=0.026).split("(smallest), ")[1]
    'expected total 650 of at most 20000 steps; 0.026 s a step (measured), about 14 s left'
    """
    end = ("converged" if converged
           else f"expected total {total} of at most {max_steps} steps")
    if seconds_per_step is not None:
        step = (format_seconds(seconds_per_step) if seconds_per_step >= 1
                else f"{seconds_per_step:.2g} s")
        end += f"; {step} a step (measured)"
        if not converged:
            end += f", about {format_seconds(seconds_per_step * max(0, total - diag.step))} left"
    return (f"emcee: step {diag.step}, tau {finite_max(diag.tau):.1f} steps (largest), "
            f"N/tau {finite_min(diag.ratio):.1f} (smallest), {end}")
