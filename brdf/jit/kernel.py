r"""The microcylinder model in Dr.Jit, written once for every Dr.Jit float type: f_r (and
f_r cos for Mitsuba), per thread its surface and volume sums, and the sampler's density.

The same equations as :mod:`brdf.kernel` and :mod:`brdf.shading` (MODEL.md, term by term),
with Dr.Jit operations on the types of :class:`brdf.jit.consts.Types`: the LLVM backend's
float64 arrays for ``Fabric.eval`` and ``Prepared.eval`` (:mod:`brdf.jit.llvm`), a Mitsuba
variant's float32 (the frame in float64) for the plugin, Python floats in ``scalar_rgb``.
One lane is a direction pair (with :mod:`brdf.jit.llvm`'s batches, a pair and a parameter
set). The fabric's numbers never enter a kernel's code: they are opaque values and arrays
(:func:`brdf.jit.consts.consts`), and the sums over the tangent samples are Dr.Jit loops
(``dr.while_loop``) over those arrays. One compiled kernel therefore serves every fabric with
the same options (masking, reweighting, transmission, gap), and its size does not grow with
the number of tangent samples. Each sample is :func:`sample_geometry` (what depends on the
directions: NumPy's :func:`brdf.kernel.thread_geometry`) then :func:`sample_shading` (what
depends on the optical parameters: NumPy's :func:`brdf.shading.thread_shade`).

Directions are in microcyl's local frame (n = +z, the warp along +x turned by the rotation
angle); ``light`` is microcyl's wi (Mitsuba's ``wo``), ``view`` its wo (Mitsuba's ``si.wi``).

Edge cases as the NumPy kernel: a direction along a tangent sample (cos theta = 0) has
azimuth 0; a sample with cos^2(theta_d) = 0 contributes 0; a pair with both directions along
the tangent has no volume term; in-plane lengths and cosines below 2^-500 are taken without
underflow (scaled by 2^600); below the horizon and Q <= 0 give 0. Three formulas differ from
the NumPy kernel in form only, for float32 (in double precision they are NumPy's, so that
both backends round alike where these cancel): theta_i + theta_r comes from ``atan2`` of its sine
and cosine (``arccos`` of a cosine near 1 loses the angle's digits); :math:`\cos^2(\phi_d/2) =
|\hat u_i + \hat u_r|^2 / 4` from the unit azimuth vectors (no cancellation in :math:`1 +
\cos\phi_d`); and the transmission :math:`1 - F_r = 2cg\,[(c + g)^{-2} + \eta^2 (\eta^2 c +
g)^{-2}]` (no cancellation near grazing incidence). In double precision a sample's Fresnel
quotients and its two exponentials share one division (:func:`_quotients`: one instead of
four), which moves them by a few ulps, not more.

Imports Dr.Jit at its top: it is imported only through :func:`brdf.jit.llvm` and
:func:`reports.mitsuba.register`.
"""

from __future__ import annotations

from typing import NamedTuple

# optional dependency: this module is imported only through brdf.jit.llvm() and the plugin
import drjit as dr

from brdf.jit.consts import Consts
from brdf.options import Gap, Transmission
from brdf.terms import SIGMA_U

__all__ = ["SampleGeometry", "sample_geometry", "sample_shading", "thread_axes",
           "fabric_sums", "fabric_q", "inverse_rho", "at", "loop", "wide", "narrow"]

_K_U = -0.5 / SIGMA_U**2            # u(x) = exp(_K_U x^2)
_TINY = 2.0 ** -500                 # as brdf.kernel: squares below this may underflow
_BIG, _SMALL = 2.0 ** 600, 2.0 ** -600
# Dr.Jit's exp in double precision (drjit/math.h, from Cephes): its least argument, log2(e),
# ln 2 in two parts, and its rational approximation's coefficients
_EXP_LO = float.fromhex("-0x1.62b7d369a5aa7p+9")
_LOG2E = float.fromhex("0x1.71547652b82fep+0")
_LN2_HI, _LN2_LO = float.fromhex("-0x1.62e4p-1"), float.fromhex("-0x1.7f7d1cf79abcap-20")
_EXP_P = (float.fromhex("0x1.089cdd5e44be8p-13"), float.fromhex("0x1.f06d10cca2c7ep-6"))
_EXP_Q = (float.fromhex("0x1.92eb6bc365fap-19"), float.fromhex("0x1.4ae39b508b6cp-9"),
          float.fromhex("0x1.d17099887e074p-3"))


