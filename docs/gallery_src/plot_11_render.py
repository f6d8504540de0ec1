"""
A render with the built-in ray tracer
=====================================

``microcyl render cylinder velvet --width 400 --height 225 --spp 4 -o cylinder.exr``

The cylinder scene in velvet, ray-traced with the key light, shadow rays and a dim sky
(multiple importance sampling of a table of the fabric's f_r cos and cosine directions),
written as a float32 OpenEXR and an sRGB PNG beside it. Small and at 4 samples per pixel so
that it builds in seconds: the report renders 448 x 252 at 16 (Mitsuba: 640 x 360).
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt

from reports.cli import main

out = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "gallery"
out.mkdir(parents=True, exist_ok=True)
assert main(["render", "cylinder", "velvet", "--width", "400", "--height", "225", "--spp", "4",
             "--workers", "1", "--quiet", "-o", str(out / "cylinder.exr")]) == 0

image = plt.imread(out / "cylinder.png")       # shown at its own size, pixel for pixel
fig = plt.figure(figsize=(image.shape[1] / 100, image.shape[0] / 100), dpi=100)
ax = fig.add_axes((0, 0, 1, 1))
ax.imshow(image, interpolation="none")
ax.set_axis_off()
