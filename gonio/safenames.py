"""Names read from files, made into path components, and paths kept inside their folder.

Every name that microcyl reads from a file someone else may have written (the dataset names
of ``measured.json``, the rows of a batch's ``summary.json``, the ``plots`` of a
``results.json``) or takes from a file name (a table's stem in ``fit-batch``) goes through
this module before it becomes part of a path.

Two policies, chosen by where the name comes from:

- **Refused** (:func:`check_component`): a name read from a state file that names a folder
  or a file microcyl itself wrote (a dataset's folder, a batch row's folder, a plot's file).
  microcyl only ever writes safe names there, so an unsafe one (absolute, ``..``, a
  separator, a leading dot, a control character, too long) is damage or an attack: the run
  stops before any work with one line naming the file, the entry and the name.
- **Sanitized** (:func:`safe_component`): a name microcyl derives itself from a file name the
  user chose (the stem of a table given to ``fit-batch``, e.g. ``...exr`` whose stem is
  ``..``). It is mapped to a safe component; a name that had to change gets a short digest of
  the original, so that distinct names stay distinct.

And whatever the name, a path about to be written (or a file about to be copied into a
report) is checked to resolve inside its folder after links are resolved
(:func:`check_inside`): a planted symbolic link cannot lead a write or a copy out.

A safe component is a non-empty string of at most :data:`MAX_CHARS` characters and
:data:`MAX_BYTES` bytes of UTF-8, without ``/`` or ``\\``, without control or format
characters (Unicode category C: NUL, newlines, bidirectional overrides), without the
characters ``<>:"|?*`` (reserved on Windows file servers), that neither starts with a dot
(``.``, ``..``, hidden files) nor starts or ends with white space.

Examples
--------
>>> check_component("curet_44_linen", source="measured.json", entry="datasets")
'curet_44_linen'
>>> check_component("../../escape_target", source="measured.json", entry="datasets")
Traceback (most recent call last):
...
ValueError: measured.json: datasets: name '../../escape_target' is not a safe file name (it contains a path separator); refused
>>> safe_component("t0")
't0'
>>> safe_component("..")
'_-5ec1f7e7'
>>> safe_component("a/b") != safe_component("a\\\\b")
True
"""

from __future__ import annotations

import hashlib
import os
import unicodedata
from pathlib import Path

__all__ = ["MAX_CHARS", "MAX_BYTES", "name_problem", "check_component", "safe_component",
           "check_inside", "digest"]

#: Longest safe component, in characters and in bytes of UTF-8 (file systems allow 255
#: bytes; the rest leaves room for the temporaries' prefixes and suffixes).
MAX_CHARS = 96
MAX_BYTES = 192

_SEPARATORS = "/\\"
_RESERVED = '<>:"|?*'


def digest(name: str, n: int = 8) -> str:
    """The first ``n`` hex digits of the SHA-256 of ``name`` (UTF-8, lone surrogates kept).

    Examples
    --------
    >>> digest("..")
    '5ec1f7e7'
    """
    return hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:n]


def name_problem(name) -> str | None:
    """Why ``name`` is not a safe path component (one phrase), or None when it is.

    Examples
    --------
    >>> name_problem("t0") is None
    True
    >>> name_problem("/etc")
    'it contains a path separator'
    >>> name_problem(".hidden")
    'it starts with a dot'
    """
    if not isinstance(name, str):
        return f"it is a {type(name).__name__}, not a string"
    if not name:
        return "it is empty"
    if any(c in _SEPARATORS for c in name):
        return "it contains a path separator"
    if name.startswith("."):
        return "it starts with a dot"
    if any(unicodedata.category(c).startswith("C") for c in name):
        return "it contains a control character"
    if any(c in _RESERVED for c in name):
        return f"it contains one of {_RESERVED}"
    if name != name.strip():
        return "it starts or ends with white space"
    if len(name) > MAX_CHARS or len(name.encode("utf-8", "surrogatepass")) > MAX_BYTES:
        return f"it is longer than {MAX_CHARS} characters or {MAX_BYTES} bytes"
    return None


