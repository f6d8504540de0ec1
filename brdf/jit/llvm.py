r"""The Dr.Jit kernel (:mod:`brdf.jit.kernel`) on the LLVM backend in float64 (a batch's
shading also in float32): what ``Fabric.eval`` (:func:`eval_pairs`) and ``Prepared.eval``
(:class:`PreparedJit`) run when
:func:`brdf.jit.backend` is ``"drjit"``, and the gradients of a fit's batched f_r with
respect to the optical parameters (:meth:`PreparedJit.eval_and_grad`, Dr.Jit's forward-mode
AD).

Every number of a fabric or a batch is an evaluated array or an opaque value, never a
literal of the kernel's code: one compiled kernel per set of options serves every fabric,
pair count and batch size (Dr.Jit's kernel cache keeps it), and only its Python tracing is
repeated per call. ``Fabric.eval`` runs one fused kernel, a lane a pair, a symbolic loop over
each thread's tangent samples. ``Prepared`` runs the samples' geometry once (a lane a pair
and a sample, :func:`brdf.jit.kernel.sample_geometry`), then each ``eval`` one kernel, a
lane a parameter set and a pair, whose loop over the samples gathers that geometry and
shades it (:func:`brdf.jit.kernel.sample_shading`).

Imports Dr.Jit at its top: it is imported only through :func:`brdf.jit.compiled`.
"""

from __future__ import annotations

import dataclasses
import math
import os
import weakref

import numpy as np

# optional dependency: this module is imported only through brdf.jit.compiled()
import drjit as dr
from drjit.llvm.ad import Array3f64, Array4f64, Float32, Float64, UInt32
from drjit.llvm.ad import Array4f as Array4f32

from brdf import jit
from brdf.combine import DENOM_MIN
from brdf.jit.consts import GAUSS_NORM, Consts, Types, consts, opaque
from brdf.jit.kernel import (SampleGeometry, at, fabric_q, fabric_sums, inverse_rho, loop,
                             sample_geometry, sample_shading, thread_axes)
from brdf.options import Transmission
from brdf.shading import PARAM_CLAMP, PARAM_CLAMP_32

__all__ = ["TYPES", "probe", "apply_thread_limit", "plan_consts", "eval_pairs",
           "eval_rotated", "PreparedJit", "GRAD_PARAMS", "CHUNK_PAIRS"]

#: The kernel's types here: float64 throughout, on the LLVM backend.
TYPES = Types(Float64, Float64, UInt32, Array3f64, Array3f64)
#: The parameters :meth:`PreparedJit.eval_and_grad` differentiates by (``Prepared.eval``'s
#: keywords).
GRAD_PARAMS = ("eta", "kd", "gamma_s", "gamma_v", "area", "albedo")
#: Pairs per kernel launch of :func:`eval_pairs`: the launch's arrays (about 100 bytes a
#: pair) stay near 25 MiB however many pairs are asked for, and the Python tracing of a
#: launch (about 0.5 ms) is a few thousandths of its run.
CHUNK_PAIRS = 1 << 18
_ALIGN = 128                        # bytes: a vector load of 16 float64
_CONSTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()   # plan -> plan_consts


def probe(min_llvm: int) -> tuple[bool, str]:
    """Whether the LLVM backend runs here (:func:`brdf.jit.available`)."""
    if not dr.has_backend(dr.JitBackend.LLVM):
        return False, "Dr.Jit's LLVM backend did not initialise (no libLLVM found; set " \
                      "DRJIT_LIBLLVM_PATH)"
    version = dr.detail.llvm_version()
    if version[0] < min_llvm:
        return False, (f"Dr.Jit found LLVM {'.'.join(map(str, version))}, which fails on its "
                       f"kernels; set DRJIT_LIBLLVM_PATH to a libLLVM {min_llvm} or later")
    x = dr.maximum(Float64([1.0, 2.0]), Float64([1.5, 0.0]))
    if float(dr.sum(x)[0]) != 3.5:
        return False, "a test kernel gave a wrong answer"
    return True, ""


def apply_thread_limit(restore: bool = False) -> None:
    """Dr.Jit's thread count from :func:`brdf.jit.thread_limit`, where one is set; else,
    with ``restore``, one a core (Dr.Jit's default), else left as it is."""
    n = jit.thread_limit()
    if n is not None or restore:
        dr.set_thread_count(n if n is not None else (os.cpu_count() or 1))


