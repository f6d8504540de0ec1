"""The parsing of a fit's parameter names (``--free`` and ``--tie`` strings, TOML spec files)
against a model's catalogue, and the fit's own parameters.

A model's parameter names are its flat parameters (:class:`brdf.ParamSchema`, from the model
protocol; :class:`analysis.families.ModelFamily`). The microcylinder's
(:mod:`brdf.microcylinder`: ``eta1``, ``kd1``, ``gamma_s1``, ``gamma_v1``, ``area1``,
``albedo1_r``, ... and the same with ``2``, then ``tangent_scale1``/``tangent_scale2``) are
the default catalogue :data:`CATALOGUE` and are re-exported here.

The fit adds its own parameters: ``scale`` (a nuisance overall factor on f_r, for relative
data such as CUReT) and ``log_noise`` (natural log of the noise standard deviation in the
likelihood's residual space, for tables without sigma).
"""

from __future__ import annotations

import dataclasses
import math
import re
from typing import Mapping

import numpy as np

from brdf import microcylinder, schema
from brdf.paramschema import PRIORS

__all__ = ["BASE_PARAMS", "PARAM_NAMES", "MODEL_PARAM_NAMES", "DEFAULT_FREE", "DEFAULT_TIES",
           "defaults_from_fabric", "parse_free", "parse_ties", "base_of", "checked_defaults",
           "checked_bounds", "checked_priors", "checked_ties", "resolve_ties", "checked_toml",
           "PRIORS", "TOML_KEYS", "Catalogue", "CATALOGUE", "EXTRA_PARAMS"]

#: Natural-unit (lo, hi, prior, unit, fallback default) of a parameter.
Entry = tuple[float, float, str, str, float]

_RGB = tuple(p.name for p in schema.THREAD_PARAMS if p.kind == "rgb")

_BASES = schema.SCALAR_PARAMS + (microcylinder.TANGENT_SCALE.name,)
#: The fit's parameters that belong to no model.
EXTRA_PARAMS: dict[str, Entry] = {
    "scale": (1e-4, 1e4, "log-uniform", "1", 1.0),
    "log_noise": (-12.0, 3.0, "uniform", "ln(residual unit)", -3.0),
}

#: The microcylinder's shading parameters, both threads.
MODEL_PARAM_NAMES: tuple[str, ...] = microcylinder.MODEL_PARAM_NAMES
#: Every parameter name a microcylinder fit knows.
PARAM_NAMES: tuple[str, ...] = microcylinder.SCHEMA.names + tuple(EXTRA_PARAMS)
#: Group aliases accepted by ``--free``: ``albedo1`` is its three channels.
ALIASES = microcylinder.ALIASES
#: The microcylinder's default free set (8 parameters) and ties.
DEFAULT_FREE = microcylinder.DEFAULT_FREE
DEFAULT_TIES = microcylinder.DEFAULT_TIES
#: A microcylinder's thread values by name (:func:`brdf.microcylinder.thread_values`).
defaults_from_fabric = microcylinder.thread_values


@dataclasses.dataclass(frozen=True)
class Catalogue:
    """The names a fit of one model knows: every parameter name, and the group aliases
    ``--free`` expands (``albedo1`` -> its three channels). The parsing and checking functions
    of this module take one (``cat=``; default :data:`CATALOGUE`, the microcylinder's); an
    :class:`analysis.families.ModelFamily` is one too."""

    names: tuple
    aliases: Mapping


#: The microcylinder's names and aliases.
CATALOGUE = Catalogue(PARAM_NAMES, ALIASES)


def base_of(name: str) -> tuple[str, int | None]:
    """Split a full name into its base quantity and thread: ``albedo2_g`` -> ``("albedo_g", 2)``;
    a name of no thread (``scale``) -> ``(name, None)``.

    Examples
    --------
    >>> base_of("gamma_s1"), base_of("albedo2_g"), base_of("scale")
    (('gamma_s', 1), ('albedo_g', 2), ('scale', None))
    """
    m = re.fullmatch(r"([a-z_]+?)([12])_([a-z])", name)
    if m and m.group(1) in _RGB and m.group(3) in schema.RGB_CHANNELS:
        return f"{m.group(1)}_{m.group(3)}", int(m.group(2))
    m = re.fullmatch(r"([a-z_]+?)([12])", name)
    if m and m.group(1) in _BASES:
        return m.group(1), int(m.group(2))
    return name, None


#: The microcylinder's base quantities (per thread, an RGB one per channel, and the tangent
#: scale): (lo, hi, prior, unit, fallback default), as thread 1's entries.
BASE_PARAMS: dict[str, Entry] = {base_of(p.name)[0]: p.entry for p in microcylinder.SCHEMA
                                 if base_of(p.name)[1] == 1}


