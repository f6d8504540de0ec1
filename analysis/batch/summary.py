"""The batch's summary: one row per table in ``summary.csv`` and ``summary.json``.

Only the client writes them, atomically (:func:`gonio.atomic_write`), after each fit ends, so
that the files always hold every finished fit and never a half-written row.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path

import gonio
from gonio.csvcells import text_cells
from gonio.safenames import check_component
from gonio.terminal import shown
from gonio.statefields import FileFields, load_json

__all__ = ["BatchSummary", "SUMMARY_CSV", "SUMMARY_JSON", "SCHEMA", "FIRST_COLUMNS",
           "STATUSES", "BATCH_FILES", "check_row", "check_not_batch_file"]

SUMMARY_CSV = "summary.csv"
SUMMARY_JSON = "summary.json"
#: The batch's own files in its folder, which no table's folder may be named (case ignored):
#: the summaries, the batch page (``reports.report_batch.PAGE``) and fit-measured's
#: summary (``analysis.measured.SUMMARY_FILE``). (The lock and the temporaries start with a
#: dot, which no safe name does.)
BATCH_FILES = (SUMMARY_JSON, SUMMARY_CSV, "index.html", "measured.json")
SCHEMA = ("microcyl-batch", 1)
#: The columns every row has, first in the CSV.
FIRST_COLUMNS = ("name", "status", "error", "steps", "wall_s")
#: The statuses of a row.
STATUSES = ("converged", "not_converged", "error")
_STRINGS = ("error", "preset", "reason", "key")
_STATS = ("_median", "_lo95", "_hi95")


def _bad(path, field: str, allowed: str, value) -> ValueError:
    """The one-line error of :class:`gonio.statefields.FileFields` (names escaped)."""
    return FileFields(path).error(field, allowed, value)


def _count(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and v >= 0


def check_not_batch_file(name: str, source, entry: str) -> str:
    """``name`` unless it is one of :data:`BATCH_FILES` (case ignored): a table's folder of
    that name would stand where the batch writes its own file. ``ValueError`` naming
    ``source`` and ``entry`` otherwise.

    Examples
    --------
    >>> check_not_batch_file("t0", "run_batch", "job name")
    't0'
    >>> check_not_batch_file("Summary.json", "run_batch", "job name")
    Traceback (most recent call last):
    ...
    ValueError: run_batch: job name: 'Summary.json' is the name of a file of the batch (summary.json, summary.csv, index.html, measured.json); refused
    """
    if isinstance(name, str) and name.casefold() in {f.casefold() for f in BATCH_FILES}:
        raise ValueError(f"{source}: {entry}: {shown(repr(name))} is the name of a file of the "
                         f"batch ({', '.join(BATCH_FILES)}); refused")
    return name


def check_row(row, path, i: int) -> dict:
    """Row ``i`` of ``path``'s ``tables`` when every field a reader uses is as written by
    :func:`analysis.batch.worker.result_row`; else a ValueError naming the file and the field.

    ``name`` and ``folder`` (default the name) are safe file names
    (:func:`gonio.safenames.check_component`: they name the fit's folder); ``status`` one of
    :data:`STATUSES`; ``error``, ``preset``, ``reason``, ``key`` strings; ``path`` a string or
    null; ``steps``, ``resumed_from`` integers >= 0, ``sample`` an integer or null;
    ``wall_s`` a finite number >= 0 or null; every ``*_median``, ``*_lo95``, ``*_hi95`` a
    finite number or null.

    Examples
    --------
    >>> check_row({"name": "t0", "status": "converged", "steps": 4}, "s.json", 0)["name"]
    't0'
    >>> check_row({"name": "t0", "status": "<b>", "steps": 4}, "s.json", 0)
    Traceback (most recent call last):
    ...
    ValueError: s.json: tables[0].status must be one of converged, not_converged, error; got '<b>'
    """
    where = f"tables[{i}]"
    if not isinstance(row, dict):
        raise _bad(path, where, "an object", row)
    check_component(row.get("name"), source=path, entry=f"{where}.name")
    check_component(row.get("folder", row["name"]), source=path, entry=f"{where}.folder")
    check_not_batch_file(row["name"], path, f"{where}.name")
    check_not_batch_file(row.get("folder", row["name"]), path, f"{where}.folder")
    if row.get("status") not in STATUSES:
        raise _bad(path, f"{where}.status", f"one of {', '.join(STATUSES)}", row.get("status"))
    for k in _STRINGS:
        if k in row and not isinstance(row[k], str):
            raise _bad(path, f"{where}.{k}", "a string", row[k])
    if row.get("path") is not None and not isinstance(row["path"], str):
        raise _bad(path, f"{where}.path", "a string", row["path"])
    for k in ("steps", "resumed_from"):
        if k in row and not _count(row[k]):
            raise _bad(path, f"{where}.{k}", "an integer >= 0", row[k])
    if row.get("sample") is not None and not _count(row["sample"]):
        raise _bad(path, f"{where}.sample", "an integer >= 0 or null", row["sample"])
    for k, v in row.items():
        wall = k == "wall_s"
        if (wall or k.endswith(_STATS)) and v is not None and (
                isinstance(v, bool) or not isinstance(v, (int, float))
                or not math.isfinite(v) or (wall and v < 0)):
            raise _bad(path, f"{where}.{k}", "a finite number" + (" >= 0" if wall else "")
                       + " or null", v)
    return row


def _cell(value):
    """A value of a row as a CSV cell: empty for None (or missing), numbers as numbers, text
    (and anything else, an unknown row's list or object) as text."""
    if value is None:
        return ""
    if isinstance(value, (bool, int, float, str)):
        return value
    return json.dumps(gonio.plain(value, nonfinite="null"))


class BatchSummary:
    """The rows of a batch, by table name, in the batch's order.

    Parameters
    ----------
    out_dir : path
        The batch's folder; an existing ``summary.json`` there is read (a rerun).

    Raises
    ------
    ValueError
        ``summary.json`` exists but is not a batch summary, or a row is out of its schema
        (:func:`check_row`; naming the file and the field).
    """

    def __init__(self, out_dir):
        self.dir = Path(out_dir)
        self.rows: dict[str, dict] = {}
        path = self.dir / SUMMARY_JSON
        if path.is_dir() and not path.is_symlink():
            raise ValueError(f"{path} is a folder, not the batch summary (the folder of a "
                             f"table named {SUMMARY_JSON}.*, from a microcyl that did not "
                             f"avoid the batch's file names?); move it away")
        if os.path.lexists(path):       # a link, FIFO, huge or deep file: one line naming it
            doc = load_json(path, "batch summary")
            ok = (isinstance(doc, dict) and doc.get("schema") == SCHEMA[0]
                  and isinstance(doc.get("tables"), list))
            if not ok:
                raise ValueError(f"{path}: not a microcyl batch summary")
            for i, r in enumerate(doc["tables"]):
                check_row(r, path, i)
                if r["name"] in self.rows:
                    raise ValueError(f"{path}: tables[{i}].name {r['name']!r} is given twice")
                self.rows[r["name"]] = r

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
        """Write ``summary.json`` and ``summary.csv`` atomically; the CSV's text cells
        through :func:`gonio.csvcells.text_cell` (a name ``=HYPERLINK(...)`` is written
        ``'=HYPERLINK(...)``: a spreadsheet shows it, never evaluates it)."""
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
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(text_cells(columns))       # a cell a spreadsheet would evaluate: quoted
        for r in rows:
            w.writerow(text_cells(_cell(r.get(k)) for k in columns))
        with gonio.atomic_write(self.dir / SUMMARY_CSV, "w") as f:
            f.write(buf.getvalue())
