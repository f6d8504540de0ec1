"""The numbers of every plot: each view's curves, images or maps computed once as a small
frozen dataclass, which the plot functions of :mod:`reports` draw and the CSVs and report
numbers read. Nothing here imports matplotlib.

One module a kind of view: lobes (planes of incidence, masking on and off), masking (the
terms M, P and u), slices (the BRDF Explorer's), hemisphere (the equal-area disc and the 3-D
lobe), reciprocity (error maps), table (a measured table against models in a plane),
tablescatter (a table of scattered pairs against models at every point, and what a view of
a table left out) and posterior (a fit's posterior-predictive lobes).
"""

from analysis.views.common import (QUANTITIES, check_angle, check_quantity, check_resolution,
                                   eval_brdf, finite_max, reduce_quantity)
from analysis.views.hemisphere import (HemisphereView, Lobe3DView, compute_hemisphere,
                                       compute_lobe_3d, equal_area_grid, equal_area_xy)
from analysis.views.lobes import (LobeView, MaskingLobesView, compute_lobes,
                                  compute_masking_lobes, plane_directions)
from analysis.views.masking import masking_terms
from analysis.views.posterior import PosteriorLobe, compute_posterior_lobes, posterior_draws
from analysis.views.reciprocity import ReciprocityView, compute_reciprocity
from analysis.views.slices import (SliceImageView, SliceView, compute_slice_image,
                                   compute_slice_theta_d, compute_slice_theta_h,
                                   compute_slice_theta_o)
from analysis.views.table import (FitOverlayView, TablePanelView, compute_fit_overlay,
                                  compute_table_panel, plane_data, plane_incidences,
                                  plane_lights, plane_points, reduce_sigma, table_panels,
                                  table_points)
from analysis.views.tablescatter import (TableCoverage, TableScatterView,
                                         compute_table_scatter, is_scattered, table_coverage)

__all__ = ["QUANTITIES", "check_angle", "check_quantity", "check_resolution", "eval_brdf",
           "finite_max", "reduce_quantity",
           "LobeView", "MaskingLobesView", "compute_lobes", "compute_masking_lobes",
           "plane_directions", "masking_terms",
           "SliceView", "SliceImageView", "compute_slice_theta_o", "compute_slice_theta_h",
           "compute_slice_theta_d", "compute_slice_image",
           "HemisphereView", "compute_hemisphere", "equal_area_grid", "equal_area_xy",
           "Lobe3DView", "compute_lobe_3d", "ReciprocityView", "compute_reciprocity",
           "TablePanelView", "compute_table_panel", "FitOverlayView", "compute_fit_overlay",
           "plane_data", "plane_incidences", "plane_lights", "plane_points", "reduce_sigma",
           "table_panels", "table_points", "TableCoverage", "TableScatterView",
           "compute_table_scatter", "is_scattered", "table_coverage",
           "PosteriorLobe", "compute_posterior_lobes", "posterior_draws"]
