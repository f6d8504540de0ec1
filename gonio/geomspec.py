"""The geometry spec mini-language (``full:10``, ``plane:warp:5``, ``merl:3``, ...) and the
``pairs:FILE.csv`` reader: strings to :class:`gonio.geometry.Geometry` objects."""

from __future__ import annotations

import errno
import os
import re
from pathlib import Path

from gonio.csvtable import ANGLES, parse_columns, read_rows
from gonio.errors import FormatError
from gonio.geometry import SPEC_HELP, Geometry
from gonio.gridsize import full_grid_pairs, merl_pairs, plane_pairs, rusinkiewicz_pairs
from gonio.layouts import (PLANE_AZIMUTHS, PLANE_THETA_I, full_grid, merl, pairs_from_angles,
                           plane, rusinkiewicz)
from gonio.memory import MemoryLimitError
from gonio.numtext import NUMBER_FORM, parse_number
from gonio.tablesize import check_table

__all__ = ["from_spec", "spec_pairs", "read_pairs_csv", "SPEC_HELP"]

_AZIMUTH = re.compile(r"[-+]?[0-9]+(\.[0-9]*)?")


def read_pairs_csv(path) -> Geometry:
    """Read theta_i,phi_i,theta_o,phi_o (degrees) from a CSV; '#' lines are comments.

    The file is split by :func:`gonio.csvtable.read_rows`, the reader of CSV tables; other
    columns are allowed and ignored. Its size is checked against the memory limit before it
    is parsed (:func:`gonio.tablesize.check_table`).

    Raises
    ------
    OSError
        The file does not exist or cannot be read.
    ValueError
        A link, FIFO or device in place of the file (opened through
        :func:`gonio.safeopen.open_regular`); a file too large for the memory; no header, a header without the four angle
        columns, or a bad row (with its line number and column: not a decimal number, or an
        angle outside :data:`gonio.csvtable.ANGLE_RANGES`): a :class:`gonio.FormatError`
        naming the file.
    """
    path = Path(path)
    if not os.path.lexists(path):       # a link or FIFO: read_rows refuses it by name
        raise FileNotFoundError(errno.ENOENT, "cannot read pairs file: No such file",
                                str(path))
    try:
        check_table(path, "csv")
        text = read_rows(path)
    except OSError as exc:
        raise OSError(exc.errno, f"cannot read pairs file: {exc.strerror}", str(path)) from None
    if text.header is None or not text.rows:
        raise FormatError(path, f"no pairs (need a header {','.join(ANGLES)} and rows)")
    missing = [c for c in ANGLES if c not in text.header]
    if missing:
        raise FormatError(path, f"line {text.header_line}: header lacks column(s) "
                                f"{', '.join(missing)}; need {','.join(ANGLES)} (degrees)")
    a = parse_columns(path, text.header, text.rows, ANGLES)
    return pairs_from_angles(*a.T, degrees=True, params={"file": str(path)})


def _parse(spec: str):
    """``(kind, args, kwargs)`` of a spec string, checked: what :func:`from_spec` builds
    and :func:`spec_pairs` counts. ValueError naming the spec when it is malformed."""
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"geometry spec must be a non-empty string; got {spec!r}; use {SPEC_HELP}")
    kind, _, rest = spec.strip().partition(":")
    kind = kind.lower()
    args = rest.split(":") if rest else []

    def bad(why):
        return ValueError(f"geometry spec {spec!r}: {why}; use {SPEC_HELP}")

    def num(x, what):
        try:
            return parse_number(x.strip(" \t"))
        except ValueError:
            raise bad(f"{what} {x!r} is not a number ({NUMBER_FORM})") from None

    if kind == "full":
        if len(args) not in (1, 2, 4):
            raise bad("full takes 1, 2 or 4 steps")
        v = [num(a, "step") for a in args]
        kw = {"theta_o_step": v[2], "phi_o_step": v[3]} if len(v) == 4 else {}
        return "full", tuple(v[:2]), kw
    if kind == "plane":
        if len(args) not in (2, 3):
            raise bad("plane takes WHICH:STEP[:THETA_I,...]")
        which = args[0].lower()
        if which not in PLANE_AZIMUTHS and not _AZIMUTH.fullmatch(which):
            raise bad(f"plane {args[0]!r} is not warp, weft, 45 or an azimuth in degrees")
        ti = ([[num(t, "theta_i") for t in args[2].split(",") if t.strip()]]
              if len(args) == 3 else [])
        return "plane", (which, num(args[1], "step"), *ti), {}
    if kind in ("rusinkiewicz", "rus"):
        if len(args) not in (1, 4):
            raise bad("rusinkiewicz takes 1 or 4 steps")
        return "rusinkiewicz", tuple(num(a, "step") for a in args), {}
    if kind == "merl":
        if len(args) > 1:
            raise bad("merl takes at most a stride")
        if args and not re.fullmatch(r"[0-9]+", args[0]):
            raise bad(f"stride {args[0]!r} is not a positive integer")
        return "merl", tuple(int(a) for a in args), {}
    if kind == "pairs":
        if not rest:
            raise bad("pairs needs a file name")
        return "pairs", (rest,), {}
    raise bad(f"unknown kind {kind!r}")