def _shown(name) -> str:
    text = repr(name)
    return text if len(text) <= 80 else text[:77] + "..."


def check_component(name, *, source, entry: str) -> str:
    """``name`` when it is a safe path component; else a ValueError naming the file.

    The policy for names read from a state file that name a folder or file microcyl wrote
    itself: an unsafe one is refused, never repaired.

    Parameters
    ----------
    name : object
        The name as read.
    source : path or str
        The file it was read from (named in the message).
    entry : str
        Where in the file (e.g. ``datasets``, ``tables[3].folder``, ``plots.corner``).

    Returns
    -------
    str
        ``name``, unchanged.

    Raises
    ------
    ValueError
        ``SOURCE: ENTRY: name NAME is not a safe file name (WHY); refused``.
    """
    why = name_problem(name)
    if why is not None:
        raise ValueError(f"{source}: {entry}: name {_shown(name)} is not a safe file name "
                         f"({why}); refused")
    return name


def safe_component(name: str, avoid=()) -> str:
    """``name`` made into a safe path component: unchanged when it is one already, else its
    unsafe characters replaced by ``_``, leading dots and surrounding white space removed,
    shortened, and ``-`` and an 8-digit digest of the original name appended (two names that
    differ give different components).

    The policy for names microcyl derives itself from a file name the user chose.

    Parameters
    ----------
    name : str
    avoid : iterable of str
        Names the component must not be, case ignored (the files of the folder it goes
        into, such as a batch's ``summary.json``): ``name`` equal to one of them gets the
        digest appended too.

    Returns
    -------
    str

    Raises
    ------
    TypeError
        ``name`` is not a string.

    Examples
    --------
    >>> safe_component("my table")
    'my table'
    >>> safe_component("../x")
    '_x-d6b96a97'
    >>> safe_component("Summary.JSON", avoid=["summary.json"])
    'Summary.JSON-987884bf'
    """
    if not isinstance(name, str):
        raise TypeError(f"a name must be a string; got {type(name).__name__}")
    if name_problem(name) is None and name.casefold() not in {a.casefold() for a in avoid}:
        return name
    keep = "".join("_" if (c in _SEPARATORS or c in _RESERVED
                           or unicodedata.category(c).startswith("C")) else c for c in name)
    keep = keep.strip().lstrip(".").strip() or "_"
    tail = "-" + digest(name)
    room = MAX_CHARS - len(tail)
    keep = keep[:room]
    while len(keep.encode("utf-8")) > MAX_BYTES - len(tail):
        keep = keep[:-1]
    return keep.rstrip() + tail


def check_inside(path, root, *, source=None, entry: str | None = None) -> Path:
    """``path`` resolved (links followed), when it lies inside ``root`` (resolved too).

    Parameters
    ----------
    path : path
        A path to be written or read (need not exist).
    root : path
        The folder it must stay inside.
    source, entry : optional
        The file and entry the path's name came from, for the message.

    Returns
    -------
    pathlib.Path
        The resolved path.

    Raises
    ------
    ValueError
        ``[SOURCE: ENTRY: ]PATH resolves to REAL, outside ROOT; refused``.

    Notes
    -----
    The check is made when called: it stops names and links planted before a run, not a
    process that swaps a folder for a link while the run writes into it.

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> check_inside(root / "a" / "b.json", root) == root.resolve() / "a" / "b.json"
    True
    >>> check_inside(root / ".." / "x", root)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: ... outside ...; refused
    """
    real_root = Path(os.path.realpath(root))
    real = Path(os.path.realpath(path))
    if real == real_root or real.is_relative_to(real_root):
        return real
    where = f"{source}: {entry}: " if source is not None and entry else (
        f"{source}: " if source is not None else "")
    raise ValueError(f"{where}{path} resolves to {real}, outside {real_root}; refused")
