r"""A sampler lobe restricted to the upper hemisphere: the exact distributions that
:mod:`brdf.sampling` draws a lobe's longitudinal angle and azimuth from, so that no draw
lands below the surface.

A lobe lives in the frame (t, b, n_t) of one tangent sample, t tilted by the offset
:math:`\alpha \in [-\pi/2, \pi/2]` from the in-plane tangent t0 toward n (MODEL.md):
:math:`t = \cos\alpha\, t_0 + \sin\alpha\, n`, :math:`n_t = \cos\alpha\, n - \sin\alpha\, t_0`,
:math:`b = n \times t_0`. A direction of longitudinal angle :math:`\theta` and azimuth
:math:`\phi` about t is
:math:`\omega = \sin\theta\, t + \cos\theta(\cos\phi\, n_t + \sin\phi\, b)`, whose height is

.. math:: \omega_z = \cos\theta\cos\phi\cos\alpha + \sin\theta\sin\alpha .

It is largest at :math:`\phi = 0`, where it is :math:`\cos(\theta - \alpha)`, so some azimuth
is above the horizon exactly when :math:`|\theta - \alpha| < \pi/2`: the longitudinal range
:func:`theta_range`, :math:`[\max(-\pi/2, \alpha - \pi/2), \min(\pi/2, \alpha + \pi/2)]`.
Given :math:`\theta` in it, the azimuths above the horizon are :math:`|\phi| < m(\theta)`,
:math:`\cos m = -\tan\theta\tan\alpha` (:func:`azimuth_window`; b has no height, so the
window is symmetric about :math:`\phi = 0`).

A lobe draws :math:`\theta` from its distribution (a Gaussian, or uniform in
:math:`\sin\theta`) truncated to that range (:func:`truncnorm_draw`, its normaliser
:func:`truncnorm_logmass`), then :math:`\phi` from its azimuth density :math:`p_\phi`
truncated to the window (:func:`azimuth_draw`), whose mass :math:`M(\theta)` divides the
density. Both normalisers are closed forms, so the density stays exact; it is never less
than the untruncated lobe's above the horizon, so weights :math:`f_r\cos\theta_i / p` only
shrink.
"""

from __future__ import annotations

import numpy as np

from brdf.lazy import special

__all__ = ["theta_range", "azimuth_window", "azimuth_mass", "azimuth_draw", "truncnorm_logmass",
           "truncnorm_draw"]

_HALF_PI = 0.5 * np.pi


def theta_range(ca, sa) -> tuple[np.ndarray, np.ndarray]:
    r"""Longitudinal angles about the tangent (cos, sin of its offset :math:`\alpha`) that
    have some azimuth above the horizon, radians.

    Parameters
    ----------
    ca, sa : array_like
        :math:`\cos\alpha \ge 0` and :math:`\sin\alpha` of the tangent offsets.

    Returns
    -------
    lo, hi : ndarray
        :math:`\max(-\pi/2, \alpha - \pi/2)` and :math:`\min(\pi/2, \alpha + \pi/2)`.

    Examples
    --------
    >>> lo, hi = theta_range([1.0, 0.0], [0.0, -1.0])      # flat; pointing down (velvet)
    >>> np.degrees(lo).round(6).tolist(), np.degrees(hi).round(6).tolist()
    ([-90.0, -90.0], [90.0, 0.0])
    """
    alpha = np.arctan2(sa, ca)
    return np.maximum(-_HALF_PI, alpha - _HALF_PI), np.minimum(_HALF_PI, alpha + _HALF_PI)


def azimuth_window(st, ct, ca, sa, masking) -> tuple[np.ndarray, np.ndarray]:
    r"""Azimuths above the horizon at longitudinal angle :math:`\theta`: the half-width
    :math:`m` (|phi| < m, radians) and the mass :math:`M` of the azimuth density there.

    Parameters
    ----------
    st, ct : array_like
        :math:`\sin\theta` and :math:`\cos\theta \ge 0`.
    ca, sa : array_like
        :math:`\cos\alpha \ge 0` and :math:`\sin\alpha` of the tangent offset.
    masking : bool
        Azimuth density :math:`\max(\cos\phi, 0)/2` (M = sin m, m <= pi/2) when True, else
        :math:`1/(2\pi)` (M = m / pi).

    Returns
    -------
    m, M : ndarray
        Half-width in [0, pi] and mass in [0, 1]; 0 where no azimuth is above.

    Notes
    -----
    :math:`m = \arccos q`, :math:`q = -\sin\theta\sin\alpha / (\cos\theta\cos\alpha)`, is
    computed as :math:`2\operatorname{asin}\sqrt{(1 - q)/2}` with
    :math:`1 - q = \cos(\theta - \alpha) / (\cos\theta\cos\alpha)`, which keeps its digits
    where the window closes (q near 1).

    Examples
    --------
    >>> m, M = azimuth_window(0.0, 1.0, 1.0, 0.0, masking=False)   # flat thread, theta = 0
    >>> float(np.degrees(m)), float(M)
    (90.0, 0.5)
    >>> m, M = azimuth_window(-0.5, np.sqrt(0.75), 0.0, -1.0, masking=True)  # pile: all
    >>> float(np.degrees(m)), float(M)
    (90.0, 1.0)
    """
    x = _half_versine(st, ct, ca, sa)
    m = 2.0 * np.arcsin(np.sqrt(x))
    if masking:
        m = np.minimum(m, _HALF_PI)
        return m, np.sin(m)
    return m, m / np.pi


