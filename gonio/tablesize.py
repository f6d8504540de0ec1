"""A table file's size, estimated before it is parsed, and its check against the memory limit.

:func:`gonio.read` (and so every verb that reads a table) calls :func:`check_table` before
parsing, so that a table too large for the memory is refused at once, in one line, instead of
after minutes of parsing and a MemoryError. Each format's estimate counts what its parser
builds, and reads no more than it must:

- text tables (CSV, ALTA, CUReT): the rows by a count of line ends, every one that the
  readers' ``str.splitlines`` splits on (:data:`LINE_ENDS`: ``\\r`` and the rarer ones too,
  not ``\\n`` alone; chunks of 4 MiB, about a second a gigabyte), the fields from the header
  line; the parse costs about :data:`TEXT_BYTES_PER_ROW` + :data:`TEXT_BYTES_PER_FIELD` per
  field a row, plus :data:`TEXT_BYTES_PER_BYTE` of the file (measured: 740 B a row for 5
  fields, 1,280 for 10), more for text that is not ASCII; a CSV file's ``#`` comment lines,
  parsed as JSON metadata, are capped at :data:`gonio.table.MAX_META_BYTES` (refused over it)
  and cost :data:`META_BYTES_PER_BYTE`;
- OpenEXR: the data window and the channels of its header (OpenEXR's ``header_only``), no
  pixel read; :data:`EXR_BYTES_PER_PIXEL` plus 4 bytes a channel a pixel (290 measured for 10
  channels), and the ``microcyl_meta`` attribute as a CSV file's metadata; a multi-part or
  deep file (whose header does not tell its samples) is refused
  (:func:`gonio.exr.check_headers`);
- MERL: its fixed size and the stride; RGL: from its header, its fields checked to fit the
  file without overlapping and the memory of loading them (:func:`gonio.rgl.check_rgl`,
  which every load of an RGL file goes through, :func:`gonio.load_rgl` included), and the
  incident directions times the outgoing ones of ``step`` (:data:`RGL_BYTES_PER_PAIR`).

A header that says the file is no table the reader can build (metadata over the cap, a deep
or multi-part OpenEXR, RGL fields that overlap) is refused by :func:`estimate_table` as a
:class:`gonio.FormatError` naming the file; a file the estimate cannot read at all is left
to its reader, which says what is wrong.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from pathlib import Path

import numpy as np
import OpenEXR

from gonio.csvtable import DELIMITERS
from gonio.errors import FormatError
from gonio.exr import check_headers
from gonio.memory import check_memory
from gonio.merl import FILE_SIZE as MERL_FILE_SIZE
from gonio.merl import SHAPE as MERL_SHAPE
from gonio.rgl import load_bytes, read_tensor_field, tensor_fields
from gonio.safeopen import open_regular
from gonio.table import check_meta_size

__all__ = ["Estimate", "estimate_table", "check_table", "text_estimate", "rgl_pairs",
           "TEXT_BYTES_PER_ROW", "TEXT_BYTES_PER_FIELD", "TEXT_BYTES_PER_BYTE",
           "TEXT_BYTES_PER_WIDE_BYTE", "META_BYTES_PER_BYTE", "LINE_ENDS",
           "EXR_BYTES_PER_PIXEL", "TABLE_BYTES_PER_ROW", "RGL_BYTES_PER_PAIR"]

#: Parsing a text table: bytes a row, a field of a row, and a byte of the file (rounded up).
TEXT_BYTES_PER_ROW = 320
TEXT_BYTES_PER_FIELD = 90
TEXT_BYTES_PER_BYTE = 4
#: Parsing text that is not all ASCII: bytes more a byte of the file (a string of it takes
#: up to 4 bytes a character).
TEXT_BYTES_PER_WIDE_BYTE = 4
#: Parsing JSON metadata (a CSV file's comments, an OpenEXR file's ``microcyl_meta``):
#: bytes a byte (``[[],[],...]`` takes about 21, an empty list for 3 bytes).
META_BYTES_PER_BYTE = 64
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


#: The line ends of ``str.splitlines``, as UTF-8 bytes: the CSV and ALTA readers split their
#: decoded text on every one of them, CUReT's (ASCII text) on the first seven.
LINE_ENDS = (b"\n", b"\r", b"\x0b", b"\x0c", b"\x1c", b"\x1d", b"\x1e", b"\xc2\x85",
             b"\xe2\x80\xa8", b"\xe2\x80\xa9")
_LINE_END = re.compile(rb"\r\n|[\n\r\x0b\x0c\x1c-\x1e]|\xc2\x85|\xe2\x80[\xa8\xa9]")


#: Every byte but the one-byte line ends, deleted to count those.
_NOT_ENDS = bytes(b for b in range(256) if bytes([b]) not in LINE_ENDS)


def _count_ends(buf: bytes) -> int:
    """Line ends in ``buf`` as ``str.splitlines`` counts them (``\\r\\n`` is one)."""
    n = len(buf.translate(None, _NOT_ENDS)) - buf.count(b"\r\n")
    if not buf.isascii():
        n += sum(buf.count(e) for e in LINE_ENDS[7:])
    return n


@dataclasses.dataclass
class _TextScan:
    """What a text table holds, counted chunk by chunk: its lines, the fields of its first
    line that is neither blank nor a ``#`` comment, the bytes of its comment lines (a
    line holding ``#``: a table's data holds none), and whether it is all ASCII."""

    sep: object
    lines: int = 0
    fields: int = 0
    comment_bytes: int = 0
    ascii: bool = True
    in_comment: bool = False        # the last line of the previous chunk is a comment
    carry: bytes = b""              # the last three bytes so far (a line end's start)
    pending: bytes = b""            # the unfinished line, while the first fields are looked for

    def feed(self, chunk: bytes) -> None:
        buf = self.carry + chunk
        self.lines += _count_ends(buf) - _count_ends(self.carry)
        self.carry = buf[-3:]
        self.ascii = self.ascii and chunk.isascii()
        self._comments(chunk)
        if self.fields or len(self.pending) > _CHUNK:
            return
        buf, start = self.pending + chunk, 0
        for m in _LINE_END.finditer(buf):
            if self._first_fields(buf[start:m.start()]):
                return
            start = m.end()
        self.pending = buf[start:]

    def _comments(self, chunk: bytes) -> None:
        """Count the bytes from each ``#`` to its line's end."""
        pos = 0
        if self.in_comment:                     # a comment line goes on from the last chunk
            m = _LINE_END.search(chunk)
            pos = len(chunk) if m is None else m.start()
            self.comment_bytes += pos
            self.in_comment = m is None
        while (h := chunk.find(b"#", pos)) >= 0:
            m = _LINE_END.search(chunk, h)
            pos = len(chunk) if m is None else m.end()
            self.comment_bytes += (len(chunk) if m is None else m.start()) - h
            self.in_comment = m is None

    def _first_fields(self, line: bytes) -> bool:
        s = line.strip().removeprefix(b"\xef\xbb\xbf").strip()
        if s and not s.startswith(b"#"):
            self.fields = _fields(s.decode("utf-8", "replace"), self.sep)
        return bool(self.fields)

    def finish(self) -> None:
        if not self.fields and self.pending.strip():
            self._first_fields(self.pending)
        if self.carry and not self.carry.endswith(LINE_ENDS):
            self.lines += 1                  # a last line without its line end
        self.fields = max(self.fields, 1)


