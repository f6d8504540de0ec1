"""Numbers written as text (CSV and ALTA fields, geometry spec strings): one strict grammar.

Python's ``float()`` reads more than a table or a spec means: ``3_0`` (30), ``١٢`` (12, in
Arabic-Indic digits), ``infinity``, and spaces around the number. Every reader of microcyl
takes a number only in the form

    [+-] digits [. digits] [e|E [+-] digits]     (ASCII digits; ``.5`` and ``5.`` too)

and, where a missing or invalid value may stand (CSV and ALTA values, never angles), the words
``nan``, ``inf``, ``+inf``, ``-inf`` in any case, as spreadsheets and microcyl's writers
produce them. Spaces and tabs around the number are the caller's to strip (CSV fields are
stripped; ALTA fields are split on white space).
"""

from __future__ import annotations

import re

__all__ = ["NUMBER_FORM", "parse_number", "is_number"]

#: The accepted form in words, for error messages.
NUMBER_FORM = "decimal digits such as 30, -1.5 or 2.5e-3"

_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_NONFINITE = {"nan": float("nan"), "inf": float("inf"), "+inf": float("inf"),
              "-inf": float("-inf")}


def parse_number(text: str, *, nonfinite: bool = False) -> float:
    """``text`` as a float if it is a decimal number (or, with ``nonfinite``, nan or inf).

    Raises
    ------
    ValueError
        Anything else (the message quotes ``text``).

    Examples
    --------
    >>> parse_number("2.5e-3"), parse_number("NaN", nonfinite=True)
    (0.0025, nan)
    >>> parse_number("3_0")
    Traceback (most recent call last):
        ...
    ValueError: '3_0' is not a number (decimal digits such as 30, -1.5 or 2.5e-3)
    """
    if isinstance(text, str):
        if _DECIMAL.fullmatch(text):
            return float(text)
        if nonfinite and text.lower() in _NONFINITE:
            return _NONFINITE[text.lower()]
    what = NUMBER_FORM + (", or nan, inf for a missing value" if nonfinite else "")
    raise ValueError(f"{text!r} is not a number ({what})")


def is_number(text: str, *, nonfinite: bool = False) -> bool:
    """Whether :func:`parse_number` reads ``text``."""
    try:
        parse_number(text, nonfinite=nonfinite)
    except ValueError:
        return False
    return True
