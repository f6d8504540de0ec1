"""The report's output folder: checked before any work, built hidden beside it, swapped in whole.

A report replaces its folder whole, so it writes only into a folder that is missing, empty, or
an earlier report holding nothing else: the marker :data:`MARKER` lists every file the report
wrote, and a folder holding a fit, a batch or any file not listed there is refused, naming what
is there. The folder is built as a microcyl temporary beside it
(:func:`gonio.atomic.make_temporary_folder`) and renamed into place at the end.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

from analysis.folderlock import LOCK_NAME, REPORT_MARKER, marker_files
from gonio.atomic import atomic_write, make_temporary_folder

__all__ = ["MARKER", "check_output_dir", "check_report_folder", "swap_into_place",
           "write_file", "write_marker"]

#: The file that marks a folder as a report a later run may replace; it lists the report's
#: files (JSON: ``{"kind": "microcyl report", "files": [...]}``).
MARKER = REPORT_MARKER
_KIND = "microcyl report"
_MARKER_MAX = 16 * 2**20            # bytes: a longer marker is no report's
#: Top-level files that show what else a folder holds.
FIT_FILES = ("checkpoint.h5", "fit_config.json", "results.csv", "results.json")
BATCH_FILES = ("measured.json", "summary.csv", "summary.json")


def check_output_dir(out_dir) -> Path:
    """Check that ``out_dir`` can be (re)written as a report folder; return it absolute (its
    parent resolved, the folder itself not: a link there is refused).

    Raises
    ------
    OSError
        If the folder's parent cannot be created or written, or ``out_dir`` is a file or a
        symbolic link.
    ValueError
        If ``out_dir`` holds anything but an earlier report (see
        :func:`check_report_folder`): it is never replaced then.
    """
    given = Path(os.path.abspath(Path(out_dir).expanduser()))
    if not given.name:
        raise ValueError(f"output folder {given} cannot be a report folder; give a subfolder")
    parent = given.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OSError(f"cannot create output folder {parent}: {exc.strerror or exc}") from None
    out = parent.resolve() / given.name
    if out.is_symlink():
        raise OSError(f"output folder {out} is a symbolic link; give the folder itself or "
                      f"another")
    if out.exists() and not out.is_dir():
        raise OSError(f"output folder {out} exists and is a file")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OSError(f"output folder {parent} is not writable")
    check_report_folder(out)
    return out


def _entries(folder: Path) -> tuple[set, set]:
    """(files, folders) under ``folder`` as relative POSIX paths; links are files here,
    never followed."""
    files, folders = set(), set()
    for root, dirs, names in os.walk(folder, followlinks=False):
        rel = Path(root).relative_to(folder)
        for d in dirs:
            (files if os.path.islink(os.path.join(root, d)) else folders).add(
                (rel / d).as_posix())
        files.update((rel / n).as_posix() for n in names)
    return files, folders


def _listed(folder: Path) -> set | None:
    """The files the marker of ``folder`` lists; None when it lists none (a marker of an
    older microcyl, or damaged)."""
    return marker_files(folder / MARKER, _KIND, _MARKER_MAX)


def _names(items) -> str:
    items = sorted(items)
    more = f" and {len(items) - 5} more" if len(items) > 5 else ""
    return ", ".join(items[:5]) + more


def check_report_folder(out) -> None:
    """Refuse ``out`` unless a report may replace it: missing, empty, or a report (its
    :data:`MARKER`) holding nothing it did not write. The lock file is ignored.

    Raises
    ------
    ValueError
        Naming what the folder holds: a fit (``fit_config.json``, ``checkpoint.h5``, ...), a
        batch (``summary.csv``, ``summary.json``, ``measured.json``) or other files.
    """
    out = Path(out)
    if not out.is_dir() or out.is_symlink():
        return
    marked = os.path.lexists(out / MARKER) and not os.path.islink(out / MARKER)
    extra = _unlisted(out) if marked else set(os.listdir(out)) - {LOCK_NAME, MARKER}
    if not extra:
        return
    fit = sorted(f for f in extra if f in FIT_FILES)
    batch = sorted(f for f in extra if f in BATCH_FILES)
    what = (f"a fit ({_names(fit)})" if fit else f"a batch ({_names(batch)})" if batch
            else f"files a report did not write ({_names(extra)})")
    tail = ("; a report replaces its folder whole: move them away or choose another" if marked
            else ", not a microcyl report; a report replaces its folder whole: remove it or "
                 "choose another")
    raise ValueError(f"output folder {out} holds {what}{tail}")


def _unlisted(out: Path) -> set:
    """What the report folder ``out`` holds that its marker does not list (the topmost of
    each such path; for an older report's marker, which lists nothing: a fit's or a batch's
    files)."""
    files, folders = _entries(out)
    files -= {LOCK_NAME, MARKER}
    listed = _listed(out)
    if listed is None:
        return files & (set(FIT_FILES) | set(BATCH_FILES))
    kept = {p.as_posix() for f in listed for p in Path(f).parents}
    never = set(FIT_FILES) | (set(BATCH_FILES) - {"summary.json"})     # no report writes these
    extra = (files - listed) | (folders - kept) | (files & never)
    return {f for f in extra if not any(p.as_posix() in extra for p in Path(f).parents)}


def write_file(path: Path, data: bytes | str) -> None:
    """Write text or bytes to ``path`` through :func:`gonio.atomic_write`."""
    with atomic_write(path, "w" if isinstance(data, str) else "wb") as fh:
        fh.write(data)


def write_marker(folder: Path) -> None:
    """Write :data:`MARKER` in the finished report ``folder``, listing every file in it."""
    files, _ = _entries(Path(folder))
    doc = {"kind": _KIND, "note": "a microcyl report folder: replaced whole by the next "
                                  "report; a report refuses it if it holds other files",
           "files": sorted(files - {MARKER})}
    write_file(Path(folder) / MARKER, json.dumps(doc, indent=1) + "\n")


def make_build_folder(out: Path) -> Path:
    """A new temporary folder beside ``out`` to build the report in."""
    try:
        return make_temporary_folder(out.parent, out.name)
    except OSError as exc:
        raise OSError(f"output folder {out.parent} is not writable: "
                      f"{exc.strerror or exc}") from None


def swap_into_place(tmp: Path, out: Path) -> None:
    """Rename the finished ``tmp`` folder to ``out``, replacing an old report there (moved
    first to a microcyl temporary, then removed)."""
    old = None
    if os.path.lexists(out):
        old = make_temporary_folder(out.parent, out.name)
        os.replace(out, old)
    try:
        os.replace(tmp, out)
    except BaseException:
        if old is not None:
            os.replace(old, out)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
