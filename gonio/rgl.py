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
from gonio.safeopen import open_regular

__all__ = ["read_tensor_file", "read_tensor_field", "load_rgl", "RGLBRDF", "HEADER_LIMIT"]

_MAGIC = b"tensor_file\0"
_DTYPES = {1: "u1", 2: "i1", 3: "<u2", 4: "<i2", 5: "<u4", 6: "<i4", 7: "<u8", 8: "<i8",
           9: "<f2", 10: "<f4", 11: "<f8"}


def _field_table(path: Path, data: bytes, file_size: int) -> dict[str, tuple]:
    """The field table of a tensor file's header: name -> (dtype, shape, offset), each
    field checked to end within ``file_size`` bytes. ``data`` holds at least the header."""
    if len(data) < 18 or data[:12] != _MAGIC:
        raise FormatError(path, f"wrong magic {data[:12]!r}, expected {_MAGIC!r} "
                                "(not an RGL tensor file)")
    major, minor = data[12], data[13]
    if (major, minor) != (1, 0):
        raise FormatError(path, f"unsupported tensor file version {major}.{minor}, expected 1.0")
    (count,) = struct.unpack_from("<I", data, 14)
    pos = 18
    table = {}
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
            dtype = np.dtype(_DTYPES[code])
            size = math.prod(shape) * dtype.itemsize
            if offset + size > file_size:
                raise FormatError(path, f"wrong size: field {name!r} needs bytes "
                                        f"{offset}..{offset + size}, file has {file_size} "
                                        "(truncated?)")
            table[name] = (dtype, shape, offset)
    except (struct.error, UnicodeDecodeError):
        raise FormatError(path, f"truncated or corrupt header (field table of {count} fields "
                                f"ends past byte {pos} of {len(data)})") from None
    return table


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
        Wrong magic, unknown version or dtype, or a field reaching past the end of the file.
    """
    path = Path(path)
    with open_regular(path, what="an RGL tensor file") as fh:   # no link, FIFO or device
        data = fh.read()
    return {name: np.frombuffer(data, dtype, math.prod(shape), offset).reshape(shape)
            for name, (dtype, shape, offset) in _field_table(path, data, len(data)).items()}


#: The most header bytes :func:`read_tensor_field` reads to find its field.
HEADER_LIMIT = 1 << 20


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


def _elevation(d):
    """Polar angle of unit vectors, computed as Mitsuba does (stable near the pole)."""
    dist = np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2 + (d[..., 2] - 1.0) ** 2)
    return 2.0 * np.arcsin(np.clip(0.5 * dist, -1.0, 1.0))


def _theta2u(theta):
    return np.sqrt(np.maximum(theta, 0.0) * (2.0 / np.pi))


def _phi2u(phi):
    return (phi + np.pi) / (2.0 * np.pi)


def _mulsign_neg(x, s):
    """x * -sign(s), with the sign taken from the sign bit (as drjit.mulsign_neg)."""
    return np.where(np.signbit(s), x, -x)


def _param_weights(values: np.ndarray, param: np.ndarray):
    """Slice index and linear weight along one parameter axis (Mitsuba's Distribution2D)."""
    n = values.shape[0]
    if n == 1:
        return np.zeros(param.shape, np.intp), np.zeros(param.shape)
    idx = np.clip(np.searchsorted(values, param, side="left") - 1, 0, n - 2)
    p0, p1 = values[idx], values[idx + 1]
    return idx, np.clip((param - p0) / (p1 - p0), 0.0, 1.0)


class _Conditional:
    """Slices of a 2-D function over the unit square indexed by parameters (phi_i, theta_i[, c]).

    ``data`` has shape (P..., ny, nx); parameters are interpolated linearly between slices,
    exactly as Mitsuba's ``Marginal2D`` does (the interpolated quantity is the slice data,
    and, for the continuous warp, its CDFs).
    """

    def __init__(self, data: np.ndarray, params: list[np.ndarray], warp: bool):
        self.params = [np.asarray(p, np.float64) for p in params]
        data = np.asarray(data, np.float64)
        self.ny, self.nx = data.shape[-2:]
        self.pshape = data.shape[:-2]
        flat = data.reshape(-1, self.ny, self.nx)
        if warp:
            cond = np.zeros_like(flat)
            cond[:, :, 1:] = np.cumsum(0.5 * (flat[:, :, :-1] + flat[:, :, 1:]), axis=2)
            marg = np.zeros((flat.shape[0], self.ny))
            marg[:, 1:] = np.cumsum(0.5 * (cond[:, :-1, -1] + cond[:, 1:, -1]), axis=1)
            norm = 1.0 / marg[:, -1]
            self.cond = cond * norm[:, None, None]
            self.marg = marg * norm[:, None]
            flat = flat * norm[:, None, None]
        self.data = flat
        self.strides = []
        s = 1
        for n in reversed(self.pshape):
            self.strides.insert(0, s)
            s *= n

    def _corners(self, param):
        """List of (slice index, weight) pairs for the multilinear parameter interpolation."""
        corners = [(0, 1.0)]
        for values, stride, p in zip(self.params, self.strides, param):
            idx, w1 = _param_weights(values, p)
            if values.shape[0] == 1:
                continue
            corners = [(base + stride * (idx + j), w * (w1 if j else 1.0 - w1))
                       for base, w in corners for j in (0, 1)]
        return corners

    @staticmethod
    def _gather(arr, corners, *index):
        return sum(w * arr[(s,) + index] for s, w in corners)

    def eval(self, pos, param):
        """Bilinear interpolation of the (un-normalized) data at ``pos`` (..., 2) in [0, 1]^2."""
        corners = self._corners(param)
        px = np.clip(pos[..., 0], 0.0, 1.0) * (self.nx - 1)
        py = np.clip(pos[..., 1], 0.0, 1.0) * (self.ny - 1)
        ix = np.minimum(px.astype(np.intp), self.nx - 2)
        iy = np.minimum(py.astype(np.intp), self.ny - 2)
        wx, wy = px - ix, py - iy
        g = lambda y, x: self._gather(self.data, corners, y, x)  # noqa: E731
        return ((1 - wy) * ((1 - wx) * g(iy, ix) + wx * g(iy, ix + 1))
                + wy * ((1 - wx) * g(iy + 1, ix) + wx * g(iy + 1, ix + 1)))

    def invert(self, sample, param):
        """Inverse of the continuous marginal-conditional warp (Mitsuba's invert_continuous)."""
        corners = self._corners(param)
        sx = np.clip(sample[..., 0], 0.0, 1.0) * (self.nx - 1)
        sy = np.clip(sample[..., 1], 0.0, 1.0) * (self.ny - 1)
        ix = np.minimum(sx.astype(np.intp), self.nx - 2)
        iy = np.minimum(sy.astype(np.intp), self.ny - 2)
        sx, sy = sx - ix, sy - iy
        d = lambda y, x: self._gather(self.data, corners, y, x)  # noqa: E731
        c = lambda y, x: self._gather(self.cond, corners, y, x)  # noqa: E731
        v00, v10, v01, v11 = d(iy, ix), d(iy, ix + 1), d(iy + 1, ix), d(iy + 1, ix + 1)
        c0 = (1 - sy) * v00 + sy * v01
        c1 = (1 - sy) * v10 + sy * v11
        ux = sx * (c0 + 0.5 * sx * (c1 - c0))
        ux = ux + (1 - sy) * c(iy, ix) + sy * c(iy + 1, ix)
        r0, r1 = c(iy, self.nx - 1), c(iy + 1, self.nx - 1)
        ux = ux / ((1 - sy) * r0 + sy * r1)
        uy = sy * (r0 + 0.5 * sy * (r1 - r0)) + self._gather(self.marg, corners, iy)
        return np.stack([ux, uy], axis=-1)


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
        ndf, sigma, vndf, rgb = (fields[k] for k in ("ndf", "sigma", "vndf", "rgb"))
        nphi, nth = phi_i.shape[0], theta_i.shape[0]
        if (ndf.ndim != 2 or sigma.ndim != 2 or vndf.shape[:2] != (nphi, nth) or vndf.ndim != 4
                or rgb.ndim != 5 or rgb.shape[:2] != (nphi, nth) or rgb.shape[2] != 3):
            raise FormatError(path, "field shapes do not match an RGB RGL tensor file: "
                              f"phi_i {phi_i.shape}, theta_i {theta_i.shape}, ndf {ndf.shape}, "
                              f"sigma {sigma.shape}, vndf {vndf.shape}, rgb {rgb.shape}")
        self.isotropic = nphi <= 2
        self.jacobian = bool(np.asarray(fields["jacobian"]).ravel()[0])
        self.reduction = 0
        if not self.isotropic:
            self.reduction = int(np.rint(2 * np.pi / (phi_i[-1] - phi_i[0])))
        desc = fields.get("description")
        self.description = bytes(np.asarray(desc, np.uint8)).decode("utf-8", "replace") \
            if desc is not None else ""
        self._ndf = _Conditional(ndf, [], warp=False)
        self._sigma = _Conditional(sigma, [], warp=False)
        self._vndf = _Conditional(vndf, [phi_i, theta_i], warp=True)
        self._rgb = _Conditional(rgb, [phi_i, theta_i, np.arange(3.0)], warp=False)

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
                w[..., 0] = _mulsign_neg(w[..., 0], sx)
                w[..., 1] = _mulsign_neg(w[..., 1], sy)
        m = wi + wo
        norm = np.linalg.norm(m, axis=-1, keepdims=True)
        m = m / np.where(norm > 0, norm, 1.0)
        theta_i, phi_i = _elevation(wi), np.arctan2(wi[..., 1], wi[..., 0])
        theta_m, phi_m = _elevation(m), np.arctan2(m[..., 1], m[..., 0])
        u_wi = np.stack([_theta2u(theta_i), _phi2u(phi_i)], axis=-1)
        um1 = _phi2u(phi_m - phi_i if self.isotropic else phi_m)
        u_m = np.stack([_theta2u(theta_m), um1 - np.floor(um1)], axis=-1)
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
