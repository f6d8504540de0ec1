"""
Shadowing and masking
=====================

``microcyl plot masking velvet -o masking.png``

The lobes with shadowing and masking on and off, a panel per plane, for a light at 60
degrees.
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt

from reports.cli import main

out = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "gallery"
out.mkdir(parents=True, exist_ok=True)
png = out / "masking.png"
assert main(["plot", "masking", "velvet", "--dpi", "100", "-o", str(png)]) == 0

# %%
# The figure as written (``--dpi``, ``--size`` and PDF or SVG output are options):
image = plt.imread(png)
fig, ax = plt.subplots(figsize=(9, 9 * image.shape[0] / image.shape[1]))
ax.imshow(image)
ax.set_axis_off()
