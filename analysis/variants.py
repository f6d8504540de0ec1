"""The model variants the physical checks examine, and the check of preset and variant names.

A variant is a set of options passed to ``brdf.fabric``: each switches one term of the model
(masking, reweighting, transmission, gap) so that the energy and reciprocity reports show which
term changes the result.
"""

from __future__ import annotations

from brdf.presets import PRESETS

__all__ = ["VARIANTS", "check_names"]

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
    presets : sequence of str, optional
        Keys of ``brdf.PRESETS`` (default all).
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
        if p not in PRESETS:
            raise ValueError(f"unknown fabric {p!r}; presets: {', '.join(PRESETS)}")
    for v in variants:
        if v not in VARIANTS:
            raise ValueError(f"unknown variant {v!r}; variants: {', '.join(VARIANTS)}")
    return presets, variants