def at(table, i, kind):
    """table[i] (an index per lane): a gather in the JIT types."""
    return dr.gather(kind, table, i) if dr.is_jit_v(kind) else table[i]


def loop(n, body, counter, *zeros):
    """Sum ``body(i)`` (a tuple of terms) over i = 0 .. n - 1 in a Dr.Jit loop: symbolic (one
    traced iteration, whatever n is) in the JIT types, a Python loop for Python floats.
    ``counter`` is the loop index's zero (a UInt32), ``zeros`` the sums' initial values."""
    def step(i, *acc):
        return (i + 1, *(a + b for a, b in zip(acc, body(i))))

    state = dr.while_loop(state=(counter, *zeros), cond=lambda i, *acc: i < n,
                          body=step, labels=("i",) + tuple(f"s{j}" for j in range(len(zeros))))
    return state[1:]


def wide(x, k: Consts):
    """x in double precision (JIT types; Python floats are doubles already)."""
    return k.types.Float64(x) if k.types.jit else x


def narrow(x, k: Consts):
    """x back in the kernel's shading precision."""
    return k.types.Float(x) if k.types.jit else x


def _double(k: Consts) -> bool:
    """Whether the kernel shades in double precision (the LLVM float64 of brdf, or Python
    floats): then it rounds as the NumPy kernel, where the float32 forms differ."""
    return not k.types.jit or dr.type_v(k.types.Float) == dr.VarType.Float64


def _norm(x, y):
    """sqrt(x^2 + y^2) (double precision), without underflow below 2^-500 (as hypot):
    tiny components are scaled by 2^600 first (exact)."""
    tiny = (dr.abs(x) < _TINY) & (dr.abs(y) < _TINY)
    kind = type(x)          # (dr.select of two Python floats would make them float32)
    up, down = dr.select(tiny, kind(_BIG), 1.0), dr.select(tiny, kind(_SMALL), 1.0)
    return dr.sqrt(dr.square(x * up) + dr.square(y * up)) * down


def thread_axes(w, c, s):
    """(w . t0, w . b, w . n) of both threads for the rotation (cos, sin) = (c, s).

    Thread 1: t0 = (c, s, 0), b = n x t0; thread 2 is thread 1 turned 90 degrees about n.
    """
    t = w.x * c + w.y * s
    b = w.y * c - w.x * s
    return (t, b, w.z), (b, -t, w.z)


class _Vec(NamedTuple):
    """Components of a direction (in double precision)."""

    x: object
    y: object
    z: object


class SampleGeometry(NamedTuple):
    """One tangent sample's direction-dependent terms (:func:`sample_geometry`), in the
    symbols of :mod:`brdf.kernel`."""

    th2: object     # (theta_i + theta_r)^2, rad^2
    cg: object      # cos_g
    ks: object      # cos(theta_i) M P cos(phi_d / 2) / cos^2(theta_d)
    kv: object      # cos(theta_i) M P / (cos^2(theta_d) (cos theta_i + cos theta_r))
    p: object       # P(wi, wo) (1 with reweighting off)
    ci: object      # longitudinal cosines
    cr: object
    si: object      # longitudinal sines, and wi . n_t (the sampler's density)
    sr: object
    xi: object
    wide: tuple = ()    # (ca, sa, si, xi, ci, sr, cr), double precision: the density's window


def _blend(a, b, cos_delta):
    r"""Pair visibility :math:`(1 - u)ab + u\min(a, b)`, :math:`u = e^{-\delta^2/2\sigma_u^2}`."""
    d = dr.acos(dr.clip(cos_delta, -1.0, 1.0))
    u = dr.exp(_K_U * d * d)
    prod = a * b
    return prod + u * (dr.minimum(a, b) - prod)


