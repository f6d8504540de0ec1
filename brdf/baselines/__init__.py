"""The cloth models renderers use, beside the microcylinder fabric: baselines to compare with.

Each is a :class:`~brdf.baselines.model.BaselineModel`: validated parameters with units and
ranges (``PARAMS``), ``eval(wi, wo)`` (RGB f_r in 1/sr, no cosine), a batched
``prepare(wi, wo).eval(**params)`` for fits, ``sample`` and ``pdf``. :data:`MODELS` maps each
model's name to its class.

Examples
--------
>>> sorted(MODELS)[:1], model_class("lambert").__name__
(['lambert'], 'Lambert')
"""

from __future__ import annotations

from brdf.baselines.lambert import BASE, Lambert
from brdf.baselines.model import BaselineModel, PreparedBaseline

__all__ = ["BaselineModel", "PreparedBaseline", "Lambert", "MODELS", "model_class", "BASE"]

#: The baseline models by name.
MODELS: dict[str, type[BaselineModel]] = {cls.name: cls for cls in (Lambert,)}


def model_class(name: str) -> type[BaselineModel]:
    """The baseline model class named ``name``; ValueError listing the names otherwise."""
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown model {name!r}; baseline models: "
                         f"{', '.join(MODELS)}") from None
