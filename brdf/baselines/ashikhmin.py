r"""The Ashikhmin velvet sheen as Filament's cloth model has it, over a Lambertian base.

    a       = roughness^2                                   (Filament: alpha = perceptual^2)
    D(h)    = 1 / (pi (1 + 4 a^2)) * (1 + 4 exp(-cot^2(theta_h) / a^2) / sin^4(theta_h))
    V       = 1 / (4 (cos_i + cos_o - cos_i cos_o))
    f_r     = sheen * D * V + base / pi                     (1/sr; a plain sum)

D is Ashikhmin and Premoze's velvet distribution (Ashikhmin, Premoze and Shirley 2000; Ashikhmin
and Premoze 2007, "Distribution-based BRDFs") in the normalized form of Neubelt and Pettineo 2013
("Crafting a Next-Gen Material Pipeline for The Order: 1886"): integral D cos(theta_h) dh = 1.
V is Neubelt and Pettineo's smooth visibility. Both are Filament's documentation's cloth
specular BRDF (google/filament docs/Filament.md.html, "Cloth model": D_velvet, equation
clothSpecularBRDF, listing D_Ashikhmin with sin^2 clamped at 2^-7 for fp16, which this float64
code does not need). Filament layers its cloth as a plain sum f = Fd + Fr with the diffuse not
scaled by the sheen (shaders/src/surface_shading_model_cloth.fs at 4c8b73e5: ``color = Fd +
Fr``; its docs: "we've opted to leave out the 1 - F(v, h) term in the diffuse component"), so
the base is not reduced here either: the sum can reflect more than it receives (docs/guide/
baselines.rst gives the measured albedos). Filament's shipped cloth shader has since replaced D
by the Charlie distribution (keeping this V); this model keeps the documented velvet D.

Reciprocal: D depends on h, V is symmetric in cos_i and cos_o.

Examples
--------
>>> import numpy as np
>>> m = Ashikhmin(base=0.0, sheen=1.0, roughness=0.5)
>>> wi = np.array([0.0, 0.0, 1.0]); wo = np.array([0.0, 0.0, 1.0])
>>> a = 0.25   # at normal incidence theta_h = 0: D = 1 / (pi (1 + 4 a^2)), V = 1 / 4
>>> bool(np.allclose(m.eval(wi, wo), 1 / (np.pi * (1 + 4 * a * a)) / 4))
True
"""

from __future__ import annotations

import math

import numpy as np

from brdf.baselines.sheen import SheenModel
from brdf.schema import ParamInfo

__all__ = ["Ashikhmin", "ROUGHNESS_ASHIKHMIN", "velvet_d", "neubelt_v"]

#: Filament's perceptual roughness (a = roughness^2); its lower clamp MIN_PERCEPTUAL_ROUGHNESS.
ROUGHNESS_ASHIKHMIN = ParamInfo(
    "roughness", "scalar", "1", 0.045, 1.0, "r", "sheen roughness (Filament's perceptual "
    "roughness; the velvet width a = r^2)", typical=(0.2, 1.0), typical_value=0.6,
    note="lower bound: Filament's MIN_PERCEPTUAL_ROUGHNESS (0.045; 0.089 on mobile)")


def velvet_d(cos_h, a):
    """Neubelt and Pettineo's normalized velvet distribution D(theta_h) (1/sr) for the width
    ``a`` (Filament's alpha = roughness^2); broadcasts."""
    c2 = np.asarray(cos_h) ** 2
    s2 = np.maximum(1.0 - c2, 1e-300)
    a2 = np.asarray(a) ** 2
    with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
        e = np.exp(-c2 / (a2 * s2))
        peak = np.where(e > 0.0, 4.0 * e / (s2 * s2), 0.0)     # -> 0 as theta_h -> 0
    return (1.0 + peak) / (math.pi * (1.0 + 4.0 * a2))


def neubelt_v(cos_i, cos_o):
    """Neubelt and Pettineo's visibility 1 / (4 (cos_i + cos_o - cos_i cos_o))."""
    return 1.0 / (4.0 * (cos_i + cos_o - cos_i * cos_o))


class Ashikhmin(SheenModel):
    """Ashikhmin velvet sheen (Filament's cloth, documented form) plus a Lambertian base; see
    the module notes. Parameters: ``base`` and ``sheen`` (RGB in [0, 1]), ``roughness``."""

    name = "ashikhmin"
    ROUGHNESS = ROUGHNESS_ASHIKHMIN
    reciprocal = True

    @classmethod
    def geometry(cls, wi, wo):
        h = wi + wo
        cos_h = h[:, 2] / np.linalg.norm(h, axis=-1)
        return {"cos_h": cos_h, "v": neubelt_v(wi[:, 2], wo[:, 2])}

    @classmethod
    def lobe(cls, geom, roughness):
        return velvet_d(geom["cos_h"], roughness * roughness) * geom["v"]

    @classmethod
    def layer(cls, geom, roughness, sheen):
        return np.ones(np.broadcast_shapes(np.shape(roughness)[:-1] + (1,),
                                           geom["cos_h"].shape))
