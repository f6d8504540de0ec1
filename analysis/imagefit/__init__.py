"""Cloth parameters from photographs (``microcyl fit-images``): :mod:`~analysis.imagefit.workflow`
(:func:`fit_images`), :mod:`~analysis.imagefit.noise` (the noise model),
:mod:`~analysis.imagefit.solver` (Levenberg-Marquardt on renders, the Laplace approximation),
:mod:`~analysis.imagefit.summary` (flat coordinates, summaries, warnings). The renderer is
passed in as a callable: analysis imports none.
"""

from analysis.imagefit.noise import NoiseModel
from analysis.imagefit.workflow import Observation, fit_images

__all__ = ["NoiseModel", "Observation", "fit_images"]
