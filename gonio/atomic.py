"""Atomic file writes: a file is either written whole or not at all."""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from pathlib import Path

__all__ = ["atomic_write", "file_mode"]


def file_mode(base: int = 0o666) -> int:
    """``base`` with the process umask applied: the mode ``open()`` would give a new file."""
    mask = os.umask(0)
    os.umask(mask)
    return base & ~mask


@contextlib.contextmanager
def atomic_write(path, mode: str = "wb"):
    """Open a temporary file beside ``path``; on success move it onto ``path``.

    The temporary file lives in the destination folder (so ``os.replace`` is atomic on the
    same file system), is flushed and fsync-ed, then renamed over ``path``. If the body raises
    anything, KeyboardInterrupt included, the temporary file is removed and ``path`` is left
    as it was.

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
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        raise _named(exc, path) from None
    tmp = Path(tmp)
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
