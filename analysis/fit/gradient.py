"""The gradient of a fit's log-posterior in the sampler's internal coordinates.

The model's derivatives come from the compiled kernel's automatic differentiation
(:meth:`brdf.Prepared.eval_and_grad`, forward mode) where the forward model offers it (a
:class:`brdf.FabricForward`, whose ``prep`` is a :class:`brdf.Prepared`); the rest of the chain
rule is cheap and done here:

- internal coordinates -> model keyword arguments (logit transforms, ties): central
  differences of :meth:`analysis.params.ParamSpec.model_kwargs`, which evaluates no model;
- model f_r -> log-likelihood: central differences of the likelihood along each parameter's
  tangent of f_r (one batched likelihood call, no model evaluation), so every likelihood kind,
  ``scale`` and ``log_noise`` included, is covered without a second derivation of it;
- the log prior: its closed form, -tanh(theta / 2) per internal coordinate.

A parameter the kernel does not differentiate (``rotation``, the tangent scales) gets a
forward difference of the model, all of them in one batched evaluation. A model without
``prep.eval_and_grad`` (the baselines), or a point where the kernel's fast path does not apply,
has no analytic gradient: :func:`gradient_available` says so and callers keep the
finite-difference gradient.
"""

from __future__ import annotations

import numpy as np

from brdf import jit
from brdf.prepared import GRAD_PARAMS

__all__ = ["gradient_available", "logpost_and_grad", "rotation_cache"]

#: Step (internal units) of the central differences of the cheap parts of the chain.
_H = 1e-6
#: Step of the likelihood's directional differences (in units of the tangent).
_EPS = 1e-5


def _eval_and_grad(model):
    """The model's ``prep.eval_and_grad`` (its kernel's AD), or None."""
    prep = getattr(model, "prep", None)
    return getattr(prep, "eval_and_grad", None)


def gradient_available(logpost) -> bool:
    """True when ``logpost``'s forward model gives analytic derivatives (a microcylinder's
    :class:`brdf.FabricForward` with Dr.Jit running).

    Examples
    --------
    >>> gradient_available(type("P", (), {"model": staticmethod(lambda **kw: None)})())
    False
    """
    if _eval_and_grad(logpost.model) is None:
        return False
    return bool(jit.available()[0])


class _Rotated:
    """The model's preparation, or one of its fabric rotated to ``kw``'s rotation (the
    last one kept), or None where the tangent scales differ from 1 (no kernel there)."""

    def __init__(self, model):
        self.model, self.key, self.prep = model, None, None

    def __call__(self, kw):
        model = self.model
        ts, rot = kw.get("tangent_scale"), kw.get("rotation")
        if ts is not None and not np.all(np.asarray(ts) == 1.0):
            return None
        fab = getattr(model, "fab", None)
        rot0 = 0.0 if fab is None else float(np.degrees(fab.options["rotation"]))
        if rot is None or float(np.asarray(rot).reshape(-1)[0]) == rot0:
            return model.prep
        if fab is None:
            return None
        r = float(np.asarray(rot).reshape(-1)[0])
        if self.key != r:
            self.key = r
            self.prep = fab.replace(rotation=float(np.radians(r))).prepare(model.wi, model.wo)
        return self.prep


def rotation_cache(logpost):
    """A cache of the model's preparations at the last rotation asked for (pass it to
    :func:`logpost_and_grad`; one a thread)."""
    return _Rotated(logpost.model)


def _tangents(logpost, x, kw0, prep):
    """The model's f_r at x (n, 3) and its derivative by each internal coordinate
    (ndim, n, 3), with the natural values' derivatives (dict name -> (ndim,))."""
    spec, model = logpost.spec, logpost.model
    d = x.size
    pts = np.repeat(x[None], 2 * d, axis=0)
    pts[2 * np.arange(d), np.arange(d)] += _H
    pts[2 * np.arange(d) + 1, np.arange(d)] -= _H
    v = spec.values(pts)
    kw = spec.model_kwargs(v)
    dkw = {k: (np.asarray(a)[0::2] - np.asarray(a)[1::2]) / (2 * _H) for k, a in kw.items()}
    dv = {k: (a[0::2] - a[1::2]) / (2 * _H) for k, a in v.items()}
    f0, grads = prep.eval_and_grad(**{k: kw0[k][0] for k in GRAD_PARAMS if k in kw0})
    t = np.zeros((d,) + f0.shape)
    for name, g in grads.items():                 # g (n, 3, 2)
        if name not in dkw:
            continue
        dk = dkw[name]                            # (d, 2) or albedo (d, 2, 3)
        if name == "albedo":
            t += np.einsum("ncj,kjc->knc", g, dk)
        else:
            t += np.einsum("ncj,kj->knc", g, dk)
    other = [k for k in dkw if k not in GRAD_PARAMS]
    cols = [i for i in range(d) if any(np.any(dkw[k][i] != 0) for k in other)]
    if cols:                                      # rotation, tangent scales: the model's FD
        h = np.where(x[cols] + _H <= spec.upper[cols], _H, -_H)
        fd = np.repeat(x[None], len(cols), axis=0)
        fd[np.arange(len(cols)), cols] += h
        kwf = spec.model_kwargs(spec.values(fd))
        f1 = np.asarray(model(**kwf), dtype=np.float64)
        t[cols] = (f1 - f0[None]) / h[:, None, None]
    return f0, t, dv


def logpost_and_grad(logpost, x, rotated=None) -> tuple[float, np.ndarray] | None:
    """The log-posterior at internal coordinates ``x`` (ndim,) and its gradient there.

    Parameters
    ----------
    logpost : analysis.fit.posterior.LogPosterior
    x : ndarray, shape (ndim,)
    rotated : optional
        The cache of rotated preparations of :func:`rotation_cache` (one a thread), so that
        steps of the same rotation prepare the pairs once.

    Returns
    -------
    (float, ndarray (ndim,)) or None
        ``(-inf, zeros)`` outside the prior's support; None where the model gives no
        analytic derivatives here (see :func:`gradient_available`; the caller falls back to
        finite differences).
    """
    spec = logpost.spec
    x = np.asarray(x, dtype=np.float64)
    lp = float(spec.log_prior(x[None])[0])
    if not np.isfinite(lp):
        return -np.inf, np.zeros_like(x)
    v0 = spec.values(x[None])
    kw0 = spec.model_kwargs(v0)
    if _eval_and_grad(logpost.model) is None:
        return None
    rotated = rotated or _Rotated(logpost.model)
    prep = rotated(kw0)
    if prep is None:
        return None
    with np.errstate(all="ignore"):
        f0, t, dv = _tangents(logpost, x, kw0, prep)
        d = x.size
        # the likelihood at f0 and along +-eps of each tangent: one batch of 2d + 1
        sgn = np.concatenate([[0.0], np.tile([1.0, -1.0], d)])
        k = np.concatenate([[0], np.repeat(np.arange(d), 2)])
        preds = f0[None] + (_EPS * sgn)[:, None, None] * t[k]
        kwl = {}
        for name, use in (("scale", logpost.use_scale), ("log_noise", logpost.use_noise)):
            if use:
                kwl[name] = v0[name][0] + _EPS * sgn * dv[name][k]
        ll = logpost.lik(preds, **kwl)
    if not np.isfinite(ll[0]):
        return -np.inf, np.zeros_like(x)
    g = (ll[1::2] - ll[2::2]) / (2 * _EPS) - np.tanh(0.5 * x)
    if not np.all(np.isfinite(g)):
        return None
    return lp + float(ll[0]), g
