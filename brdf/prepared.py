"""Fixed direction pairs of a fabric, shaded for batches of parameter sets (what fits use)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from brdf import jit, schema
from brdf.frames import flat_pairs
from brdf.kernel import ThreadGeometry
from brdf.plan import FabricPlan, ShadeParams, plan_of
from brdf.scratch import Scratch
from brdf.shading import shade_dtype

__all__ = ["Prepared", "GRAD_PARAMS"]

#: The parameters :meth:`Prepared.eval_and_grad` differentiates f_r by.
GRAD_PARAMS = ("eta", "kd", "gamma_s", "gamma_v", "area", "albedo")


class Prepared:
    """Direction-dependent work of a fabric done once for n fixed pairs.

    ``eval`` shades the pairs for batches of optical parameters; tangent curves and options
    are those of the plan (:attr:`brdf.Fabric.plan`) it was prepared from.

    Parameters
    ----------
    plan : brdf.FabricPlan or brdf.Fabric
        The fabric's compiled form (``Fabric.prepare`` passes its own; a Fabric stands for
        its ``plan``).
    wi, wo : array_like, shape (n, 3)
        Direction pairs (broadcast, normalized; below-horizon or bad pairs give 0 / NaN).

    Attributes
    ----------
    block_elements : int or None
        (Parameter set, pair, sample) elements shaded per block; None (the default) takes
        :data:`brdf.shading.SHADE_BLOCK`. Only the speed and the rounding of the
        weighted sums over samples depend on it.

    Examples
    --------
    >>> import brdf
    >>> fab = brdf.fabric("silk_crepe_de_chine")
    >>> wi = brdf.directions.from_angles(np.radians([10, 40]), 0.3)
    >>> wo = brdf.directions.from_angles(np.radians([20, 60]), 2.0)
    >>> prep = fab.prepare(wi, wo)
    >>> np.allclose(prep.eval(), fab.eval(wi, wo), rtol=1e-13, atol=0)
    True
    >>> prep.eval(eta=np.full((5, 2), 1.4)).shape
    (5, 2, 3)
    >>> np.allclose(prep.eval(dtype=np.float32), prep.eval(), rtol=1e-5, atol=0)
    True
    """

    block_elements: int | None = None

    def __init__(self, plan: FabricPlan, wi, wo):
        plan = plan_of(plan)
        wi, wo, shape, bad, below = flat_pairs(wi, wo)
        self.plan = plan
        self.shape = shape
        self._bad = bad
        self._ok = ~(bad | below)
        wi_ok, wo_ok = wi[self._ok], wo[self._ok]
        self._pairs = (wi_ok, wo_ok)
        # the Dr.Jit kernel (brdf.jit), where it is the backend now, shades (float64,
        # float32) a batch worth a call, prepared on the first (:meth:`_uses_jit`), but for
        # pairs with a nearly zero component (``_exact``, NumPy's: brdf.jit's notes);
        # NumPy's geometry on first use
        self._drjit = jit.backend() == "drjit"
        self._jit, self._exact, self._jit_all = None, None, None
        self._tiny: np.ndarray | None = None        # jit.tiny_pairs of the pairs, found once
        self._geoms: list[ThreadGeometry] | None = None
        self._geoms32: list[ThreadGeometry] | None = None
        self._scratch = Scratch()
        self._zi = wi_ok[:, 2]
        self._zo = wo_ok[:, 2]

    def eval(self, *, eta=None, albedo=None, kd=None, gamma_s=None, gamma_v=None,
             area=None, dtype=np.float64) -> np.ndarray:
        r"""f_r (1/sr) of the prepared pairs for a batch of parameter sets.

        Parameters
        ----------
        eta, kd, gamma_s, gamma_v, area : array_like, shape (B..., 2), optional
            Per thread; gamma in degrees. Omitted ones take the fabric's values.
        albedo : array_like, shape (B..., 2, 3), optional
        dtype : {numpy.float64, numpy.float32}
            Precision of the shading (the per-sample terms and their sums); the geometry is
            computed, and the threads combined, in float64 either way, and the result is
            float64. float32 shades about twice as fast (the sampling of a fit uses it), at
            a relative error of a few 1e-6 where f_r is not far below its largest value
            over the pairs; terms below about 1e-38 of their scale round to zero. Either
            runs on the kernel :func:`brdf.jit.backend` names (Dr.Jit's or NumPy's).

        Returns
        -------
        ndarray, shape (B..., n..., 3)
            f_r in 1/sr (B... is the broadcast batch shape; absent when every parameter is
            omitted or has shape (2,).)

        Raises
        ------
        ValueError
            If a parameter's last axis is not 2 (per thread), an element lies outside its
            range in :mod:`brdf.schema` (eta > 1, k_d and area in [0, 1], gammas > 0,
            albedo >= 0, all finite), or a parameter set's areas sum above 1; checked on the
            whole batch before any shading. If ``dtype`` is not float64 or float32.
        """
        dtype = shade_dtype(dtype)
        par, batch = self._params(eta, albedo, kd, gamma_s, gamma_v, area)
        nb = par.eta.shape[0]
        out = (np.empty if self._ok.all() else np.zeros)((nb, self._ok.size, 3))
        if self._uses_jit(nb):
            vals = self._jit_eval(par, dtype)
            if self._ok.all():
                out = vals                  # a new array of every pair
        else:
            vals = self._numpy_eval(par, dtype, out)
        if vals is not out:
            out[:, self._ok] = vals
        out[:, self._bad] = np.nan
        return out.reshape(batch + self.shape + (3,))

    def eval_rotated(self, rotation, *, dtype=np.float64, **params) -> np.ndarray:
        r"""f_r (1/sr) as :meth:`eval`, each parameter set under its own rotation of both
        threads about n (the fabric option ``rotation``, here in degrees).

        Parameters
        ----------
        rotation : array_like, shape (B...)
            Degrees, finite; broadcast with the batch of ``params``.
        dtype : {numpy.float64, numpy.float32}
            The shading's precision on the NumPy kernel; the Dr.Jit kernel shades these
            in float64 either way (one fused kernel forms each set's geometry: nothing is
            prepared per rotation).
        **params
            :meth:`eval`'s parameters.

        Returns
        -------
        ndarray, shape (B..., n..., 3)

        Raises
        ------
        ValueError
            As :meth:`eval`; or ``rotation`` is not finite or does not broadcast.

        Examples
        --------
        >>> import brdf
        >>> fab = brdf.fabric("velvet")
        >>> wi = brdf.directions.from_angles(np.radians([10, 40]), 0.3)
        >>> wo = brdf.directions.from_angles(np.radians([20, 60]), 2.0)
        >>> f = fab.prepare(wi, wo).eval_rotated([0.0, 30.0])
        >>> np.allclose(f[1], fab.replace(rotation=np.radians(30.0)).eval(wi, wo), rtol=1e-12)
        True
        """
        dtype = shade_dtype(dtype)
        par, batch = self._params(*(params.pop(k, None) for k in
                                    ("eta", "albedo", "kd", "gamma_s", "gamma_v", "area")))
        if params:
            raise TypeError(f"eval_rotated got unexpected parameters {sorted(params)}")
        rot = np.asarray(rotation, dtype=np.float64)
        if not np.all(np.isfinite(rot)):
            raise ValueError(f"rotation must be finite (degrees); got {rotation!r}")
        try:
            shape = np.broadcast_shapes(batch, rot.shape)
        except ValueError:
            raise ValueError(f"rotation of shape {rot.shape} does not broadcast with the "
                             f"parameters' batch {batch}") from None
        nb = math.prod(shape)
        par = ShadeParams(*(np.broadcast_to(a.reshape(batch + a.shape[1:]),
                                            shape + a.shape[1:]).reshape((nb,) + a.shape[1:])
                            for a in _arrays(par)))
        rad = np.radians(np.broadcast_to(rot, shape).reshape(-1))
        out = np.zeros((nb, self._ok.size, 3))
        if self._fused(nb):
            out[:, self._ok] = jit.compiled().eval_rotated(self.plan, *self._pairs, par, rad)
        else:                       # each set's pairs prepared under its rotation
            for b in range(nb):
                row = ShadeParams(*(a[b:b + 1] for a in _arrays(par)))
                plan = dataclasses.replace(self.plan, options=dataclasses.replace(
                    self.plan.options, rotation=float(rad[b])))
                out[b:b + 1, self._ok] = Prepared(plan, *self._pairs)._eval_par(row, dtype)
        out[:, self._bad] = np.nan
        return out.reshape(shape + self.shape + (3,))

    def _fused(self, nb: int) -> bool:
        """Whether :meth:`eval_rotated` of ``nb`` sets runs Dr.Jit's fused kernel: the
        backend was drjit when this was prepared (as for :meth:`_uses_jit`), the sets'
        (pair, sample) elements make a call worth it, and no
        pair has a nearly zero component (:func:`brdf.jit.tiny_pairs`)."""
        if not (self._zi.size and self._drjit
                and jit.worth_a_call(self.plan, nb * self._zi.size)):
            return False
        return not self._tiny_pairs().any()

    def _tiny_pairs(self) -> np.ndarray:
        """:func:`brdf.jit.tiny_pairs` of the pairs above the horizon, found on first use
        (the fused and the prepared kernels leave the same pairs to NumPy)."""
        if self._tiny is None:
            self._tiny = jit.tiny_pairs(*self._pairs)
        return self._tiny

    def _uses_jit(self, nb: int) -> bool:
        """Whether a batch of ``nb`` sets is shaded by Dr.Jit: the backend was drjit when
        this was prepared, and the batch's (set, pair, sample) elements make a call worth it
        (:func:`brdf.jit.worth_a_call`: a fit's batches of tens of sets of a small table do,
        where one set would not). The kernel's preparation of the pairs is made on the
        first such batch."""
        if not (self._drjit and jit.worth_a_call(self.plan, nb * self._zi.size)):
            return False
        if self._jit is None:
            wi_ok, wo_ok = self._pairs
            exact = self._tiny_pairs()
            self._jit = jit.compiled().PreparedJit(self.plan, wi_ok[~exact], wo_ok[~exact])
            self._exact = exact if exact.any() else None
            if self._jit_all is None and self._exact is None:
                self._jit_all = self._jit
        return True

    def _eval_par(self, par: ShadeParams, dtype) -> np.ndarray:
        """f_r (nb, pairs above the horizon, 3) of the checked batch ``par``."""
        if self._uses_jit(par.eta.shape[0]):
            return self._jit_eval(par, dtype)
        return self._numpy_eval(par, dtype, None).copy()

    def eval_and_grad(self, *, eta=None, albedo=None, kd=None, gamma_s=None, gamma_v=None,
                      area=None) -> tuple[np.ndarray, dict]:
        r"""f_r (1/sr) of the prepared pairs for a batch of parameter sets, as :meth:`eval`
        (float64), and its derivatives by each parameter, from Dr.Jit's automatic
        differentiation (forward mode) whatever :func:`brdf.jit.backend` says.

        Returns
        -------
        f : ndarray, shape (B..., n..., 3)
        grads : dict of ndarray, shape (B..., n..., 3, 2)
            For each of ``eta``, ``kd``, ``gamma_s``, ``gamma_v``, ``area``, ``albedo``:
            ``grads[name][..., ch, j]`` = d f_r[..., ch] / d name[..., j] of the same
            parameter set (thread j; per degree for the gammas, 1/sr per degree; for
            ``albedo`` the derivative by thread j's albedo in the same channel ch, those by
            the other channels being 0). NaN where f_r is NaN (bad pairs), 0 below the
            horizon.

        Raises
        ------
        ValueError
            As :meth:`eval`.
        RuntimeError
            Dr.Jit does not run here (the reason given).
        """
        par, batch = self._params(eta, albedo, kd, gamma_s, gamma_v, area)
        ok, why = jit.available()
        if not ok:
            raise RuntimeError(f"eval_and_grad needs Dr.Jit, which does not run here: {why}")
        if self._jit_all is None:       # subnormal components raised to the least normal
            self._jit_all = jit.compiled().PreparedJit(self.plan, *map(_normal, self._pairs))
        nb = par.eta.shape[0]
        f, grads = np.zeros((nb, self._ok.size, 3)), {}
        if self._zi.size:
            gvals = self._jit_all.eval_and_grad(par)[1]
            vals = self._eval_par(par, np.float64)                   # eval's f_r
        else:
            vals, gvals = f[:, :0], {k: np.zeros((nb, 0, 3, 2)) for k in GRAD_PARAMS}
        f[:, self._ok] = vals
        f[:, self._bad] = np.nan
        for name, g in gvals.items():
            full = np.zeros((nb, self._ok.size, 3, 2))
            full[:, self._ok] = g
            full[:, self._bad] = np.nan
            grads[name] = full.reshape(batch + self.shape + (3, 2))
        return f.reshape(batch + self.shape + (3,)), grads

    def _jit_eval(self, par: ShadeParams, dtype) -> np.ndarray:
        """The Dr.Jit kernel's f_r (nb, pairs above the horizon, 3), shaded in ``dtype``;
        those with a nearly zero component (:func:`brdf.jit.tiny_pairs`) from the NumPy
        kernel."""
        single = dtype == np.float32
        if self._exact is None:
            return self._jit.eval(par, single)
        vals = self._numpy_eval(par, dtype, None).copy()
        keep = ~self._exact
        if keep.any():
            vals[:, keep] = self._jit.eval(par, single)
        return vals

    def _numpy_eval(self, par: ShadeParams, dtype, out) -> np.ndarray:
        """The NumPy kernel's shading of the prepared pairs into ``out`` (nb, n, 3) where
        every pair is above the horizon, else into a buffer of the pairs that are (returned)."""
        geoms = self._geometries(dtype)
        nb, plan, block = par.eta.shape[0], self.plan, self.block_elements
        shades = plan.shade(geoms, par, block=block, scratch=self._scratch)
        vals = out if out is not None and self._ok.all() else self._scratch.array(
            "vals", (nb, self._zi.size, 3))
        plan.combine_into(shades, [g.pmean for g in self._geometries(np.float64)], self._zi,
                          self._zo, par, vals, block=block)
        return vals

    def _params(self, eta, albedo, kd, gamma_s, gamma_v, area) -> tuple[ShadeParams, tuple]:
        """The parameters checked (the plan's where omitted; gammas to radians) and
        broadcast to one batch, flattened: ``(ShadeParams, batch shape)``."""
        own = self.plan.params

        def param(name, value, default, radians=False):
            if value is None:
                return default[0]
            try:
                v = np.asarray(value, dtype=np.float64)
            except (TypeError, ValueError):
                raise ValueError(f"{name} must be a numeric array; got {value!r}") from None
            want = default.shape[1:]
            if v.shape[v.ndim - len(want):] != want:
                raise ValueError(f"{name} must have shape (..., {', '.join(map(str, want))}); "
                                 f"got {v.shape}")
            v = schema.THREAD[name].check_array(v)
            return np.radians(v) if radians else v

        eta = param("eta", eta, own.eta)
        kd = param("kd", kd, own.kd)
        gs = param("gamma_s", gamma_s, own.gamma_s, radians=True)
        gv = param("gamma_v", gamma_v, own.gamma_v, radians=True)
        area = param("area", area, own.area)
        schema.check_area_sums(area)
        alb = param("albedo", albedo, own.albedo)
        batch = np.broadcast_shapes(eta.shape[:-1], kd.shape[:-1], gs.shape[:-1],
                                    gv.shape[:-1], area.shape[:-1], alb.shape[:-2])
        nb = math.prod(batch)

        def flat(x, k):  # (B..., *tail) with k tail axes -> (nb, *tail)
            tail = x.shape[x.ndim - k:]
            return np.broadcast_to(x, batch + tail).reshape((nb,) + tail)

        return ShadeParams(*(flat(x, 1) for x in (eta, kd, gs, gv, area)), flat(alb, 2)), batch

    def _geometries(self, dtype) -> list[ThreadGeometry]:
        """The NumPy kernel's geometry in ``dtype`` (made once, on first use; float32 copies
        of the float64)."""
        if self._geoms is None:
            self._geoms = self.plan.geometry(*self._pairs)
        if shade_dtype(dtype) == np.float64:
            return self._geoms
        if self._geoms32 is None:
            self._geoms32 = [ThreadGeometry(*(None if a is None else _to_float32(a) for a in g))
                             for g in self._geoms]
        return self._geoms32


def _arrays(par: ShadeParams) -> list[np.ndarray]:
    """The arrays of ``par`` in its fields' order (uncopied)."""
    return [getattr(par, f.name) for f in dataclasses.fields(par)]


def _normal(w: np.ndarray) -> np.ndarray:
    """``w`` with its subnormal components raised to the least normal number, their sign
    kept (what Dr.Jit's kernels would flush to 0)."""
    tiny = np.finfo(np.float64).tiny
    return np.where((w != 0) & (np.abs(w) < tiny), np.copysign(tiny, w), w)


def _to_float32(a: np.ndarray) -> np.ndarray:
    """A C-contiguous float32 copy, clipped to float32's finite range (so that a factor
    beyond it, near exact grazing, times a zero stays zero rather than NaN)."""
    f32 = np.finfo(np.float32)
    return np.ascontiguousarray(np.clip(a, -f32.max, f32.max), dtype=np.float32)
