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

from brdf.combine import DENOM_MIN  # noqa: F401  (its older home: gonio.rgl imports it here)
from brdf.kernel import ThreadGeometry
from brdf.options import Transmission, validate_method

__all__ = ["thread_shade", "fresnel2_into", "transmission_into", "gaussian_norm",
           "gaussian_exponent", "gaussian_into", "surface_term", "volume_term", "f_rv",
           "f_rv_coefficients", "shade_dtype", "GAUSS_NORM", "SHADE_BLOCK", "SHADE_DTYPES"]

GAUSS_NORM = 1.0 / np.sqrt(2.0 * np.pi)

#: Default (parameter set, pair, sample) elements per block of :func:`thread_shade`: each of
#: its four float64 temporaries then takes 1 MiB. Chosen by bench/bench_prepared.py (2 cores,
#: 1 MiB L2 each, 32 MiB L3): blocks of 2^14..2^15, which stay in L2, lost more to the ~25
#: NumPy calls a block costs than they gained; 2^18 was no faster.
SHADE_BLOCK = 1 << 17

def gaussian_norm(gamma):
    r"""The factor :math:`1/(\gamma\sqrt{2\pi})` of MODEL.md's unit-area Gaussian g, 1/rad.

    >>> float(gaussian_norm(1.0)) == float(GAUSS_NORM)
    True
    """
    return GAUSS_NORM / gamma


def gaussian_exponent(gamma):
    r"""The exponent of g per unit of ``th2`` = :math:`(\theta_i + \theta_r)^2 = 4\theta_h^2`:
    :math:`-1/(8\gamma^2)`, 1/rad^2, so that :math:`e^{-\theta_h^2/(2\gamma^2)} =
    e^{\mathrm{th2}\cdot(-1/(8\gamma^2))}`."""
    return -0.125 / (gamma * gamma)


def gaussian_into(th2, exponent, out):
    r"""The exponential of MODEL.md's Gaussian :math:`g(\gamma, \theta_h)`, into ``out``:
    :math:`\exp(\mathrm{th2}\cdot\mathrm{exponent})` (``exponent`` from
    :func:`gaussian_exponent`); g is this times :func:`gaussian_norm`, a per-row factor the
    callers apply after the sum over samples (twin: ``terms.gaussian``). Returns ``out``."""
    np.multiply(th2, exponent, out=out)
    np.exp(out, out=out)
    return out


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
    s_scale = gaussian_norm(gamma_s)
    s_scale *= 0.5
    par = _ShadeParams((eta * eta)[c3], gaussian_exponent(gamma_s)[c3],
                       gaussian_exponent(gamma_v)[c3], gamma_v == 2.0 * gamma_s,
                       s_scale[:, None], f_rv_coefficients(kd, gamma_v)[c3], kd[c3])
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
        gaussian_into(geom.th2, par.cs, es)
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


def transmission_into(f2, geom, eta2, transmission):
    r"""MODEL.md's transmission F_T, up to a constant factor: ``(ft, scale)`` with
    :math:`F_T` = ``ft * scale``.

    ``"half_angle"``: :math:`F_T = (1 - F_r(\eta, \cos g))^2` = (2 - 2F)^2 / 4, formed in
    ``f2`` (2F of cos g, overwritten; scale 1/4, a power of two: exact);
    ``"longitudinal"``: :math:`(1 - F_r(\eta, \cos\theta_i))(1 - F_r(\eta,
    \cos\theta_r))` from the geometry's cosines (a new array; scale 1). Twin:
    ``terms.transmission``.
    """
    if transmission is Transmission.HALF_ANGLE:
        ft = np.subtract(2.0, f2, out=f2)   # 2 (1 - F), exactly; F_T = ft^2 / 4
        ft *= ft
        return ft, 0.25
    ft = 1.0 - _fresnel_from_cos(eta2, geom.ci, geom.ci * geom.ci)
    ft *= 1.0 - _fresnel_from_cos(eta2, geom.cr, geom.cr * geom.cr)
    return ft, 1.0


def f_rv_coefficients(kd, gamma_v):
    r"""The per-row factor of f_rv's lobe, :math:`(1 - k_d)/(\gamma_v\sqrt{2\pi})`, 1/rad
    (its flat part's factor is k_d itself): :math:`(1 - k_d) g(\gamma_v, \theta_h) + k_d`
    is this times the lobe's exponential (:func:`gaussian_into`) plus k_d."""
    return (1.0 - kd) * GAUSS_NORM / gamma_v


def f_rv(ft, ev, weight, v_scale, kd, scale, out):
    r"""MODEL.md's volume term f_rv, summed over the samples: into ``out`` (b, c),
    :math:`\sum_t w_t\, (f_{rv}/A)\, k` in 1/sr.

    .. math::
        f_{rv} = A\, F_T\, ((1 - k_d)\, g(\gamma_v, \theta_h) + k_d)
        / (\cos\theta_i + \cos\theta_r)

    assembled from its factors, each computed where it is cheapest and named after it:
    ``ft`` (b, c, S) is F_T / ``scale`` (:func:`transmission_into`) already multiplied by
    ``kv`` = k / (cos theta_i + cos theta_r) (:func:`brdf.kernel.f_rv_geometry`, per pair and
    sample, k the common factor cos(theta_i) M P / cos^2(theta_d)); ``ev`` (b, c, S) the
    lobe's exponential (:func:`gaussian_into`), overwritten; ``v_scale`` (b, 1) the factor
    :func:`f_rv_coefficients` and ``kd`` (b, 1) k_d, per row. The sum is taken as
    :math:`v \sum_t w F_T k_v e_v + k_d \sum_t w F_T k_v`; the albedo A, constant over
    the samples, multiplies the sums in :func:`brdf.combine.combine_rgb`.
    """
    ev *= ft
    _weighted_sum(ev, weight, out)
    out *= v_scale
    flat = np.empty_like(out)
    _weighted_sum(ft, weight, flat)
    flat *= kd
    out += flat
    if scale != 1.0:
        out *= scale


def volume_term(geom, weight, par, f2, ev, transmission, out):
    r"""The volume sums :math:`\sum_t w_t (f_{rv}/A) M P \cos\theta_i / \cos^2\theta_d`
    (1/sr) of a block of rows, into ``out`` (b, c): :func:`transmission_into`, then
    :func:`f_rv` (twins: ``terms.transmission``, ``terms.gaussian``). ``f2`` (2F of cos g)
    and ``ev`` (the lobe's exponential) are overwritten.
    """
    ft, scale = transmission_into(f2, geom, par.eta2, transmission)
    ft *= geom.kv
    f_rv(ft, ev, weight, par.v_scale[:, :, 0], par.kd[:, :, 0], scale, out)


def _shade_block(geom, weight, par, transmission, surf, vol, work):
    """One block of :func:`thread_shade`: geometry (c, S), constants of b rows, outputs (b, c).

    ``work`` is a buffer of the geometry's dtype of at least 4 b c S elements, overwritten.
    """
    shape = (par.eta2.shape[0],) + geom.th2.shape
    n = shape[0] * shape[1] * shape[2]
    a, f2, es, d = (work[k * n:(k + 1) * n].reshape(shape) for k in range(4))
    fresnel2_into(par.eta2, geom.cg, geom.cg2, a, f2, es, d)     # 2F in f2
    # The volume lobe's exponential exp(-theta_h^2 / (2 gamma_v^2)); theta_h^2 = th2 / 4.
    ev = gaussian_into(geom.th2, par.cv, a)
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
    transmission = validate_method("transmission", transmission, Transmission)
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
