r"""The sampler of :mod:`brdf.sampling` in Dr.Jit, and f_r cos with its density in one pass:
what the Mitsuba plugin (:mod:`reports.mitsuba.bsdf`) calls, in any Mitsuba RGB variant.

:func:`eval_pdf` sums f_r cos and the sampler's density over the tangent samples in one
loop (:func:`brdf.jit.kernel.fabric_sums`), sharing each sample's angles; :func:`sample`
draws a light direction from the same mixture.

Imports Dr.Jit at its top: it is imported only through :func:`reports.mitsuba.register`.
"""

from __future__ import annotations

import bisect
import math

# optional dependency: this module is imported only through reports.mitsuba.register()
import drjit as dr

from brdf.jit.consts import GAUSS_NORM, Consts
from brdf.jit import horizon
from brdf.jit.kernel import SampleGeometry, at, fabric_q, fabric_sums, narrow

__all__ = ["eval_pdf", "eval_cos", "density", "sample"]

_COS_MIN = 1e-12                    # as brdf.sampling: the 1/cos(theta) density stays finite


def eval_pdf(k: Consts, light, view, rot_c, rot_s, with_pdf=True, albedo=(None, None)):
    r"""f_r(wi, wo) cos(theta_i), RGB, and the sampler's density, for the light direction
    ``light`` (microcyl's wi) and the viewer ``view`` (its wo), unit vectors in the local
    frame (n = +z), in one pass over the tangent samples. ``albedo``: per thread, a Color3
    per lane (a texture's values at the hits) in place of its constant albedo.

    ``rot_c``, ``rot_s``: cos and sin of the warp's angle from +x (the fabric's rotation and
    any per-hit turn). Returns a Color3, 1/sr times the cosine (dimensionless per sr):

    .. math:: f_r \cos\theta_i = \frac{a_1 S_1 + a_2 S_2}{Q}

    (MODEL.md's f_r multiplied by n . wi), 0 where either direction is at or below the
    horizon or Q <= 0; and the density (1/sr) of :func:`sample`'s light directions, the
    mixture of :func:`brdf.sampling.pdf` term by term, 0 where either direction is at or
    below the horizon (the plugin also sets it to 0 where f_r is 0, see
    :mod:`reports.mitsuba.plugin`), or None without ``with_pdf``.
    """
    sums = fabric_sums(k, light, view, rot_c, rot_s, density if with_pdf else None)
    rgb = [0.0, 0.0, 0.0]
    total = k.cos_p * (1.0 / math.pi) * dr.maximum(light.z, 0.0)
    for j, th in enumerate(k.threads):
        surf, vol = sums[j][:2]
        if len(sums[j]) > 3:
            total += k.thread_p[j] * sums[j][3]
        alb = th.albedo if albedo[j] is None else (albedo[j].x, albedo[j].y, albedo[j].z)
        for ch in range(3):
            rgb[ch] = rgb[ch] + th.area * (surf + alb[ch] * vol)
    q = fabric_q(k, sums, light.z, view.z)
    up = (light.z > 0.0) & (view.z > 0.0)
    ok = up & (q > 0.0)
    inv = dr.select(ok, 1.0 / dr.select(ok, q, 1.0), 0.0)
    f = k.types.Color3(rgb[0] * inv, rgb[1] * inv, rgb[2] * inv)
    return f, (dr.select(up, total, 0.0) if with_pdf else None)


def eval_cos(k: Consts, light, view, rot_c, rot_s, albedo=(None, None)):
    """f_r(wi, wo) cos(theta_i) alone (:func:`eval_pdf`)."""
    return eval_pdf(k, light, view, rot_c, rot_s, with_pdf=False, albedo=albedo)[0]


def density(k: Consts, th, g: SampleGeometry):
    """The density (1/sr) of a thread's lobes at one tangent sample, unweighted: the
    light's longitudinal angle (sine ``si``, cosine ``ci``; ``xi`` its cosine's component
    along the normal's side) under the Gaussians about the mirror of the viewer's (``sr``,
    ``cr``), truncated to the angles with an azimuth above the horizon, times the azimuth's
    density truncated to its window (brdf.sampling, brdf.horizon). The window is found in
    double precision (``g.wide``: windows that close), the lobes in the kernel's."""
    ca, sa, si, xi, ci, sr, cr = g.wide
    cth = dr.maximum(ci, _COS_MIN)
    _, mass = horizon.azimuth_window(si, cth, ca, sa, k.masking)
    pphi = dr.maximum(xi, 0.0) / (2.0 * cth) if k.masking else 0.5 / math.pi
    ok = mass > 0.0
    pphi = narrow(dr.select(ok, pphi / dr.select(ok, mass, 1.0), 0.0), k)
    mu, th_i = narrow(-dr.atan2(sr, cr), k), narrow(dr.atan2(si, cth), k)
    lo, hi = (narrow(x, k) for x in horizon.theta_range(ca, sa))
    cth = narrow(cth, k)
    dens = th.lobe_p[2] / (1.0 + narrow(ca, k))          # sin(hi) - sin(lo) = 1 + cos(alpha)
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
                            lambda i: dr.gather(k.types.Float, k.comp_cdf, i) <= u)


def sample(k: Consts, view, u1, u2, rot_c, rot_s):
    """A light direction (a Vector3 of ``k.types``, local frame) for the viewer ``view``.

    ``u1`` picks the component, ``u2`` (a Point2) the longitudinal angle (x) and the
    azimuth (y), as :func:`brdf.sampling.sample` does with its rescaled first and its second
    number.
    """
    t_ = k.types
    idx = _pick(k, u1)
    j, ca, sa = (at(t, idx, t_.Float) for t in (k.comp_thread, k.comp_ca, k.comp_sa))
    kind, sig = at(k.comp_kind, idx, t_.Float), at(k.comp_sigma, idx, t_.Float)
    second = j > 0.5
    # thread 1: t0 = (c, s, 0), b = (-s, c, 0); thread 2: t0 = (-s, c, 0), b = (-c, -s, 0)
    t0x, t0y = dr.select(second, -rot_s, rot_c), dr.select(second, rot_c, rot_s)
    bx, by = dr.select(second, -rot_c, -rot_s), dr.select(second, -rot_s, rot_c)
    t = t_.Vector3(ca * t0x, ca * t0y, sa)
    nt = t_.Vector3(-sa * t0x, -sa * t0y, ca)
    b = t_.Vector3(bx, by, 0.0)
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
    return dr.select(kind < -0.5, t_.cosine_hemisphere(u2), wi)
