"""ALTA text files of BRDF tables: ``#PARAM_IN`` COS_TH (the 1-D back-scatter slice, such as
MERL's theta_d = 0), SPHERICAL_TL_PL_TV_PV, RUSIN_TH_PH_TD_PD, RUSIN_TH_TD_PD and CARTESIAN.

The layout follows ALTA's ``sources/core/args.h`` (``arguments::parse_header``: header lines
``#KEY value``; ``# text`` is a comment) and ``sources/core/data_storage.cpp``
(``load_data_from_text``, ``read_confidence_interval``): each data line holds the ``#DIM``
n_in coordinates, then the n_out values, then, with ``#VS 2``, the confidence interval as
two **distances** below and above the value (ALTA since its 2017-07-25 fix, commit 302c046:
lower = value - a, upper = value + b). microcyl writes one (a, b) pair per channel, R first;
ALTA's own reader takes the R pair and gives G and B its default ``--dt``. Coordinates and
their conventions: :mod:`gonio.alta_params`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from brdf import validate
from gonio.alta_params import DIMENSION, WRITABLE, from_params, phi_h, to_params
from gonio.atomic import atomic_write
from gonio.errors import FormatError
from gonio.exr import count_missing
from gonio.jsonplain import json_line
from gonio.numtext import parse_number
from gonio.safeopen import open_regular
from gonio.table import Table

__all__ = ["read_alta", "write_alta"]

_KEYS = ("DIM", "PARAM_IN", "PARAM_OUT", "VS", "FORMAT")


def _ranges(*names):
    """(name, lo, hi) of each coordinate: polar angles [0, pi], azimuths [-2 pi, 2 pi]."""
    return tuple((n, 0.0, np.pi) if n.startswith("theta") else (n, -2 * np.pi, 2 * np.pi)
                 for n in names)


#: Accepted coordinates of each #PARAM_IN: (name, lo, hi), radians (COS_TH a cosine,
#: CARTESIAN unit-vector components).
COORDINATE_RANGES = {
    "COS_TH": (("COS_TH", 0.0, 1.0),),
    "RUSIN_TH_TD_PD": _ranges("theta_h", "theta_d", "phi_d"),
    "SPHERICAL_TL_PL_TV_PV": _ranges("theta_l", "phi_l", "theta_v", "phi_v"),
    "RUSIN_TH_PH_TD_PD": _ranges("theta_h", "phi_h", "theta_d", "phi_d"),
    "CARTESIAN": tuple((n, -1.0, 1.0) for n in ("V.x", "V.y", "V.z", "L.x", "L.y", "L.z")),
}


def _split(path: Path):
    """Header dict, comments and (line number, text) data lines of an ALTA text file."""
    with open_regular(path, what="an ALTA table") as fh:   # no link, FIFO or device
        raw = fh.read()
    if raw.startswith(b"\xef\xbb\xbf"):     # a UTF-8 byte-order mark (spreadsheets, editors)
        raw = raw[3:]
    head, comments, data = {}, [], []
    for lineno, line in enumerate(raw.decode("utf-8", errors="replace").splitlines(), 1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            parts = s[1:].split()
            if parts and parts[0] in _KEYS and not s[1:2].isspace():
                head[parts[0]] = parts[1:]
            elif s[1:].strip():
                comments.append(s[1:].strip())
            continue
        data.append((lineno, s))
    if head.get("FORMAT", ["text"])[0] != "text":
        raise FormatError(path, f"#FORMAT {' '.join(head['FORMAT'])}: binary ALTA files are "
                                "not supported (save as text with ALTA's data2data)")
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError:
        raise FormatError(path, "not text; expected an ALTA file") from None
    return head, comments, data


def _check_header(path: Path, head: dict) -> tuple[str, int, int]:
    """The parametrization, its dimension and the number of interval numbers per row."""
    param = " ".join(head.get("PARAM_IN", ["missing"]))
    if param not in DIMENSION:
        raise FormatError(path, f"header #PARAM_IN is {param}, expected one of "
                                + ", ".join(DIMENSION))
    want = {"DIM": [str(DIMENSION[param]), "3"], "PARAM_OUT": ["RGB_COLOR"]}
    for key, value in want.items():
        if head.get(key) != value:
            raise FormatError(path, f"header #{key} is {' '.join(head.get(key, ['missing']))}, "
                                    f"expected {' '.join(value)} (for #PARAM_IN {param})")
    vs = head.get("VS", ["0"])
    if vs not in (["0"], ["1"], ["2"]):
        raise FormatError(path, f"header #VS is {' '.join(vs)}, expected 0, 1 or 2")
    return param, DIMENSION[param], int(vs[0])


def _rows(path: Path, data, n_in: int, vs: int) -> tuple[np.ndarray, list[int]]:
    """Parse the data lines into an (n, columns) array and their line numbers, checking the
    column count and that each field is a number (:mod:`gonio.numtext`: coordinates
    finite decimals, values and intervals also nan or inf)."""
    allowed = {0: (0,), 1: (1, 3), 2: (2, 6)}[vs]
    rows, lines = [], []
    for lineno, s in data:
        fields = s.split()
        extra = len(fields) - n_in - 3
        if extra not in allowed:
            raise FormatError(path, f"line {lineno}: expected {n_in + 3 + allowed[-1]} numbers "
                                    f"({n_in} coordinates, R G B"
                                    + (f", #VS {vs} interval" if vs else "")
                                    + f"), got {len(fields)}")
        try:
            row = [parse_number(x, nonfinite=k >= n_in) for k, x in enumerate(fields)]
        except ValueError as exc:
            raise FormatError(path, f"line {lineno}: not a number in {s[:60]!r}: {exc}") \
                from None
        rows.append(row + [np.nan] * (allowed[-1] - extra))
        lines.append(lineno)
    if not rows:
        raise FormatError(path, "no data rows")
    return np.array(rows), lines


def _check_coordinates(path: Path, param: str, x: np.ndarray, lines: list[int]) -> None:
    """Refuse coordinates outside :data:`COORDINATE_RANGES` (one vectorized test), naming
    the line and the coordinate; CARTESIAN vectors must not be zero."""
    names, lo, hi = zip(*COORDINATE_RANGES[param])
    lo, hi = np.array(lo), np.array(hi)
    bad = ~((x >= lo - 1e-9) & (x <= hi + 1e-9))
    if bad.any():
        k, j = np.unravel_index(int(np.argmax(bad)), bad.shape)
        raise FormatError(path, f"line {lines[k]}: {names[j]} = {x[k, j]:g} is outside "
                                f"[{lo[j]:g}, {hi[j]:g}] (#PARAM_IN {param}, coordinate {j + 1})")
    if param == "CARTESIAN":
        zero = np.all(x[:, :3] == 0, axis=1) | np.all(x[:, 3:] == 0, axis=1)
        if zero.any():
            raise FormatError(path, f"line {lines[int(np.argmax(zero))]}: a zero vector "
                                    "(#PARAM_IN CARTESIAN holds unit vectors V, L)")


def _sigma(extra: np.ndarray, vs: int):
    """sigma (n, 3) from the interval columns: the mean of the two distances (#VS 2)."""
    if vs == 0:
        return None
    if vs == 1:
        return np.abs(extra)
    return 0.5 * (np.abs(extra[:, 0::2]) + np.abs(extra[:, 1::2]))


def read_alta(path) -> Table:
    """Read an ALTA text file of RGB BRDF values (``#PARAM_OUT RGB_COLOR``).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    Table
        One row per data line; f_r in 1/sr. Directions from the ``#PARAM_IN`` coordinates
        (radians) as in :func:`gonio.alta_params.from_params`: COS_TH gives back-scatter
        wi = wo = (sin theta_h, 0, cos theta_h); RUSIN_TH_TD_PD puts phi_h = 0 and sets
        ``meta["isotropic"]``. With ``#VS 2``, sigma is the mean of the two distances below
        and above the value (NaN for channels without an interval); ``#VS 1``, the
        half-width. ``meta`` holds ``alta_param``, the header comments and
        ``missing_values``.

    Raises
    ------
    FormatError
        A binary ALTA file, an unknown ``#PARAM_IN``, a ``#DIM`` or ``#PARAM_OUT`` that does
        not match, a row with the wrong number of fields or a field that is not a number
        (:mod:`gonio.numtext`; nan and inf only as values), a coordinate outside
        :data:`COORDINATE_RANGES` (its line and coordinate are given), or no data. A UTF-8
        byte-order mark is skipped.
    """
    path = Path(path)
    head, comments, data = _split(path)
    param, n_in, vs = _check_header(path, head)
    arr, lines = _rows(path, data, n_in, vs)
    x = arr[:, :n_in]
    _check_coordinates(path, param, x, lines)
    wi, wo = from_params(param, x)
    values = arr[:, n_in:n_in + 3]
    meta = {"source": f"ALTA {path.name}", "file_format": "alta", "file": str(path),
            "alta_param": param, "units": "1/sr", "comments": comments,
            "missing_values": count_missing(values)}
    if param == "COS_TH":
        meta["geometry"] = "back-scatter slice theta_d = 0 (wi = wo, phi = 0)"
    if param == "RUSIN_TH_TD_PD":
        meta["isotropic"] = True
    return Table(wi, wo, values, _sigma(arr[:, n_in + 3:], vs), meta)


def _default_param(table: Table) -> str:
    """COS_TH when every row has wi = wo (to 1e-9) above the horizon, else
    SPHERICAL_TL_PL_TV_PV."""
    off = np.max(np.abs(table.wi - table.wo), axis=1)
    back = np.all(off <= 1e-9) and np.all(table.wi[:, 2] >= 0)
    return "COS_TH" if back else "SPHERICAL_TL_PL_TV_PV"


def _check_param(table: Table, param: str) -> None:
    """Refuse a table that the parametrization cannot hold (one ValueError line)."""
    if param not in WRITABLE:
        raise ValueError(f"write_alta: param {param!r} is not supported; known: "
                         + ", ".join(WRITABLE))
    if param == "COS_TH":
        off = np.max(np.abs(table.wi - table.wo), axis=1)
        if np.any(off > 1e-9):
            raise ValueError(f"write_alta: row {int(np.argmax(off > 1e-9))} has wi != wo; a "
                             "1-D ALTA COS_TH slice holds back-scatter (theta_d = 0) rows only")
        if np.any(table.wi[:, 2] < 0):
            raise ValueError(f"write_alta: row {int(np.argmax(table.wi[:, 2] < 0))} lies below "
                             "the horizon; COS_TH holds cosines in [0, 1]")
    if param == "RUSIN_TH_TD_PD" and not table.meta.get("isotropic"):
        bad = np.abs(phi_h(table.wi, table.wo)) > 1e-9
        if np.any(bad):
            raise ValueError(f"write_alta: param RUSIN_TH_TD_PD (isotropic, phi_h = 0) refused: "
                             f"{int(bad.sum())} rows have phi_h != 0 and table.meta['isotropic'] "
                             "is not true; use RUSIN_TH_PH_TD_PD")


def write_alta(table: Table, path, param: str | None = None, digits: int = 17) -> None:
    """Write a table as an ALTA text file (``#PARAM_OUT RGB_COLOR``, ``#DIM n_in 3``).

    Parameters
    ----------
    table : Table
        f_r in 1/sr. Rows with a missing value (NaN or negative) or a non-finite sigma are
        left out and counted in a header comment.
    path : str or os.PathLike
        Written atomically.
    param : str, optional
        ``#PARAM_IN``: "COS_TH" (every row wi = wo; COS_TH = wi_z), "SPHERICAL_TL_PL_TV_PV",
        "RUSIN_TH_PH_TD_PD", "RUSIN_TH_TD_PD" or "CARTESIAN"; coordinates in radians as in
        :func:`gonio.alta_params.to_params`. Default: COS_TH when every row has wi = wo,
        else SPHERICAL_TL_PL_TV_PV. RUSIN_TH_TD_PD drops phi_h, i.e. turns each pair about
        n to phi_h = 0: allowed when ``table.meta["isotropic"]`` is true or every phi_h is 0
        to 1e-9 rad.
    digits : int
        Significant digits printed; the default 17 round-trips doubles exactly.

    Raises
    ------
    ValueError
        An empty table or one without a row to keep, ``digits`` not an integer >= 1, an
        unknown ``param``, a COS_TH table with a row wi != wo, or a
        RUSIN_TH_TD_PD table that is not isotropic-representable.

    Notes
    -----
    The first line is the comment ``# source: JSON``, ``table.meta["source"]`` as JSON (a
    text in quotes, the object of what was measured); :func:`read_alta` keeps it, as every
    comment, in ``meta["comments"]``. With sigma, the header has ``#VS 2`` and each row
    ends with (sigma, sigma) per channel, R G B: the distances below and above the value,
    as ALTA reads them since 2017.
    """
    digits = validate.integer("digits", digits, lo=1)
    if not isinstance(table, Table):
        raise TypeError(f"write_alta: table must be a gonio.Table; got {type(table).__name__}")
    if len(table) == 0:
        raise ValueError("write_alta: the table is empty")
    if param is not None and not isinstance(param, str):
        raise ValueError(f"write_alta: param must be one of {', '.join(WRITABLE)}; got {param!r}")
    param = _default_param(table) if param is None else param
    _check_param(table, param)
    keep = np.all(table.valid, axis=1)
    if table.sigma is not None:
        keep &= np.all(np.isfinite(table.sigma) & (table.sigma >= 0), axis=1)
    if not keep.any():
        raise ValueError(f"write_alta: every one of the table's {len(table)} rows has a missing "
                         "value or sigma; an ALTA file holds measured rows only (read_alta "
                         "refuses a file without data)")
    cols = [to_params(param, table.wi[keep], table.wo[keep]), table.values[keep]]
    if table.sigma is not None:
        s = table.sigma[keep]
        cols.append(np.repeat(s, 2, axis=1))
    body = np.concatenate(cols, axis=1)
    fmt = f"%.{digits}g"
    with atomic_write(path, "w") as f:
        f.write(f"# source: {json_line(table.meta.get('source', 'microcyl table'))}\n")
        f.write(f"# {int((~keep).sum())} rows with a missing value or sigma left out\n")
        f.write(f"#DIM {DIMENSION[param]} 3\n#PARAM_IN {param}\n#PARAM_OUT RGB_COLOR\n")
        if table.sigma is not None:
            f.write("# interval: distances below and above each value, R G B\n#VS 2\n")
        for row in body:
            f.write("\t".join(fmt % x for x in row) + "\n")
