"""The files a fit writes into its output folder, and the folder's check: a fit writes only
where it wrote before.

A fit replaces its files (``results.csv``, ``corner.png``, ...) by rename, so a folder of the
user's (the measured table itself, ``results.csv``; a figure of the user's, ``corner.png``)
would lose them without a word. Before it writes, a fit lists the files it will write in the
folder's marker :data:`FIT_MARKER` (JSON: ``{"kind": "microcyl fit", "files": [...]}``); a
folder holding anything else (a file or folder neither listed there nor microcyl's own: the
lock, temporaries) is refused, naming what is there, and so is a table to be fitted that lies
in the output folder itself. A folder of a fit written before the marker existed (its
``fit_config.json`` and no marker) holds the fit's files by their names (:data:`FIT_FILES`),
so its resume still works.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from analysis.fit.checkpoint import CHECKPOINT_FILE, CONFIG_FILE
from analysis.fit.loo import LOO_FILE
from analysis.folderlock import LOCK_NAME, marker_files, refuse_report_folder
from gonio.atomic import atomic_write, is_temporary
from gonio.terminal import shown

__all__ = ["FIT_MARKER", "FIT_FILES", "STATE_FILES", "PLOT_FILES", "check_fit_folder",
           "claim_fit_folder", "release_fit_folder", "fit_folder_files"]

#: The marker of a fit's folder: the files the fits there wrote (or were about to).
FIT_MARKER = ".microcyl-fit"
_KIND = "microcyl fit"
_MARKER_MAX = 1 << 20               # bytes: a longer marker is no fit's
#: What every fit writes: its configuration, checkpoint, PSIS-LOO and results.
STATE_FILES = (CONFIG_FILE, CHECKPOINT_FILE, LOO_FILE, "results.json", "results.csv")
#: The figures of :func:`reports.plots.fit_diagnostics.write_fit_plots` (claimed before they
#: are drawn; another ``plots`` callable's files are claimed once it returns them).
PLOT_FILES = ("corner.png", "traces.png", "lobes.png", "residuals.png", "adequacy.png",
              "pit.png")
#: Every file a fit of microcyl writes, by name.
FIT_FILES = STATE_FILES + PLOT_FILES


def _listed(folder: Path) -> set | None:
    """The files the marker of ``folder`` lists; None without a readable marker."""
    return marker_files(folder / FIT_MARKER, _KIND, _MARKER_MAX)


def fit_folder_files(folder) -> set:
    """The files of ``folder`` a fit wrote (or claimed): those its marker lists; for a fit
    folder of a microcyl before the marker (``fit_config.json``, no marker), every name of
    :data:`FIT_FILES`; else none.

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> fit_folder_files(d)
    set()
    >>> claim_fit_folder(d, ["results.json"])
    >>> sorted(fit_folder_files(d))
    ['results.json']
    """
    folder = Path(folder)
    listed = _listed(folder)
    if listed is not None:
        return listed
    config = folder / CONFIG_FILE
    if os.path.isfile(config) and not os.path.islink(config):
        return set(FIT_FILES)
    return set()


def _names(items) -> str:
    items = sorted(items)
    more = f" and {len(items) - 5} more" if len(items) > 5 else ""
    return ", ".join(items[:5]) + more


def check_fit_folder(out, table_file=None) -> None:
    """Refuse ``out`` as a fit's output folder unless it is missing, empty, or holds only
    what fits wrote there (:func:`fit_folder_files`), microcyl's lock and temporaries; and
    refuse a ``table_file`` (the table fitted) that lies in ``out`` itself.

    Parameters
    ----------
    out : path
        The output folder (``fit -o DIR``, one table's folder of a batch).
    table_file : path, optional
        The table file to be fitted.

    Raises
    ------
    ValueError
        One line naming the folder and what it holds that a fit did not write (a fit
        replaces its files whole), or the table.

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> _ = (d / "results.csv").write_text("theta_i,phi_i,theta_o,phi_o,value\\n")
    >>> try:
    ...     check_fit_folder(d)
    ... except ValueError as exc:
    ...     print(str(exc).split(" holds ")[1])
    files a fit did not write (results.csv); a fit replaces its files there: move them away
    or choose another folder
    >>> claim_fit_folder(d, ["results.csv"]); check_fit_folder(d)     # a fit's: fine
    """
    out = Path(os.path.abspath(out))
    if table_file is not None:
        table = Path(os.path.abspath(table_file))
        if os.path.realpath(table.parent) == os.path.realpath(out):
            raise ValueError(shown(f"the table {table} lies in the output folder {out}; a fit "
                                   f"writes its files there: choose another output folder"))
    if os.path.islink(out) or not os.path.isdir(out):
        return                          # missing: created; a link: refused by the lock
    refuse_report_folder(out, "fit")
    ours = fit_folder_files(out) | {LOCK_NAME, FIT_MARKER}
    foreign = {e for e in os.listdir(out) if e not in ours and not is_temporary(e)}
    if foreign:
        raise ValueError(shown(f"output folder {out} holds files a fit did not write "
                               f"({_names(foreign)}); a fit replaces its files there: move "
                               f"them away or choose another folder"))


def claim_fit_folder(out, files) -> None:
    """List ``files`` (names) in the marker of the folder ``out`` before a fit writes them,
    beside those listed already (written through :func:`gonio.atomic_write`). Call while
    holding the folder's lock, after :func:`check_fit_folder`."""
    out = Path(out)
    listed = fit_folder_files(out)
    wanted = listed | set(files)
    if _listed(out) is not None and wanted == listed:
        return
    with atomic_write(out / FIT_MARKER, "w") as fh:
        json.dump({"kind": _KIND, "files": sorted(wanted)}, fh, indent=1)
        fh.write("\n")


def release_fit_folder(out) -> None:
    """Remove the marker of the folder ``out`` when no fit file is there (a fit refused
    before it wrote any: the table too small, the chains over the memory limit), so that
    the folder is left as it was, and a new one empty (removed with the lock). Call while
    holding the folder's lock.

    Examples
    --------
    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> claim_fit_folder(d, ["results.json"]); release_fit_folder(d); sorted(os.listdir(d))
    []
    """
    out = Path(out)
    try:
        held = [e for e in os.listdir(out)
                if e not in (LOCK_NAME, FIT_MARKER) and not is_temporary(e)]
        if not held:
            os.unlink(out / FIT_MARKER)
    except OSError:
        pass
