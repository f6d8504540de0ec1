"""
Lobes in the planes of the threads
==================================

``microcyl plot lobes velvet silk_shot -o lobes.png``

f_r in the warp and weft planes of incidence for three incidences (0, 30 and 60 degrees),
two presets overlaid, each in its own colour-blind-safe colour and line style.
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

png = out / "lobes.png"
assert main(["plot", "lobes", "velvet", "silk_shot", "--dpi", "100", "-o", str(png)]) == 0

# %%
# The figure as written (``--dpi``, ``--size`` and PDF or SVG output are options):
show_png(png)
