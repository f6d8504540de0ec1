"""Lights of the renderer's scenes: a point (or small disc) light and a directional light.

Intensities in W/sr and irradiances in W/m^2 (any consistent radiometric unit), RGB.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reports.render.vec3 import INF as _INF
from reports.render.vec3 import basis as _basis
from reports.render.vec3 import unit as _unit

__all__ = ["PointLight", "DirectionalLight", "LIGHTS"]


@dataclass(frozen=True)
class PointLight:
    """A point light, or a small one-sided Lambertian disc when ``radius > 0``.

    Parameters
    ----------
    position : (3,) array_like
        Position (disc centre), scene units.
    intensity : float or (3,) array_like
        Radiant intensity, W/sr (RGB); for a disc, the intensity along its axis (the disc's
        radiance is ``intensity / (pi radius^2)``).
    radius : float
        Disc radius, scene units; 0 for a point light.
    target : (3,) array_like
        The disc faces this point.

    Notes
    -----
    Irradiance at distance r, normal to the direction to the light: point light
    ``E = I / r^2``; disc, sampled uniformly by area with one sample per camera sample,
    ``E = I cos(theta_l) / r^2`` (theta_l between the disc axis and the direction to the
    shaded point), an unbiased estimate of the disc's irradiance.
    """

    position: tuple = (-2.0, 3.0, 3.0)
    intensity: object = 20.0
    radius: float = 0.0
    target: tuple = (0.0, 0.0, 0.0)

    def sample(self, p, rng):
        """Unit direction to the light, distance, and irradiance (m, 3) at points ``p``."""
        m = len(p)
        pos = np.broadcast_to(np.asarray(self.position, float), (m, 3))
        axis = _unit(np.asarray(self.target, float) - np.asarray(self.position, float))
        if self.radius > 0:
            r = self.radius * np.sqrt(rng.random(m))
            a = 2 * np.pi * rng.random(m)
            _, e1, e2 = _basis((0.0, 0.0, 0.0), axis, (0.0, 1.0, 0.0))
            pos = pos + (r * np.cos(a))[:, None] * e1 + (r * np.sin(a))[:, None] * e2
        v = pos - p
        dist = np.linalg.norm(v, axis=1)
        wi = v / dist[:, None]
        scale = 1.0 / dist ** 2
        if self.radius > 0:
            scale = scale * np.maximum(-(wi @ axis), 0.0)
        E = scale[:, None] * np.broadcast_to(np.asarray(self.intensity, float), (3,))
        return wi, dist, E


@dataclass(frozen=True)
class DirectionalLight:
    """A distant light: every point receives irradiance ``irradiance`` (W/m^2, RGB) on a
    plane normal to ``direction``, the unit vector pointing TOWARD the light."""

    direction: tuple = (0.0, 0.0, 1.0)
    irradiance: object = 1.0

    def sample(self, p, rng):
        """Unit direction to the light, distance (inf) and irradiance (m, 3)."""
        m = len(p)
        wi = np.broadcast_to(_unit(self.direction), (m, 3))
        E = np.broadcast_to(np.asarray(self.irradiance, float), (3,))
        return wi, np.full(m, _INF), np.broadcast_to(E, (m, 3))


#: The light types a scene may hold.
LIGHTS = (PointLight, DirectionalLight)
