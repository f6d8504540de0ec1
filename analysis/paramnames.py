"""The fit's parameter names, bounds and priors, derived from :mod:`brdf.schema`; ``--free`` and
``--tie`` strings.

Model parameters are named by quantity and thread number: ``eta1``, ``kd1``, ``gamma_s1``,
``gamma_v1``, ``area1``, ``albedo1_r``, ``albedo1_g``, ``albedo1_b`` and the same with ``2``:
the scalar parameters of :data:`brdf.schema.THREAD_PARAMS`, then each RGB one per channel. Their
bounds are the schema's typical ranges (inside the ranges a Thread accepts), their units the
schema's, their priors log-uniform where the schema's range spans decades (``log_scale``) and
uniform otherwise, their fallback defaults the schema's typical values.

The fit adds its own parameters: ``tangent_scale1``/``tangent_scale2`` (a factor on a thread's
tangent offsets), ``scale`` (a nuisance overall factor on f_r, for relative data such as CUReT)
and ``log_noise`` (natural log of the noise standard deviation in the likelihood's residual
space, for tables without sigma).
"""

from __future__ import annotations

import re

import numpy as np

from brdf import schema

__all__ = ["BASE_PARAMS", "PARAM_NAMES", "MODEL_PARAM_NAMES", "DEFAULT_FREE", "DEFAULT_TIES",
           "defaults_from_fabric", "parse_free", "parse_ties", "base_of"]

#: Natural-unit (lo, hi, prior, unit, fallback default) of an entry derived from the schema.
Entry = tuple[float, float, str, str, float]


def _entry(info: schema.ParamInfo) -> Entry:
    lo, hi = info.typical
    prior = "log-uniform" if info.log_scale else "uniform"
    return (float(lo), float(hi), prior, info.unit, float(info.typical_value))


_RGB = tuple(p.name for p in schema.THREAD_PARAMS if p.kind == "rgb")

#: Base quantities: (lo, hi, prior, unit, fallback default), per thread: the schema's scalar
#: parameters, its RGB ones per channel (``albedo_r`` ...), and the fit's ``tangent_scale``.
BASE_PARAMS: dict[str, Entry] = {
    **{name: _entry(schema.THREAD[name]) for name in schema.SCALAR_PARAMS},
    **{f"{name}_{c}": _entry(schema.THREAD[name]) for name in _RGB for c in schema.RGB_CHANNELS},
    "tangent_scale": (0.25, 2.0, "uniform", "1", 1.0),
}
#: The fit's parameters that belong to no thread.
EXTRA_PARAMS: dict[str, Entry] = {
    "scale": (1e-4, 1e4, "log-uniform", "1", 1.0),
    "log_noise": (-12.0, 3.0, "uniform", "ln(residual unit)", -3.0),
}


def _thread_name(base: str, j: int) -> str:
    head, _, channel = base.rpartition("_")
    if head in _RGB and channel in schema.RGB_CHANNELS:
        return f"{head}{j}_{channel}"
    return f"{base}{j}"


#: Names of the model parameters proper (what ``prepare(...).eval`` takes), both threads.
MODEL_PARAM_NAMES: tuple[str, ...] = tuple(
    _thread_name(b, j) for j in (1, 2) for b in BASE_PARAMS if b != "tangent_scale")
#: Every parameter name a spec knows.
PARAM_NAMES: tuple[str, ...] = MODEL_PARAM_NAMES + ("tangent_scale1", "tangent_scale2") \
    + tuple(EXTRA_PARAMS)
#: Group aliases accepted by ``--free``: ``albedo1`` is its three channels.
ALIASES = {f"{name}{j}": tuple(f"{name}{j}_{c}" for c in schema.RGB_CHANNELS)
           for j in (1, 2) for name in _RGB}

