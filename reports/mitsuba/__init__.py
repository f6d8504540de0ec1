"""Mitsuba 3: the ``microcylinder`` BSDF plugin and the ``--engine mitsuba`` render.

:mod:`~reports.mitsuba.plugin` registers the plugin (:func:`register`; its names are re-exported
here, with the plugin's dictionary, which needs no Mitsuba); :mod:`~reports.mitsuba.bsdf`
the BSDF class around brdf's Dr.Jit kernel (:mod:`brdf.jit`, in the variant's float type);
:mod:`~reports.mitsuba.scene` the scenes as Mitsuba scenes,
:mod:`~reports.mitsuba.render` the render and its variant choice. Mitsuba is imported on use.
"""

from reports.mitsuba.plugin import (  # noqa: F401  (re-exported)
    register,
    plugin_dict,
    plugin_xml,
    fabric_from_dict,
    PLUGIN_NAME,
    THREAD_KEYS,
    OPTION_KEYS,
    RGB_VARIANTS,
)

__all__ = ['register', 'plugin_dict', 'plugin_xml', 'fabric_from_dict', 'PLUGIN_NAME', 'THREAD_KEYS', 'OPTION_KEYS', 'RGB_VARIANTS']
