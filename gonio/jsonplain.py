"""One conversion of microcyl's values to plain JSON data (the only one in the project)."""

from __future__ import annotations

import dataclasses
import json
import math
import os

import numpy as np

__all__ = ["plain", "json_line", "meta_text"]


def plain(value, *, nonfinite: str = "keep", _depth: int = 0):
    """``value`` as JSON-ready Python data: dicts (keys as str), lists, str, int, float, bool,
    None.

    Numpy scalars and arrays become numbers and (nested) lists, tuples lists, dataclasses dicts
    of their fields, paths strings, anything else ``str(value)``.

    Parameters
    ----------
    value : object
    nonfinite : {"keep", "null", "repr"}
        What becomes of NaN and infinities: kept as floats (``json.dumps`` writes ``NaN``),
        ``None`` (strict JSON), or their text (``'nan'``).

    Examples
    --------
    >>> plain({"a": np.float64(1.5), 2: (np.arange(2), float("nan"))}, nonfinite="null")
    {'a': 1.5, '2': [[0, 1], None]}
    """
    if nonfinite not in ("keep", "null", "repr"):
        raise ValueError(f"nonfinite must be 'keep', 'null' or 'repr'; got {nonfinite!r}")
    if _depth > 32:
        return repr(value)
    kw = {"nonfinite": nonfinite, "_depth": _depth + 1}
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.generic):
        return plain(value.item(), **kw)
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        if math.isfinite(value) or nonfinite == "keep":
            return float(value)
        return None if nonfinite == "null" else repr(value)
    if isinstance(value, np.ndarray):
        return plain(value.tolist(), **kw)
    if isinstance(value, dict):
        return {str(k): plain(v, **kw) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v, **kw) for v in value]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: plain(getattr(value, f.name), **kw) for f in dataclasses.fields(value)}
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return str(value)


def json_line(value) -> str:
    """``value`` as strict JSON on one line (NaN and infinities as null).

    Examples
    --------
    >>> print(json_line({"name": "velvet", "snr": np.float64("nan"), "t": (1, 2)}))
    {"name": "velvet", "snr": null, "t": [1, 2]}
    """
    return json.dumps(plain(value, nonfinite="null"), allow_nan=False)


def meta_text(value) -> str:
    """A table's metadata value as one line to print: a one-line text as it is, anything
    else (a dict, a list, a number, a text with line breaks) as :func:`json_line`, never a
    Python repr.

    Examples
    --------
    >>> print(meta_text("MERL alum-bronze.binary"))
    MERL alum-bronze.binary
    >>> print(meta_text({"type": "Fabric", "name": "linen_plain"}))
    {"type": "Fabric", "name": "linen_plain"}
    """
    if isinstance(value, str) and value.isprintable():
        return value
    return json_line(value)
