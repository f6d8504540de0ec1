"""A fabric's numbers as :mod:`brdf.jit.kernel` takes them, for one Dr.Jit float type.

:class:`Types` names the Dr.Jit types a kernel runs on: the LLVM backend's float64 arrays for
``Fabric.eval`` and ``Prepared.eval`` (:mod:`brdf.jit.llvm`), or a Mitsuba variant's
(``mi.Float`` float32, ``mi.Float64`` for the frame's angles; Python floats in
``scalar_rgb``) for the plugin of :mod:`reports.mitsuba`. In the JIT types every number is
an opaque Dr.Jit value or an evaluated array, so it is a parameter of a compiled kernel, not a
literal of its code: one kernel then serves every fabric with the same options (masking,
reweighting, transmission, gap), presets and fitted fabrics alike, and Dr.Jit's kernel cache
keeps it for the next run. Only the options (Python values) choose the code.

Imports Dr.Jit at its top: it is imported only through :func:`brdf.jit.llvm` and
:func:`reports.mitsuba.register` (Dr.Jit is optional at run time).
"""

from __future__ import annotations

import dataclasses
import itertools

# optional dependency: this module is imported only through brdf.jit.llvm() and the plugin
import drjit as dr

import numpy as np

from brdf import shading
from brdf.options import Gap, Transmission

__all__ = ["Types", "Consts", "ThreadConsts", "consts", "opaque", "MIN_COMPONENTS",
           "GAUSS_NORM"]

#: 1 / sqrt(2 pi), the normal density's factor (:data:`brdf.shading.GAUSS_NORM`), a Python
#: float (a NumPy scalar times a Dr.Jit value would go through NumPy).
GAUSS_NORM = float(shading.GAUSS_NORM)
#: The sampler's component table is padded to a power of two at least this long: the binary
#: search that picks a component has as many steps as the table has bits, and every preset
#: (at most 1 + 3 x 64 components) then shares one kernel.
MIN_COMPONENTS = 256


@dataclasses.dataclass(frozen=True)
class Types:
    """The Dr.Jit types of one kernel.

    Attributes
    ----------
    Float : type
        The precision of the shading (``mi.Float``; ``drjit.llvm.ad.Float64`` in brdf).
    Float64 : type
        Double precision, for the frame's dot products and angles.
    UInt32 : type
    Color3 : type
        The RGB result.
    Vector3 : type, optional
        Directions (the sampler's draws).
    cosine_hemisphere : callable, optional
        Point2 -> Vector3, the sampler's cosine-weighted component (``mi.warp``'s).
    """

    Float: type
    Float64: type
    UInt32: type
    Color3: type
    Vector3: type | None = None
    cosine_hemisphere: object = None

    @property
    def jit(self) -> bool:
        """Whether these are JIT arrays (else Python floats: Mitsuba's ``scalar_rgb``)."""
        return dr.is_jit_v(self.Float)


@dataclasses.dataclass(frozen=True)
class ThreadConsts:
    """One thread's numbers (:func:`consts`)."""

    n: object           # number of distinct tangent offsets (UInt32)
    ca: object          # cos of the distinct tangent offsets (Float64 array, n + 1 entries)
    sa: object          # their sin
    weight: object      # their weights (sum 1; Float array)
    eta2: object        # eta^2
    eta2m1: object      # eta^2 - 1
    kd: object
    area: object
    albedo: tuple       # RGB
    gs_k: object        # -1 / (8 gamma_s^2): the surface Gaussian of (theta_i + theta_r)^2
    gs_c: object        # 1 / (sqrt(2 pi) gamma_s)
    gv_k: object        # -1 / (8 gamma_v^2)
    gv_c: object        # (1 - kd) / (sqrt(2 pi) gamma_v)
    inv_sig: tuple      # 1 / (2 gamma_s), 1 / (2 gamma_v): the sampler's Gaussians, 1/rad
    lobe_p: tuple       # surface, volume, isotropic: the sampler's lobes within the thread
    inv_eta: object = None   # 1 / eta, 1 / eta^2: the double-precision Fresnel's scales
    inv_eta2: object = None


@dataclasses.dataclass(frozen=True)
class Consts:
    """Everything the kernel needs of a :class:`brdf.Fabric`, from its plan
    (:class:`brdf.FabricPlan`); the options typed as the plan types them.

    ``comp_*`` is the sampler's flat component table (component 0 the cosine-weighted
    hemisphere, then per thread, tangent offset and lobe; :func:`brdf.sampling.sample`'s
    mixture), padded to :data:`MIN_COMPONENTS` or the next power of two with components
    that are never drawn; ``comp_cdf`` is its cumulative distribution (exactly 1 from the
    last real component on). Without the sampler (``consts(..., lobes=None)``) they are
    None and ``sampled`` is false for both threads.
    """

    types: Types
    threads: tuple
    masking: bool
    reweighting: bool
    transmission: Transmission
    gap: Gap
    rotation: float     # radians
    gap_area: object    # 1 - A_1 - A_2: the gap's share of the area
    sampled: tuple      # bool per thread: does the sampler draw its lobes (thread_p > 0)
    cos_p: object       # probability of the cosine-weighted component
    thread_p: tuple     # probability of each thread's lobes (brdf.sampling.lobe_probabilities)
    comp_size: int = 0  # entries in the padded table
    comp_cdf: object = None
    comp_thread: object = None
    comp_ca: object = None
    comp_sa: object = None
    comp_kind: object = None   # -1 cosine, 0 surface, 1 volume, 2 isotropic
    comp_sigma: object = None  # standard deviation of the longitudinal Gaussian, radians


