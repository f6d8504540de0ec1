"""CSV cells a spreadsheet shows as text, never evaluates: :func:`text_cell`, through which
every text cell microcyl writes into a CSV file goes (a batch's ``summary.csv``, a report's
data files, ``plot table --data``, a fit's ``results.csv``, a plan file, a table's metadata).

A spreadsheet evaluates a cell that begins with ``=``, ``+``, ``-``, ``@``, a tab or a carriage
return (``=HYPERLINK(...)``, ``@SUM(...)``): a table's file name or a row copied from a
colleague's ``summary.json`` would then run in the reader's spreadsheet. Such a text cell is
written with a single quote in front (OWASP's advice for CSV injection), which a spreadsheet
shows as text; a number, negative ones included, stays a number.
"""

from __future__ import annotations

import re

__all__ = ["FORMULA_START", "text_cell", "text_cells", "comment_json", "comment_text"]

#: The first characters that make a spreadsheet evaluate a cell.
FORMULA_START = ("=", "+", "-", "@", "\t", "\r")
_NUMBER = re.compile(r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf|infinity|nan)",
                     re.IGNORECASE)


def text_cell(value):
    """``value`` as a CSV cell a spreadsheet does not evaluate: a text beginning with one of
    :data:`FORMULA_START` (and not a number written as text, such as ``-0.25``) gets a
    single quote in front; anything else is returned as it is.

    Examples
    --------
    >>> text_cell('=HYPERLINK("http://x","y")'), text_cell("@SUM(A1)"), text_cell("\\t=1")
    ('\\'=HYPERLINK("http://x","y")', "'@SUM(A1)", "'\\t=1")
    >>> text_cell("-0.25"), text_cell("-1e-3"), text_cell(-2.5), text_cell("silk")
    ('-0.25', '-1e-3', -2.5, 'silk')
    >>> text_cell("-1+cmd")
    "'-1+cmd"
    """
    if (isinstance(value, str) and value.startswith(FORMULA_START)
            and not _NUMBER.fullmatch(value)):
        return "'" + value
    return value


def text_cells(values) -> list:
    """:func:`text_cell` of each of ``values`` (a row of cells).

    Examples
    --------
    >>> text_cells(["=1+1", 3, "-3", None])
    ["'=1+1", 3, '-3', None]
    """
    return [text_cell(v) for v in values]


def comment_json(text: str) -> str:
    """A JSON text written into a CSV comment line (``# key: VALUE``) with no cell after a
    comma that begins with a formula character: ``,=`` (``,+``, ``,-``, ``,@``) inside a JSON
    string written as ``,\\u003d`` (...), which JSON reads back as the same text. (Between
    JSON items, ``json.dumps`` writes a space after each comma; tabs and carriage returns are
    escaped by JSON already.)

    Examples
    --------
    >>> import json
    >>> t = comment_json(json.dumps("x,=HYPERLINK(1)"))
    >>> t, json.loads(t)
    ('"x,\\\\u003dHYPERLINK(1)"', 'x,=HYPERLINK(1)')
    >>> comment_json(json.dumps([1, -2, "a,-b"]))
    '[1, -2, "a,\\\\u002db"]'
    """
    return re.sub(r",([=+\-@])", lambda m: f",\\u{ord(m[1]):04x}", text)


def comment_text(text: str) -> str:
    """A plain text written into a CSV comment line (``# key: VALUE``) with no cell after a
    comma that a spreadsheet evaluates: each such cell gets a single quote in front
    (:func:`text_cell`); a text without one is returned as it is.

    Examples
    --------
    >>> comment_text("gamma1,kd1"), comment_text("a,=HYPERLINK(1),-2")
    ('gamma1,kd1', "a,'=HYPERLINK(1),-2")
    """
    return ",".join(text_cell(part) for part in text.split(","))
