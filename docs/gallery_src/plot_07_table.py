"""
A measured table against the presets
====================================

``microcyl plot table velvet.csv velvet linen_plain -o table.png``

A table (here simulated by the virtual gonioreflectometer and written as CSV, as a lab's
table would arrive) drawn against two presets: a panel per incidence, each model evaluated
with the light where it was measured, the measured points with their error bars.
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt

import brdf
import gonio
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

table = gonio.measure(brdf.fabric("velvet"), "plane:warp:5:20,45,70",
                      gonio.Instrument(snr=20, cone_detector=1.0), seed=1, progress=False)
gonio.write(table, out / "velvet.csv")
table

# %%
png = out / "table.png"
assert main(["plot", "table", str(out / "velvet.csv"), "velvet", "linen_plain",
             "--dpi", "100", "-o", str(png)]) == 0
show_png(png)
