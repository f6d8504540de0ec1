"""Small analytic BRDFs with the brdf contract's surface, for the reports tests.

``Phongish`` is an anisotropic, colourful, deliberately non-reciprocal analytic BRDF with
``.eval``, ``.replace(masking=...)``, ``.threads`` and ``.options``; ``Lambert`` is constant.
"""

from __future__ import annotations

import dataclasses

import numpy as np


@dataclasses.dataclass(frozen=True)
class StandinThread:
    albedo: tuple = (0.6, 0.3, 0.1)
    area: float = 0.5
    eta: float = 1.46
    kd: float = 0.3
    gamma_s: float = 10.0
    gamma_v: float = 20.0
    offsets: tuple = (-25.0, 25.0)
    lengths: tuple = (1.0,)

    def replace(self, **changes):
        return dataclasses.replace(self, **changes)


class Lambert:
    """f_r = A / pi above the horizon."""

    def __init__(self, albedo=(0.5, 0.4, 0.3)):
        self.albedo = np.asarray(albedo, dtype=float)
        self.threads = (StandinThread(albedo=tuple(albedo), area=1.0),)

    def eval(self, wi, wo):
        wi = np.asarray(wi, float)
        wo = np.asarray(wo, float)
        up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
        return np.where(up[..., None], self.albedo / np.pi, 0.0)


class Phongish:
    """Diffuse + anisotropic Gaussian lobe about the mirror direction, with a toggle.

    f = A/pi + k exp(-(hx^2/ax^2 + hy^2/ay^2)) * m, m = (n.wi) (masking on) or 1,
    times (1 + 0.3 wi_x) so that f(wi, wo) != f(wo, wi).
    """

    def __init__(self, masking=True, ax=0.15, ay=0.4, k=2.0, albedo=(0.6, 0.3, 0.1)):
        self.masking = bool(masking)
        self.ax, self.ay, self.k = ax, ay, k
        self.albedo = np.asarray(albedo, float)
        self.threads = (StandinThread(albedo=tuple(albedo), area=0.5),
                        StandinThread(albedo=(0.2, 0.2, 0.6), area=0.5))
        self.options = {"masking": self.masking}

    def replace(self, masking=None):
        return Phongish(self.masking if masking is None else masking, self.ax, self.ay,
                        self.k, tuple(self.albedo))

    def eval(self, wi, wo):
        wi = np.asarray(wi, float)
        wo = np.asarray(wo, float)
        h = wi + wo
        h = h / np.linalg.norm(h, axis=-1, keepdims=True).clip(1e-12)
        spec = self.k * np.exp(-(h[..., 0] ** 2 / self.ax ** 2 + h[..., 1] ** 2 / self.ay ** 2))
        if self.masking:
            spec = spec * np.clip(wi[..., 2], 0, 1) * np.clip(wo[..., 2], 0, 1)
        spec = spec * (1.0 + 0.3 * wi[..., 0])
        f = self.albedo / np.pi + spec[..., None] * np.array([1.0, 1.0, 1.0])
        up = (wi[..., 2] > 0) & (wo[..., 2] > 0)
        return np.where(up[..., None], f, 0.0)
