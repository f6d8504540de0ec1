r"""The microcylinder fabric as a registered model (:class:`brdf.Model`): its flat parameter
vector <-> :class:`brdf.Fabric`, and its batched forward model.

:class:`brdf.Fabric` takes the model protocol from :class:`MicrocylinderModel` here, so a fit,
a comparison or a report treats it as any other entry of :data:`brdf.MODELS`.

Parameters are named by quantity and thread: ``eta1``, ``kd1``, ``gamma_s1``, ``gamma_v1``,
``area1``, ``albedo1_r``, ``albedo1_g``, ``albedo1_b``, the same with ``2`` (the scalar rows
of :data:`brdf.schema.THREAD_PARAMS`, then the RGB one per channel), then
``tangent_scale1``/``tangent_scale2``, a factor on each thread's tangent offsets (clipped to
[-90, 90] degrees), then ``rotation``, the rotation of both threads about the normal n in
degrees (the fabric option :attr:`brdf.FabricOptions.rotation` is in radians; the fit's
parameter, its results and the command line are in degrees: warp along (cos rho, sin rho, 0),
counter-clockwise from +x toward +y). A fit's search range and prior are uniform over one
period (:mod:`analysis.params`: [-90, 90] degrees, or [-180, 180] for a fabric that a half
turn changes): a fabric whose tangent curves are symmetric (unchanged by negating and reversing
the offsets: four presets' threads; not velvet's pile nor the satin back's first thread) is
unchanged by a half turn, so [-90, 90] holds every orientation of it, once
(:meth:`MicrocylinderModel.periods`; a fit summarizes such a rotation as an angle on a circle,
:mod:`analysis.fit.circular`, so that -90 and +90 are one orientation, not two bounds);
rotating by 90 degrees swaps the roles of the two threads. Any finite angle is valid (a ``--spec`` file's
``[bounds]`` may widen the range to [-180, 180] for an asymmetric fabric). Search ranges, units and priors
are the schema's (log-uniform where its
range spans decades); a thread parameter's plausible range is its row's (its typical range
where the row gives none).

The microcylinder is not reciprocal: MODEL.md's f_r divides by n . wi and its normalization Q
takes the gap term from one direction (``gap``).

Examples
--------
>>> import brdf
>>> MODEL_PARAM_NAMES[:5], SCHEMA.names[-3:]
(('eta1', 'kd1', 'gamma_s1', 'gamma_v1', 'area1'), ('tangent_scale1', 'tangent_scale2', 'rotation'))
>>> fab = brdf.fabric("velvet")
>>> v = fab.values()
>>> v["gamma_s2"], v["tangent_scale1"], v["rotation"]
(6.0, 1.0, 0.0)
>>> round(fab.with_values({"rotation": 30.0}).options["rotation"], 6)    # radians inside
0.523599
>>> fab.with_values({"gamma_s2": 9.0, "tangent_scale2": 0.5}).threads[1].offsets
(-45.0, -27.5, 27.5, 45.0)
"""

from __future__ import annotations

import copy
import dataclasses
from typing import ClassVar, Mapping

import numpy as np

from brdf import schema
from brdf.paramschema import ParamSchema
from brdf.prepared import Prepared
from brdf.presettable import DEFAULT_PRESET, PRESETS, check_preset, preset_threads
from brdf.shading import shade_dtype

__all__ = ["MicrocylinderModel", "FabricForward", "SCHEMA", "MODEL_PARAM_NAMES", "ALIASES",
           "DEFAULT_FREE", "DEFAULT_TIES", "TANGENT_SCALE", "ROTATION", "thread_values"]

#: The fit's factor on a thread's tangent offsets (not a parameter of the paper).
TANGENT_SCALE = schema.ParamInfo(
    "tangent_scale", "scalar", "1", 0.0, None, "s_t", "factor on the thread's tangent offsets "
    "(clipped to [-90, 90] degrees)", lo_open=True, typical=(0.25, 2.0), typical_value=1.0)

#: The fit's rotation of both threads about n, degrees (the option ``rotation`` in radians).
ROTATION = schema.ParamInfo(
    "rotation", "scalar", "deg", None, None, "ρ", "rotation of both threads about the normal "
    "n (warp along (cos ρ, sin ρ, 0))", typical=(-90.0, 90.0), typical_value=0.0,
    note="a half turn leaves a fabric with symmetric tangent curves unchanged")

