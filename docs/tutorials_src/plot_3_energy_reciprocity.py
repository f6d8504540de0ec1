"""
Energy conservation and reciprocity
===================================

Two properties of a physical BRDF that the microcylinder model does not guarantee
(:doc:`../guide/model`): that it reflects no more light than it receives, and that it gives the
same value with light and viewer exchanged. microcyl measures both, with error bars, instead
of assuming them. ``microcyl energy velvet`` and ``microcyl reciprocity velvet`` print the
same reports; ``microcyl report`` puts them, for every preset and variant, on its pages.
"""

# %%
# Energy: two albedos
# -------------------
# Since the model is not reciprocal, there are two directional albedos: the *reflectance*
# :math:`\rho'(\omega_i) = \int f_r \cos\theta_o\, d\omega_o` (energy conservation means
# :math:`\rho' \le 1`) and the *furnace albedo* :math:`\rho(\omega_o) = \int f_r
# \cos\theta_i\, d\omega_i` (what a white-furnace render shows). Each thread is integrated in
# its own coordinates by composite Gauss-Legendre at two resolutions; the error bar is their
# difference, and the resolution doubles until it is below the tolerance.
import matplotlib.pyplot as plt
import numpy as np

import analysis
import brdf

fab = brdf.fabric("velvet")
wi = brdf.directions.from_angles(np.radians(60), 0.0)
r = analysis.albedo(fab, wi, swap=True)        # integral over wo of f_r cos(theta_o)
print("reflectance at theta_i = 60:", np.round(r.value, 5), "+-", np.round(r.error, 6))

# %%
# Over the incidence angle, for two presets, in the warp and the weft plane:
theta = np.array([0, 15, 30, 45, 60, 75, 85, 89], dtype=float)
fig, ax = plt.subplots(figsize=(7, 4))
for name in ("velvet", "silk_shot"):
    curve = analysis.albedo_curve(brdf.fabric(name), theta, (0.0, 90.0), swap=True, tol=2e-3,
                                   workers=1)
    value = curve.value.mean(axis=-1)          # the mean of R, G and B
    for k, phi in enumerate((0, 90)):
        ax.errorbar(theta, value[:, k], yerr=curve.error.max(axis=-1)[:, k], capsize=2,
                    label=f"{name}, plane {phi} deg")
ax.axhline(1.0, color="k", lw=0.8, ls=":")
ax.set_xlabel("theta_i (degrees)")
ax.set_ylabel("reflectance rho' (mean of R, G, B)")
ax.legend(fontsize=8)

# %%
# The white furnace
# -----------------
# With every albedo set to 1, the reflectance may exceed 1 where the model creates energy.
# :func:`analysis.white_furnace` varies one parameter at a time over a scan and reports the
# largest albedo found; here velvet's, over its index of refraction only, at three angles.
rows = analysis.white_furnace(["velvet"], scan={"eta": (1.2, 1.46, 2.0)},
                              theta_deg=(0.0, 60.0, 85.0), phi_deg=(0.0,), tol=5e-3,
                              workers=1)
print(f"{'scan':10} {'furnace albedo (max)':>32} {'reflectance (max)':>34}")
for row in rows:
    cells = [f"{row[m]['value']:8.4f} +- {row[m]['error']:.1g} at {row[m]['theta_deg']:g} deg"
             + (" > 1" if row[m]["exceeds_one"] else "") for m in ("furnace", "reflectance")]
    label = "preset" if row["parameter"] == "none" else f"{row['parameter']} = {row['value']:g}"
    print(f"{label:10} {cells[0]:>32} {cells[1]:>34}")

# %%
# "> 1" marks a maximum whose lower bound (the value less its error bar) is above 1: the model
# itself, not its integration, creates energy there.

# %%
# Reciprocity
# -----------
# The relative error of a pair is :math:`|f(\omega_i, \omega_o) - f(\omega_o, \omega_i)| /
# \max(f(\omega_i, \omega_o), f(\omega_o, \omega_i))` (pairs where both are 0 left out, and
# counted), here over 20,000 random pairs:
rec = analysis.reciprocity(fab, n=20000, seed=0)
print(f"median {rec.median:.3g}, 95th percentile {rec.p95:.3g}, max {rec.max:.3g}")

# %%
# Where it is largest: the map of ``microcyl plot reciprocity`` over
# :math:`(\theta_o, \theta_i)`, the light opposite the viewer.
from reports import plots

fig, ax = plots.plot_reciprocity_map(fab)
