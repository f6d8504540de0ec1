"""
A fit's posterior: the corner plot
==================================

A small fit (two free parameters of velvet, a simulated table of 625 pairs, at most 200
steps) and the corner plot of its posterior with the true values marked. ``microcyl fit``
writes the same figure as ``corner.png``.
"""
import os
from pathlib import Path

import brdf
import gonio
from analysis.fit import fit_fabric
from analysis.params import ParamSpec, defaults_from_fabric
from reports.plots import fit_diagnostics as fitplots

work = Path(os.environ.get("MICROCYL_DOCS_WORK", "."))
fab = brdf.fabric("velvet")
table = gonio.measure(fab, "full:30", gonio.Instrument(snr=30), seed=2, progress=False)
spec = ParamSpec("gamma_s1,kd1", defaults=defaults_from_fabric(fab))
result = fit_fabric(table, fab, spec, work / "velvet_fit", max_steps=200, progress=False)
result

# %%
# The truth is the preset's: gamma_s1 = 6 degrees, kd1 = 0.1.
fig = fitplots.corner_plot(result, truths={"gamma_s1": 6.0, "kd1": 0.1})
