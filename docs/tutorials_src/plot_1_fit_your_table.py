"""
Fit your own gonioreflectometer table
=====================================

From a table of measurements to a fitted fabric, its diagnostics, an export for Mitsuba 3 and
a render. Your table arrives as a CSV file (:doc:`../guide/formats`); here the virtual
gonioreflectometer makes one, so that the truth is known. Every step is also a command of
``microcyl``, given in each section; the script calls them through
:func:`reports.cli.main`, which takes the same arguments.

The fit is kept small (a few hundred pairs, three free parameters, a few hundred steps) so that
this page builds in seconds; a real fit runs to convergence, with the default free set.
"""

# %%
# A table in CSV
# --------------
# A linen measured in the warp's plane of incidence at four incidences, every 5 degrees, through
# an instrument with a 1-degree detector cone and a signal-to-noise ratio of 30. The table
# keeps the noise's standard deviation as ``sigma``, which the fit uses.
import json
import os
from pathlib import Path

import matplotlib.pyplot as plt

import brdf
import gonio
from reports.cli import main

work = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "tutorial_fit"
work.mkdir(parents=True, exist_ok=True)
truth = brdf.fabric("linen_plain").replace(name="lab linen")
table = gonio.measure(truth, "plane:warp:5:15,35,55,70",
                      gonio.Instrument(snr=30, cone_detector=1.0), seed=4, progress=False)
gonio.write(table, work / "linen.csv")
for line in (work / "linen.csv").read_text().splitlines()[:12]:
    print(line if len(line) < 100 else line[:96] + " ...")

# %%
# Reading it back gives a :class:`gonio.Table`; its ``repr`` says what it holds.
table = gonio.read(work / "linen.csv")
table

# %%
# What can this table tell?
# -------------------------
# ``microcyl fit linen.csv --fabric linen_plain --free eta1,kd1,gamma_s1,gamma_v1 --suggest``
# computes the Fisher information of the table about each candidate at the preset's values,
# before any sampling, and suggests a free set.
status = main(["fit", str(work / "linen.csv"), "--fabric", "linen_plain",
               "--free", "eta1,kd1,gamma_s1,gamma_v1", "--suggest"])

# %%
# The fit
# -------
# ``microcyl fit linen.csv --fabric linen_plain --free kd1,gamma_s1,gamma_v1 --tie none
# --max-steps 300 -o fit/``. The preset gives the start and every parameter not free; the
# fit writes its folder as it goes, and the same command resumes it. A real fit leaves out
# ``--max-steps``: it stops when every parameter has converged.
fit_dir = work / "fit"
status = main(["fit", str(work / "linen.csv"), "--fabric", "linen_plain",
               "--free", "kd1,gamma_s1,gamma_v1", "--tie", "none", "--max-steps", "300",
               "--no-progress", "-o", str(fit_dir)])
print("exit status", status, "| files:", ", ".join(sorted(p.name for p in fit_dir.iterdir())))

# %%
# Diagnostics
# -----------
# ``results.json`` holds the verdict and why, each parameter's median, intervals and
# convergence statistics, the quality of the fit (residuals, the LOO-PIT test, and in newer
# versions an adequacy verdict), its warnings and its PSIS-LOO. What this version wrote:
results = json.loads((fit_dir / "results.json").read_text())
print("converged:", results["converged"], "-", results["reason"])
print(f"{'parameter':10} {'median':>9} {'95% interval':>22} {'R-hat':>7}   truth")
for name, p in results["parameters"].items():
    true = getattr(truth.threads[0], name[:-1])
    print(f"{name:10} {p['median']:9.4g}   [{p['lo95']:8.4g}, {p['hi95']:8.4g}] "
          f"{p['rhat']:7.4f}   {true:g}")


def show(value):
    """A number to 4 significant digits; lists and dicts of them."""
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list):
        return "[" + ", ".join(show(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {show(v)}" for k, v in value.items()) + "}"
    return str(value)


for key in ("quality", "adequacy", "loo"):       # the fields this version wrote
    if isinstance(results.get(key), dict):
        print(f"{key}:")
        for k, v in results[key].items():
            print(f"    {k}: {show(v)}")
print("warnings:", [w.get("message", w) for w in results.get("warnings", [])] or "none")

# %%
# The corner plot, the chains and the posterior-predictive lobes are written beside it:
fig, axes = plt.subplots(1, 2, figsize=(12, 6))
for ax, name in zip(axes, ("corner.png", "lobes.png")):
    ax.imshow(plt.imread(fit_dir / name))
    ax.set_axis_off()
    ax.set_title(name)

# %%
# The table against the fit: ``microcyl plot table linen.csv linen_plain --fit fit/``.
assert main(["plot", "table", str(work / "linen.csv"), "linen_plain", "--fit", str(fit_dir),
             "--dpi", "90", "-o", str(work / "table.png")]) == 0
image = plt.imread(work / "table.png")
fig, ax = plt.subplots(figsize=(10, 10 * image.shape[0] / image.shape[1]))
ax.imshow(image)
ax.set_axis_off()

# %%
# Export
# ------
# ``microcyl export fit/ -o fabric.json``: the posterior medians (fixed and tied parameters as
# the fit held them) as the dictionary of the Mitsuba 3 BSDF ``microcylinder``, which
# ``microcyl render`` also takes. ``-o fabric.xml`` writes a ``<bsdf>`` element instead.
assert main(["export", str(fit_dir), "-o", str(work / "fabric.json")]) == 0
print((work / "fabric.json").read_text())

# %%
# A render
# --------
# ``microcyl render sphere fit/ -o fitted.exr``: the fitted fabric on the lit sphere (tiny and
# at 4 samples per pixel here; the default is 1280 x 720 at 16).
assert main(["render", "sphere", str(fit_dir), "--width", "200", "--height", "150",
             "--spp", "4", "--workers", "1", "--quiet", "-o", str(work / "fitted.exr")]) == 0
fig, ax = plt.subplots(figsize=(5, 3.75))
ax.imshow(plt.imread(work / "fitted.png"))
ax.set_axis_off()
