"""brdf: the microcylinder cloth BRDF of Sadeghi, Bisker, De Deken and Jensen (2013).

The model as ``../shared/spec/MODEL.md`` specifies it: threads with tangent curves, fabrics
of two threads, the paper's six presets, and every variant; importance sampling of a fabric
(:mod:`brdf.sampling`: ``Fabric.sample``, ``Fabric.pdf``). NumPy and SciPy only.
"""

from brdf import directions, frames, sampling, schema, terms
from brdf.curve import TangentCurve
from brdf.fabric import Fabric, Prepared
from brdf.options import (GAP_METHODS, OPTIONS, SAMPLING_METHODS, TRANSMISSION_METHODS,
                          FabricOptions, Gap, TangentSampling, Transmission)
from brdf.plan import FabricPlan, ThreadPlan
from brdf.presets import PRESETS, fabric, preset_threads
from brdf.protocols import BRDF, SampledBRDF, ThreadedBRDF
from brdf.thread import Thread

__all__ = [
    "Thread", "TangentCurve", "Fabric", "FabricPlan", "ThreadPlan", "FabricOptions",
    "Transmission", "Gap", "TangentSampling", "Prepared", "fabric", "preset_threads", "PRESETS",
    "OPTIONS", "SAMPLING_METHODS", "TRANSMISSION_METHODS", "GAP_METHODS", "directions", "frames",
    "schema", "terms", "sampling", "BRDF", "ThreadedBRDF", "SampledBRDF",
]