#: The default free set (8 parameters) and ties: one eta for both threads, area2 = 1 - area1.
DEFAULT_FREE = ("eta1", "kd1", "kd2", "gamma_s1", "gamma_v1", "gamma_s2", "gamma_v2", "area1")
DEFAULT_TIES = ("eta2=eta1", "area2=1-area1")


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
    if m and m.group(1) in BASE_PARAMS:
        return m.group(1), int(m.group(2))
    return name, None


def entry(name: str) -> Entry:
    """(lo, hi, prior, unit, fallback default) of a full parameter name."""
    base, _ = base_of(name)
    return BASE_PARAMS.get(base) or EXTRA_PARAMS[name]


def unknown(name: str, what: str = "parameter") -> ValueError:
    """The error for a name that is no parameter (it lists the valid ones)."""
    return ValueError(f"unknown {what} {name!r}; valid names: {', '.join(PARAM_NAMES)} "
                      f"(aliases: {', '.join(ALIASES)})")
def parse_free(free) -> tuple[str, ...]:
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
    items = [s.strip() for s in free.split(",")] if isinstance(free, str) else list(free)
    out: list[str] = []
    for s in items:
        if not s:
            continue
        for name in ALIASES.get(s, (s,)):
            if name not in PARAM_NAMES:
                raise unknown(name, "free parameter")
            if name not in out:
                out.append(name)
    if not out:
        raise ValueError(f"free parameters: none given ({free!r}); valid names: "
                         f"{', '.join(PARAM_NAMES)}")
    return tuple(out)


def parse_ties(ties) -> dict[str, tuple[str, str]]:
    """Parse ties ``"eta2=eta1"`` or ``"area2=1-area1"`` into {target: (source, kind)}.

    ``a=b`` makes a follow b (a is the target). :class:`ParamSpec` swaps the two when only the
    target is listed free, so ``--free eta1 --tie eta1=eta2`` samples eta1 and sets eta2 equal.
    ``kind`` is ``"equal"`` or ``"complement"`` (target = 1 - source).

    Examples
    --------
    >>> parse_ties(["eta2=eta1", "area2=1-area1"])
    {'eta2': ('eta1', 'equal'), 'area2': ('area1', 'complement')}
    """
    if isinstance(ties, str):
        ties = [t for t in ties.split(",")]
    out: dict[str, tuple[str, str]] = {}
    for t in ties or ():
        t = t.replace(" ", "")
        if not t:
            continue
        m = re.fullmatch(r"([a-z0-9_]+)=(1-)?([a-z0-9_]+)", t)
        if not m:
            raise ValueError(f"tie {t!r}: expected 'a=b' or 'a=1-b' with parameter names")
        target, comp, source = m.group(1), m.group(2), m.group(3)
        for name in (target, source):
            if name not in PARAM_NAMES:
                raise unknown(name, "tied parameter")
        if target == source:
            raise ValueError(f"tie {t!r}: a parameter cannot be tied to itself")
        out[target] = (source, "complement" if comp else "equal")
    return out


def defaults_from_fabric(fab) -> dict[str, float]:
    """Default values of every model parameter from a fabric's threads (natural units).

    Parameters
    ----------
    fab : object with ``threads``
        Two threads with the scalar parameters of :data:`brdf.schema.SCALAR_PARAMS` (``eta``,
        ``kd``, ``gamma_s``, ``gamma_v`` in degrees, ``area``) and ``albedo`` (one or 3 values).

    Examples
    --------
    >>> import brdf
    >>> d = defaults_from_fabric(brdf.fabric("linen_plain"))
    >>> d["gamma_s1"], round(d["albedo2_g"], 12), tuple(d) == MODEL_PARAM_NAMES
    (12.0, 0.24, True)
    """
    out: dict[str, float] = {}
    for j, th in enumerate(fab.threads, start=1):
        for name in schema.SCALAR_PARAMS:
            out[f"{name}{j}"] = float(getattr(th, name))
        for name in _RGB:
            rgb = np.broadcast_to(np.asarray(getattr(th, name), float), (3,))
            for c, a in zip(schema.RGB_CHANNELS, rgb):
                out[f"{name}{j}_{c}"] = float(a)
    return out
