"""The cloth models renderers use, beside the microcylinder fabric: baselines to compare with.

Each is a :class:`~brdf.baselines.model.BaselineModel`: validated parameters with units and
ranges (``PARAMS``), ``eval(wi, wo)`` (RGB f_r in 1/sr, no cosine), a batched
``prepare(wi, wo).eval(**params)`` for fits, ``sample`` and ``pdf``, and the rest of the
model protocol (:class:`brdf.Model`). Each is registered by name in :data:`brdf.MODELS`.

Examples
--------
>>> Zeltner.name, Zeltner.param_schema().names[:3]
('zeltner', ('base_r', 'base_g', 'base_b'))
"""

from __future__ import annotations

from brdf.baselines.ashikhmin import Ashikhmin
from brdf.baselines.charlie import Charlie
from brdf.baselines.lambert import BASE, Lambert
from brdf.baselines.model import BaselineModel, PreparedBaseline
from brdf.baselines.sheen import SHEEN, SheenModel
from brdf.baselines.zeltner import Zeltner

__all__ = ["BaselineModel", "PreparedBaseline", "SheenModel", "Lambert", "Charlie", "Ashikhmin",
           "Zeltner", "BASE", "SHEEN"]
