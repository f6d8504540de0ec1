"""The native table format: OpenEXR, float32 channels, metadata in header attributes.

Layout (format ``microcyl-table/1``): one part, a w x h scanline image whose first
``microcyl_rows`` pixels in row-major order are the table's rows (:func:`image_layout`: one
image row per incidence direction for a sweep, else a near-square block; the padding pixels
hold NaN values). Files of the first writer, one 1 x n scanline with ``microcyl_rows`` as a
string, read the same. Channels, all FLOAT (32-bit):

- ``R``, ``G``, ``B``: f_r in 1/sr (a grey file may carry ``Y`` instead);
- ``sigma.R``, ``sigma.G``, ``sigma.B``: standard deviations in 1/sr (optional);
- ``theta_i``, ``phi_i``, ``theta_o``, ``phi_o``: angles in **radians** (theta from the normal,
  phi from the warp +x toward +y); wi points to the light, wo to the viewer.

Header attributes: ``microcyl_format`` = ``microcyl-table/1``, ``angle_unit`` = ``radian``,
``value_unit`` = ``1/sr``, ``microcyl_rows`` = n (an int), ``microcyl_layout`` (the layout's
name) and ``microcyl_meta``, the table's ``meta`` as a JSON object (strings).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import OpenEXR

from brdf.frames import from_angles
from gonio.atomic import atomic_write
from gonio.errors import FormatError
from gonio.jsonplain import plain
from gonio.safeopen import open_regular
from gonio.table import Table, check_meta_size

__all__ = ["read_exr", "write_exr", "image_layout", "from_angles", "meta_to_json",
           "check_headers"]

FORMAT = "microcyl-table/1"
_MAGIC = b"\x76\x2f\x31\x01"
ANGLE_CHANNELS = ("theta_i", "phi_i", "theta_o", "phi_o")


def meta_to_json(meta: dict) -> str:
    """The meta dict as compact JSON (numpy scalars and arrays become numbers and lists)."""
    return json.dumps(plain(meta), sort_keys=True, allow_nan=True)


def count_missing(values: np.ndarray) -> int:
    """Number of NaN or negative entries of an (n, 3) value array."""
    return int(np.count_nonzero(~(np.isfinite(values) & (values >= 0))))


def image_layout(angles) -> tuple[int, int, str]:
    """The image shape (height, width) of a table with angles (n, 4), and its layout's name.

    ``"incidence rows"``: when the rows come in runs of one incidence direction, all of the
    same length (a gonioreflectometer's sweep), one image row per incidence. Otherwise
    ``"block"``: a near-square block, width ceil(sqrt(n)), the last row padded.

    Examples
    --------
    >>> a = np.zeros((6, 4)); a[3:, 0] = 0.5            # two incidences, three views each
    >>> image_layout(a), image_layout(np.arange(40.0).reshape(10, 4))
    ((2, 3, 'incidence rows'), (3, 4, 'block'))
    """
    n = angles.shape[0]
    inc = np.round(np.asarray(angles)[:, :2], 9)
    starts = np.flatnonzero(np.r_[True, np.any(inc[1:] != inc[:-1], axis=1)])
    runs = np.diff(np.r_[starts, n])
    distinct = len(np.unique(inc[starts], axis=0))    # the runs are maximal: no need for all
    if 1 < len(runs) == distinct and np.all(runs == runs[0]) and runs[0] > 1:
        return len(runs), int(runs[0]), "incidence rows"
    w = int(np.ceil(np.sqrt(n)))
    return int(np.ceil(n / w)), w, "block"


def write_exr(table: Table, path) -> None:
    """Write a table as the native OpenEXR format (atomically).

    Parameters
    ----------
    table : Table
        At least one row.
    path : str or os.PathLike
        Destination ``.exr`` file; replaced whole or left untouched.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> t = Table([[0, 0, 1.0]], [[0.6, 0, 0.8]], [[0.1, 0.2, 0.3]], meta={"source": "doc"})
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "t.exr"
    >>> write_exr(t, p)
    >>> back = read_exr(p)
    >>> back.values.astype("f4").tolist(), back.meta["source"]
    ([[0.1, 0.2, 0.3]], 'doc')
    """
    n = len(table)
    if n == 0:
        raise ValueError("write_exr: the table is empty; an OpenEXR image needs >= 1 pixel")
    angles = table.angles
    h, w, layout = image_layout(angles)

    def f32(a, pad):
        img = np.full(h * w, pad, np.float32)
        img[:n] = np.asarray(a, np.float32)
        return img.reshape(h, w)

    channels = {c: f32(table.values[:, k], np.nan) for k, c in enumerate("RGB")}
    if table.sigma is not None:
        channels.update({f"sigma.{c}": f32(table.sigma[:, k], np.nan)
                         for k, c in enumerate("RGB")})
    channels.update({name: f32(angles[:, k], 0.0) for k, name in enumerate(ANGLE_CHANNELS)})
    header = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
        "microcyl_format": FORMAT,
        "angle_unit": "radian",
        "value_unit": "1/sr",
        "microcyl_rows": int(n),
        "microcyl_layout": layout,
        "microcyl_meta": meta_to_json(table.meta),
    }
    with atomic_write(path, "wb") as f:
        with OpenEXR.File(header, channels) as exr:
            exr.write(str(f.tmp_path))


def read_exr(path) -> Table:
    """Read a native OpenEXR table.

    Parameters
    ----------
    path : str or os.PathLike
        An ``.exr`` file written by :func:`write_exr` (or by anyone following the layout in
        this module's docstring).

    Returns
    -------
    Table
        Values and sigma exactly as stored (float32 widened to float64); directions from the
        stored angles; ``meta`` from the header plus ``missing_values`` (count of NaN or
        negative values, kept and flagged in ``Table.valid``).

    Raises
    ------
    FormatError
        Not an OpenEXR file (wrong magic), unreadable or truncated, a missing channel, or a
        ``microcyl_rows`` larger than the image.
    """
    path = Path(path)
    header, chans = _read_channels(path)
    has_sigma = _check_channels(path, chans)
    n = _row_count(path, header, next(iter(chans.values())).size)
    flat = lambda name: chans[name].astype(np.float64).ravel()[:n]  # noqa: E731
    if "R" in chans:
        values = np.stack([flat(c) for c in "RGB"], axis=1)
    else:
        values = np.repeat(flat("Y")[:, None], 3, axis=1)
    sigma = None
    if has_sigma:
        sigma = (np.stack([flat(f"sigma.{c}") for c in "RGB"], axis=1) if "sigma.R" in chans
                 else np.repeat(flat("sigma.Y")[:, None], 3, axis=1))
    ti, pi_, to, po = (flat(c) for c in ANGLE_CHANNELS)
    if str(header.get("angle_unit", "radian")).startswith("deg"):
        ti, pi_, to, po = (np.radians(a) for a in (ti, pi_, to, po))
    if not all(np.all(np.isfinite(a)) for a in (ti, pi_, to, po)):
        raise FormatError(path, "non-finite angle in the angle channels")
    meta = _header_meta(path, header)
    meta["missing_values"] = count_missing(values)
    meta.setdefault("file_format", "exr")
    return Table(from_angles(ti, pi_), from_angles(to, po), values, sigma, meta)


def _read_channels(path: Path) -> tuple[dict, dict[str, np.ndarray]]:
    """The header attributes and the channels (name -> pixel array) of an OpenEXR file."""
    with open_regular(path, what="an OpenEXR table") as fh:    # no link, FIFO or device
        head = fh.read(4)
        if head != _MAGIC:
            raise FormatError(path, f"wrong magic {head!r}, expected {_MAGIC!r} (not an "
                                    f"OpenEXR file)")
        try:            # read from this descriptor, never by name again
            fh.seek(0)
            with OpenEXR.File(fh, header_only=True) as exr:
                check_headers(path, [dict(part.header) for part in exr.parts])
            fh.seek(0)
            with OpenEXR.File(fh, separate_channels=True) as exr:
                header = dict(exr.header())
                chans = {k: np.array(v.pixels) for k, v in exr.channels().items()}
        except (RuntimeError, OSError, ValueError) as exc:
            raise FormatError(path, f"unreadable OpenEXR (truncated or corrupt): {exc}") \
                from None
    return header, chans


def check_headers(path, headers: list[dict]) -> None:
    """Refuse, from the headers of its parts alone (before a pixel is read), an OpenEXR file
    that is no microcyl table: several parts, a deep image (its pixels hold any number of
    samples each, which the image size does not tell), or a ``microcyl_meta`` attribute of
    more than :data:`gonio.table.MAX_META_BYTES` (:func:`gonio.table.check_meta_size`).

    Raises
    ------
    FormatError
        Naming the file and what it holds.

    Examples
    --------
    >>> check_headers("t.exr", [{"type": OpenEXR.deepscanline}])
    Traceback (most recent call last):
    ...
    gonio.errors.FormatError: t.exr: a deep OpenEXR image (deepscanline); a microcyl table is \
one flat scanline or tiled image
    """
    if len(headers) != 1:
        raise FormatError(path, f"a multi-part OpenEXR file ({len(headers)} parts); a microcyl "
                                "table is one flat scanline or tiled image")
    kind = headers[0].get("type", OpenEXR.scanlineimage)
    if kind not in (OpenEXR.scanlineimage, OpenEXR.tiledimage):
        raise FormatError(path, f"a deep OpenEXR image ({getattr(kind, 'name', kind)}); a "
                                "microcyl table is one flat scanline or tiled image")
    meta = str(headers[0].get("microcyl_meta", ""))
    check_meta_size(path, len(meta.encode("utf-8", "replace")), "the microcyl_meta attribute")


def _check_channels(path: Path, chans: dict) -> bool:
    """FormatError unless the angle and value channels (and all sigma ones, if any) are there;
    returns whether sigma is."""
    need = list(ANGLE_CHANNELS)
    if not ("Y" in chans and not any(c in chans for c in "RGB")):
        need += ["R", "G", "B"]
    missing = [c for c in need if c not in chans]
    if missing:
        raise FormatError(path, f"missing channel(s) {', '.join(missing)}; "
                                f"found {', '.join(sorted(chans)) or 'none'}")
    sig_names = [f"sigma.{c}" for c in "RGB"]
    has_sigma = any(s in chans for s in sig_names) or "sigma.Y" in chans
    if has_sigma and "sigma.Y" not in chans and not all(s in chans for s in sig_names):
        raise FormatError(path, "missing channel(s) " +
                          ", ".join(s for s in sig_names if s not in chans))
    return has_sigma


def _row_count(path: Path, header: dict, size: int) -> int:
    """The table's rows: ``microcyl_rows`` (checked against the image size), else ``size``."""
    if "microcyl_rows" not in header:
        return size
    try:
        n = int(str(header["microcyl_rows"]))
    except ValueError:
        raise FormatError(path, f"bad microcyl_rows attribute {header['microcyl_rows']!r}")
    if not 0 < n <= size:
        raise FormatError(path, f"wrong size: microcyl_rows = {n} but the image has "
                                f"{size} pixels")
    return n


def _header_meta(path: Path, header: dict) -> dict:
    """The table's ``meta`` from the ``microcyl_meta`` attribute ({} without one)."""
    if "microcyl_meta" not in header:
        return {}
    try:
        meta = json.loads(str(header["microcyl_meta"]))
    except json.JSONDecodeError as exc:
        raise FormatError(path, f"microcyl_meta attribute is not JSON: {exc}") from None
    except RecursionError:
        raise FormatError(path, "microcyl_meta attribute is nested too deeply") from None
    if not isinstance(meta, dict):
        raise FormatError(path, "microcyl_meta attribute is not a JSON object")
    return meta
