r"""Model families: what a fit needs to know of a model, for the microcylinder and each baseline.

A fit samples named scalar parameters (:class:`analysis.params.ParamSpec`); a *family* says
which names a model has, their bounds, priors, units and fallback values, which are free by
default and how they are tied, how a model object (a :class:`brdf.Fabric` or a
:class:`brdf.baselines.BaselineModel`) gives the start values, and how the sampled values
become the keyword arguments of the model's batched ``prepare(wi, wo).eval``.

- ``microcylinder``: the names of :mod:`analysis.paramnames` (per thread: ``eta1``, ``kd1``,
  ``gamma_s1``, ..., ``albedo1_r``; the fit's ``tangent_scale1/2``), default free set
  :data:`analysis.paramnames.DEFAULT_FREE` with its ties.
- each baseline model of :data:`brdf.baselines.MODELS` (``lambert``, and the sheen models as
  they are added): its ``PARAMS`` rows, a scalar one under its own name, an RGB one per
  channel (``base_r``, ``base_g``, ``base_b``; the alias ``base`` names the three). Bounds:
  the row's typical range; prior uniform in the value, or log-uniform where the row's
  ``log_scale`` says the range spans decades; fallback value the row's ``typical_value``.
  Default free set: every parameter.

Every family adds the fit's nuisance parameters ``scale`` (a factor on f_r for relative
tables, log-uniform on [1e-4, 1e4]) and ``log_noise`` (uniform on [-12, 3]).

**Identifiability** (:meth:`ModelFamily.default_free`): a baseline's default free set depends
on the table. On a grey table (the same value in R, G and B everywhere: CUReT) the channels of
a colour are not separately informed, so ``X_g`` and ``X_b`` are tied to ``X_r`` for each RGB
parameter X. On a relative table (a free ``scale``) the overall level of f_r is the scale's:
a model's f_r is linear in its colours taken together (exactly for Lambert, nearly for the
sheen models), so scale and colours would make a ridge of equal likelihood. The base colour is
then fixed at its start value (its red channel on an RGB table, all three on a grey one) and
the scale free: the other colours are fitted relative to the base. Each choice is recorded
(:meth:`ModelFamily.default_free`'s notes, ``results.json``'s ``identifiability``).

Examples
--------
>>> lam = family("lambert")
>>> lam.names
('base_r', 'base_g', 'base_b', 'scale', 'log_noise')
>>> free, ties, notes = lam.default_free(grey=True, relative=True)
>>> free, ties
(('scale',), ())
>>> family("microcylinder").default_free()[0][:2]
('eta1', 'kd1')
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from analysis import paramnames
from brdf import schema
from brdf.baselines import MODELS, BaselineModel, model_class
from brdf.fabric import Fabric
from brdf.presets import fabric as preset_fabric

__all__ = ["ModelFamily", "MicrocylinderFamily", "BaselineFamily", "MICROCYLINDER", "family",
           "family_of", "model_names", "CHANNELS"]

#: The microcylinder model's name (the default of ``microcyl fit --model``).
MICROCYLINDER = "microcylinder"
#: The channel suffixes of an RGB parameter.
CHANNELS = schema.RGB_CHANNELS


def model_names() -> tuple[str, ...]:
    """Every model a fit may use: ``microcylinder`` and the baselines of
    :data:`brdf.baselines.MODELS`, in that order."""
    return (MICROCYLINDER,) + tuple(MODELS)


class ModelFamily:
    """What a fit knows of one model (see the module notes); a
    :class:`analysis.paramnames.Catalogue` (``names``, ``aliases``)."""

    name: str = ""
    #: Every parameter name (model parameters, then the fit's own).
    names: tuple[str, ...] = ()
    #: The names the forward model takes (not ``scale``, ``log_noise``).
    model_names: tuple[str, ...] = ()
    aliases: Mapping[str, tuple[str, ...]] = {}

    @property
    def is_microcylinder(self) -> bool:
        return self.name == MICROCYLINDER

    def entry(self, name: str) -> paramnames.Entry:
        """(lo, hi, prior, unit, fallback default) of a parameter name."""
        raise NotImplementedError

    def defaults(self, obj) -> dict[str, float]:
        """Every model parameter's value in ``obj`` (natural units)."""
        raise NotImplementedError

    def model_kwargs(self, values: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The keyword arguments of the model's ``prepare(...).eval`` from every parameter's
        natural values (arrays B...)."""
        raise NotImplementedError

    def start(self, preset: str | None = None, options: Mapping | None = None):
        """The model object a fit starts from (fixed values and the start point)."""
        raise NotImplementedError

    def plausible(self, name: str):
        """The range real cloth takes for ``name`` (``implausible`` warnings), or None."""
        return None

    def default_free(self, grey: bool = False, relative: bool = False):
        """``(free, ties, notes)``: the default free set and ties for a table (grey: one
        value in R, G and B; relative: a free scale), and a sentence per choice made for
        identifiability."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"


class MicrocylinderFamily(ModelFamily):
    """The microcylinder fabric (:mod:`analysis.paramnames`' names)."""

    name = MICROCYLINDER
    names = paramnames.PARAM_NAMES
    model_names = paramnames.MODEL_PARAM_NAMES
    aliases = paramnames.ALIASES

    def entry(self, name):
        return paramnames.entry(name)

    def defaults(self, obj):
        return paramnames.defaults_from_fabric(obj)

    def model_kwargs(self, values):
        """Each scalar quantity (B..., 2), each RGB one (B..., 2, 3): both threads."""
        kw = {}
        for q in schema.SCALAR_PARAMS:
            kw[q] = np.stack([values[f"{q}1"], values[f"{q}2"]], axis=-1)
        for q in (p.name for p in schema.THREAD_PARAMS if p.kind == "rgb"):
            kw[q] = np.stack([np.stack([values[f"{q}{j}_{c}"] for c in CHANNELS], axis=-1)
                              for j in (1, 2)], axis=-2)
        return kw

    def start(self, preset=None, options=None):
        return preset_fabric(preset or "linen_plain", **dict(options or {}))

    def plausible(self, name):
        base, _ = paramnames.base_of(name)
        info = schema.THREAD.get(base) or schema.THREAD.get(base.rsplit("_", 1)[0])
        return None if info is None else (info.plausible or info.typical)

    def default_free(self, grey=False, relative=False):
        return paramnames.DEFAULT_FREE, paramnames.DEFAULT_TIES, ()


class BaselineFamily(ModelFamily):
    """A baseline model class of :mod:`brdf.baselines` (its ``PARAMS``)."""

    def __init__(self, cls: type[BaselineModel]):
        self.cls = cls
        self.name = cls.name
        self.info = {p.name: p for p in cls.PARAMS}
        self.rgb = tuple(p.name for p in cls.PARAMS if p.kind == "rgb")
        self.aliases = {q: tuple(f"{q}_{c}" for c in CHANNELS) for q in self.rgb}
        self.model_names = tuple(n for p in cls.PARAMS
                                 for n in self.aliases.get(p.name, (p.name,)))
        self.names = self.model_names + tuple(paramnames.EXTRA_PARAMS)
        self._owner = {n: q for q, group in self.aliases.items() for n in group}

    def entry(self, name):
        if name in paramnames.EXTRA_PARAMS:
            return paramnames.EXTRA_PARAMS[name]
        q = self._owner.get(name, name)
        info = self.info[q]
        lo, hi = info.typical
        prior = "log-uniform" if info.log_scale else "uniform"
        fallback = info.typical_value
        if np.ndim(fallback):
            fallback = fallback[CHANNELS.index(name.rsplit("_", 1)[1])]
        return float(lo), float(hi), prior, info.unit, float(fallback)

    def defaults(self, obj):
        out = {}
        for q, v in obj.params().items():
            if q in self.aliases:
                out.update({n: float(x) for n, x in zip(self.aliases[q], v)})
            else:
                out[q] = float(v)
        return out

    def model_kwargs(self, values):
        """Each scalar parameter (B...), each RGB one (B..., 3)."""
        return {q: (np.stack([values[n] for n in self.aliases[q]], axis=-1)
                    if q in self.aliases else values[q]) for q in self.info}

    def start(self, preset=None, options=None):
        if options:
            raise ValueError(f"model {self.name} takes no fabric option "
                             f"({', '.join(sorted(options))})")
        return self.cls()

    def build(self, values: Mapping[str, float]) -> BaselineModel:
        """The model at natural ``values`` (every model parameter by name)."""
        return self.cls(**{q: (tuple(float(values[n]) for n in self.aliases[q])
                               if q in self.aliases else float(values[q]))
                           for q in self.info})

    def plausible(self, name):
        info = self.info.get(self._owner.get(name, name))
        return None if info is None else info.plausible

    @property
    def base_param(self) -> str | None:
        """The RGB parameter fixed on a relative table: the Lambertian base
        (``BASE_PARAM``), else the first RGB parameter."""
        b = self.cls.BASE_PARAM
        return b if b in self.rgb else (self.rgb[0] if self.rgb else None)

    def default_free(self, grey=False, relative=False):
        free = list(self.model_names)
        ties, notes = [], []
        base = self.base_param if relative else None
        if base is not None:
            fixed = list(self.aliases[base]) if grey else [f"{base}_r"]
            free = [n for n in free if n not in fixed]
            notes.append(f"relative table: {', '.join(fixed)} fixed at the start value and "
                         f"scale free (f_r is linear in the colours together, so scale and "
                         f"colours would form a ridge; any other colour is fitted relative "
                         f"to {base})")
        tied = [q for q in self.rgb if not (grey and q == base)] if grey else []
        for q in tied:
            ties += [f"{q}_g={q}_r", f"{q}_b={q}_r"]
            free = [n for n in free if n not in (f"{q}_g", f"{q}_b")]
        if tied:
            notes.insert(0, "grey table: " + ", ".join(f"{q}_g and {q}_b tied to {q}_r"
                                                       for q in tied)
                         + " (the channels are not separately informed)")
        if relative:
            free.append("scale")
        return tuple(free), tuple(ties), tuple(notes)


_MICRO = MicrocylinderFamily()
_BASELINES: dict[type, BaselineFamily] = {}


def family(name: str | None = None) -> ModelFamily:
    """The family of the model named ``name`` (default ``microcylinder``).

    Raises
    ------
    ValueError
        An unknown name (the message lists the models).
    """
    if name is None or name == MICROCYLINDER:
        return _MICRO
    if not isinstance(name, str) or name not in MODELS:
        raise ValueError(f"unknown model {name!r}; models: {', '.join(model_names())}")
    cls = model_class(name)
    if cls not in _BASELINES:
        _BASELINES[cls] = BaselineFamily(cls)
    return _BASELINES[cls]


def family_of(obj) -> ModelFamily:
    """The family of a model object: a :class:`brdf.Fabric` (microcylinder) or a
    :class:`brdf.baselines.BaselineModel`."""
    if isinstance(obj, BaselineModel):
        return family(obj.name)
    if isinstance(obj, Fabric):
        return _MICRO
    raise ValueError(f"not a model a fit knows: {type(obj).__name__} (a brdf.Fabric or a "
                     f"brdf.baselines model)")
