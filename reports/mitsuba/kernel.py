r"""The microcylinder model in Dr.Jit: f_r cos, the sampler's density and its draws.

The same equations as :mod:`brdf.kernel` and :mod:`brdf.shading` (MODEL.md, term by term),
written with Dr.Jit operations so that they run in every Mitsuba 3 RGB variant: on Python
floats in ``scalar_rgb``, on JIT arrays (one lane a direction pair) in ``llvm_ad_rgb`` and
``cuda_ad_rgb``. The fabric's numbers never enter a kernel's code: in the JIT variants they
are opaque values and arrays (:mod:`reports.mitsuba.consts`), and the sums over the tangent
samples are Dr.Jit loops (``dr.while_loop``) over those arrays. One compiled kernel therefore
serves every fabric with the same options (masking, reweighting, transmission, gap), presets
and fitted fabrics alike, and its size does not grow with the number of tangent samples.
:func:`eval_pdf` sums f_r cos and the sampler's density in one loop, sharing each sample's
angles. Directions are in microcyl's local frame (n = +z, the warp along +x turned by the rotation
angle); ``light`` is microcyl's wi (Mitsuba's ``wo``), ``view`` its wo (Mitsuba's ``si.wi``).

Three formulas differ from the NumPy kernel in form only, for float32: theta_i + theta_r comes
from ``atan2`` of its sine and cosine (``arccos`` of a cosine near 1 loses the angle's digits);
:math:`\cos^2(\phi_d/2) = |\hat u_i + \hat u_r|^2 / 4` from the unit azimuth vectors (no
cancellation in :math:`1 + \cos\phi_d`); and the transmission
:math:`1 - F_r = 2cg\,[(c + g)^{-2} + \eta^2 (\eta^2 c + g)^{-2}]` (no cancellation near
grazing incidence).

This module imports Mitsuba and Dr.Jit at its top: it is imported only through
:func:`reports.mitsuba.register` (both are optional at run time).
"""

from __future__ import annotations

import bisect
import math
from typing import NamedTuple

# optional dependencies: this module is imported only by reports.mitsuba.register()
import drjit as dr
import mitsuba as mi

from brdf.options import Gap, Transmission
from brdf.terms import SIGMA_U
from reports.mitsuba import horizon
from reports.mitsuba.consts import GAUSS_NORM, Consts, consts

__all__ = ["Consts", "consts", "eval_pdf", "eval_cos", "sample", "wide", "narrow"]

_K_U = -0.5 / SIGMA_U**2            # u(x) = exp(_K_U x^2)
_COS_MIN = 1e-12                    # as brdf.sampling: the 1/cos(theta) density stays finite


def _at(table, i, kind):
    """table[i] (an index per lane): a gather in the JIT variants."""
    return dr.gather(kind, table, i) if dr.is_jit_v(kind) else table[i]


def _loop(n, body, *zeros):
    """Sum ``body(i)`` (a tuple of terms) over i = 0 .. n - 1 in a Dr.Jit loop: symbolic (one
    traced iteration, whatever n is) in the JIT variants, a Python loop in ``scalar_rgb``.
    ``zeros`` are the sums' initial values."""
    def step(i, *acc):
        return (i + 1, *(a + b for a, b in zip(acc, body(i))))

    state = dr.while_loop(state=(mi.UInt32(0), *zeros), cond=lambda i, *acc: i < n,
                          body=step, labels=("i",) + tuple(f"s{j}" for j in range(len(zeros))))
    return state[1:]


# -- frames --------------------------------------------------------------------------------
def thread_axes(w, c, s):
    """(w . t0, w . b, w . n) of both threads for the rotation (cos, sin) = (c, s).

    Thread 1: t0 = (c, s, 0), b = n x t0; thread 2 is thread 1 turned 90 degrees about n.
    """
    t = w.x * c + w.y * s
    b = w.y * c - w.x * s
    return (t, b, w.z), (b, -t, w.z)


def wide(x):
    """x in double precision (JIT variants; Python floats are doubles already)."""
    return mi.Float64(x) if dr.is_jit_v(x) else x


class _Vec(NamedTuple):
    """Components of a direction (in double precision)."""

    x: object
    y: object
    z: object


