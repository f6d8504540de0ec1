"""Read and write BRDF tables, the format chosen by the file name's suffix."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gonio.alta import read_alta, write_alta
from gonio.csvtable import read_csv
from gonio.csvwrite import write_csv
from gonio.curet import read_curet
from gonio.exr import count_missing, from_angles, read_exr, write_exr
from gonio.merl import read_merl, write_merl
from gonio.rgl import load_rgl, read_tensor_file
from gonio.table import Table
from gonio.tablesize import check_table

__all__ = ["read", "write", "check_read_options", "table_kind", "READ_SUFFIXES", "WRITE_SUFFIXES",
           "READ_OPTIONS"]

READ_SUFFIXES = (".exr", ".csv", ".binary", ".alta", ".bsdf", "abrdf.dat")
WRITE_SUFFIXES = (".exr", ".csv", ".binary", ".alta")
#: Each format read: its name in messages, and the options its reader takes.
READ_OPTIONS = {"exr": ("a native .exr", ()), "csv": ("a .csv", ()),
                "alta": ("an ALTA .alta", ()),
                "merl": ("a MERL .binary", ("stride", "keep_missing")),
                "curet": ("a CUReT abrdf.dat", ("sample",)), "rgl": ("an RGL .bsdf", ("step",))}


def _kind(path: Path, known) -> str:
    name = path.name.lower()
    if name == "abrdf.dat" and "abrdf.dat" in known:
        return "curet"
    suffix = path.suffix.lower()
    kinds = {".exr": "exr", ".csv": "csv", ".binary": "merl", ".alta": "alta", ".bsdf": "rgl"}
    if suffix not in known or suffix not in kinds:
        raise ValueError(f"{path}: unknown table format {suffix or '(no suffix)'!r}; known: "
                         + ", ".join(known))
    return kinds[suffix]


def table_kind(path, quiet: bool = False) -> str | None:
    """The format of a table to read, from its name (a key of :data:`READ_OPTIONS`).

    Raises
    ------
    ValueError
        An unknown suffix (listing the known ones); with ``quiet``, None instead.

    Examples
    --------
    >>> table_kind("t.exr"), table_kind("x/abrdf.dat"), table_kind("t.txt", quiet=True)
    ('exr', 'curet', None)
    """
    try:
        return _kind(Path(path), READ_SUFFIXES)
    except ValueError:
        if quiet:
            return None
        raise


def check_read_options(path, options, *, as_flags: bool = False) -> None:
    """Refuse, by name, an option that the reader of ``path``'s format does not take.

    Parameters
    ----------
    path : str or os.PathLike
        The table file (only its name is used: the format comes from the suffix).
    options : iterable of str
        The option names given.
    as_flags : bool
        Name them as command-line flags (``--stride``) in the message.

    Raises
    ------
    ValueError
        ``stride applies to a MERL .binary only, not to t.csv; drop it`` for an option of
        another format (whatever the suffix of ``path``), ``unknown option 'x' for t.csv; its
        reader takes none`` for one of no format (for a file of unknown suffix, the unknown
        format instead).

    Examples
    --------
    >>> check_read_options("t.binary", ["stride"])
    >>> check_read_options("t.csv", ["stride"])
    Traceback (most recent call last):
    ...
    ValueError: stride applies to a MERL .binary only, not to t.csv; drop it
    """
    path = Path(path)
    try:
        takes = READ_OPTIONS[_kind(path, READ_SUFFIXES)][1]
    except ValueError:                  # an unknown suffix: an option of a format says so
        takes = None
    for key in options:
        if takes is not None and key in takes:
            continue
        name = f"--{key.replace('_', '-')}" if as_flags else key
        owners = [what for what, opts in READ_OPTIONS.values() if key in opts]
        if owners:
            raise ValueError(f"{name} applies to {' or '.join(owners)} only, not to "
                             f"{path.name}; drop it")
        if takes is None:
            _kind(path, READ_SUFFIXES)
        raise ValueError(f"unknown option {name!r} for {path.name}; its reader takes "
                         f"{', '.join(takes) or 'none'}")


def read(path, **options) -> Table:
    """Read a BRDF table; the format comes from the suffix.

    Parameters
    ----------
    path : str or os.PathLike
        ``.exr`` (native), ``.csv``, ``.binary`` (MERL: the full grid at bin centres, or
        ``stride=`` for a sample), ``.alta`` (ALTA text: COS_TH, SPHERICAL_TL_PL_TV_PV, RUSIN_TH_PH_TD_PD,
        RUSIN_TH_TD_PD or CARTESIAN), ``.bsdf`` (RGL: sampled through
        :func:`gonio.load_rgl` at its theta_i nodes below 90 deg, phi_i = 0, and wo every
        ``step`` degrees, default 5), or a CUReT ``abrdf.dat`` (needs ``sample=N``; its
        ``table.txt`` must be beside it).
    **options
        Passed to the reader (``stride`` and ``keep_missing`` for MERL, ``step`` for RGL,
        ``sample`` for CUReT; :data:`READ_OPTIONS`); another is refused by name
        (:func:`check_read_options`) before the file is opened.

    The table's size is estimated from the file before it is parsed (its line count, an
    OpenEXR header, an RGL header: :func:`gonio.tablesize.check_table`), and a table whose
    reading would exceed the memory limit (:func:`gonio.memory.memory_limit`) is refused.

    Returns
    -------
    Table

    Raises
    ------
    ValueError
        Unknown suffix (the message lists the known ones), an option the format does not
        take, a missing option, a table too large for the memory, or a link, FIFO or device
        in place of the file (every reader, and the size estimate, opens the file through
        :func:`gonio.safeopen.open_regular`: one line naming it, at once, never a hang).
    FormatError
        The file is not what its name says, truncated or corrupt.
    """
    path = Path(path)
    kind = _kind(path, READ_SUFFIXES)
    check_read_options(path, options)
    if not path.exists():
        raise FileNotFoundError(2, "No such file", str(path))
    check_table(path, kind, **options)
    if kind == "exr":
        return read_exr(path, **options)
    if kind == "csv":
        return read_csv(path, **options)
    if kind == "merl":
        return read_merl(path, **options)
    if kind == "alta":
        return read_alta(path, **options)
    if kind == "curet":
        if "sample" not in options:
            raise ValueError(f"{path}: a CUReT abrdf.dat holds 61 samples; give one: "
                             "gonio.read(path, sample=N) or gonio.read_curet(folder, N)")
        return read_curet(path.parent, options.pop("sample"), **options)
    return _rgl_table(path, **options)


def _rgl_table(path: Path, step: float = 5.0) -> Table:
    fields = read_tensor_file(path)
    brdf = load_rgl(path)
    theta_i = np.asarray(fields["theta_i"], np.float64)
    theta_i = theta_i[theta_i < np.radians(89.9)]
    if not 0 < step <= 90:
        raise ValueError(f"read: step must be in (0, 90] degrees; got {step!r}")
    th_o = np.radians(np.arange(0.0, 90.0 - 1e-9, step))
    ph_o = np.radians(np.arange(-180.0 + step, 180.0 + 1e-9, step))
    ti, to, po = (a.ravel() for a in np.meshgrid(theta_i, th_o, ph_o, indexing="ij"))
    wi, wo = from_angles(ti, np.zeros_like(ti)), from_angles(to, po)
    values = brdf.eval(wi, wo)
    meta = {"source": f"RGL {path.name}: {brdf.description}", "file_format": "rgl",
            "file": str(path), "units": "1/sr",
            "note": "sampled with gonio.load_rgl (Mitsuba 3 measured-plugin evaluation)",
            "step_deg": step, "missing_values": count_missing(values)}
    return Table(wi, wo, values, None, meta)


def write(obj, path, **options) -> None:
    """Write a table (or, for ``.binary``, any BRDF) in the format of the suffix, atomically.

    Parameters
    ----------
    obj : Table, or an object with ``eval(wi, wo)`` for ``.binary``
    path : str or os.PathLike
        ``.exr`` (native, default choice), ``.csv``, ``.binary`` (MERL), ``.alta``
        (ALTA text; ``param=`` picks the ``#PARAM_IN``, see :func:`gonio.write_alta`).
    **options
        Passed to the writer (``digits`` for CSV/ALTA, ``param`` for ALTA, ``rotations`` for
        MERL).

    Raises
    ------
    ValueError
        Unknown suffix (the message lists the known ones), or an object the format cannot
        hold.
    """
    path = Path(path)
    kind = _kind(path, WRITE_SUFFIXES)
    if kind == "merl":
        return write_merl(obj, path, **options)
    if not isinstance(obj, Table):
        raise ValueError(f"write: {path.suffix} holds a Table, got {type(obj).__name__} "
                         "(measure a BRDF first, or write it to .binary)")
    if kind == "exr":
        return write_exr(obj, path, **options)
    if kind == "csv":
        return write_csv(obj, path, **options)
    return write_alta(obj, path, **options)