_RGB = tuple(p.name for p in schema.THREAD_PARAMS if p.kind == "rgb")
_ROWS = tuple(schema.THREAD[n] for n in schema.SCALAR_PARAMS + _RGB)
_THREADS = (1, 2)

#: The parameters the shading takes (both threads).
_SHADING = ParamSchema.from_rows(_ROWS, "1", plausible_fallback=True) \
    + ParamSchema.from_rows(_ROWS, "2", plausible_fallback=True)
#: Every parameter of the model: the shading's, then the tangent scales and the rotation.
SCHEMA = _SHADING + ParamSchema.from_rows([TANGENT_SCALE], "1") \
    + ParamSchema.from_rows([TANGENT_SCALE], "2") + ParamSchema.from_rows([ROTATION])
#: Names of the shading parameters, both threads (``Prepared.eval``'s, per thread).
MODEL_PARAM_NAMES: tuple[str, ...] = _SHADING.names
#: Group aliases: ``albedo1`` is its three channels.
ALIASES = SCHEMA.aliases
#: A fit's default free set (8 parameters) and ties: one eta for both threads, area2 = 1 - area1.
DEFAULT_FREE = ("eta1", "kd1", "kd2", "gamma_s1", "gamma_v1", "gamma_s2", "gamma_v2", "area1")
DEFAULT_TIES = ("eta2=eta1", "area2=1-area1")


def thread_values(fab) -> dict[str, float]:
    """The shading parameters of a fabric's threads by name (natural units: degrees for
    gammas), in the order of :data:`MODEL_PARAM_NAMES`.

    Parameters
    ----------
    fab : object with ``threads``
        Two threads with the scalar parameters of :data:`brdf.schema.SCALAR_PARAMS` and
        ``albedo`` (one or three values).
    """
    out: dict[str, float] = {}
    for j, th in zip(_THREADS, fab.threads):
        for name in schema.SCALAR_PARAMS:
            out[f"{name}{j}"] = float(getattr(th, name))
        for name in _RGB:
            rgb = np.broadcast_to(np.asarray(getattr(th, name), float), (3,))
            for c, a in zip(schema.RGB_CHANNELS, rgb):
                out[f"{name}{j}_{c}"] = float(a)
    return out


def _scaled_offsets(offsets, factor) -> tuple:
    return tuple(np.clip(np.asarray(offsets) * factor, -90, 90).tolist())