apply_thread_limit()


def plan_consts(plan) -> tuple[Consts, Float64, Float64]:
    """The kernel's constants of ``plan`` and its rotation's (cos, sin), made once a plan."""
    got = _CONSTS.get(plan)
    if got is None:
        rot = plan.options.rotation
        # NumPy's cos and sin, as FabricPlan.frames takes them (math's may differ by an ulp)
        got = (consts(plan, TYPES), opaque(float(np.cos(rot)), Float64),
               opaque(float(np.sin(rot)), Float64))
        _CONSTS[plan] = got
    return got


def _aligned(a: np.ndarray, dtype=np.float64) -> np.ndarray:
    """A copy of ``a`` (float64, or ``dtype``) starting at a 128-byte boundary (Dr.Jit maps
    NumPy's memory, and a kernel's vector loads state its alignment: another alignment,
    another kernel, compiled anew, about 0.3 s)."""
    size = np.dtype(dtype).itemsize
    buf = np.empty(a.size + _ALIGN // size, dtype)
    off = (-buf.ctypes.data % _ALIGN) // size
    out = buf[off:off + a.size]
    out[...] = a
    return out


def _vector(w: np.ndarray) -> Array3f64:
    """(n, 3) float64 directions as an Array3f64 (aligned: :func:`_aligned`)."""
    return Array3f64(*(Float64(_aligned(w[:, c])) for c in range(3)))


def _inverse_denominator(q, zi):
    """1 / max(Q n.wi, DENOM_MIN), 0 where Q or n . wi is not positive
    (:func:`brdf.combine.inverse_denominator`)."""
    ok = (q > 0.0) & (zi > 0.0)
    return dr.select(ok, 1.0 / dr.maximum(q * zi, DENOM_MIN), 0.0)


def _rgb(parts, inv):
    """sum_j a_j (S_j + A_j V_j) / (Q n.wi) (``parts``: per thread (area, albedo, surf, vol)),
    in the order of :func:`brdf.combine.combine_rgb`."""
    (a1, alb1, s1, v1), (a2, alb2, s2, v2) = parts
    base = (s1 * a1 + s2 * a2) * inv
    w1, w2 = v1 * inv * a1, v2 * inv * a2
    return Array3f64(*(w1 * alb1[ch] + base + w2 * alb2[ch] for ch in range(3)))


def _numpy(x) -> np.ndarray:
    """An evaluated Array3f64 as an (n, 3) float64 array (a copy per component: the
    conversion of the whole would launch a kernel, one per alignment of NumPy's buffer)."""
    return np.stack([np.asarray(c.numpy(), dtype=np.float64) for c in (x.x, x.y, x.z)],
                    axis=1)


def eval_pairs(plan, wi: np.ndarray, wo: np.ndarray, split: bool = False):
    """f_r (1/sr) of unit (C, 3) pairs above the horizon: (C, 3) RGB, or per thread (C, 2,
    3) with ``split`` (:meth:`brdf.FabricPlan.eval`'s kernel), in chunks of at most
    :data:`CHUNK_PAIRS` pairs (one kernel launch each)."""
    out = np.empty((wi.shape[0], 2, 3) if split else (wi.shape[0], 3))
    for start in range(0, wi.shape[0], CHUNK_PAIRS):
        sl = slice(start, start + CHUNK_PAIRS)
        out[sl] = _eval_chunk(plan, wi[sl], wo[sl], split)
    return out


def _eval_chunk(plan, wi, wo, split):
    """:func:`eval_pairs` of one chunk."""
    k, rc, rs = plan_consts(plan)
    light, view = _vector(wi), _vector(wo)
    sums = fabric_sums(k, light, view, rc, rs)
    inv = _inverse_denominator(fabric_q(k, sums, light.z, view.z), light.z)
    parts = [(th.area, th.albedo, s[0], s[1]) for th, s in zip(k.threads, sums)]
    if not split:
        out = _rgb(parts, inv)
        dr.eval(out)
        return _numpy(out)
    outs = [Array3f64(*(a * (s + alb[ch] * v) * inv for ch in range(3)))
            for a, alb, s, v in parts]
    dr.eval(outs)
    return np.stack([_numpy(o) for o in outs], axis=1)


def eval_rotated(plan, wi: np.ndarray, wo: np.ndarray, par, rotation: np.ndarray):
    """f_r (1/sr), (nb, C, 3), of unit (C, 3) pairs above the horizon for the batch ``par``
    (checked, gammas in radians), parameter set b under its own ``rotation[b]`` (radians)
    of both threads: one fused kernel, a lane a pair and a set (pair-major), its loop over
    each thread's tangent samples forming the geometry under the lane's rotation and
    shading it (what ``Fabric.eval`` runs, with a batch's parameters): a fit that frees the
    rotation prepares nothing per set."""
    k = plan_consts(plan)[0]
    nb, size = par.eta.shape[0], wi.shape[0]
    nbo = opaque(nb, UInt32)
    idx = dr.arange(UInt32, nb * size)
    c = idx // nbo
    b = idx - c * nbo
    x = PreparedJit.inputs(par)
    row = lambda a: dr.gather(Float64, a, b)  # noqa: E731
    light, view = (Array3f64(*(dr.gather(Float64, v, c) for v in _vector(w)))
                   for w in (wi, wo))
    rc, rs = (row(Float64(_aligned(f(rotation)))) for f in (np.cos, np.sin))
    threads = []
    for j, th in enumerate(k.threads):
        rcj = _RowConsts(*(row(x[name][j]) for name in ("eta", "kd", "gamma_s", "gamma_v")))
        threads.append(dataclasses.replace(
            th, **{name: getattr(rcj, name) for name in _RowConsts.NAMES},
            area=row(x["area"][j]), albedo=tuple(map(row, x["albedo"][j]))))
    a1, a2 = threads[0].area, threads[1].area
    k = dataclasses.replace(k, threads=tuple(threads), gap_area=1.0 - a1 - a2)
    sums = fabric_sums(k, light, view, rc, rs)
    inv = _inverse_denominator(fabric_q(k, sums, light.z, view.z), light.z)
    out = _rgb([(th.area, th.albedo, s[0], s[1]) for th, s in zip(threads, sums)], inv)
    buf = dr.empty(Float64, nb * size * 3)
    dr.scatter(buf, out, b * opaque(size, UInt32) + c)
    dr.eval(buf)
    return np.asarray(buf.numpy()).reshape(nb, size, 3)


class _RowConsts:
    """A thread's optical constants per lane (:class:`brdf.jit.consts.ThreadConsts`' names)
    from its raw parameters per lane (eta, kd, gammas in radians), clamped as the NumPy
    kernel clamps them (:data:`brdf.shading.PARAM_CLAMP`, or ``PARAM_CLAMP_32`` for float32
    shading: formed in float64, then rounded, as :func:`brdf.shading.thread_shade` does)."""

    #: The names :func:`brdf.jit.kernel.sample_shading` reads.
    NAMES = ("eta2", "eta2m1", "inv_eta", "inv_eta2", "kd", "gs_k", "gs_c", "gv_k", "gv_c")

    def __init__(self, eta, kd, gamma_s, gamma_v, single=False):
        clamp = PARAM_CLAMP_32 if single else PARAM_CLAMP
        eta, gs, gv = (dr.clip(x, *clamp) for x in (eta, gamma_s, gamma_v))
        cast = Float32 if single else (lambda v: v)
        self.eta2 = cast(eta * eta)
        self.eta2m1 = cast(eta * eta - 1.0)
        # three divisions a lane (the reciprocals; within PARAM_CLAMP their squares stay
        # normal numbers), not six: a few ulps from NumPy's quotients
        ieta, igs, igv = 1.0 / eta, 1.0 / gs, 1.0 / gv
        self.inv_eta, self.inv_eta2 = ieta, ieta * ieta
        self.kd = cast(kd)
        self.gs_k, self.gs_c = cast(-0.125 * (igs * igs)), cast(GAUSS_NORM * igs)
        self.gv_k, self.gv_c = cast(-0.125 * (igv * igv)), cast((1.0 - kd) * GAUSS_NORM * igv)


class _ThreadGeom:
    """One thread's geometry of the prepared pairs, evaluated: arrays of C x S entries
    (pair-major: entry c S + s is sample s of pair c, so that a lane's loop over the samples
    reads consecutive entries), ``ks`` and ``kv`` multiplied by the sample's weight, and
    the P mean of each pair."""

    def __init__(self, g: SampleGeometry, keep_cos: bool, pmean):
        # packed four (six) to an entry: one packet gather per lane and sample
        cols = (g.th2, g.cg, g.ks, g.kv) + ((g.ci, g.cr, g.ci, g.cr) if keep_cos else ())
        self.width = len(cols)
        self.host = np.stack([np.asarray(c.numpy()) for c in cols], axis=1).ravel()
        self.packed = Float64(_aligned(self.host))
        self.packed32 = None
        self.pmean = pmean

    def at(self, i, single=False) -> SampleGeometry:
        """The geometry of entries ``i`` (one per lane), float32 with ``single`` (clipped to
        its finite range, as ``Prepared``'s NumPy float32 copies, made on first use)."""
        if single and self.packed32 is None:
            f32 = np.finfo(np.float32).max
            self.packed32 = Float32(_aligned(np.clip(self.host, -f32, f32), np.float32))
        packed, kind = (self.packed32, Array4f32) if single else (self.packed, Array4f64)
        v = dr.gather(kind, packed, i * (self.width // 4))
        if self.width == 4:
            return SampleGeometry(v.x, v.y, v.z, v.w, None, None, None, None, None, None)
        u = dr.gather(kind, packed, i * 2 + 1)
        return SampleGeometry(v.x, v.y, v.z, v.w, None, u.x, u.y, None, None, None)


class PreparedJit:
    """The Dr.Jit half of :class:`brdf.Prepared`: n fixed pairs' geometry, shaded for
    batches of parameter sets.

    Parameters
    ----------
    plan : brdf.FabricPlan
    wi, wo : ndarray, shape (C, 3)
        Unit directions above the horizon (``Prepared`` has checked and filtered them).
    """

    def __init__(self, plan, wi: np.ndarray, wo: np.ndarray):
        self.plan = plan
        self.k, rc, rs = plan_consts(plan)
        self.size = wi.shape[0]
        self._n = opaque(self.size, UInt32)
        if not self.size:                   # nothing to shade (Dr.Jit has no empty kernels)
            return
        light, view = _vector(wi), _vector(wo)
        self._zi, self._zo = light.z, view.z
        self._geoms = [self._thread_geometry(j, light, view, rc, rs) for j in range(2)]

    def _thread_geometry(self, j, light, view, rc, rs) -> _ThreadGeom:
        """Thread j's geometry, a lane a (pair, sample)."""
        k, th, tp = self.k, self.k.threads[j], self.plan.threads[j]
        ns = tp.ca.size
        idx = dr.arange(UInt32, ns * self.size)
        c = idx // th.n
        s = idx - c * th.n
        axes = [thread_axes(Array3f64(*(dr.gather(Float64, x, c) for x in w)), rc, rs)[j]
                for w in (light, view)]
        g = sample_geometry(k, at(th.ca, s, Float64), at(th.sa, s, Float64), *axes,
                            tuple(inverse_rho(k, a) for a in axes))
        w = at(th.weight, s, Float64)           # the sample's weight, in its two factors
        g = g._replace(ks=g.ks * w, kv=g.kv * w)
        keep_cos = k.transmission is Transmission.LONGITUDINAL
        dr.eval(g.th2, g.cg, g.ks, g.kv, *((g.ci, g.cr) if keep_cos else ()),
                *((g.p,) if k.reweighting else ()))
        pmean = None
        if k.reweighting:
            p = np.asarray(g.p.numpy(), dtype=np.float64).reshape(self.size, ns)
            pmean = Float64(_aligned(p @ np.asarray(tp.weight)))
        return _ThreadGeom(g, keep_cos, pmean)

    @staticmethod
    def inputs(par) -> dict:
        """``par``'s arrays as Dr.Jit arrays: per name a list of the two threads' Float64
        arrays (nb,); ``albedo`` a list of the threads' (R, G, B) triples."""
        col = lambda a, j: Float64(_aligned(a[:, j]))  # noqa: E731
        out = {name: [col(getattr(par, name), j) for j in range(2)]
               for name in ("eta", "kd", "gamma_s", "gamma_v", "area")}
        out["albedo"] = [tuple(col(par.albedo[:, j], ch) for ch in range(3)) for j in range(2)]
        return out

    def shade(self, x: dict, nb: int, single: bool = False) -> tuple[Array3f64, UInt32]:
        """f_r (1/sr) of every (pair, parameter set), a lane each (pair-major: the lanes of
        a vector share their pair, and so the geometry they read), from the Dr.Jit arrays
        ``x`` of :meth:`inputs` (unevaluated: AD may flow through it), and each lane's
        index (b, c) in the (nb, C) result. With ``single`` the samples are
        shaded and summed in float32, the threads combined in float64."""
        k, nbo = self.k, opaque(nb, UInt32)
        idx = dr.arange(UInt32, nb * self.size)
        c = idx // nbo
        b = idx - c * nbo
        row = lambda a: dr.gather(Float64, a, b)  # noqa: E731
        zero = (Float32 if single else Float64)(0.0)
        sums, parts = [], []
        for j, (th, geom) in enumerate(zip(k.threads, self._geoms)):
            rc = _RowConsts(*(row(x[name][j]) for name in ("eta", "kd", "gamma_s", "gamma_v")),
                            single=single)

            def terms(s, th=th, geom=geom, rc=rc):      # (weights in ks, kv)
                return sample_shading(rc, geom.at(c * th.n + s, single), k.transmission)

            surf, vol = (Float64(v) for v in loop(th.n, terms, UInt32(0), zero, zero))
            pmean = None if geom.pmean is None else dr.gather(Float64, geom.pmean, c)
            sums.append((surf, vol, pmean))
            parts.append((row(x["area"][j]), tuple(map(row, x["albedo"][j])), surf, vol))
        zi, zo = dr.gather(Float64, self._zi, c), dr.gather(Float64, self._zo, c)
        a1, a2 = parts[0][0], parts[1][0]
        q = fabric_q(k, sums, zi, zo, (a1, a2, 1.0 - a1 - a2))
        return _rgb(parts, _inverse_denominator(q, zi)), b * self._n + c

    def eval(self, par, single: bool = False) -> np.ndarray:
        """f_r (1/sr), shape (nb, C, 3), of the batch ``par`` (checked, gammas in radians);
        shaded in float32 with ``single``."""
        nb = par.eta.shape[0]
        if not self.size:
            return np.zeros((nb, 0, 3))
        return self._to_numpy(*self.shade(self.inputs(par), nb, single), nb)

    def _to_numpy(self, x, dest, nb) -> np.ndarray:
        """The Array3f64 ``x`` of :meth:`shade`'s lanes (pair-major), unevaluated, as (nb,
        C, 3): scattered by the kernel itself (to ``dest``) into one buffer in that order,
        which NumPy then reads without a transposing copy."""
        buf = dr.empty(Float64, nb * self.size * 3)
        dr.scatter(buf, x, dest)            # one packet of three a lane: (b, c, :)
        dr.eval(buf)
        return np.asarray(buf.numpy()).reshape(nb, self.size, 3)

    def eval_and_grad(self, par) -> tuple[np.ndarray, dict]:
        """f_r (nb, C, 3) and its derivatives by each of :data:`GRAD_PARAMS`, by Dr.Jit's
        forward-mode AD (one pass a parameter and thread).

        Returns
        -------
        f : ndarray, shape (nb, C, 3)
        grads : dict of ndarray, shape (nb, C, 3, 2)
            ``grads[name][b, c, ch, j]`` = d f_r[b, c, ch] / d name_j of set b (per degree
            for the gammas; for ``albedo`` the derivative by thread j's albedo in the same
            channel ch, the others' being 0).
        """
        nb = par.eta.shape[0]
        f = self.eval(par)
        grads = {}
        for name in GRAD_PARAMS:
            cols = []
            for j in range(2):
                x = self.inputs(par)
                var = x[name][j] if name == "albedo" else (x[name][j],)
                for v in var:
                    dr.enable_grad(v)
                out, dest = self.shade(x, nb)
                for v in var:
                    dr.set_grad(v, 1.0)
                dr.forward_to(out)
                cols.append(self._to_numpy(dr.grad(out), dest, nb))
            scale = math.pi / 180.0 if name.startswith("gamma") else 1.0
            grads[name] = np.stack(cols, axis=-1) * scale
        return f, grads
