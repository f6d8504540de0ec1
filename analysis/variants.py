"""The model variants the physical checks examine, and the check of preset and variant names.

A variant is a set of options passed to ``brdf.fabric``: each switches one term of the model
(masking, reweighting, transmission, gap) so that the energy and reciprocity reports show which
term changes the result. A BRDF that is no microcylinder fabric (a baseline model, a fit of
one) enters under a name (:class:`Named`) and in the ``default`` variant only
(:func:`applies`): the variants switch terms of the microcylinder.
"""

from __future__ import annotations

import dataclasses

from brdf.fabric import Fabric
from brdf.presets import PRESETS, check_preset
from brdf.presets import fabric as preset_fabric

__all__ = ["VARIANTS", "check_names", "fabric_of", "label_of", "Named", "applies"]


@dataclasses.dataclass(frozen=True)
class Named:
    """A BRDF that is no microcylinder fabric, under a name for reports.

    Attributes
    ----------
    name : str
    brdf : object
        ``eval(wi, wo)`` -> RGB f_r (..., 3) in 1/sr (e.g. a
        registered model of :data:`brdf.MODELS`).
    model : str
        Its model's name (``lambert``, ...).
    """

    name: str
    brdf: object
    model: str = ""

    def eval(self, wi, wo):
        """f_r (..., 3) in 1/sr of the BRDF."""
        return self.brdf.eval(wi, wo)


def applies(preset, variant: str) -> bool:
    """Whether ``variant`` applies to ``preset``: every variant to a preset or fabric, only
    ``default`` to a :class:`Named` BRDF."""
    return not isinstance(preset, Named) or variant == "default"

#: Model variants examined, by name: options passed to ``brdf.fabric``.
VARIANTS = {
    "default": {},
    "masking_off": {"masking": False},
    "reweighting_off": {"reweighting": False},
    "transmission_longitudinal": {"transmission": "longitudinal"},
    "gap_outgoing": {"gap": "outgoing"},
}


def check_names(presets=None, variants=None) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Preset and variant names, checked; None means all of them.

    Parameters
    ----------
    presets : sequence of str or brdf.Fabric, optional
        Keys of ``brdf.PRESETS`` (default all), or fabrics (a fit's, a file's) named by their
        ``name`` (:func:`label_of`).
    variants : sequence of str, optional
        Keys of :data:`VARIANTS` (default all).

    Returns
    -------
    presets, variants : tuple of str

    Raises
    ------
    ValueError
        An unknown preset or variant, naming it and the valid ones.

    Examples
    --------
    >>> check_names(["velvet"], ["default"])
    (('velvet',), ('default',))
    >>> len(check_names()[1])
    5
    """
    presets = tuple(PRESETS if presets is None else presets)
    variants = tuple(VARIANTS if variants is None else variants)
    for p in presets:
        if not isinstance(p, (Fabric, Named)):
            check_preset(p)
    for v in variants:
        if v not in VARIANTS:
            raise ValueError(f"unknown variant {v!r}; variants: {', '.join(VARIANTS)}")
    return presets, variants


def fabric_of(preset, variant: str = "default") -> Fabric:
    """The fabric of ``preset`` (a preset's name or a :class:`brdf.Fabric`) in ``variant``
    (a key of :data:`VARIANTS`: its options replace the fabric's).

    Examples
    --------
    >>> fabric_of("velvet", "masking_off").options["masking"]
    False
    """
    if isinstance(preset, Named):
        if not applies(preset, variant):
            raise ValueError(f"{preset.name}: variant {variant} applies to microcylinder "
                             f"fabrics only")
        return preset
    base = preset if isinstance(preset, Fabric) else preset_fabric(check_preset(preset))
    return base.replace(**VARIANTS[variant]) if VARIANTS[variant] else base


def label_of(preset) -> str:
    """What reports call ``preset``: its name (a preset's, or the fabric's ``name``)."""
    return preset.name if isinstance(preset, (Fabric, Named)) else str(preset)
