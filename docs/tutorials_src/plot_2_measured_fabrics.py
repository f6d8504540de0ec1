"""
The measured felts and CUReT fabrics
====================================

microcyl knows nine measured datasets (:data:`analysis.MEASURED`): three acrylic felts of the
RGL material database (Dupuy and Jakob 2018, RGB tensor files) and six fabrics of the CUReT
database (Dana et al. 1999: 205 grey, relative measurements per sample). This tutorial reads
them from ``../shared/data`` beside the repository (the data are not part of microcyl), draws
them against the presets and fits one. ``microcyl fit-measured -o fits/`` fits all nine
(about 11 minutes on 2 cores) and ``microcyl report --measured fits/`` shows them.

Where the data folder is absent, the steps below say so and are skipped.
"""
import os
from pathlib import Path

import matplotlib.pyplot as plt

import analysis
from reports.cli import main

data = Path(os.environ.get("MICROCYL_DOCS_DATA", "../shared/data"))
work = Path(os.environ.get("MICROCYL_DOCS_WORK", ".")) / "tutorial_measured"
work.mkdir(parents=True, exist_ok=True)
have_data = (data / "rgl").is_dir() and (data / "curet").is_dir()
print("data folder:", data, "(found)" if have_data else "(absent: the steps below are skipped)")


def show_png(path):
    """A PNG written by microcyl, shown at its own size (one image pixel a screen pixel)."""
    image = plt.imread(path)
    fig = plt.figure(figsize=(image.shape[1] / 100, image.shape[0] / 100), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.imshow(image, interpolation="none")
    ax.set_axis_off()


# %%
# The datasets
# ------------
# Each starts from its closest preset, with one set of optical parameters shared by both
# threads (and the albedo for the RGB felts; CUReT's albedo is absorbed by a free ``scale``).
for name, ds in analysis.MEASURED.items():
    print(f"{name:26} {ds.kind:6} start {ds.preset:27} free {', '.join(ds.free)}")

# %%
# A felt of the RGL database
# --------------------------
# The RGL files are sampled at their own incidence nodes and every 15 degrees outgoing
# (on one half of the azimuths: the files are isotropic and mirror the other half).
if have_data:
    felt = analysis.load_measured("rgl_pink_felt", data)
    print(repr(felt))
    felt_file = data / "rgl" / "acrylic_felt_pink_rgb.bsdf"
    assert main(["plot", "table", str(felt_file), "linen_plain", "--dpi", "120",
                 "-o", str(work / "felt.png")]) == 0
    show_png(work / "felt.png")

# %%
# A CUReT fabric, and a short fit
# -------------------------------
# CUReT sample 44 (linen): 205 configurations, grey and relative, so the fit adds a free
# ``scale`` and, as the table has no sigma, a free noise level ``log_noise``. The settings of
# ``fit-measured`` (:func:`analysis.measured_spec`), here stopped at 300 steps to keep the page
# quick: the verdict says whether that was enough.
if have_data:
    from analysis.fit import fit_fabric
    from reports.plots.fit_diagnostics import write_fit_plots

    linen = analysis.load_measured("curet_44_linen", data)
    print(repr(linen))
    spec, start = analysis.measured_spec("curet_44_linen")
    result = fit_fabric(linen, start, spec, work / "curet_44", max_steps=300, progress=False,
                        plots=write_fit_plots)
    print(repr(result))
    for w in result.warnings:
        print("warning:", w.get("message", w))

# %%
# The posterior of the CUReT fit: ridges where the parameters trade against each other, which
# ``microcyl fit --suggest`` would have flagged before sampling.
if have_data:
    from reports.plots import fit_diagnostics as fitplots

    fig = fitplots.corner_plot(result)

# %%
# The fit writes its plots beside ``results.json``, as ``microcyl fit-measured`` does for each
# dataset (the measured page of ``microcyl report --measured`` shows them): ``lobes.png``,
# the posterior-predictive lobes over the data (click a figure for its full size),
if have_data:
    show_png(work / "curet_44" / "lobes.png")

# %%
# and ``adequacy.png``, the standardized residuals against angle with the adequacy verdict.
if have_data:
    show_png(work / "curet_44" / "adequacy.png")