def _scan(path: Path, sep) -> _TextScan:
    scan = _TextScan(sep)
    with open_regular(path, what="a table") as fh:     # no link, FIFO or device
        step = min(_CHUNK, max(os.fstat(fh.fileno()).st_size, 1))   # no 4 MiB for a small file
        while chunk := fh.read(step):
            scan.feed(chunk)
    scan.finish()
    return scan


def _fields(line: str, sep) -> int:
    """Fields of a line split on ``sep`` (None: white space; a tuple: the one of its
    delimiters that gives the most)."""
    if isinstance(sep, tuple):
        return max(len(line.split(d)) for d in sep)
    return len(line.split(sep))


def text_estimate(path, sep: str | tuple | None = ",", *, meta: bool = False) -> Estimate:
    """The size of a text table: lines counted (every line end its reader splits on,
    :data:`LINE_ENDS`), fields from the first data or header line split on ``sep`` (None:
    white space; a tuple of delimiters: the one that gives the most, as a CSV file's header
    says which it uses); with ``meta``, the comment lines that the reader parses as JSON
    metadata (a CSV file's), capped at :data:`gonio.table.MAX_META_BYTES` and counted at
    :data:`META_BYTES_PER_BYTE`. Text that is not all ASCII counts
    :data:`TEXT_BYTES_PER_WIDE_BYTE` more a byte (a decoded string takes up to 4 bytes a
    character).

    Raises
    ------
    FormatError
        With ``meta``, comment lines holding more than :data:`gonio.table.MAX_META_BYTES`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
    >>> _ = p.write_text("# c\\ntheta_i,phi_i,theta_o,phi_o,value\\n" + "30,0,30,180,0.1\\n" * 4)
    >>> text_estimate(p).rows
    6
    >>> _ = p.write_bytes(b"theta_i,phi_i,theta_o,phi_o,value\\r" + b"30,0,30,180,0.1\\r" * 4)
    >>> text_estimate(p).basis
    '5 lines of 5 fields'
    """
    path = Path(path)
    scan = _scan(path, sep)
    lines, fields = scan.lines, scan.fields
    size = path.stat().st_size
    if meta:
        check_meta_size(path, scan.comment_bytes, "the # comment lines")
    per_byte = TEXT_BYTES_PER_BYTE + (0 if scan.ascii else TEXT_BYTES_PER_WIDE_BYTE)
    nbytes = (lines * (TEXT_BYTES_PER_ROW + TEXT_BYTES_PER_FIELD * fields + TABLE_BYTES_PER_ROW)
              + per_byte * size + (META_BYTES_PER_BYTE * scan.comment_bytes if meta else 0))
    return Estimate(lines, nbytes, f"{lines:,} lines of {fields} fields")


