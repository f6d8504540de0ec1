"""BRDF tables read from CSV text (specification: docs/guide/formats.rst, "The CSV table
format"); :mod:`gonio.csvwrite` writes them."""

from __future__ import annotations

import dataclasses
import json
import re
import warnings
from pathlib import Path

import numpy as np

from gonio.errors import FormatError, TableWarning
from gonio.exr import count_missing, from_angles
from gonio.numtext import is_number, parse_number
from gonio.safeopen import read_bytes
from gonio.table import Table, check_meta_size

__all__ = ["read_csv", "read_rows", "parse_columns", "delimiter", "CsvRows",
           "looks_like_radians", "ANGLES", "ANGLE_RANGES", "DELIMITERS"]

ANGLES = ("theta_i", "phi_i", "theta_o", "phi_o")
#: Accepted angles in degrees: theta is a polar angle (beyond 90 below the horizon, where
#: f_r = 0), phi an azimuth, either way round (a spreadsheet's 0..360 or -180..180).
ANGLE_RANGES = {"theta": (0.0, 180.0), "phi": (-360.0, 360.0)}
#: A metadata comment line, `# key: value` (the key, then the value as JSON or text).
KEY_PATTERN = re.compile(r"^([A-Za-z_][\w.\-]*)\s*:\s?(.*)$")
_VALUE_SETS = (("r", "g", "b"), ("value",))
_SIGMA_SETS = (("sigma_r", "sigma_g", "sigma_b"), ("sigma",))
#: The delimiters of a CSV file (found in its header line), and their names in messages.
DELIMITERS = {",": "comma", ";": "semicolon", "\t": "tab"}


def _parse_value(text: str) -> float:
    """A value or sigma field: a number, nan or inf; an empty field is NaN (missing)."""
    return float("nan") if text == "" else parse_number(text, nonfinite=True)


@dataclasses.dataclass(frozen=True)
class CsvRows:
    """The text of a CSV file with ``#`` comments, split but not yet interpreted.

    Attributes
    ----------
    meta : dict
        The ``# key: value`` comments (JSON values decoded when they parse).
    header : list of str or None
        The first non-comment row (column names, in lower case), None if there is none.
    header_line : int
        Its line number (0 without a header).
    rows : list of (int, list of str)
        Each data row's line number and fields (stripped).
    """

    meta: dict
    header: list[str] | None
    header_line: int
    rows: list[tuple[int, list[str]]]


def read_rows(path) -> CsvRows:
    r"""Split a CSV file into comments, header and data rows (the layer under :func:`read_csv`
    and the ``pairs:FILE.csv`` geometry reader).

    The columns are separated by commas, semicolons or tabs, whichever the header line holds
    (:func:`delimiter`); column names are read in any case (``R,G,B`` is ``r,g,b``).

    Raises
    ------
    OSError
        The file cannot be read.
    FormatError
        Not UTF-8 text, a header without a known delimiter, a data row with another number
        of fields than the header (its line number is given), or metadata over 1 MiB.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "p.csv"
    >>> _ = p.write_text("# source: \"doc\"\ntheta_i,phi_i\n30, 0\n")
    >>> r = read_rows(p)
    >>> r.meta, r.header, r.rows
    ({'source': 'doc'}, ['theta_i', 'phi_i'], [(3, ['30', '0'])])
    """
    path = Path(path)
    try:        # opened once: no link, FIFO or device; a spreadsheet's byte-order mark dropped
        text = read_bytes(path, max_bytes=None, what="a CSV table").decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise FormatError(path, f"not UTF-8 text (byte {exc.start}); not a CSV table") from None
    meta: dict = {}
    header, header_line, rows, sep, meta_bytes = None, 0, [], ",", 0
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            m = KEY_PATTERN.match(stripped[1:].strip())
            if m:
                key, raw = m.group(1), m.group(2).strip()
                meta_bytes += len(raw)
                check_meta_size(path, meta_bytes, f"line {lineno}: the metadata so far")
                try:
                    meta[key] = json.loads(raw)
                except json.JSONDecodeError:
                    meta[key] = raw
                except RecursionError:
                    raise FormatError(path, f"line {lineno}: metadata {key!r} is nested too "
                                            f"deeply") from None
            continue
        if header is None:
            sep = delimiter(path, lineno, stripped)
            header, header_line = [c.strip().lower() for c in stripped.split(sep)], lineno
            continue
        fields = [c.strip() for c in stripped.split(sep)]
        if len(fields) != len(header):
            raise FormatError(path, f"line {lineno}: expected {len(header)} columns "
                                    f"({','.join(header)}), got {len(fields)}"
                                    + _other_delimiter(stripped, sep))
        rows.append((lineno, fields))
    return CsvRows(meta, header, header_line, rows)