def narrow(x):
    """x back in the variant's precision."""
    return mi.Float(x) if dr.is_jit_v(x) else x


# -- f_r cos -------------------------------------------------------------------------------
def _blend(a, b, cos_delta):
    r"""Pair visibility :math:`(1 - u)ab + u\min(a, b)`, :math:`u = e^{-\delta^2/2\sigma_u^2}`."""
    d = dr.acos(dr.clip(cos_delta, -1.0, 1.0))
    u = dr.exp(_K_U * d * d)
    prod = a * b
    return prod + u * (dr.minimum(a, b) - prod)


def _fresnel(eta2, eta2m1, c):
    """Unpolarized Fresnel reflectance F_r and transmission 1 - F_r at incidence cosine c
    (``eta2`` = eta^2, ``eta2m1`` = eta^2 - 1)."""
    g = dr.sqrt(eta2m1 + c * c)
    e2c = eta2 * c
    rs, rp = (c - g) / (c + g), (e2c - g) / (e2c + g)
    a, b = c + g, e2c + g
    return 0.5 * (rs * rs + rp * rp), 2.0 * c * g * (1.0 / (a * a) + eta2 / (b * b))


def _sample_terms(th, ca, sa, light, view, k, density):
    """One tangent sample: (surface, volume / A, P) of MODEL.md, cos(theta_i) / cos^2(theta_d)
    and M, P included, and with ``density`` the sampler's density of the thread's lobes at
    this sample (:func:`_density`)."""
    (ti, bi, zi), (to, bo, zo) = light, view
    si, xi = ti * ca + zi * sa, zi * ca - ti * sa
    sr, xr = to * ca + zo * sa, zo * ca - to * sa
    ci, cr = dr.sqrt(xi * xi + bi * bi), dr.sqrt(xr * xr + bo * bo)
    zero_i, zero_r = ci == 0.0, cr == 0.0                  # along the tangent: phi := 0
    ci_s, cr_s = dr.select(zero_i, 1.0, ci), dr.select(zero_r, 1.0, cr)
    ui_x, ui_y = dr.select(zero_i, 1.0, xi / ci_s), dr.select(zero_i, 0.0, bi / ci_s)
    ur_x, ur_y = dr.select(zero_r, 1.0, xr / cr_s), dr.select(zero_r, 0.0, bo / cr_s)
    hp = narrow(dr.clip(0.25 * (dr.square(ui_x + ur_x) + dr.square(ui_y + ur_y)), 0.0, 1.0))
    wide_angles = (ca, sa, si, xi, ci, sr, cr)           # the density's, in double precision
    cc, ss = ci * cr, si * sr
    c2d = narrow(1.0 + cc + ss)                           # 2 cos^2(theta_d)
    th2 = dr.square(narrow(dr.atan2(si * cr + ci * sr, cc - ss)))   # (theta_i + theta_r)^2
    ss = narrow(ss)
    si, xi, ci, sr, xr, cr, ui_x, ur_x = map(narrow, (si, xi, ci, sr, xr, cr, ui_x, ur_x))
    ti, zi, to, zo = map(narrow, (ti, zi, to, zo))
    cphi = 2.0 * hp - 1.0                                  # cos(phi_d)
    ok = c2d > 0.0
    c2d = dr.select(ok, c2d, 1.0)
    geo = dr.select(ok, 2.0 * ci / c2d, 0.0)               # cos(theta_i) / cos^2(theta_d)
    if k.masking:
        geo *= _blend(dr.maximum(ui_x, 0.0), dr.maximum(ur_x, 0.0), cphi)
    p = 1.0
    if k.reweighting:
        irho_i = dr.rsqrt(zi * zi + ti * ti)
        irho_r = dr.rsqrt(zo * zo + to * to)
        p = _blend(dr.maximum(xi, 0.0) * irho_i, dr.maximum(xr, 0.0) * irho_r,
                   (xi * xr + ss) * irho_i * irho_r)
        geo *= p
    cg = dr.sqrt(0.5 * c2d * hp)                           # cos_g
    fr, tr = _fresnel(th.eta2, th.eta2m1, cg)
    if k.transmission is Transmission.HALF_ANGLE:
        ft = tr * tr
    else:
        ft = _fresnel(th.eta2, th.eta2m1, ci)[1] * _fresnel(th.eta2, th.eta2m1, cr)[1]
    gs = dr.exp(th2 * th.gs_k) * th.gs_c
    gv = dr.exp(th2 * th.gv_k) * th.gv_c
    csum = ci + cr
    surf = fr * dr.sqrt(hp) * gs * geo
    vol = ft * (gv + th.kd) * geo / dr.select(csum > 0.0, csum, 1.0)
    if not density:
        return surf, vol, p
    return surf, vol, p, _density(k, th, *wide_angles)


