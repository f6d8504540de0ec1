"""The models the explorer shows, behind one small adapter: each model's sliders (name,
range, step, unit), its variant switches, its presets and how its values become a BRDF.

Built on :mod:`analysis.families` (the microcylinder's parameter names of
:mod:`analysis.paramnames`, from :mod:`brdf.schema`; each baseline of
:data:`brdf.baselines.MODELS` from its ``PARAMS``). When one registry ``brdf.MODELS`` lands,
:func:`model_names` and :func:`explore_model` are the only places to change.

Examples
--------
>>> m = explore_model("microcylinder")
>>> [s.name for s in m.sliders][:3], m.is_microcylinder
(['eta1', 'kd1', 'gamma_s1'], True)
>>> v = m.values_of(m.start("velvet"))
>>> round(v["gamma_s1"], 3) > 0, explore_model("lambert").variants
(True, {})
"""

from __future__ import annotations

import dataclasses
import math
from typing import Mapping

import numpy as np

from analysis.families import MICROCYLINDER, family
from analysis.families import model_names as _family_names
from brdf import PRESETS, schema
from brdf.fabric import Fabric
from brdf.options import GAP_METHODS, OPTIONS, SAMPLING_METHODS, TRANSMISSION_METHODS

__all__ = ["Slider", "ExploreModel", "explore_model", "model_names", "VARIANTS"]

#: The microcylinder's variant switches: option name -> its choices (first the default).
VARIANTS = {"masking": (True, False), "reweighting": (True, False),
            "transmission": TRANSMISSION_METHODS, "gap": GAP_METHODS,
            "tangent_sampling": SAMPLING_METHODS}


@dataclasses.dataclass(frozen=True)
class Slider:
    """One parameter's slider: ``name`` (the fit's name, e.g. ``gamma_s1``), range ``lo`` ..
    ``hi`` and ``step`` in ``unit`` (``deg`` for angles), and its ``default``."""

    name: str
    lo: float
    hi: float
    step: float
    unit: str
    default: float

    def clip(self, value) -> float:
        """``value`` as a float inside [lo, hi]; a ValueError when it is not a finite number.

        >>> Slider("kd1", 0.0, 1.0, 0.01, "1", 0.3).clip(7)
        1.0
        """
        v = float(value)
        if not math.isfinite(v):
            raise ValueError(f"{self.name} must be a finite number; got {value!r}")
        return min(max(v, self.lo), self.hi)


def _step(lo: float, hi: float) -> float:
    """A round step of about 1/200 of the range."""
    raw = (hi - lo) / 200.0
    return float(10.0 ** math.floor(math.log10(raw))) if raw > 0 else 1.0


def model_names() -> tuple[str, ...]:
    """The models to pick from: ``microcylinder`` then each baseline."""
    return _family_names()


@dataclasses.dataclass(frozen=True)
class ExploreModel:
    """One model as the explorer sees it (:func:`explore_model`)."""

    name: str
    sliders: tuple
    variants: Mapping
    presets: tuple

    @property
    def is_microcylinder(self) -> bool:
        return self.name == MICROCYLINDER

    def start(self, preset: str | None = None):
        """The model object of a preset (microcylinder) or the model's defaults."""
        return family(self.name).start(preset if self.is_microcylinder else None)

    def values_of(self, obj) -> dict:
        """Every slider's value in a model object (natural units), clipped to its range."""
        got = family(self.name).defaults(obj)
        return {s.name: s.clip(got.get(s.name, s.default)) for s in self.sliders}

    def build(self, values: Mapping, base=None, options: Mapping | None = None):
        """The BRDF at ``values`` (every slider by name): a :class:`brdf.Fabric` from
        ``base``'s tangent curves and ``options``, or a baseline model.

        Raises
        ------
        ValueError
            A value the model refuses (the message names it).
        """
        fam = family(self.name)
        if not self.is_microcylinder:
            return fam.build(values)
        base = base if isinstance(base, Fabric) else fam.start()
        kw = fam.model_kwargs({k: np.asarray(v, float) for k, v in values.items()})
        threads = []
        for j, th in enumerate(base.threads):
            change = {q: float(kw[q][j]) for q in schema.SCALAR_PARAMS}
            change["albedo"] = tuple(float(a) for a in kw["albedo"][j])
            threads.append(th.replace(**change))
        return base.replace(threads=tuple(threads), **dict(options or {}))


#: Parameters the app controls itself, not as a shading slider: the fabric's rotation (its
#: own control, which rebuilds the prepared frame) and the tangent scales (the base curves).
APP_CONTROLLED = ("rotation", "tangent_scale1", "tangent_scale2")


def _sliders(name: str) -> tuple:
    fam = family(name)
    out = []
    for n in fam.model_names:
        if n in APP_CONTROLLED:
            continue
        lo, hi, _prior, unit, default = fam.entry(n)
        out.append(Slider(n, float(lo), float(hi), _step(lo, hi), unit, float(default)))
    return tuple(out)


def explore_model(name: str = MICROCYLINDER) -> ExploreModel:
    """The :class:`ExploreModel` of ``name`` (:func:`model_names`); a ValueError otherwise."""
    if name not in model_names():
        raise ValueError(f"unknown model {name!r}; models: {', '.join(model_names())}")
    micro = name == MICROCYLINDER
    variants = {k: v for k, v in VARIANTS.items() if k in OPTIONS} if micro else {}
    # rotation (schema.FABRIC, an option of the fabric) is the app's own slider
    return ExploreModel(name, _sliders(name), variants, PRESETS if micro else ())
