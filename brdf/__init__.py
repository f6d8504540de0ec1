"""brdf: the microcylinder cloth BRDF of Sadeghi, Bisker, De Deken and Jensen (2013).

The model as ``../shared/spec/MODEL.md`` specifies it: threads with tangent curves, fabrics
of two threads, the paper's six presets, and every variant; importance sampling of a fabric
(:mod:`brdf.sampling`: ``Fabric.sample``, ``Fabric.pdf``). NumPy and SciPy only.
"""

from brdf import directions, frames, sampling, schema, terms
from brdf.curve import MAX_TANGENT_SAMPLES, SAMPLING_METHODS, TangentCurve
from brdf.fabric import GAP_METHODS, OPTIONS, TRANSMISSION_METHODS, Fabric, Prepared
from brdf.presets import PRESETS, check_preset, fabric, preset_threads
from brdf.protocols import BRDF, SampledBRDF, ThreadedBRDF
from brdf.thread import Thread

__all__ = [
    "Thread", "TangentCurve", "Fabric", "Prepared", "fabric", "preset_threads", "PRESETS",
    "check_preset",
    "OPTIONS", "SAMPLING_METHODS", "TRANSMISSION_METHODS", "GAP_METHODS", "directions", "frames",
    "MAX_TANGENT_SAMPLES", "schema", "terms", "sampling", "BRDF", "ThreadedBRDF", "SampledBRDF",
]
