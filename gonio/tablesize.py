"""A table file's size, estimated before it is parsed, and its check against the memory limit.

:func:`gonio.read` (and so every verb that reads a table) calls :func:`check_table` before
parsing, so that a table too large for the memory is refused at once, in one line, instead of
after minutes of parsing and a MemoryError. The estimate reads no more than it must:

- text tables (CSV, ALTA, CUReT): the rows by a count of line ends (chunks of 4 MiB, about a
  second a gigabyte), the fields from the header line; the parse costs about
  :data:`TEXT_BYTES_PER_ROW` + :data:`TEXT_BYTES_PER_FIELD` per field a row, plus
  :data:`TEXT_BYTES_PER_BYTE` of the file (measured: 740 B a row for 5 fields, 1,280 for 10);
- OpenEXR: the data window and the channels of its header (OpenEXR's ``header_only``), no
  pixel read; :data:`EXR_BYTES_PER_PIXEL` plus 4 bytes a channel a pixel (290 measured for 10
  channels);
- MERL: its fixed size and the stride; RGL: the file's size and, from its header, the
  incident directions times the outgoing ones of ``step`` (:data:`RGL_BYTES_PER_PAIR`).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import OpenEXR

from gonio.csvtable import DELIMITERS
from gonio.memory import check_memory
from gonio.merl import FILE_SIZE as MERL_FILE_SIZE
from gonio.merl import SHAPE as MERL_SHAPE
from gonio.rgl import read_tensor_field
from gonio.safeopen import open_regular

__all__ = ["Estimate", "estimate_table", "check_table", "text_estimate", "rgl_pairs",
           "TEXT_BYTES_PER_ROW", "TEXT_BYTES_PER_FIELD", "TEXT_BYTES_PER_BYTE",
           "EXR_BYTES_PER_PIXEL", "TABLE_BYTES_PER_ROW", "RGL_BYTES_PER_PAIR"]

#: Parsing a text table: bytes a row, a field of a row, and a byte of the file (rounded up).
TEXT_BYTES_PER_ROW = 320
TEXT_BYTES_PER_FIELD = 90
TEXT_BYTES_PER_BYTE = 1.5
#: Reading an OpenEXR table: bytes a pixel besides its channels (4 bytes each).
EXR_BYTES_PER_PIXEL = 260
#: A Table in memory (directions, values, sigma, masks) and its making, bytes a row.
TABLE_BYTES_PER_ROW = 300
#: Peak memory of reading an RGL .bsdf per sampled pair, bytes (about 430 measured).
RGL_BYTES_PER_PAIR = 600
_CHUNK = 1 << 22


@dataclasses.dataclass(frozen=True)
class Estimate:
    """A table's size before it is read: ``rows``, peak ``nbytes`` of reading it, and the
    ``basis`` of the count (said in the refusal)."""

    rows: int
    nbytes: float
    basis: str


def _lines_and_fields(path: Path, sep: str | None) -> tuple[int, int]:
    """(lines, fields of the first line that is neither blank nor a ``#`` comment)."""
    lines, fields, pending, last = 0, 0, b"", b""
    with open_regular(path, what="a table") as fh:     # no link, FIFO or device
        while chunk := fh.read(_CHUNK):
            lines += chunk.count(b"\n")
            last = chunk[-1:]
            if fields or len(pending) > _CHUNK:
                continue
            *complete, pending = (pending + chunk).split(b"\n")
            for line in complete:
                s = line.strip().removeprefix(b"\xef\xbb\xbf").strip()
                if s and not s.startswith(b"#"):
                    fields = _fields(s.decode("utf-8", "replace"), sep)
                    break
    if pending.strip() and not fields:
        fields = _fields(pending.decode("utf-8", "replace"), sep)
    if last not in (b"", b"\n"):
        lines += 1                  # a last line without its line end
    return lines, max(fields, 1)


def _fields(line: str, sep) -> int:
    """Fields of a line split on ``sep`` (None: white space; a tuple: the one of its
    delimiters that gives the most)."""
    if isinstance(sep, tuple):
        return max(len(line.split(d)) for d in sep)
    return len(line.split(sep))


def text_estimate(path, sep: str | tuple | None = ",") -> Estimate:
    """The size of a text table: lines counted, fields from the first data or header line
    split on ``sep`` (None: white space; a tuple of delimiters: the one that gives the
    most, as a CSV file's header says which it uses).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
    >>> _ = p.write_text("# c\\ntheta_i,phi_i,theta_o,phi_o,value\\n" + "30,0,30,180,0.1\\n" * 4)
    >>> text_estimate(p).rows
    6
    """
    path = Path(path)
    lines, fields = _lines_and_fields(path, sep)
    size = path.stat().st_size
    nbytes = (lines * (TEXT_BYTES_PER_ROW + TEXT_BYTES_PER_FIELD * fields + TABLE_BYTES_PER_ROW)
              + TEXT_BYTES_PER_BYTE * size)
    return Estimate(lines, nbytes, f"{lines:,} lines of {fields} fields")


def _exr_estimate(path: Path) -> Estimate | None:
    """Pixels and channels of every part, from the headers alone."""
    try:
        with open_regular(path, what="an OpenEXR table") as fh, \
                OpenEXR.File(fh, header_only=True) as exr:
            headers = [dict(part.header) for part in exr.parts]
    except (RuntimeError, OSError, ValueError, TypeError):
        return None                             # the reader says what is wrong
    pixels, nbytes = 0, 0.0
    for h in headers:
        lo, hi = (np.asarray(v, dtype=np.int64) for v in h["dataWindow"])
        n = math.prod(max(0, int(b) - int(a) + 1) for a, b in zip(lo, hi))
        channels = len(h.get("channels", ()))
        pixels += n
        nbytes += n * (EXR_BYTES_PER_PIXEL + 4 * channels)
    return Estimate(pixels, nbytes, "the image size in the OpenEXR header")


def _merl_estimate(path: Path, stride=1) -> Estimate:
    s = (stride,) * 3 if np.ndim(stride) == 0 else tuple(stride)
    try:
        counts = [math.ceil(n / max(1, int(st))) for n, st in zip(MERL_SHAPE, s)]
    except (TypeError, ValueError):
        counts = list(MERL_SHAPE)                    # the reader says what is wrong
    rows = math.prod(counts)
    return Estimate(rows, 3 * MERL_FILE_SIZE + rows * TABLE_BYTES_PER_ROW,
                    "the MERL layout and the stride")


def rgl_pairs(path, step: float = 5.0) -> tuple[int, int]:
    """(incident directions, outgoing ones) of an RGL table read at ``step`` degrees, the
    incident ones from the file's header and ``theta_i`` field alone (89, the most, when
    the field is missing)."""
    theta_i = read_tensor_field(path, "theta_i")
    n_i = 89 if theta_i is None else max(1, int(np.count_nonzero(
        np.asarray(theta_i, dtype=float) < np.radians(89.9))))
    n_o = math.ceil(90 / step - 1e-9) * math.ceil(360 / step - 1e-9)
    return n_i, n_o


def _rgl_estimate(path: Path, step: float = 5.0) -> Estimate | None:
    if not (isinstance(step, (int, float)) and math.isfinite(step) and 0 < step <= 90):
        return None                                  # the reader refuses it by name
    n_i, n_o = rgl_pairs(path, step)
    pairs = n_i * n_o
    return Estimate(pairs, path.stat().st_size + pairs * RGL_BYTES_PER_PAIR,
                    f"step {step:g}: {n_o:,} outgoing directions for each of {n_i} incident "
                    f"ones")


def estimate_table(path, kind: str, **options) -> Estimate | None:
    """The size of the table ``path`` of format ``kind`` (:data:`gonio.io.READ_OPTIONS`'s
    names) read with ``options``; None when it cannot be told before reading: a file that
    cannot be opened, a header that cannot be read (the reader then says what is wrong).
    """
    path = Path(path)
    try:
        return _estimate(path, kind, **options)
    except (OSError, ValueError):
        return None


def _estimate(path: Path, kind: str, **options) -> Estimate | None:
    if kind in ("csv", "alta"):
        return text_estimate(path, tuple(DELIMITERS) if kind == "csv" else None)
    if kind == "exr":
        return _exr_estimate(path)
    if kind == "merl":
        return _merl_estimate(path, options.get("stride", 1))
    if kind == "rgl":
        return _rgl_estimate(path, options.get("step", 5.0))
    if kind == "curet":
        parts = [text_estimate(p, None) for p in (path, path.parent / "table.txt")
                 if p.is_file()]
        return Estimate(sum(e.rows for e in parts), sum(e.nbytes for e in parts),
                        " and ".join(e.basis for e in parts)) if parts else None
    return None


#: What to change when a table is refused, by format.
_CHANGE = {"merl": "use a larger stride (--stride)", "rgl": "use a coarser step (--step)"}


def check_table(path, kind: str, **options) -> Estimate | None:
    """Refuse, before it is parsed, a table whose reading would exceed the memory limit
    (:func:`gonio.memory.check_memory`); returns the estimate.

    Raises
    ------
    ValueError
        ``reading t.csv (5,000,001 lines of 10 fields) would take about 6.6 GB of memory;
        the limit is ...``.
    """
    path = Path(path)
    est = estimate_table(path, kind, **options)
    if est is not None:
        check_memory(f"reading {path.name} ({est.basis})", est.nbytes,
                     _CHANGE.get(kind, "read it on a machine with more memory, or split it"))
    return est

