"""The batch's summary: one row per table in ``summary.csv`` and ``summary.json``.

Only the client writes them, atomically (:func:`gonio.atomic_write`), after each fit ends, so
that the files always hold every finished fit and never a half-written row.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import gonio

__all__ = ["BatchSummary", "SUMMARY_CSV", "SUMMARY_JSON", "SCHEMA", "FIRST_COLUMNS"]

SUMMARY_CSV = "summary.csv"
SUMMARY_JSON = "summary.json"
SCHEMA = ("microcyl-batch", 1)
#: The columns every row has, first in the CSV.
FIRST_COLUMNS = ("name", "status", "error", "steps", "wall_s")


class BatchSummary:
    """The rows of a batch, by table name, in the batch's order.

    Parameters
    ----------
    out_dir : path
        The batch's folder; an existing ``summary.json`` there is read (a rerun).

    Raises
    ------
    ValueError
        ``summary.json`` exists but is not a batch summary (naming the file).
    """

    def __init__(self, out_dir):
        self.dir = Path(out_dir)
        self.rows: dict[str, dict] = {}
        path = self.dir / SUMMARY_JSON
        if path.exists():
            try:
                doc = json.loads(path.read_text(encoding="utf-8"))
                ok = (isinstance(doc, dict) and doc.get("schema") == SCHEMA[0]
                      and isinstance(doc.get("tables"), list))
            except (OSError, ValueError) as exc:
                raise ValueError(f"{path}: cannot read the batch summary ({exc})") from None
            if not ok:
                raise ValueError(f"{path}: not a microcyl batch summary")
            self.rows = {r["name"]: r for r in doc["tables"]}

    def done(self, job) -> bool:
        """Whether ``job`` converged before with the same key and its results are there."""
        row = self.rows.get(job.name)
        return (row is not None and row.get("status") == "converged"
                and row.get("key") == job.key()
                and (self.dir / job.name / "results.json").exists())

    def update(self, row: dict) -> None:
        """Add or replace the row of ``row["name"]``."""
        self.rows[row["name"]] = row

    def ordered(self, names=None) -> list[dict]:
        """Rows in the order of ``names`` (then the rest in their stored order)."""
        names = list(names or [])
        out = [self.rows[n] for n in names if n in self.rows]
        return out + [r for n, r in self.rows.items() if n not in names]

    def counts(self) -> dict:
        """Rows per status."""
        out: dict[str, int] = {}
        for r in self.rows.values():
            out[r["status"]] = out.get(r["status"], 0) + 1
        return out

    def write(self, names=None) -> None:
        """Write ``summary.json`` and ``summary.csv`` atomically."""
        rows = self.ordered(names)
        doc = {"schema": SCHEMA[0], "version": SCHEMA[1], "counts": self.counts(),
               "tables": rows}
        self.dir.mkdir(parents=True, exist_ok=True)
        with gonio.atomic_write(self.dir / SUMMARY_JSON, "w") as f:
            json.dump(gonio.plain(doc, nonfinite="null"), f, indent=1)
        columns = list(FIRST_COLUMNS)
        for r in rows:
            columns += [k for k in r if k not in columns]
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=columns, restval="", lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if v is None else v) for k, v in r.items()})
        with gonio.atomic_write(self.dir / SUMMARY_CSV, "w") as f:
            f.write(buf.getvalue())
