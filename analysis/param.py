"""One scalar fit parameter and its internal (logit) coordinate (:class:`Param`), the unit
:class:`analysis.params.ParamSpec` is made of; the transform is described there."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from analysis.lazy import special

__all__ = ["Param", "INTERNAL_LIMIT", "INTERNAL_WIDTH"]


#: Internal (logit) coordinates are limited to [-INTERNAL_LIMIT, INTERNAL_LIMIT].
INTERNAL_LIMIT = 40.0
#: A typical internal scale: a logit range of 4 spans p from 0.12 to 0.88.
INTERNAL_WIDTH = 4.0


@dataclasses.dataclass(frozen=True)
class Param:
    """One scalar parameter: bounds (natural units), prior, unit, default.

    Parameters
    ----------
    name : str
        Full name, e.g. ``"gamma_s1"``.
    lo, hi : float
        Bounds in natural units (``lo < hi``; ``lo > 0`` for a log-uniform prior).
    prior : {"uniform", "log-uniform"}
        Flat in the value, or flat in its logarithm.
    unit : str
        Unit of the value (``"deg"``, ``"1"``, ...).
    default : float
        Starting / fixed value in natural units.
    """

    name: str
    lo: float
    hi: float
    prior: str
    unit: str
    default: float

    def __post_init__(self):
        if self.prior not in ("uniform", "log-uniform"):
            raise ValueError(f"prior of {self.name} must be 'uniform' or 'log-uniform'; "
                             f"got {self.prior!r}")
        if not (math.isfinite(self.lo) and math.isfinite(self.hi) and self.lo < self.hi):
            raise ValueError(f"bounds of {self.name} must be finite with lo < hi; "
                             f"got ({self.lo}, {self.hi})")
        if self.prior == "log-uniform" and self.lo <= 0:
            raise ValueError(f"log-uniform prior of {self.name} needs lo > 0; got {self.lo}")

    @property
    def is_log(self) -> bool:
        return self.prior == "log-uniform"

    def _g(self, x):
        if self.is_log:
            with np.errstate(divide="ignore", invalid="ignore"):
                return np.log(x)
        return x

    def to_internal(self, x):
        """Natural value -> internal coordinate logit(p), p the position within the bounds
        (on a log scale for log-uniform); +-inf at the bounds, NaN outside.

        Examples
        --------
        >>> p = Param("kd1", 0.0, 1.0, "uniform", "1", 0.5)
        >>> float(p.to_internal(0.5)), round(float(p.to_natural(p.to_internal(0.9))), 12)
        (0.0, 0.9)
        """
        x = np.asarray(x, dtype=np.float64)
        g0, g1 = self._g(self.lo), self._g(self.hi)
        q = (self._g(x) - g0) / (g1 - g0)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where((q >= 0) & (q <= 1), np.log(q) - np.log1p(-q), np.nan)

    @property
    def scale_bounds(self) -> tuple[float, float]:
        """The bounds on the scale the internal coordinate maps linearly onto: (lo, hi), or
        their logarithms for a log-uniform prior (what :meth:`to_natural` interpolates).

        >>> Param("g", 1.0, 100.0, "log-uniform", "deg", 10.0).scale_bounds
        (0.0, 4.605170185988092)
        """
        return float(self._g(self.lo)), float(self._g(self.hi))

    def to_natural(self, u):
        """Internal coordinate -> natural value (within the bounds)."""
        u = np.asarray(u, dtype=np.float64)
        q = special.expit(u)
        g0, g1 = self.scale_bounds
        v = g0 + q * (g1 - g0)
        x = np.exp(v) if self.is_log else v
        return np.clip(x, self.lo, self.hi)

    @property
    def internal_bounds(self) -> tuple[float, float]:
        return (-INTERNAL_LIMIT, INTERNAL_LIMIT)
