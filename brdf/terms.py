r"""The named terms of the microcylinder model, each callable and testable alone.

Every function broadcasts over its array arguments. Angles are in radians; the paper's
tables give gamma in degrees (convert with ``numpy.radians``). The equations are those of
``MODEL.md`` (Sadeghi et al. 2013, section 4).
"""

from __future__ import annotations

import numpy as np

from brdf.options import Transmission, validate_method
from brdf.validate import array

__all__ = ["SIGMA_U", "fresnel", "gaussian", "u", "visibility", "pair_weight",
           "transmission"]

#: Width of the unit-height Gaussian that blends the masking and reweighting terms: 20 deg,
#: in radians.
SIGMA_U = float(np.radians(20.0))


def fresnel(eta, cos_i):
    r"""Exact unpolarized Fresnel reflectance of a dielectric, light arriving from air.

    Parameters
    ----------
    eta : array_like
        Relative index of refraction of the fibre (> 1), dimensionless.
    cos_i : array_like
        Cosine of the incidence angle, in [0, 1].

    Returns
    -------
    ndarray
        F_r(eta, cos_i), dimensionless, in [0, 1].

    Notes
    -----
    With :math:`c = \cos\theta_i` and :math:`g = \sqrt{\eta^2 - 1 + c^2} = \eta\cos\theta_t`,

    .. math::
        r_s = \frac{c - g}{c + g},\quad
        r_p = \frac{\eta^2 c - g}{\eta^2 c + g},\quad
        F_r = \tfrac12 (r_s^2 + r_p^2).

    Examples
    --------
    >>> round(float(fresnel(1.5, 1.0)), 12)   # ((1.5 - 1) / (1.5 + 1))**2
    0.04
    >>> float(fresnel(1.5, 0.0))
    1.0
    """
    eta = array("eta", eta)
    c = array("cos_i", cos_i)
    eta2 = eta * eta
    g = np.sqrt(eta2 - 1.0 + c * c)
    rs = (c - g) / (c + g)
    e2c = eta2 * c
    rp = (e2c - g) / (e2c + g)
    return 0.5 * (rs * rs + rp * rp)


def gaussian(gamma, x):
    r"""Unit-area Gaussian of standard deviation ``gamma``.

    Parameters
    ----------
    gamma : array_like
        Standard deviation, radians (> 0).
    x : array_like
        Argument, radians.

    Returns
    -------
    ndarray
        :math:`g(\gamma, x) = \exp(-x^2 / (2\gamma^2)) / (\gamma\sqrt{2\pi})`, in 1/rad.

    Examples
    --------
    >>> round(float(gaussian(1.0, 0.0) * np.sqrt(2 * np.pi)), 12)
    1.0
    """
    gamma = array("gamma", gamma)
    x = array("x", x)
    return np.exp(-x * x / (2.0 * gamma * gamma)) / (gamma * np.sqrt(2.0 * np.pi))


def u(x, sigma=SIGMA_U):
    r"""Unit-height Gaussian that blends the two shadowing regimes.

    Parameters
    ----------
    x : array_like
        An angle difference (phi_d or psi_d), radians.
    sigma : float, optional
        Width, radians; the model's value is 20 degrees.

    Returns
    -------
    ndarray
        :math:`u(x) = \exp(-x^2 / (2\sigma_u^2))`, dimensionless, in (0, 1].

    Examples
    --------
    >>> float(u(0.0)), round(float(u(SIGMA_U)), 12) == round(float(np.exp(-0.5)), 12)
    (1.0, True)
    """
    x = array("x", x)
    sigma = array("sigma", sigma)
    return np.exp(-x * x / (2.0 * sigma * sigma))


def visibility(cos_angle):
    r"""One-sided visibility :math:`\max(\cos a, 0)`: M(w) with a = phi, P(w) with a = psi.

    Parameters
    ----------
    cos_angle : array_like
        Cosine of the azimuth about the thread (masking) or of psi (reweighting).

    Returns
    -------
    ndarray
        Dimensionless, in [0, 1].

    Examples
    --------
    >>> visibility([-0.5, 0.25])
    array([0.  , 0.25])
    """
    return np.maximum(array("cos_angle", cos_angle), 0.0)


def pair_weight(m_i, m_o, delta):
    r"""Blend of independent and fully correlated visibility for a pair of directions.

    Parameters
    ----------
    m_i, m_o : array_like
        One-sided visibilities of the two directions (M or P), in [0, 1].
    delta : array_like
        Their angle difference (phi_d or psi_d), radians.

    Returns
    -------
    ndarray
        :math:`(1 - u(\delta))\, m_i m_o + u(\delta) \min(m_i, m_o)`, in [0, 1].

    Examples
    --------
    >>> float(pair_weight(0.5, 0.8, 0.0))      # u(0) = 1: the minimum
    0.5
    >>> round(float(pair_weight(0.5, 0.8, np.pi)), 6)   # u(pi) ~ 0: the product
    0.4
    """
    m_i = array("m_i", m_i)
    m_o = array("m_o", m_o)
    w = u(array("delta", delta))
    return (1.0 - w) * m_i * m_o + w * np.minimum(m_i, m_o)


def transmission(eta, cos_g, cos_theta_i, cos_theta_r, method="half_angle"):
    r"""Transmission F_T into and out of the fibre.

    Parameters
    ----------
    eta : array_like
        Index of refraction (> 1).
    cos_g : array_like
        Effective incidence cosine :math:`\cos\theta_d \cos(\phi_d / 2)`.
    cos_theta_i, cos_theta_r : array_like
        Longitudinal cosines of the two directions (used by ``"longitudinal"``).
    method : {"half_angle", "longitudinal"} or brdf.Transmission
        ``"half_angle"``: :math:`(1 - F_r(\eta, \cos g))^2`;
        ``"longitudinal"``: :math:`(1 - F_r(\eta, \cos\theta_i))(1 - F_r(\eta, \cos\theta_r))`.

    Returns
    -------
    ndarray
        F_T, dimensionless, in [0, 1].

    Examples
    --------
    >>> round(float(transmission(1.5, 1.0, 1.0, 1.0)), 12)
    0.9216
    """
    eta, cos_g = array("eta", eta), array("cos_g", cos_g)
    cos_theta_i = array("cos_theta_i", cos_theta_i)
    cos_theta_r = array("cos_theta_r", cos_theta_r)
    method = validate_method("transmission", method, Transmission)
    if method is Transmission.HALF_ANGLE:
        return (1.0 - fresnel(eta, cos_g)) ** 2
    return (1.0 - fresnel(eta, cos_theta_i)) * (1.0 - fresnel(eta, cos_theta_r))
