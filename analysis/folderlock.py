"""One writer per output: a lock file with the owner's pid, and the stale temporaries of a
killed run removed by the next.

A fit, a batch and a report each hold the lock of their output while they run
(:func:`output_lock`): ``fcntl.flock`` on a small file holding the pid, released when the
block ends and by the kernel when the process dies (even by SIGKILL), so a lock left by a dead
process is simply taken over. A second run on the same output is refused at once with
``another fit is running in DIR (pid N)``. While it holds the lock, a run owns every
temporary file of its output (``gonio.atomic_write``'s ``.NAME.*.tmp``, a report's
``.NAME.tmp-*`` folder): any found then were left by a killed run, and are removed.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
from pathlib import Path

__all__ = ["output_lock", "FolderBusy", "remove_stale_temporaries", "LOCK_NAME",
           "missing_folders", "remove_empty_folders"]

#: The lock file inside a locked folder.
LOCK_NAME = ".microcyl.lock"


class FolderBusy(RuntimeError):
    """Another process holds the lock of an output (its pid in the message)."""


def _holder(path: Path) -> str:
    try:
        pid = path.read_text().strip()
    except OSError:
        return "pid unknown"
    return f"pid {pid}" if pid.isdigit() else "pid unknown"


def _acquire(lock: Path, what: str, where: Path) -> int:
    """An open descriptor of ``lock``, flock-ed exclusively with our pid written in it."""
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise FolderBusy(f"another {what} is running in {where} ({_holder(lock)}); wait "
                             f"for it to end or use another output") from None
        except BaseException:
            os.close(fd)
            raise
        try:                             # the holder before us may have removed the file
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
            return fd
        os.close(fd)


def remove_stale_temporaries(folder, name: str | None = None) -> list[Path]:
    """Remove the temporaries of a killed run: in ``folder``, those of the file or folder
    ``name`` (``.NAME.*.tmp``, ``.NAME.tmp-*``), or every ``.*.tmp`` when ``name`` is None.
    Call only while holding the output's lock. Returns what was removed."""
    folder = Path(folder)
    patterns = [f".{name}.*.tmp", f".{name}.tmp-*"] if name else [".*.tmp"]
    removed = []
    for pattern in patterns:
        for p in folder.glob(pattern):
            with contextlib.suppress(OSError):
                if p.is_dir() and not p.is_symlink():
                    shutil.rmtree(p)
                else:
                    p.unlink()
                removed.append(p)
    return removed


def missing_folders(path) -> list[Path]:
    """``path`` and those of its parents that do not exist, deepest first (what
    ``mkdir(parents=True)`` would create)."""
    path = Path(path).absolute()
    return [p for p in (path, *path.parents) if not p.exists()]


def remove_empty_folders(folders) -> None:
    """Remove each of ``folders`` (deepest first) that is empty; leave any other alone."""
    for p in folders:
        with contextlib.suppress(OSError):
            os.rmdir(p)


@contextlib.contextmanager
def output_lock(path, what: str, *, inside: bool = True):
    """Hold the lock of an output while the block runs; remove its stale temporaries first.

    Parameters
    ----------
    path : path
        The output: a folder locked from inside (``inside=True``: ``PATH/.microcyl.lock``,
        the folder created when missing, e.g. a fit's ``-o DIR``), or a file or folder that
        is replaced whole and locked from beside it (``inside=False``: ``.NAME.lock`` in its
        parent, e.g. a report folder or a converted table).
    what : str
        The kind of run, for the message (``"fit"``, ``"batch"``, ``"report"``).

    Raises
    ------
    FolderBusy
        Another live process holds the lock (``another fit is running in DIR (pid N)``).

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> with output_lock(d, "fit"):
    ...     try:
    ...         with output_lock(d, "fit"):
    ...             pass
    ...     except FolderBusy as exc:
    ...         print(str(exc).split(" (pid")[0] == f"another fit is running in {d}")
    True
    """
    path = Path(path)
    created = []
    if inside:
        created = missing_folders(path)
        path.mkdir(parents=True, exist_ok=True)
        lock, folder, name = path / LOCK_NAME, path, None
    else:
        folder = path.parent if str(path.parent) else Path(".")
        lock, name = folder / f".{path.name}.lock", path.name
    fd, done = None, False
    try:
        fd = _acquire(lock, what, path)
        remove_stale_temporaries(folder, name)
        yield lock
        done = True
    finally:
        if fd is not None:
            with contextlib.suppress(OSError):
                os.unlink(lock)
            os.close(fd)
        if not done:
            remove_empty_folders(created)
