"""analysis package of microcyl."""

from analysis.albedo import (AlbedoCurve, AlbedoResult, HemisphericalAlbedo, albedo,
                             albedo_curve, albedo_hemispherical)
from analysis.energy import VARIANTS, EnergyReport, energy_report, white_furnace
from analysis.reciprocity import ReciprocityResult, reciprocity, reciprocity_report
from analysis.sanity import SanityResult, sanity_scan

__all__ = []
__all__ += ["albedo", "albedo_curve", "albedo_hemispherical", "AlbedoResult", "AlbedoCurve",
            "HemisphericalAlbedo", "energy_report", "white_furnace", "EnergyReport", "VARIANTS",
            "reciprocity", "reciprocity_report", "ReciprocityResult", "sanity_scan",
            "SanityResult"]
