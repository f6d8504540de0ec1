r"""A Mitsuba 3 plugin: the BSDF ``microcylinder``, microcyl's fabrics in Mitsuba's renderers.

After :func:`register` (with a Mitsuba RGB variant set),
``mi.load_dict({"type": "microcylinder", "fabric": "velvet"})`` is the preset, and every
thread parameter and option is a key of the same dictionary (:data:`THREAD_KEYS`,
:data:`OPTION_KEYS`): ``eta1``, ``albedo2`` (a number or ``{"type": "rgb", "value": [r, g,
b]}``), ``offsets1`` (degrees, a comma-separated string), ``masking``, ``rotation`` (degrees),
... Keys left out keep the preset's values and microcyl's defaults. ``albedo1`` and ``albedo2``
also take a Mitsuba texture (``bitmap``, ``checkerboard``, ...): f_r uses its value at each
hit, the sampler its mean (:data:`reports.mitsuba.bsdf.TEXTURED_KEYS`). ``mi.traverse`` exposes each
thread's ``eta``, ``albedo``, ``kd``, ``gamma_s``, ``gamma_v`` and ``area`` (1 or 2 appended) and
``rotation`` for editing (:data:`reports.mitsuba.bsdf.TRAVERSED_THREAD_KEYS`); a JIT variant
then reuses its compiled kernel. The kernel is brdf's Dr.Jit kernel (:mod:`brdf.jit.kernel`,
:mod:`brdf.jit.sampler`, in the variant's float type) and runs in ``scalar_rgb``, ``llvm_ad_rgb`` and
``cuda_ad_rgb``.

Conventions. Mitsuba's ``si.wi`` points toward the viewer and a BSDF's ``wo`` toward the light:
microcyl's ``wo`` and ``wi``. ``eval`` returns :math:`f_r(\omega_i, \omega_o)\cos\theta_i`
(the cosine on the light side), ``sample`` draws the light direction as
:func:`brdf.sampling.sample` does and returns ``(BSDFSample3f, f_r cos / pdf)``. The warp
follows the surface's first tangent ``dp_du`` projected onto the tangent plane, as microcyl's
renderer has the warp follow each primitive's tangent; ``rotation`` turns it further about n.
Mitsuba counts a draw of weight 0 as no draw, so the plugin's ``pdf`` is the density of
the draws of nonzero weight: :func:`brdf.sampling.pdf` where :math:`f_r\cos\theta_i > 0`, 0
elsewhere (where the model's f_r vanishes above the horizon, as it does for velvet seen at
grazing angles: every tangent sample then faces away from the light or the viewer; the
sampler draws nothing below it, :mod:`brdf.horizon`). The BSDF is one-sided
(``FrontSide``); wrap it in Mitsuba's ``twosided`` for cloth seen from both sides.

:func:`plugin_dict`, :func:`plugin_xml` and :func:`fabric_from_dict` need no Mitsuba: they
turn a :class:`brdf.Fabric` into the plugin's dictionary (or its XML ``<bsdf>`` element, for
scene files) and back (``microcyl export`` writes either for a fit's posterior medians). They
live in :mod:`analysis.fabricfile` (which also reads the XML back) and are re-exported here.
"""

from __future__ import annotations

from analysis.fabricfile import (OPTION_KEYS, PLUGIN_NAME, THREAD_KEYS, fabric_from_dict,
                                 plugin_dict, plugin_xml)
from brdf import jit

__all__ = ["register", "plugin_dict", "plugin_xml", "fabric_from_dict", "PLUGIN_NAME", "THREAD_KEYS",
           "OPTION_KEYS", "RGB_VARIANTS"]

#: The variants the plugin supports (their spectra are RGB triples).
RGB_VARIANTS = ("scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb")


def mitsuba_modules():
    """``(mitsuba, drjit, bsdf, scene)``: Mitsuba, Dr.Jit, :mod:`reports.mitsuba.bsdf` and
    :mod:`reports.mitsuba.scene`, imported on first use (the one place the modules of
    reports.mitsuba load them).

    Raises
    ------
    ImportError
        Mitsuba is not installed.
    """
    with jit.ctrl_c_held():        # (an interrupt inside the extensions' start crashes)
        # optional dependency, loaded on use: bsdf and scene import mitsuba and drjit at their top
        from reports.mitsuba import bsdf, scene
    return bsdf.mi, bsdf.dr, bsdf, scene


def register() -> None:
    """Register the BSDF ``microcylinder`` with Mitsuba for the variant that is set.

    Call it after ``mitsuba.set_variant(...)`` (again after switching variants: a Mitsuba
    plugin class belongs to one variant).

    Raises
    ------
    ImportError
        Mitsuba is not installed.
    ValueError
        No variant is set, or it is not one of :data:`RGB_VARIANTS`' kind (``*_rgb``).
    """
    mi, _, mitsuba_bsdf, _ = mitsuba_modules()

    variant = mi.variant()
    if variant is None or not variant.endswith("_rgb") or "polarized" in variant:
        raise ValueError(f"the {PLUGIN_NAME} BSDF needs an RGB variant "
                         f"({', '.join(RGB_VARIANTS)}); the variant set is {variant!r}")
    mi.register_bsdf(PLUGIN_NAME, lambda props: mitsuba_bsdf.bsdf_class()(props))
