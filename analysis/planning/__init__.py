"""Measurement planning: which (wi, wo) pairs to measure, chosen for the free parameters.

:func:`plan` chooses N pairs by Bayesian D-optimality (the expected log determinant of the
posterior precision in the Laplace approximation, over draws of the parameters), greedily
with rank-r updates and one exchange pass; one part a module: candidates (the pairs to
choose from, uniform designs), draws (the local prior or a fit's posterior), information
(each pair's whitened Jacobian), select (greedy, exchange, the criterion), core (:func:`plan`
and :class:`Plan`), workflow (what ``microcyl plan`` does: the plan written as a pairs CSV).
"""

from analysis.lazy import lazy_getattr

#: Names loaded on first use, with their modules (:mod:`analysis.lazy`): the planner loads the
#: fit (emcee, scipy.stats; about 0.5 s), which ``microcyl export`` does not need when it
#: reads :mod:`~analysis.planning.draws` for a fit folder's posterior.
_LAZY = {name: f"analysis.planning.{module}" for module, names in {
    "candidates": ("DEFAULT_CANDIDATES", "candidates", "uniform_pairs"),
    "core": ("DEFAULT_DRAWS", "MAX_BUDGET", "Plan", "plan"), "draws": ("LOCAL_SD",),
}.items() for name in names}
__getattr__ = lazy_getattr(__name__, _LAZY, globals())

__all__ = ["plan", "Plan", "candidates", "uniform_pairs", "DEFAULT_CANDIDATES",
           "DEFAULT_DRAWS", "MAX_BUDGET", "LOCAL_SD"]
