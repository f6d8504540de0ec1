"""All plots of microcyl in one namespace.

Every function takes ``ax=`` (or ``fig=`` for multi-panel figures), returns ``(fig, ax)``,
saves only when given ``filename=`` (atomically) and never calls ``show()``. Angles of the
plot API are in degrees; f_r is in 1/sr. RGB quantities are drawn either per channel in red,
green and blue (``quantity="rgb"``) or as Rec. 709 luminance in the fabric's own sRGB colour
(``quantity="luminance"``); colours go through :mod:`reports.colour` (colour-science).

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> class Lambert:
...     def eval(self, wi, wo):
...         up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
...         return np.where(up[..., None], np.array([0.5, 0.4, 0.3]) / np.pi, 0.0)
>>> fig, ax = plot_polar_lobe(Lambert(), theta_i_deg=[30.0])
>>> y = ax.get_lines()[0].get_ydata()
>>> bool(np.allclose(y, (0.2126 * 0.5 + 0.7152 * 0.4 + 0.0722 * 0.3) / np.pi))
True
"""

import numpy as np  # noqa: F401  (doctest namespace)

from reports.plots.albedo import plot_albedo
from reports.plots.fit import plane_points, plot_fit_overlay
from reports.plots.hemisphere import (equal_area_grid, equal_area_xy, hemisphere_image,
                                     plot_hemisphere)
from reports.plots.lobe3d import plot_lobe_3d
from reports.plots.lobes import (lobe_peak, plane_directions, plot_lobe_comparison,
                                plot_lobe_planes, plot_polar_lobe)
from reports.plots.masking import masking_terms, plot_masking_lobes, plot_masking_terms
from reports.plots.reciprocity import plot_reciprocity_map, reciprocity_map
from reports.plots.slices import (plot_slice_image, plot_slice_theta_d, plot_slice_theta_h,
                                 plot_slice_theta_o, slice_image)
from reports.plots.common import half_diff_to_io, save_figure

__all__ = [
    "plot_polar_lobe", "plot_lobe_planes", "plot_lobe_comparison", "plot_lobe_3d", "lobe_peak",
    "plot_slice_theta_o", "plot_slice_theta_h", "plot_slice_theta_d", "plot_slice_image",
    "plot_hemisphere", "plot_albedo", "plot_masking_lobes", "plot_masking_terms",
    "plot_reciprocity_map", "plot_fit_overlay",
    "plane_directions", "plane_points", "slice_image", "hemisphere_image", "equal_area_grid",
    "equal_area_xy", "reciprocity_map", "masking_terms", "half_diff_to_io", "save_figure",
]
