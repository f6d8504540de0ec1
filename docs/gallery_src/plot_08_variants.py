"""
Variants of the model, from Python
==================================

Every option of :class:`brdf.Fabric` is a variant of MODEL.md: here the polar lobe of the
charmeuse satin with its defaults, without masking, and with the longitudinal transmission,
drawn on one polar axis with :func:`reports.plots.plot_polar_lobe` (which takes ``ax=`` and
returns ``(fig, ax)``).
"""
import matplotlib.pyplot as plt

import brdf
from reports import plots

fab = brdf.fabric("polyester_satin_charmeuse")
fig, axes = plt.subplots(1, 3, figsize=(12, 4.2), subplot_kw={"projection": "polar"})
for ax, (label, variant) in zip(axes, [
        ("defaults", fab),
        ("masking off", fab.replace(masking=False)),
        ("longitudinal transmission", fab.replace(transmission="longitudinal"))]):
    plots.plot_polar_lobe(variant, theta_i_deg=(30, 60), ax=ax)
    ax.set_title(label)
fig.tight_layout()
