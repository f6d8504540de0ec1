"""Checks of the fields of a state file that others may have written (results.json,
fit_config.json, checkpoint.h5, a fabric JSON, a TOML spec).

A file from a colleague is untrusted: every field a reader uses is checked here for type,
shape and finiteness before the reader uses it, and a bad one is one ``ValueError`` line
naming the file and the field (a dotted path such as ``parameters.kd1.median``), the value and
what is allowed. :func:`load_json` and :func:`load_toml` read a whole file the same way: an
unreadable, undecodable or too deeply nested one is one line naming the file.

Examples
--------
>>> f = FileFields("results.json")
>>> f.number({"median": 0.2}, "median", "parameters.kd1")
0.2
>>> f.number({"median": [1, 2]}, "median", "parameters.kd1")
Traceback (most recent call last):
...
ValueError: results.json: parameters.kd1.median must be a finite number; got [1, 2]
"""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from gonio.safeopen import MAX_STATE_BYTES, read_bytes, read_text
from gonio.terminal import shown

__all__ = ["FileFields", "load_json", "loads_json", "load_toml", "MAX_DEPTH", "MAX_MAGNITUDE"]

#: Deepest nesting of lists and objects a state file may hold (microcyl writes at most ~6).
MAX_DEPTH = 64
#: Largest magnitude of a model parameter read from a file (a fabric JSON, a fit's medians):
#: beyond it f_r and the float32 pixels of a render overflow (an albedo of 1e308 renders inf),
#: so it is refused like a range error.
MAX_MAGNITUDE = 1e6

_MISSING = object()


#: The same function as :func:`gonio.terminal.shown` (the one escape of text read from a
#: file), under the name its first callers used.
one_line = shown