def entry(name: str) -> Entry:
    """(lo, hi, prior, unit, fallback default) of a full parameter name."""
    base, _ = base_of(name)
    return BASE_PARAMS.get(base) or EXTRA_PARAMS[name]


def unknown(name: str, what: str = "parameter", cat: Catalogue = CATALOGUE) -> ValueError:
    """The error for a name that is no parameter (it lists the valid ones)."""
    tail = f" (aliases: {', '.join(cat.aliases)})" if cat.aliases else ""
    return ValueError(f"unknown {what} {name!r}; valid names: {', '.join(cat.names)}{tail}")

def parse_free(free, cat: Catalogue = CATALOGUE) -> tuple[str, ...]:
    """Parse ``"eta1,kd1,albedo1"`` (or a sequence) into full names, aliases expanded.

    Raises
    ------
    ValueError
        A name that is not a parameter (the message lists the valid ones) or an empty list.

    Examples
    --------
    >>> parse_free("eta1, albedo2")
    ('eta1', 'albedo2_r', 'albedo2_g', 'albedo2_b')
    """
    items = _items(free, "free parameters", "names")
    out: list[str] = []
    for s in items:
        s = s.strip()
        if not s:
            continue
        for name in cat.aliases.get(s, (s,)):
            if name not in cat.names:
                raise unknown(name, "free parameter", cat)
            if name not in out:
                out.append(name)
    if not out:
        raise ValueError(f"free parameters: none given ({free!r}); valid names: "
                         f"{', '.join(cat.names)}")
    return tuple(out)


def _items(value, what: str, allowed: str) -> list[str]:
    """A comma-separated string, or a list/tuple of strings, as a list of strings; a
    ValueError naming ``what`` for anything else (a number, a table, a list of numbers)."""
    if value is None:
        return []
    if isinstance(value, str):
        return value.split(",")
    if not isinstance(value, (list, tuple)):
        raise ValueError(f"{what}: expected a comma-separated string or a list of {allowed}; "
                         f"got {type(value).__name__} {value!r:.60}")
    out = []
    for k, item in enumerate(value, start=1):
        if not isinstance(item, str):
            raise ValueError(f"{what}: item {k} is {type(item).__name__} {item!r:.60}; "
                             f"expected {allowed}")
        out.extend(item.split(","))
    return out


def parse_ties(ties, cat: Catalogue = CATALOGUE) -> dict[str, tuple[str, str]]:
    """Parse ties ``"eta2=eta1"`` or ``"area2=1-area1"`` into {target: (source, kind)}.

    ``a=b`` makes a follow b (a is the target). :class:`ParamSpec` swaps the two when only the
    target is listed free, so ``--free eta1 --tie eta1=eta2`` samples eta1 and sets eta2 equal.
    ``kind`` is ``"equal"`` or ``"complement"`` (target = 1 - source).

    Examples
    --------
    >>> parse_ties(["eta2=eta1", "area2=1-area1"])
    {'eta2': ('eta1', 'equal'), 'area2': ('area1', 'complement')}
    """
    out: dict[str, tuple[str, str]] = {}
    for t in _items(ties, "ties", "'a=b' or 'a=1-b' strings"):
        t = t.replace(" ", "")
        if not t:
            continue
        m = re.fullmatch(r"([a-z0-9_]+)=(1-)?([a-z0-9_]+)", t)
        if not m:
            raise ValueError(f"tie {t!r}: expected 'a=b' or 'a=1-b' with parameter names")
        target, comp, source = m.group(1), m.group(2), m.group(3)
        for name in (target, source):
            if name not in cat.names:
                raise unknown(name, "tied parameter", cat)
        if target == source:
            raise ValueError(f"tie {t!r}: a parameter cannot be tied to itself")
        tie = (source, "complement" if comp else "equal")
        if out.get(target, tie) != tie:
            raise ValueError(f"tie {t!r}: {target} is already tied to {out[target][0]}; "
                             f"tie each parameter once")
        out[target] = tie
    return out


