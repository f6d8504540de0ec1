"""
A fit's posterior-predictive lobes
==================================

The same small fit as the corner plot (the same folder: a finished fit is summarized again
without sampling), and its posterior-predictive bands over the data: for up to three
incidences, the median and 5-95% band of :math:`f_r \\cos\\theta_o` of 48 posterior draws in
the plane of incidence, with the table's points. ``microcyl fit`` writes it as ``lobes.png``.
"""
import os
from pathlib import Path

import brdf
import gonio
from analysis.fit import FabricModel, fit_fabric
from analysis.params import ParamSpec, defaults_from_fabric
from reports.plots import fit_diagnostics as fitplots

work = Path(os.environ.get("MICROCYL_DOCS_WORK", "."))
fab = brdf.fabric("velvet")
table = gonio.measure(fab, "full:30", gonio.Instrument(snr=30), seed=2, progress=False)
spec = ParamSpec("gamma_s1,kd1", defaults=defaults_from_fabric(fab))
result = fit_fabric(table, fab, spec, work / "velvet_fit", max_steps=200, progress=False)

fig, ax = fitplots.lobe_plot(result, table, lambda wi, wo: FabricModel(fab, wi, wo))
