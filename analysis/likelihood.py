r"""Likelihood of a BRDF table given model predictions, vectorized over a batch of walkers.

Default (``"gaussian"``): the residual is taken in the compressed space
y = log(1 + f_r cos(theta_i)), which keeps both the narrow specular peaks and the diffuse floor
informative. The table's sigma is propagated by the delta method,

    sigma_y = cos(theta_i) sigma / (1 + f_r cos(theta_i)),

and the log-likelihood is sum over valid (point, channel) of
-1/2 [ (y_data - y_model)^2 / s^2 + log(2 pi s^2) ], with s^2 = sigma_y^2 + exp(2 log_noise)
(the noise term only when ``log_noise`` is a parameter; it is the whole of s when the table has
no sigma).

:meth:`Likelihood.pointwise` gives the same terms one used value at a time (and, on request,
each value's predictive CDF), which PSIS-LOO and LOO-PIT need (:mod:`analysis.fit.loo`);
:attr:`Likelihood.log_jacobian` carries a density of the residual space back to f_r.

``"relative"``: Gaussian on log(f_r) residuals (errors proportional to the value), with
sigma_y = sigma / f_r; points with f_r = 0 are masked as well.

``"student-t"``: the residuals of the default space with Student-t errors of ``nu`` degrees of
freedom and scale s (robust to outliers): log t_nu(r / s) - log s.

Points with NaN or negative values, with non-finite or non-positive sigma, or with either
direction at or below the horizon are masked; every mask is counted in :attr:`Likelihood.counts`.

A grey table (R = G = B, and the same sigma, at every point: CUReT, a CSV with one ``value``
column) holds one measurement per point, not three: it enters once, against the mean of the
model's R, G and B (CUReT's grey value is that mean), so that it is not counted three times.
"""

from __future__ import annotations

import math

import numpy as np

from analysis.lazy import stats
from brdf.scratch import Scratch

__all__ = ["Likelihood", "KINDS", "is_relative", "is_grey"]

KINDS = ("gaussian", "relative", "student-t")
_LOG_2PI = math.log(2.0 * math.pi)


def is_grey(a) -> bool:
    """True when the (n, 3) array holds the same value in R, G and B at every row (NaN equal).

    Examples
    --------
    >>> is_grey(np.array([[0.1, 0.1, 0.1], [np.nan, np.nan, np.nan]]))
    True
    """
    a = np.asarray(a)
    return bool(np.array_equal(a[:, 0], a[:, 1], equal_nan=True)
                and np.array_equal(a[:, 0], a[:, 2], equal_nan=True))


def is_relative(meta) -> bool:
    """True when a table's metadata says its values are relative (need a free ``scale``).

    Looks for ``meta["relative"]`` true, or "relative" in ``meta["units"]`` or ``meta["unit"]``.

    Examples
    --------
    >>> is_relative({"units": "relative reflectance"}), is_relative({})
    (True, False)
    """
    meta = meta or {}
    if meta.get("relative") is True:
        return True
    return any("relative" in str(meta.get(k, "")).lower() for k in ("units", "unit"))


