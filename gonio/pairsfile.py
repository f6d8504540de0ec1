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
to the same float64. The format is specified in docs/guide/formats.rst ("The plan file").

**Arm travel.** :func:`travel` is the cost an order is judged by: the sum, over consecutive
measurements, of the great-circle angle the source arm moves plus the angle the detector arm
moves (degrees). Great-circle angles are a stand-in that needs no instrument's kinematics (a
theta/phi arm moving near the pole turns its azimuth stage further than this says).
:func:`order_for_travel` groups the pairs by source position (the source is set once per
group), sweeps the detector along a short open path within a group (nearest neighbour then
2-opt; detectors on one great circle, such as an in-plane sweep, are swept monotonically
along it), runs each group's sweep from the end nearer where the detector is (so
consecutive sweeps alternate direction, boustrophedon), and orders the groups by the same
heuristic on the source's move plus the move between the groups' mean detector directions.
Beyond :data:`MAX_TOUR` nodes (source positions, or detectors of one source) 2-opt is
left out, and beyond :data:`MAX_GREEDY` the heuristic gives way to a serpentine order (theta
rows, azimuth alternating).
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
from gonio.statefields import one_line

__all__ = ["order_for_travel", "travel", "write_pairs_csv", "read_pairs_header",
           "PLAN_COLUMNS", "MAX_TOUR", "MAX_GREEDY", "MAX_HEADER_BYTES", "MAX_HEADER_LINES"]

#: The leading columns of a plan file.
PLAN_COLUMNS = ("index",) + ANGLES
#: Largest number of source positions, or of detector positions of one source, ordered by
#: nearest neighbour and 2-opt (O(n^2) memory and time); beyond, by nearest neighbour alone
#: up to MAX_GREEDY (O(n) memory, O(n^2) time), then a serpentine order.
MAX_TOUR = 2000
MAX_GREEDY = 10000
_MAX_PASSES = 100
#: The comment lines of a plan file, in bytes and in lines, that :func:`read_pairs_header`
#: reads (and :func:`write_pairs_csv` writes) at most.
MAX_HEADER_BYTES = 1 << 20
MAX_HEADER_LINES = 10000
_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-]*")
_COLUMN = re.compile(r"[a-z_][a-z0-9_]*")
_COMMENT = re.compile(r"#\s*([A-Za-z_][\w.\-]*)\s*:\s?(.*)")
_INTRO = ("# microcyl measurement plan. Angles in degrees, rows in measurement order "
          "(index), comment lines start with #\n")


def _angles(angles_deg, what: str = "angles_deg") -> np.ndarray:
    a = np.asarray(angles_deg, dtype=float)
    if a.ndim != 2 or a.shape[1] != 4:
        raise ValueError(f"{what} must be an (n, 4) array of theta_i, phi_i, theta_o, phi_o "
                         f"in degrees; got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{what}: row {int(np.argmax(~np.isfinite(a).all(axis=1))) + 1} "
                         f"is not finite")
    return a


