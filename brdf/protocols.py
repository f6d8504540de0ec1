"""What "a BRDF" means to the rest of microcyl, as typing Protocols (no inheritance needed).

Checks made with ``isinstance(obj, BRDF)`` replace ``hasattr`` probes: a measured file
(:class:`gonio.MerlBRDF`, :class:`gonio.RGLBRDF`), a :class:`brdf.Fabric` or a user's own
object all qualify by having the methods.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

__all__ = ["BRDF", "ThreadedBRDF"]


@runtime_checkable
class BRDF(Protocol):
    """Anything with ``eval(wi, wo) -> f_r``: directions (..., 3), RGB f_r (..., 3) in 1/sr.

    Examples
    --------
    >>> import brdf
    >>> isinstance(brdf.fabric("velvet"), BRDF), isinstance(object(), BRDF)
    (True, False)
    """

    def eval(self, wi, wo) -> np.ndarray:
        """RGB f_r in 1/sr (no cosine) of direction pairs."""


@runtime_checkable
class ThreadedBRDF(BRDF, Protocol):
    """A BRDF that also gives each thread's share: ``eval_threads(wi, wo)`` (..., 2, 3), 1/sr."""

    def eval_threads(self, wi, wo) -> np.ndarray:
        """Per-thread RGB f_r in 1/sr, threads on the second-to-last axis."""
