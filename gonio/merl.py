"""MERL ``.binary`` BRDF files (Matusik et al. 2003): read, look up, write.

File: three little-endian int32 (90, 90, 180), then 3 x 1,458,000 float64 (all red, then
green, then blue), scaled: f_r = stored * (1/1500, 1.15/1500, 1.66/1500); negative = missing.
Index (theta_h i, theta_d j, phi_d k): flat = k + 180 (j + 90 i), with bin i covering
theta_h in [(i/90)^2, ((i+1)/90)^2) * 90 degrees, j covering theta_d in [j, j+1) degrees and
k covering phi_d in [k, k+1) degrees, phi_d folded into [0, 180) (phi_d + 180 is the same
configuration with wi and wo exchanged, so equal by reciprocity).

Lookup is nearest-bin exactly as the MERL reference code (``BRDFRead.cpp``): each coordinate
is floored to its bin (no interpolation). The writer stores at each bin the BRDF evaluated at
the bin's centre, theta_h = ((i + 1/2)/90)^2 90 deg (the centre in the square-root mapped
coordinate), theta_d = j + 1/2 deg, phi_d = k + 1/2 deg, and reading a file as a Table puts
each value at that same centre, so Table -> .binary -> Table is exact bin by bin. (A lower
node would sit on a bin edge, where floating-point round-off sends the lookup to either side.)
"""

from __future__ import annotations

import os
import time
import warnings
from pathlib import Path

import numpy as np

from brdf.frames import from_angles, rotate_y, rotate_z
from brdf.protocols import BRDF
from gonio.atomic import atomic_write
from gonio.errors import FormatError
from gonio.exr import count_missing
from gonio.progress import progress_bar
from gonio.safeopen import open_regular
from gonio.table import Table

__all__ = ["MerlBRDF", "load_merl", "read_merl", "write_merl", "merl_table", "half_diff",
           "merl_index", "merl_directions", "SCALE", "SHAPE", "FILE_SIZE"]

SHAPE = (90, 90, 180)
N = 90 * 90 * 180
SCALE = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])
FILE_SIZE = 12 + 3 * 8 * N


def half_diff(wi, wo):
    """Rusinkiewicz coordinates (theta_h, phi_h, theta_d, phi_d), radians, as MERL computes them.

    Parameters
    ----------
    wi, wo : array_like, shape (..., 3)
        Unit vectors toward the light and the viewer.

    Returns
    -------
    tuple of numpy.ndarray
        theta_h, phi_h, theta_d, phi_d; the difference vector is wi expressed in the frame of
        the half vector (rotated by -phi_h about z, then -theta_h about y).
    """
    wi = np.asarray(wi, np.float64)
    wo = np.asarray(wo, np.float64)
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    theta_h = np.arccos(np.clip(h[..., 2], -1.0, 1.0))
    phi_h = np.arctan2(h[..., 1], h[..., 0])
    d = rotate_y(rotate_z(wi, -phi_h), -theta_h)
    theta_d = np.arccos(np.clip(d[..., 2], -1.0, 1.0))
    phi_d = np.arctan2(d[..., 1], d[..., 0])
    return theta_h, phi_h, theta_d, phi_d


def merl_index(theta_h, theta_d, phi_d) -> np.ndarray:
    """Flat MERL index of half/difference angles (radians), nearest (floored) bin.

    Examples
    --------
    >>> int(merl_index(0.0, 0.0, 0.0)), int(merl_index(np.pi / 2, np.radians(45.5), 0.1))
    (0, 1449905)
    """
    theta_h, theta_d, phi_d = np.broadcast_arrays(*(np.asarray(a, np.float64)
                                                    for a in (theta_h, theta_d, phi_d)))
    ih = np.where(theta_h <= 0, 0,
                  np.sqrt(np.maximum(theta_h, 0) / (np.pi / 2) * 90 * 90)).astype(np.int64)
    ih = np.clip(ih, 0, 89)
    jd = np.clip((theta_d / (np.pi / 2) * 90).astype(np.int64), 0, 89)
    pd = np.where(phi_d < 0, phi_d + np.pi, phi_d)
    kd = np.clip((pd / np.pi * 180).astype(np.int64), 0, 179)
    return kd + 180 * (jd + 90 * ih)


def merl_directions(i, j, k, phi_h=0.0):
    """(wi, wo) at the centre of MERL bins (i, j, k), rotated by ``phi_h`` about z.

    Returns
    -------
    wi, wo : numpy.ndarray, shape (..., 3)
    """
    theta_h = ((np.asarray(i, np.float64) + 0.5) / 90.0) ** 2 * (np.pi / 2)
    theta_d = np.radians(np.asarray(j, np.float64) + 0.5)
    phi_d = np.radians(np.asarray(k, np.float64) + 0.5)
    theta_h, theta_d, phi_d, phi_h = np.broadcast_arrays(theta_h, theta_d, phi_d,
                                                         np.asarray(phi_h, np.float64))
    d = from_angles(theta_d, phi_d)
    wi = rotate_z(rotate_y(d, theta_h), phi_h)
    h = from_angles(theta_h, phi_h)
    wo = 2.0 * np.sum(wi * h, axis=-1, keepdims=True) * h - wi
    return wi, wo


