"""A ``.npz`` from others read as data: every member's size known before a byte is inflated.

``numpy.load`` of an ``.npz`` inflates each member it is asked for, whatever size the member
claims: a 2 MB file of deflated zeros becomes gigabytes in memory before any check can run.
:func:`load_npz` opens the file once (:func:`gonio.safeopen.open_regular`: no link, a regular
file, its size capped), reads the zip's directory (names, declared sizes, compression), then
each wanted member's ``.npy`` header (shape and dtype, :mod:`numpy.lib.format`), and refuses,
before anything is inflated:

- a member missing, not stored or deflated, or declaring more than ``max_bytes``;
- a compression ratio above :data:`MAX_RATIO` (what microcyl writes is stored, ratio 1);
- an array of objects (it would need unpickling), or one whose shape and dtype do not fit in
  the member's declared size;
- arrays that would together exceed the memory limit (:func:`gonio.memory.check_memory`).

Each array is then inflated in blocks of at most 1 MiB into a buffer of exactly its declared
size; a member that holds more or less than it declared is refused. Every refusal is one
``ValueError`` line naming the file, the member and what is allowed.

Examples
--------
>>> import io, tempfile, os
>>> p = os.path.join(tempfile.mkdtemp(), "a.npz")
>>> np.savez(p, x=np.arange(3.0), s="abc")
>>> d = load_npz(p, ("x", "s"), what="a test file")
>>> d["x"].tolist(), str(d["s"])
([0.0, 1.0, 2.0], 'abc')
>>> load_npz(p, ("y",), what="a test file")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: ...a.npz: no member 'y' (a test file holds x, s)
"""

from __future__ import annotations

import math
import os
import struct
import zipfile
from pathlib import Path

import numpy as np
from numpy.lib import format as npformat

from gonio.memory import check_memory
from gonio.safeopen import open_regular

__all__ = ["load_npz", "MAX_NPZ_BYTES", "MAX_RATIO", "MAX_MEMBERS", "MAX_DIRECTORY_BYTES"]

#: Largest ``.npz`` file, and largest member once inflated (bytes).
MAX_NPZ_BYTES = 256 << 20
#: Most members, and largest zip directory (bytes), read: microcyl writes about ten members.
MAX_MEMBERS = 1000
MAX_DIRECTORY_BYTES = 1 << 20
#: Largest ratio of a member's inflated size to its compressed size (deflate of random
#: floats is near 1; of zeros above 1000).
MAX_RATIO = 50
_BLOCK = 1 << 20
_KINDS = "biufcSU"                  # no objects (pickles), no void/structured records


def _size(n: int) -> str:
    return f"{n} bytes" if n < 10 << 20 else f"{n / (1 << 20):.0f} MiB"


def load_npz(path, names, *, max_bytes: int = MAX_NPZ_BYTES, what: str = "file") -> dict:
    """The arrays ``names`` of the ``.npz`` ``path``, each size checked before it is inflated.

    Parameters
    ----------
    path : path
    names : iterable of str
        The arrays to read (each must be there).
    max_bytes : int
        Largest file, and largest array (bytes).
    what : str
        What the file should be, for the messages ("a fit's LOO file").

    Returns
    -------
    dict
        name -> numpy array.

    Raises
    ------
    ValueError
        One line naming the file (and the member): a link, not a regular file, larger than
        ``max_bytes``, not a zip, a member missing, compressed otherwise than deflate, too
        compressed, of objects, larger than ``max_bytes``, than it declares or than the
        memory allows.
    """
    path = Path(path)
    names = list(names)
    with open_regular(path, max_bytes=max_bytes, what=what) as fh:
        try:
            _check_directory(path, fh, what)
            with zipfile.ZipFile(fh) as zf:
                infos = _members(path, zf, names, max_bytes, what)
                heads = {k: _header(path, zf, info, k) for k, info in infos.items()}
                total = sum(h[3] for h in heads.values())
                check_memory(f"reading {path.name} ({what}: {len(heads)} arrays)", 2 * total,
                             f"{path} is not a file microcyl wrote; remove it")
                return {k: _array(path, zf, infos[k], k, heads[k]) for k in names}
        except zipfile.BadZipFile as exc:
            raise ValueError(f"{path}: not {what} (not a readable zip: {exc})") from None
        except (OSError, EOFError, NotImplementedError) as exc:
            raise ValueError(f"{path}: not {what} (unreadable: {exc})") from None