def sample_geometry(k: Consts, ca, sa, light, view, irho) -> SampleGeometry:
    """The geometry of one tangent sample (cos, sin of its offset: ``ca``, ``sa``) for the
    thread axes ``light`` and ``view`` (:func:`thread_axes`, double precision); ``irho``
    the pair's (1/rho_i, 1/rho_r), rho = |(w . t0, w . n)| (reweighting's lengths)."""
    (ti, bi, zi), (to, bo, zo) = light, view
    si, xi = ti * ca + zi * sa, zi * ca - ti * sa
    sr, xr = to * ca + zo * sa, zo * ca - to * sa
    ci, cr = _norm(xi, bi), _norm(xr, bo)
    zero_i, zero_r = ci == 0.0, cr == 0.0                  # along the tangent: phi := 0
    ici, icr = 1.0 / dr.select(zero_i, 1.0, ci), 1.0 / dr.select(zero_r, 1.0, cr)
    ui_x, ui_y = dr.select(zero_i, 1.0, xi * ici), dr.select(zero_i, 0.0, bi * ici)
    ur_x, ur_y = dr.select(zero_r, 1.0, xr * icr), dr.select(zero_r, 0.0, bo * icr)
    cc, ss = ci * cr, si * sr
    if _double(k):              # (1 + cos phi_d) / 2, rounded as the NumPy kernel rounds it
        tiny = (ci < _TINY) | (cr < _TINY)
        cphi = dr.select(tiny, ui_x * ur_x + ui_y * ur_y,
                         (bi * bo + xi * xr) / dr.select(tiny, 1.0, cc))
        hp = 0.5 * (1.0 + dr.clip(cphi, -1.0, 1.0))
    else:                       # without its cancellation near phi_d = pi (module notes)
        hp = narrow(dr.clip(0.25 * (dr.square(ui_x + ur_x) + dr.square(ui_y + ur_y)), 0.0,
                            1.0), k)
    c2d = narrow(cc + ss + 1.0, k)                        # 2 cos^2(theta_d)
    if _double(k):              # (theta_i + theta_r)^2, as the NumPy kernel forms it
        th2 = dr.square(dr.acos(dr.clip(cc - ss, -1.0, 1.0)))
    else:
        th2 = dr.square(narrow(dr.atan2(si * cr + ci * sr, cc - ss), k))
    p = 1.0
    if k.reweighting:
        (ii, ir) = irho
        pu_i, pu_r = narrow(xi * ii, k), narrow(xr * ir, k)
        cpsi = pu_i * pu_r + narrow(si * ii, k) * narrow(sr * ir, k)
        p = _blend(dr.maximum(pu_i, 0.0), dr.maximum(pu_r, 0.0), cpsi)
    wide_angles = (ca, sa, si, xi, ci, sr, cr)
    si, xi, ci, sr, cr, ui_x, ur_x = (narrow(v, k) for v in (si, xi, ci, sr, cr, ui_x, ur_x))
    ok = c2d > 0.0
    c2d = dr.select(ok, c2d, 1.0)
    geo = dr.select(ok, 2.0 * ci / c2d, 0.0)               # cos(theta_i) / cos^2(theta_d)
    if k.masking:
        geo *= _blend(dr.maximum(ui_x, 0.0), dr.maximum(ur_x, 0.0), 2.0 * hp - 1.0)
    geo *= p
    csum = ci + cr
    return SampleGeometry(th2, dr.sqrt(0.5 * c2d * hp), geo * dr.sqrt(hp),
                          geo / dr.select(csum > 0.0, csum, 1.0), p, ci, cr, si, sr, xi,
                          wide_angles)


def _fresnel(eta2, eta2m1, c, wide_float: bool):
    """Unpolarized Fresnel reflectance F_r and transmission 1 - F_r at incidence cosine c
    (``eta2`` = eta^2, ``eta2m1`` = eta^2 - 1). In double precision (``wide_float``)
    1 - F_r is taken as such, rounded as the NumPy kernel rounds it (r_s = -1 exactly at
    c = 0, so F_r = 1); in float32 in the form without cancellation (module notes)."""
    g = dr.sqrt(eta2m1 + c * c)
    e2c = eta2 * c
    a, b = c + g, e2c + g
    if wide_float:
        rs, rp = (c - g) / a, (e2c - g) / b
        f = 0.5 * (rs * rs + rp * rp)
        return f, 1.0 - f
    ia, ib = 1.0 / a, 1.0 / b
    rs, rp = (c - g) * ia, (e2c - g) * ib
    return 0.5 * (rs * rs + rp * rp), 2.0 * c * g * (ia * ia + eta2 * (ib * ib))


