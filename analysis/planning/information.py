r"""The information one measured pair holds about the free parameters, per draw.

The likelihood of a fit (:mod:`analysis.likelihood`, Gaussian) compares the table and the
model in the residual space :math:`y = \log(1 + f_r \cos\theta_i)`, with the table's sigma
carried there by the delta method, :math:`s = \cos\theta_i\,\sigma / (1 + f_r\cos\theta_i)`.
A table measured by an instrument of noise model :math:`\sigma(f_r)`
(:meth:`gonio.Instrument.sigma`) holds, about the free parameters u (internal coordinates),
the Fisher information

.. math::

    I(u) = \sum_{\text{pairs } p} \sum_{c} \frac{\nabla_u \mu_{pc}\, \nabla_u \mu_{pc}^T}
           {s_{pc}^2} = \sum_p \tilde J_p^T \tilde J_p,
    \qquad \tilde J_{p,c\cdot} = \nabla_u \mu_{pc} / s_{pc},

with :math:`\mu_{pc}` the model's prediction in the residual space at pair p, channel c (R, G,
B: three rows a pair; one row, the channels' mean, for a grey instrument, as the likelihood
counts a grey table) and s evaluated at the model's value. It is the term of
:func:`analysis.fit.fisher.fisher_information` for a table with sigma (whose sigma the
likelihood takes as known, so the variance term is absent). :func:`whitened_jacobians` gives
:math:`\tilde J_p` (r x d) of every candidate pair at every draw of the parameters: 2d + 1
batched evaluations of the model (:meth:`brdf.Fabric.prepare`) a draw, central differences of
step :data:`analysis.fit.fisher.STEP`. The model is evaluated at the nominal directions: the
instrument's cones, which average f_r over a few degrees, are not modelled here (a local
linearisation of an already local quantity).

A value with no usable sigma (a zero f_r with a noise model proportional to it, a
non-finite one) or a direction at or below the horizon gives zero rows: it informs nothing,
as the likelihood masks it.
"""

from __future__ import annotations

import numpy as np

from analysis.fit.fisher import STEP
from analysis.fit.posterior import LogPosterior, forward_model
from analysis.params import ParamSpec

__all__ = ["whitened_jacobians", "information", "rows_per_pair"]


def rows_per_pair(grey: bool) -> int:
    """Rows of information a pair gives: 3 (R, G, B) or 1 (a grey instrument)."""
    return 1 if grey else 3


def _residual_space(f: np.ndarray, cos_i: np.ndarray, grey: bool) -> np.ndarray:
    """log(1 + max(f, 0) cos theta_i), per channel (..., M, 3) or grey (..., M, 1)."""
    if grey:
        f = f.mean(axis=-1, keepdims=True)
    return np.log1p(np.maximum(f, 0.0) * cos_i[:, None])


def whitened_jacobians(fabric, spec: ParamSpec, thetas, wi, wo, instrument, *,
                       grey: bool = False, progress=None) -> np.ndarray:
    r""":math:`\tilde J` (K, M, r, d) of M pairs at K draws (module notes).

    Parameters
    ----------
    fabric : brdf.Fabric
        The fabric whose parameters ``spec`` replaces (its defaults the fixed values).
    spec : ParamSpec
        The free parameters (d) and the fixed and tied ones.
    thetas : array_like (K, d)
        Internal coordinates of the draws.
    wi, wo : array_like (M, 3)
        Unit directions of the pairs.
    instrument : gonio.Instrument
        Its :meth:`~gonio.Instrument.sigma` is the noise of a reading (1/sr); it must be
        noisy.
    grey : bool
        One row a pair (the channels' mean) rather than three.
    progress : callable, optional
        Called with 1 after each draw.

    Returns
    -------
    ndarray (K, M, r, d)
    """
    thetas = np.atleast_2d(np.asarray(thetas, dtype=np.float64))
    wi = np.asarray(wi, dtype=np.float64).reshape(-1, 3)
    wo = np.asarray(wo, dtype=np.float64).reshape(-1, 3)
    d, m, r = spec.ndim, wi.shape[0], rows_per_pair(grey)
    out = np.zeros((thetas.shape[0], m, r, d))
    if m == 0:
        return out
    post = LogPosterior(spec, None, forward_model(fabric, wi, wo))
    cos_i = wi[:, 2]
    above = (cos_i > 0) & (wo[:, 2] > 0)
    h = STEP * np.eye(d)
    for k, theta in enumerate(thetas):
        pts = np.concatenate([theta[None], theta + h, theta - h])
        with np.errstate(all="ignore"):
            f = post.predict(pts)                                   # (2d + 1, M, 3)
            mu = _residual_space(f, cos_i, grey)                    # (2d + 1, M, r)
            f0 = f[0].mean(axis=-1, keepdims=True) if grey else f[0]
            sigma = instrument.sigma(f0)
            s = cos_i[:, None] * sigma / (1.0 + np.maximum(f0, 0.0) * cos_i[:, None])
            dmu = (mu[1:d + 1] - mu[d + 1:]) / (2 * STEP)           # (d, M, r)
            jac = np.moveaxis(dmu, 0, -1) / s[..., None]
        ok = np.isfinite(s) & (s > 0) & above[:, None] & np.all(np.isfinite(jac), axis=-1)
        out[k] = np.where(ok[..., None], jac, 0.0)
        if progress is not None:
            progress(1)
    return out


def information(jac) -> np.ndarray:
    """The Fisher information (K, d, d) of a design from its :math:`\\tilde J` (K, M, r, d):
    the sum over its pairs and rows of :math:`\\tilde J^T \\tilde J`."""
    jac = np.asarray(jac, dtype=np.float64)
    flat = jac.reshape(jac.shape[0], -1, jac.shape[-1])
    info = np.einsum("kni,knj->kij", flat, flat)
    return 0.5 * (info + np.swapaxes(info, -1, -2))
