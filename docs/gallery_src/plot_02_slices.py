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
png = out / "slices.png"
assert main(["plot", "slices", "velvet", "--channel", "b", "--dpi", "100", "-o", str(png)]) == 0

# %%
# The figure as written (``--dpi``, ``--size`` and PDF or SVG output are options):
image = plt.imread(png)
fig, ax = plt.subplots(figsize=(9, 9 * image.shape[0] / image.shape[1]))
ax.imshow(image)
ax.set_axis_off()
