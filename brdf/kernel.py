r"""The fast evaluation of the microcylinder model, in MODEL.md's names.

:func:`thread_geometry` computes, for one thread and a chunk of direction pairs, everything
that depends on the directions and the tangent samples but not on the optical parameters
(eta, k_d, the gammas, albedo, area); :func:`brdf.shading.thread_shade` turns that into the
thread's weighted sums for given parameters. :class:`brdf.FabricPlan` runs both per chunk
(``Fabric.eval``); ``Fabric.prepare`` keeps the geometry so that a fit can shade the same pairs
for many parameter sets.

The blocks carry the names of MODEL.md, and each has a twin in :mod:`brdf.terms` (the same
equation written from angles) that ``tests/test_brdf_kernel.py`` compares it with (the table of
every name, shading's included, is in :mod:`brdf`'s docstring)::

    block              computes                                    twin in brdf.terms
    longitudinal       s = sin(theta) = w.t, x = w.n_t, cos(theta)  (the frame of MODEL.md)
    half_difference    (theta_i + theta_r)^2, 2 cos^2(theta_d)      --
    azimuth            cos(phi_d)                                   --
    masking            M(wi, wo)                                    pair_weight, visibility
    reweighting        P(wi, wo) and its mean over samples          pair_weight, visibility
    u_of_cos           u(delta) from cos(delta)                     u
    f_rs_geometry      k cos(phi_d / 2), f_rs's direction factor     cos(phi_d / 2), in the tests
    f_rv_geometry      k / (cos theta_i + cos theta_r), f_rv's one   1 / (ci + cr), in the tests

Symbols (arrays (C, S): C pairs by S distinct tangent samples; suffix i for wi, r for wo):

========  =====================================================================
``s``     w . t = sin(theta), the longitudinal sine
``x``     w . n_t; ``y`` = w . b (does not depend on the tangent offset)
``c``     cos(theta) = sqrt(x^2 + y^2), the longitudinal cosine
``th2``   (theta_i + theta_r)^2 = 4 theta_h^2, rad^2
``c2d``   2 cos^2(theta_d) = 1 + cos(theta_i - theta_r)
``cphi``  cos(phi_d);  ``cpsi`` cos(psi_d)
``cg``    cos_g = cos(theta_d) cos(phi_d / 2), the effective incidence cosine
``k``     cos(theta_i) M P / cos^2(theta_d), the geometric factor of both terms
``ks``    k cos(phi_d / 2) (surface);  ``kv`` k / (cos(theta_i) + cos(theta_r)) (volume)
========  =====================================================================

No angle is formed by atan2 of single directions: every cosine the model needs comes from
dot products, and the three angles whose squares enter Gaussians come from one ``arccos`` each:

.. math::
    \cos(\theta_i + \theta_r) &= \cos\theta_i\cos\theta_r - \sin\theta_i\sin\theta_r,
        \qquad \theta_h^2 = \arccos(\cdot)^2 / 4,\\
    \cos\phi_d &= (x_i x_r + y_i y_r) / (\cos\theta_i \cos\theta_r),\\
    \cos\psi_d &= (x_i x_r + s_i s_r) / (\rho_i \rho_r),

with :math:`\rho = \sqrt{x^2 + s^2} = \sqrt{(w\cdot n)^2 + (w\cdot t_0)^2}`, which does not
depend on the tangent offset. Near zero angles arccos loses digits in the angle but not in its
square, which is all the Gaussians see.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from brdf.terms import SIGMA_U

__all__ = ["ThreadGeometry", "Sides", "thread_geometry", "longitudinal", "half_difference",
           "azimuth", "masking", "reweighting", "pair_blend", "u_of_cos", "f_rs_geometry",
           "f_rv_geometry"]

_K_U = -0.5 / SIGMA_U**2          # u(x) = exp(_K_U x^2)
#: Below this a cosine or an in-plane length is "tiny": its square may underflow (2^-500,
#: about 3e-151), so the blocks take the slower careful forms (hypot, ratios before products).
_TINY = 2.0 ** -500


class ThreadGeometry(NamedTuple):
    """Direction-dependent, parameter-independent quantities of one thread.

    Arrays have shape (C, S): C pairs by S distinct tangent samples (symbols of the module
    notes).
    """

    th2: np.ndarray     # (theta_i + theta_r)^2 = 4 theta_h^2, rad^2
    cg: np.ndarray      # cos_g = cos(theta_d) cos(phi_d / 2)
    cg2: np.ndarray     # cos_g^2
    ks: np.ndarray      # 2 cos(theta_i) M P cos(phi_d / 2) / (2 cos^2(theta_d))
    kv: np.ndarray      # 2 cos(theta_i) M P / (2 cos^2(theta_d) (cos(theta_i) + cos(theta_r)))
    ci: np.ndarray | None   # longitudinal cosines, kept for transmission="longitudinal"
    cr: np.ndarray | None
    pmean: np.ndarray | None  # (C,) weighted mean of P over the samples (for Q)


class Sides(NamedTuple):
    """Both directions in the frame (t, b, n_t) of every tangent sample: arrays (C, S)."""

    si: np.ndarray      # wi . t = sin(theta_i)
    xi: np.ndarray      # wi . n_t
    ci: np.ndarray      # cos(theta_i) = sqrt(xi^2 + (wi . b)^2)
    sr: np.ndarray      # the same for wo
    xr: np.ndarray
    cr: np.ndarray


def longitudinal(ti, bi, zi, to, bo, zo, ca, sa) -> Sides:
    r"""Longitudinal sines and cosines of both directions for every tangent sample.

    Parameters
    ----------
    ti, bi, zi, to, bo, zo : ndarray, shape (C, 1)
        w . t0, w . b, w . n of wi and of wo for the thread's in-plane tangent t0, b = n x t0.
    ca, sa : ndarray, shape (S,)
        cos and sin of the distinct tangent offsets alpha.

    Returns
    -------
    Sides
        :math:`s = w\cdot t`, :math:`x = w\cdot n_t` and :math:`\cos\theta = \sqrt{x^2 +
        y^2}` with :math:`t = \cos\alpha\, t_0 + \sin\alpha\, n`, :math:`n_t = \cos\alpha\,
        n - \sin\alpha\, t_0`.
    """
    out = []
    for t, b, z in ((ti, bi, zi), (to, bo, zo)):
        s = t * ca
        s += z * sa
        x = z * ca
        x -= t * sa
        c = x * x
        c += b * b
        np.sqrt(c, out=c)
        out += [s, x, c]
    return Sides(*out)


def half_difference(sd: Sides):
    """``th2`` = (theta_i + theta_r)^2 (rad^2), ``c2d`` = 2 cos^2(theta_d), and the products
    ``cc`` = cos(theta_i) cos(theta_r), ``ss`` = sin(theta_i) sin(theta_r)."""
    cc = sd.ci * sd.cr
    ss = sd.si * sd.sr
    c2d = cc + ss                  # 2 cos^2(theta_d) = 1 + cos(theta_i - theta_r)
    c2d += 1.0
    th2 = cc - ss                  # cos(theta_i + theta_r)
    np.clip(th2, -1.0, 1.0, out=th2)
    np.arccos(th2, out=th2)
    th2 *= th2
    return th2, c2d, cc, ss


def azimuth(sd: Sides, bi, bo, cc, degenerate: bool, tiny: bool = False):
    r"""cos(phi_d) (clipped to [-1, 1]) and the directions' (x, cos theta) used for M.

    :math:`\cos\phi_d = (x_i x_r + y_i y_r) / (\cos\theta_i\cos\theta_r)`. With
    ``degenerate`` (some direction along a tangent sample, cos theta = 0) its azimuth is taken
    as 0, atan2(0, 0) = 0 in MODEL.md: (x, y) / cos theta := (1, 0) there. With ``tiny``
    (some cos theta below 2^-500, whose product may underflow) each direction's (x, y) is
    divided by its own cos theta first.

    Returns
    -------
    cphi : ndarray (C, S)
    frame : tuple (xi, ci, xr, cr)
        The components M(w) = max(x, 0) / cos(theta) is formed from.
    """
    xi, ci, xr, cr = sd.xi, sd.ci, sd.xr, sd.cr
    if tiny:
        (xi, yi), (xr, yr) = _unit_xy(xi, bi, ci), _unit_xy(xr, bo, cr)
        cphi = xi * xr + yi * yr
        one = np.ones_like(cphi)
        np.clip(cphi, -1.0, 1.0, out=cphi)
        return cphi, (xi, one, xr, one)
    if degenerate:
        zi_, zr_ = ci == 0.0, cr == 0.0
        xi, ci = np.where(zi_, 1.0, xi), np.where(zi_, 1.0, ci)
        xr, cr = np.where(zr_, 1.0, xr), np.where(zr_, 1.0, cr)
        cphi = xi * xr + np.where(zi_, 0.0, bi) * np.where(zr_, 0.0, bo)
        cphi /= ci * cr
    else:
        cphi = bi * bo
        cphi = cphi + sd.xi * sd.xr
        cphi /= cc
    np.clip(cphi, -1.0, 1.0, out=cphi)
    return cphi, (xi, ci, xr, cr)


def _unit_xy(x, y, c):
    """(x, y) / c with c = hypot(x, y); (1, 0) where c = 0 (MODEL.md's atan2(0, 0) = 0)."""
    zero = c == 0.0
    safe = np.where(zero, 1.0, c)
    return np.where(zero, 1.0, x / safe), np.where(zero, 0.0, y / safe)


def masking(frame, cphi, k):
    r"""Shadowing and masking :math:`M(w_i, w_o)`, multiplied into ``k`` in place.

    :math:`M(w) = \max(\cos\phi, 0)` with :math:`\cos\phi = x / \cos\theta`, blended by
    :func:`pair_blend` over :math:`\phi_d` (twin: ``terms.pair_weight``).
    """
    xi, ci, xr, cr = frame
    mi = np.maximum(xi, 0.0)
    mi /= ci
    mr = np.maximum(xr, 0.0)
    mr /= cr
    return pair_blend(mi, mr, cphi, k)


def reweighting(sd: Sides, ti, zi, to, zo, ss, k, weight):
    r"""Reweighting by visible length :math:`P(w_i, w_o)`, multiplied into ``k`` in place.

    :math:`P(w) = \max(\cos\psi, 0) = \max(x, 0) / \rho`, :math:`\cos\psi_d = (x_i x_r +
    s_i s_r) / (\rho_i\rho_r)` (twin: ``terms.pair_weight`` of ``terms.visibility``).

    Returns
    -------
    ndarray, shape (C,)
        The weighted mean of P over the samples (for Q).
    """
    rho_i, rho_o = np.sqrt(zi * zi + ti * ti), np.sqrt(zo * zo + to * to)
    if rho_i.size and min(rho_i.min(), rho_o.min()) < _TINY:   # squares may underflow, 1/rho overflow
        rho_i, rho_o = np.hypot(zi, ti), np.hypot(zo, to)    # > 0 above the horizon
        ui, vi, ur, vr = sd.xi / rho_i, sd.si / rho_i, sd.xr / rho_o, sd.sr / rho_o
        cpsi = ui * ur + vi * vr
        pi, pr = np.maximum(ui, 0.0), np.maximum(ur, 0.0)
    else:
        irho_i = 1.0 / rho_i
        irho_o = 1.0 / rho_o
        pi = np.maximum(sd.xi, 0.0)
        pi *= irho_i
        pr = np.maximum(sd.xr, 0.0)
        pr *= irho_o
        cpsi = sd.xi * sd.xr
        cpsi += ss
        cpsi *= irho_i * irho_o
    np.clip(cpsi, -1.0, 1.0, out=cpsi)
    return pair_blend(pi, pr, cpsi, k) @ weight


def thread_geometry(ti, bi, zi, to, bo, zo, ca, sa, weight, *, with_masking=True,
                    with_reweighting=True, keep_cos=False) -> ThreadGeometry:
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
    with_masking, with_reweighting : bool
        Toggles ``masking`` and ``reweighting`` of MODEL.md; off means M = 1 (resp. P = 1
        and no P-mean).
    keep_cos : bool
        Keep cos(theta_i), cos(theta_r) (needed by the longitudinal transmission).

    Returns
    -------
    ThreadGeometry

    Notes
    -----
    The blocks :func:`longitudinal`, :func:`half_difference`, :func:`azimuth`,
    :func:`masking` and :func:`reweighting`, then :math:`\cos^2 g = (c2d / 2)(1 + \cos\phi_d)
    / 2`. Where cos^2(theta_d) rounds to 0 (wi and wo both grazing along the tangent,
    opposite), the sample's term is 0: the spec's f_s diverges there while P vanishes, and no
    finite-precision value is meaningful. Where a direction lies along the tangent, the term
    carries the factor cos(theta_i) = 0 (wi side) or is finite (wo side).
    """
    sd = longitudinal(ti, bi, zi, to, bo, zo, ca, sa)
    tiny = sd.ci.size > 0 and min(sd.ci.min(), sd.cr.min()) < _TINY
    degenerate = False               # some cos theta = 0 (a direction along a sample)
    if tiny:                         # x^2 + y^2 may have underflowed: cos theta by hypot
        sd = sd._replace(ci=np.hypot(sd.xi, bi), cr=np.hypot(sd.xr, bo))
        degenerate = sd.ci.min() == 0.0 or sd.cr.min() == 0.0
    th2, c2d, cc, ss = half_difference(sd)
    cphi, frame = azimuth(sd, bi, bo, cc, degenerate, tiny)
    ci_k = sd.ci
    if c2d.size and c2d.min() == 0.0:            # theta_i = -theta_r = +-pi/2: the term is 0 (Notes)
        zero = c2d == 0.0
        np.copyto(c2d, 1.0, where=zero)
        np.copyto(ci_k := sd.ci.copy(), 0.0, where=zero)
    k = ci_k / c2d                   # cos(theta_i) / (2 cos^2 theta_d); x2 with ks, kv
    if with_masking:
        masking(frame, cphi, k)
    pmean = reweighting(sd, ti, zi, to, zo, ss, k, weight) if with_reweighting else None
    hp = cphi                        # (1 + cos phi_d) / 2 = cos^2(phi_d / 2)
    hp += 1.0
    cg2 = c2d * hp
    cg2 *= 0.25
    cg = np.sqrt(cg2)
    k *= 2.0
    ks = f_rs_geometry(hp, k)
    kv = f_rv_geometry(sd.ci, sd.cr, k, degenerate)
    return ThreadGeometry(th2, cg, cg2, ks, kv, sd.ci if keep_cos else None,
                          sd.cr if keep_cos else None, pmean)


def f_rs_geometry(hp, k):
    r"""The direction factor of f_rs, :math:`\cos(\phi_d/2)`, times the common factor ``k``:
    ``ks`` (computed in ``hp``'s storage, which holds :math:`1 + \cos\phi_d` on entry).

    :math:`\cos(\phi_d/2) = \sqrt{(1 + \cos\phi_d)/2} \ge 0` (twin: ``np.cos(phi_d / 2)``).
    """
    hp *= 0.5
    np.sqrt(hp, out=hp)              # cos(phi_d / 2) >= 0
    hp *= k
    return hp


def f_rv_geometry(ci, cr, k, degenerate=False):
    r"""The direction factor of f_rv, :math:`1/(\cos\theta_i + \cos\theta_r)`, times the
    common factor ``k``: ``kv`` (a new array).

    With ``degenerate`` (some cos theta = 0), a pair with both directions along the tangent
    gets 0 (its ``k`` is 0 there) instead of 0/0. The rest of f_rv is
    :func:`brdf.shading.f_rv`.
    """
    kv = ci + cr
    if degenerate:
        np.copyto(kv, 1.0, where=kv == 0.0)   # both along the tangent: k = 0 there
    np.divide(k, kv, out=kv)
    return kv


def pair_blend(a, b, cos_delta, k):
    r"""Pair visibility :math:`(1-u)ab + u\min(a, b)`, with :math:`u = u(\arccos c)`.

    The in-place form of ``terms.pair_weight``: multiplies ``k`` by the result and returns
    the result (computed in ``a``'s storage). ``a`` and ``b`` are overwritten.
    """
    u = u_of_cos(cos_delta)
    prod = a * b
    np.minimum(a, b, out=a)
    a -= prod
    a *= u
    a += prod
    k *= a
    return a


def u_of_cos(cos_delta):
    r"""MODEL.md's unit-height Gaussian :math:`u(\delta) = \exp(-\delta^2 / (2\sigma_u^2))`
    of the angle :math:`\delta = \arccos(c)` whose cosine ``cos_delta`` is given (a new
    array; twin: ``terms.u``)."""
    u = np.arccos(cos_delta)
    u *= u
    u *= _K_U
    np.exp(u, out=u)
    return u
