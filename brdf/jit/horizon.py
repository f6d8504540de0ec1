r"""The sampler's lobes restricted to the upper hemisphere, in Dr.Jit: :mod:`brdf.horizon`'s
twin (the same formulas; its module notes derive them), for :mod:`brdf.jit.sampler`.

Dr.Jit has ``erf`` and ``erfinv`` but neither a logarithm of the normal CDF nor its inverse,
which a lobe truncated many standard deviations from its mean needs (velvet's pile at normal
view: the interval ends 7.5 standard deviations out, where ``0.5 (1 + erf)`` is 0 in float32
and keeps 3 digits in float64). :func:`log_ndtr` takes the logarithm of erfc's Chebyshev
fit (Numerical Recipes' ``erfcc``, fractional error below 1.2e-7 for every x >= 0), and
:func:`ndtri_exp` inverts it by Newton's method on :math:`\log\Phi` (concave: the iterates
approach the root from below after the first step).

This module imports Dr.Jit at its top: it is imported only through
:func:`reports.mitsuba.register` (as :mod:`brdf.jit.sampler`).
"""

from __future__ import annotations

import math

# optional dependency: this module is imported only through reports.mitsuba.register()
import drjit as dr

__all__ = ["log_ndtr", "ndtri_exp", "theta_range", "azimuth_window", "azimuth_mass_masked",
           "azimuth_draw", "truncnorm_logmass", "truncnorm_density", "truncnorm_draw"]

_HALF_PI = 0.5 * math.pi
_LOG_HALF = math.log(0.5)
_LOG_SQRT_2PI = 0.5 * math.log(2.0 * math.pi)
#: erfc(x) = t exp(-x^2 + P(t)), t = 1 / (1 + x / 2): P's coefficients, constant first.
_ERFC = (-1.26551223, 1.00002368, 0.37409196, 0.09678418, -0.18628806, 0.27886807,
         -1.13520398, 1.48851587, -0.82215223, 0.17087277)
_NEWTON = 3


def _erfc_fit(x):
    """(t, P) of erfc(x) = t exp(-x^2 + P) for x >= 0 (erfc's Chebyshev fit)."""
    t = 1.0 / (1.0 + 0.5 * x)
    poly = _ERFC[-1]
    for c in reversed(_ERFC[:-1]):
        poly = poly * t + c
    return t, poly


def _log_erfc(x):
    """log erfc(x) for x >= 0."""
    t, poly = _erfc_fit(x)
    return dr.log(t) - x * x + poly


def log_ndtr(z):
    r""":math:`\log\Phi(z)` of the standard normal, relative error about 1e-7 at any z."""
    log_erfc = _log_erfc(dr.abs(z) * (1.0 / math.sqrt(2.0)))
    return dr.select(z < 0.0, _LOG_HALF + log_erfc, dr.log(1.0 - 0.5 * dr.exp(log_erfc)))


def _log_ndtr_neg(z):
    """log Phi(z) for z <= 0 only (one branch of :func:`log_ndtr`)."""
    return _LOG_HALF + _log_erfc(-z * (1.0 / math.sqrt(2.0)))


def ndtri_exp(y):
    r"""The z with :math:`\log\Phi(z) = y` (y < 0): erfinv's where :math:`\Phi(z) \ge 1/2`;
    below, Newton steps from erfinv's (or, below y = -12, from the tail's asymptote
    :math:`z^2 + 2\log|z| \approx -2y - \log 2\pi`). Above 1/2 the step's factor
    :math:`\Phi/\varphi` grows without bound (6.7e5 at z = 5) and erfinv keeps its digits."""
    p = dr.exp(y)
    z_mid = math.sqrt(2.0) * dr.erfinv(dr.clip(2.0 * p - 1.0, -0.999999, 0.999999))
    s = dr.maximum(-2.0 * y - 2.0 * _LOG_SQRT_2PI, 2.0)
    z = dr.select(y < -12.0, -dr.sqrt(s - dr.log(s)), z_mid)
    for _ in range(_NEWTON):
        lz = log_ndtr(z)
        # d log Phi / dz = phi / Phi
        z = z - (lz - y) * dr.exp(lz + 0.5 * z * z + _LOG_SQRT_2PI)
    return dr.select(y < _LOG_HALF, z, z_mid)