def _read_raw(path) -> np.ndarray:
    """The (3, N) scaled-to-1/sr array (negative entries left as they are)."""
    path = Path(path)
    with open_regular(path, what="a MERL table") as fh:    # no link, FIFO or device
        size = os.fstat(fh.fileno()).st_size
        head = fh.read(12)
        if len(head) < 12:
            raise FormatError(path, f"wrong size: {size} bytes, too short for the MERL header")
        dims = tuple(int(x) for x in np.frombuffer(head, "<i4"))
        if dims != SHAPE:
            raise FormatError(path, f"wrong magic: header dimensions {dims}, expected {SHAPE} "
                                    "(not a MERL .binary file)")
        if size != FILE_SIZE:
            raise FormatError(path, f"wrong size: {size} bytes, expected {FILE_SIZE} "
                                    "(truncated or padded)")
        raw = np.fromfile(fh, "<f8", 3 * N).reshape(3, N)
    return raw * SCALE[:, None]


class MerlBRDF:
    """An isotropic measured BRDF from a MERL table, looked up like the reference code.

    Build it with :func:`load_merl`. ``eval(wi, wo)`` -> (..., 3) f_r in 1/sr by
    nearest-bin lookup (see the module notes); missing (negative) entries are returned as
    they are stored, negative, so callers can flag them; 0 below the horizon.
    """

    def __init__(self, data: np.ndarray, path="<memory>"):
        self.data = np.asarray(data, np.float64).reshape(3, N)
        self.path = os.fspath(path)

    def __repr__(self):
        return f"MerlBRDF(file={self.path!r})"

    @property
    def missing_values(self) -> int:
        """Number of negative (missing) entries over the 3 x 1,458,000 table."""
        return int(np.count_nonzero(~(self.data >= 0)))

    def eval(self, wi, wo) -> np.ndarray:
        """RGB f_r (1/sr) at unit directions wi (to the light), wo (to the viewer), (..., 3)."""
        wi = np.asarray(wi, np.float64)
        wo = np.asarray(wo, np.float64)
        wi, wo = np.broadcast_arrays(wi, wo)
        above = (wi[..., 2] > 0) & (wo[..., 2] > 0)
        th, _, td, pd = half_diff(wi, wo)
        idx = merl_index(th, td, pd)
        out = np.moveaxis(self.data[:, idx], 0, -1)
        return np.where(above[..., None], out, 0.0)


def load_merl(path) -> MerlBRDF:
    """Load a MERL ``.binary`` file as a BRDF with ``eval(wi, wo)``.

    Raises
    ------
    FormatError
        Wrong header dimensions (magic) or wrong file size.
    """
    return MerlBRDF(_read_raw(path), path)


