"""
Variants of the model, from Python
==================================

Every option of :class:`brdf.Fabric` is a variant of the model (:doc:`/guide/model`): here
the polar lobe of the charmeuse satin with its defaults, without masking, and with the
longitudinal transmission, drawn on one polar axis each with
:func:`reports.plots.plot_polar_lobe` (which takes ``ax=`` and returns ``(fig, ax)``). The
axes are :class:`reports.plots.halfdisc.HalfDiscAxes`, polar axes whose box is the half disc
(any polar axes will do, with a square box's empty quarters above and below the disc).
"""
import matplotlib.pyplot as plt

import brdf
from reports import plots
from reports.plots.halfdisc import HalfDiscAxes

fab = brdf.fabric("polyester_satin_charmeuse")
fig, axes = plt.subplots(1, 3, figsize=(12, 2.9), subplot_kw={"axes_class": HalfDiscAxes},
                         layout="constrained")
for ax, (label, variant) in zip(axes, [
        ("defaults", fab),
        ("masking off", fab.replace(masking=False)),
        ("longitudinal transmission", fab.replace(transmission="longitudinal"))]):
    plots.plot_polar_lobe(variant, theta_i_deg=(30, 60), ax=ax)
    ax.set_title(label)
