"""brdf: the microcylinder cloth BRDF of Sadeghi, Bisker, De Deken and Jensen (2013).

The model as ``../shared/spec/MODEL.md`` specifies it: threads with tangent curves, fabrics
of two threads, the paper's six presets, and every variant; importance sampling of a fabric
(:mod:`brdf.sampling`: ``Fabric.sample``, ``Fabric.pdf``). NumPy and SciPy only.

:data:`MODELS` registers every model by name (``microcylinder``, the fabric, and the baselines
of :mod:`brdf.baselines`), each a :class:`Model`: flat parameters (:class:`ParamSchema`),
``eval``, ``sample``, ``pdf`` and a batched forward model for fits.

A :class:`Fabric` checks its threads and options and compiles them into a frozen
:class:`FabricPlan` (``Fabric.plan``: the typed options, :class:`FabricOptions`, and each
thread's constants); ``Fabric.eval``, :class:`Prepared`, the sampler and the Mitsuba plugin
read only the plan.

Where each of MODEL.md's names runs (the hot path), and its transliteration from the angles in
:mod:`brdf.terms` that ``tests/test_brdf_kernel.py`` compares it with::

    MODEL.md   hot path                                          twin in brdf.terms
    ---------  ------------------------------------------------  ----------------------------
    theta,phi  kernel.longitudinal, half_difference, azimuth     (angles, in the tests)
    F_r        shading.fresnel2_into (2 F_r, in place)           fresnel
    F_T        shading.transmission_into                         transmission
    g          shading.gaussian_into * gaussian_norm             gaussian
               (exponent per th2 = 4 theta_h^2: gaussian_exponent)
    f_rs       shading.surface_term; its direction factor        fresnel, gaussian
               cos(phi_d/2): kernel.f_rs_geometry
    f_rv       shading.f_rv (volume_term = transmission_into     transmission, gaussian
               + f_rv); its factors: kernel.f_rv_geometry
               (1/(cos theta_i + cos theta_r)),
               shading.f_rv_coefficients ((1-k_d)/(gamma_v
               sqrt(2 pi))), A in combine.combine_rgb
    M          kernel.masking                                    pair_weight, visibility
    P          kernel.reweighting (and its mean over samples)    pair_weight, visibility
    u          kernel.u_of_cos (in kernel.pair_blend)            u
    Q          combine.normalization_q (FabricPlan.q: options)   (from psi, in the tests)
    S_j, f_r   FabricPlan.geometry, .shade, .combine_into        tests/spec_reference.py
               (Fabric.eval and Prepared.eval both)
"""


from brdf import directions, frames, microcylinder, sampling, schema, terms
from brdf.forward import Forward
from brdf.curve import TangentCurve
from brdf.fabric import Fabric, Prepared
from brdf.options import (GAP_METHODS, MAX_TANGENT_SAMPLES, OPTIONS, SAMPLING_METHODS,
                          TRANSMISSION_METHODS, FabricOptions, Gap, TangentSampling,
                          Transmission)
from brdf.microcylinder import FabricForward
from brdf.models import DEFAULT_MODEL, MODELS, model_class, model_name, model_names
from brdf.paramschema import FlatParam, ParamSchema
from brdf.plan import FabricPlan, ThreadPlan
from brdf.presets import PRESETS, check_preset, fabric, preset_threads
from brdf.protocols import BRDF, Model, SampledBRDF, ThreadedBRDF
from brdf.thread import Thread

__all__ = [
    "Thread", "TangentCurve", "Fabric", "FabricPlan", "ThreadPlan", "FabricOptions",
    "Transmission", "Gap", "TangentSampling", "Prepared", "fabric", "preset_threads", "PRESETS",
    "check_preset",
    "OPTIONS", "SAMPLING_METHODS", "TRANSMISSION_METHODS", "GAP_METHODS", "directions", "frames",
    "MAX_TANGENT_SAMPLES", "schema", "terms", "sampling", "BRDF", "ThreadedBRDF", "SampledBRDF",
    "Model", "MODELS", "DEFAULT_MODEL", "model_class", "model_name", "model_names",
    "ParamSchema", "FlatParam", "Forward", "FabricForward", "microcylinder",
]
