"""Directions as (..., 3) unit vectors and their polar angles (kept for compatibility: the
functions live in :mod:`brdf.frames`).

Frame: n = +z; the warp (thread 1) along +x; theta is the polar angle from n, phi the
azimuth from +x toward +y. All angles in radians.
"""

from brdf.frames import as_directions, from_angles, normalize, to_angles

__all__ = ["from_angles", "to_angles", "as_directions", "normalize"]
