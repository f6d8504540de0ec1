"""What "a BRDF" and "a model" mean to the rest of microcyl, as typing Protocols (no
inheritance needed).

Checks made with ``isinstance(obj, BRDF)`` replace ``hasattr`` probes: a measured file
(:class:`gonio.MerlBRDF`, :class:`gonio.RGLBRDF`), a :class:`brdf.Fabric` or a user's own
object all qualify by having the methods. :class:`Model` is what every entry of
:data:`brdf.MODELS` is: a BRDF with sampling, a flat parameter vector and a batched forward
model, all a fit, a comparison or a report asks of a model.
"""

from __future__ import annotations

from typing import ClassVar, Mapping, Protocol, runtime_checkable

import numpy as np

__all__ = ["BRDF", "ThreadedBRDF", "SampledBRDF", "Model"]


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


@runtime_checkable
class Model(SampledBRDF, Protocol):
    """A model of the registry :data:`brdf.MODELS` (a class; its instances are models).

    Class level: ``reciprocal`` (whether f_r(wi, wo) = f_r(wo, wi) for every pair);
    ``param_schema()``, the flat parameters (:class:`brdf.paramschema.ParamSchema`: names,
    units, search ranges, defaults, which are colour channels); ``start(preset, options)``,
    the model a fit starts from (``PRESETS`` the presets it takes, none for most);
    ``batch_kwargs(values)``, the keyword arguments of ``prepare(wi, wo).eval`` from flat
    values (B...); a fit's defaults ``DEFAULT_FREE`` (None: every parameter) and
    ``DEFAULT_TIES``, and ``BASE_PARAM`` (the colour that carries the level of f_r, or None);
    ``admissible(values)``, whether values in range make a model together (B...) bool, for
    the parameters ``CONSTRAINED`` together (a fabric's two areas; none for most).

    Instance level: ``eval``, ``sample``, ``pdf`` (:class:`SampledBRDF`); ``values()``
    (every flat parameter by name), ``with_values(values)`` (a copy with some changed);
    ``prepare(wi, wo)`` (fixed pairs; ``.eval(**kw)`` f_r (B..., n, 3) in 1/sr for a batch
    of parameter sets) and ``forward(wi, wo)`` (a fit's forward model: called with
    ``batch_kwargs``' arguments).

    Examples
    --------
    >>> import brdf
    >>> all(isinstance(cls.start(), Model) for cls in brdf.MODELS.values())
    True
    >>> isinstance(brdf.fabric("velvet"), Model), isinstance(object(), Model)
    (True, False)
    """

    reciprocal: ClassVar[bool]
    DEFAULT_FREE: ClassVar[tuple[str, ...] | None]
    DEFAULT_TIES: ClassVar[tuple[str, ...]]
    BASE_PARAM: ClassVar[str | None]
    PRESETS: ClassVar[tuple[str, ...]]
    CONSTRAINED: ClassVar[tuple[str, ...]]

    @classmethod
    def param_schema(cls):
        """The flat parameters (a :class:`brdf.paramschema.ParamSchema`)."""

    @classmethod
    def start(cls, preset=None, options=None) -> "Model":
        """The model a fit starts from."""

    @classmethod
    def admissible(cls, values: Mapping[str, np.ndarray]) -> np.ndarray:
        """Whether each set of flat values (B...) makes a model together."""

    @classmethod
    def batch_kwargs(cls, values: Mapping[str, np.ndarray]) -> dict:
        """``prepare(...).eval``'s keyword arguments from flat values (B...)."""

    def values(self) -> dict:
        """Every flat parameter's value by name (natural units)."""

    def with_values(self, values: Mapping[str, float]) -> "Model":
        """A copy with some flat parameters changed (validated)."""

    def prepare(self, wi, wo):
        """Fixed pairs, shaded for batches of parameter sets (``.eval(**kw)``)."""

    def forward(self, wi, wo):
        """The forward model at fixed pairs: ``(**batch_kwargs) -> f_r (B..., n, 3)``."""
