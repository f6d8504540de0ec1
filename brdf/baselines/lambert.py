r"""The Lambertian model: f_r = rho / pi, rho the RGB albedo ``base``.

The simplest model a fit can compare against (and the base under every sheen model).

Examples
--------
>>> import numpy as np
>>> m = Lambert(base=(0.2, 0.5, 0.8))
>>> wi = np.array([0.0, 0.0, 1.0]); wo = np.array([0.6, 0.0, 0.8])
>>> np.allclose(m.eval(wi, wo) * np.pi, [0.2, 0.5, 0.8])
True
>>> m.prepare(wi[None], wo[None]).eval(base=np.full((4, 3), 0.5)).shape
(4, 1, 3)
"""

from __future__ import annotations

import math

import numpy as np

from brdf.baselines.model import BaselineModel
from brdf.schema import ParamInfo

__all__ = ["Lambert", "BASE"]

#: The Lambertian base's albedo, shared by every model with a base.
BASE = ParamInfo("base", "rgb", "1", 0.0, 1.0, "ρ_base", "albedo of the Lambertian base "
                 "(R, G, B): f_r = ρ / π", typical=(0.0, 1.0), typical_value=0.5,
                 what="one or three numbers in [0, 1] (R, G, B)")


class Lambert(BaselineModel):
    """f_r = base / pi (1/sr) for every pair above the horizon; see the module notes."""

    name = "lambert"
    PARAMS = (BASE,)
    reciprocal = True

    @classmethod
    def geometry(cls, wi, wo):
        return {"n": np.zeros(wi.shape[0])}

    @classmethod
    def shade(cls, geom, base):
        n = geom["n"].shape[0]
        return np.broadcast_to(base[..., None, :] / math.pi, base.shape[:-1] + (n, 3)).copy()