def azimuth_mass(st, ct, ca, sa, masking) -> np.ndarray:
    r"""The mass M of :func:`azimuth_window` alone, without its inverse sines where
    ``masking`` is on: :math:`M = \sin m = 2\sqrt{x(1 - x)}` for :math:`x = \sin^2(m/2) \le
    1/2`, else 1.

    Examples
    --------
    >>> st, ct = np.sin(0.3), np.cos(0.3)
    >>> bool(np.isclose(azimuth_mass(st, ct, 0.8, -0.6, True),
    ...                 azimuth_window(st, ct, 0.8, -0.6, True)[1]))
    True
    """
    x = _half_versine(st, ct, ca, sa)
    if masking:
        return np.where(x >= 0.5, 1.0, 2.0 * np.sqrt(x * (1.0 - x)))
    return (2.0 / np.pi) * np.arcsin(np.sqrt(x))


def _half_versine(st, ct, ca, sa):
    """x = (1 - q) / 2 = sin^2(m / 2) of the window (m = arccos q), clipped to [0, 1]: 1
    where every azimuth is above the horizon (cos(theta) cos(alpha) = 0, sin theta sin
    alpha > 0), 0 where none is."""
    den = np.asarray(ct * ca, dtype=np.float64)
    lift = np.asarray(st * sa, dtype=np.float64)
    out = np.array(np.broadcast_to(np.where(lift > 0, 1.0, 0.0),
                                   np.broadcast_shapes(den.shape, lift.shape)))
    x = np.divide(0.5 * (den + lift), den, out=out, where=den > 0)
    return np.clip(x, 0.0, 1.0, out=x)


def azimuth_draw(m, u, masking) -> np.ndarray:
    r"""Azimuths from the density of :func:`azimuth_window` truncated to |phi| < m.

    Parameters
    ----------
    m : array_like
        Half-widths of the windows, radians.
    u : array_like
        Uniform numbers in [0, 1).
    masking : bool
        :math:`\phi = \operatorname{asin}((2u - 1)\sin m)` (density :math:`\cos\phi / (2M)`)
        when True, :math:`\phi = (2u - 1) m` (density :math:`1 / (2 m)`) when False.

    Returns
    -------
    ndarray
        Azimuths in (-m, m), radians.

    Examples
    --------
    >>> azimuth_draw(np.pi / 2, np.array([0.0, 0.5, 0.75]), masking=True).round(6).tolist()
    [-1.570796, 0.0, 0.523599]
    """
    if masking:
        return np.arcsin((2.0 * u - 1.0) * np.sin(m))
    return (2.0 * u - 1.0) * m


def _oriented(za, zb):
    """The interval [za, zb] of a standard normal, reflected (-zb, -za) where it lies more
    on the right of 0 than on the left, so that its upper end's CDF is >= 1/2 of the larger
    tail's: (flip, a, b, log Phi(b), Phi(a) / Phi(b))."""
    flip = za + zb > 0.0
    a, b = np.where(flip, -zb, za), np.where(flip, -za, zb)
    lb = special.log_ndtr(b)
    return flip, a, b, lb, np.exp(special.log_ndtr(a) - lb)


def truncnorm_logmass(mu, sigma, lo, hi) -> np.ndarray:
    r"""Log of the mass of :math:`N(\mu, \sigma)` on [lo, hi], accurate far in the tails.

    Examples
    --------
    >>> float(np.exp(truncnorm_logmass(0.0, 1.0, -1.0, 1.0))).__round__(6)
    0.682689
    >>> float(truncnorm_logmass(0.0, 1.0, 40.0, 41.0)).__round__(3)   # Phi(-40) ~ 4e-350
    -804.608
    """
    _, _, _, lb, r = _oriented((lo - mu) / sigma, (hi - mu) / sigma)
    return lb + np.log1p(-r)


def truncnorm_draw(mu, sigma, lo, hi, v) -> np.ndarray:
    r"""Inverse CDF of :math:`N(\mu, \sigma)` truncated to [lo, hi] at ``v`` in [0, 1).

    On the oriented interval [a, b] (:func:`_oriented`):
    :math:`z = \Phi^{-1}\big(\Phi(b)\,[r + v(1 - r)]\big)`, :math:`r = \Phi(a)/\Phi(b)`, in
    logarithms (``scipy.special.ndtri_exp``), so that intervals many standard deviations
    from the mean keep their digits.

    Examples
    --------
    >>> x = truncnorm_draw(0.0, 1.0, 30.0, 31.0, np.array([0.0, 0.5, 0.999]))
    >>> bool(np.all((x >= 30) & (x <= 31))), float(x[1]).__round__(4)
    (True, 30.0231)
    """
    flip, a, b, lb, r = _oriented((lo - mu) / sigma, (hi - mu) / sigma)
    z = np.clip(special.ndtri_exp(lb + np.log(r + v * (1.0 - r))), a, b)
    return np.clip(mu + sigma * np.where(flip, -z, z), lo, hi)
