r"""Model families: what a fit needs to know of a registered model (:data:`brdf.MODELS`).

A fit samples named scalar parameters (:class:`analysis.params.ParamSpec`); a *family* is one
registered model class read through the model protocol (:class:`brdf.Model`): its flat
parameters (``param_schema``: names, bounds, priors, units, fallback values, the colour
aliases), which are free by default and how they are tied, the model object a fit starts
from (``start``) and its values (``values``), and the keyword arguments of its batched
forward model (``batch_kwargs``). Nothing here knows one model from another.

Every family adds the fit's nuisance parameters ``scale`` (a factor on f_r for relative
tables, log-uniform on [1e-4, 1e4]) and ``log_noise`` (uniform on [-12, 3]).

**Identifiability** (:meth:`ModelFamily.default_free`): a model with a default free set of its
own (``DEFAULT_FREE``, the microcylinder's) takes it with its ties whatever the table. Any
other's default free set is every parameter, and depends on the table. On a grey table (the
same value in R, G and B everywhere: CUReT) the channels of a colour are not separately
informed, so ``X_g`` and ``X_b`` are tied to ``X_r`` for each colour X. On a relative table (a
free ``scale``) the overall level of f_r is the scale's: a model's f_r is linear in its colours
taken together (exactly for Lambert, nearly for the sheen models), so scale and colours would
make a ridge of equal likelihood. The scale is free, and the base colour (``BASE_PARAM``,
else the first colour) is tied to the model's next colour (a sheen) as a mix: ``base = 1 -
sheen`` (all three channels to ``sheen_r`` on a grey table, its red channel alone on an RGB
one), so that the sheen is the share w of the two and the ratio sheen/base = w/(1 - w) spans
0 to infinity with both colours inside [0, 1]. The bound w = 0 or 1 is then a pure base or a
pure sheen, not a box: fixing the base at its start 0.5 instead boxed the ratio in at 2, where
the sheen of CUReT's velvet sat at its bound (``zeltner``, elpd 474; 517 with the mix), and any
fixed base boxes a model whose data want no base at all (``ashikhmin`` there). A model with one
colour (Lambert) has its base fixed at its start value instead. Each choice is recorded
(:meth:`ModelFamily.default_free`'s notes, ``results.json``'s ``identifiability``).

Examples
--------
>>> lam = family("lambert")
>>> lam.names
('base_r', 'base_g', 'base_b', 'scale', 'log_noise')
>>> free, ties, notes = lam.default_free(grey=True, relative=True)
>>> free, ties
(('scale',), ())
>>> free, ties, notes = family("zeltner").default_free(grey=True, relative=True)
>>> free, ties[:3]
(('sheen_r', 'roughness', 'scale'), ('base_r=1-sheen_r', 'base_g=1-sheen_r', 'base_b=1-sheen_r'))
>>> family("microcylinder").default_free()[0][:2]
('eta1', 'kd1')
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from analysis import paramnames
from brdf.models import DEFAULT_MODEL, MODELS, model_class, model_name

__all__ = ["ModelFamily", "MICROCYLINDER", "family", "family_of", "model_names"]

#: The default model's name (``microcyl fit --model``'s default): the registry's.
MICROCYLINDER = DEFAULT_MODEL


def model_names() -> tuple[str, ...]:
    """Every model a fit may use: the names of :data:`brdf.MODELS`, in its order."""
    return tuple(MODELS)


class ModelFamily:
    """What a fit knows of one registered model class (see the module notes); a
    :class:`analysis.paramnames.Catalogue` (``names``, ``aliases``).

    Parameters
    ----------
    name : str
        The model's name in :data:`brdf.MODELS`.
    cls : type
        The model class (a :class:`brdf.Model`).
    """

    def __init__(self, name: str, cls: type):
        self.name = name
        self.cls = cls
        self.schema = cls.param_schema()
        #: The model's parameters (what ``batch_kwargs`` takes).
        self.model_names: tuple[str, ...] = self.schema.names
        #: Every parameter name: the model's, then the fit's own.
        self.names: tuple[str, ...] = self.model_names + tuple(paramnames.EXTRA_PARAMS)
        #: Each colour's alias and its channels (``albedo1``, ``base``).
        self.aliases: Mapping[str, tuple[str, ...]] = self.schema.aliases

    @property
    def is_default(self) -> bool:
        """Whether this is the default model (:data:`brdf.DEFAULT_MODEL`)."""
        return self.name == DEFAULT_MODEL

    @property
    def presets(self) -> tuple[str, ...]:
        """The presets the model starts from (``PRESETS``; none for most models)."""
        return tuple(self.cls.PRESETS)

    def check_preset(self, preset) -> str | None:
        """``preset`` when the model has presets and it names one; None for a model without.

        Raises
        ------
        ValueError
            An unknown preset (the message lists the valid ones).
        """
        if not self.presets:
            return None
        if not isinstance(preset, str) or preset not in self.presets:
            raise ValueError(f"unknown fabric {preset!r}; valid presets are "
                             f"{', '.join(self.presets)}")
        return preset

    def entry(self, name: str) -> paramnames.Entry:
        """(lo, hi, prior, unit, fallback default) of a parameter name."""
        if name in paramnames.EXTRA_PARAMS:
            return paramnames.EXTRA_PARAMS[name]
        return self.schema[name].entry

    def defaults(self, obj) -> dict[str, float]:
        """Every model parameter's value in the model object ``obj`` (natural units)."""
        return obj.values()

    def periods(self, obj) -> dict[str, float]:
        """The parameters of the model object ``obj`` that are angles repeating with a
        period (natural units): its ``periods()`` (a fabric's ``rotation``), or none."""
        get = getattr(obj, "periods", None)
        return dict(get()) if callable(get) else {}

    def model_kwargs(self, values: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The keyword arguments of the model's forward model from every parameter's
        natural values (arrays B...): the class's ``batch_kwargs``."""
        return self.cls.batch_kwargs(values)

    def start(self, preset: str | None = None, options: Mapping | None = None):
        """The model object a fit starts from (fixed values and the start point)."""
        return self.cls.start(preset, options)

    def build(self, values: Mapping[str, float], preset: str | None = None,
              options: Mapping | None = None):
        """The model at natural ``values`` (model parameters by name), from :meth:`start`."""
        return self.start(preset, options).with_values(
            {n: v for n, v in values.items() if n in self.schema})

    def plausible(self, name: str):
        """The range real cloth takes for ``name`` (``implausible`` warnings), or None."""
        return self.schema[name].plausible if name in self.schema else None

    @property
    def base_param(self) -> str | None:
        """The colour fixed on a relative table: ``BASE_PARAM``, else the first colour."""
        colours = self.schema.colours
        b = getattr(self.cls, "BASE_PARAM", None)
        return b if b in colours else (colours[0] if colours else None)

    def default_free(self, grey: bool = False, relative: bool = False):
        """``(free, ties, notes)``: the default free set and ties for a table (grey: one
        value in R, G and B; relative: a free scale), and a sentence per choice made for
        identifiability."""
        if self.cls.DEFAULT_FREE is not None:
            return tuple(self.cls.DEFAULT_FREE), tuple(self.cls.DEFAULT_TIES), ()
        free = list(self.model_names)
        ties, notes = [], []
        base = self.base_param if relative else None
        mix = next((q for q in self.schema.colours if q != base), None)
        if base is not None:
            fixed = list(self.aliases[base]) if grey else [f"{base}_r"]
            free = [n for n in free if n not in fixed]
            why = ("f_r is linear in the colours together, so scale and colours would form a "
                   "ridge")
            if mix is None:
                notes.append(f"relative table: {', '.join(fixed)} fixed at the start value "
                             f"and scale free ({why})")
            else:
                ties += [f"{n}=1-{mix}_r" for n in fixed]
                notes.append(f"relative table: {', '.join(fixed)} = 1 - {mix}_r and scale "
                             f"free ({why}; {mix}_r is the share of {mix} in {mix} + {base}, "
                             f"so their ratio is unbounded)")
        tied = [q for q in self.schema.colours if not (grey and q == base)] if grey else []
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

    def __repr__(self) -> str:
        return f"ModelFamily({self.name!r})"


_FAMILIES: dict[tuple[str, type], ModelFamily] = {}


def family(name: str | None = None) -> ModelFamily:
    """The family of the model named ``name`` (default :data:`brdf.DEFAULT_MODEL`).

    Raises
    ------
    ValueError
        An unknown name (the message lists the models).
    """
    name = DEFAULT_MODEL if name is None else name
    cls = model_class(name)
    key = (name, cls)
    if key not in _FAMILIES:
        _FAMILIES[key] = ModelFamily(name, cls)
    return _FAMILIES[key]


def family_of(obj) -> ModelFamily:
    """The family of a model object (an instance of a class of :data:`brdf.MODELS`)."""
    try:
        return family(model_name(obj))
    except ValueError:
        raise ValueError(f"not a model a fit knows: {type(obj).__name__} (an instance of a "
                         f"model of brdf.MODELS: {', '.join(MODELS)})") from None
