"""Standard geometries at which every report quotes f_r."""

from __future__ import annotations

import numpy as np

import brdf
from analysis.colour import luminance

__all__ = ["STANDARD_GEOMETRIES", "standard_values", "standard_luminance"]

#: (label, theta_i, phi_i, theta_o, phi_o), degrees; phi from the warp (+x).
STANDARD_GEOMETRIES = (
    ("normal", 0.0, 0.0, 0.0, 0.0),
    ("specular 30 warp", 30.0, 0.0, 30.0, 180.0),
    ("specular 30 weft", 30.0, 90.0, 30.0, 270.0),
    ("specular 60 warp", 60.0, 0.0, 60.0, 180.0),
    ("retro 45 warp", 45.0, 0.0, 45.0, 0.0),
    ("oblique 60/30 at 45", 60.0, 45.0, 30.0, 225.0),
)


def standard_values(fab) -> dict[str, list[float]]:
    """RGB f_r (1/sr) of any BRDF at :data:`STANDARD_GEOMETRIES`, by label.

    Examples
    --------
    >>> vals = standard_values(brdf.fabric("linen_plain"))
    >>> list(vals)[1], len(vals["normal"])
    ('specular 30 warp', 3)
    """
    angles = np.radians([g[1:] for g in STANDARD_GEOMETRIES])
    wi = brdf.directions.from_angles(angles[:, 0], angles[:, 1])
    wo = brdf.directions.from_angles(angles[:, 2], angles[:, 3])
    f = np.asarray(fab.eval(wi, wo))
    return {g[0]: [float(v) for v in row] for g, row in zip(STANDARD_GEOMETRIES, f)}


def standard_luminance(fab) -> list[float]:
    """The luminance of :func:`standard_values` (1/sr), in the order of
    :data:`STANDARD_GEOMETRIES`.

    Examples
    --------
    >>> lum = standard_luminance(brdf.fabric("linen_plain"))
    >>> rgb = standard_values(brdf.fabric("linen_plain"))["normal"]
    >>> len(lum), min(rgb) <= lum[0] <= max(rgb)
    (6, True)
    """
    return luminance(np.array(list(standard_values(fab).values()), dtype=np.float64)).tolist()
