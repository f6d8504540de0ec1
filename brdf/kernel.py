r"""The fast evaluation of the microcylinder model, split into geometry and shading.

``thread_geometry`` computes, for one thread and a chunk of direction pairs, everything that
depends on the directions and the tangent samples but not on the optical parameters (eta,
k_d, the gammas, albedo, area). ``thread_shade`` turns that into the thread's weighted sums
for given parameters. ``Fabric.eval`` runs both per chunk; ``Fabric.prepare`` keeps the
geometry so that a fit can shade the same pairs for many parameter sets.

No angle is formed by atan2 of single directions: every cosine the model needs comes from
dot products, and the three angles whose squares enter Gaussians come from one ``arccos`` each:

.. math::
    \cos(\theta_i + \theta_r) &= \cos\theta_i\cos\theta_r - \sin\theta_i\sin\theta_r,
        \qquad \theta_h^2 = \arccos(\cdot)^2 / 4,\\
    \cos\phi_d &= (x_i x_r + y_i y_r) / (\cos\theta_i \cos\theta_r),\\
    \cos\psi_d &= (x_i x_r + s_i s_r) / (\rho_i \rho_r),

with :math:`s = w\cdot t`, :math:`x = w\cdot n_t`, :math:`y = w\cdot b`,
:math:`\cos\theta = \sqrt{x^2 + y^2}` and :math:`\rho = \sqrt{x^2 + s^2} = \sqrt{(w\cdot n)^2 +
(w\cdot t_0)^2}`, which does not depend on the tangent offset. Near zero angles arccos loses
digits in the angle but not in its square, which is all the Gaussians see.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from brdf.terms import SIGMA_U

__all__ = ["ThreadGeometry", "thread_geometry", "thread_shade", "GAUSS_NORM"]

_K_U = -0.5 / SIGMA_U**2          # u(x) = exp(_K_U x^2)
GAUSS_NORM = 1.0 / np.sqrt(2.0 * np.pi)

#: Default (parameter set, pair, sample) elements per block of :func:`thread_shade`: each of
#: its four float64 temporaries then takes 1 MiB. Chosen by bench/bench_prepared.py (2 cores,
#: 1 MiB L2 each, 32 MiB L3): blocks of 2^14..2^15, which stay in L2, lost more to the ~25
#: NumPy calls a block costs than they gained; 2^18 was no faster.
SHADE_BLOCK = 1 << 17


class ThreadGeometry(NamedTuple):
    """Direction-dependent, parameter-independent quantities of one thread.

    Arrays have shape (C, S): C pairs by S distinct tangent samples.
    """

    th2: np.ndarray     # (theta_i + theta_r)^2 = 4 theta_h^2, rad^2
    cg: np.ndarray      # cos_g = cos(theta_d) cos(phi_d / 2)
    cg2: np.ndarray     # cos_g^2
    ks: np.ndarray      # M P cos(theta_i) cos(phi_d / 2) / cos^2(theta_d)
    kv: np.ndarray      # M P cos(theta_i) / (cos^2(theta_d) (cos(theta_i) + cos(theta_r)))
    ci: np.ndarray | None   # longitudinal cosines, kept for transmission="longitudinal"
    cr: np.ndarray | None
    pmean: np.ndarray | None  # (C,) weighted mean of P over the samples (for Q)


def thread_geometry(ti, bi, zi, to, bo, zo, ca, sa, weight, *, masking=True,
                    reweighting=True, keep_cos=False) -> ThreadGeometry:
    r"""Geometry of one thread for a chunk of pairs.

    Parameters
    ----------
    ti, bi, zi : ndarray, shape (C, 1)
        wi . t0, wi . b, wi . n for the thread's in-plane tangent t0 and b = n x t0.
    to, bo, zo : ndarray, shape (C, 1)
        The same for wo.
    ca, sa : ndarray, shape (S,)
        cos and sin of the distinct tangent offsets alpha.
    weight : ndarray, shape (S,)
        Weights of the distinct offsets (sum 1).
    masking, reweighting : bool
        Toggles of MODEL.md; off means M = 1 (resp. P = 1 and no P-mean).
    keep_cos : bool
        Keep cos(theta_i), cos(theta_r) (needed by the longitudinal transmission).

    Returns
    -------
    ThreadGeometry

    Notes
    -----
    With :math:`t(\alpha) = \cos\alpha\, t_0 + \sin\alpha\, n` and
    :math:`n_t(\alpha) = \cos\alpha\, n - \sin\alpha\, t_0`:
    :math:`s = w\cdot t`, :math:`x = w\cdot n_t`, and
    :math:`M = (1-u(\phi_d)) M_i M_r + u(\phi_d)\min(M_i, M_r)`, :math:`M_i = \max(x_i, 0)/\cos\theta_i`;
    :math:`P` likewise with :math:`P_i = \max(x_i, 0)/\rho_i` and :math:`\psi_d`.
    Where a direction lies along the tangent (cos theta = 0) its azimuth phi is taken as 0,
    as atan2(0, 0) = 0 in MODEL.md's definition; there the thread's term carries the factor
    cos(theta_i) = 0 (wi side) or is finite (wo side). Where cos^2(theta_d) rounds to 0
    (wi and wo both grazing along the tangent, opposite), the sample's term is 0: the spec's
    f_s diverges there while P vanishes, and no finite-precision value is meaningful.
    """
    # Longitudinal sines s = w.t and normal components x = w.n_t of every (pair, sample).
    si = ti * ca
    si += zi * sa
    xi = zi * ca
    xi -= ti * sa
    sr = to * ca
    sr += zo * sa
    xr = zo * ca
    xr -= to * sa
    bi2 = bi * bi
    bo2 = bo * bo
    ci = xi * xi
    ci += bi2
    np.sqrt(ci, out=ci)
    cr = xr * xr
    cr += bo2
    np.sqrt(cr, out=cr)
    cc = ci * cr
    ss = si * sr
    # 2 cos^2(theta_d) = 1 + cos(theta_i - theta_r)
    c2d = cc + ss
    c2d += 1.0
    # (theta_i + theta_r)^2 from cos(theta_i + theta_r)
    th2 = cc - ss
    np.clip(th2, -1.0, 1.0, out=th2)
    np.arccos(th2, out=th2)
    th2 *= th2
    xx = xi * xr
    degenerate = ci.min() == 0.0 or cr.min() == 0.0
    if degenerate:
        # Directions along a tangent sample: azimuth phi := 0, i.e. (x, y)/cos = (1, 0).
        zi_, zr_ = ci == 0.0, cr == 0.0
        xi_p, ci_p = np.where(zi_, 1.0, xi), np.where(zi_, 1.0, ci)
        xr_p, cr_p = np.where(zr_, 1.0, xr), np.where(zr_, 1.0, cr)
        yi_p, yr_p = np.where(zi_, 0.0, bi), np.where(zr_, 0.0, bo)
        cphi = xi_p * xr_p + yi_p * yr_p
        cphi /= ci_p * cr_p
    else:
        xi_p, ci_p, xr_p, cr_p = xi, ci, xr, cr
        cphi = bi * bo
        cphi = cphi + xx
        cphi /= cc
    np.clip(cphi, -1.0, 1.0, out=cphi)
    if c2d.min() == 0.0:
        # cos^2(theta_d) = 0 only with theta_i = -theta_r = +-pi/2, where cos(theta_i) is 0 or
        # round-off: the term is taken as 0 there (see Notes).
        zero = c2d == 0.0
        np.copyto(c2d, 1.0, where=zero)
        np.copyto(ci_k := ci.copy(), 0.0, where=zero)
    else:
        ci_k = ci
    # K = 2 cos(theta_i) / (2 cos^2 theta_d), the factor 2 applied with ks and kv below.
    k = ci_k / c2d
    pmean = None
    if masking or reweighting:
        mxi = np.maximum(xi, 0.0)
        mxr = np.maximum(xr, 0.0)
    if masking:
        if degenerate:
            mi = np.maximum(xi_p, 0.0) / ci_p
            mr = np.maximum(xr_p, 0.0) / cr_p
        else:
            mi = mxi / ci
            mr = mxr / cr
        _blend(mi, mr, cphi, k)
    if reweighting:
        irho_i = 1.0 / np.sqrt(zi * zi + ti * ti)
        irho_o = 1.0 / np.sqrt(zo * zo + to * to)
        mxi *= irho_i
        mxr *= irho_o
        cpsi = xx + ss
        cpsi *= irho_i * irho_o
        np.clip(cpsi, -1.0, 1.0, out=cpsi)
        p = _blend(mxi, mxr, cpsi, k)
        pmean = p @ weight
    # cos^2 g = cos^2(theta_d) cos^2(phi_d / 2) = (c2d / 2) ((1 + cos phi_d) / 2)
    hp = cphi
    hp += 1.0
    cg2 = c2d * hp
    cg2 *= 0.25
    cg = np.sqrt(cg2)
    hp *= 0.5
    np.sqrt(hp, out=hp)          # cos(phi_d / 2) >= 0
    k *= 2.0
    ks = hp
    ks *= k
    kv = ci + cr
    if degenerate:
        np.copyto(kv, 1.0, where=kv == 0.0)   # both along the tangent: k = 0 there
    np.divide(k, kv, out=kv)
    return ThreadGeometry(th2, cg, cg2, ks, kv, ci if keep_cos else None,
                          cr if keep_cos else None, pmean)


def _blend(a, b, cos_delta, k):
    r"""Pair visibility :math:`(1-u)ab + u\min(a, b)`, with :math:`u = u(\arccos c)`.

    Multiplies ``k`` by the result in place and returns the result (computed in ``a``'s
    storage). ``a`` and ``b`` are overwritten.
    """
    u = np.arccos(cos_delta)
    u *= u
    u *= _K_U
    np.exp(u, out=u)
    prod = a * b
    np.minimum(a, b, out=a)
    a -= prod
    a *= u
    a += prod
    k *= a
    return a


def _fresnel_from_cos(eta2, c, c2):
    """Unpolarized dielectric Fresnel reflectance from c = cos and c2 = cos^2 (broadcasting)."""
    shape = np.broadcast_shapes(np.shape(eta2), np.shape(c), np.shape(c2))
    rs = _fresnel2_into(eta2, c, c2, *(np.empty(shape) for _ in range(4)))
    rs *= 0.5
    return rs


def _fresnel2_into(eta2, c, c2, g, rs, t, rp):
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


def _shade_params(eta, kd, gamma_s, gamma_v) -> _ShadeParams:
    """Row constants from 1-D arrays (nb,) of eta, k_d and the gammas (radians)."""
    c3 = (slice(None), None, None)
    s_scale = GAUSS_NORM / gamma_s
    s_scale *= 0.5
    return _ShadeParams((eta * eta)[c3], (-0.125 / (gamma_s * gamma_s))[c3],
                        (-0.125 / (gamma_v * gamma_v))[c3], gamma_v == 2.0 * gamma_s,
                        s_scale[:, None], ((1.0 - kd) * GAUSS_NORM / gamma_v)[c3], kd[c3])


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


def _shade_block(geom, weight, par, transmission, surf, vol, work):
    """One block of :func:`thread_shade`: geometry (c, S), constants of b rows, outputs (b, c).

    ``work`` is a float64 buffer of at least 4 b c S elements, overwritten.
    """
    shape = (par.eta2.shape[0],) + geom.th2.shape
    n = shape[0] * shape[1] * shape[2]
    a, f2, es, d = (work[k * n:(k + 1) * n].reshape(shape) for k in range(4))
    _fresnel2_into(par.eta2, geom.cg, geom.cg2, a, f2, es, d)     # 2F in f2
    # Volume lobe exp(-theta_h^2 / (2 gamma_v^2)); theta_h^2 = th2 / 4.
    ev = np.multiply(geom.th2, par.cv, out=a)
    np.exp(ev, out=ev)
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
    _weighted_sum(es, weight, surf)
    surf *= par.s_scale
    if transmission == "half_angle":
        ft = np.subtract(2.0, f2, out=f2)   # 2 (1 - F), exactly
        ft *= ft
        scale = 0.25
    else:
        ft = 1.0 - _fresnel_from_cos(par.eta2, geom.ci, geom.ci * geom.ci)
        ft *= 1.0 - _fresnel_from_cos(par.eta2, geom.cr, geom.cr * geom.cr)
        scale = 1.0
    ev *= par.v_scale
    ev += par.kd
    ev *= ft
    ev *= geom.kv
    _weighted_sum(ev, weight, vol)
    if scale != 1.0:
        vol *= scale


def thread_shade(geom: ThreadGeometry, weight, eta, kd, gamma_s, gamma_v,
                 transmission="half_angle", *, out=None, block=None):
    r"""Weighted sums of one thread's surface and volume terms.

    Parameters
    ----------
    geom : ThreadGeometry
        From :func:`thread_geometry`, arrays (C, S).
    weight : ndarray, shape (S,)
        Weights of the distinct tangent samples.
    eta, kd : float or ndarray of shape (B...)
        Index of refraction; isotropic volume share. Arrays shade a batch of parameter sets.
    gamma_s, gamma_v : float or ndarray of shape (B...)
        Lobe widths, radians.
    transmission : {"half_angle", "longitudinal"}
    out : tuple of two ndarray, shape (B..., C), optional
        C-contiguous float64 arrays to write ``surf`` and ``vol`` into (returned).
    block : int, optional
        Target number of (parameter set, pair, sample) elements per block (default
        :data:`SHADE_BLOCK`): the batch and the pairs are shaded in blocks of about this
        size, so that the temporaries stay in cache. Only the speed and the rounding of
        the weighted sums depend on it.

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
    params = [np.asarray(x, dtype=np.float64) for x in (eta, kd, gamma_s, gamma_v)]
    batch = np.broadcast_shapes(*(x.shape for x in params))
    nb = math.prod(batch)
    par = _shade_params(*(np.broadcast_to(x, batch).reshape(nb) for x in params))
    nc, ns = geom.th2.shape
    if out is None:
        out = (np.empty(batch + (nc,)), np.empty(batch + (nc,)))
    surf, vol = (o.reshape(nb, nc) for o in out)
    block = SHADE_BLOCK if block is None else max(1, int(block))
    work = np.empty(4 * min(nb * nc * ns, max(block, ns)))
    for rows, pairs in _blocks(nb, nc, ns, block):
        g = ThreadGeometry(*(None if x is None else x[pairs] for x in geom))
        _shade_block(g, weight, par.rows(rows), transmission, surf[rows, pairs],
                     vol[rows, pairs], work)
    return out