def delimiter(path, lineno: int, header: str) -> str:
    """The delimiter of a CSV file, from its header line: the one of comma, semicolon and
    tab that it holds (comma for a header of one name).

    Raises
    ------
    FormatError
        A header holding two of them, or none but another separator (a space, ``|``),
        naming what was found.

    Examples
    --------
    >>> delimiter("t.csv", 1, "theta_i;phi_i;theta_o;phi_o;value")
    ';'
    >>> delimiter("t.csv", 1, "theta_i|phi_i|theta_o|phi_o|value")
    Traceback (most recent call last):
    ...
    gonio.errors.FormatError: t.csv: line 1: found '|' between the column names; expected \
comma, semicolon or tab
    """
    found = [d for d in DELIMITERS if d in header]
    if len(found) == 1:
        return found[0]
    if found:
        raise FormatError(path, f"line {lineno}: the header holds both "
                                + " and ".join(DELIMITERS[d] for d in found)
                                + "; separate the columns by one of them")
    other = re.search(r"[^\w.\-]+", header)
    if other:
        raise FormatError(path, f"line {lineno}: found {other.group()!r} between the column "
                                "names; expected comma, semicolon or tab")
    return ","


def _other_delimiter(row: str, sep: str) -> str:
    """A note for a row split into the wrong number of fields that holds another delimiter."""
    other = [DELIMITERS[d] for d in DELIMITERS if d != sep and d in row]
    return (f"; the header is split on {DELIMITERS[sep]}s, this row holds "
            f"{' and '.join(other)}s" if other else "")


def read_csv(path) -> Table:
    """Read a CSV BRDF table.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    Table
        ``meta`` holds the ``# key: value`` comments (JSON values decoded when they parse)
        and ``missing_values``, the count of NaN (or empty) and negative values, which are
        kept and flagged in ``Table.valid``.

    Raises
    ------
    FormatError
        No header, unknown or missing columns, or a bad row (its line number is given, and
        for a bad field its column): a field that is not a decimal number (nan, inf or empty
        only as values, :mod:`gonio.numtext`), or an angle outside :data:`ANGLE_RANGES`.
    """
    path = Path(path)
    text = read_rows(path)
    meta, header = text.meta, text.header
    if header is None:
        raise FormatError(path, "no header row (expected theta_i,phi_i,theta_o,phi_o,r,g,b)")
    _check_header(path, text.header_line, header)
    if not text.rows:
        raise FormatError(path, "no data rows after the header")
    data = parse_columns(path, header, text.rows)
    col = {name: data[:, k] for k, name in enumerate(header)}
    ang = [np.radians(col[a]) for a in ANGLES]
    values = (np.stack([col[c] for c in "rgb"], axis=1) if "r" in col
              else np.repeat(col["value"][:, None], 3, axis=1))
    sigma = None
    if "sigma_r" in col:
        sigma = np.stack([col[f"sigma_{c}"] for c in "rgb"], axis=1)
    elif "sigma" in col:
        sigma = np.repeat(col["sigma"][:, None], 3, axis=1)
    meta["missing_values"] = count_missing(values)
    meta.setdefault("file_format", "csv")
    return Table(from_angles(ang[0], ang[1]), from_angles(ang[2], ang[3]), values, sigma, meta)


