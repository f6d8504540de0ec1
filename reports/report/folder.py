"""The report's output folder: checked before any work, built hidden beside it, swapped in whole."""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

from gonio.atomic import atomic_write

__all__ = ["MARKER", "check_output_dir", "swap_into_place", "write_file"]

#: The file that marks a folder as a report a later run may replace.
MARKER = ".microcyl-report"


def check_output_dir(out_dir) -> Path:
    """Check that ``out_dir`` can be (re)written as a report folder; return it resolved.

    Raises
    ------
    OSError
        If the folder's parent cannot be created or written, or ``out_dir`` is a file.
    ValueError
        If ``out_dir`` exists and is not a report written by this module (no
        ``.microcyl-report`` marker) nor a folder holding nothing but ``summary.json`` and
        ``index.html`` (an earlier ``microcyl report``): it is never replaced then.
    """
    out = Path(out_dir).expanduser().resolve()
    if out.exists() and not out.is_dir():
        raise OSError(f"output folder {out} exists and is a file")
    if out.is_dir() and not (out / MARKER).is_file() and not {
            c.name for c in out.iterdir()} <= {"summary.json", "index.html"}:
        raise ValueError(f"output folder {out} exists, is not empty and is not a microcyl "
                         f"report; remove it or choose another")
    parent = out.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OSError(f"cannot create output folder {parent}: {exc.strerror or exc}") from None
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OSError(f"output folder {parent} is not writable")
    return out


def write_file(path: Path, data: bytes | str) -> None:
    """Write text or bytes to ``path`` through :func:`gonio.atomic_write`."""
    with atomic_write(path, "w" if isinstance(data, str) else "wb") as fh:
        fh.write(data)


def swap_into_place(tmp: Path, out: Path) -> None:
    """Rename the finished ``tmp`` folder to ``out``, replacing an old report there."""
    old = None
    if out.exists():
        old = out.with_name(f".{out.name}.old-{os.getpid()}-{time.monotonic_ns()}")
        os.replace(out, old)
    try:
        os.replace(tmp, out)
    except BaseException:
        if old is not None:
            os.replace(old, out)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