def eval_pdf(k: Consts, light, view, rot_c, rot_s, with_pdf=True, albedo=(None, None)):
    r"""f_r(wi, wo) cos(theta_i), RGB, and the sampler's density, for the light direction
    ``light`` (microcyl's wi) and the viewer ``view`` (its wo), unit mi.Vector3f in the local
    frame (n = +z), in one pass over the tangent samples. ``albedo``: per thread, an
    mi.Color3f per lane (a texture's values at the hits) in place of its constant albedo.

    ``rot_c``, ``rot_s``: cos and sin of the warp's angle from +x (the fabric's rotation and
    any per-hit turn). Returns an mi.Color3f, 1/sr times the cosine (dimensionless per sr):

    .. math:: f_r \cos\theta_i = \frac{a_1 S_1 + a_2 S_2}{Q}

    (MODEL.md's f_r multiplied by n . wi), 0 where either direction is at or below the
    horizon or Q <= 0; and the density (1/sr) of :func:`sample`'s light directions, the
    mixture of :func:`brdf.sampling.pdf` term by term, 0 where either direction is at or
    below the horizon (the plugin also sets it to 0 where f_r is 0, see
    :mod:`reports.mitsuba.plugin`), or None without ``with_pdf``.
    """
    rc, rs = wide(rot_c), wide(rot_s)
    axes_l, axes_v = (thread_axes(_Vec(*map(wide, (w.x, w.y, w.z))), rc, rs)
                      for w in (light, view))
    rgb = [0.0, 0.0, 0.0]
    q = 1.0
    if k.reweighting:
        gap = light.z if k.gap is Gap.INCIDENT else view.z
        q = k.gap_area * gap
    total = k.cos_p * (1.0 / math.pi) * dr.maximum(light.z, 0.0)
    for j, th in enumerate(k.threads):
        density = with_pdf and k.sampled[j]

        def terms(i, th=th, j=j, density=density):
            out = _sample_terms(th, _at(th.ca, i, mi.Float64), _at(th.sa, i, mi.Float64),
                                axes_l[j], axes_v[j], k, density)
            w = _at(th.weight, i, mi.Float)
            return tuple(w * x for x in out)

        sums = _loop(th.n, terms, *(mi.Float(0.0),) * (4 if density else 3))
        surf, vol, pmean = sums[:3]
        if density:
            total += k.thread_p[j] * sums[3]
        if k.reweighting:
            q = q + th.area * pmean
        alb = th.albedo if albedo[j] is None else (albedo[j].x, albedo[j].y, albedo[j].z)
        for ch in range(3):
            rgb[ch] = rgb[ch] + th.area * (surf + alb[ch] * vol)
    up = (light.z > 0.0) & (view.z > 0.0)
    ok = up & (q > 0.0)
    inv = dr.select(ok, 1.0 / dr.select(ok, q, 1.0), 0.0)
    f = mi.Color3f(rgb[0] * inv, rgb[1] * inv, rgb[2] * inv)
    return f, (dr.select(up, total, 0.0) if with_pdf else None)


def eval_cos(k: Consts, light, view, rot_c, rot_s, albedo=(None, None)):
    """f_r(wi, wo) cos(theta_i) alone (:func:`eval_pdf`)."""
    return eval_pdf(k, light, view, rot_c, rot_s, with_pdf=False, albedo=albedo)[0]


