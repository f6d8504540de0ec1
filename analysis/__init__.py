"""analysis package of microcyl: physical checks, Bayesian fitting (emcee) and measurement
planning (:func:`plan`)."""

from analysis.lazy import lazy_getattr
from analysis.albedo import (AlbedoCurve, AlbedoResult, HemisphericalAlbedo, albedo,
                             albedo_curve, albedo_hemispherical)
from analysis.energy import VARIANTS, EnergyReport, energy_report, white_furnace
from analysis.reciprocity import (ReciprocityReport, ReciprocityResult, reciprocity,
                                  reciprocity_report)
from analysis.colour import luminance
from analysis.sanity import SanityResult, sanity_scan
from analysis.diagnostics import autocorr_time, ess, interval_summary, split_rhat
from analysis.likelihood import Likelihood
from analysis.params import (DEFAULT_FREE, DEFAULT_TIES, PARAM_NAMES, ParamSpec,
                             defaults_from_fabric)

#: Names loaded on first use, with their modules (:mod:`analysis.lazy`).
_LAZY = {**dict.fromkeys(("FabricModel", "FitResult", "LogPosterior", "fit_fabric",
                          "write_results"), "analysis.fit"),
         **dict.fromkeys(("MEASURED", "MeasuredDataset", "load_measured", "measured_spec"),
                         "analysis.measured"),
         **dict.fromkeys(("Plan", "plan"), "analysis.planning")}
__getattr__ = lazy_getattr(__name__, _LAZY, globals())

__all__ = []
__all__ += ["albedo", "albedo_curve", "albedo_hemispherical", "AlbedoResult", "AlbedoCurve",
            "HemisphericalAlbedo", "energy_report", "white_furnace", "EnergyReport", "VARIANTS",
            "reciprocity", "reciprocity_report", "ReciprocityResult", "ReciprocityReport",
            "sanity_scan", "SanityResult", "luminance"]
__all__ += ["ParamSpec", "PARAM_NAMES", "DEFAULT_FREE", "DEFAULT_TIES", "defaults_from_fabric",
            "Likelihood", "fit_fabric", "FitResult", "FabricModel", "LogPosterior", "write_results",
            "autocorr_time", "split_rhat", "ess", "interval_summary",
            "MEASURED", "MeasuredDataset", "load_measured", "measured_spec", "plan", "Plan"]
