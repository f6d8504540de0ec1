r"""The fabric level of MODEL.md: the normalization Q, the denominator Q (n . wi), and the sum
of the two threads' shares into the RGB f_r (the albedo A of f_rv applied to its sums).
"""

from __future__ import annotations

import numpy as np

__all__ = ["normalization_q", "inverse_denominator", "combine_rgb", "DENOM_MIN"]

#: The least Q (n . wi) that f_r is divided by, 2^-1000 (about 9.3e-302). MODEL.md's f_r grows
#: like 1/(n . wi) at grazing incidence (the thread-frame cos(theta_i) in S_j does not vanish
#: with n . wi); below this the exact value would leave the float64 range, so it saturates.
DENOM_MIN = 2.0 ** -1000


def normalization_q(pmean1, pmean2, area1, area2, gap):
    r"""MODEL.md's normalization Q from the threads' mean reweighting (broadcasting):
    :math:`Q = a_1 \bar P_1 + a_2 \bar P_2 + (1 - a_1 - a_2)\, c_{gap}`, with
    :math:`\bar P_j = \frac{1}{N_j}\sum_{T_j} P(t)` (:func:`brdf.kernel.reweighting`'s
    mean) and ``gap`` = c_gap (n . wi or n . wo, the option ``gap``)."""
    return area1 * pmean1 + area2 * pmean2 + (1.0 - area1 - area2) * gap


def inverse_denominator(q, zi) -> np.ndarray:
    r""":math:`1 / (Q\, n\cdot w_i)` (broadcast), 0 where Q or n . wi is not positive.

    The product is taken as at least :data:`DENOM_MIN`, so that f_r stays finite for every
    direction above the horizon, however close to it (n . wi = 1e-200 gives about 1e200 / sr
    times the cosine-weighted value, as MODEL.md's equation does).
    """
    denom = np.multiply(q, zi)
    ok = (np.asarray(q) > 0) & (zi > 0)
    return np.divide(1.0, np.maximum(denom, DENOM_MIN), out=np.zeros(np.shape(denom)),
                     where=np.broadcast_to(ok, np.shape(denom)))


def combine_rgb(surf, vol, area, albedo, inv, out):
    r"""The fabric's RGB f_r from its threads' sums, into ``out``.

    :math:`f_r = \sum_j a_j (S_j + \mathrm{albedo}_j V_j) / (Q\, n\cdot w_i)`, computed one
    channel at a time on (set, pair) planes (long inner loops; broadcasting over a last axis
    of 3 would run NumPy's loops three elements at a time).

    Parameters
    ----------
    surf, vol : sequence of two ndarray, shape (B, C)
        Per thread the surface and volume sums of :func:`thread_shade`, 1/sr.
    area : ndarray, shape (B, 2)
        The threads' area shares.
    albedo : ndarray, shape (B, 2, 3)
        The threads' volume albedos (RGB).
    inv : ndarray, shape (B, C) or (C,)
        :math:`1 / (Q\, n\cdot w_i)` (0 where that is not positive).
    out : ndarray, shape (B, C, 3)
        Written (any strides); returned.
    """
    a1, a2 = area[:, 0, None], area[:, 1, None]
    base = np.multiply(surf[0], a1)
    base += surf[1] * a2
    base *= inv
    w1 = np.multiply(vol[0], inv)
    w1 *= a1
    w2 = np.multiply(vol[1], inv)
    w2 *= a2
    tmp, tmp2 = np.empty_like(base), np.empty_like(base)
    for ch in range(3):
        np.multiply(w1, albedo[:, 0, ch, None], out=tmp)
        tmp += base
        np.multiply(w2, albedo[:, 1, ch, None], out=tmp2)
        tmp += tmp2
        out[..., ch] = tmp
    return out
