"""Image files: float32 OpenEXR (linear RGB) and 8-bit sRGB PNG, written atomically.

Both writers put the file in a temporary file in the target folder and move it into place
with :func:`os.replace`, so an interrupted write (Ctrl-C included) leaves no partial file.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import OpenEXR
from PIL import Image

from gonio.atomic import atomic_write
from gonio.safeopen import open_regular

# colour-science's first import sets NumPy's print options to legacy="1.13", which would
# change every later array repr (doctests included): keep the options as they were
_PRINT_OPTIONS = np.get_printoptions()
import colour  # noqa: E402
np.set_printoptions(**_PRINT_OPTIONS)

__all__ = ["write_exr", "read_exr", "read_exr_attributes", "write_png", "encode_srgb",
           "check_output"]


def _check_rgb(rgb):
    a = np.asarray(rgb)
    if a.ndim != 3 or a.shape[2] != 3 or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"image of shape {a.shape} must be (height, width, 3)")
    return a


def check_output(path):
    """Raise OSError at once unless the folder of ``path`` exists and is writable.

    Examples
    --------
    >>> check_output("/nonexistent-folder/out.exr")
    Traceback (most recent call last):
    ...
    FileNotFoundError: output folder /nonexistent-folder does not exist
    """
    folder = Path(path).resolve().parent
    if not folder.is_dir():
        raise FileNotFoundError(f"output folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PermissionError(f"output folder {folder} is not writable")
    if Path(path).is_dir():
        raise IsADirectoryError(f"output {path} is a folder")


def _atomic(path, write):
    """Call ``write(tmp_path)`` on a temporary file that is moved onto ``path`` on success."""
    path = Path(path)
    check_output(path)
    with atomic_write(path, "wb") as fh:
        write(fh.tmp_path)
    return path


def write_exr(path, rgb, attributes=None):
    """Write linear RGB as a float32 OpenEXR file (one ``RGB`` channel group, ZIP).

    Parameters
    ----------
    path : str or Path
        Output file.
    rgb : (height, width, 3) array_like
        Linear radiance; stored as float32.
    attributes : dict, optional
        Extra header attributes, name -> float or str (e.g. the exposure,
        :func:`reports.render.exposure.exr_attributes`); :func:`read_exr_attributes` reads them.

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "x.exr"
    >>> _ = write_exr(out, np.full((2, 3, 3), 0.25))
    >>> read_exr(out)[1, 2].tolist()
    [0.25, 0.25, 0.25]
    """
    a = np.ascontiguousarray(_check_rgb(rgb), dtype=np.float32)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    for key, value in (attributes or {}).items():
        if not isinstance(value, (float, str)) or key in header:
            raise ValueError(f"EXR attribute {key!r}={value!r}: a new name with a float or "
                             f"str value expected")
        header[key] = value

    def write(tmp):
        with OpenEXR.File(header, {"RGB": a}) as f:
            f.write(str(tmp))

    return _atomic(path, write)


def read_exr(path):
    """Read an RGB OpenEXR file written by :func:`write_exr`: (height, width, 3) float32.

    Raises
    ------
    ValueError
        If the file is not a readable OpenEXR image with R, G and B channels.
    """
    try:            # opened once: no link, FIFO or device (one line naming it)
        with open_regular(path, what="an OpenEXR image") as fh, OpenEXR.File(fh) as f:
            ch = f.channels()
            if "RGB" in ch:
                return np.asarray(ch["RGB"].pixels, dtype=np.float32)
            return np.stack([np.asarray(ch[c].pixels, np.float32) for c in "RGB"], axis=-1)
    except (KeyError, RuntimeError) as exc:
        raise ValueError(f"{path}: not a readable RGB OpenEXR file ({exc})") from None


def read_exr_attributes(path) -> dict:
    """The float and str attributes of an OpenEXR file's header (its own and microcyl's).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "x.exr"
    >>> _ = write_exr(out, np.zeros((1, 1, 3)), {"microcyl_exposure_stops": 1.5})
    >>> read_exr_attributes(out)["microcyl_exposure_stops"]
    1.5
    """
    try:
        with open_regular(path, what="an OpenEXR image") as fh, \
                OpenEXR.File(fh) as f:   # the header is emptied when the file closes
            return {k: v for k, v in f.header().items() if isinstance(v, (float, str))}
    except (KeyError, RuntimeError) as exc:
        raise ValueError(f"{path}: not a readable OpenEXR file ({exc})") from None


def encode_srgb(rgb, exposure=0.0):
    """Linear RGB -> sRGB-encoded values in [0, 1] (colour-science's sRGB CCTF).

    Parameters
    ----------
    rgb : array_like
        Linear values.
    exposure : float
        Stops: the values are multiplied by ``2 ** exposure`` before encoding.

    Returns
    -------
    ndarray
        ``cctf_encoding(clip(rgb * 2**exposure, 0, 1), "sRGB")``.

    Examples
    --------
    >>> np.round(encode_srgb(np.array([0.0, 0.214041, 1.0, 4.0])), 6).tolist()
    [0.0, 0.5, 1.0, 1.0]
    """
    exposure = float(exposure)
    if not np.isfinite(exposure):
        raise ValueError(f"exposure={exposure} must be a finite number of stops")
    x = np.asarray(rgb, dtype=np.float64) * 2.0 ** exposure
    x = np.clip(np.nan_to_num(x, nan=0.0, posinf=1.0), 0.0, 1.0)
    return np.asarray(colour.cctf_encoding(x, function="sRGB"))


def write_png(path, rgb, exposure=0.0):
    """Write linear RGB as an 8-bit sRGB PNG (values scaled by ``2 ** exposure``, clipped).

    Parameters
    ----------
    path : str or Path
        Output file.
    rgb : (height, width, 3) array_like
        Linear radiance.
    exposure : float
        Exposure in stops.

    Returns
    -------
    Path
        ``path``.
    """
    a = _check_rgb(rgb)
    q = np.round(encode_srgb(a, exposure) * 255.0).astype(np.uint8)

    def write(tmp):
        Image.fromarray(q).save(tmp, format="PNG")

    return _atomic(path, write)