def theta_range(ca, sa):
    """:func:`brdf.horizon.theta_range`: (lo, hi), radians."""
    alpha = dr.atan2(sa, ca)
    return dr.maximum(-_HALF_PI, alpha - _HALF_PI), dr.minimum(_HALF_PI, alpha + _HALF_PI)


def azimuth_window(st, ct, ca, sa, masking):
    """:func:`brdf.horizon.azimuth_window`: the half-width m and mass M of the azimuths
    above the horizon."""
    den = ct * ca
    pos = den > 0.0
    one_minus_q = dr.select(pos, (den + st * sa) / dr.select(pos, den, 1.0),
                            dr.select(st * sa > 0.0, 2.0, 0.0))
    x = dr.clip(0.5 * one_minus_q, 0.0, 1.0)             # sin^2(m / 2)
    m = 2.0 * dr.asin(dr.sqrt(x))
    if masking:
        return dr.minimum(m, _HALF_PI), azimuth_mass_masked(x)
    return m, m * (1.0 / math.pi)


def azimuth_mass_masked(x):
    """The window's mass sin(min(m, pi/2)) under masking from x = sin^2(m / 2), without
    trigonometry (:func:`brdf.horizon.azimuth_mass`)."""
    return dr.select(x >= 0.5, 1.0, 2.0 * dr.sqrt(dr.maximum(x * (1.0 - x), 0.0)))


def azimuth_draw(m, u, masking):
    """:func:`brdf.horizon.azimuth_draw`: an azimuth in (-m, m)."""
    if masking:
        return dr.asin(dr.clip((2.0 * u - 1.0) * dr.sin(m), -1.0, 1.0))
    return (2.0 * u - 1.0) * m


def _oriented_bounds(za, zb):
    """(flip, a, b): [za, zb] reflected where it lies more on the right of 0."""
    flip = za + zb > 0.0
    return flip, dr.select(flip, -zb, za), dr.select(flip, -za, zb)


def _oriented(za, zb):
    """brdf.horizon._oriented: (flip, a, b, log Phi(b), Phi(a) / Phi(b))."""
    flip, a, b = _oriented_bounds(za, zb)
    lb = log_ndtr(b)
    return flip, a, b, lb, dr.exp(_log_ndtr_neg(a) - lb)      # a <= -|b| <= 0


def truncnorm_logmass(mu, inv_sigma, lo, hi):
    """:func:`brdf.horizon.truncnorm_logmass` (with 1 / sigma)."""
    _, _, _, lb, r = _oriented((lo - mu) * inv_sigma, (hi - mu) * inv_sigma)
    return lb + dr.log(1.0 - r)


def truncnorm_density(z, za, zb):
    r""":math:`e^{-z^2/2} / (\Phi(z_b) - \Phi(z_a))`: the standard normal truncated to
    [za, zb] at z, times :math:`\sqrt{2\pi}`, without logarithms (the shading loop's
    cost). On the oriented interval [a, b] (a <= -|b|), where b < 0 both tails are scaled
    by :math:`e^{g}`, :math:`g = b^2/2 - P_b` (erfc's fit at b), so that neither underflows:
    :math:`\Phi(b) e^{g} = t_b / 2`,
    :math:`\Phi(a) e^{g} = (t_a / 2) e^{-a^2/2 + P_a + g}`."""
    _, a, b = _oriented_bounds(za, zb)
    k = 1.0 / math.sqrt(2.0)
    t_a, p_a = _erfc_fit(-a * k)
    t_b, p_b = _erfc_fit(dr.abs(b) * k)
    neg = b < 0.0
    g = dr.select(neg, 0.5 * b * b - p_b, 0.0)
    e_b = dr.exp(dr.select(neg, 0.0, p_b - 0.5 * b * b))
    phi_b = dr.select(neg, 0.5 * t_b, 1.0 - 0.5 * t_b * e_b)
    phi_a = 0.5 * t_a * dr.exp(p_a - 0.5 * a * a + g)
    return dr.exp(g - 0.5 * z * z) / (phi_b - phi_a)


def truncnorm_draw(mu, sigma, lo, hi, v):
    """:func:`brdf.horizon.truncnorm_draw`: the inverse CDF of N(mu, sigma) on [lo, hi]."""
    flip, a, b, lb, r = _oriented((lo - mu) / sigma, (hi - mu) / sigma)
    z = dr.clip(ndtri_exp(lb + dr.log(r + v * (1.0 - r))), a, b)
    return dr.clip(mu + sigma * dr.select(flip, -z, z), lo, hi)