def parse_columns(path, header, rows, columns=None) -> np.ndarray:
    """The data rows' ``columns`` (default: all of ``header``) as an (n, k) array.

    Angles are decimal numbers (:mod:`gonio.numtext`), finite and within
    :data:`ANGLE_RANGES` (one vectorized check); other columns numbers, nan, inf or empty
    (NaN). ``rows`` are :attr:`CsvRows.rows`.

    Raises
    ------
    FormatError
        Naming the file, the line and the column of the first bad field.

    Warns
    -----
    TableWarning
        When ``columns`` hold the four angles and every one of them lies within the range
        it would have in radians, not all zero (:func:`looks_like_radians`).
    """
    columns = list(header if columns is None else columns)
    idx = [header.index(c) for c in columns]
    is_angle = [c in ANGLES for c in columns]
    out = np.empty((len(rows), len(columns)))
    for k, (lineno, fields) in enumerate(rows):
        for j, (c, angle) in enumerate(zip(idx, is_angle)):
            x = fields[c]
            try:
                out[k, j] = parse_number(x) if angle else _parse_value(x)
            except ValueError as exc:
                if angle and is_number(x, nonfinite=True):
                    exc = f"angles must be finite numbers; got {x!r}"
                hint = (f"; a decimal comma? write {x.replace(',', '.')}"
                        if re.fullmatch(r"[+-]?[0-9]+,[0-9]+", x) else "")
                raise FormatError(path, f"line {lineno}: {exc}, in column {columns[j]}"
                                        + hint) from None
    for j, name in enumerate(columns):
        if not is_angle[j]:
            continue
        lo, hi = ANGLE_RANGES[name[:-2]]
        bad = ~((out[:, j] >= lo) & (out[:, j] <= hi))
        if bad.any():
            lineno, fields = rows[int(np.argmax(bad))]
            raise FormatError(path, f"line {lineno}: {name} = {fields[idx[j]]} is outside "
                                    f"[{lo:g}, {hi:g}] degrees")
    if all(a in columns for a in ANGLES) and looks_like_radians(
            out[:, [columns.index(a) for a in ANGLES]]):
        warnings.warn(f"{path}: every angle is within the range of radians (theta at most "
                      "pi, |phi| at most 2 pi); angles are read in degrees: were radians "
                      "written?", TableWarning, stacklevel=2)
    return out


def looks_like_radians(angles) -> bool:
    """Whether (n, 4) angles theta_i, phi_i, theta_o, phi_o, read as degrees, look like
    radians: every theta at most pi and every phi at most 2 pi in magnitude (1e-3 over for
    rounding: ``3.1416``), and not all zero.

    This holds for every table written in radians, including those whose azimuths run to
    pi or 2 pi (a table with every angle at most pi/2 is the first of them), and for no
    table of degrees that a gonioreflectometer measures: every direction within 3.2 deg of
    the normal, within 6.3 deg of the warp.

    Examples
    --------
    >>> looks_like_radians([[0.5236, 0, 0.5236, 3.1416]]), looks_like_radians([[30, 0, 30, 180]])
    (True, False)
    >>> looks_like_radians([[0, 0, 0, 0]])
    False
    """
    a = np.abs(np.asarray(angles, dtype=np.float64))
    if not a.size or not a.any():
        return False
    return bool(np.all(a[:, 0::2] <= np.pi + 1e-3) and np.all(a[:, 1::2] <= 2 * np.pi + 1e-3))


def _check_header(path, lineno, header):
    known = set(ANGLES) | {c for s in _VALUE_SETS + _SIGMA_SETS for c in s}
    unknown = [c for c in header if c not in known]
    if unknown:
        raise FormatError(path, f"line {lineno}: unknown column(s) {', '.join(unknown)}; "
                                "the header must be theta_i,phi_i,theta_o,phi_o then r,g,b or "
                                "value, then optionally sigma_r,sigma_g,sigma_b or sigma")
    if len(set(header)) != len(header):
        raise FormatError(path, f"line {lineno}: repeated column in header {','.join(header)}")
    missing = [a for a in ANGLES if a not in header]
    if missing:
        raise FormatError(path, f"line {lineno}: missing column(s) {', '.join(missing)}")
    for group, what in ((_VALUE_SETS, "values"), (_SIGMA_SETS, "sigma")):
        present = [s for s in group if any(c in header for c in s)]
        if len(present) > 1:
            raise FormatError(path, f"line {lineno}: both {','.join(present[0])} and "
                                    f"{','.join(present[1])} columns for {what}")
        if present and not all(c in header for c in present[0]):
            raise FormatError(path, f"line {lineno}: missing column(s) " + ", ".join(
                c for c in present[0] if c not in header))
        if what == "values" and not present:
            raise FormatError(path, f"line {lineno}: missing columns r,g,b (or value)")