def _exp_parts(x):
    """(N, D) with exp(x) = N / D, for x <= 0, in double precision: Dr.Jit's own ``exp``
    (Cody and Waite's reduction x = n ln 2 + r, then the rational approximation
    e^r = (Q + P) / (Q - P)) without its division, so that several quotients share one
    (:func:`_quotients`); N = 0 below its least argument (exp would be below 2^-1023)."""
    xc = dr.maximum(x, _EXP_LO)
    n = dr.floor(dr.fma(xc, _LOG2E, 0.5))
    r = dr.fma(n, _LN2_LO, dr.fma(n, _LN2_HI, xc))
    r2 = r * r
    r4 = r2 * r2
    p = r * dr.fma(r4, _EXP_P[0], dr.fma(r2, _EXP_P[1], 1.0))
    q = dr.fma(r4, dr.fma(r2, _EXP_Q[0], _EXP_Q[1]), dr.fma(r2, _EXP_Q[2], 2.0))
    kind = type(x)
    ints = dr.int64_array_t(kind)
    scale = dr.reinterpret_array(kind, (ints(n) + 1023) << 52)      # 2^n, n >= -1023
    return dr.select(x < _EXP_LO, 0.0, (q + p) * scale), q - p


def _quotients(nums, dens):
    """nums[i] / dens[i] for every i with one division (of the product of the
    denominators, each within about [1e-8, 4] here: the product neither over- nor
    underflows); a few ulps from the quotients taken one by one."""
    before = [1.0]
    for d in dens[:-1]:
        before.append(before[-1] * d)
    inv = 1.0 / (before[-1] * dens[-1])
    out, after = [None] * len(nums), inv
    for i in range(len(nums) - 1, -1, -1):
        out[i] = nums[i] * before[i] * after
        after = after * dens[i]
    return out


def _fresnel_parts(th, c):
    """The numerators and denominators of r_s and r_p at incidence cosine c, scaled by
    1/eta and 1/eta^2 so that each denominator lies within [1e-8, 2] for any eta > 1
    (the eta of :data:`brdf.shading.PARAM_CLAMP` included)."""
    g = dr.sqrt(th.eta2m1 + c * c)
    gi = g * th.inv_eta2
    return ((c - g) * th.inv_eta, c - gi), ((c + g) * th.inv_eta, c + gi)


def _transmission(rs, rp, c):
    """1 - F_r from r_s and r_p; exactly 0 at c = 0 (r_s = r_p = -1 there, as NumPy forms
    them)."""
    return dr.select(c > 0.0, 1.0 - 0.5 * (rs * rs + rp * rp), 0.0)


def _shading_double(th, g: SampleGeometry, transmission: Transmission):
    """:func:`sample_shading` in double precision with one division a sample: the
    Fresnel quotients and the two Gaussians' exponentials share it (:func:`_quotients`;
    four divisions before, with Dr.Jit's own ``exp``)."""
    cosines = (g.cg,) if transmission is Transmission.HALF_ANGLE else (g.cg, g.ci, g.cr)
    nums, dens = [], []
    for c in cosines:
        n, d = _fresnel_parts(th, c)
        nums += n
        dens += d
    for k in (th.gs_k, th.gv_k):
        n, d = _exp_parts(g.th2 * k)
        nums.append(n)
        dens.append(d)
    q = _quotients(nums, dens)
    rs, rp = q[0], q[1]
    fr = 0.5 * (rs * rs + rp * rp)
    if transmission is Transmission.HALF_ANGLE:
        tr = 1.0 - fr
        ft = dr.select(g.cg > 0.0, tr * tr, 0.0)
    else:
        ft = _transmission(q[2], q[3], g.ci) * _transmission(q[4], q[5], g.cr)
    es, ev = q[-2], q[-1]
    return fr * (es * th.gs_c) * g.ks, ft * (ev * th.gv_c + th.kd) * g.kv


