"""The paper's Table II: six fabrics, by the names of MODEL.md (their threads:
:mod:`brdf.presettable`)."""

from __future__ import annotations

from brdf.fabric import Fabric
from brdf.presettable import PRESETS, check_preset, preset_threads

__all__ = ["PRESETS", "fabric", "preset_threads", "check_preset"]


def fabric(name: str, **options) -> Fabric:
    """A preset fabric of Table II, with options (variants) of :class:`Fabric`.

    Parameters
    ----------
    name : str
        One of :data:`PRESETS`.
    **options
        ``masking``, ``reweighting``, ``tangent_samples``, ``tangent_sampling``,
        ``transmission``, ``gap``, ``rotation`` (radians).

    Returns
    -------
    Fabric

    Raises
    ------
    ValueError
        Unknown preset (the valid names are listed) or option.

    Examples
    --------
    >>> fabric("velvet").threads[1].offsets
    (-90.0, -55.0, 55.0, 90.0)
    >>> fabric("denim")
    Traceback (most recent call last):
    ...
    ValueError: unknown fabric 'denim'; valid presets are linen_plain, silk_crepe_de_chine, polyester_satin_charmeuse, polyester_satin_charmeuse_back, silk_shot, velvet
    """
    return Fabric(preset_threads(name), name=name, **options)
