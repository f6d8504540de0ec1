"""The geometry spec mini-language (``full:10``, ``plane:warp:5``, ``merl:3``, ...) and the
``pairs:FILE.csv`` reader: strings to :class:`gonio.geometry.Geometry` objects."""

from __future__ import annotations

import re
from pathlib import Path

from gonio.csvtable import ANGLES, parse_columns, read_rows
from gonio.errors import FormatError
from gonio.geometry import SPEC_HELP, Geometry
from gonio.layouts import PLANE_AZIMUTHS, full_grid, merl, pairs_from_angles, plane, rusinkiewicz
from gonio.numtext import NUMBER_FORM, parse_number

__all__ = ["from_spec", "read_pairs_csv", "SPEC_HELP"]

_AZIMUTH = re.compile(r"[-+]?[0-9]+(\.[0-9]*)?")


def read_pairs_csv(path) -> Geometry:
    """Read theta_i,phi_i,theta_o,phi_o (degrees) from a CSV; '#' lines are comments.

    The file is split by :func:`gonio.csvtable.read_rows`, the reader of CSV tables; other
    columns are allowed and ignored.

    Raises
    ------
    OSError
        The file cannot be read.
    ValueError
        No header, a header without the four angle columns, or a bad row (with its line
        number and column: not a decimal number, or an angle outside
        :data:`gonio.csvtable.ANGLE_RANGES`): a :class:`gonio.FormatError` naming the file.
    """
    path = Path(path)
    try:
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


def from_spec(spec: str, rotation: float = 0.0) -> Geometry:
    """Build a geometry from a compact string; see :meth:`Geometry.from_spec`.

    Examples
    --------
    >>> from_spec("full:30").spec
    'full:30:30:30:30'
    >>> from_spec("plane:45:45:0").spec
    'plane:45:45:0'
    """
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"geometry spec must be a non-empty string; got {spec!r}; use {SPEC_HELP}")
    s = spec.strip()
    kind, _, rest = s.partition(":")
    kind = kind.lower()
    args = rest.split(":") if rest else []

    def bad(why):
        return ValueError(f"geometry spec {spec!r}: {why}; use {SPEC_HELP}")

    def num(x, what):
        try:
            return parse_number(x.strip(" \t"))
        except ValueError:
            raise bad(f"{what} {x!r} is not a number ({NUMBER_FORM})") from None

    try:
        if kind == "full":
            if len(args) not in (1, 2, 4):
                raise bad("full takes 1, 2 or 4 steps")
            v = [num(a, "step") for a in args]
            if len(v) == 1:
                return full_grid(v[0], rotation=rotation)
            if len(v) == 2:
                return full_grid(v[0], v[1], rotation=rotation)
            return full_grid(v[0], v[1], theta_o_step=v[2], phi_o_step=v[3], rotation=rotation)
        if kind == "plane":
            if len(args) not in (2, 3):
                raise bad("plane takes WHICH:STEP[:THETA_I,...]")
            which = args[0].lower()
            if which not in PLANE_AZIMUTHS and not _AZIMUTH.fullmatch(which):
                raise bad(f"plane {args[0]!r} is not warp, weft, 45 or an azimuth in degrees")
            step = num(args[1], "step")
            if len(args) == 3:
                ti = [num(t, "theta_i") for t in args[2].split(",") if t.strip()]
                return plane(which, step, ti, rotation=rotation)
            return plane(which, step, rotation=rotation)
        if kind in ("rusinkiewicz", "rus"):
            if len(args) not in (1, 4):
                raise bad("rusinkiewicz takes 1 or 4 steps")
            v = [num(a, "step") for a in args]
            return rusinkiewicz(*v, rotation=rotation) if len(v) == 4 else \
                rusinkiewicz(v[0], rotation=rotation)
        if kind == "merl":
            if len(args) > 1:
                raise bad("merl takes at most a stride")
            if args:
                if not re.fullmatch(r"[0-9]+", args[0]):
                    raise bad(f"stride {args[0]!r} is not a positive integer")
                return merl(int(args[0]), rotation=rotation)
            return merl(rotation=rotation)
        if kind == "pairs":
            if not rest:
                raise bad("pairs needs a file name")
            return read_pairs_csv(rest)
    except ValueError as exc:
        if str(exc).startswith("geometry spec"):
            raise
        raise ValueError(f"geometry spec {spec!r}: {exc}; use {SPEC_HELP}") from None
    raise bad(f"unknown kind {kind!r}")