def sample_shading(th, g: SampleGeometry, transmission: Transmission):
    r"""(surface, volume / A) of one tangent sample: :math:`f_{rs}\, k` and
    :math:`(f_{rv}/A)\, k` with k = cos(theta_i) M P / cos^2(theta_d) (1/sr).

    ``th`` holds the thread's optical constants (:class:`brdf.jit.consts.ThreadConsts`'
    ``eta2``, ``eta2m1``, ``inv_eta``, ``inv_eta2``, ``kd``, ``gs_k``, ``gs_c``, ``gv_k``,
    ``gv_c``): opaque values, or one per lane for a batch of parameter sets.
    """
    wide_float = not dr.is_jit_v(g.cg) or dr.type_v(g.cg) == dr.VarType.Float64
    if wide_float and dr.is_jit_v(g.cg):
        return _shading_double(th, g, transmission)
    fr, tr = _fresnel(th.eta2, th.eta2m1, g.cg, wide_float)
    if transmission is Transmission.HALF_ANGLE:
        ft = tr * tr
    else:
        ft = (_fresnel(th.eta2, th.eta2m1, g.ci, wide_float)[1]
              * _fresnel(th.eta2, th.eta2m1, g.cr, wide_float)[1])
    gs = dr.exp(g.th2 * th.gs_k) * th.gs_c
    gv = dr.exp(g.th2 * th.gv_k) * th.gv_c
    return fr * gs * g.ks, ft * (gv + th.kd) * g.kv


def inverse_rho(k: Consts, axes):
    """(1/rho) of one direction's thread axes, rho = |(w . t0, w . n)| > 0 above the
    horizon (double precision; 1 with reweighting off, unused)."""
    t, _, z = axes
    return 1.0 / _norm(t, z) if k.reweighting else 1.0


def fabric_sums(k: Consts, light, view, rot_c, rot_s, density=None):
    """Per thread ``(surf, vol, pmean[, dens])``: the weighted sums over its tangent
    samples of :func:`sample_shading`'s terms, of P and, where ``density`` is given and the
    thread is sampled (``k.sampled``), of ``density(k, th, geometry)`` (the sampler's
    density, :func:`brdf.jit.sampler.density`), for unit directions ``light``, ``view``
    (``.x``, ``.y``, ``.z``) and the warp's angle (cos, sin) = (rot_c, rot_s)."""
    t = k.types
    rc, rs = wide(rot_c, k), wide(rot_s, k)
    axes_l, axes_v = (thread_axes(_Vec(*(wide(c, k) for c in (w.x, w.y, w.z))), rc, rs)
                      for w in (light, view))
    out = []
    dens = tuple(density is not None and s for s in k.sampled)
    for j, th in enumerate(k.threads):
        irho = (inverse_rho(k, axes_l[j]), inverse_rho(k, axes_v[j]))

        def terms(i, th=th, j=j):
            g = sample_geometry(k, at(th.ca, i, t.Float64), at(th.sa, i, t.Float64),
                                axes_l[j], axes_v[j], irho)
            terms = sample_shading(th, g, k.transmission) + (g.p,)
            if dens[j]:
                terms += (density(k, th, g),)
            w = at(th.weight, i, t.Float)
            return tuple(w * x for x in terms)

        zero = t.Float(0.0)
        out.append(loop(th.n, terms, t.UInt32(0), *(zero,) * (4 if dens[j] else 3)))
    return out


def fabric_q(k: Consts, sums, zi, zo, areas=None):
    """MODEL.md's Q from the threads' P means (1 with reweighting off). ``areas``: (a_1,
    a_2, 1 - a_1 - a_2), default the fabric's (the gap's share formed in double precision,
    as the NumPy kernel: in float32, 1 - 0.9 - 0.1 is 2e-8, not 0)."""
    if not k.reweighting:
        return 1.0
    a1, a2, gap_area = areas or (k.threads[0].area, k.threads[1].area, k.gap_area)
    gap = zi if k.gap is Gap.INCIDENT else zo
    return a1 * sums[0][2] + a2 * sums[1][2] + gap_area * gap