class Likelihood:
    """Vectorized log-likelihood of a table.

    Parameters
    ----------
    table : gonio.Table-like
        Needs ``wi``, ``wo`` (n, 3), ``values`` (n, 3) in 1/sr, ``sigma`` (n, 3) or None,
        ``meta``.
    kind : {"gaussian", "relative", "student-t"}
        Residual model (see the module notes).
    nu : float
        Degrees of freedom of the Student-t (> 0).

    Attributes
    ----------
    counts : dict
        ``total`` (n x 3 values, n for a grey table), ``used``, ``invalid_value`` (NaN or negative),
        ``bad_sigma``, ``below_horizon``, ``zero_value`` (relative only).
    has_sigma : bool
        Whether the table gave sigma (otherwise a ``log_noise`` parameter is needed).
    log_jacobian : ndarray (n_used,)
        log |dy/df| at each used value (y the residual space, f the table's value): added to
        a log density of y it gives the log density of f (per 1/sr), the same space for every
        ``kind``.

    Raises
    ------
    ValueError
        An unknown ``kind`` or a non-positive ``nu``.

    Examples
    --------
    >>> from gonio.table import Table
    >>> t = Table([[0, 0, 1.0]] * 2, [[0, 0, 1.0]] * 2, [[0.1, 0.2, np.nan], [0.3, 0.3, 0.3]],
    ...           sigma=np.full((2, 3), 0.01))
    >>> lik = Likelihood(t)
    >>> lik.counts["used"], lik.counts["invalid_value"]
    (5, 1)
    >>> float(lik(t.values[None])[0]) > float(lik(2 * t.values[None])[0])
    True
    """

    def __init__(self, table, kind: str = "gaussian", nu: float = 4.0):
        if kind not in KINDS:
            raise ValueError(f"likelihood must be one of {', '.join(KINDS)}; got {kind!r}")
        if not (np.isfinite(nu) and nu > 0):
            raise ValueError(f"nu (Student-t degrees of freedom) must be > 0; got {nu}")
        self.kind, self.nu = kind, float(nu)
        values = np.asarray(table.values, dtype=np.float64)
        n = values.shape[0]
        cos_i = np.asarray(table.wi, dtype=np.float64)[:, 2]
        cos_o = np.asarray(table.wo, dtype=np.float64)[:, 2]
        good_value = np.isfinite(values) & (values >= 0)
        above = np.broadcast_to(((cos_i > 0) & (cos_o > 0))[:, None], (n, 3))
        sigma = None if table.sigma is None else np.asarray(table.sigma, dtype=np.float64)
        good_sigma = np.ones((n, 3), bool) if sigma is None else np.isfinite(sigma) & (sigma > 0)
        mask = good_value & above & good_sigma
        self.grey = is_grey(values) and (sigma is None or is_grey(sigma))
        if self.grey:
            mask[:, 1:] = False
            good_value, above, good_sigma = (a[:, :1] for a in (good_value, above, good_sigma))
        counts = {
            "total": int(good_value.size),
            "invalid_value": int((~good_value).sum()),
            "below_horizon": int((good_value & ~above).sum()),
            "bad_sigma": int((good_value & above & ~good_sigma).sum()),
            "zero_value": 0,
        }
        if kind == "relative":
            pos = values > 0
            counts["zero_value"] = int((mask & ~pos).sum())
            mask &= pos
        counts["used"] = int(mask.sum())
        self.counts = counts
        self.mask = mask
        self.has_sigma = sigma is not None
        self.relative_data = is_relative(getattr(table, "meta", {}))
        self.pt, self.ch = np.nonzero(mask)
        self._scratch = Scratch()
        # the used entries as indices into the flattened (n * 3) values; None when all are
        self._flat = None if mask.all() else self.pt * 3 + self.ch
        f = values[self.pt, self.ch]
        c = cos_i[self.pt]
        self.cos_i = c
        if kind == "relative":
            self.y = np.log(f)
            sy = None if sigma is None else sigma[self.pt, self.ch] / f
            with np.errstate(divide="ignore"):
                self.log_jacobian = -np.log(f)
        else:
            self.y = np.log1p(f * c)
            sy = None if sigma is None else c * sigma[self.pt, self.ch] / (1.0 + f * c)
            with np.errstate(divide="ignore"):
                self.log_jacobian = np.log(c) - np.log1p(f * c)
        self.sigma_y2 = None if sy is None else sy * sy
        if self.sigma_y2 is not None:
            self._inv_s2 = 1.0 / self.sigma_y2
            self._gauss_const = -0.5 * float(np.sum(np.log(self.sigma_y2) + _LOG_2PI))
        if kind == "student-t":
            nu = self.nu
            # math.lgamma: nu is one float, and scipy.special costs a verb 0.12 s to import
            self._t_const = (math.lgamma((nu + 1) / 2) - math.lgamma(nu / 2)
                             - 0.5 * math.log(nu * math.pi))

    def _at(self, model_values) -> np.ndarray:
        """Model values (B..., n, 3) at the used entries (B..., n_used); grey: channel mean."""
        m = np.asarray(model_values, dtype=np.float64)
        if self.grey:
            return np.take(m, self.pt, axis=-2).mean(axis=-1)
        flat = m.reshape(m.shape[:-2] + (-1,))
        # np.take, not m[..., pt, ch]: fancy indexing over two trailing axes gives an array
        # laid out point-major, whose every later operation is strided (6x slower)
        if self._flat is None:
            return flat
        return np.take(flat, self._flat, axis=-1,
                       out=self._scratch.array("at", flat.shape[:-1] + self._flat.shape))

    @property
    def n_used(self) -> int:
        """Number of (point, channel) values that enter the likelihood."""
        return self.counts["used"]

    def transform(self, model_values) -> np.ndarray:
        """Model f_r (B..., n, 3) -> the residual space at the used entries (B..., n_used)."""
        return self._mu(self._at(model_values), None, out=None)

    def _mu(self, m, scale, out) -> np.ndarray:
        """The residual space of model values ``m`` (B..., n_used) times ``scale`` (B...):
        log f (relative) or log(1 + f cos theta_i), into ``out`` (a new array when None)."""
        lo = 1e-300 if self.kind == "relative" else 0.0
        if scale is None:
            mu = np.maximum(m, lo, out=out)
        else:
            mu = np.multiply(m, np.asarray(scale, dtype=np.float64)[..., None], out=out)
            np.maximum(mu, lo, out=mu)
        if self.kind == "relative":
            return np.log(mu, out=mu)
        mu *= self.cos_i
        return np.log1p(mu, out=mu)

    def __call__(self, model_values, scale=None, log_noise=None) -> np.ndarray:
        """Log-likelihood for model predictions.

        Parameters
        ----------
        model_values : array_like, shape (B..., n, 3)
            Predicted f_r in 1/sr at the table's n pairs.
        scale : array_like, shape (B...), optional
            Overall factor applied to the predictions (relative data).
        log_noise : array_like, shape (B...), optional
            Natural log of an extra noise standard deviation in the residual space.

        Returns
        -------
        ndarray, shape (B...)
            Log-likelihood; -inf where the prediction is not finite.

        Raises
        ------
        ValueError
            When the table has no sigma and no ``log_noise`` is given.
        """
        if log_noise is None and self.sigma_y2 is None:
            raise ValueError("the table has no sigma: a log_noise parameter is needed")
        m = self._at(model_values)
        # one buffer for mu and the residuals, the rest in place: fresh large temporaries
        # cost page faults, which threads take in turn
        mu = self._mu(m, scale, out=self._scratch.array("mu", m.shape))
        r = np.subtract(self.y, mu, out=mu)
        if self.kind == "student-t":
            out = self._student_t(r, log_noise)
        elif log_noise is None:           # fixed sigma: sum r^2 / s^2 as one product
            out = -0.5 * (np.multiply(r, r, out=r) @ self._inv_s2) + self._gauss_const
        elif self.sigma_y2 is None:       # s^2 = exp(2 log_noise), one value per row
            ln = np.asarray(log_noise, dtype=np.float64)
            n = r.shape[-1]
            out = (-0.5 * np.exp(-2.0 * ln) * np.multiply(r, r, out=r).sum(axis=-1)
                   - n * ln - 0.5 * n * _LOG_2PI)
        else:
            s2 = self.sigma_y2 + np.exp(2.0 * np.asarray(log_noise, dtype=np.float64))[..., None]
            out = -0.5 * (r * r / s2 + np.log(s2) + _LOG_2PI).sum(axis=-1)
        return np.where(np.isfinite(out), out, -np.inf)

    def pointwise(self, model_values, scale=None, log_noise=None, cdf: bool = False):
        """The log-likelihood of each used value, and optionally its predictive CDF.

        Parameters
        ----------
        model_values, scale, log_noise
            As :meth:`__call__`.
        cdf : bool
            Also return the CDF of each value's predictive distribution (given the
            parameters) at the measured value: the probability integral transform.

        Returns
        -------
        ndarray, shape (B..., n_used)
            The terms whose sum is :meth:`__call__` (-inf where the prediction is not finite),
            in the residual space (add :attr:`log_jacobian` for the density of f_r); and,
            with ``cdf``, an array of the same shape in [0, 1].

        Raises
        ------
        ValueError
            When the table has no sigma and no ``log_noise`` is given.
        """
        if log_noise is None and self.sigma_y2 is None:
            raise ValueError("the table has no sigma: a log_noise parameter is needed")
        m = self._at(model_values)
        r = self.y - self._mu(m, scale, out=None)
        if log_noise is None:
            s2 = np.broadcast_to(self.sigma_y2, r.shape)
        else:
            noise2 = np.exp(2.0 * np.asarray(log_noise, dtype=np.float64))[..., None]
            s2 = noise2 + (0.0 if self.sigma_y2 is None else self.sigma_y2)
        z = r / np.sqrt(s2)
        if self.kind == "student-t":
            ll = (self._t_const - 0.5 * (self.nu + 1) * np.log1p(z * z / self.nu)
                  - 0.5 * np.log(s2))
        else:
            ll = -0.5 * (z * z + np.log(s2) + _LOG_2PI)
        ll = np.where(np.isfinite(ll), ll, -np.inf)
        if not cdf:
            return ll
        dist = stats.t(self.nu) if self.kind == "student-t" else stats.norm
        return ll, dist.cdf(z)

    def _student_t(self, r, log_noise):
        if log_noise is None:
            s2 = self.sigma_y2
        else:
            ln = np.asarray(log_noise, dtype=np.float64)[..., None]
            s2 = np.exp(2.0 * ln) if self.sigma_y2 is None else self.sigma_y2 + np.exp(2.0 * ln)
        s2 = np.broadcast_to(s2, r.shape)
        z2 = r * r / s2
        ll = self._t_const - 0.5 * (self.nu + 1) * np.log1p(z2 / self.nu) - 0.5 * np.log(s2)
        return ll.sum(axis=-1)
