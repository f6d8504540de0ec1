"""The plan file: a pairs CSV an operator follows, in an order that limits arm travel.

A plan file is what ``microcyl measure --geometry pairs:FILE`` reads
(:func:`gonio.geomspec.read_pairs_csv`: ``#`` lines are comments, extra columns ignored) with
what an operator needs before a day at the gonioreflectometer::

    # microcyl measurement plan. Angles in degrees, rows in measurement order.
    # fabric: velvet
    # free: gamma1,kd1
    index,theta_i,phi_i,theta_o,phi_o
    1,30.0,0.0,30.0,180.0
    2,30.0,0.0,45.0,180.0

``# key: value`` lines first (:func:`read_pairs_header` reads them back), then the header row
``index,theta_i,phi_i,theta_o,phi_o`` and any extra columns; ``index`` is the measurement
order, 1-based. Angles are written with Python's shortest round-trip repr, so they read back
to the same float64. The format is specified in docs/guide/formats.rst ("Pairs files and the plan file").

The rows are written in :func:`gonio.travel.order_for_travel`'s order (re-exported here
with :func:`gonio.travel.travel`).
"""

from __future__ import annotations

import errno
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from gonio.atomic import atomic_write
from gonio.csvtable import ANGLE_RANGES, ANGLES
from gonio.errors import FormatError
from gonio.geometry import HORIZON_EPS
from gonio.csvcells import comment_text, text_cells
from gonio.terminal import shown
from gonio.safeopen import open_regular
from gonio.travel import check_angles, order_for_travel, travel

__all__ = ["write_pairs_csv", "read_pairs_header", "order_for_travel", "travel",
           "PLAN_COLUMNS", "MAX_HEADER_BYTES", "MAX_HEADER_LINES"]

#: The leading columns of a plan file.
PLAN_COLUMNS = ("index",) + ANGLES
#: The comment lines of a plan file, in bytes and in lines, that :func:`read_pairs_header`
#: reads (and :func:`write_pairs_csv` writes) at most.
MAX_HEADER_BYTES = 1 << 20
MAX_HEADER_LINES = 10000
_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-]*")
_COLUMN = re.compile(r"[a-z_][a-z0-9_]*")
_COMMENT = re.compile(r"#\s*([A-Za-z_][\w.\-]*)\s*:\s?(.*)")
_INTRO = ("# microcyl measurement plan. Angles in degrees, rows in measurement order "
          "(index), comment lines start with #\n")


def _header_lines(header) -> list[str]:
    lines = []
    for key, value in (header or {}).items():
        if not isinstance(key, str) or not _KEY.fullmatch(key):
            raise ValueError(f"header key {shown(key)!r} must be a name of letters, digits, "
                             f"'_', '.', '-' (starting with a letter or '_')")
        lines.append(f"# {key}: {comment_text(shown(value).strip())}\n")
    size = sum(len(s.encode()) for s in lines) + len(_INTRO)
    if len(lines) + 1 > MAX_HEADER_LINES or size > MAX_HEADER_BYTES:
        raise ValueError(f"header: {len(lines)} lines, {size} bytes; a plan file's comments "
                         f"hold at most {MAX_HEADER_LINES} lines and {MAX_HEADER_BYTES} bytes")
    return lines


def _column_text(name, values, n: int) -> list[str]:
    if not isinstance(name, str) or not _COLUMN.fullmatch(name) or name in PLAN_COLUMNS:
        raise ValueError(f"column name {shown(name)!r} must be lower-case letters, digits "
                         f"and '_' (starting with a letter or '_'), not one of "
                         f"{', '.join(PLAN_COLUMNS)}")
    v = np.asarray(values)
    if v.shape != (n,):
        raise ValueError(f"column {name!r} must have one value a pair ({n}); got shape "
                         f"{v.shape}")
    if v.dtype.kind in "biuf":
        return [repr(x) for x in v.astype(float).tolist()] if v.dtype.kind == "f" else \
            [str(x) for x in v.tolist()]
    text = [str(x) for x in v.tolist()]
    for k, t in enumerate(text):
        if not t.isprintable() or any(c in t for c in ",;\t") or t != t.strip():
            raise ValueError(f"column {name!r}, pair {k + 1}: {shown(t)!r} must be "
                             f"printable, without ',', ';', tabs or surrounding spaces")
    return text_cells(text)


def _check_ranges(a: np.ndarray) -> None:
    """theta in [0, 90) above the horizon (where :func:`gonio.pairs_from_angles` keeps the
    pair: a row at the horizon would be dropped by ``measure``), phi in [-360, 360]."""
    for k, name in enumerate(ANGLES):
        if name.startswith("theta"):
            lo, hi = 0.0, 90.0
            bad = (a[:, k] < 0) | ~(np.cos(np.radians(a[:, k])) > HORIZON_EPS)
            allowed = "[0, 90) (above the horizon, where measure keeps the pair)"
        else:
            lo, hi = ANGLE_RANGES["phi"]
            bad = (a[:, k] < lo) | (a[:, k] > hi)
            allowed = f"[{lo:g}, {hi:g}]"
        if bad.any():
            r = int(np.argmax(bad))
            raise ValueError(f"angles_deg row {r + 1}: {name} {float(a[r, k])!r} outside "
                             f"{allowed} degrees")