def _exr_estimate(path: Path) -> Estimate | None:
    """Pixels and channels of the image, and the bytes of its ``microcyl_meta``, from the
    header alone; a file that is no microcyl table (several parts, a deep image, metadata
    over the cap) refused first (:func:`gonio.exr.check_headers`)."""
    try:
        with open_regular(path, what="an OpenEXR table") as fh, \
                OpenEXR.File(fh, header_only=True) as exr:
            headers = [dict(part.header) for part in exr.parts]
    except (RuntimeError, OSError, ValueError, TypeError):
        return None                             # the reader says what is wrong
    check_headers(path, headers)
    pixels, nbytes = 0, 0.0
    for h in headers:
        lo, hi = (np.asarray(v, dtype=np.int64) for v in h["dataWindow"])
        n = math.prod(max(0, int(b) - int(a) + 1) for a, b in zip(lo, hi))
        channels = len(h.get("channels", ()))
        pixels += n
        nbytes += n * (EXR_BYTES_PER_PIXEL + 4 * channels)
        nbytes += META_BYTES_PER_BYTE * len(str(h.get("microcyl_meta", "")))
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
    """The file read (:func:`gonio.read_tensor_file`), its loading
    (:func:`gonio.rgl.load_bytes`, the fields checked to fit the file without overlapping)
    and the sampled pairs."""
    if not (isinstance(step, (int, float)) and math.isfinite(step) and 0 < step <= 90):
        return None                                  # the reader refuses it by name
    fields, size = tensor_fields(path)
    n_i, n_o = rgl_pairs(path, step)
    pairs = n_i * n_o
    return Estimate(pairs, size + load_bytes(fields, size) + pairs * RGL_BYTES_PER_PAIR,
                    f"step {step:g}: {n_o:,} outgoing directions for each of {n_i} incident "
                    f"ones")


def estimate_table(path, kind: str, **options) -> Estimate | None:
    """The size of the table ``path`` of format ``kind`` (:data:`gonio.io.READ_OPTIONS`'s
    names) read with ``options``; None when it cannot be told before reading: a file that
    cannot be opened, a header that cannot be read (the reader then says what is wrong).

    Raises
    ------
    FormatError
        A header that says the reader could not build the table: a CSV file's metadata
        comments or an OpenEXR file's ``microcyl_meta`` over
        :data:`gonio.table.MAX_META_BYTES`, a deep or multi-part OpenEXR file, RGL fields
        outside the file, in its header or overlapping.
    """
    path = Path(path)
    try:
        return _estimate(path, kind, **options)
    except FormatError:
        raise                               # what the header says is refused before parsing
    except (OSError, ValueError):
        return None


def _estimate(path: Path, kind: str, **options) -> Estimate | None:
    if kind in ("csv", "alta"):
        return text_estimate(path, tuple(DELIMITERS) if kind == "csv" else None,
                             meta=kind == "csv")
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

