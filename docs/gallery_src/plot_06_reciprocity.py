"""
Reciprocity
===========

``microcyl plot reciprocity velvet -o reciprocity.png``

The relative reciprocity error
:math:`|f(\omega_i, \omega_o) - f(\omega_o, \omega_i)| / \max` over
:math:`(\theta_o, \theta_i)`: the model is not reciprocal, and this map says where and by how
much.
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt

from reports.cli import main

out = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "gallery"
out.mkdir(parents=True, exist_ok=True)
png = out / "reciprocity.png"
assert main(["plot", "reciprocity", "velvet", "--dpi", "100", "-o", str(png)]) == 0

# %%
# The figure as written (``--dpi``, ``--size`` and PDF or SVG output are options):
image = plt.imread(png)
fig, ax = plt.subplots(figsize=(9, 9 * image.shape[0] / image.shape[1]))
ax.imshow(image)
ax.set_axis_off()
