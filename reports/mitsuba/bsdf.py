"""The Mitsuba BSDF class of :mod:`reports.mitsuba.plugin`: Mitsuba's interface around
brdf's Dr.Jit kernel (:mod:`brdf.jit.kernel`, :mod:`brdf.jit.sampler`) in the variant's types.

A Mitsuba plugin class derives from the ``mi.BSDF`` of one variant, so :func:`bsdf_class`
builds one per variant (and keeps it). Imports Mitsuba at its top: it is imported only by
:func:`reports.mitsuba.register`.
"""

from __future__ import annotations

import math

import numpy as np

import brdf
from brdf import sampling

# optional dependencies: this module is imported only by reports.mitsuba.register()
import drjit as dr
import mitsuba as mi

from brdf.jit import sampler as kern
from brdf.jit.consts import Types, consts
from analysis.fabricfile import PLUGIN_NAME, fabric_from_dict

__all__ = ["bsdf_class", "variant_types", "TRAVERSED_THREAD_KEYS", "TEXTURED_KEYS"]

_CLASSES: dict = {}


#: The keys that take a Mitsuba texture (``bitmap``, ``checkerboard``, ...) as well as an RGB
#: value: the albedo then varies over the surface, evaluated at each hit.
TEXTURED_KEYS = ("albedo1", "albedo2")


def _props_dict(props) -> tuple[dict, dict]:
    """Mitsuba properties as a plain dict (RGB values as tuples), and the textures given for
    :data:`TEXTURED_KEYS` (each stands in the plain dict as its mean, clipped to [0, 1]: the
    sampler's lobe probabilities use it)."""
    out, textures = {}, {}
    for key in props.keys():
        v = props[key]
        if isinstance(v, mi.Texture):
            if key not in TEXTURED_KEYS:
                raise ValueError(f"{PLUGIN_NAME}: parameter {key!r} cannot be a texture; "
                                 f"only {' and '.join(TEXTURED_KEYS)} can")
            textures[key] = v
            v = min(max(float(np.ravel(v.mean())[0]), 0.0), 1.0)
        elif not isinstance(v, (bool, int, float, str)):
            try:
                v = tuple(float(v[i]) for i in range(3))
            except (TypeError, IndexError, ValueError):
                raise ValueError(f"{PLUGIN_NAME}: parameter {key!r} must be a number, a "
                                 f"string, an RGB value or (albedo) a texture; got "
                                 f"{type(v).__name__}") from None
        out[key] = v
    return out, textures


def _warp(si, rotation):
    """cos and sin of the warp's angle from the local x axis: dp_du projected onto the
    tangent plane (x when it vanishes there), turned by ``rotation`` (radians); in double
    precision in the JIT variants."""
    d = si.sh_frame.to_local(si.dp_du)
    r2 = d.x * d.x + d.y * d.y
    ok = r2 > 0.0
    inv = dr.rsqrt(dr.select(ok, r2, 1.0))
    c, s = dr.select(ok, d.x * inv, 1.0), dr.select(ok, d.y * inv, 0.0)
    # the turn in double precision: in float32, cos(40 degrees) alone moved velvet's f_r by
    # 1.5e-4 of its peak
    if dr.is_jit_v(c):
        c, s = mi.Float64(c), mi.Float64(s)
    cr, sr = math.cos(rotation), math.sin(rotation)
    return c * cr - s * sr, s * cr + c * sr


#: The thread parameters that ``mi.traverse`` exposes (with 1 or 2 appended), beside
#: ``rotation``; gammas and rotation in degrees, as in the plugin's dictionary. The tangent
#: curves (offsets, lengths) and the other options shape the kernel: change them by loading
#: anew.
TRAVERSED_THREAD_KEYS = ("eta", "albedo", "kd", "gamma_s", "gamma_v", "area")


def _values_of(fabric, textured=()) -> dict:
    """The traversed values of ``fabric``: floats, RGB tuples for the albedos (not the keys
    ``textured``: their textures are traversed instead)."""
    out = {}
    for j, t in enumerate(fabric.threads, start=1):
        for key in TRAVERSED_THREAD_KEYS:
            if f"{key}{j}" not in textured:
                v = getattr(t, key)
                out[f"{key}{j}"] = tuple(map(float, v)) if key == "albedo" else float(v)
    out["rotation"] = math.degrees(fabric.plan.options.rotation)
    return out


def _param(value):
    """A traversable holder of ``value``: Color3f for RGB, else a one-entry array that
    ``SceneParameters`` can write (a Python float it cannot)."""
    if isinstance(value, tuple):
        return mi.Color3f(*value)
    return mi.Float(value) if dr.is_jit_v(mi.Float) else dr.scalar.Array1f(value)


def _read(holder):
    """The Python float, or RGB tuple, that a :func:`_param` holder holds now."""
    v = np.asarray(holder, dtype=np.float64).ravel()
    return tuple(float(x) for x in v) if v.size == 3 else float(v[0])


def _write(params, fabric) -> None:
    """Put ``fabric``'s values into the holders ``params``, in place (the SceneParameters of
    an earlier ``mi.traverse`` keep them)."""
    values = _values_of(fabric)
    for key, holder in params.items():
        value = values[key]
        for i, x in enumerate(value if isinstance(value, tuple) else (value,)):
            holder[i] = x


