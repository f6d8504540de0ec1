r"""A fabric's compiled form: its typed options and each thread's constants, and the one
orchestration of the kernel that ``Fabric.eval``, ``Fabric.prepare`` (:class:`brdf.Prepared`),
the sampler and the Mitsuba plugin's constants read.

A :class:`FabricPlan` is frozen and holds no direction: everything about a fabric that
:mod:`brdf.kernel` and :mod:`brdf.shading` need, computed once when the fabric is made
(``Fabric.plan``). Per chunk of direction pairs the kernel runs in two steps, which fits
separate (the first once, the second per parameter set):

1. :meth:`FabricPlan.geometry`: each thread's :class:`~brdf.kernel.ThreadGeometry`;
2. :meth:`FabricPlan.shade`, then :meth:`FabricPlan.combine_into`: the threads' surface and
   volume sums for a batch of optical parameters, then Q and the RGB f_r.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence

import numpy as np

from brdf import jit
from brdf.combine import combine_rgb, inverse_denominator, normalization_q
from brdf.frames import flat_pairs
from brdf.kernel import ThreadGeometry, thread_geometry
from brdf.options import FabricOptions, Gap, Transmission
from brdf.shading import SHADE_BLOCK, thread_shade

__all__ = ["FabricPlan", "ThreadPlan", "ShadeParams", "plan_of", "CHUNK_ELEMENTS"]

#: Target number of (pair, sample) elements per chunk of :meth:`FabricPlan.eval`: large
#: enough to amortize NumPy's per-call cost, small enough that the working set stays in
#: cache. 2^15 since the kernel's named blocks and underflow guards added per-chunk calls
#: (2026-12-01, 2-core EPYC, CPU time per 10^5 pairs: velvet 0.337-0.352 s at 2^15 against
#: 0.343-0.354 at 2^14 and 0.424-0.438 at 2^16, which falls out of the 1 MiB L2).
CHUNK_ELEMENTS = 1 << 15


def _frozen(a) -> np.ndarray:
    """A read-only float64 copy."""
    a = np.array(a, dtype=np.float64)
    a.setflags(write=False)
    return a


@dataclasses.dataclass(frozen=True, eq=False)
class ThreadPlan:
    """One thread's constants (nothing here depends on the directions).

    Attributes
    ----------
    ca, sa : ndarray, shape (S,)
        cos and sin of the distinct tangent offsets (read-only).
    weight : ndarray, shape (S,)
        Weight of each distinct offset (sum 1; read-only).
    gamma_s, gamma_v : float
        Lobe widths, radians.
    eta, kd, area : float
    albedo : tuple of three float
    """

    ca: np.ndarray
    sa: np.ndarray
    weight: np.ndarray
    gamma_s: float
    gamma_v: float
    eta: float
    kd: float
    area: float
    albedo: tuple[float, float, float]

    @classmethod
    def of(cls, thread, options: FabricOptions) -> "ThreadPlan":
        """The constants of a :class:`brdf.Thread` under ``options``."""
        alpha, weight = thread.curve.samples(options.tangent_samples, options.tangent_sampling)
        a = np.radians(alpha)
        return cls(_frozen(np.cos(a)), _frozen(np.sin(a)), _frozen(weight),
                   float(np.radians(thread.gamma_s)), float(np.radians(thread.gamma_v)),
                   float(thread.eta), float(thread.kd), float(thread.area),
                   tuple(float(x) for x in thread.albedo))


@dataclasses.dataclass(frozen=True)
class ShadeParams:
    """Optical parameters of a batch of nb parameter sets, flat: ``eta``, ``kd``,
    ``gamma_s``, ``gamma_v`` (radians) and ``area`` of shape (nb, 2), ``albedo`` (nb, 2, 3)."""

    eta: np.ndarray
    kd: np.ndarray
    gamma_s: np.ndarray
    gamma_v: np.ndarray
    area: np.ndarray
    albedo: np.ndarray


@dataclasses.dataclass(frozen=True, eq=False)
class FabricPlan:
    """A fabric compiled: typed options and the two threads' constants.

    Attributes
    ----------
    options : brdf.options.FabricOptions
    threads : tuple of two ThreadPlan
        Warp, weft.

    Examples
    --------
    >>> import brdf
    >>> plan = brdf.fabric("linen_plain", transmission="longitudinal").plan
    >>> plan.options.transmission is brdf.Transmission.LONGITUDINAL
    True
    >>> plan.threads[0].ca.size, round(plan.threads[0].gamma_s, 6)
    (32, 0.20944)
    """

    options: FabricOptions
    threads: tuple[ThreadPlan, ThreadPlan]

    @classmethod
    def compile(cls, threads: Sequence, options: FabricOptions) -> "FabricPlan":
        """The plan of two :class:`brdf.Thread` (checked by ``Fabric``) under ``options``."""
        return cls(options, tuple(ThreadPlan.of(t, options) for t in threads))

    @property
    def samples(self) -> int:
        """The larger number of distinct tangent samples of the two threads."""
        return max(t.ca.size for t in self.threads)

    @functools.cached_property
    def params(self) -> ShadeParams:
        """The threads' own optical parameters as a batch of one set (read-only arrays,
        made on first use)."""
        th = self.threads
        row = lambda name: _frozen([[getattr(t, name) for t in th]])  # noqa: E731
        return ShadeParams(row("eta"), row("kd"), row("gamma_s"), row("gamma_v"),
                           row("area"), _frozen([[t.albedo for t in th]]))

    # -- the kernel, step 1: geometry ----------------------------------------------------
    def frames(self, wi, wo):
        """Per-pair dot products of unit (C, 3) ``wi``, ``wo`` with each thread's t0, b and
        n: per thread the six arrays (C, 1) that :func:`brdf.kernel.thread_geometry` takes."""
        rot = self.options.rotation
        c, s = np.cos(rot), np.sin(rot)
        out = []
        for w in (wi, wo):
            t = w[:, 0:1] * c + w[:, 1:2] * s      # w . t0 of thread 1
            b = w[:, 1:2] * c - w[:, 0:1] * s      # w . b  of thread 1 (= w . t0 of thread 2)
            out.append((t, b, w[:, 2:3]))
        (t_i, b_i, z_i), (t_o, b_o, z_o) = out
        # Thread 2 is thread 1 turned 90 degrees about n: t0' = b, b' = n x b = -t0.
        return ((t_i, b_i, z_i, t_o, b_o, z_o), (b_i, -t_i, z_i, b_o, -t_o, z_o))

    def geometry(self, wi, wo) -> list[ThreadGeometry]:
        """Each thread's :class:`~brdf.kernel.ThreadGeometry` for unit (C, 3) pairs above the
        horizon."""
        opts = self.options
        keep_cos = opts.transmission is Transmission.LONGITUDINAL
        return [thread_geometry(*side, t.ca, t.sa, t.weight, with_masking=opts.masking,
                                with_reweighting=opts.reweighting, keep_cos=keep_cos)
                for side, t in zip(self.frames(wi, wo), self.threads)]

    # -- the kernel, step 2: shading and the sum over threads -----------------------------
    def shade(self, geoms, par: ShadeParams, *, block=None, scratch=None) -> np.ndarray:
        """The threads' sums (:func:`brdf.shading.thread_shade`): an array (2, 2, nb, C) of
        per thread the surface and the volume sums, in the geometry's dtype (kept in
        ``scratch``'s buffer "sums" when given)."""
        nb, nc = par.eta.shape[0], geoms[0].th2.shape[0]
        shape, dtype = (2, 2, nb, nc), geoms[0].th2.dtype
        shades = np.empty(shape, dtype) if scratch is None else scratch.array("sums", shape,
                                                                              dtype)
        for j, (g, t) in enumerate(zip(geoms, self.threads)):
            thread_shade(g, t.weight, par.eta[:, j], par.kd[:, j], par.gamma_s[:, j],
                         par.gamma_v[:, j], self.options.transmission, out=tuple(shades[j]),
                         block=block, scratch=scratch)
        return shades

    def q(self, pmeans, area1, area2, zi, zo):
        """Q of MODEL.md from the threads' P means (:func:`brdf.combine.normalization_q`);
        1 with reweighting off. ``area`` broadcasts (nb, 1) over pairs."""
        if not self.options.reweighting:
            return 1.0
        gap = zi if self.options.gap is Gap.INCIDENT else zo
        return normalization_q(pmeans[0], pmeans[1], area1, area2, gap)

    def combine_into(self, shades, pmeans, zi, zo, par: ShadeParams, vals, *, block=None):
        """f_r = (a_1 S_1 + a_2 S_2) / (Q n.wi) into ``vals`` (nb, C, 3), in blocks of pairs.

        ``shades`` from :meth:`shade`; ``pmeans`` the threads' float64 P means (C,) (None
        with reweighting off); ``zi``, ``zo`` (C,) the directions' n components.
        """
        nb, nc = shades.shape[2:]
        step = max(1, (block or SHADE_BLOCK) // (4 * max(nb, 1)))
        a1, a2 = par.area[:, 0, None], par.area[:, 1, None]
        for c0 in range(0, nc, step):
            sl = slice(c0, c0 + step)
            pm = [None if p is None else p[sl] for p in pmeans]
            inv = inverse_denominator(self.q(pm, a1, a2, zi[sl], zo[sl]), zi[sl])
            combine_rgb(shades[:, 0, :, sl], shades[:, 1, :, sl], par.area, par.albedo, inv,
                        vals[:, sl])
        return vals

    def split_into(self, shades, pmeans, zi, zo, par: ShadeParams, out):
        """Each thread's share a_j S_j / (Q n.wi) of the first parameter set into ``out``
        (C, 2, 3)."""
        inv = inverse_denominator(self.q(pmeans, par.area[0, 0], par.area[0, 1], zi, zo), zi)
        for j in range(2):
            part = par.area[0, j] * (shades[j, 0, 0][:, None]
                                     + par.albedo[0, j] * shades[j, 1, 0][:, None])
            out[:, j] = part * inv[:, None]
        return out

    # -- evaluation ----------------------------------------------------------------------
    def eval(self, wi, wo, split: bool = False) -> np.ndarray:
        """f_r (1/sr) of (..., 3) direction pairs, RGB (..., 3), or per thread (..., 2, 3)
        with ``split``: what ``Fabric.eval`` and ``Fabric.eval_threads`` return, from the
        kernel :func:`brdf.jit.backend` names (NumPy's, or Dr.Jit's in float64)."""
        wi, wo, shape, bad, below = flat_pairs(wi, wo)
        n = wi.shape[0]
        out = np.zeros((n, 2, 3) if split else (n, 3))
        ok = ~(bad | below)
        if ok.all():
            self._eval_into(wi, wo, out, split)
        elif ok.any():
            res = np.zeros((int(ok.sum()),) + out.shape[1:])
            self._eval_into(wi[ok], wo[ok], res, split)
            out[ok] = res
        out[bad] = np.nan
        return out.reshape(shape + out.shape[1:])

    def _eval_into(self, wi, wo, out, split):
        if jit.use_jit(self, wi.shape[0]):   # the Dr.Jit kernel (brdf.jit), float64 on LLVM
            exact = jit.tiny_pairs(wi, wo)   # NumPy's (brdf.jit's notes)
            if exact.any():
                part = np.zeros((int(exact.sum()),) + out.shape[1:])
                self._numpy_into(wi[exact], wo[exact], part, split)
                out[exact] = part
                keep = ~exact
                if keep.any():
                    out[keep] = jit.compiled().eval_pairs(self, wi[keep], wo[keep], split)
            else:
                out[...] = jit.compiled().eval_pairs(self, wi, wo, split)
            return
        self._numpy_into(wi, wo, out, split)

    def _numpy_into(self, wi, wo, out, split):
        """The NumPy kernel's f_r of unit pairs above the horizon into ``out``."""
        par = self.params
        chunk = max(64, CHUNK_ELEMENTS // self.samples)
        for start in range(0, wi.shape[0], chunk):
            sl = slice(start, start + chunk)
            geoms = self.geometry(wi[sl], wo[sl])
            shades = self.shade(geoms, par)
            pmeans = [g.pmean for g in geoms]
            zi, zo = wi[sl, 2], wo[sl, 2]
            if split:
                self.split_into(shades, pmeans, zi, zo, par, out[sl])
            else:
                self.combine_into(shades, pmeans, zi, zo, par, out[None, sl])


def plan_of(fabric) -> FabricPlan:
    """The :class:`FabricPlan` of a :class:`brdf.Fabric` (its ``plan``), or the plan itself;
    what :class:`brdf.Prepared` and :mod:`brdf.sampling` take."""
    if isinstance(fabric, FabricPlan):
        return fabric
    plan = getattr(fabric, "plan", None)
    if not isinstance(plan, FabricPlan):
        raise ValueError(f"fabric must be a brdf.Fabric or a brdf.FabricPlan; got "
                         f"{type(fabric).__name__}")
    return plan