# -- the sampler (brdf/sampling.py) --------------------------------------------------------
def _density(k, th, ca, sa, si, xi, ci, sr, cr):
    """The density (1/sr) of a thread's lobes at one tangent sample (cos, sin of its offset
    ``ca``, ``sa``), unweighted: the light's longitudinal angle (sine ``si``, cosine ``ci``;
    ``xi`` its cosine's component along the normal's side) under the Gaussians about the
    mirror of the viewer's (``sr``, ``cr``), truncated to the angles with an azimuth above
    the horizon, times the azimuth's density truncated to its window (brdf.sampling,
    brdf.horizon)."""
    cth = dr.maximum(ci, _COS_MIN)
    _, mass = horizon.azimuth_window(si, cth, ca, sa, k.masking)     # double: closing windows
    pphi = dr.maximum(xi, 0.0) / (2.0 * cth) if k.masking else 0.5 / math.pi
    ok = mass > 0.0
    pphi = narrow(dr.select(ok, pphi / dr.select(ok, mass, 1.0), 0.0))
    # the lobes in the variant's precision (float32)
    mu, th_i = narrow(-dr.atan2(sr, cr)), narrow(dr.atan2(si, cth))
    lo, hi = map(narrow, horizon.theta_range(ca, sa))
    cth = narrow(cth)
    dens = th.lobe_p[2] / (1.0 + narrow(ca))           # sin(hi) - sin(lo) = 1 + cos(alpha)
    for lobe in (0, 1):
        inv = th.inv_sig[lobe]
        trunc = horizon.truncnorm_density((th_i - mu) * inv, (lo - mu) * inv, (hi - mu) * inv)
        dens += th.lobe_p[lobe] * trunc * (GAUSS_NORM * inv) / cth
    return dens * pphi


def _pick(k: Consts, u):
    """The sampler's component for the uniform number ``u``: the first with cdf > u (a
    binary search of log2(k.comp_size) steps in the JIT variants)."""
    if not dr.is_jit_v(u):
        return bisect.bisect_right(k.comp_cdf, u)
    return dr.binary_search(0, k.comp_size - 1,
                            lambda i: dr.gather(mi.Float, k.comp_cdf, i) <= u)


def sample(k: Consts, view, u1, u2, rot_c, rot_s):
    """A light direction (mi.Vector3f, local frame) for the viewer ``view``.

    ``u1`` picks the component, ``u2`` (mi.Point2f) the longitudinal angle (x) and the
    azimuth (y), as :func:`brdf.sampling.sample` does with its rescaled first and its second
    number.
    """
    idx = _pick(k, u1)
    j, ca, sa = (_at(t, idx, mi.Float) for t in (k.comp_thread, k.comp_ca, k.comp_sa))
    kind, sig = _at(k.comp_kind, idx, mi.Float), _at(k.comp_sigma, idx, mi.Float)
    second = j > 0.5
    # thread 1: t0 = (c, s, 0), b = (-s, c, 0); thread 2: t0 = (-s, c, 0), b = (-c, -s, 0)
    t0x, t0y = dr.select(second, -rot_s, rot_c), dr.select(second, rot_c, rot_s)
    bx, by = dr.select(second, -rot_c, -rot_s), dr.select(second, -rot_s, rot_c)
    t = mi.Vector3f(ca * t0x, ca * t0y, sa)
    nt = mi.Vector3f(-sa * t0x, -sa * t0y, ca)
    b = mi.Vector3f(bx, by, 0.0)
    mu = -dr.atan2(dr.dot(view, t), dr.sqrt(dr.square(dr.dot(view, nt))
                                            + dr.square(dr.dot(view, b))))
    v = u2.x
    lo, hi = horizon.theta_range(ca, sa)
    th = horizon.truncnorm_draw(mu, sig, lo, hi, v)
    iso = kind > 1.5                                   # sin(theta) uniform in its range
    s_lo, s_hi = dr.sin(lo), dr.sin(hi)
    s = dr.select(iso, s_lo + v * (s_hi - s_lo), dr.sin(th))
    c = dr.select(iso, dr.sqrt(dr.maximum(1.0 - s * s, 0.0)), dr.cos(th))
    m, _ = horizon.azimuth_window(s, c, ca, sa, k.masking)
    phi = horizon.azimuth_draw(m, u2.y, k.masking)
    wi = s * t + c * (dr.cos(phi) * nt + dr.sin(phi) * b)
    return dr.select(kind < -0.5, mi.warp.square_to_cosine_hemisphere(u2), wi)
