"""One writer per output: a lock file with the owner's pid, and the stale temporaries of a
killed run removed by the next.

Every run that writes an output folder (fit, fit-batch, fit-measured, report) takes the same
lock, ``DIR/.microcyl.lock`` (:func:`output_lock`): ``fcntl.flock`` on a small file holding
the pid and the kind of run, released when the block ends and by the kernel when the process
dies (even by SIGKILL), so a lock left by a dead process is simply taken over. A second run on
the same folder, of any kind, is refused at once: ``another fit is running in DIR (pid N)``.
A file replaced whole (a converted table, a measured one) is locked from beside it,
``.microcyl-NAME.lock``.

Nothing is opened through a link: the folder and the lock file are opened ``O_NOFOLLOW`` (the
lock ``O_EXCL`` when new), and an output folder or a lock file that is a symbolic link is
refused by name. While it holds the lock, a run owns the temporaries of its output (named by
:mod:`gonio.atomic`: ``.microcyl-NAME.XXXXXXXXXXXX.tmp``): any found then were left by a
killed run, and are removed; no other file is (a user's ``.notes.tmp`` stays).

A folder holding a report (its marker :data:`REPORT_MARKER`) is replaced whole by the next
report, so a fit or a batch refuses it.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import json
import os
import re
import shutil
import stat
from pathlib import Path

from gonio.atomic import TEMP_PREFIX, is_temporary, temporary_stem
from gonio.safeopen import read_bytes

__all__ = ["marker_files", "output_lock", "FolderBusy", "remove_stale_temporaries", "LOCK_NAME",
           "REPORT_MARKER", "lock_name", "missing_folders", "remove_empty_folders",
           "refuse_report_folder"]

#: The lock file inside a locked folder.
LOCK_NAME = ".microcyl.lock"
#: The file that marks a folder as a microcyl report (replaced whole by the next report).
REPORT_MARKER = ".microcyl-report"

_NOFOLLOW = os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0)


class FolderBusy(RuntimeError):
    """Another process holds the lock of an output (its pid in the message)."""


def lock_name(name: str) -> str:
    """The lock file beside a file or folder ``name`` that is replaced whole.

    Examples
    --------
    >>> lock_name("table.exr")
    '.microcyl-table.exr.lock'
    """
    return f"{TEMP_PREFIX}{temporary_stem(name)}.lock"


def _holder(fd: int, what: str) -> tuple[str, str]:
    """(kind, ``pid N``) of the lock's holder, read from the open lock file."""
    try:
        words = os.pread(fd, 200, 0).decode("ascii", "replace").split()
    except OSError:
        words = []
    pid = f"pid {words[0]}" if words and words[0].isdigit() else "pid unknown"
    kind = words[1] if len(words) > 1 and re.fullmatch(r"[a-z-]{1,20}", words[1]) else what
    return kind, pid


def _open_lock(dfd: int, name: str, lock: Path) -> int:
    """A descriptor of the lock file ``name`` in the folder ``dfd``: created ``O_EXCL`` when
    new, else opened ``O_NOFOLLOW``; a link, a hard-linked file or anything but a plain file
    is refused by name."""
    flags = os.O_RDWR | os.O_NONBLOCK | _NOFOLLOW
    while True:
        try:
            return os.open(name, flags | os.O_CREAT | os.O_EXCL, 0o644, dir_fd=dfd)
        except FileExistsError:
            pass
        try:
            fd = os.open(name, flags, dir_fd=dfd)
        except FileNotFoundError:
            continue                     # removed by its holder meanwhile: create it
        except OSError as exc:
            if exc.errno == errno.ELOOP:
                raise OSError(f"lock file {lock} is a symbolic link; microcyl never opens "
                              f"one: remove it") from None
            raise OSError(f"lock file {lock} cannot be opened: {exc.strerror}") from None
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_nlink > 1:
            os.close(fd)
            raise OSError(f"lock file {lock} is not a plain file of its own (a hard link or a "
                          f"special file); microcyl never writes through one: remove it")
        return fd


