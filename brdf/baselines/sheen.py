r"""What the sheen models share: a sheen lobe over the Lambertian base.

Every sheen model is

    f_r(wi, wo) = sheen * s(wi, wo; r) + L(wi, wo; r, sheen) * base / pi        (1/sr)

with ``sheen`` and ``base`` RGB colours in [0, 1], ``r`` the model's roughness, s the colourless
sheen lobe (:meth:`SheenModel.lobe`) and L the layering factor that scales the base
(:meth:`SheenModel.layer`; 1 for a plain sum). A subclass sets its roughness
(:class:`~brdf.schema.ParamInfo`) and writes the two.

:func:`hemisphere_rule` is the quadrature over the hemisphere of incident directions that the
tabulated albedos, the documentation's numbers and the tests' energy checks use: Gauss-Legendre
in t with cos(theta_i) = t^2 (nodes crowd toward grazing, where the sheen lobes live) times
Gauss-Legendre in the azimuth over [0, pi] (the lobes are symmetric about the plane of wo).

Examples
--------
>>> wi, w = hemisphere_rule(0.6, n_mu=32, n_phi=32)
>>> float(np.sum(w * wi[:, 2]) / np.pi).__round__(12)      # Lambert: albedo 1
1.0
"""

from __future__ import annotations

import math

import numpy as np

from brdf.baselines.lambert import BASE
from brdf.baselines.model import BaselineModel
from brdf.schema import ParamInfo

__all__ = ["SHEEN", "SheenModel", "hemisphere_rule", "lobe_albedo"]

#: The sheen lobe's RGB colour, shared by every sheen model.
SHEEN = ParamInfo("sheen", "rgb", "1", 0.0, 1.0, "sheen", "colour of the sheen lobe (R, G, B), "
                  "multiplying its colourless lobe", typical=(0.0, 1.0), typical_value=0.5,
                  what="one or three numbers in [0, 1] (R, G, B)")


def hemisphere_rule(cos_o: float, n_mu: int = 128, n_phi: int = 128):
    """Incident directions and solid-angle weights over the upper hemisphere for the viewer
    wo = (sin theta_o, 0, cos theta_o).

    Covers the azimuth half [0, pi] with doubled weights (the models are symmetric about the
    plane of wo). Returns ``(wi (m, 3), w (m,))`` with sum(w g(wi)) ~ integral of g over the
    hemisphere (sr) for g symmetric in the azimuth; ``wo`` is implied by ``cos_o``.
    """
    x, wx = np.polynomial.legendre.leggauss(n_mu)
    t = 0.5 * (x + 1.0)
    mu, wmu = t * t, wx * t                          # d(mu) = 2 t dt, dt = dx / 2
    y, wy = np.polynomial.legendre.leggauss(n_phi)
    ph, wph = 0.5 * math.pi * (y + 1.0), 0.5 * math.pi * wy
    M, P = np.meshgrid(mu, ph, indexing="ij")
    s = np.sqrt(np.maximum(0.0, 1.0 - M * M))
    wi = np.stack([s * np.cos(P), s * np.sin(P), M], axis=-1).reshape(-1, 3)
    return wi, (2.0 * np.outer(wmu, wph)).ravel()


def _wo(cos_o: float) -> np.ndarray:
    return np.array([math.sqrt(max(0.0, 1.0 - cos_o * cos_o)), 0.0, cos_o])


def lobe_albedo(model: type["SheenModel"], cos_o, roughness, n_mu: int = 128,
                n_phi: int = 128) -> np.ndarray:
    """Directional albedo of a model's colourless sheen lobe (sheen colour 1):
    E(theta_o) = integral of s(wi, wo) cos(theta_i) dwi, by :func:`hemisphere_rule`.

    ``cos_o`` (k,) and ``roughness`` (j,) give an array (k, j).
    """
    cos_o = np.atleast_1d(np.asarray(cos_o, dtype=np.float64))
    r = np.atleast_1d(np.asarray(roughness, dtype=np.float64))
    out = np.empty((cos_o.size, r.size))
    for k, c in enumerate(cos_o):
        wi, w = hemisphere_rule(float(c), n_mu, n_phi)
        geom = model.geometry(wi, np.broadcast_to(_wo(float(c)), wi.shape))
        out[k] = model.lobe(geom, r[:, None]) @ (w * wi[:, 2])
    return out


class SheenModel(BaselineModel):
    """A colourless sheen lobe times ``sheen`` over a Lambertian ``base`` (module notes).

    Subclasses set :attr:`ROUGHNESS` (their roughness's ParamInfo, with the source's range)
    and implement :meth:`geometry`, :meth:`lobe` and :meth:`layer`.
    """

    ROUGHNESS: ParamInfo
    SHEEN_PARAM = "sheen"

    def __init_subclass__(cls, **kw):
        super().__init_subclass__(**kw)
        if hasattr(cls, "ROUGHNESS"):
            cls.PARAMS = (BASE, SHEEN, cls.ROUGHNESS)

    @classmethod
    def lobe(cls, geom, roughness: np.ndarray) -> np.ndarray:
        """The colourless sheen lobe s (B..., n) in 1/sr for roughness (B..., 1)."""
        raise NotImplementedError

    @classmethod
    def layer(cls, geom, roughness: np.ndarray, sheen: np.ndarray) -> np.ndarray:
        """The factor L (B..., n) scaling the base, for roughness (B..., 1), sheen (B..., 3)."""
        raise NotImplementedError

    @classmethod
    def shade(cls, geom, base, sheen, roughness):
        r = np.asarray(roughness)[..., None]
        s = cls.lobe(geom, r)
        lay = cls.layer(geom, r, sheen)
        return (sheen[..., None, :] * s[..., None]
                + np.asarray(lay)[..., None] * base[..., None, :] / math.pi)