class MicrocylinderModel:
    """The model protocol of :class:`brdf.Fabric` (a mixin: see the module notes)."""

    #: f_r(wi, wo) = f_r(wo, wi) does not hold (1/(n . wi), the gap term).
    reciprocal: ClassVar[bool] = False
    #: A fit's default free set and ties (whatever the table).
    DEFAULT_FREE: ClassVar[tuple[str, ...] | None] = DEFAULT_FREE
    DEFAULT_TIES: ClassVar[tuple[str, ...]] = DEFAULT_TIES
    #: No colour carries the level of f_r alone.
    BASE_PARAM: ClassVar[str | None] = None
    #: The presets :meth:`start` takes (one is required on the command line).
    PRESETS: ClassVar[tuple[str, ...]] = PRESETS

    #: The parameters constrained together (:meth:`admissible`).
    CONSTRAINED: ClassVar[tuple[str, ...]] = ("area1", "area2")

    @classmethod
    def param_schema(cls) -> ParamSchema:
        """The flat parameters (:data:`SCHEMA`)."""
        return SCHEMA

    @classmethod
    def admissible(cls, values: Mapping[str, np.ndarray]) -> np.ndarray:
        """Whether each set of values (arrays B...) makes a fabric beyond each parameter's own
        range: the threads' areas sum to at most :data:`brdf.schema.AREA_SUM_MAX` (up to a
        rounding margin of 1e-12), (B...) bool."""
        return np.asarray(values["area1"] + values["area2"] <= schema.AREA_SUM_MAX + 1e-12)

    @classmethod
    def start(cls, preset: str | None = None, options: Mapping | None = None):
        """The preset fabric ``preset`` (default :data:`brdf.presettable.DEFAULT_PRESET`)
        with the variant ``options``."""
        name = check_preset(preset or DEFAULT_PRESET)
        return cls(preset_threads(name), name=name, **dict(options or {}))

    def values(self) -> dict[str, float]:
        """Every parameter by name: the threads' (:func:`thread_values`), tangent scales 1,
        the rotation in degrees."""
        return {**thread_values(self), "tangent_scale1": 1.0, "tangent_scale2": 1.0,
                "rotation": float(np.degrees(self.options["rotation"]))}

    def periods(self) -> dict[str, float]:
        """The parameters that repeat (degrees): ``rotation``, 180 when every thread's
        tangent curve is symmetric (unchanged by negating and reversing its offsets and
        lengths, as linen's (-25, 25)): a half turn then leaves the fabric unchanged; 360
        otherwise (velvet's pile, (-90, -50), leans one way).

        Examples
        --------
        >>> import brdf
        >>> brdf.fabric("linen_plain").periods(), brdf.fabric("velvet").periods()
        ({'rotation': 180.0}, {'rotation': 360.0})
        """
        sym = all(tuple(-o for o in th.offsets[::-1]) == tuple(th.offsets)
                  and tuple(th.lengths[::-1]) == tuple(th.lengths) for th in self.threads)
        return {"rotation": 180.0 if sym else 360.0}

    def thread_swap(self) -> float | None:
        """The rotation (degrees) under which the two threads trade places, when they can: 90
        for a fabric of two threads with the same tangent curve, symmetric under a half turn
        (linen's (-25, 25) for both); None otherwise. Such a fabric with its threads'
        parameters swapped and turned by a quarter is the same fabric (``area1`` = a at
        ``rotation`` r is ``area1`` = 1 - a at r + 90 when the rest are equal).

        Examples
        --------
        >>> import brdf
        >>> brdf.fabric("linen_plain").thread_swap(), brdf.fabric("velvet").thread_swap()
        (90.0, None)
        """
        if len(self.threads) != 2 or self.periods()["rotation"] != 180.0:
            return None
        a, b = self.threads
        same = tuple(a.offsets) == tuple(b.offsets) and tuple(a.lengths) == tuple(b.lengths)
        return 90.0 if same else None

    def with_values(self, values: Mapping[str, float]):
        """This fabric with some parameters changed (names of :data:`SCHEMA`; a colour's
        channels not given keep their values; a tangent scale multiplies the offsets; the
        rotation, degrees, replaces the option ``rotation``).

        Raises
        ------
        ValueError
            A value a thread refuses (the message names the thread) or an unknown name.
        """
        unknown = sorted(set(values) - set(SCHEMA.names))
        if unknown:
            raise ValueError(f"microcylinder: unknown parameter(s) {', '.join(unknown)}")
        if any(n.startswith(_RGB) for n in values):       # a colour's other channels kept
            values = {**{n: v for n, v in thread_values(self).items()
                         if n.startswith(_RGB)}, **values}
        threads = []
        for j, t in zip(_THREADS, self.threads):
            change = {q: float(values[f"{q}{j}"]) for q in schema.SCALAR_PARAMS
                      if f"{q}{j}" in values}
            for q in _RGB:
                rgb = [f"{q}{j}_{c}" for c in schema.RGB_CHANNELS]
                if all(k in values for k in rgb):
                    change[q] = tuple(float(values[k]) for k in rgb)
            factor = values.get(f"tangent_scale{j}", 1.0)
            if factor != 1.0:
                change["offsets"] = _scaled_offsets(t.offsets, factor)
            try:
                threads.append(t.replace(**change))
            except ValueError as exc:
                raise ValueError(f"thread {j}: {exc}") from None
        if "rotation" in values:
            return self.replace(threads=threads,
                                rotation=float(np.radians(float(values["rotation"]))))
        return self.replace(threads=threads)

    @classmethod
    def batch_kwargs(cls, values: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """:meth:`brdf.Prepared.eval`'s keyword arguments from every shading parameter's
        values (B...): each scalar quantity (B..., 2), each RGB one (B..., 2, 3), both
        threads; ``tangent_scale`` (B..., 2) when both tangent scales are given; ``rotation``
        (B...) in degrees when given."""
        kw = {}
        for q in schema.SCALAR_PARAMS:
            kw[q] = np.stack([values[f"{q}{j}"] for j in _THREADS], axis=-1)
        for q in _RGB:
            kw[q] = np.stack([np.stack([values[f"{q}{j}_{c}"] for c in schema.RGB_CHANNELS],
                                       axis=-1) for j in _THREADS], axis=-2)
        if all(f"tangent_scale{j}" in values for j in _THREADS):
            kw["tangent_scale"] = np.stack([values[f"tangent_scale{j}"] for j in _THREADS], -1)
        if "rotation" in values:
            kw["rotation"] = np.asarray(values["rotation"], dtype=np.float64)
        return kw

    def forward(self, wi, wo) -> "FabricForward":
        """The forward model at the pairs (wi, wo): :class:`FabricForward`."""
        return FabricForward(self, wi, wo)


class FabricForward:
    """Forward model of a fabric at fixed direction pairs, batched over parameters.

    Wraps ``fab.prepare(wi, wo)``; the call takes the keyword arguments of ``prep.eval``
    (each (B..., 2), albedo (B..., 2, 3)) and optionally ``tangent_scale`` (B..., 2), a factor
    on each thread's tangent offsets, and ``rotation`` (B..., degrees), and returns f_r
    (B..., n, 3) in 1/sr, float64. Rotations alone go to :meth:`brdf.Prepared.eval_rotated`
    (on Dr.Jit one fused kernel, shading in float64 whatever ``dtype``). Scaled curves
    cannot be prepared once: that slow path rebuilds the fabric and its preparation for
    every batch row whose factors differ from 1.

    ``dtype`` is the precision of the shading (:meth:`brdf.Prepared.eval`): float64 by
    default; :meth:`with_dtype` gives the same model shading in float32.
    """

    def __init__(self, fab, wi, wo, dtype=np.float64):
        self.fab = fab
        self.wi = np.asarray(wi, dtype=np.float64)
        self.wo = np.asarray(wo, dtype=np.float64)
        self.prep = fab.prepare(self.wi, self.wo)
        self.dtype = shade_dtype(dtype)

    def with_dtype(self, dtype) -> "FabricForward":
        """The same model (sharing its preparation) shading in ``dtype``."""
        other = copy.copy(self)
        other.dtype = shade_dtype(dtype)
        return other

    def __call__(self, tangent_scale=None, rotation=None, **kw) -> np.ndarray:
        kw["dtype"] = self.dtype
        rot0 = float(np.degrees(self.fab.options["rotation"]))
        same_ts = tangent_scale is None or np.all(np.asarray(tangent_scale) == 1.0)
        same_rot = rotation is None or np.all(np.asarray(rotation) == rot0)
        if same_ts and same_rot:
            return self.prep.eval(**kw)
        if same_ts:                     # the plan's threads, each set under its rotation
            return self.prep.eval_rotated(rot0 if rotation is None else rotation, **kw)
        ts = (np.ones(np.shape(rotation) + (2,)) if tangent_scale is None
              else np.asarray(tangent_scale, dtype=np.float64))
        batch = ts.shape[:-1]
        rot = np.broadcast_to(rot0 if rotation is None else
                              np.asarray(rotation, dtype=np.float64), batch).reshape(-1)
        flat_kw = {k: np.asarray(v).reshape((-1,) + np.shape(v)[len(batch):])
                   for k, v in kw.items() if k != "dtype"}
        out = np.empty((int(np.prod(batch)), self.wi.shape[0], 3))
        ts = ts.reshape(-1, 2)
        for b in range(ts.shape[0]):
            if np.all(ts[b] == 1.0):            # the plan's threads as they are: rotate it
                plan = self.prep.plan
                plan = dataclasses.replace(plan, options=dataclasses.replace(
                    plan.options, rotation=float(np.radians(rot[b]))))
                prep = Prepared(plan, self.wi, self.wo)
            else:
                threads = tuple(th.replace(offsets=_scaled_offsets(th.offsets, ts[b, j]))
                                for j, th in enumerate(self.fab.threads))
                prep = self.fab.replace(threads=threads, rotation=float(np.radians(rot[b]))
                                        ).prepare(self.wi, self.wo)
            out[b] = prep.eval(dtype=self.dtype, **{k: v[b] for k, v in flat_kw.items()})
        return out.reshape(batch + out.shape[1:])