def _fabric_with(fabric, params, keys) -> brdf.Fabric:
    """``fabric`` with the values that the holders ``params`` of ``keys`` hold now (the
    others as they were: a holder is float32); ValueError where one is out of range, naming
    its thread."""
    keys = set(keys)
    threads = []
    for j, t in enumerate(fabric.threads, start=1):
        changes = {k: _read(params[f"{k}{j}"]) for k in TRAVERSED_THREAD_KEYS
                   if f"{k}{j}" in keys and f"{k}{j}" in params}
        try:
            threads.append(t.replace(**changes))
        except ValueError as exc:
            raise ValueError(f"{PLUGIN_NAME}: thread {j}: {exc}") from None
    rotation = (math.radians(_read(params["rotation"])) if "rotation" in keys
                else fabric.plan.options.rotation)
    return fabric.replace(threads=threads, rotation=rotation)


def variant_types() -> Types:
    """The kernel's types in the variant that is set: ``mi.Float`` (float32) shading, the
    frame in ``mi.Float64``."""
    return Types(mi.Float, mi.Float64, mi.UInt32, mi.Color3f, mi.Vector3f,
                 mi.warp.square_to_cosine_hemisphere)


def _consts(fabric):
    """The kernel's constants of ``fabric`` in the variant's types, the sampler's included."""
    return consts(fabric.plan, variant_types(), sampling.lobe_probabilities(fabric.plan))


def bsdf_class():
    """The ``microcylinder`` BSDF class of the variant that is set."""
    variant = mi.variant()
    if variant not in _CLASSES:
        _CLASSES[variant] = _make_class()
    return _CLASSES[variant]


def _make_class():
    flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide | mi.BSDFFlags.Anisotropic

    class MicrocylinderBSDF(mi.BSDF):
        """Mitsuba BSDF ``microcylinder`` (see :mod:`reports.mitsuba.plugin`)."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            plain, self.textures = _props_dict(props)
            self.fabric = fabric_from_dict(plain)
            self.k = _consts(self.fabric)
            self.params = {key: _param(v)
                           for key, v in _values_of(self.fabric, self.textures).items()}
            self.m_components = [flags]
            self.m_flags = flags

        def traverse(self, callback):
            """Expose :data:`TRAVERSED_THREAD_KEYS`, ``rotation`` and the albedo textures to
            ``mi.traverse`` (not differentiable)."""
            for key, holder in self.params.items():
                callback.put(key, holder, mi.ParamFlags.NonDifferentiable)
            for key, texture in self.textures.items():
                callback.put(key, texture, mi.ParamFlags.NonDifferentiable)

        def parameters_changed(self, keys):
            """Rebuild the fabric and its constants from the traversed values: the kernel
            takes them as parameters, so the next render reuses it. An out-of-range value
            raises ValueError and leaves the BSDF as it was."""
            try:
                fabric = _fabric_with(self.fabric, self.params, keys)
            except ValueError:
                _write(self.params, self.fabric)        # back to the values in use
                raise
            self.fabric, self.k = fabric, _consts(fabric)

        def _frame(self, si):
            return _warp(si, self.k.rotation)

        def _albedo(self, si, active):
            """Each thread's albedo texture evaluated at ``si`` (None: its constant)."""
            return tuple(self.textures[f"albedo{j}"].eval(si, active)
                         if f"albedo{j}" in self.textures else None for j in (1, 2))

        def eval_pdf(self, ctx, si, wo, active=True):
            """f_r cos and the density of valid draws: 0 where f_r cos is 0 (module notes)."""
            c, s = self._frame(si)
            f, p = kern.eval_pdf(self.k, wo, si.wi, c, s, albedo=self._albedo(si, active))
            on = active & ctx.is_enabled(mi.BSDFFlags.GlossyReflection)
            return dr.select(on, f, 0.0), dr.select(on & (dr.max(f) > 0.0), p, 0.0)

        def eval(self, ctx, si, wo, active=True):
            c, s = self._frame(si)
            value = kern.eval_cos(self.k, wo, si.wi, c, s, albedo=self._albedo(si, active))
            on = active & ctx.is_enabled(mi.BSDFFlags.GlossyReflection)
            return dr.select(on, value, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[1]

        def sample(self, ctx, si, sample1, sample2, active=True):
            c, s = self._frame(si)
            cn, sn = (mi.Float(c), mi.Float(s)) if dr.is_jit_v(c) else (c, s)
            wo = kern.sample(self.k, si.wi, sample1, sample2, cn, sn)
            f, p = kern.eval_pdf(self.k, wo, si.wi, c, s, albedo=self._albedo(si, active))
            on = active & ctx.is_enabled(mi.BSDFFlags.GlossyReflection) & (p > 0.0) \
                & (dr.max(f) > 0.0)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = wo
            bs.pdf = dr.select(on, p, 0.0)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = mi.UInt32(0)
            weight = dr.select(on, f / dr.select(on, p, 1.0), 0.0)
            return bs, weight

        def to_string(self):
            return f"MicrocylinderBSDF[{self.fabric!r}]"

    return MicrocylinderBSDF
