"""
Albedo and energy
=================

``microcyl plot albedo linen_plain silk_shot -o albedo.png``

The directional albedo against the polar angle, a curve per fabric (luminance), integrated
with error bounds (:func:`analysis.albedo`); energy conservation means it stays below 1.
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt

from reports.cli import main

out = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "gallery"
out.mkdir(parents=True, exist_ok=True)
png = out / "albedo.png"
assert main(["plot", "albedo", "linen_plain", "silk_shot", "--dpi", "100", "-o", str(png)]) == 0

# %%
# The figure as written (``--dpi``, ``--size`` and PDF or SVG output are options):
image = plt.imread(png)
fig, ax = plt.subplots(figsize=(9, 9 * image.shape[0] / image.shape[1]))
ax.imshow(image)
ax.set_axis_off()
