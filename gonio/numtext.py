"""Numbers written as text (CSV and ALTA fields, geometry spec strings): one strict grammar.

Python's ``float()`` reads more than a table or a spec means: ``3_0`` (30), ``١٢`` (12, in
Arabic-Indic digits), ``infinity``, and spaces around the number. Every reader of microcyl
takes a number only in the form

    [+-] digits [. digits] [e|E [+-] digits]     (ASCII digits; ``.5`` and ``5.`` too)

and, where a missing or invalid value may stand (CSV and ALTA values, never angles), the words
``nan``, ``inf``, ``+inf``, ``-inf`` in any case, as spreadsheets and microcyl's writers
produce them. Spaces and tabs around the number are the caller's to strip (CSV fields are
stripped; ALTA fields are split on white space).

Writers print float64 numbers with a number of significant digits, and float32 data (an
OpenEXR table's channels) with the fewest digits that read back to the same float32
(:func:`float32_shortest`), all numbers of a column at once.
"""

from __future__ import annotations

import re

import numpy as np

__all__ = ["NUMBER_FORM", "DIGITS", "parse_number", "is_number", "round_significant",
           "float32_shortest", "float32_column", "column_digits", "format_numbers"]

#: Significant digits printed of float64 data by default (9 also give any float32 back).
DIGITS = 9
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


def round_significant(x, digits) -> np.ndarray:
    """``x`` rounded to ``digits`` significant decimal digits (one count, or one per number):
    the float nearest to that decimal, so that ``"%.{digits}g"`` prints it exactly; NaN where
    no such float is sure (non-finite ``x``, or a power of ten beyond 1e22, which floats do
    not hold exactly).

    Examples
    --------
    >>> round_significant([15.0000004, -0.123456, 0.0, 1234.5], 3).tolist()
    [15.0, -0.123, 0.0, 1230.0]
    """
    x = np.asarray(x, dtype=np.float64)
    return _round(x, _exponent(x), digits)