def _acquire(dfd: int, name: str, lock: Path, what: str, where: Path) -> int:
    """An open descriptor of the lock ``name`` in ``dfd``, flock-ed exclusively, holding our
    pid and ``what``."""
    while True:
        fd = _open_lock(dfd, name, lock)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            kind, pid = _holder(fd, what)
            os.close(fd)
            raise FolderBusy(f"another {kind} is running in {where} ({pid}); wait for it to "
                             f"end or use another output") from None
        except BaseException:
            os.close(fd)
            raise
        try:                             # the holder before us may have removed the file
            same = os.fstat(fd).st_ino == os.stat(name, dir_fd=dfd,
                                                  follow_symlinks=False).st_ino
        except FileNotFoundError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()} {what}\n".encode(), 0)
            return fd
        os.close(fd)


def _release(dfd: int, name: str, fd: int) -> None:
    """Remove the lock file if it is still ours, then close it."""
    with contextlib.suppress(OSError):
        if os.stat(name, dir_fd=dfd, follow_symlinks=False).st_ino == os.fstat(fd).st_ino:
            os.unlink(name, dir_fd=dfd)
    os.close(fd)


def remove_stale_temporaries(folder, name: str | None = None) -> list[Path]:
    """Remove the temporaries of a killed run, and only those (:func:`gonio.atomic.is_temporary`
    names): in ``folder``, the files or folders of the output ``name``, or every temporary
    file (not folder) when ``name`` is None. Links are never followed. Call only while holding
    the output's lock. Returns what was removed."""
    folder = Path(folder)
    removed = []
    with contextlib.suppress(OSError), os.scandir(folder) as entries:
        candidates = [e for e in entries if is_temporary(e.name, name)]
    for e in candidates:
        with contextlib.suppress(OSError):
            if e.is_file(follow_symlinks=False):
                os.unlink(e.path)
            elif name is not None and e.is_dir(follow_symlinks=False):
                shutil.rmtree(e.path)
            else:
                continue
            removed.append(Path(e.path))
    return removed


def missing_folders(path) -> list[Path]:
    """``path`` and those of its parents that do not exist, deepest first (what
    ``mkdir(parents=True)`` would create)."""
    path = Path(path).absolute()
    return [p for p in (path, *path.parents) if not os.path.lexists(p)]


def remove_empty_folders(folders) -> None:
    """Remove each of ``folders`` (deepest first) that is empty; leave any other alone."""
    for p in folders:
        with contextlib.suppress(OSError):
            os.rmdir(p)


def _open_folder(path: Path, create: bool, follow: bool = False) -> tuple[int, list[Path]]:
    """A descriptor of the folder ``path`` (``O_NOFOLLOW`` unless ``follow``), created when
    missing if ``create``; and the folders created. A link is refused by name."""
    if not follow and os.path.islink(path):
        raise OSError(f"output folder {path} is a symbolic link; give the folder itself or "
                      f"another")
    if os.path.lexists(path) and not os.path.isdir(path):
        raise OSError(f"output folder {path} exists and is not a folder")
    created = missing_folders(path) if create else []
    if create:
        try:
            path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OSError(f"cannot create output folder {path}: "
                          f"{exc.strerror or exc}") from None
    flags = os.O_RDONLY | os.O_DIRECTORY | (getattr(os, "O_CLOEXEC", 0) if follow
                                            else _NOFOLLOW)
    try:
        return os.open(path, flags), created
    except OSError as exc:
        remove_empty_folders(created)
        if exc.errno == errno.ELOOP:
            raise OSError(f"output folder {path} is a symbolic link; give the folder itself "
                          f"or another") from None
        if exc.errno == errno.ENOTDIR:
            raise OSError(f"output folder {path} is not a folder") from None
        raise OSError(f"output folder {path} cannot be opened: {exc.strerror}") from None


def refuse_report_folder(path, what: str) -> None:
    """Refuse the folder ``path`` (a ValueError naming it) for a run of kind ``what`` when it
    holds a report (:data:`REPORT_MARKER`): the next report there replaces it whole."""
    path = Path(path)
    if os.path.lexists(path / REPORT_MARKER):
        raise ValueError(f"output folder {path} holds a microcyl report ({REPORT_MARKER}); a "
                         f"{what} would be deleted by the next report there; choose another "
                         f"folder")