def _checked(spec, make):
    """``make()``, its ValueErrors naming the spec (once); a refusal for the memory limit
    passes as it is (it names the file or the layout and what to change)."""
    try:
        return make()
    except MemoryLimitError:
        raise
    except ValueError as exc:
        if str(exc).startswith("geometry spec"):
            raise
        raise ValueError(f"geometry spec {spec!r}: {exc}; use {SPEC_HELP}") from None


def from_spec(spec: str, rotation: float = 0.0) -> Geometry:
    """Build a geometry from a compact string (the command line's ``--geometry``).

    Parameters
    ----------
    spec : str
        One of (angles in degrees)::

            full:STEP                 full grid, all four steps STEP
            full:STEP:PHI_STEP        theta steps STEP, phi steps PHI_STEP
            full:TI:PI:TO:PO          four steps
            plane:WHICH:STEP          plane of incidence; WHICH is warp (0), weft (90),
                                      45 or an azimuth in degrees; theta_o every STEP
            plane:WHICH:STEP:T1,T2    ... with these incidence angles
            rusinkiewicz:STEP         half/difference grid, all four steps STEP
            rusinkiewicz:TH:PH:TD:PD  four steps
            merl                      the MERL 90 x 90 x 180 layout
            merl:STRIDE               ... every STRIDE-th node in each dimension
            pairs:FILE.csv            a CSV with columns theta_i,phi_i,theta_o,phi_o (deg)
    rotation : float
        Sample rotation, radians.

    Raises
    ------
    ValueError
        On an unknown kind or a malformed or out-of-range parameter; the message quotes
        the spec and the allowed forms.

    Examples
    --------
    >>> from_spec("full:30").spec
    'full:30:30:30:30'
    >>> from_spec("plane:45:45:0").spec
    'plane:45:45:0'
    >>> len(from_spec("plane:warp:5"))
    210
    >>> from_spec("merl:10").params
    {'stride': 10}
    >>> from_spec("sphere:3")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: geometry spec 'sphere:3': unknown kind 'sphere'; use full:STEP[:PHI_STEP] | ...
    """
    def make():
        kind, args, kw = _parse(spec)
        if kind == "pairs":
            return read_pairs_csv(*args)
        build = {"full": full_grid, "plane": plane, "rusinkiewicz": rusinkiewicz,
                 "merl": merl}[kind]
        return build(*args, rotation=rotation, **kw)
    return _checked(spec, make)


def _plane_pairs(which, step, theta_i=PLANE_THETA_I):
    return plane_pairs(step, len(theta_i))


def spec_pairs(spec: str) -> int | None:
    """Number of direction pairs the layout ``spec`` places, counted without building it (an
    exact int, however large; ``rus`` and ``merl`` before their below-horizon nodes are
    dropped); None for ``pairs``, whose file :func:`read_pairs_csv` sizes before reading.

    Raises
    ------
    ValueError
        A malformed spec, as :func:`from_spec` says it.

    Examples
    --------
    >>> spec_pairs("full:45:90"), spec_pairs("full:0.5"), spec_pairs("plane:warp:30:0,30")
    (25, 16610312161, 10)
    """
    def count():
        kind, args, kw = _parse(spec)
        counter = {"full": full_grid_pairs, "rusinkiewicz": rusinkiewicz_pairs,
                   "merl": merl_pairs, "plane": _plane_pairs}.get(kind)
        return None if counter is None else counter(*args, **kw)
    return _checked(spec, count)
