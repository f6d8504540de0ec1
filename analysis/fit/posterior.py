"""The posterior of a fit: the forward model at the table's pairs and log prior + likelihood.

Both are vectorized over a batch of parameter sets and safe to call from several threads at
once (numpy releases the GIL; the only shared state, the evaluation count, is locked).
"""

from __future__ import annotations

import copy
import threading
from typing import Callable

import numpy as np

from analysis.likelihood import Likelihood
from analysis.params import ParamSpec
from brdf.forward import Forward
from brdf.microcylinder import FabricForward

__all__ = ["FabricModel", "BaselineForward", "forward_model", "LogPosterior"]


#: The microcylinder's forward model (:class:`brdf.FabricForward`), by its former name.
FabricModel = FabricForward
#: A baseline's forward model (:class:`brdf.Forward`), by its former name.
BaselineForward = Forward


def forward_model(obj, wi, wo):
    """The forward model of a model object (a :class:`brdf.Model`) at pairs (wi, wo):
    ``obj.forward(wi, wo)``, called with :meth:`ParamSpec.model_kwargs`' arguments."""
    return obj.forward(wi, wo)


class _Count:
    """A count shared by threads (and by a posterior and its :meth:`~LogPosterior.with_model`
    copies)."""

    def __init__(self):
        self.n = 0
        self._lock = threading.Lock()

    def add(self, k: int):
        with self._lock:
            self.n += k


class LogPosterior:
    """log prior + log likelihood, vectorized: theta (B, ndim) -> (B,).

    Parameters
    ----------
    spec : ParamSpec
    likelihood : Likelihood
    model : callable
        ``model(**kwargs) -> (B, n, 3)`` f_r in 1/sr, kwargs as :meth:`ParamSpec.model_kwargs`
        (a model's ``forward``, :func:`forward_model`).
    """

    def __init__(self, spec: ParamSpec, likelihood: Likelihood, model: Callable):
        self.spec, self.lik, self.model = spec, likelihood, model
        self._count = _Count()
        names = set(spec.free) | set(spec.ties)
        self.use_scale = "scale" in names or spec.params["scale"].default != 1.0
        self.use_noise = "log_noise" in names

    @property
    def n_evals(self) -> int:
        """Parameter sets evaluated so far (those inside the prior's support)."""
        return self._count.n

    def with_model(self, model: Callable) -> "LogPosterior":
        """This posterior with another forward model (e.g. ``model.with_dtype(np.float32)``);
        its evaluations count in this one's :attr:`n_evals`."""
        other = copy.copy(self)                # shares the count, the spec, the likelihood
        other.model = model
        return other

    def predict(self, theta) -> np.ndarray:
        """Model f_r (B, n, 3) for internal theta (B, ndim), scale included."""
        theta = np.atleast_2d(np.asarray(theta, dtype=np.float64))
        return self._predict(self.spec.values(theta))

    def _predict(self, v, scaled: bool = True) -> np.ndarray:
        """Model f_r (B, n, 3) from the natural values ``v`` of :meth:`ParamSpec.values`
        (times ``scale`` unless ``scaled`` is False)."""
        kw = self.spec.model_kwargs(v)
        out = np.asarray(self.model(**kw), dtype=np.float64)
        if self.use_scale and scaled:
            out = out * v["scale"][:, None, None]
        return out

    def pointwise(self, theta, cdf: bool = False):
        """The log-likelihood of each used value of the table, for internal theta (B, ndim)
        inside the prior's support: (B, n_used), and with ``cdf`` each value's predictive
        CDF at the measured value (:meth:`analysis.likelihood.Likelihood.pointwise`).
        Their sum over values is the log-likelihood part of :meth:`__call__`."""
        theta = np.atleast_2d(np.asarray(theta, dtype=np.float64))
        v = self.spec.values(theta)
        with np.errstate(all="ignore"):
            pred = self._predict(v, scaled=False)          # the likelihood applies scale
            return self.lik.pointwise(pred, scale=v["scale"] if self.use_scale else None,
                                      log_noise=v["log_noise"] if self.use_noise else None,
                                      cdf=cdf)

    def __call__(self, theta) -> np.ndarray:
        theta = np.atleast_2d(np.asarray(theta, dtype=np.float64))
        lp = self.spec.log_prior(theta)
        ok = np.isfinite(lp)
        out = np.full(theta.shape[0], -np.inf)
        if np.any(ok):
            th = theta[ok]
            v = self.spec.values(th)
            with np.errstate(all="ignore"):
                pred = self._predict(v, scaled=False)      # the likelihood applies scale
                ll = self.lik(pred, scale=v["scale"] if self.use_scale else None,
                              log_noise=v["log_noise"] if self.use_noise else None)
            out[ok] = lp[ok] + ll
            self._count.add(int(ok.sum()))
        return out


