"""The cloth models renderers use, beside the microcylinder fabric: baselines to compare with.

Each is a :class:`~brdf.baselines.model.BaselineModel`: validated parameters with units and
ranges (``PARAMS``), ``eval(wi, wo)`` (RGB f_r in 1/sr, no cosine), a batched
``prepare(wi, wo).eval(**params)`` for fits, ``sample`` and ``pdf``. :data:`MODELS` maps each
model's name to its class.

Examples
--------
>>> list(MODELS), model_class("zeltner").__name__
(['lambert', 'charlie', 'ashikhmin', 'zeltner'], 'Zeltner')
"""

from __future__ import annotations

from brdf.baselines.ashikhmin import Ashikhmin
from brdf.baselines.charlie import Charlie
from brdf.baselines.lambert import BASE, Lambert
from brdf.baselines.model import BaselineModel, PreparedBaseline
from brdf.baselines.sheen import SHEEN, SheenModel
from brdf.baselines.zeltner import Zeltner

__all__ = ["BaselineModel", "PreparedBaseline", "SheenModel", "Lambert", "Charlie", "Ashikhmin",
           "Zeltner", "MODELS", "model_class", "BASE", "SHEEN"]

#: The baseline models by name.
MODELS: dict[str, type[BaselineModel]] = {cls.name: cls for cls in (Lambert, Charlie,
                                                                     Ashikhmin, Zeltner)}


def model_class(name: str) -> type[BaselineModel]:
    """The baseline model class named ``name``; ValueError listing the names otherwise."""
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown model {name!r}; baseline models: "
                         f"{', '.join(MODELS)}") from None
