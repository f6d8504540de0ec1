r"""The shading half of the kernel: a thread's surface and volume sums for batches of
optical parameters, from the geometry of :mod:`brdf.kernel`, and the fabric's RGB f_r.

The blocks :func:`fresnel2_into`, :func:`surface_term` and :func:`volume_term` carry MODEL.md's
names (symbols in :mod:`brdf.kernel`); ``tests/test_brdf_kernel.py`` compares each with its
twin in :mod:`brdf.terms`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from brdf.kernel import ThreadGeometry

__all__ = ["thread_shade", "combine_rgb", "fresnel2_into", "surface_term", "volume_term",
           "inverse_denominator", "shade_dtype", "GAUSS_NORM", "SHADE_BLOCK", "DENOM_MIN",
           "SHADE_DTYPES"]

GAUSS_NORM = 1.0 / np.sqrt(2.0 * np.pi)

#: Default (parameter set, pair, sample) elements per block of :func:`thread_shade`: each of
#: its four float64 temporaries then takes 1 MiB. Chosen by bench/bench_prepared.py (2 cores,
#: 1 MiB L2 each, 32 MiB L3): blocks of 2^14..2^15, which stay in L2, lost more to the ~25
#: NumPy calls a block costs than they gained; 2^18 was no faster.
SHADE_BLOCK = 1 << 17

#: The least Q (n . wi) that f_r is divided by, 2^-1000 (about 9.3e-302). MODEL.md's f_r grows
#: like 1/(n . wi) at grazing incidence (the thread-frame cos(theta_i) in S_j does not vanish
#: with n . wi); below this the exact value would leave the float64 range, so it saturates.
DENOM_MIN = 2.0 ** -1000


def _fresnel_from_cos(eta2, c, c2):
    """Unpolarized dielectric Fresnel reflectance from c = cos and c2 = cos^2 (broadcasting)."""
    shape = np.broadcast_shapes(np.shape(eta2), np.shape(c), np.shape(c2))
    dtype = np.result_type(eta2, c, c2)
    rs = fresnel2_into(eta2, c, c2, *(np.empty(shape, dtype) for _ in range(4)))
    rs *= 0.5
    return rs


def fresnel2_into(eta2, c, c2, g, rs, t, rp):
    r"""Twice the unpolarized Fresnel reflectance, :math:`2F = r_s^2 + r_p^2`, into ``rs``.

    ``eta2`` is :math:`\eta^2`, ``c`` and ``c2`` the cosine and its square (broadcasting to
    the buffers); ``g``, ``rs``, ``t``, ``rp`` are distinct float64 buffers of the broadcast
    shape, overwritten. Returns ``rs``. The factor 1/2 is left to the caller: scaling by a
    power of two is exact, so leaving it for later changes no bit of the results.
    """
    np.add(c2, eta2 - 1.0, out=g)
    np.sqrt(g, out=g)
    np.subtract(c, g, out=rs)
    np.add(c, g, out=t)
    rs /= t
    np.multiply(eta2, c, out=t)
    np.subtract(t, g, out=rp)
    t += g
    rp /= t
    rs *= rs
    rp *= rp
    rs += rp
    return rs


class _ShadeParams(NamedTuple):
    """Per-row constants of a flattened batch of nb parameter sets (see thread_shade)."""

    eta2: np.ndarray      # (nb, 1, 1) eta^2
    cs: np.ndarray        # (nb, 1, 1) -1 / (8 gamma_s^2), 1/rad^2
    cv: np.ndarray        # (nb, 1, 1) -1 / (8 gamma_v^2), 1/rad^2
    once: np.ndarray      # (nb,) bool: gamma_v == 2 gamma_s, surface lobe = volume lobe^4
    s_scale: np.ndarray   # (nb, 1) GAUSS_NORM / gamma_s / 2 (the 1/2 of F), 1/rad
    v_scale: np.ndarray   # (nb, 1, 1) (1 - k_d) GAUSS_NORM / gamma_v, 1/rad
    kd: np.ndarray        # (nb, 1, 1)

    def rows(self, sl):
        """The constants of rows ``sl``."""
        return _ShadeParams(*(a[sl] for a in self))


#: eta and the gammas (radians) are taken within these bounds (2^-500..2^500, about
#: 3e-151..3e150), where eta^2 and 1/gamma^2 stay finite: no change for any sane value, and
#: the limits (F_r -> 1, a flat or a needle lobe) beyond.
PARAM_CLAMP = (2.0 ** -500, 2.0 ** 500)

#: The same bounds for float32 shading (2^-60..2^60): eta^2 and 1/(8 gamma^2) stay below
#: float32's largest number (about 2^128).
PARAM_CLAMP_32 = (2.0 ** -60, 2.0 ** 60)

#: The precisions :func:`thread_shade` shades in (that of its geometry's arrays).
SHADE_DTYPES = (np.dtype(np.float64), np.dtype(np.float32))


def shade_dtype(dtype) -> np.dtype:
    """``dtype`` as one of :data:`SHADE_DTYPES`, or a ValueError naming what is allowed.

    >>> shade_dtype("float32").name
    'float32'
    """
    try:
        dt = np.dtype(dtype)
    except TypeError:
        dt = None
    if dt is None or dt not in SHADE_DTYPES:   # (np.dtype(float) == None is True)
        raise ValueError(f"dtype must be numpy.float64 or numpy.float32; got {dtype!r}")
    return dt


def _shade_params(eta, kd, gamma_s, gamma_v, dtype=np.float64) -> _ShadeParams:
    """Row constants from 1-D arrays (nb,) of eta, k_d and the gammas (radians), each
    within :data:`PARAM_CLAMP` (:data:`PARAM_CLAMP_32` for float32), computed in float64
    and given in ``dtype``."""
    c3 = (slice(None), None, None)
    clamp = PARAM_CLAMP if np.dtype(dtype) == np.float64 else PARAM_CLAMP_32
    eta, gamma_s, gamma_v = (np.clip(x, *clamp) for x in (eta, gamma_s, gamma_v))
    s_scale = GAUSS_NORM / gamma_s
    s_scale *= 0.5
    par = _ShadeParams((eta * eta)[c3], (-0.125 / (gamma_s * gamma_s))[c3],
                       (-0.125 / (gamma_v * gamma_v))[c3], gamma_v == 2.0 * gamma_s,
                       s_scale[:, None], ((1.0 - kd) * GAUSS_NORM / gamma_v)[c3], kd[c3])
    if np.dtype(dtype) == np.float64:
        return par
    return _ShadeParams(*(a if a.dtype == bool else a.astype(dtype) for a in par))


def _blocks(nb, nc, ns, block):
    """Slices (rows, pairs) tiling (nb, nc) into blocks of at most about ``block`` (row, pair,
    sample) elements, of near-equal sizes: as many pairs as fit, then as many rows; pairs
    outermost. (Long runs of pairs in a block keep NumPy's inner loops long: by measurement
    few rows of many pairs beat many rows of few pairs.)"""
    rows = max(1, block // ns)
    cb = _even(nc, rows)
    bb = _even(nb, max(1, rows // cb))
    for c0 in range(0, nc, cb):
        for b0 in range(0, nb, bb):
            yield slice(b0, b0 + bb), slice(c0, c0 + cb)


def _even(n, most):
    """The size of near-equal parts of n items, none over ``most`` (at least 1)."""
    parts = -(-n // max(1, most))
    return max(1, -(-n // max(1, parts)))


def _weighted_sum(x, weight, out):
    """out = x @ weight over the last axis (a product, not a matrix call, for one sample)."""
    if weight.size == 1:
        np.multiply(x[..., 0], weight[0], out=out)
    else:
        np.matmul(x, weight, out=out)


def surface_term(geom, weight, par, f2, ev, es, out):
    r"""The surface sums :math:`\sum_t w_t f_{rs} M P \cos\theta_i / \cos^2\theta_d`
    (1/sr) of a block of rows, into ``out`` (b, c).

    :math:`f_{rs} = F_r(\eta, \cos g) \cos(\phi_d/2)\, g(\gamma_s, \theta_h)` (twins:
    ``terms.fresnel``, ``terms.gaussian``): ``f2`` holds 2F and ``ev`` the volume lobe's
    exponential (reused where gamma_v = 2 gamma_s); ``es`` is a buffer, overwritten.
    """
    if par.once.all():
        np.multiply(ev, ev, out=es)     # exp(a)^4 = exp(4 a): gamma_s = gamma_v / 2 (Table II)
        es *= es
    else:
        np.multiply(geom.th2, par.cs, out=es)
        np.exp(es, out=es)
        if par.once.any():              # those rows as in the single-set evaluation
            once = par.once
            lobe = ev[once]
            lobe *= lobe
            lobe *= lobe
            es[once] = lobe
    es *= f2
    es *= geom.ks
    _weighted_sum(es, weight, out)
    out *= par.s_scale


def volume_term(geom, weight, par, f2, ev, transmission, out):
    r"""The volume sums :math:`\sum_t w_t (f_{rv}/A) M P \cos\theta_i / \cos^2\theta_d`
    (1/sr) of a block of rows, into ``out`` (b, c).

    :math:`f_{rv}/A = F_T ((1 - k_d) g(\gamma_v, \theta_h) + k_d) / (\cos\theta_i +
    \cos\theta_r)` (twins: ``terms.transmission``, ``terms.gaussian``), summed as
    :math:`(1-k_d)\,\mathrm{norm} \sum_t w F_T k_v e_v + k_d \sum_t w F_T k_v`. ``f2`` (2F
    of cos g) and ``ev`` (the lobe's exponential) are overwritten.
    """
    if transmission == "half_angle":
        ft = np.subtract(2.0, f2, out=f2)   # 2 (1 - F), exactly; F_T = ft^2 / 4
        ft *= ft
        scale = 0.25
    else:
        ft = 1.0 - _fresnel_from_cos(par.eta2, geom.ci, geom.ci * geom.ci)
        ft *= 1.0 - _fresnel_from_cos(par.eta2, geom.cr, geom.cr * geom.cr)
        scale = 1.0
    ft *= geom.kv
    ev *= ft
    _weighted_sum(ev, weight, out)
    out *= par.v_scale[:, :, 0]
    flat = np.empty_like(out)
    _weighted_sum(ft, weight, flat)
    flat *= par.kd[:, :, 0]
    out += flat
    if scale != 1.0:
        out *= scale


def _shade_block(geom, weight, par, transmission, surf, vol, work):
    """One block of :func:`thread_shade`: geometry (c, S), constants of b rows, outputs (b, c).

    ``work`` is a buffer of the geometry's dtype of at least 4 b c S elements, overwritten.
    """
    shape = (par.eta2.shape[0],) + geom.th2.shape
    n = shape[0] * shape[1] * shape[2]
    a, f2, es, d = (work[k * n:(k + 1) * n].reshape(shape) for k in range(4))
    fresnel2_into(par.eta2, geom.cg, geom.cg2, a, f2, es, d)     # 2F in f2
    # The volume lobe's exponential exp(-theta_h^2 / (2 gamma_v^2)); theta_h^2 = th2 / 4.
    ev = np.multiply(geom.th2, par.cv, out=a)
    np.exp(ev, out=ev)
    surface_term(geom, weight, par, f2, ev, es, surf)
    volume_term(geom, weight, par, f2, ev, transmission, vol)


def thread_shade(geom: ThreadGeometry, weight, eta, kd, gamma_s, gamma_v,
                 transmission="half_angle", *, out=None, block=None, scratch=None):
    r"""Weighted sums of one thread's surface and volume terms.

    Parameters
    ----------
    geom : ThreadGeometry
        From :func:`thread_geometry`, arrays (C, S). Their dtype, float64 or float32 (see
        :meth:`brdf.Prepared.eval`), is the precision of the shading and of the sums.
    weight : ndarray, shape (S,)
        Weights of the distinct tangent samples.
    eta, kd : float or ndarray of shape (B...)
        Index of refraction; isotropic volume share. Arrays shade a batch of parameter sets.
    gamma_s, gamma_v : float or ndarray of shape (B...)
        Lobe widths, radians.
    transmission : {"half_angle", "longitudinal"}
    out : tuple of two ndarray, shape (B..., C), optional
        C-contiguous arrays of the geometry's dtype to write ``surf`` and ``vol`` into
        (returned).
    block : int, optional
        Target number of (parameter set, pair, sample) elements per block (default
        :data:`SHADE_BLOCK`): the batch and the pairs are shaded in blocks of about this
        size, so that the temporaries stay in cache. Only the speed and the rounding of
        the weighted sums depend on it.
    scratch : brdf.scratch.Scratch, optional
        Where the block temporaries are kept between calls (else allocated per call).

    Returns
    -------
    surf, vol : ndarray, shape (B..., C)
        :math:`\frac1N\sum_t f_{rs} M P \cos\theta_i` and the same for :math:`f_{rv}/A`, in 1/sr
        (before the division by Q and n . wi).

    Notes
    -----
    :math:`f_{rs} = F_r(\eta, \cos g)\cos(\phi_d/2)\, g(\gamma_s, \theta_h) / \cos^2\theta_d`,
    :math:`f_{rv} = F_T\,((1-k_d) g(\gamma_v, \theta_h) + k_d) / (\cos\theta_i + \cos\theta_r)
    \,A / \cos^2\theta_d`, with :math:`g(\gamma, x) = e^{-x^2/2\gamma^2}/(\gamma\sqrt{2\pi})`
    and :math:`\theta_h^2 = \mathrm{th2}/4`. Where :math:`\gamma_v = 2\gamma_s` (Table II) the
    surface lobe is the volume lobe to the fourth power, one ``exp`` for both.
    """
    dtype = shade_dtype(geom.th2.dtype)
    params = [np.asarray(x, dtype=np.float64) for x in (eta, kd, gamma_s, gamma_v)]
    batch = np.broadcast_shapes(*(x.shape for x in params))
    nb = math.prod(batch)
    par = _shade_params(*(np.broadcast_to(x, batch).reshape(nb) for x in params), dtype=dtype)
    weight = np.asarray(weight, dtype=dtype)
    nc, ns = geom.th2.shape
    if out is None:
        out = (np.empty(batch + (nc,), dtype), np.empty(batch + (nc,), dtype))
    surf, vol = (o.reshape(nb, nc) for o in out)
    block = SHADE_BLOCK if block is None else max(1, int(block))
    size = 4 * min(nb * nc * ns, max(block, ns))
    work = np.empty(size, dtype) if scratch is None else scratch.array("shade", (size,), dtype)
    for rows, pairs in _blocks(nb, nc, ns, block):
        g = ThreadGeometry(*(None if x is None else x[pairs] for x in geom))
        _shade_block(g, weight, par.rows(rows), transmission, surf[rows, pairs],
                     vol[rows, pairs], work)
    return out


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
