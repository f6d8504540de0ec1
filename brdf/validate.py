"""Input checks that raise ``ValueError`` naming the parameter, its value and what is allowed."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["choice", "real", "flag", "integer", "array"]


def choice(name: str, value, allowed: Sequence[str]) -> str:
    """Return ``value`` if it is one of ``allowed``; otherwise raise ValueError listing them.

    Examples
    --------
    >>> choice("gap", "incident", ("incident", "outgoing"))
    'incident'
    """
    if not isinstance(value, str) or value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(repr(a) for a in allowed)}; "
                         f"got {value!r}")
    return value


def real(name: str, value, *, lo=None, hi=None, lo_open=False, hi_open=False,
         what: str | None = None) -> float:
    """Return ``value`` as a finite float within the given bounds, or raise ValueError.

    Examples
    --------
    >>> real("kd", 0.3, lo=0, hi=1)
    0.3
    """
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number; got {value!r}") from None
    bad = not math.isfinite(x)
    if lo is not None:
        bad |= x <= lo if lo_open else x < lo
    if hi is not None:
        bad |= x >= hi if hi_open else x > hi
    if bad:
        if what is None:
            left = "" if lo is None else f"{lo} {'<' if lo_open else '<='} "
            right = "" if hi is None else f" {'<' if hi_open else '<='} {hi}"
            what = f"a finite number with {left}{name}{right}"
        raise ValueError(f"{name} must be {what}; got {value!r}")
    return x


def flag(name: str, value) -> bool:
    """Return a bool for True/False (or 'on'/'off' strings); raise ValueError otherwise."""
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.lower() in ("on", "off", "true", "false", "yes", "no"):
        return value.lower() in ("on", "true", "yes")
    raise ValueError(f"{name} must be True or False (or 'on'/'off'); got {value!r}")


def integer(name: str, value, *, lo: int, hi: int | None = None) -> int:
    """Return ``value`` as an int >= ``lo`` (and <= ``hi`` when given); raise ValueError
    otherwise.

    Examples
    --------
    >>> integer("n", 3, lo=1, hi=4)
    3
    """
    allowed = f"an integer >= {lo}" if hi is None else f"an integer in {lo}..{hi}"
    if isinstance(value, bool) or not isinstance(value, (int,)) and not (
            hasattr(value, "__index__")):
        raise ValueError(f"{name} must be {allowed}; got {value!r}")
    v = int(value)
    if v < lo or (hi is not None and v > hi):
        raise ValueError(f"{name} must be {allowed}; got {value!r}")
    return v


def array(name: str, value) -> np.ndarray:
    """``value`` as a float64 array; ValueError naming ``name`` if it is not numeric.

    Examples
    --------
    >>> array("eta", [1.5, 2]).tolist()
    [1.5, 2.0]
    """
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number or an array of real numbers; got "
                         f"{value!r}") from None
