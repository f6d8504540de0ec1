"""Atomic file writes: a file is either written whole or not at all; and the names of
microcyl's temporaries.

Every temporary file or folder microcyl writes is named ``.microcyl-NAME.XXXXXXXXXXXX.tmp``
(NAME the file or folder it becomes, X a random hex digit) and created new: ``O_CREAT |
O_EXCL | O_NOFOLLOW`` for a file, ``mkdir`` for a folder, so an existing file or a planted
link is never opened. :func:`is_temporary` recognises those names and no others: a clean-up
of a killed run's leftovers removes nothing a user named ``.notes.tmp``.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import os
import re
import secrets
from pathlib import Path

__all__ = ["atomic_write", "file_mode", "TEMP_PREFIX", "temporary_stem", "is_temporary",
           "open_temporary", "make_temporary_folder"]

#: The start of the name of every temporary file or folder microcyl writes.
TEMP_PREFIX = ".microcyl-"
_TOKEN = r"[0-9a-f]{12}"          # secrets.token_hex(6)
_STEM_MAX = 100                   # bytes of NAME kept whole in a temporary's name
_ANY_TEMP = re.compile(re.escape(TEMP_PREFIX) + r".+\." + _TOKEN + r"\.tmp", re.S)


def temporary_stem(name: str) -> str:
    """The NAME part of the temporaries of ``name``: ``name`` itself, or when longer than 100
    bytes its start and a digest of the whole (a file name holds at most 255 bytes).

    Examples
    --------
    >>> temporary_stem("checkpoint.h5")
    'checkpoint.h5'
    >>> len(temporary_stem("x" * 250).encode())
    77
    """
    if len(name.encode("utf-8", "surrogateescape")) <= _STEM_MAX:
        return name
    digest = hashlib.sha256(name.encode("utf-8", "surrogateescape")).hexdigest()[:16]
    return name[:60] + "-" + digest


def _temporary_name(name: str) -> str:
    return f"{TEMP_PREFIX}{temporary_stem(name)}.{secrets.token_hex(6)}.tmp"


def is_temporary(entry: str, name: str | None = None) -> bool:
    """Whether ``entry`` (a file name) is a microcyl temporary: of the output ``name``, or of
    any output when ``name`` is None.

    Examples
    --------
    >>> is_temporary(".microcyl-results.json.0123456789ab.tmp", "results.json")
    True
    >>> is_temporary(".microcyl-rep.v2.0123456789ab.tmp", "rep")
    False
    >>> is_temporary(".notes.tmp"), is_temporary(".mydata.tmp")
    (False, False)
    """
    if name is None:
        return _ANY_TEMP.fullmatch(entry) is not None
    return re.fullmatch(re.escape(f"{TEMP_PREFIX}{temporary_stem(name)}.") + _TOKEN
                        + r"\.tmp", entry) is not None


def open_temporary(folder, name: str) -> tuple[int, Path]:
    """Create a new temporary file for ``name`` in ``folder``: a descriptor open for reading
    and writing (mode 0600) and its path. Opened ``O_CREAT | O_EXCL | O_NOFOLLOW``: never an
    existing file, never through a link."""
    flags = os.O_RDWR | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0)
    while True:
        tmp = Path(folder) / _temporary_name(name)
        try:
            return os.open(tmp, flags, 0o600), tmp
        except FileExistsError:
            continue


def make_temporary_folder(folder, name: str) -> Path:
    """Create a new, empty temporary folder for ``name`` in ``folder`` (mode 0700); its
    path. ``mkdir`` creates it new: never an existing folder or a link."""
    while True:
        tmp = Path(folder) / _temporary_name(name)
        try:
            os.mkdir(tmp, 0o700)
            return tmp
        except FileExistsError:
            continue


def file_mode(base: int = 0o666) -> int:
    """``base`` with the process umask applied: the mode ``open()`` would give a new file."""
    mask = os.umask(0)
    os.umask(mask)
    return base & ~mask


@contextlib.contextmanager
def atomic_write(path, mode: str = "wb"):
    """Open a temporary file beside ``path``; on success move it onto ``path``.

    The temporary file (``.microcyl-NAME.XXXXXXXXXXXX.tmp``, :func:`open_temporary`: created
    new, never through a link) lives in the destination folder (so ``os.replace`` is atomic
    on the same file system; a link at ``path`` is replaced, its target untouched), is
    flushed and fsync-ed, then renamed over ``path``. If the body raises anything,
    KeyboardInterrupt included, the temporary file is removed and ``path`` is left as it
    was.

    Parameters
    ----------
    path : str or os.PathLike
        The destination file.
    mode : {"wb", "w"}
        Binary or text (UTF-8, ``\\n`` line ends) mode.

    Raises
    ------
    OSError
        The file cannot be written (missing folder, no permission, a folder in its place,
        disk full): the error names ``path``, never the temporary file.

    Yields
    ------
    file object, with an extra attribute ``tmp_path`` (a :class:`pathlib.Path`) for writers
    (such as OpenEXR) that need a file name rather than a stream.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_write(d / "a.txt", "w") as f:
    ...     _ = f.write("hello")
    >>> (d / "a.txt").read_text()
    'hello'
    >>> try:
    ...     with atomic_write(d / "b.txt", "w") as f:
    ...         _ = f.write("half")
    ...         raise RuntimeError("writer failed")
    ... except RuntimeError:
    ...     pass
    >>> sorted(p.name for p in d.iterdir())
    ['a.txt']
    """
    if mode not in ("wb", "w"):
        raise ValueError(f"atomic_write mode must be 'wb' or 'w'; got {mode!r}")
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "Is a directory, not a file to write", str(path))
    folder = path.parent if str(path.parent) else Path(".")
    try:
        fd, tmp = open_temporary(folder, path.name)
    except OSError as exc:
        raise _named(exc, path) from None
    in_body = False
    try:
        kwargs = {} if mode == "wb" else {"encoding": "utf-8", "newline": "\n"}
        with os.fdopen(fd, mode, **kwargs) as f:
            f.tmp_path = tmp
            in_body = True
            yield f
            in_body = False
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError) and (not in_body or str(tmp) in (exc.filename,
                                                                      exc.filename2)):
            raise _named(exc, path) from None
        raise


def _named(exc: OSError, path: Path) -> OSError:
    """``exc`` again, naming the user's ``path`` instead of the hidden temporary file."""
    if exc.errno is None:
        return OSError(f"{path}: cannot write: {exc}")
    return OSError(exc.errno, f"cannot write: {exc.strerror}", str(path))
