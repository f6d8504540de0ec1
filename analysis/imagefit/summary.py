"""The free parameters of an image fit: flat coordinates, summaries and warnings.

A parameter's flat coordinate is its value, or the value's logarithm for a log-uniform prior
(``gamma_s1``, ``gamma_v1``, ...): where the prior is flat. The Laplace approximation is a
Gaussian there, so a log-uniform parameter's intervals are asymmetric in its value. The
warnings are those of ``microcyl fit`` (:mod:`analysis.fit.trust`) computed from that
Gaussian: ``not_informed`` (posterior sd above :data:`analysis.fit.trust.SD_RATIO` of the
prior's, both flat), ``at_bound`` (the 95% interval reaches into the outer
:data:`analysis.fit.trust.BOUND_ZONE` of the range), ``correlated`` (|corr| above
:data:`analysis.fit.trust.CORR_MAX`); and ``noise_scaled`` (the residuals are wider than the
noise model says and the intervals were widened by that factor), ``not_converged``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from analysis.fit.trust import BOUND_ZONE, CORR_MAX, SD_RATIO, warning
from analysis.paramnames import entry

__all__ = ["Params", "summaries", "warnings_of", "Z68", "Z95"]

#: Normal quantiles of the central 68% and 95% intervals.
Z68, Z95 = 0.9944578832097535, 1.959963984540054


@dataclasses.dataclass(frozen=True)
class Params:
    """The free parameters: ``names``, natural bounds ``lo``/``hi``, whether each is
    log-uniform (``log``), and ``units``.

    Examples
    --------
    >>> p = Params.of(["kd1", "gamma_s1"])
    >>> p.log.tolist(), np.round(p.to_flat([0.3, 10.0]), 4).tolist()
    ([False, True], [0.3, 2.3026])
    >>> p.to_natural(p.to_flat([0.3, 10.0])).tolist()
    [0.3, 10.0]
    """

    names: tuple
    lo: np.ndarray
    hi: np.ndarray
    log: np.ndarray
    units: tuple

    @classmethod
    def of(cls, names) -> "Params":
        rows = [entry(n) for n in names]
        return cls(tuple(names), np.array([r[0] for r in rows], float),
                   np.array([r[1] for r in rows], float),
                   np.array([r[2] == "log-uniform" for r in rows]),
                   tuple(r[3] for r in rows))

    def to_flat(self, x) -> np.ndarray:
        x = np.asarray(x, float)
        return np.where(self.log, np.log(np.maximum(x, 1e-300)), x)

    def to_natural(self, u) -> np.ndarray:
        u = np.asarray(u, float)
        return np.where(self.log, np.exp(u), u)

    @property
    def flat_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self.to_flat(self.lo), self.to_flat(self.hi)

    @property
    def prior_sd(self) -> np.ndarray:
        """The sd of each flat prior in flat coordinates: range / sqrt(12)."""
        lo, hi = self.flat_bounds
        return (hi - lo) / math.sqrt(12.0)


def summaries(params: Params, u, cov, start) -> dict:
    """Each parameter's ``median``, ``lo68``/``hi68``/``lo95``/``hi95`` (the Gaussian's in
    flat coordinates mapped back, clipped to the bounds), ``sd`` (flat coordinates),
    ``start`` and ``unit``."""
    sd = np.sqrt(np.diag(cov))
    lo, hi = params.flat_bounds
    out = {}
    for i, name in enumerate(params.names):
        def at(z, i=i):
            v = float(np.clip(u[i] + z * sd[i], lo[i], hi[i]))
            return math.exp(v) if params.log[i] else v
        out[name] = {"median": at(0.0), "lo68": at(-Z68), "hi68": at(Z68),
                     "lo95": at(-Z95), "hi95": at(Z95), "sd_flat": float(sd[i]),
                     "flat": "log" if params.log[i] else "value", "start": float(start[i]),
                     "unit": params.units[i]}
    return out


def warnings_of(params: Params, u, cov, *, scale: float, converged: bool,
                reason: str) -> list[dict]:
    """The warnings of the module notes, each ``{"kind", "parameters", "message"}``."""
    out = []
    sd, prior = np.sqrt(np.diag(cov)), params.prior_sd
    lo, hi = params.flat_bounds
    for i, name in enumerate(params.names):
        where = " of its logarithm" if params.log[i] else ""
        ratio = sd[i] / prior[i]
        if ratio > SD_RATIO:
            out.append(warning("not_informed", [name], (
                f"{name}: posterior sd{where} {sd[i]:.3g} is {ratio:.2f} x the prior's "
                f"{prior[i]:.3g} (above {SD_RATIO:g}): the images hardly inform it; its "
                f"interval mostly restates the prior range")))
        zone = BOUND_ZONE * (hi[i] - lo[i])
        if u[i] - Z95 * sd[i] < lo[i] + zone or u[i] + Z95 * sd[i] > hi[i] - zone:
            out.append(warning("at_bound", [name], (
                f"{name}: the 95% interval reaches the outer {100 * BOUND_ZONE:g}% of the "
                f"range [{params.lo[i]:.4g}, {params.hi[i]:.4g}]: the bound, not the "
                f"images, shapes that end")))
    corr = cov / np.outer(sd, sd)
    for i in range(len(sd)):
        for j in range(i + 1, len(sd)):
            if abs(corr[i, j]) > CORR_MAX:
                a, b = params.names[i], params.names[j]
                out.append(warning("correlated", [a, b], (
                    f"{a} and {b}: correlation {corr[i, j]:+.3f} (|corr| above {CORR_MAX:g}): "
                    f"the images fix a combination of the two, not each")))
    if scale > 1.5:
        out.append(warning("noise_scaled", list(params.names), (
            f"the residuals' variance is {scale:.3g} x the noise model's (chi2 per degree "
            f"of freedom): the intervals were widened by sqrt({scale:.3g}) = "
            f"{math.sqrt(scale):.3g}; give the camera's --shot-noise/--read-noise, or the "
            f"model misses something in the images")))
    if not converged:
        out.append(warning("not_converged", list(params.names), reason))
    return out
