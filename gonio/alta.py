"""ALTA 1-D BRDF slices (``#PARAM_IN COS_TH``), such as MERL's back-scatter slice theta_d = 0."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gonio.atomic import atomic_write
from gonio.errors import FormatError
from gonio.exr import count_missing
from gonio.table import Table

__all__ = ["read_alta", "write_alta"]


def read_alta(path) -> Table:
    """Read a 1-D ALTA slice (``#DIM 1 3``, ``#PARAM_IN COS_TH``, ``#PARAM_OUT RGB_COLOR``).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    Table
        One row per data line: the slice theta_d = 0, i.e. back-scatter with
        wi = wo = (sin theta_h, 0, cos theta_h), theta_h = acos(COS_TH), phi = 0; RGB f_r in
        1/sr. ``meta`` holds the header comments and ``missing_values``.

    Raises
    ------
    FormatError
        Missing or different ``#DIM`` / ``#PARAM_IN`` / ``#PARAM_OUT``, a row that is not
        four numbers (its line number is given), COS_TH outside [0, 1], or no data.
    """
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except UnicodeDecodeError:
        raise FormatError(path, "not text; expected an ALTA file") from None
    head, rows, comments = {}, [], []
    for lineno, line in enumerate(lines, start=1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            parts = s[1:].split()
            if parts and parts[0] in ("DIM", "PARAM_IN", "PARAM_OUT", "VS"):
                head[parts[0]] = parts[1:]
            elif s[1:].strip():
                comments.append(s[1:].strip())
            continue
        fields = s.split()
        if len(fields) != 4:
            raise FormatError(path, f"line {lineno}: expected 4 numbers (COS_TH R G B), "
                                    f"got {len(fields)}")
        try:
            rows.append([float(x) for x in fields])
        except ValueError:
            raise FormatError(path, f"line {lineno}: not a number in {s[:60]!r}") from None
    expect = {"DIM": ["1", "3"], "PARAM_IN": ["COS_TH"], "PARAM_OUT": ["RGB_COLOR"]}
    for key, want in expect.items():
        if head.get(key) != want:
            raise FormatError(path, f"header #{key} is {' '.join(head.get(key, ['missing']))}, "
                                    f"expected {' '.join(want)} (wrong magic for a 1-D slice)")
    if not rows:
        raise FormatError(path, "no data rows")
    data = np.array(rows)
    cos_th = data[:, 0]
    if not np.all((cos_th >= 0) & (cos_th <= 1)):
        bad = int(np.flatnonzero(~((cos_th >= 0) & (cos_th <= 1)))[0])
        raise FormatError(path, f"data row {bad + 1}: COS_TH = {cos_th[bad]} outside [0, 1]")
    sin_th = np.sqrt(1.0 - cos_th ** 2)
    w = np.stack([sin_th, np.zeros_like(sin_th), cos_th], axis=1)
    values = data[:, 1:]
    meta = {"source": f"ALTA {path.name}", "file_format": "alta", "file": str(path),
            "geometry": "back-scatter slice theta_d = 0 (wi = wo, phi = 0)", "units": "1/sr",
            "comments": comments, "missing_values": count_missing(values)}
    return Table(w, w.copy(), values, None, meta)


def write_alta(table: Table, path, digits: int = 15) -> None:
    """Write a back-scatter table (wi = wo in every row) as a 1-D ALTA COS_TH slice.

    Parameters
    ----------
    table : Table
        Every row must have wi = wo (to 1e-9); COS_TH = wi_z.
    path : str or os.PathLike
        Written atomically.
    digits : int
        Significant digits printed.

    Raises
    ------
    ValueError
        A row with wi != wo (not a theta_d = 0 slice), or an empty table.
    """
    if len(table) == 0:
        raise ValueError("write_alta: the table is empty")
    off = np.max(np.abs(table.wi - table.wo), axis=1)
    if np.any(off > 1e-9):
        raise ValueError(f"write_alta: row {int(np.argmax(off > 1e-9))} has wi != wo; a 1-D "
                         "ALTA COS_TH slice holds back-scatter (theta_d = 0) rows only")
    fmt = f"%.{digits}g"
    with atomic_write(path, "w") as f:
        f.write(f"# {table.meta.get('source', 'microcyl table')}: slice theta_d = 0\n")
        f.write("#DIM 1 3\n#PARAM_IN  COS_TH\n#PARAM_OUT RGB_COLOR\n")
        for w, v in zip(table.wi, table.values):
            f.write("\t".join(fmt % x for x in (w[2], *v)) + "\n")
