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

from gonio.alta_params import DIMENSION, WRITABLE, from_params, phi_h, to_params
from gonio.atomic import atomic_write
from gonio.errors import FormatError
from gonio.exr import count_missing
from gonio.table import Table

__all__ = ["read_alta", "write_alta"]

_KEYS = ("DIM", "PARAM_IN", "PARAM_OUT", "VS", "FORMAT")


def _split(path: Path):
    """Header dict, comments and (line number, text) data lines of an ALTA text file."""
    raw = path.read_bytes()
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


def _rows(path: Path, data, n_in: int, vs: int) -> np.ndarray:
    """Parse the data lines into an (n, columns) array, checking the column count."""
    allowed = {0: (0,), 1: (1, 3), 2: (2, 6)}[vs]
    rows = []
    for lineno, s in data:
        fields = s.split()
        extra = len(fields) - n_in - 3
        if extra not in allowed:
            raise FormatError(path, f"line {lineno}: expected {n_in + 3 + allowed[-1]} numbers "
                                    f"({n_in} coordinates, R G B"
                                    + (f", #VS {vs} interval" if vs else "")
                                    + f"), got {len(fields)}")
        try:
            rows.append([float(x) for x in fields] + [np.nan] * (allowed[-1] - extra))
        except ValueError:
            raise FormatError(path, f"line {lineno}: not a number in {s[:60]!r}") from None
    if not rows:
        raise FormatError(path, "no data rows")
    return np.array(rows)


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
        not match, a row with the wrong number of fields or a non-number (its line number
        is given), COS_TH outside [0, 1], or no data.
    """
    path = Path(path)
    head, comments, data = _split(path)
    param, n_in, vs = _check_header(path, head)
    arr = _rows(path, data, n_in, vs)
    x = arr[:, :n_in]
    if param == "COS_TH" and not np.all((x[:, 0] >= 0) & (x[:, 0] <= 1)):
        bad = int(np.flatnonzero(~((x[:, 0] >= 0) & (x[:, 0] <= 1)))[0])
        raise FormatError(path, f"data row {bad + 1}: COS_TH = {x[bad, 0]} outside [0, 1]")
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
    """COS_TH when every row has wi = wo (to 1e-9), else SPHERICAL_TL_PL_TV_PV."""
    off = np.max(np.abs(table.wi - table.wo), axis=1)
    return "COS_TH" if np.all(off <= 1e-9) else "SPHERICAL_TL_PL_TV_PV"


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
        An empty table, an unknown ``param``, a COS_TH table with a row wi != wo, or a
        RUSIN_TH_TD_PD table that is not isotropic-representable.

    Notes
    -----
    With sigma, the header has ``#VS 2`` and each row ends with (sigma, sigma) per channel,
    R G B: the distances below and above the value, as ALTA reads them since 2017.
    """
    if len(table) == 0:
        raise ValueError("write_alta: the table is empty")
    param = _default_param(table) if param is None else param
    _check_param(table, param)
    keep = np.all(table.valid, axis=1)
    if table.sigma is not None:
        keep &= np.all(np.isfinite(table.sigma) & (table.sigma >= 0), axis=1)
    cols = [to_params(param, table.wi[keep], table.wo[keep]), table.values[keep]]
    if table.sigma is not None:
        s = table.sigma[keep]
        cols.append(np.repeat(s, 2, axis=1))
    body = np.concatenate(cols, axis=1)
    fmt = f"%.{digits}g"
    with atomic_write(path, "w") as f:
        f.write("# " + " ".join(str(table.meta.get("source", "microcyl table")).split()) + "\n")
        f.write(f"# {int((~keep).sum())} rows with a missing value or sigma left out\n")
        f.write(f"#DIM {DIMENSION[param]} 3\n#PARAM_IN {param}\n#PARAM_OUT RGB_COLOR\n")
        if table.sigma is not None:
            f.write("# interval: distances below and above each value, R G B\n#VS 2\n")
        for row in body:
            f.write("\t".join(fmt % x for x in row) + "\n")
