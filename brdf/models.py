"""The registry of models: every model microcyl fits, compares, reports and exports, by name.

:data:`MODELS` maps a name to a class satisfying :class:`brdf.Model` (the microcylinder,
:class:`brdf.Fabric`, first, then the baselines of :mod:`brdf.baselines`). Everything above
brdf reads a model through this registry and the protocol: adding a model is its module and
its line here.

Examples
--------
>>> list(MODELS)
['microcylinder', 'lambert', 'charlie', 'ashikhmin', 'zeltner']
>>> model_class("lambert").__name__, model_name(MODELS["microcylinder"].start())
('Lambert', 'microcylinder')
>>> model_class("phong")
Traceback (most recent call last):
    ...
ValueError: unknown model 'phong'; models: microcylinder, lambert, charlie, ashikhmin, zeltner
"""

from __future__ import annotations

from brdf.baselines import Ashikhmin, Charlie, Lambert, Zeltner
from brdf.fabric import Fabric

__all__ = ["MODELS", "DEFAULT_MODEL", "model_class", "model_name", "model_names"]

#: The models by name (the first is the default of ``microcyl fit --model``).
MODELS: dict[str, type] = {
    "microcylinder": Fabric,
    "lambert": Lambert,
    "charlie": Charlie,
    "ashikhmin": Ashikhmin,
    "zeltner": Zeltner,
}
#: The model fitted when none is named.
DEFAULT_MODEL = "microcylinder"


def model_names() -> tuple[str, ...]:
    """Every registered model's name, in the registry's order."""
    return tuple(MODELS)


def model_class(name: str) -> type:
    """The model class named ``name``; ValueError listing the names otherwise."""
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown model {name!r}; models: {', '.join(MODELS)}") from None


def model_name(obj) -> str:
    """The registry's name of a model object (an instance of a registered class).

    Raises
    ------
    ValueError
        An object of no registered class.
    """
    for name, cls in MODELS.items():
        if type(obj) is cls:
            return name
    for name, cls in MODELS.items():
        if isinstance(obj, cls):
            return name
    raise ValueError(f"not a registered model: {type(obj).__name__} (models: "
                     f"{', '.join(MODELS)})")
