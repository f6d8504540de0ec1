"""
Slices of the BRDF
==================

``microcyl plot slices velvet --channel b -o slices.png``

The slices of Disney's BRDF Explorer for a light at 30 degrees in the warp plane: the
:math:`\theta_h \times \theta_d` image and f_r against :math:`\theta_o`, :math:`\theta_h`
and :math:`\theta_d`, here for the blue channel.
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt

from reports.cli import main

out = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "gallery"
out.mkdir(parents=True, exist_ok=True)


def show_png(path):
    """A PNG written by microcyl, shown at its own size (one image pixel a screen pixel)."""
    image = plt.imread(path)
    fig = plt.figure(figsize=(image.shape[1] / 100, image.shape[0] / 100), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.imshow(image, interpolation="none")
    ax.set_axis_off()

png = out / "slices.png"
assert main(["plot", "slices", "velvet", "--channel", "b", "--dpi", "100", "-o", str(png)]) == 0

# %%
# The figure as written (``--dpi``, ``--size`` and PDF or SVG output are options):
show_png(png)
