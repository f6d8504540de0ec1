"""Measurement planning: which (wi, wo) pairs to measure, chosen for the free parameters.

:func:`plan` chooses N pairs by Bayesian D-optimality (the expected log determinant of the
posterior precision in the Laplace approximation, over draws of the parameters), greedily
with rank-r updates and one exchange pass; one part a module: candidates (the pairs to
choose from, uniform designs), draws (the local prior or a fit's posterior), information
(each pair's whitened Jacobian), select (greedy, exchange, the criterion), core (:func:`plan`
and :class:`Plan`), workflow (what ``microcyl plan`` does: the plan written as a pairs CSV).
"""

from analysis.planning.candidates import DEFAULT_CANDIDATES, candidates, uniform_pairs
from analysis.planning.core import DEFAULT_DRAWS, MAX_BUDGET, Plan, plan
from analysis.planning.draws import LOCAL_SD

__all__ = ["plan", "Plan", "candidates", "uniform_pairs", "DEFAULT_CANDIDATES",
           "DEFAULT_DRAWS", "MAX_BUDGET", "LOCAL_SD"]