def read_merl(path, stride: int | tuple[int, int, int] = 1, keep_missing: bool = True) -> Table:
    """A MERL file as a Table at the centres of its bins.

    Parameters
    ----------
    path : str or os.PathLike
    stride : int or (int, int, int)
        Take every ``stride``-th bin along theta_h, theta_d, phi_d (1 = the full
        1,458,000-row grid).
    keep_missing : bool
        Keep rows with negative (missing) values (flagged in ``Table.valid``); when False
        they are dropped and ``meta["dropped_missing_rows"]`` says how many.
    """
    brdf = load_merl(path)
    s = (stride,) * 3 if np.ndim(stride) == 0 else tuple(stride)
    if len(s) != 3 or any(int(x) < 1 for x in s):
        raise ValueError(f"read_merl: stride must be a positive int or three; got {stride!r}")
    i, j, k = np.meshgrid(*(np.arange(0, n, int(st)) for n, st in zip(SHAPE, s)), indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    values = brdf.data[:, k + 180 * (j + 90 * i)].T
    wi, wo = merl_directions(i, j, k)
    meta = {"source": f"MERL {Path(path).name}", "file_format": "merl", "file": str(path),
            "stride": list(s), "units": "1/sr"}
    if not keep_missing:
        good = np.all(values >= 0, axis=1)
        meta["dropped_missing_rows"] = int(np.count_nonzero(~good))
        wi, wo, values = wi[good], wo[good], values[good]
    meta["missing_values"] = count_missing(values)
    return Table(wi, wo, values, None, meta)


def merl_table(path, stride=1, keep_missing: bool = True) -> Table:
    """Deprecated name of :func:`read_merl` (``read_*`` gives a Table, ``load_*`` a BRDF)."""
    warnings.warn("gonio.merl_table is deprecated; use gonio.read_merl (it returns a Table)",
                  DeprecationWarning, stacklevel=2)
    return read_merl(path, stride, keep_missing)


def _table_to_grid(table: Table) -> np.ndarray:
    """Mean of a table's valid values per MERL bin; -1 where a bin has none."""
    th, _, td, pd = half_diff(table.wi, table.wo)
    idx = merl_index(th, td, pd)
    out = np.full((3, N), -1.0)
    for c in range(3):
        ok = table.valid[:, c]
        sums = np.bincount(idx[ok], weights=table.values[ok, c], minlength=N)
        cnt = np.bincount(idx[ok], minlength=N)
        out[c] = np.where(cnt > 0, sums / np.maximum(cnt, 1), -1.0)
    return out


def write_merl(obj, path, rotations: int = 8, chunk_rows: int = 2, progress: bool = False):
    """Write a Table or any BRDF (object with ``eval(wi, wo)``) as a MERL ``.binary`` file.

    Parameters
    ----------
    obj : Table or BRDF
        A Table is binned: each MERL bin gets the mean of the valid values falling in it,
        -1 (missing) when none do. A BRDF is evaluated at every bin's centre.
    path : str or os.PathLike
        Destination; written atomically.
    rotations : int
        K. MERL is isotropic, so an anisotropic BRDF is averaged over K fabric rotations
        (wi and wo rotated together about z by 2 pi k / K, k = 0..K-1). K = 1 evaluates at
        phi_h = 0 only.
    chunk_rows : int
        theta_h rows evaluated at a time (each is 16,200 bins x K rotations), which bounds
        memory.
    progress : bool
        Show a tqdm bar.

    Notes
    -----
    Stored value = f_r / scale (scale = 1/1500, 1.15/1500, 1.66/1500 for R, G, B); bins
    where either direction is below the horizon, or the BRDF returns non-finite values, are
    stored as -1 (missing).
    """
    if isinstance(obj, Table):
        grid = _table_to_grid(obj)
    else:
        if not isinstance(obj, BRDF):
            raise ValueError(f"write_merl: need a Table or an object with eval(wi, wo); "
                             f"got {type(obj).__name__}")
        if int(rotations) < 1:
            raise ValueError(f"write_merl: rotations must be >= 1; got {rotations!r}")
        if int(chunk_rows) < 1:
            raise ValueError(f"write_merl: chunk_rows must be >= 1; got {chunk_rows!r}")
        grid = _brdf_to_grid(obj, int(rotations), int(chunk_rows), progress)
    stored = np.where(grid >= 0, grid / SCALE[:, None], -1.0)
    with atomic_write(path, "wb") as f:
        f.write(np.asarray(SHAPE, "<i4").tobytes())
        f.write(np.ascontiguousarray(stored, "<f8").tobytes())


def _brdf_to_grid(brdf, rotations: int, chunk_rows: int, progress: bool) -> np.ndarray:
    grid = np.empty((3, N))
    phis = 2 * np.pi * np.arange(rotations) / rotations
    rows = range(0, 90, chunk_rows)
    bar = progress_bar(len(rows), desc="MERL rows", unit="chunk", enabled=progress)
    jk = np.arange(90 * 180)
    j, k = jk // 180, jk % 180
    with bar:
        for i0 in rows:
            _grid_rows(brdf, grid, i0, min(i0 + chunk_rows, 90), phis, j, k, rotations)
            bar.update()
    return grid


def _grid_rows(brdf, grid, i0, i1, phis, j, k, rotations):
    """Fill the MERL grid's theta_h rows i0..i1 (averaged over the rotations ``phis``)."""
    i = np.repeat(np.arange(i0, i1), 90 * 180)
    jj, kk = np.tile(j, i1 - i0), np.tile(k, i1 - i0)
    # the horizon does not depend on the rotation about z: evaluate only bins above it
    wi, wo = merl_directions(i, jj, kk, 0.0)
    above = np.flatnonzero((wi[:, 2] > 0) & (wo[:, 2] > 0))
    i, jj, kk = i[above], jj[above], kk[above]
    acc = np.zeros((above.size, 3))
    bad = np.zeros(above.size, bool)
    for phi in phis:
        wi, wo = merl_directions(i, jj, kk, phi)
        f = np.asarray(brdf.eval(wi, wo), np.float64)
        finite = np.all(np.isfinite(f), axis=1)
        bad |= ~finite
        acc += np.where(finite[:, None], f, 0.0)
    vals = np.full((16200 * (i1 - i0), 3), -1.0)
    vals[above] = np.where(bad[:, None], -1.0, acc / rotations)
    grid[:, i0 * 16200:i1 * 16200] = vals.T


def time_write(brdf, path, rotations: int = 8) -> float:
    """Seconds taken by ``write_merl(brdf, path, rotations)`` (used by bench/)."""
    t0 = time.perf_counter()
    write_merl(brdf, path, rotations=rotations)
    return time.perf_counter() - t0