def _check_directory(path: Path, fh, what: str) -> None:
    """Refuse a zip whose end record declares more than :data:`MAX_MEMBERS` members or a
    directory larger than :data:`MAX_DIRECTORY_BYTES` (``zipfile`` would read it whole)."""
    size = os.fstat(fh.fileno()).st_size
    fh.seek(max(0, size - (1 << 16) - 22))
    tail = fh.read()
    at = tail.rfind(b"PK\x05\x06")
    if at < 0 or len(tail) - at < 22:
        raise ValueError(f"{path}: not {what} (not a zip: no end of central directory)")
    members, cd_size = struct.unpack("<6xHL", tail[at + 4:at + 16])
    if members > MAX_MEMBERS or cd_size > MAX_DIRECTORY_BYTES:
        raise ValueError(f"{path}: a zip directory of {members} members in {_size(cd_size)}; "
                         f"{what} has at most {MAX_MEMBERS} in {_size(MAX_DIRECTORY_BYTES)}")
    fh.seek(0)


def _members(path: Path, zf: zipfile.ZipFile, names, max_bytes: int, what: str) -> dict:
    """The zip entries of ``names``, each checked by what the directory declares."""
    have = {i.filename: i for i in zf.infolist()}
    out = {}
    for k in names:
        info = have.get(f"{k}.npy")
        if info is None:
            held = ", ".join(n.removesuffix(".npy") for n in list(have)[:12]) or "nothing"
            raise ValueError(f"{path}: no member {k!r} ({what} holds {held})")
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise ValueError(f"{path}: member {k!r} is compressed with method "
                             f"{info.compress_type}; only stored or deflated members are read")
        if info.file_size > max_bytes:
            raise ValueError(f"{path}: member {k!r} declares {_size(info.file_size)}, more than "
                             f"the {_size(max_bytes)} an array of {what} may have")
        if info.file_size > MAX_RATIO * max(info.compress_size, 1) and info.file_size > _BLOCK:
            raise ValueError(f"{path}: member {k!r} inflates {info.compress_size} bytes to "
                             f"{_size(info.file_size)} (ratio above {MAX_RATIO}: a "
                             f"decompression bomb, not {what})")
        out[k] = info
    return out


def _header(path: Path, zf: zipfile.ZipFile, info: zipfile.ZipInfo, name: str):
    """(shape, fortran order, dtype, bytes) from a member's ``.npy`` header, checked."""
    with zf.open(info) as m:
        try:
            version = npformat.read_magic(m)
            read = (npformat.read_array_header_1_0 if version == (1, 0)
                    else npformat.read_array_header_2_0)
            shape, fortran, dtype = read(m, max_header_size=10000)
            offset = m.tell()
        except ValueError as exc:
            raise ValueError(f"{path}: member {name!r} is not a .npy array ({exc})") from None
    if dtype.hasobject or dtype.kind not in _KINDS or dtype.itemsize == 0:
        raise ValueError(f"{path}: member {name!r} holds dtype {dtype.str!r}; only numbers "
                         f"and strings are read (never objects)")
    nbytes = math.prod(shape) * dtype.itemsize
    if offset + nbytes != info.file_size:
        raise ValueError(f"{path}: member {name!r} declares {_size(info.file_size)} but its "
                         f"header says {shape} of {dtype.str} ({_size(offset + nbytes)})")
    return shape, fortran, dtype, nbytes


def _array(path: Path, zf: zipfile.ZipFile, info: zipfile.ZipInfo, name: str, head):
    """A member's array, inflated in blocks into a buffer of its declared size."""
    shape, fortran, dtype, nbytes = head
    buf = bytearray(nbytes)
    view = memoryview(buf)
    n = 0
    with zf.open(info) as m:
        npformat.read_magic(m)
        m.seek(info.file_size - nbytes)         # past the header (read once already)
        while n < nbytes and (block := m.read(min(_BLOCK, nbytes - n))):
            view[n:n + len(block)] = block
            n += len(block)
        extra = m.read(1)                       # a stored member's CRC is checked at its end
    if n != nbytes or extra:
        raise ValueError(f"{path}: member {name!r} holds {'more' if extra else 'less'} than "
                         f"its header declares")
    arr = np.frombuffer(buf, dtype=dtype)
    return arr.reshape(shape[::-1]).T if fortran else arr.reshape(shape)
