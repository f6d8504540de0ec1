"""
A measured velvet for the renderers people use
==============================================

``microcyl export FIT --to openpbr|materialx|gltf|blender|mitsuba -o FILE``

CUReT sample 7 (velvet) fitted briefly with the microcylinder model, then exported to every
target: Mitsuba's ``microcylinder`` plugin (the fabric itself) and the sheen models of
OpenPBR, MaterialX, glTF and Blender, each projected from the fit's posterior (the medians of
4 projected draws, with 95% intervals) over a stated grid. Beside each file,
``FILE.fidelity.json`` says how closely it follows the fit and where it cannot; the bars show
the relative L2 error of f_r cos cos and the largest CIEDE2000 of a patch lit at 45 degrees,
and the spheres show the fit and each export read back, rendered side by side. CUReT's values
are relative: the export says what absolute level it assumed (``--albedo-scale`` sets one).
"""
import json
import os
from pathlib import Path

import matplotlib.pyplot as plt

import analysis
from reports.cli import main

data = Path(os.environ.get("MICROCYL_DOCS_DATA", "../shared/data"))
out = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "gallery_export"
out.mkdir(parents=True, exist_ok=True)
have_data = (data / "curet").is_dir()
print("data folder:", data, "(found)" if have_data else "(absent: the velvet preset instead)")

if have_data:
    from analysis.fit import fit_fabric

    velvet = analysis.load_measured("curet_07_velvet", data)
    spec, start = analysis.measured_spec("curet_07_velvet")
    fit_fabric(velvet, start, spec, out / "fit", max_steps=40, ensembles=2, progress=False,
               config_extra={"fabric": start.name, "options": start.options})
    fabric = str(out / "fit")
else:
    fabric = "velvet"

# %%
# Every target, each with its fidelity printed on the terminal and written beside the file
# (a coarse 5 x 8 grid and 4 draws keep this page quick; the defaults are 9 x 12 and 40).
files = {"mitsuba": "velvet.json", "openpbr": "velvet_openpbr.mtlx",
         "materialx": "velvet_materialx.mtlx", "gltf": "velvet.glb", "blender": "velvet.py"}
for target, name in files.items():
    assert main(["export", fabric, "--to", target, "-o", str(out / name), "--grid", "5x8",
                 "--draws", "4"]) == 0

# %%
# The fidelity of each export, from the files beside them.
docs = {t: json.loads((out / (n + ".fidelity.json")).read_text()) for t, n in files.items()}
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.2))
names = list(docs)
ax1.bar(names, [docs[t]["fidelity"]["relative_l2"]["luminance"] for t in names])
ax1.set_ylabel("rel. L2 error of f_r cos cos")
ax2.bar(names, [docs[t]["fidelity"]["delta_e2000"]["max"] for t in names])
ax2.set_ylabel("max CIEDE2000, lit at 45 deg")
for ax in (ax1, ax2):
    ax.tick_params(axis="x", labelrotation=30)
fig.tight_layout()

# %%
# What the sheen models cannot follow, in the words of the glTF export's fidelity file:
for line in docs["gltf"]["fidelity"]["cannot_follow"] or ["nothing flagged"]:
    print(line)

# %%
# The fit and each export read back as a FABRIC (the ``.mtlx`` and ``.glb`` files themselves;
# Blender's script is code, so its sphere is microcyl's Zeltner model at the values its
# fidelity file records), rendered by microcyl's built-in renderer in the lit-sphere scene,
# all at one exposure (the fit's brightest pixels at 90%).
import numpy as np

from analysis.sources import resolve
from brdf.baselines import Zeltner
from reports.colour import to_srgb
from reports.render.engine import render

v = docs["blender"]["projection"]["values"]
spheres = {"fit (mitsuba)": resolve(fabric).brdf,
           "openpbr": resolve(str(out / files["openpbr"])).brdf,
           "materialx": resolve(str(out / files["materialx"])).brdf,
           "gltf": resolve(str(out / files["gltf"])).brdf,
           "blender": Zeltner(base=tuple(v["base"]), sheen=tuple(v["sheen"]),
                              roughness=v["roughness"])}
images = {name: np.asarray(render("sphere", b, width=120, height=120, spp=4, workers=1,
                                  progress=False))
          for name, b in spheres.items()}
peak = float(np.percentile(images["fit (mitsuba)"], 99.5)) / 0.9
fig, axes = plt.subplots(1, len(images), figsize=(2.2 * len(images), 2.6))
for ax, (name, img) in zip(axes, images.items()):
    ax.imshow(to_srgb(img / peak))
    key = name.split(" ")[-1].strip("()")
    ax.set_title(f"{name}\nmax ΔE {docs[key]['fidelity']['delta_e2000']['max']:.1f}",
                 fontsize=9)
    ax.set_axis_off()
fig.tight_layout()
