"""CUReT BRDF measurements (Dana et al. 1999): ``abrdf.dat`` + ``table.txt``.

The geometry, as the files give it: camera and lamp lie in one plane with the sample, 22.5 to
157.5 degrees apart in steps of 22.5; 31 pairs of configurations are each other's image in the
mirror x -> -x with light and view exchanged (within 0.004 rad), where a reciprocal fabric
symmetric under that mirror has equal values: over the 61 samples the log ratio of such pairs
does not follow log(cos theta_i) (median slope 0.01), so the values are f_r up to a scale,
without a cos(theta_i) factor. In this geometry a pair whose half vector leans to -x is one
whose view is more oblique than its light (93 of 93), and to +x one whose light is more
oblique (84 of 84) (tests/test_gonio_curet.py).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from gonio.errors import FormatError
from gonio.exr import count_missing, from_angles
from gonio.safeopen import open_regular
from gonio.table import Table

__all__ = ["read_curet", "load_curet", "N_SAMPLES", "N_CONFIGS"]

N_SAMPLES = 61
N_CONFIGS = 205


def _read_numbers(path: Path, ncols: int, nrows: int, what: str) -> np.ndarray:
    with open_regular(path, what="a CUReT file") as fh:    # no link, FIFO or device
        data = fh.read()
    try:
        lines = [ln for ln in data.decode("ascii").splitlines() if ln.strip()]
    except UnicodeDecodeError:
        raise FormatError(path, f"not ASCII text; expected {what}") from None
    if len(lines) != nrows:
        raise FormatError(path, f"wrong size: {len(lines)} rows, expected {nrows} ({what})")
    out = np.empty((nrows, ncols))
    for k, line in enumerate(lines):
        fields = line.split()
        if len(fields) != ncols:
            raise FormatError(path, f"line {k + 1}: expected {ncols} numbers, got {len(fields)}")
        try:
            out[k] = [float(x) for x in fields]
        except ValueError:
            raise FormatError(path, f"line {k + 1}: not a number in {line.strip()[:60]!r}") \
                from None
    return out


def read_curet(folder, sample: int) -> Table:
    """One CUReT sample's 205 BRDF measurements as a Table.

    Parameters
    ----------
    folder : str or os.PathLike
        Folder holding ``abrdf.dat`` (61 rows: sample number, then 205 values) and
        ``table.txt`` (205 rows: index, theta_v, phi_v, theta_i, phi_i in radians), e.g.
        ``../shared/data/curet``.
    sample : int
        CUReT sample number, 1..61 (1 felt, 2 polyester, 3 terrycloth, 7 velvet, 44 linen...).

    Returns
    -------
    Table
        205 rows; wi = illumination (i) and wo = viewer (v) directions; values grey (the mean
        of R, G, B) repeated to 3 channels. CUReT values are **relative** reflectance, not
        f_r in 1/sr: ``meta["units"] = "relative"``; fit with a free scale.

    Notes
    -----
    The angles: CUReT's BRDF page (https://www.cs.columbia.edu/CAVE/software/curet/html/
    brdfm.html) and Dana et al. 1999 (ACM TOG 18(1), "Reflectance and texture of real-world
    surfaces") give one table of (viewing, illumination) directions for the 205
    measurements, polar angle from the sample's normal and azimuth about it, both in the
    sample's frame; ``table.txt`` holds them in the order index, theta_v, phi_v, theta_i,
    phi_i, radians. They are read as this project's angles (theta from n = +z, phi from +x
    toward +y) unchanged. The data agree: on the shiny polyester (sample 2) the largest value
    lies at an exact mirror pair (theta_v = theta_i = 79 degrees, phi_v = phi_i + 180) and the
    next three within 15 degrees of the mirror direction, as they must when both azimuths
    are measured in one frame and one sense.
    The geometry the angles make is in the module notes.
    What the files do not give is where the sample's warp points in that frame, nor
    whether phi turns counter-clockwise seen from above: a fit frees the fabric's
    ``rotation`` for that (a turned frame moves the fitted rotation by the turn; a mirrored
    one changes its sign; neither changes how well the model fits).

    Raises
    ------
    ValueError
        ``sample`` outside 1..61.
    FormatError
        Either file malformed (wrong row count, column count, or a non-number), or the
        sample's row missing.

    Examples
    --------
    >>> from tests.conftest import SHARED_DATA  # doctest: +SKIP
    >>> read_curet(SHARED_DATA / "curet", 44).meta["units"]  # doctest: +SKIP
    'relative'
    """
    if isinstance(sample, bool) or not isinstance(sample, (int, np.integer)) \
            or not 1 <= sample <= N_SAMPLES:
        raise ValueError(f"read_curet: sample must be an integer in 1..{N_SAMPLES}; got {sample!r}")
    folder = Path(folder)
    geometry = _read_numbers(folder / "table.txt", 5, N_CONFIGS, "index theta_v phi_v theta_i phi_i")
    if not np.array_equal(geometry[:, 0], np.arange(1, N_CONFIGS + 1)):
        raise FormatError(folder / "table.txt", "first column must count 1..205")
    data = _read_numbers(folder / "abrdf.dat", N_CONFIGS + 1, N_SAMPLES,
                         "sample number then 205 values")
    rows = np.flatnonzero(data[:, 0] == sample)
    if rows.size != 1:
        raise FormatError(folder / "abrdf.dat", f"sample {sample} appears {rows.size} times")
    values = data[rows[0], 1:]
    theta_v, phi_v, theta_i, phi_i = geometry[:, 1:].T
    meta = {
        "source": f"CUReT sample {int(sample)}",
        "file_format": "curet",
        "files": [str(folder / "abrdf.dat"), str(folder / "table.txt")],
        "units": "relative",
        "note": "CUReT relative reflectance (mean of R, G, B), not f_r in 1/sr",
        "curet_sample": int(sample),
        "missing_values": count_missing(np.repeat(values[:, None], 3, axis=1)),
    }
    return Table(from_angles(theta_i, phi_i), from_angles(theta_v, phi_v), values, None, meta)


def load_curet(folder, sample: int) -> Table:
    """Deprecated name of :func:`read_curet` (``read_*`` gives a Table, ``load_*`` a BRDF)."""
    warnings.warn("gonio.load_curet is deprecated; use gonio.read_curet (it returns a Table)",
                  DeprecationWarning, stacklevel=2)
    return read_curet(folder, sample)
