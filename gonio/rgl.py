"""RGL tensor ``.bsdf`` files (Dupuy and Jakob 2018) and their evaluation as a BRDF."""

from __future__ import annotations

import math
import os
import struct
from pathlib import Path

import numpy as np

from brdf.frames import flat_pairs
from brdf.shading import DENOM_MIN
from gonio.errors import FormatError
from gonio.memory import check_memory
from gonio.rglwarp import Conditional, elevation, mulsign_neg, phi2u, theta2u
from gonio.safeopen import open_regular

__all__ = ["read_tensor_file", "read_tensor_field", "tensor_fields", "load_bytes", "check_rgl",
           "load_rgl", "RGLBRDF", "HEADER_LIMIT", "MAX_FIELDS", "RGL_BYTES_PER_ELEMENT"]

_MAGIC = b"tensor_file\0"
_DTYPES = {1: "u1", 2: "i1", 3: "<u2", 4: "<i2", 5: "<u4", 6: "<i4", 7: "<u8", 8: "<i8",
           9: "<f2", 10: "<f4", 11: "<f8"}


#: The most header bytes a tensor file's field table may take (read before any field).
HEADER_LIMIT = 1 << 20
#: The most fields a tensor file may declare (an RGL file has 11).
MAX_FIELDS = 4096
#: Peak memory of loading an RGL file (:class:`RGLBRDF`) per element of its fields, bytes,
#: besides the file's own bytes: the vndf warp's float64 copies, CDFs and their normalized
#: copies (about 50 bytes an element, measured: 7.4 times a real float32 file in all).
RGL_BYTES_PER_ELEMENT = 64


def _field_table(path: Path, data: bytes, file_size: int) -> dict[str, tuple]:
    """The field table of a tensor file's header: name -> (dtype, shape, offset), checked by
    :func:`_check_layout` against ``file_size`` bytes. ``data`` holds at least the header;
    only its first :data:`HEADER_LIMIT` bytes are read."""
    data = data[:HEADER_LIMIT]
    if len(data) < 18 or data[:12] != _MAGIC:
        raise FormatError(path, f"wrong magic {data[:12]!r}, expected {_MAGIC!r} "
                                "(not an RGL tensor file)")
    major, minor = data[12], data[13]
    if (major, minor) != (1, 0):
        raise FormatError(path, f"unsupported tensor file version {major}.{minor}, expected 1.0")
    (count,) = struct.unpack_from("<I", data, 14)
    if count > MAX_FIELDS:
        raise FormatError(path, f"the header declares {count:,} fields; a tensor file may "
                                f"have at most {MAX_FIELDS:,} (an RGL file has 11)")
    pos = 18
    entries = []
    try:
        for _ in range(count):
            (name_len,) = struct.unpack_from("<H", data, pos)
            pos += 2
            name = data[pos:pos + name_len].decode("utf-8")
            if len(name) != name_len:
                raise struct.error("name")
            pos += name_len
            ndim, code, offset = struct.unpack_from("<HBQ", data, pos)
            pos += 11
            shape = struct.unpack_from(f"<{ndim}Q", data, pos)
            pos += 8 * ndim
            if code not in _DTYPES:
                raise FormatError(path, f"field {name!r} has unknown dtype code {code}")
            entries.append((name, np.dtype(_DTYPES[code]), shape, offset))
    except (struct.error, UnicodeDecodeError):
        raise FormatError(path, f"truncated or corrupt header (field table of {count} fields "
                                f"ends past byte {pos} of {len(data)})") from None
    _check_layout(path, entries, pos, file_size)
    return {name: (dtype, shape, offset) for name, dtype, shape, offset in entries}


def _check_layout(path: Path, entries, header_end: int, file_size: int) -> None:
    """Refuse a field table whose fields do not each lie within the file, after the header,
    apart from one another (one name once): what is declared is then at most what the file
    holds, and the memory of loading it follows from the file's size."""
    spans, seen = [], set()
    for name, dtype, shape, offset in entries:
        if name in seen:
            raise FormatError(path, f"field {name!r} is declared twice")
        seen.add(name)
        size = math.prod(shape) * dtype.itemsize
        if offset + size > file_size:
            raise FormatError(path, f"wrong size: field {name!r} needs bytes "
                                    f"{offset}..{offset + size}, file has {file_size} "
                                    "(truncated?)")
        if size and offset < header_end:
            raise FormatError(path, f"field {name!r} starts at byte {offset}, inside the "
                                    f"header (which ends at byte {header_end})")
        if size:
            spans.append((offset, offset + size, name))
    spans.sort()
    for (_, end, a), (start, _, b) in zip(spans, spans[1:]):
        if start < end:
            raise FormatError(path, f"fields {a!r} and {b!r} overlap (bytes {start}..{end}); "
                                    "each field of a tensor file has bytes of its own")


