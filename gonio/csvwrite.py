"""BRDF tables written as CSV text (specification: docs/guide/formats.rst, "The CSV table
format"); :mod:`gonio.csvtable` reads them."""

from __future__ import annotations

import json

import numpy as np

from brdf import validate
from gonio.atomic import atomic_write
from gonio.csvcells import comment_json
from gonio.csvtable import ANGLES, KEY_PATTERN
from gonio.jsonplain import plain
from gonio.numtext import column_digits, float32_column, format_numbers
from gonio.table import Table

__all__ = ["write_csv"]

_WRITE_ROWS = 65536     # rows formatted at a time (their strings held in memory)


def write_csv(table: Table, path, digits: int | None = None) -> None:
    """Write a table as CSV (atomically).

    Parameters
    ----------
    table : Table
    path : str or os.PathLike
    digits : int, optional
        Significant digits printed for every number (angles in degrees, f_r in 1/sr). By
        default 9, except for float32 data: a column whose every value is a float32 (an
        OpenEXR table's channels; for angles, radians within a few float64 ulps of a
        float32) is written with the fewest digits that read back to the same float32
        (``15``, not ``15.0000004``; :func:`gonio.numtext.float32_shortest`).

    Raises
    ------
    ValueError
        An empty table, or ``digits`` not an integer >= 1.

    Notes
    -----
    A grey table (r = g = b everywhere) is written with one ``value`` column (and ``sigma``);
    otherwise ``r,g,b`` (and ``sigma_r,sigma_g,sigma_b``). ``meta`` goes in ``# key: value``
    comment lines, each value as JSON. Missing values are written as ``nan``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> t = Table([[0, 0, 1.0]], [[0.6, 0, 0.8]], [0.25], meta={"source": "doc"})
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
    >>> write_csv(t, p)
    >>> print(p.read_text().splitlines()[-2:])
    ['theta_i,phi_i,theta_o,phi_o,value', '0,0,36.8698976,0,0.25']
    """
    if digits is not None:
        digits = validate.integer("digits", digits, lo=1)
    if not isinstance(table, Table):
        raise TypeError(f"write_csv: table must be a gonio.Table; got {type(table).__name__}")
    if len(table) == 0:
        raise ValueError("write_csv: table is empty (0 rows); a CSV table holds at least one "
                         "row, as read_csv requires")
    cols, data = _columns(table)
    angles = table.angles
    fields = [_angle_text(angles[:, k], digits, name.startswith("phi"))
              for k, name in enumerate(ANGLES)]
    fields += [column_digits(data[:, k], digits) for k in range(data.shape[1])]
    with atomic_write(path, "w") as f:
        f.write("# microcyl BRDF table. Angles in degrees, f_r in 1/sr, "
                "comment lines start with #\n")
        for key, value in table.meta.items():
            if KEY_PATTERN.match(f"{key}: x"):
                f.write(f"# {key}: {comment_json(json.dumps(plain(value)))}\n")
        f.write(",".join(cols) + "\n")
        for a in range(0, len(table), _WRITE_ROWS):
            rows = zip(*(format_numbers(x[a:a + _WRITE_ROWS],
                                        p[a:a + _WRITE_ROWS] if np.ndim(p) else p)
                         for x, p in fields))
            f.write("\n".join(map(",".join, rows)) + "\n")


def _columns(table: Table) -> tuple[list[str], np.ndarray]:
    """The column names (angles first) and the (n, 1..6) values and sigma to write: one
    ``value`` (and ``sigma``) column for a grey table, else r, g, b (and sigma_r, ...)."""
    def same(a):
        return bool(np.array_equal(a[:, 0], a[:, 1], equal_nan=True)
                    and np.array_equal(a[:, 0], a[:, 2], equal_nan=True))
    grey = same(table.values) and (table.sigma is None or same(table.sigma))
    cols = list(ANGLES) + (["value"] if grey else ["r", "g", "b"])
    data = [table.values[:, :1] if grey else table.values]
    if table.sigma is not None:
        cols += ["sigma"] if grey else ["sigma_r", "sigma_g", "sigma_b"]
        data.append(table.sigma[:, :1] if grey else table.sigma)
    return cols, np.concatenate(data, axis=1)


def _angle_text(a: np.ndarray, digits: int | None, azimuth: bool):
    """(degrees, digits) to print an angle column given in radians: ``digits`` when given;
    else float32 angles (to 16 float64 ulps: directions made from float32 angles and back)
    with the fewest digits that read back to that float32, as
    :func:`gonio.numtext.float32_column` has it. An azimuth stored as float32 pi (above pi)
    comes back from its direction as -pi + 2e-7, and is written as 180."""
    if digits is not None:
        return np.degrees(a), digits

    def near32(v):
        return np.abs(v - v.astype(np.float32)) <= 16 * np.spacing(np.abs(v))
    near = near32(a)
    if azimuth:
        turned = np.where(a < 0, a + 2 * np.pi, a - 2 * np.pi)
        turn = ~near & (np.abs(a) > 3) & near32(turned)
        a, near = np.where(turn, turned, a), near | turn
    return float32_column(np.degrees(a), a.astype(np.float32), near, np.radians, slack=8)
