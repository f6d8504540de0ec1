"""Cameras of the renderer's scenes: pinhole and orthographic (world +y up, scene units)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reports.render.vec3 import basis as _basis
from reports.render.vec3 import unit as _unit

__all__ = ["PinholeCamera", "OrthographicCamera"]


@dataclass(frozen=True)
class PinholeCamera:
    """A pinhole camera at ``position`` looking at ``target``; ``fov`` vertical, degrees."""

    position: tuple = (0.0, 0.0, 4.0)
    target: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    fov: float = 40.0

    def rays(self, sx, sy, width, height):
        """Origins and unit directions, each (m, 3), through image points ``(sx, sy)``.

        ``sx`` in [0, width) from the left, ``sy`` in [0, height) from the top, in pixels.
        """
        f, r, u = _basis(self.position, self.target, self.up)
        th = np.tan(np.radians(self.fov) / 2)
        px = (2 * sx / width - 1) * th * width / height
        py = (1 - 2 * sy / height) * th
        d = _unit(f + px[:, None] * r + py[:, None] * u)
        return np.broadcast_to(np.asarray(self.position, float), d.shape), d


@dataclass(frozen=True)
class OrthographicCamera:
    """An orthographic camera looking along ``target - position``; ``extent`` is the
    height of the view in scene units (the width follows the image aspect)."""

    position: tuple = (0.0, 0.0, 4.0)
    target: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    extent: float = 2.0

    def rays(self, sx, sy, width, height):
        """Origins on the image plane and the common direction, each (m, 3)."""
        f, r, u = _basis(self.position, self.target, self.up)
        px = (sx / width - 0.5) * self.extent * width / height
        py = (0.5 - sy / height) * self.extent
        o = np.asarray(self.position, float) + px[:, None] * r + py[:, None] * u
        return o, np.broadcast_to(f, o.shape)