def tensor_fields(path) -> tuple[dict[str, tuple], int]:
    """The field table of a tensor file (name -> (dtype, shape, offset)) and the file's
    size, from its header alone; the fields checked to lie within the file without
    overlapping (:func:`read_tensor_file` checks the same).

    Raises
    ------
    FormatError
        As :func:`read_tensor_file`, before any field is read.
    """
    path = Path(path)
    with open_regular(path, what="an RGL tensor file") as fh:   # no link, FIFO or device
        size = os.fstat(fh.fileno()).st_size
        return _field_table(path, fh.read(HEADER_LIMIT), size), size


def load_bytes(fields: dict[str, tuple], file_size: int) -> int:
    """Peak memory of loading a tensor file as an :class:`RGLBRDF`, bytes: the file and
    :data:`RGL_BYTES_PER_ELEMENT` for each element of its fields (:func:`tensor_fields`).

    Examples
    --------
    >>> load_bytes({"rgb": (np.dtype("<f4"), (1, 2, 3, 4, 4), 64)}, 448)
    6592
    """
    elements = sum(math.prod(shape) for _, shape, _ in fields.values())
    return file_size + RGL_BYTES_PER_ELEMENT * elements


def check_rgl(path) -> int:
    """Refuse, from its header alone, an RGL file whose fields do not fit the file
    (:func:`tensor_fields`) or whose loading would exceed the memory limit
    (:func:`gonio.memory.check_memory`); returns the bytes of loading it
    (:func:`load_bytes`). Every load of a tensor file goes through it.

    Raises
    ------
    FormatError
        A damaged or aliasing field table (one line naming the file and the field).
    MemoryLimitError
        A file too large for the memory.
    """
    path = Path(path)
    fields, size = tensor_fields(path)
    nbytes = load_bytes(fields, size)
    check_memory(f"loading {path.name} ({len(fields)} fields, {size:,} bytes)", nbytes,
                 "load it on a machine with more memory")
    return nbytes


def read_tensor_file(path) -> dict[str, np.ndarray]:
    """Read every field of a tensor file (the RGL ``.bsdf`` container).

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    dict of str to numpy.ndarray
        Each field with its shape and dtype as stored (little-endian).

    Raises
    ------
    FormatError
        Wrong magic, unknown version or dtype, a field reaching past the end of the file,
        into the header or into another field (:func:`check_rgl`, before the fields are
        read).
    MemoryLimitError
        Loading the file would exceed the memory limit (:func:`check_rgl`).
    """
    path = Path(path)
    check_rgl(path)
    with open_regular(path, what="an RGL tensor file") as fh:   # no link, FIFO or device
        data = fh.read()
    return {name: np.frombuffer(data, dtype, math.prod(shape), offset).reshape(shape)
            for name, (dtype, shape, offset) in _field_table(path, data, len(data)).items()}


def read_tensor_field(path, name: str) -> np.ndarray | None:
    """One field of a tensor file, reading only the header and that field's bytes (the
    incident angles of an RGL file, to size its table before reading it); None when the
    file has no such field.

    Raises
    ------
    FormatError
        As :func:`read_tensor_file` for the header (a header longer than
        :data:`HEADER_LIMIT` bytes is called corrupt).
    """
    path = Path(path)
    with open_regular(path, what="an RGL tensor file") as fh:
        size = os.fstat(fh.fileno()).st_size
        table = _field_table(path, fh.read(HEADER_LIMIT), size)
        if name not in table:
            return None
        dtype, shape, offset = table[name]
        fh.seek(offset)
        raw = fh.read(math.prod(shape) * dtype.itemsize)
    return np.frombuffer(raw, dtype).reshape(shape)


def _check_angles(path, theta_i, phi_i) -> None:
    """Refuse, naming the field, incident angles that the evaluation cannot interpolate
    between: ``theta_i`` and ``phi_i`` non-empty lists, finite and strictly increasing,
    ``theta_i`` in [0, pi/2] and ``phi_i`` in [-pi, pi] radians."""
    for name, values, hi in (("theta_i", theta_i, np.pi / 2), ("phi_i", phi_i, np.pi)):
        lo = 0.0 if name == "theta_i" else -np.pi
        if values.ndim != 1 or values.size == 0:
            raise FormatError(path, f"field {name!r} must be a non-empty list of angles; "
                                    f"got shape {values.shape}")
        if not np.all(np.isfinite(values)) or np.any(np.diff(values) <= 0):
            raise FormatError(path, f"field {name!r} must increase strictly (finite angles, "
                                    f"radians); got " + ", ".join(f"{v:.4g}" for v in values[:8])
                              + (", ..." if values.size > 8 else ""))
        if values[0] < lo - 1e-6 or values[-1] > hi + 1e-6:
            raise FormatError(path, f"field {name!r} must lie in [{lo:.4g}, {hi:.4g}] "
                                    f"radians; got {values[0]:.4g}..{values[-1]:.4g}")