def _unit(theta_deg, phi_deg) -> np.ndarray:
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def _arc(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Great-circle angle in degrees between unit directions (broadcast)."""
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)))


def travel(angles_deg, order=None) -> float:
    """The arm travel of measuring the rows in ``order`` (default: as given), in degrees.

    The sum over consecutive rows of the great-circle angle between the source directions
    plus that between the detector directions (rows theta_i, phi_i, theta_o, phi_o in
    degrees).

    Examples
    --------
    >>> travel([[30, 0, 30, 180], [30, 0, 60, 180], [40, 0, 60, 180]])
    40.0
    """
    a = _angles(angles_deg)
    if order is not None:
        a = a[np.asarray(order, dtype=np.intp)]
    if len(a) < 2:
        return 0.0
    wi, wo = _unit(a[:, 0], a[:, 1]), _unit(a[:, 2], a[:, 3])
    return float(np.round(np.sum(_arc(wi[1:], wi[:-1]) + _arc(wo[1:], wo[:-1])), 9))


def _two_opt(tour: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """2-opt of a closed tour (best move for each edge in turn, until none gains)."""
    m = len(tour)
    for _ in range(_MAX_PASSES):
        improved = False
        for i in range(m - 2):
            j = np.arange(i + 2, m if i > 0 else m - 1)
            if not len(j):
                continue
            a, b, c, d = tour[i], tour[i + 1], tour[j], tour[(j + 1) % m]
            gain = dist[a, b] + dist[c, d] - dist[a, c] - dist[b, d]
            k = int(np.argmax(gain))
            if gain[k] > 1e-9:
                tour[i + 1:j[k] + 1] = tour[i + 1:j[k] + 1][::-1].copy()
                improved = True
        if not improved:
            break
    return tour


def _open_path(dist: np.ndarray, start: int) -> np.ndarray:
    """A short open path through all nodes of the (m, m) ``dist``: nearest neighbour from
    ``start``, then 2-opt with free ends (a node at distance 0 from all closes the tour)."""
    m = len(dist)
    if m <= 2:
        return np.array([start, 1 - start][:m])
    seen = np.zeros(m, dtype=bool)
    path = [start]
    seen[start] = True
    for _ in range(m - 1):
        row = np.where(seen, np.inf, dist[path[-1]])
        nxt = int(np.argmin(row))
        path.append(nxt)
        seen[nxt] = True
    full = np.zeros((m + 1, m + 1))
    full[:m, :m] = dist
    tour = _two_opt(np.array([m] + path), full)
    cut = int(np.argmax(tour == m))
    return np.concatenate([tour[cut + 1:], tour[:cut]])


def _serpentine(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Rows of equal theta (ascending), azimuth ascending and descending in turn."""
    rows = np.unique(np.round(theta, 6), return_inverse=True)[1]
    ph = np.mod(phi, 360.0)
    return np.lexsort((np.where(rows % 2 == 0, ph, -ph), rows))


def _greedy(units: np.ndarray, extra, start: int) -> np.ndarray:
    """Nearest-neighbour path from ``start``, each row of distances made when needed (O(m)
    memory)."""
    m = len(units)
    seen = np.zeros(m, dtype=bool)
    path = [start]
    seen[start] = True
    for _ in range(m - 1):
        k = path[-1]
        row = np.arccos(np.clip(units @ units[k], -1.0, 1.0))
        if extra is not None:
            row += np.arccos(np.clip(extra @ extra[k], -1.0, 1.0))
        nxt = int(np.argmin(np.where(seen, np.inf, row)))
        path.append(nxt)
        seen[nxt] = True
    return np.array(path)


def _sequence(units: np.ndarray, theta, phi, extra=None) -> np.ndarray:
    """An order of the nodes at ``units`` (m, 3) that keeps moves short (see module notes);
    ``extra`` (m, 3) more unit directions whose moves count too."""
    m, start = len(units), int(np.argmin(theta))
    if m > MAX_GREEDY:
        return _serpentine(theta, phi)
    if m > MAX_TOUR:
        return _greedy(units, extra, start)
    dist = _arc(units[:, None, :], units[None, :, :])
    if extra is not None:
        dist = dist + _arc(extra[:, None, :], extra[None, :, :])
    return _open_path(dist, start)


def order_for_travel(angles_deg) -> np.ndarray:
    """A measurement order of the pairs that limits arm travel (see the module notes).

    Parameters
    ----------
    angles_deg : array_like, shape (n, 4)
        Rows theta_i, phi_i, theta_o, phi_o in degrees.

    Returns
    -------
    ndarray of int, shape (n,)
        A permutation of ``range(n)``: measure row ``order[0]`` first. The same input gives
        the same order.

    Examples
    --------
    >>> a = [[30, 0, 10, 0], [0, 0, 10, 0], [30, 0, 60, 0], [0, 0, 60, 0], [30, 0, 40, 0]]
    >>> order_for_travel(a).tolist()   # normal incidence first, then theta_i 30 swept back
    [1, 3, 2, 4, 0]
    """
    a = _angles(angles_deg)
    n = len(a)
    if n < 2:
        return np.arange(n)
    wi, wo = _unit(a[:, 0], a[:, 1]), _unit(a[:, 2], a[:, 3])
    keys, group = np.unique(np.round(wi, 9), axis=0, return_inverse=True)
    group = group.reshape(-1)
    members = [np.flatnonzero(group == g) for g in range(len(keys))]
    mean_o = np.array([wo[idx].mean(axis=0) for idx in members])
    norm = np.linalg.norm(mean_o, axis=1, keepdims=True)
    mean_o = np.where(norm > 1e-9, mean_o / np.maximum(norm, 1e-300), [0.0, 0.0, 1.0])
    first = [idx[0] for idx in members]
    tour = _sequence(wi[first], a[first, 0], a[first, 1], mean_o)
    out, here = [], None
    for g in tour:
        idx = members[g]
        sweep = idx[_sequence(wo[idx], a[idx, 2], a[idx, 3])]
        if here is not None and _arc(wo[sweep[-1]], here) < _arc(wo[sweep[0]], here):
            sweep = sweep[::-1]
        out.append(sweep)
        here = wo[sweep[-1]]
    return np.concatenate(out).astype(np.intp)


def _header_lines(header) -> list[str]:
    lines = []
    for key, value in (header or {}).items():
        if not isinstance(key, str) or not _KEY.fullmatch(key):
            raise ValueError(f"header key {one_line(key)!r} must be a name of letters, digits, "
                             f"'_', '.', '-' (starting with a letter or '_')")
        lines.append(f"# {key}: {one_line(value).strip()}\n")
    size = sum(len(s.encode()) for s in lines) + len(_INTRO)
    if len(lines) + 1 > MAX_HEADER_LINES or size > MAX_HEADER_BYTES:
        raise ValueError(f"header: {len(lines)} lines, {size} bytes; a plan file's comments "
                         f"hold at most {MAX_HEADER_LINES} lines and {MAX_HEADER_BYTES} bytes")
    return lines


def _column_text(name, values, n: int) -> list[str]:
    if not isinstance(name, str) or not _COLUMN.fullmatch(name) or name in PLAN_COLUMNS:
        raise ValueError(f"column name {one_line(name)!r} must be lower-case letters, digits "
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
            raise ValueError(f"column {name!r}, pair {k + 1}: {one_line(t)!r} must be "
                             f"printable, without ',', ';', tabs or surrounding spaces")
    return text


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
        :func:`gonio.statefields.one_line`).
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
    a = _angles(angles_deg)
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
    try:
        if path.exists() and not path.is_file():
            raise OSError(errno.EINVAL, "not a regular file", str(path))
        with open(path, "rb") as f:
            data = f.read(MAX_HEADER_BYTES + 1)
    except OSError as exc:
        raise OSError(exc.errno, f"cannot read plan file: {exc.strerror}", str(path)) from None
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
            out[m.group(1)] = one_line(m.group(2).strip())
    return out
