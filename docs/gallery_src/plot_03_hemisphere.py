"""
The outgoing hemisphere
=======================

``microcyl plot hemisphere polyester_satin_charmeuse -o hemisphere.png``

f_r (luminance) over the whole outgoing hemisphere for a light at 45 degrees in the warp
plane: the satin's anisotropic highlight.
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt

from reports.cli import main

out = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "gallery"
out.mkdir(parents=True, exist_ok=True)
png = out / "hemisphere.png"
assert main(["plot", "hemisphere", "polyester_satin_charmeuse", "--dpi", "100",
             "-o", str(png)]) == 0

# %%
# The figure as written (``--dpi``, ``--size`` and PDF or SVG output are options):
image = plt.imread(png)
fig, ax = plt.subplots(figsize=(9, 9 * image.shape[0] / image.shape[1]))
ax.imshow(image)
ax.set_axis_off()