def _check_grids(path, fields) -> None:
    """Refuse, naming the field, a grid the evaluation cannot interpolate in: every 2-D grid
    (``ndf``, ``sigma``, the last two axes of ``vndf`` and ``rgb``) at least 2 x 2;
    ``jacobian`` non-empty."""
    for name in ("ndf", "sigma", "vndf", "rgb"):
        grid = fields[name].shape[-2:]
        if min(grid) < 2:
            raise FormatError(path, f"field {name!r} is a {grid[0]} x {grid[1]} grid; the "
                                    "interpolation needs at least 2 x 2")
    if np.asarray(fields["jacobian"]).size == 0:
        raise FormatError(path, "field 'jacobian' is empty; expected one flag")


class RGLBRDF:
    """A measured BRDF from an RGL tensor file, evaluated as Mitsuba 3's ``measured`` plugin.

    Build it with :func:`load_rgl`. ``eval(wi, wo)`` returns RGB f_r in 1/sr.

    Notes
    -----
    With Mitsuba's names (``wi_m`` = our ``wo``, the viewer; ``wo_m`` = our ``wi``, the light),
    for wi_m, wo_m above the horizon:

    1. (anisotropic files with a reduced phi_i range) reflect wi_m and wo_m so that wi_m falls
       in the stored phi_i range (``reduction`` = 2 or 4 fold symmetry);
    2. half vector m = normalize(wi_m + wo_m); theta by Mitsuba's stable ``elevation``;
    3. u_m = (sqrt(2 theta_m / pi), (phi_m - phi_i + pi) / (2 pi) mod 1) (phi_m alone when
       anisotropic), params = (phi_i, theta_i) of wi_m;
    4. (u, v) = inverse of the continuous marginal-conditional ``vndf`` warp at u_m, slices
       interpolated linearly in (phi_i, theta_i);
    5. each channel c: rgb(phi_i, theta_i, c, u, v) by multilinear interpolation;
    6. if the file's ``jacobian`` flag is set, times ndf(u_m) / (4 sigma(u_wi)), where ndf and
       sigma are bilinear interpolations of the tabulated microfacet distribution and
       projected area, u_wi = (sqrt(2 theta_i / pi), (phi_i + pi) / (2 pi)).

    That product is Mitsuba's ``eval``: f_r times the cosine of wo_m, so
    f_r = product / cos(theta of our wi).
    """

    def __init__(self, fields: dict[str, np.ndarray], path="<memory>"):
        self.path = os.fspath(path)
        need = ("theta_i", "phi_i", "ndf", "sigma", "vndf", "rgb", "jacobian")
        missing = [k for k in need if k not in fields]
        if missing:
            raise FormatError(path, f"missing field(s) {', '.join(missing)} of an RGB "
                                    "RGL tensor file")
        theta_i = np.asarray(fields["theta_i"], np.float64)
        phi_i = np.asarray(fields["phi_i"], np.float64)
        _check_angles(path, theta_i, phi_i)
        ndf, sigma, vndf, rgb = (fields[k] for k in ("ndf", "sigma", "vndf", "rgb"))
        nphi, nth = phi_i.shape[0], theta_i.shape[0]
        if (ndf.ndim != 2 or sigma.ndim != 2 or vndf.shape[:2] != (nphi, nth) or vndf.ndim != 4
                or rgb.ndim != 5 or rgb.shape[:2] != (nphi, nth) or rgb.shape[2] != 3):
            raise FormatError(path, "field shapes do not match an RGB RGL tensor file: "
                              f"phi_i {phi_i.shape}, theta_i {theta_i.shape}, ndf {ndf.shape}, "
                              f"sigma {sigma.shape}, vndf {vndf.shape}, rgb {rgb.shape}")
        _check_grids(path, fields)
        self.isotropic = nphi <= 2
        self.jacobian = bool(np.asarray(fields["jacobian"]).ravel()[0])
        self.reduction = 0
        if not self.isotropic:
            self.reduction = int(np.rint(2 * np.pi / (phi_i[-1] - phi_i[0])))
        desc = fields.get("description")
        self.description = bytes(np.asarray(desc, np.uint8)).decode("utf-8", "replace") \
            if desc is not None else ""
        self._ndf = Conditional(ndf, [], warp=False)
        self._sigma = Conditional(sigma, [], warp=False)
        self._vndf = Conditional(vndf, [phi_i, theta_i], warp=True)
        self._rgb = Conditional(rgb, [phi_i, theta_i, np.arange(3.0)], warp=False)

    def __repr__(self):
        return f"RGLBRDF({self.description!r}, file={self.path!r})"

    def eval_mitsuba(self, wi_m, wo_m) -> np.ndarray:
        """Mitsuba's ``measured`` ``eval``: f_r cos(theta of wo_m), wi_m the viewer side.

        Parameters
        ----------
        wi_m, wo_m : array_like, shape (..., 3)
            Unit vectors in Mitsuba's convention (``si.wi`` and ``wo``).

        Returns
        -------
        numpy.ndarray, shape (..., 3)
            RGB f_r times cos(theta of wo_m), in 1/sr; 0 where either is below the horizon,
            NaN where either is zero or not finite (as ``brdf.Fabric.eval``).

        Raises
        ------
        ValueError
            If the arrays lack a last axis of 3 or do not broadcast.
        """
        wi, wo, shape, bad, below = flat_pairs(wi_m, wo_m, ("wi_m", "wo_m"))
        out = np.zeros(wi.shape)
        ok = ~(bad | below)
        if ok.any():
            out[ok] = self._eval_mitsuba(wi[ok], wo[ok])
        out[bad] = np.nan
        return out.reshape(shape + (3,))

    def _eval_mitsuba(self, wi, wo) -> np.ndarray:
        """:meth:`eval_mitsuba` of unit (n, 3) pairs above the horizon."""
        wi, wo = wi.copy(), wo.copy()
        if self.reduction >= 2:
            sy = wi[..., 1].copy()
            sx = wi[..., 0].copy() if self.reduction == 4 else sy
            for w in (wi, wo):
                w[..., 0] = mulsign_neg(w[..., 0], sx)
                w[..., 1] = mulsign_neg(w[..., 1], sy)
        m = wi + wo
        norm = np.linalg.norm(m, axis=-1, keepdims=True)
        m = m / np.where(norm > 0, norm, 1.0)
        theta_i, phi_i = elevation(wi), np.arctan2(wi[..., 1], wi[..., 0])
        theta_m, phi_m = elevation(m), np.arctan2(m[..., 1], m[..., 0])
        u_wi = np.stack([theta2u(theta_i), phi2u(phi_i)], axis=-1)
        um1 = phi2u(phi_m - phi_i if self.isotropic else phi_m)
        u_m = np.stack([theta2u(theta_m), um1 - np.floor(um1)], axis=-1)
        params = [phi_i, theta_i]
        sample = self._vndf.invert(u_m, params)
        spec = np.stack([self._rgb.eval(sample, params + [np.full(phi_i.shape, float(c))])
                         for c in range(3)], axis=-1)
        if self.jacobian:
            spec = spec * (self._ndf.eval(u_m, []) / (4.0 * self._sigma.eval(u_wi, [])))[..., None]
        return spec

    def eval(self, wi, wo) -> np.ndarray:
        """RGB f_r in 1/sr.

        Parameters
        ----------
        wi, wo : array_like, shape (..., 3)
            Unit vectors toward the light and toward the viewer, local frame (n = +z).

        Returns
        -------
        numpy.ndarray, shape (..., 3)
            f_r in 1/sr, no cosine; 0 below the horizon; NaN where a direction is zero or not
            finite. Non-unit vectors are normalized; cos(theta of wi) is taken as at least
            :data:`brdf.shading.DENOM_MIN` (f_r stays finite at grazing incidence).

        Raises
        ------
        ValueError
            If the arrays lack a last axis of 3 or do not broadcast.
        """
        wi, wo, shape, bad, below = flat_pairs(wi, wo)
        out = np.zeros(wi.shape)
        ok = ~(bad | below)
        if ok.any():
            w = wi[ok]
            out[ok] = self._eval_mitsuba(wo[ok], w) / np.maximum(w[:, 2:3], DENOM_MIN)
        out[bad] = np.nan
        return out.reshape(shape + (3,))


def load_rgl(path) -> RGLBRDF:
    """Load an RGL tensor ``.bsdf`` file (RGB) as a BRDF with ``eval(wi, wo)``.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.bsdf`` file, e.g. ``../shared/data/rgl/acrylic_felt_white_rgb.bsdf``.

    Returns
    -------
    RGLBRDF
        ``.eval(wi, wo)`` -> (..., 3) f_r in 1/sr, following Mitsuba 3's ``measured`` plugin.

    Raises
    ------
    FormatError
        Not a tensor file, truncated, or missing one of the fields the evaluation needs.
    """
    return RGLBRDF(read_tensor_file(path), path)
