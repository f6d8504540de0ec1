"""What "a BRDF" means to the rest of microcyl, as typing Protocols (no inheritance needed).

Checks made with ``isinstance(obj, BRDF)`` replace ``hasattr`` probes: a measured file
(:class:`gonio.MerlBRDF`, :class:`gonio.RGLBRDF`), a :class:`brdf.Fabric` or a user's own
object all qualify by having the methods.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

__all__ = ["BRDF", "ThreadedBRDF", "SampledBRDF"]


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


@runtime_checkable
class SampledBRDF(BRDF, Protocol):
    """A BRDF with importance sampling: ``sample(wo, u) -> (wi, weight, pdf)`` and
    ``pdf(wo, wi)`` in 1/sr (as :meth:`brdf.Fabric.sample` and :meth:`brdf.Fabric.pdf`).

    Examples
    --------
    >>> import brdf
    >>> isinstance(brdf.fabric("velvet"), SampledBRDF)
    True
    """

    def sample(self, wo, u):
        """Directions toward the light, ``f_r cos / pdf`` (RGB) and the pdf (1/sr)."""

    def pdf(self, wo, wi) -> np.ndarray:
        """Density (1/sr) of ``sample``'s directions."""
