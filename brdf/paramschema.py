r"""A model's parameters as one flat vector of named scalars: what a fit samples.

Every registered model (:data:`brdf.MODELS`) describes its parameters the same way, whatever
its own structure (a fabric's two threads, a baseline's rows): a :class:`ParamSchema` of
:class:`FlatParam` entries, each one number with its unit, search range (the row's typical
range), prior shape (log-uniform where the range spans decades), default and plausible range.
A colour (an RGB row of :mod:`brdf.schema`) becomes three entries ``<group>_r``, ``_g``,
``_b`` sharing a :attr:`FlatParam.group`, the alias that names the three.

Examples
--------
>>> from brdf.schema import THREAD
>>> s = ParamSchema.from_rows([THREAD["kd"], THREAD["albedo"]], suffix="1")
>>> s.names, s.aliases
(('kd1', 'albedo1_r', 'albedo1_g', 'albedo1_b'), {'albedo1': ('albedo1_r', 'albedo1_g', 'albedo1_b')})
>>> s["albedo1_g"].entry
(0.0, 1.0, 'uniform', '1', 0.2)
"""

from __future__ import annotations

import dataclasses
from typing import Iterable, Iterator, Mapping

import numpy as np

from brdf.schema import RGB_CHANNELS, ParamInfo

__all__ = ["FlatParam", "ParamSchema", "PRIORS"]

#: The prior shapes a parameter may take: flat in the value, or in its logarithm.
PRIORS = ("uniform", "log-uniform")


@dataclasses.dataclass(frozen=True)
class FlatParam:
    """One scalar parameter of a model's flat vector.

    Attributes
    ----------
    name : str
        The fit's name (``gamma_s1``, ``base_g``, ``roughness``).
    info : ParamInfo
        The row it comes from (meaning, heading, validated range).
    lo, hi : float
        The search range, natural units (the row's typical range).
    prior : {"uniform", "log-uniform"}
    unit : str
        ``"1"``, ``"deg"``, ... (the row's).
    default : float
        The fallback start value (the row's typical value; a colour's own channel).
    plausible : (float, float) or None
        The range real cloth takes (a fitted value outside it is implausible), or None.
    group : str or None
        For a colour channel, the alias naming its three channels (``albedo1``, ``base``).
    channel : int or None
        The channel (0, 1, 2 for R, G, B) of a colour channel.
    """

    name: str
    info: ParamInfo
    lo: float
    hi: float
    prior: str
    unit: str
    default: float
    plausible: tuple[float, float] | None = None
    group: str | None = None
    channel: int | None = None

    @property
    def entry(self) -> tuple[float, float, str, str, float]:
        """(lo, hi, prior, unit, default): what a fit's parameter spec takes."""
        return (self.lo, self.hi, self.prior, self.unit, self.default)

    @classmethod
    def of(cls, info: ParamInfo, name: str | None = None, channel: int | None = None,
           group: str | None = None, plausible_fallback: bool = False) -> "FlatParam":
        """The entry of row ``info`` (its ``channel`` of a colour), named ``name``.

        ``plausible_fallback``: take the row's typical range where it gives no plausible one.
        """
        lo, hi = info.typical
        default = info.typical_value
        if np.ndim(default):
            default = default[channel or 0]
        plausible = info.plausible or (info.typical if plausible_fallback else None)
        return cls(name or info.name, info, float(lo), float(hi),
                   "log-uniform" if info.log_scale else "uniform", info.unit, float(default),
                   plausible, group, channel)


@dataclasses.dataclass(frozen=True)
class ParamSchema:
    """A model's flat parameter vector, in order (see the module notes).

    Attributes
    ----------
    params : tuple of FlatParam
    """

    params: tuple[FlatParam, ...]

    @classmethod
    def from_rows(cls, rows: Iterable[ParamInfo], suffix: str = "",
                  plausible_fallback: bool = False) -> "ParamSchema":
        """Scalar rows by name (``+ suffix``), RGB rows per channel ``<name><suffix>_r`` ..."""
        out = []
        for info in rows:
            if info.kind == "rgb":
                group = f"{info.name}{suffix}"
                out += [FlatParam.of(info, f"{group}_{c}", k, group, plausible_fallback)
                        for k, c in enumerate(RGB_CHANNELS)]
            elif info.kind == "scalar":
                out.append(FlatParam.of(info, f"{info.name}{suffix}",
                                        plausible_fallback=plausible_fallback))
            else:
                raise ValueError(f"{info.name}: a {info.kind} parameter has no flat form")
        return cls(tuple(out))

    def __add__(self, other: "ParamSchema") -> "ParamSchema":
        return ParamSchema(self.params + other.params)

    def __iter__(self) -> Iterator[FlatParam]:
        return iter(self.params)

    def __len__(self) -> int:
        return len(self.params)

    def __contains__(self, name) -> bool:
        return name in self.names

    def __getitem__(self, name: str) -> FlatParam:
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def names(self) -> tuple[str, ...]:
        """Every name, in order."""
        return tuple(p.name for p in self.params)

    @property
    def aliases(self) -> dict[str, tuple[str, ...]]:
        """Each colour's alias and its three channels' names."""
        out: dict[str, tuple[str, ...]] = {}
        for p in self.params:
            if p.group is not None:
                out[p.group] = out.get(p.group, ()) + (p.name,)
        return out

    @property
    def colours(self) -> tuple[str, ...]:
        """The colour aliases, in order."""
        return tuple(self.aliases)

    def grouped(self, values: Mapping[str, object], combine=None) -> dict[str, object]:
        """Values by flat name -> by row: a colour's three channels joined by ``combine``
        (a function of their list; default stacked on a new last axis), a scalar as it is.
        Missing names are left out.

        Examples
        --------
        >>> from brdf.schema import THREAD
        >>> s = ParamSchema.from_rows([THREAD["kd"], THREAD["albedo"]])
        >>> s.grouped({"kd": 0.5, "albedo_r": 0.1, "albedo_g": 0.2, "albedo_b": 0.3}, tuple)
        {'kd': 0.5, 'albedo': (0.1, 0.2, 0.3)}
        """
        join = combine or (lambda xs: np.stack(xs, axis=-1))
        out: dict[str, object] = {}
        for group, names in self.aliases.items():
            if all(n in values for n in names):
                out[group] = join([values[n] for n in names])
        for p in self.params:
            if p.group is None and p.name in values:
                out[p.name] = values[p.name]
        order = {p.group or p.name: i for i, p in reversed(list(enumerate(self.params)))}
        return dict(sorted(out.items(), key=lambda kv: order[kv[0]]))