def _same_folder(path: Path, dfd: int) -> bool:
    """Whether ``path`` still names the folder open as ``dfd`` (a report renames its old
    folder away when it ends)."""
    try:
        return os.stat(path, follow_symlinks=False).st_ino == os.fstat(dfd).st_ino
    except OSError:
        return False


def _lock_folder(path: Path, inside: bool, what: str):
    """(folder descriptor, lock name, lock descriptor, folders created): the lock taken."""
    if not inside:
        folder = path.parent if str(path.parent) else Path(".")
        dfd, _ = _open_folder(folder, create=False, follow=True)
        name = lock_name(path.name)
        try:
            return dfd, name, _acquire(dfd, name, folder / name, what, path), []
        except BaseException:
            os.close(dfd)
            raise
    dfd, created = _open_folder(path, create=True)
    while True:
        try:
            fd = _acquire(dfd, LOCK_NAME, path / LOCK_NAME, what, path)
        except BaseException:
            os.close(dfd)
            remove_empty_folders(created)
            raise
        if _same_folder(path, dfd):
            return dfd, LOCK_NAME, fd, created
        _release(dfd, LOCK_NAME, fd)      # a report renamed the folder away meanwhile
        os.close(dfd)
        dfd, _ = _open_folder(path, create=True)


def _clean(path: Path, inside: bool, what: str) -> None:
    """Under the lock: refuse a report's folder for another kind of run; remove the stale
    temporaries of the output (inside a folder, and the folder's own beside it)."""
    full = Path(os.path.abspath(path))
    if not inside:
        remove_stale_temporaries(full.parent, full.name)
        return
    if what != "report":
        refuse_report_folder(path, what)
    remove_stale_temporaries(full)
    if full.name:
        remove_stale_temporaries(full.parent, full.name)


@contextlib.contextmanager
def output_lock(path, what: str, *, inside: bool = True):
    """Hold the lock of an output while the block runs; remove its stale temporaries first.

    Parameters
    ----------
    path : path
        The output: a folder locked from inside (``inside=True``: ``PATH/.microcyl.lock``,
        the folder created when missing; a fit's, batch's or report's ``-o DIR``), or a file
        replaced whole and locked from beside it (``inside=False``: ``.microcyl-NAME.lock``
        in its parent, e.g. a converted table).
    what : str
        The kind of run, for the messages (``"fit"``, ``"batch"``, ``"report"``).

    Raises
    ------
    FolderBusy
        Another live process holds the lock (``another fit is running in DIR (pid N)``).
    OSError
        The output folder or the lock file is a symbolic link (or the lock a hard link).
    ValueError
        ``what`` is not ``"report"`` and the folder holds a report (:data:`REPORT_MARKER`).

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> with output_lock(d, "fit"):
    ...     try:
    ...         with output_lock(d, "report"):
    ...             pass
    ...     except FolderBusy as exc:
    ...         print(str(exc).split(" (pid")[0] == f"another fit is running in {d}")
    True
    """
    path = Path(path)
    dfd, name, fd, created = _lock_folder(path, inside, what)
    done = False
    try:
        _clean(path, inside, what)
        yield (path if inside else path.parent) / name
        done = True
    finally:
        _release(dfd, name, fd)
        os.close(dfd)
        if not done:
            remove_empty_folders(created)


def marker_files(path, kind: str, max_bytes: int) -> set | None:
    """The files a folder's marker ``path`` lists (JSON ``{"kind": kind, "files": [...]}``,
    written by a fit or a report of microcyl); None when it lists none: missing, a link, not
    a regular file, over ``max_bytes`` bytes, not JSON, or another kind (a marker of an
    older microcyl, or damaged). Opened once (:func:`gonio.safeopen.read_bytes`)."""
    try:
        doc = json.loads(read_bytes(path, max_bytes=max_bytes, what="a marker"))
    except (OSError, ValueError, RecursionError):
        return None
    files = doc.get("files") if isinstance(doc, dict) and doc.get("kind") == kind else None
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return None
    return set(files)
