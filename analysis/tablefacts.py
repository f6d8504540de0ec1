"""What a BRDF table holds, as plain data (``microcyl info``): its source, size, the ranges of
its angles (degrees) and values (f_r in the table's units) and its missing values."""

from __future__ import annotations

import numpy as np

import gonio

__all__ = ["table_facts"]


def table_facts(table) -> dict:
    """What a table holds, as plain data (``microcyl info --json``): its source as the
    table's metadata has it (a text, or the JSON object of what was measured), angles in
    degrees over the rows with data, value ranges per channel (f_r in the table's units),
    missing counts.

    Examples
    --------
    >>> import brdf
    >>> from gonio.table import Table
    >>> wi = brdf.directions.from_angles(np.radians([0.0, 30.0]), np.radians([0.0, 90.0]))
    >>> wo = brdf.directions.from_angles(np.radians([45.0, 60.0]), np.radians([180.0, 0.0]))
    >>> f = table_facts(Table(wi, wo, np.array([[0.1, 0.2, 0.3], [np.nan, 0.5, -1.0]])))
    >>> f["rows"], f["angles_deg"]["theta_o"], f["values"]["B"], f["missing"]["values"]
    (2, [45.0, 60.0], [0.3, 0.3], 2)
    """
    ang = np.degrees(table.angles)
    valid = table.valid
    data = valid.any(axis=1)          # a MERL file lists its empty bins below the horizon too
    sel = ang[data] if data.any() else ang
    values = {}
    for c, name in enumerate("RGB"):
        v = table.values[valid[:, c], c]
        values[name] = [float(v.min()), float(v.max())] if v.size else None
    return {
        "source": gonio.plain(table.meta.get("source", "unknown"), nonfinite="null"),
        "format": str(table.meta.get("file_format", "unknown")),
        "rows": len(table), "units": str(table.meta.get("units", "1/sr")),
        "angles_deg": {name: [float(sel[:, k].min()), float(sel[:, k].max())]
                       for k, name in enumerate(("theta_i", "phi_i", "theta_o", "phi_o"))},
        "angles_over": "all rows" if data.all() else "rows with data",
        "values": values,
        "missing": {"values": int(np.count_nonzero(~valid)), "of": int(valid.size),
                    "nan": int(np.count_nonzero(np.isnan(table.values))),
                    "negative": int(np.count_nonzero(table.values < 0)),
                    "infinite": int(np.count_nonzero(np.isinf(table.values))),
                    "rows_with_any": int(np.count_nonzero(~valid.all(axis=1)))},
        "sigma": None if table.sigma is None else [float(np.nanmin(table.sigma)),
                                                   float(np.nanmax(table.sigma))],
    }
