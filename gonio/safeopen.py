"""Files from others opened once, as data: no link followed, regular files only, sizes capped.

A file in a shared folder can be swapped between a check and a use, be a symbolic link to
another file, a FIFO that never answers, a device, or a sparse file that claims gigabytes.
Every reader of an untrusted file (a table, a state file, a fabric file, a figure a report
copies) therefore opens it through :func:`open_regular`: one ``open`` with ``O_NOFOLLOW`` and
``O_NONBLOCK`` (a FIFO opens at once instead of hanging), then ``fstat`` on the open
descriptor, which must be a regular file no larger than the cap. What is read or copied
afterwards comes from that descriptor, never from the name again, and no more than the cap is
ever read (a file growing under the reader is cut, and refused).

Every refusal is one ``ValueError`` line naming the file, what it is and what is allowed.

Examples
--------
>>> import tempfile, os
>>> d = tempfile.mkdtemp()
>>> p = os.path.join(d, "a.json")
>>> _ = open(p, "w").write('{"x": 1}')
>>> read_bytes(p, max_bytes=100, what="a fit's results")
b'{"x": 1}'
>>> read_bytes(p, max_bytes=4, what="a fit's results")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: ...a.json: 8 bytes, more than the 4 bytes a fit's results may have
>>> os.symlink(p, os.path.join(d, "link.json"))
>>> read_bytes(os.path.join(d, "link.json"), max_bytes=100)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: ...link.json: a symbolic link; microcyl opens no link in a folder it reads (give the file itself)
"""

from __future__ import annotations

import errno
import fcntl
import os
import stat
from pathlib import Path
from typing import BinaryIO

__all__ = ["open_regular", "read_bytes", "read_text", "copy_capped", "file_kind",
           "MAX_STATE_BYTES", "MAX_FIGURE_BYTES"]

#: Largest state file (results.json, fit_config.json, measured.json, summary.json, a fabric
#: JSON or TOML, a spec) microcyl reads: the largest it writes is well under 1 MiB.
MAX_STATE_BYTES = 16 << 20
#: Largest figure (PNG, SVG, CSV beside a plot) a report copies from a fit folder.
MAX_FIGURE_BYTES = 64 << 20
_BLOCK = 1 << 20


def file_kind(mode: int) -> str:
    """What a ``st_mode`` is, in words ('a FIFO', 'a directory', ...)."""
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISSOCK, "a socket"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISLNK, "a symbolic link")):
        if test(mode):
            return name
    return "not a regular file"


def _size(n: int) -> str:
    return f"{n} bytes" if n < 10 << 20 else f"{n / (1 << 20):.0f} MiB"


def open_regular(path, *, max_bytes: int | None = None, what: str = "file") -> BinaryIO:
    """``path`` opened for binary reading, once: never through a link, only a regular file.

    Parameters
    ----------
    path : path
    max_bytes : int, optional
        Largest size allowed (bytes), checked on the open descriptor. None: no cap.
    what : str
        What the file should be, for the message ("a fit's results").

    Returns
    -------
    file object
        Opened in blocking binary mode; the caller closes it (use ``with``).

    Raises
    ------
    ValueError
        One line naming the file: missing, a link, not a regular file, larger than the cap,
        or unreadable.
    """
    path = Path(path)
    flags = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise ValueError(f"{path}: a symbolic link; microcyl opens no link in a folder it "
                             f"reads (give the file itself)") from None
        raise ValueError(f"{path}: cannot read {what} ({exc.strerror or exc})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(f"{path}: {file_kind(st.st_mode)}, not a regular file; cannot "
                             f"read {what} from it")
        if max_bytes is not None and st.st_size > max_bytes:
            raise ValueError(f"{path}: {_size(st.st_size)}, more than the {_size(max_bytes)} "
                             f"{what} may have")
        fl = fcntl.fcntl(fd, fcntl.F_GETFL)
        fcntl.fcntl(fd, fcntl.F_SETFL, fl & ~os.O_NONBLOCK)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_bytes(path, *, max_bytes: int | None = MAX_STATE_BYTES, what: str = "file") -> bytes:
    """The bytes of ``path`` (opened by :func:`open_regular`), at most ``max_bytes``.

    A file that grows past the cap while it is read is refused too. ``max_bytes=None``: no
    cap (a table, whose size :func:`gonio.tablesize.check_table` checks against the memory).
    """
    with open_regular(path, max_bytes=max_bytes, what=what) as fh:
        data = fh.read(-1 if max_bytes is None else max_bytes + 1)
    if max_bytes is not None and len(data) > max_bytes:
        raise ValueError(f"{path}: more than the {_size(max_bytes)} {what} may have")
    return data


def read_text(path, *, max_bytes: int = MAX_STATE_BYTES, what: str = "file") -> str:
    """The UTF-8 text of ``path`` (as :func:`read_bytes`); not UTF-8 is one line."""
    try:
        return read_bytes(path, max_bytes=max_bytes, what=what).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: cannot read {what} (not UTF-8 text: {exc.reason})") from None


def copy_capped(src, dst_fh: BinaryIO, *, max_bytes: int = MAX_FIGURE_BYTES,
                what: str = "file") -> int:
    """Copy the regular file ``src`` into the open file ``dst_fh`` from one descriptor.

    The source is opened once (:func:`open_regular`) and read block by block, at most
    ``max_bytes`` in all, so a link swapped in after an earlier check is refused, and a
    sparse file that claims more than the cap is refused before a byte is copied.

    Returns
    -------
    int
        Bytes copied.
    """
    n = 0
    with open_regular(src, max_bytes=max_bytes, what=what) as fh:
        while block := fh.read(min(_BLOCK, max_bytes + 1 - n)):
            n += len(block)
            if n > max_bytes:
                raise ValueError(f"{src}: more than the {_size(max_bytes)} {what} may have")
            dst_fh.write(block)
    return n
