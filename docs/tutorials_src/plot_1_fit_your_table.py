"""
Fit your own gonioreflectometer table
=====================================

From a table of measurements to a fitted fabric, its diagnostics, an export for Mitsuba 3 and
a render. Your table arrives as a CSV file (:doc:`../guide/formats`), written by hand or by your
lab's software. Every step is also a command of ``microcyl``, given in each section; the script
calls them through :func:`reports.cli.main`, which takes the same arguments.

The fit is kept small (140 pairs, three free parameters, a few hundred steps) so that this page
builds in seconds; a real fit runs to convergence, with the default free set.
"""

# %%
# A table in CSV
# --------------
# A linen measured in the warp's plane of incidence at four incidences (15, 35, 55 and 70
# degrees), every 5 degrees outgoing: 140 rows, as a lab writes them. Comment lines start with
# ``#``; a ``# key: value`` comment is kept as metadata; then a header naming the columns;
# angles in degrees, :math:`f_r` in 1/sr per channel, and its standard deviation ``sigma``
# per channel, which the fit uses as the noise of each value (a table without it gets a free
# noise level). The values were made by the virtual gonioreflectometer from the preset
# ``linen_plain`` (1-degree detector cone, signal-to-noise ratio 30), so that the truth is
# known. The script reads :download:`lab_linen.csv <../tutorials_src/lab_linen.csv>` from the
# folder it runs in.
import json
import os
import shutil
from pathlib import Path

import matplotlib.pyplot as plt

import brdf
import gonio
from reports.cli import main

work = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "tutorial_fit"
work.mkdir(parents=True, exist_ok=True)
csv = work / "linen.csv"
shutil.copyfile("lab_linen.csv", csv)        # the file beside this script
lines = csv.read_text().splitlines()
print("\n".join(lines[:14] + [f"... ({len(lines) - 14} more lines)"]))
truth = brdf.fabric("linen_plain")


def show_png(path):
    """A PNG written by microcyl, shown at its own size (one image pixel a screen pixel)."""
    image = plt.imread(path)
    fig = plt.figure(figsize=(image.shape[1] / 100, image.shape[0] / 100), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.imshow(image, interpolation="none")
    ax.set_axis_off()


# %%
# Reading it back gives a :class:`gonio.Table`; its ``repr`` says what it holds.
table = gonio.read(csv)
table

# %%
# What can this table tell?
# -------------------------
# ``microcyl fit linen.csv --fabric linen_plain --free eta1,kd1,gamma_s1,gamma_v1 --suggest``
# computes the Fisher information of the table about each candidate at the preset's values,
# before any sampling, and suggests a free set.
status = main(["fit", str(csv), "--fabric", "linen_plain",
               "--free", "eta1,kd1,gamma_s1,gamma_v1", "--suggest"])

# %%
# The fit
# -------
# ``microcyl fit linen.csv --fabric linen_plain --free kd1,gamma_s1,gamma_v1 --tie none
# --max-steps 300 -o fit/``. The preset gives the start and every parameter not free; the
# fit writes its folder as it goes, and the same command resumes it. A real fit leaves out
# ``--max-steps``: it stops when every parameter has converged.
fit_dir = work / "fit"
status = main(["fit", str(csv), "--fabric", "linen_plain",
               "--free", "kd1,gamma_s1,gamma_v1", "--tie", "none", "--max-steps", "300",
               "--no-progress", "-o", str(fit_dir)])
print("exit status", status, "| files:", ", ".join(sorted(p.name for p in fit_dir.iterdir())))

# %%
# Diagnostics
# -----------
# ``results.json`` holds the verdict and why, each parameter's median, intervals and
# convergence statistics, the quality of the fit (residuals, the albedo colour, the LOO-PIT
# test), its adequacy verdict, its warnings and its PSIS-LOO. The parameters against the
# truth:
results = json.loads((fit_dir / "results.json").read_text())
print("converged:", results["converged"], "-", results["reason"])
print(f"{'parameter':10} {'median':>8} {'95% interval':>20} {'R-hat':>7} {'truth':>7}")
for name, p in results["parameters"].items():
    true = getattr(truth.threads[0], name[:-1])
    print(f"{name:10} {p['median']:8.3f}   [{p['lo95']:7.3f}, {p['hi95']:7.3f}] "
          f"{p['rhat']:7.3f} {true:7.3f}")

# %%
# The quality of the fit, and whether the model is adequate for the data (each test's
# p-value, Holm-corrected over the tests that ran; a region test skips when a side has fewer
# than 8 points):
q, ad, loo = results["quality"], results["quality"]["adequacy"], results["loo"]
rgb = "measured {} vs predicted {}".format(
    *("(" + ", ".join(f"{c:.3f}" for c in q[k]) + ")"
      for k in ("albedo_measured", "albedo_predicted")))
print(f"residuals: rms {q['rms_residual']:.4f} in the likelihood's space, "
      f"{q['rms_normalized']:.2f} in units of the noise ({q['values']} values)")
print(f"albedo colour: {rgb}, CIEDE2000 {q['albedo_delta_e2000']:.2f}")
print(f"LOO-PIT uniformity: KS p = {q['loo_pit']['ks_pvalue']:.2f}")
print("adequate:", ad["adequate"], "-", ad["reason"])
for test, t in ad["tests"].items():
    p = "skipped" if t["p"] is None else f"p {t['p']:.3f}, Holm {t['p_holm']:.3f}"
    print(f"    {test:22} {p}")
print(f"PSIS-LOO: elpd {loo['elpd']:.1f} +- {loo['se']:.1f}, p_loo {loo['p_loo']:.1f}, "
      f"Pareto k max {loo['pareto_k_max']:.2f}")
print("warnings:", [w.get("message", w) for w in results.get("warnings", [])] or "none")

# %%
# The plots are written beside it (click a figure for its full size): the corner plot of
# the posterior,
show_png(fit_dir / "corner.png")

# %%
# the posterior-predictive lobes over the data,
show_png(fit_dir / "lobes.png")

# %%
# and the standardized residuals against angle, with the adequacy verdict.
show_png(fit_dir / "adequacy.png")

# %%
# The table against the fit: ``microcyl plot table linen.csv linen_plain --fit fit/ --dpi 110``.
assert main(["plot", "table", str(csv), "linen_plain", "--fit", str(fit_dir),
             "--dpi", "110", "-o", str(work / "table.png")]) == 0
show_png(work / "table.png")

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
# ``microcyl render sphere fit/ -o fitted.exr``: the fitted fabric on the lit sphere (small and
# at 4 samples per pixel here; the default is 1280 x 720 at 16).
assert main(["render", "sphere", str(fit_dir), "--width", "320", "--height", "240",
             "--spp", "4", "--workers", "1", "--quiet", "-o", str(work / "fitted.exr")]) == 0
show_png(work / "fitted.png")
