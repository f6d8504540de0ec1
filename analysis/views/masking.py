"""The terms of shadowing/masking and reweighting against angle, for the plot of M, P and u.

MODEL.md: M(w) = max(cos(phi), 0) with phi the azimuth about the thread;
M(wi, wo) = (1 - u(phi_d)) M(wi) M(wo) + u(phi_d) min(M(wi), M(wo));
u(x) = exp(-x^2 / (2 sigma_u^2)), sigma_u = 20 degrees. P(w) = max(cos(psi), 0) with the same
pairing over psi_d (the visible-length reweighting).
"""

from __future__ import annotations

import numpy as np

from brdf import terms

__all__ = ["masking_terms"]


def masking_terms(angle_deg, pair_with_deg=0.0):
    """M (= P) of one direction, u, and the paired weight, against an angle in degrees.

    Parameters
    ----------
    angle_deg : array_like
        Azimuth about the thread (phi for M, psi for P) in degrees.
    pair_with_deg : float
        The other direction's angle in degrees, for the paired weight.

    Returns
    -------
    dict of numpy.ndarray
        "M": max(cos(angle), 0); "u": u(angle); "pair": pair weight of (angle, pair_with) with
        difference angle - pair_with, from :func:`brdf.terms.u` and
        :func:`brdf.terms.pair_weight`.

    Examples
    --------
    >>> t = masking_terms([0.0, 20.0, 90.0])
    >>> np.round(t["u"], 4).tolist()
    [1.0, 0.6065, 0.0]
    """
    x = np.radians(np.asarray(angle_deg, dtype=np.float64))
    other = np.radians(float(pair_with_deg))
    m = np.maximum(np.cos(x), 0.0)
    m_other = np.maximum(np.cos(other), 0.0) * np.ones_like(x)
    delta = np.angle(np.exp(1j * (x - other)))  # wrap into (-pi, pi]
    u = np.asarray(terms.u(x), dtype=np.float64)
    pair = np.asarray(terms.pair_weight(m, m_other, delta), dtype=np.float64)
    return {"M": m, "u": u, "pair": pair}

