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
from brdf.baselines import BaselineModel
from brdf.shading import shade_dtype

__all__ = ["FabricModel", "BaselineForward", "forward_model", "LogPosterior"]


class FabricModel:
    """Forward model of a fabric at fixed direction pairs, batched over parameters.

    Wraps ``fab.prepare(wi, wo)``; the call takes the keyword arguments of ``prep.eval``
    (each (B..., 2), albedo (B..., 2, 3)) and optionally ``tangent_scale`` (B..., 2), a factor
    on each thread's tangent offsets, and returns f_r (B..., n, 3) in 1/sr, float64. Scaled
    curves cannot be prepared once: that slow path rebuilds the fabric and its preparation
    for every batch row whose factors differ from 1.

    ``dtype`` is the precision of the shading (:meth:`brdf.Prepared.eval`): float64 by
    default; :meth:`with_dtype` gives the same model shading in float32, which the sampling
    of :func:`~analysis.fit.fit` uses.
    """

    def __init__(self, fab, wi, wo, dtype=np.float64):
        self.fab = fab
        self.wi = np.asarray(wi, dtype=np.float64)
        self.wo = np.asarray(wo, dtype=np.float64)
        self.prep = fab.prepare(self.wi, self.wo)
        self.dtype = shade_dtype(dtype)

    def with_dtype(self, dtype) -> "FabricModel":
        """The same model (sharing its preparation) shading in ``dtype``."""
        other = copy.copy(self)
        other.dtype = shade_dtype(dtype)
        return other

    def __call__(self, tangent_scale=None, **kw) -> np.ndarray:
        kw["dtype"] = self.dtype
        if tangent_scale is None or np.all(np.asarray(tangent_scale) == 1.0):
            return self.prep.eval(**kw)
        ts = np.asarray(tangent_scale, dtype=np.float64)
        batch = ts.shape[:-1]
        flat_kw = {k: np.asarray(v).reshape((-1,) + np.shape(v)[len(batch):])
                   for k, v in kw.items() if k != "dtype"}
        out = np.empty((int(np.prod(batch)), self.wi.shape[0], 3))
        ts = ts.reshape(-1, 2)
        for b in range(ts.shape[0]):
            threads = tuple(
                th.replace(offsets=tuple(np.clip(np.asarray(th.offsets) * ts[b, j], -90, 90)))
                for j, th in enumerate(self.fab.threads))
            prep = self.fab.replace(threads=threads).prepare(self.wi, self.wo)
            out[b] = prep.eval(dtype=self.dtype, **{k: v[b] for k, v in flat_kw.items()})
        return out.reshape(batch + out.shape[1:])


class BaselineForward:
    """Forward model of a baseline model (:class:`brdf.baselines.BaselineModel`) at fixed
    pairs: ``model.prepare(wi, wo)``, called with its batched keyword arguments (scalars
    (B...), RGB ones (B..., 3); :meth:`analysis.families.BaselineFamily.model_kwargs`) ->
    f_r (B..., n, 3) in 1/sr, float64 (baselines shade in float64 only, so it offers no
    ``with_dtype``)."""

    def __init__(self, model: BaselineModel, wi, wo):
        self.model = model
        self.wi = np.asarray(wi, dtype=np.float64)
        self.wo = np.asarray(wo, dtype=np.float64)
        self.prep = model.prepare(self.wi, self.wo)

    def __call__(self, **kw) -> np.ndarray:
        return self.prep.eval(**kw)


def forward_model(obj, wi, wo):
    """The forward model of a model object at pairs (wi, wo): a :class:`FabricModel` of a
    :class:`brdf.Fabric`, a :class:`BaselineForward` of a baseline model."""
    if isinstance(obj, BaselineModel):
        return BaselineForward(obj, wi, wo)
    return FabricModel(obj, wi, wo)


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
        (plus ``tangent_scale`` when a tangent scale is free or not 1).
    """

    def __init__(self, spec: ParamSpec, likelihood: Likelihood, model: Callable):
        self.spec, self.lik, self.model = spec, likelihood, model
        self._count = _Count()
        names = set(spec.free) | set(spec.ties)
        self.use_scale = "scale" in names or spec.params["scale"].default != 1.0
        self.use_noise = "log_noise" in names
        tangent = [f"tangent_scale{j}" for j in (1, 2) if f"tangent_scale{j}" in spec.params]
        self.use_tangent = bool(set(tangent) & names) or any(
            spec.params[n].default != 1.0 for n in tangent)

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
        if self.use_tangent:
            kw["tangent_scale"] = np.stack([v["tangent_scale1"], v["tangent_scale2"]], -1)
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


