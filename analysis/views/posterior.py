"""A fit's posterior-predictive lobes as data: for a few incidences, the 5-95% band and the
median of f_r cos(theta_o) over posterior draws in the plane of incidence, and the table's
points near that plane."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.fit import LogPosterior

__all__ = ["PosteriorLobe", "compute_posterior_lobes", "posterior_draws"]


def posterior_draws(result, n: int = 64, seed: int = 0) -> np.ndarray:
    """``n`` posterior draws in the sampler's internal coordinates, shape (n, ndim): the
    samples of every chain, drawn without replacement (all of them when there are fewer).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> r = SimpleNamespace(chains_internal=np.arange(24.0).reshape(2, 4, 3), names="abc")
    >>> d = posterior_draws(r, n=5)
    >>> d.shape, all(row in r.chains_internal.reshape(-1, 3).tolist() for row in d.tolist())
    ((5, 3), True)
    >>> len({tuple(row) for row in posterior_draws(r, n=100)})
    8
    """
    flat = result.chains_internal.reshape(-1, len(result.names))
    idx = np.random.default_rng(seed).choice(flat.shape[0], min(n, flat.shape[0]), False)
    return flat[idx]


@dataclass(frozen=True, eq=False)
class PosteriorLobe:
    """One incidence's posterior-predictive lobe (f_r cos theta_o, mean of R, G, B; 1/sr).

    Attributes
    ----------
    theta_i_deg, phi_i_deg : float
        The light, degrees.
    signed_deg : numpy.ndarray, shape (n,)
        Signed theta_o, degrees (+ forward, away from the light; - backward).
    lo, median, hi : numpy.ndarray, shape (n,)
        The 5th, 50th and 95th percentiles over the draws.
    data_signed_deg, data : numpy.ndarray
        The table's points near the plane and incidence: signed theta_o (degrees) and their
        mean valid f_r cos theta_o (1/sr); empty when none is near.
    """

    theta_i_deg: float
    phi_i_deg: float
    signed_deg: np.ndarray
    lo: np.ndarray
    median: np.ndarray
    hi: np.ndarray
    data_signed_deg: np.ndarray
    data: np.ndarray


def _default_incidences(ang) -> list:
    vals, cnt = np.unique(np.round(ang[:, 0]), return_counts=True)
    if len(vals) > 12:   # scattered directions: use quantiles
        return list(np.percentile(ang[:, 0], [20, 50, 80]).round())
    return list(vals[np.argsort(-cnt)[:3]])


def compute_posterior_lobes(result, table, model_factory, theta_i_deg=None, phi_i_deg=None, *,
                            n_draws: int = 48, plane_tol_deg: float = 8.0,
                            theta_tol_deg: float = 4.0) -> list:
    """The :class:`PosteriorLobe` of each incidence (default up to three of the table's most
    common ones), each draw evaluated once on 121 signed angles in [-89, 89] degrees;
    ``model_factory(wi, wo)`` makes the model of new directions (e.g. ``FabricModel``)."""
    ang = np.degrees(table.angles)
    theta_i_deg = _default_incidences(ang) if theta_i_deg is None else theta_i_deg
    phi_i_deg = 0.0 if phi_i_deg is None else phi_i_deg
    draws = posterior_draws(result, n_draws)
    signed = np.linspace(-89, 89, 121)
    out = []
    for ti in theta_i_deg:
        ti_r, pi_r = np.radians(ti), np.radians(phi_i_deg)
        wi = np.tile([np.sin(ti_r) * np.cos(pi_r), np.sin(ti_r) * np.sin(pi_r), np.cos(ti_r)],
                     (signed.size, 1))
        po = np.where(signed >= 0, pi_r + np.pi, pi_r)
        to = np.radians(np.abs(signed))
        wo = np.stack([np.sin(to) * np.cos(po), np.sin(to) * np.sin(po), np.cos(to)], -1)
        lp = LogPosterior(result.spec, None, model_factory(wi, wo))
        pred = lp.predict(draws).mean(-1) * np.cos(to)
        lo, med, hi = np.percentile(pred, [5, 50, 95], axis=0)
        # data near this plane
        dphi = np.angle(np.exp(1j * np.radians(ang[:, 3] - phi_i_deg)))
        near_i = np.abs(ang[:, 0] - ti) <= theta_tol_deg
        fwd = np.abs(np.abs(dphi) - np.pi) <= np.radians(plane_tol_deg)
        back = np.abs(dphi) <= np.radians(plane_tol_deg)
        dphi_i = np.abs(np.angle(np.exp(1j * np.radians(ang[:, 1] - phi_i_deg))))
        near_i &= dphi_i <= np.radians(plane_tol_deg)
        sel = near_i & (fwd | back)
        s = np.where(fwd[sel], 1.0, -1.0) * ang[sel, 2]
        v = np.nanmean(np.where(table.valid[sel], table.values[sel], np.nan), -1) \
            * np.cos(np.radians(ang[sel, 2]))
        out.append(PosteriorLobe(float(ti), float(phi_i_deg), signed, lo, med, hi, s, v))
    return out
