"""The Mitsuba BSDF class of :mod:`reports.mitsuba`: Mitsuba's interface around
:mod:`reports.mitsuba_kernel`.

A Mitsuba plugin class derives from the ``mi.BSDF`` of one variant, so :func:`bsdf_class`
builds one per variant (and keeps it). Imports Mitsuba at its top: it is imported only by
:func:`reports.mitsuba.register`.
"""

from __future__ import annotations

import math

# optional dependencies: this module is imported only by reports.mitsuba.register()
import drjit as dr
import mitsuba as mi

from reports import mitsuba_kernel as kern
from reports.mitsuba import fabric_from_dict

__all__ = ["bsdf_class"]

_CLASSES: dict = {}


def _props_dict(props) -> dict:
    """Mitsuba properties as a plain dict (RGB values as tuples)."""
    out = {}
    for key in props.keys():
        v = props[key]
        if not isinstance(v, (bool, int, float, str)):
            try:
                v = tuple(float(v[i]) for i in range(3))
            except (TypeError, IndexError, ValueError):
                raise ValueError(f"microcylinder: parameter {key!r} must be a number, a string "
                                 f"or an RGB value; got {type(v).__name__}") from None
        out[key] = v
    return out


def _warp(si, rotation):
    """cos and sin of the warp's angle from the local x axis: dp_du projected onto the
    tangent plane (x when it vanishes there), turned by ``rotation`` (radians); in double
    precision in the JIT variants."""
    d = si.sh_frame.to_local(si.dp_du)
    r2 = d.x * d.x + d.y * d.y
    ok = r2 > 0.0
    inv = dr.rsqrt(dr.select(ok, r2, 1.0))
    c, s = dr.select(ok, d.x * inv, 1.0), dr.select(ok, d.y * inv, 0.0)
    c, s = kern.wide(c), kern.wide(s)           # the turn in double precision: a float32
    cr, sr = math.cos(rotation), math.sin(rotation)  # cos 40 degrees moves velvet's lobes 1e-4
    return c * cr - s * sr, s * cr + c * sr


def bsdf_class():
    """The ``microcylinder`` BSDF class of the variant that is set."""
    variant = mi.variant()
    if variant not in _CLASSES:
        _CLASSES[variant] = _make_class()
    return _CLASSES[variant]


def _make_class():
    flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide | mi.BSDFFlags.Anisotropic

    class MicrocylinderBSDF(mi.BSDF):
        """Mitsuba BSDF ``microcylinder`` (see :mod:`reports.mitsuba`)."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.fabric = fabric_from_dict(_props_dict(props))
            self.k = kern.consts(self.fabric)
            self.m_components = [flags]
            self.m_flags = flags

        def _frame(self, si):
            return _warp(si, self.k.rotation)

        def eval_pdf(self, ctx, si, wo, active=True):
            """f_r cos and the density of valid draws: 0 where f_r cos is 0 (module notes)."""
            c, s = self._frame(si)
            f, p = kern.eval_pdf(self.k, wo, si.wi, c, s)
            on = active & ctx.is_enabled(mi.BSDFFlags.GlossyReflection)
            return dr.select(on, f, 0.0), dr.select(on & (dr.max(f) > 0.0), p, 0.0)

        def eval(self, ctx, si, wo, active=True):
            c, s = self._frame(si)
            value = kern.eval_cos(self.k, wo, si.wi, c, s)
            on = active & ctx.is_enabled(mi.BSDFFlags.GlossyReflection)
            return dr.select(on, value, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            return self.eval_pdf(ctx, si, wo, active)[1]

        def sample(self, ctx, si, sample1, sample2, active=True):
            c, s = self._frame(si)
            cn, sn = kern.narrow(c), kern.narrow(s)
            wo = kern.sample(self.k, si.wi, sample1, sample2, cn, sn)
            f, p = kern.eval_pdf(self.k, wo, si.wi, c, s)
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