def _table(value, what: str, cat: Catalogue = CATALOGUE) -> dict:
    """A mapping keyed by parameter names (unknown names refused), as a dict."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ValueError(f"{what}: expected a table of parameter names; got "
                         f"{type(value).__name__} {value!r:.60}")
    for name in value:
        if name not in cat.names:
            raise unknown(name, f"parameter in {what}", cat)
    return dict(value)


def _number(value, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{what} must be a number; got {type(value).__name__} {value!r:.60}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{what} must be finite; got {value!r}")
    return v


def checked_defaults(defaults, cat: Catalogue = CATALOGUE) -> dict[str, float]:
    """Start values: a mapping name -> finite number (a ValueError naming the first bad one)."""
    return {n: _number(v, f"start value of {n}")
            for n, v in _table(defaults, "start", cat).items()}


def checked_bounds(bounds, cat: Catalogue = CATALOGUE) -> dict[str, tuple[float, float]]:
    """Bounds: a mapping name -> (lo, hi) of finite numbers."""
    out = {}
    for name, b in _table(bounds, "bounds", cat).items():
        if isinstance(b, (str, bytes, Mapping)) or not hasattr(b, "__len__") or len(b) != 2:
            raise ValueError(f"bounds of {name} must be [lo, hi]; got {b!r:.60}")
        out[name] = (_number(b[0], f"lower bound of {name}"),
                     _number(b[1], f"upper bound of {name}"))
    return out


def checked_priors(priors, cat: Catalogue = CATALOGUE) -> dict[str, str]:
    """Priors: a mapping name -> "uniform" | "log-uniform"."""
    out = _table(priors, "prior", cat)
    for name, v in out.items():
        if v not in PRIORS:
            raise ValueError(f"prior of {name} must be 'uniform' or 'log-uniform'; "
                             f"got {v!r:.60}")
    return out


def checked_ties(ties, cat: Catalogue = CATALOGUE) -> dict[str, tuple[str, str]]:
    """Ties as {target: (source, kind)}: strings parsed (:func:`parse_ties`), a mapping of
    that shape checked."""
    if not isinstance(ties, Mapping):
        return parse_ties(ties, cat)
    out = {}
    for target, value in ties.items():
        ok = (isinstance(value, (tuple, list)) and len(value) == 2
              and value[1] in ("equal", "complement") and isinstance(value[0], str))
        if not ok:
            raise ValueError(f"tie of {target!r}: expected (source, 'equal' | 'complement'); "
                             f"got {value!r:.60}")
        for name in (target, value[0]):
            if name not in cat.names:
                raise unknown(name, "tied parameter", cat)
        if target == value[0]:
            raise ValueError(f"tie {target}={target}: a parameter cannot be tied to itself")
        out[target] = (value[0], value[1])
    return out


def resolve_ties(free, ties: dict) -> dict[str, tuple[str, str]]:
    """Orient each tie onto its free side (``a=b`` with only ``a`` free samples ``a`` and sets
    ``b``) and refuse the contradictions: both sides free, neither side free, a parameter
    tied twice.

    Examples
    --------
    >>> resolve_ties(["eta2"], {"eta2": ("eta1", "equal")})
    {'eta1': ('eta2', 'equal')}
    """
    out: dict[str, tuple[str, str]] = {}
    for target, (source, kind) in ties.items():
        tie = f"tie {target}={'1-' if kind == 'complement' else ''}{source}"
        if target in free and source in free:
            raise ValueError(f"{tie}: both {target} and {source} are listed free; a tied "
                             f"parameter takes its source's value, so drop {target} from the "
                             f"free parameters or drop the tie")
        if target not in free and source not in free:
            raise ValueError(f"{tie}: neither {target} nor {source} is free (a tie between "
                             f"fixed parameters does nothing); free {source} or drop the tie")
        if target in free:
            target, source = source, target
        if target in out:
            raise ValueError(f"{tie}: {target} is already tied to {out[target][0]}; tie each "
                             f"parameter once")
        out[target] = (source, kind)
    return out


#: The keys of a TOML spec file and what each holds.
TOML_KEYS = {"free": "a list of names", "tie": "a list of 'a=b' strings",
             "bounds": "a table name = [lo, hi]", "prior": "a table name = 'uniform' | "
             "'log-uniform'", "start": "a table name = value", "fabric": "a preset name"}


def checked_toml(doc: Mapping, cat: Catalogue = CATALOGUE) -> dict:
    """The keys of a parsed TOML spec, each checked once (a ValueError naming the key):
    ``free`` and ``tie`` as lists of strings, ``bounds``/``prior``/``start`` as checked
    tables, ``fabric`` a string."""
    extra = set(doc) - set(TOML_KEYS)
    if extra:
        raise ValueError(f"unknown keys {sorted(extra)}; allowed: {sorted(TOML_KEYS)}")
    out = {}
    for key, check in (("free", lambda v: list(parse_free(v, cat))),
                       ("tie", lambda v: [t for t in _items(v, "tie", "'a=b' strings")
                                          if t.strip()]),
                       ("bounds", lambda v: checked_bounds(v, cat)),
                       ("prior", lambda v: checked_priors(v, cat)),
                       ("start", lambda v: checked_defaults(v, cat))):
        if key in doc:
            try:
                out[key] = check(doc[key])
            except ValueError as exc:
                raise ValueError(f"key {key!r} ({TOML_KEYS[key]}): {exc}") from None
    if "fabric" in doc and not isinstance(doc["fabric"], str):
        raise ValueError(f"key 'fabric' ({TOML_KEYS['fabric']}): got {doc['fabric']!r:.60}")
    return out