def _exponent(x: np.ndarray) -> np.ndarray:
    """floor(log10(|x|)) exactly (log10 may round across a power of ten); 0 for 0."""
    a = np.abs(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.floor(np.log10(np.where((a > 0) & np.isfinite(a), a, 1.0)))
    e += a >= 10.0 ** (e + 1)
    e -= a < 10.0 ** e
    return np.where(a > 0, e, 0.0)


def _round(x: np.ndarray, e: np.ndarray, digits) -> np.ndarray:
    """``x`` (with exponents ``e``) rounded to ``digits`` significant digits, as
    :func:`round_significant`."""
    k = digits - 1 - e
    exact = np.abs(k) <= 22                     # 10**k is a float exactly
    scale = 10.0 ** np.abs(np.where(exact, k, 0))
    with np.errstate(over="ignore", invalid="ignore"):
        r = np.where(k >= 0, np.round(x * scale) / scale, np.round(x / scale) * scale)
    return np.where(exact & np.isfinite(x), r, np.nan)


def float32_shortest(x, stored, convert=None, *, max_digits: int = 9, slack: int = 0):
    """The fewest significant digits that give back each float32 value ``stored``.

    Parameters
    ----------
    x : array_like
        The numbers to print (float64), e.g. a float32 value widened, or converted to other
        units (an angle stored in radians, printed in degrees).
    stored : array_like
        The float32 values that the printed numbers must read back to, same shape.
    convert : callable, optional
        From a printed number to the stored units (``np.radians``); identity by default.
    max_digits : int
        The most digits tried (at most 15).
    slack : int
        Also require the converted number moved by ``slack`` float64 ulps either way to
        round to ``stored`` (a reader's own rounding after the conversion).

    Returns
    -------
    r : ndarray
        Each number rounded to its digits (``"%.{p}g" % r`` prints the decimal); ``x`` where
        none is found.
    p : ndarray of int
        The digits to print, ``"%.{p}g" % r``: the fewest significant ones, or as many as
        the number has before its decimal point up to ``max_digits`` (``30``, not
        ``3e+01``); 0 where no count up to ``max_digits`` gives ``stored`` back (and for
        non-finite ``x``).

    Notes
    -----
    The count is found by bisection between 1 and ``max_digits`` (four vectorized passes
    for 9), each count checked on the number printed: whatever the count, the printed
    number gives ``stored`` back. Bisection assumes that a count that works makes every
    larger one work, true but for rare numbers, which then get a digit or two more than
    the fewest.

    Examples
    --------
    >>> x32 = np.float32([0.1, 1 / 3, 15.0, 3000.0])
    >>> r, p = float32_shortest(x32.astype(float), x32)
    >>> ["%.*g" % (d, v) for d, v in zip(p.tolist(), r.tolist())]
    ['0.1', '0.33333334', '15', '3000']
    """
    x = np.asarray(x, dtype=np.float64)
    stored = np.asarray(stored, dtype=np.float32)
    top = min(int(max_digits), 15)
    r, p = x.copy(), np.zeros(x.shape, dtype=np.int64)
    idx = np.flatnonzero(np.isfinite(x))
    v, s = x.ravel()[idx], stored.ravel()[idx]
    e = _exponent(v)

    def works(sel, digits):
        cand = _round(v[sel], e[sel], digits)
        y = cand if convert is None else np.asarray(convert(cand), dtype=np.float64)
        return cand, np.isfinite(cand) & _rounds_to(y, s[sel], slack)

    best, good = works(slice(None), top)
    lo, hi = np.zeros(v.shape, dtype=np.int64), np.full(v.shape, top, dtype=np.int64)
    while True:
        sel = np.flatnonzero(good & (hi - lo > 1))
        if not sel.size:
            break
        mid = (lo[sel] + hi[sel]) // 2
        cand, ok = works(sel, mid)
        hi[sel[ok]], best[sel[ok]] = mid[ok], cand[ok]
        lo[sel[~ok]] = mid[~ok]
    r.flat[idx[good]] = best[good]
    p.flat[idx[good]] = hi[good]
    whole = np.where(p > 0, _exponent(r) + 1, 0).astype(np.int64)   # digits before the point
    return r, np.where((whole > p) & (whole <= max_digits), whole, p)


def _rounds_to(y, stored, slack):
    """Whether float64 ``y`` (and ``y`` moved ``slack`` ulps either way) round to ``stored``."""
    with np.errstate(over="ignore", invalid="ignore"):
        same = y.astype(np.float32) == stored
        if slack:
            step = slack * np.spacing(np.abs(y))
            same &= ((y - step).astype(np.float32) == stored) \
                & ((y + step).astype(np.float32) == stored)
    return same


def column_digits(x, digits: int | None = None):
    """(numbers, digits) to print a column with :func:`format_numbers`: ``digits`` when
    given; else as :func:`float32_column` has it, the float32 values being those that are
    floats32 exactly.

    Examples
    --------
    >>> format_numbers(*column_digits(np.float32([0.1, 0.25, np.nan]).astype(float)))
    ['0.1', '0.25', 'nan']
    >>> format_numbers(*column_digits(np.array([0.1, 1 / 3])))
    ['0.1', '0.333333333']
    """
    x = np.asarray(x, dtype=np.float64)
    if digits is not None:
        return x, digits
    with np.errstate(over="ignore"):
        x32 = x.astype(np.float32)
    return float32_column(x, x32, x32 == x)


def float32_column(x, stored, is32, convert=None, *, slack: int = 0):
    """(numbers, digits) to print a column of float64 numbers ``x``, of which those where
    ``is32`` stand for the float32 values ``stored`` (through ``convert`` as in
    :func:`float32_shortest`).

    When at least half of the nonzero numbers are float32 (float32 data, as an OpenEXR
    table's channels), each of those is printed with the fewest digits that give its
    float32 back, and every other with :data:`DIGITS`; otherwise (float64 data, where a
    float32 turns up by chance alone) all with :data:`DIGITS`.
    """
    x = np.asarray(x, dtype=np.float64)
    is32 = np.asarray(is32, dtype=bool)
    nonzero = np.isfinite(x) & (x != 0)
    if 2 * np.count_nonzero(is32 & nonzero) < np.count_nonzero(nonzero):
        return x, DIGITS
    r, p = float32_shortest(x, stored, convert, max_digits=DIGITS, slack=slack)
    use = is32 & (p > 0)
    return np.where(use, r, x), np.where(use, p, DIGITS)


def format_numbers(x, digits) -> list[str]:
    """Each number of ``x`` printed with ``"%.{digits}g"`` (``digits`` one count or one per
    number); ``nan``, ``inf`` and ``-inf`` as such.

    Examples
    --------
    >>> format_numbers([15.0, 0.125, float("nan"), -float("inf")], [2, 3, 9, 9])
    ['15', '0.125', 'nan', '-inf']
    """
    x = np.asarray(x, dtype=np.float64).ravel()
    p = np.broadcast_to(np.asarray(digits, dtype=np.int64), x.shape)
    return list(map("%.*g".__mod__, zip(p.tolist(), x.tolist())))