def _short(value, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _depth(value, limit: int = MAX_DEPTH) -> int:
    """Nesting depth of lists/dicts, counted without recursion (stops past ``limit``)."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, (dict, list)):
            deepest = max(deepest, d)
            if deepest > limit:
                return deepest
            stack.extend((x, d + 1) for x in (v.values() if isinstance(v, dict) else v))
    return deepest


def _check_depth(path, doc):
    if _depth(doc) > MAX_DEPTH:
        raise ValueError(f"{path}: nested more than {MAX_DEPTH} levels deep; not a microcyl "
                         f"file")
    return doc


def load_json(path, what: str = "JSON file", *, max_bytes: int = MAX_STATE_BYTES):
    """The JSON document in ``path``.

    Raises
    ------
    ValueError
        One line naming the file: unreadable, a link or not a regular file, larger than
        ``max_bytes`` (bytes; :data:`gonio.safeopen.MAX_STATE_BYTES` by default), not UTF-8,
        not JSON, or nested more than :data:`MAX_DEPTH` levels (``what`` says what the file
        should have been). The file is opened once through :func:`gonio.safeopen.open_regular`.
    """
    path = Path(path)
    return loads_json(read_text(path, max_bytes=max_bytes, what=what), path, what)


def loads_json(text: str, path, what: str = "JSON file"):
    """The JSON document ``text`` read from ``path`` (named in errors, as :func:`load_json`)."""
    try:
        doc = json.loads(text)
    except RecursionError:
        raise ValueError(f"{path}: not a {what} (nested too deeply)") from None
    except ValueError as exc:
        raise ValueError(f"{path}: not a {what} (invalid JSON: {exc})") from None
    return _check_depth(path, doc)


def load_toml(path, what: str = "TOML file", *, max_bytes: int = MAX_STATE_BYTES) -> dict:
    """The TOML document in ``path``; errors and the size cap as :func:`load_json`."""
    path = Path(path)
    data = read_bytes(path, max_bytes=max_bytes, what=what)
    try:
        doc = tomllib.loads(data.decode("utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML (not UTF-8 text: {exc.reason})") from None
    except RecursionError:
        raise ValueError(f"{path}: not a {what} (nested too deeply)") from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read {what} ({exc.strerror or exc})") from None
    return _check_depth(path, doc)


class FileFields:
    """The checks of one file's fields; every error names the file and the field.

    Each method takes the containing ``doc`` (a mapping), the ``key`` to read and the dotted
    ``where`` of ``doc`` in the file ("" for the top level), and returns the checked value.
    A missing key is an error unless ``default`` is given.

    Parameters
    ----------
    path : path
        The file, as named in the messages.
    """

    def __init__(self, path):
        self.path = Path(path)

    # ------------------------------------------------------------------ basics
    def error(self, field: str, allowed: str, value=_MISSING, *, got: str | None = None
              ) -> ValueError:
        """The one-line error: ``FILE: FIELD must be ALLOWED; got VALUE`` (``got`` the text
        shown for the value instead of its repr)."""
        field = shown(field)
        if got is None and value is _MISSING:
            return ValueError(f"{self.path}: {field} must be {allowed}; it is missing")
        return ValueError(f"{self.path}: {field} must be {allowed}; "
                          f"got {shown(_short(value) if got is None else got)}")

    @staticmethod
    def name(where: str, key) -> str:
        """The dotted name of ``key`` inside ``where``."""
        return f"{where}.{key}" if where else str(key)

    def _get(self, doc, key, where, allowed, default):
        if not isinstance(doc, Mapping):
            raise self.error(where or "the document", "an object", doc)
        if key in doc:
            return doc[key]
        if default is not _MISSING:
            return default
        raise self.error(self.name(where, key), allowed)

    def mapping(self, doc, key, where: str = "", *, default=_MISSING) -> dict:
        """An object (``dict``)."""
        v = self._get(doc, key, where, "an object", default)
        if v is not default and not isinstance(v, Mapping):
            raise self.error(self.name(where, key), "an object", v)
        return v

    def string(self, doc, key, where: str = "", *, default=_MISSING, none: bool = False):
        """A string (or None when ``none``)."""
        v = self._get(doc, key, where, "a string", default)
        if v is default or (none and v is None):
            return v
        if not isinstance(v, str):
            raise self.error(self.name(where, key), "a string", v)
        return v

    def boolean(self, doc, key, where: str = "", *, default=_MISSING, none: bool = False):
        """true or false (or null when ``none``)."""
        v = self._get(doc, key, where, "true or false", default)
        if v is default or (none and v is None):
            return v
        if not isinstance(v, (bool, np.bool_)):
            raise self.error(self.name(where, key), "true or false", v)
        return bool(v)

    # ------------------------------------------------------------------ numbers
    def number(self, doc, key, where: str = "", *, finite: bool = True, lo=None, hi=None,
               default=_MISSING, none: bool = False):
        """A real number (not a bool, not a string), finite unless ``finite`` is False, in
        ``[lo, hi]`` when given; returned as float."""
        allowed = ("a finite number" if finite else "a number") + _range(lo, hi)
        v = self._get(doc, key, where, allowed, default)
        if v is default or (none and v is None):
            return v
        return self.as_number(v, self.name(where, key), finite=finite, lo=lo, hi=hi)

    def as_number(self, v, field: str, *, finite: bool = True, lo=None, hi=None) -> float:
        """:meth:`number` of a value already read (``field`` its dotted name)."""
        allowed = ("a finite number" if finite else "a number") + _range(lo, hi)
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.number)) or (
                isinstance(v, np.ndarray)):
            raise self.error(field, allowed, v)
        try:
            x = float(v)
        except OverflowError:
            raise self.error(field, allowed, got="an integer too large for a float") from None
        if (finite and not math.isfinite(x)) or (math.isnan(x) and (lo is not None
                                                                    or hi is not None)):
            raise self.error(field, allowed, v)
        if (lo is not None and x < lo) or (hi is not None and x > hi):
            raise self.error(field, allowed, v)
        return x

    def integer(self, doc, key, where: str = "", *, lo=None, hi=None, default=_MISSING,
                none: bool = False):
        """An integer (a float with an integer value is not one) in ``[lo, hi]``."""
        allowed = "an integer" + _range(lo, hi)
        v = self._get(doc, key, where, allowed, default)
        if v is default or (none and v is None):
            return v
        if isinstance(v, np.ndarray) and v.shape == ():
            v = v[()]
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
            raise self.error(self.name(where, key), allowed, v)
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise self.error(self.name(where, key), allowed, v)
        return int(v)

    def array(self, doc, key, where: str = "", *, shape: tuple, finite: bool = True,
              integer: bool = False, default=_MISSING, none: bool = False) -> np.ndarray:
        """An array of numbers of ``shape`` (a tuple; None for any length in that place),
        finite unless ``finite`` is False, of integers when ``integer``; returned as float64
        (int64 when ``integer``)."""
        dims = ", ".join("N" if s is None else str(s) for s in shape) + (
            "," if len(shape) == 1 else "")
        kind = "integers" if integer else ("finite numbers" if finite else "numbers")
        allowed = f"an array of {kind} of shape ({dims})"
        v = self._get(doc, key, where, allowed, default)
        if v is default or (none and v is None):
            return v
        field = self.name(where, key)
        try:
            a = np.asarray(v)
        except (ValueError, TypeError):
            raise self.error(field, allowed, v) from None
        ok_kind = a.dtype.kind in "iu" if integer else a.dtype.kind in "iuf"
        if not ok_kind or a.ndim != len(shape) or any(
                s is not None and n != s for n, s in zip(a.shape, shape)):
            shown = None if a.size <= 8 else f"shape {a.shape}, type {a.dtype}"
            raise self.error(field, allowed, v, got=shown)
        if integer:
            return a.astype(np.int64)
        a = a.astype(np.float64)
        if finite and not np.all(np.isfinite(a)):
            raise self.error(field, allowed, got=f"{int(np.sum(~np.isfinite(a)))} non-finite "
                                                 f"value(s)")
        return a


def _range(lo, hi) -> str:
    if lo is not None and hi is not None:
        return f" in [{lo:g}, {hi:g}]"
    if lo is not None:
        return f" >= {lo:g}"
    if hi is not None:
        return f" <= {hi:g}"
    return ""