def opaque(x, kind):
    """``x`` (a Python number or sequence) as an opaque value or evaluated array of the JIT
    type ``kind``; the Python number or tuple for a non-JIT ``kind`` (``scalar_rgb``)."""
    if not dr.is_jit_v(kind):
        return tuple(x) if isinstance(x, (tuple, list)) else x
    if isinstance(x, (tuple, list)):
        return kind(x)                      # evaluated: the kernel takes its address
    return dr.opaque(kind, x)


def _clamped(x: float) -> float:
    """eta or a gamma within :data:`brdf.shading.PARAM_CLAMP` (as the NumPy kernel)."""
    lo, hi = shading.PARAM_CLAMP
    return min(max(float(x), lo), hi)


def _thread_consts(c, lobe_p, t: Types) -> ThreadConsts:
    """:class:`ThreadConsts` of the thread whose plan is ``c``."""
    kd, gs, gv = float(c.kd), _clamped(c.gamma_s), _clamped(c.gamma_v)
    eta2 = _clamped(c.eta) ** 2
    f = lambda x: opaque(float(x), t.Float)  # noqa: E731
    # a table of one entry would be a scalar to Dr.Jit, and another kernel: each gets an
    # entry the loop never reads
    ca, sa, w = (tuple(map(float, x)) + (v,) for x, v in ((c.ca, 1.0), (c.sa, 0.0),
                                                            (c.weight, 0.0)))
    return ThreadConsts(
        opaque(len(c.ca), t.UInt32), opaque(ca, t.Float64), opaque(sa, t.Float64),
        opaque(w, t.Float), f(eta2), f(eta2 - 1.0), f(kd), f(c.area),
        tuple(f(a) for a in c.albedo),
        f(shading.gaussian_exponent(gs)), f(shading.gaussian_norm(gs)),
        f(shading.gaussian_exponent(gv)), f(shading.f_rv_coefficients(kd, gv)),
        (f(0.5 / gs), f(0.5 / gv)), tuple(f(p) for p in lobe_p),
        f(1.0 / _clamped(c.eta)), f(1.0 / eta2))


def _components(plan, thread_p, lobe_p) -> list:
    """The sampler's components: (probability, thread, cos, sin, kind, sigma) each."""
    rows = [(1.0 - float(thread_p.sum()), 0, 1.0, 0.0, -1, 1.0)]
    for j, c in enumerate(plan.threads):
        if thread_p[j] == 0.0:
            continue
        for cj, sj, w in zip(c.ca, c.sa, c.weight):
            for k in range(3):
                rows.append((float(thread_p[j] * w * lobe_p[j, k]), j, float(cj), float(sj),
                             k, 2.0 * float(c.gamma_s if k == 0 else c.gamma_v)))
    return rows


def _sampler_table(plan, thread_p, lobe_p, t: Types) -> dict:
    """The ``comp_*`` fields of :class:`Consts`."""
    rows = _components(plan, thread_p, lobe_p)
    size = max(MIN_COMPONENTS, 1 << (len(rows) - 1).bit_length())
    cdf = list(itertools.accumulate(r[0] for r in rows))
    cdf = [min(x / cdf[-1], 1.0) for x in cdf[:-1]] + [1.0] * (size - len(rows) + 1)
    rows += [rows[0]] * (size - len(rows))     # never drawn: u < 1 = the last real cdf
    cols = list(zip(*rows))
    return dict(comp_size=size, comp_cdf=opaque(cdf, t.Float),
                comp_thread=opaque([float(j) for j in cols[1]], t.Float),
                comp_ca=opaque(list(cols[2]), t.Float), comp_sa=opaque(list(cols[3]), t.Float),
                comp_kind=opaque([float(k) for k in cols[4]], t.Float),
                comp_sigma=opaque(list(cols[5]), t.Float))


def consts(plan, types: Types, lobes=None) -> Consts:
    """The kernel's constants of ``plan`` (a :class:`brdf.FabricPlan`) in ``types``.

    ``lobes``: the sampler's ``(thread_p, lobe_p)`` (:func:`brdf.sampling.lobe_probabilities`
    of the plan), for its tables and density (the Mitsuba plugin's ``sample`` and ``pdf``);
    None for f_r alone.
    """
    t = types
    if lobes is None:
        thread_p, lobe_p = np.zeros(2), np.zeros((2, 3))
    else:
        thread_p, lobe_p = (np.asarray(x, dtype=np.float64) for x in lobes)
    threads = tuple(_thread_consts(c, lobe_p[j], t) for j, c in enumerate(plan.threads))
    opts = plan.options
    area = 1.0 - float(plan.threads[0].area) - float(plan.threads[1].area)
    table = {} if lobes is None else _sampler_table(plan, thread_p, lobe_p, t)
    return Consts(t, threads, opts.masking, opts.reweighting, opts.transmission,
                  opts.gap, float(opts.rotation), opaque(area, t.Float),
                  tuple(lobes is not None and bool(p > 0.0) for p in thread_p),
                  opaque(1.0 - float(thread_p.sum()), t.Float),
                  tuple(opaque(float(p), t.Float) for p in thread_p), **table)