def write_pairs_csv(path, angles_deg, header: Mapping[str, str] | None = None,
                    columns: Mapping[str, np.ndarray] | None = None,
                    order: bool = True) -> Path:
    """Write a plan file (atomically): comments, then the pairs in measurement order.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file to write.
    angles_deg : array_like, shape (n, 4)
        theta_i, phi_i, theta_o, phi_o in degrees (theta in [0, 90) above the horizon,
        phi in [-360, 360]).
    header : mapping of str to str, optional
        ``# key: value`` lines, in this order: keys names of letters, digits, ``_.-``;
        values written with :func:`str`, one line (unprintable characters escaped,
        :func:`gonio.terminal.shown`).
    columns : mapping of str to array, optional
        Extra columns after the angles, one value a pair (in the rows' given order):
        numbers (floats written to round-trip) or printable text without delimiters.
    order : bool
        Write the rows in :func:`order_for_travel`'s order (default); else as given.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        No pairs, an angle out of range, a bad header key or column (before anything is
        written).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "plan.csv"
    >>> _ = write_pairs_csv(p, [[30, 0, 60, 180], [30, 0, 30, 180]], {"fabric": "velvet"})
    >>> print(p.read_text().splitlines()[1:])
    ['# fabric: velvet', 'index,theta_i,phi_i,theta_o,phi_o', '1,30.0,0.0,30.0,180.0', '2,30.0,0.0,60.0,180.0']
    """
    a = check_angles(angles_deg)
    if not len(a):
        raise ValueError("angles_deg: no pairs (a plan file holds at least one)")
    _check_ranges(a)
    lines = _header_lines(header)
    extra = {name: _column_text(name, v, len(a)) for name, v in (columns or {}).items()}
    perm = order_for_travel(a) if order else np.arange(len(a))
    text = [repr(x) for x in a.reshape(-1).tolist()]
    path = Path(path)
    with atomic_write(path, "w") as f:
        f.write(_INTRO)
        f.writelines(lines)
        f.write(",".join(PLAN_COLUMNS + tuple(extra)) + "\n")
        for k, r in enumerate(perm.tolist(), start=1):
            f.write(",".join([str(k)] + text[4 * r:4 * r + 4]
                             + [col[r] for col in extra.values()]) + "\n")
    return path


def read_pairs_header(path) -> dict[str, str]:
    """The ``# key: value`` lines of a plan file (before its first row), values as written.

    The file is untrusted: at most :data:`MAX_HEADER_BYTES` bytes and
    :data:`MAX_HEADER_LINES` lines of comments are read (the rows after them are not);
    values keep their escapes (one line each). A repeated key keeps its last value.

    Raises
    ------
    OSError
        The file cannot be read.
    ValueError
        Comments longer than the limits, or not UTF-8 text (a :class:`gonio.FormatError`
        naming the file and the line).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "plan.csv"
    >>> read_pairs_header(write_pairs_csv(p, [[0, 0, 30, 0]], {"free": "gamma1,kd1"}))
    {'free': 'gamma1,kd1'}
    """
    path = Path(path)
    try:                    # opened once: no link, FIFO or device (one line, at once)
        with open_regular(path, what="a plan file") as f:
            data = f.read(MAX_HEADER_BYTES + 1)
    except ValueError as exc:
        raise OSError(errno.EINVAL, "cannot read plan file: "
                      + str(exc).removeprefix(f"{path}: "), str(path)) from None
    out: dict[str, str] = {}
    lines = data.split(b"\n")
    for lineno, raw in enumerate(lines, start=1):
        raw = raw.strip()
        if lineno == 1 and raw.startswith(b"\xef\xbb\xbf"):      # a byte-order mark
            raw = raw[3:].strip()
        if not raw:
            continue
        if not raw.startswith(b"#"):
            break                                              # the first row
        if lineno > MAX_HEADER_LINES or (lineno == len(lines)
                                         and len(data) > MAX_HEADER_BYTES):
            raise FormatError(path, f"comment lines longer than {MAX_HEADER_LINES} lines or "
                                    f"{MAX_HEADER_BYTES} bytes; not a plan file")
        try:
            line = raw.decode("utf-8")
        except UnicodeDecodeError:
            raise FormatError(path, f"line {lineno}: not UTF-8 text; not a plan file") from None
        m = _COMMENT.fullmatch(line)
        if m:
            out[m.group(1)] = shown(m.group(2).strip())
    return out
