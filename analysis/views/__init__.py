"""The numbers of every plot: each view's curves, images or maps computed once as a small
frozen dataclass, which the plot functions of :mod:`reports` draw and the CSVs and report
numbers read. Nothing here imports matplotlib.

One module a kind of view: lobes (planes of incidence, masking on and off), slices (the BRDF
Explorer's), hemisphere (the equal-area disc and the 3-D lobe), reciprocity (error maps) and
table (a measured table against models in a plane).
"""

from analysis.views.common import (QUANTITIES, check_angle, check_quantity, check_resolution,
                                   eval_brdf, finite_max, reduce_quantity)
from analysis.views.lobes import (LobeView, MaskingLobesView, compute_lobes,
                                  compute_masking_lobes, plane_directions)
from analysis.views.masking import masking_terms

__all__ = ["QUANTITIES", "check_angle", "check_quantity", "check_resolution", "eval_brdf",
           "finite_max", "reduce_quantity",
           "LobeView", "MaskingLobesView", "compute_lobes", "compute_masking_lobes",
           "plane_directions", "masking_terms"]
