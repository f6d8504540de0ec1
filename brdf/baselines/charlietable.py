r"""The Charlie sheen's directional albedo E(cos theta, roughness) as a table: its grid, the
checked-in values (charlie_albedo.json beside this module) and their bilinear interpolation.

Grid: u = sqrt(cos theta) = k / N_U for k = 1..N_U (nodes crowd toward grazing, where E changes
fastest; cos theta from 1/4096 to 1) by roughness r from R_MIN to 1 in N_R equal steps of
sqrt(r) (E changes fastest at small roughness). The values
are the quadrature :func:`brdf.baselines.charlie.albedo_table` computes;
``bench/charlie_albedo_table.py`` regenerates the file (deterministic bytes, about 15 s).
Interpolation is bilinear in (u, sqrt(roughness)), the arguments clamped to the grid.

Examples
--------
>>> U.shape, R.shape, table().shape
((64,), (33,), (64, 33))
>>> bool(np.isclose(interpolate(U[3] ** 2, R[7]), table()[3, 7]))
True
"""

from __future__ import annotations

import json
import os
import tempfile
from functools import lru_cache
from pathlib import Path

import numpy as np

__all__ = ["N_U", "N_R", "R_MIN", "U", "R", "PATH", "table", "interpolate", "cos_nodes",
           "interpolate_nodes", "write"]

N_U, N_R = 64, 33
#: The least roughness tabulated (Filament's MIN_PERCEPTUAL_ROUGHNESS).
R_MIN = 0.045
#: sqrt(cos theta) nodes and roughness nodes.
U = np.arange(1, N_U + 1) / N_U
R = np.linspace(np.sqrt(R_MIN), 1.0, N_R) ** 2
_V0 = float(np.sqrt(R_MIN))
#: The checked-in table.
PATH = Path(__file__).with_name("charlie_albedo.json")


@lru_cache(maxsize=1)
def table() -> np.ndarray:
    """The tabulated E (N_U, N_R), read once from :data:`PATH`; a clear error if it is
    missing or not of the grid's shape."""
    try:
        data = json.loads(PATH.read_text())
        values = np.asarray(data["E"], dtype=np.float64)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise OSError(f"{PATH}: cannot read the Charlie albedo table ({exc}); regenerate it "
                      f"with bench/charlie_albedo_table.py") from None
    if values.shape != (N_U, N_R) or not np.all(np.isfinite(values)):
        raise OSError(f"{PATH}: the Charlie albedo table must be {N_U} x {N_R} finite numbers; "
                      f"got shape {values.shape}")
    return values


def cos_nodes(cos) -> tuple[np.ndarray, np.ndarray]:
    """The table row below each cos theta and the fraction toward the next, ``(i, fx)``: the
    direction-dependent half of :func:`interpolate`, computed once for fixed pairs."""
    u = np.sqrt(np.clip(np.asarray(cos, dtype=np.float64), 0.0, 1.0))
    x = np.clip(u * N_U - 1.0, 0.0, N_U - 1.0)
    i = np.minimum(x.astype(int), N_U - 2)
    return i, x - i


def _columns(roughness):
    v = np.sqrt(np.maximum(np.asarray(roughness, dtype=np.float64), 0.0))
    y = np.clip((v - _V0) / (1.0 - _V0) * (N_R - 1), 0.0, N_R - 1.0)
    j = np.minimum(y.astype(int), N_R - 2)
    return j, y - j


def interpolate_nodes(i, fx, roughness) -> np.ndarray:
    """E from :func:`cos_nodes`' ``(i, fx)`` (n,) and roughness (B..., 1): (B..., n). The
    table is first interpolated along roughness (B..., N_U), then gathered at the rows."""
    j, fy = _columns(np.asarray(roughness)[..., 0])
    t = table()
    rows = t[:, j] * (1.0 - fy) + t[:, j + 1] * fy                  # (N_U, B...)
    rows = np.moveaxis(rows, 0, -1)[..., None, :]                    # (B..., 1, N_U)
    return (1.0 - fx) * rows[..., 0, i] + fx * rows[..., 0, i + 1]


def interpolate(cos, roughness) -> np.ndarray:
    """Bilinear E at (cos theta, roughness) (broadcast) in (sqrt(cos theta), sqrt(roughness)),
    the arguments clamped to the grid."""
    i, fx = cos_nodes(cos)
    j, fy = _columns(roughness)
    t = table()
    return ((1 - fx) * ((1 - fy) * t[i, j] + fy * t[i, j + 1])
            + fx * ((1 - fy) * t[i + 1, j] + fy * t[i + 1, j + 1]))


def write(values: np.ndarray, path: Path = PATH) -> None:
    """Write the table (N_U, N_R) as JSON, atomically (a temporary file, then rename)."""
    values = np.asarray(values, dtype=np.float64)
    if values.shape != (N_U, N_R):
        raise ValueError(f"values must have shape ({N_U}, {N_R}); got {values.shape}")
    text = json.dumps({"about": "Charlie sheen directional albedo E[k][j] at cos theta = "
                       "U[k]^2, roughness R[j]; written by bench/charlie_albedo_table.py",
                       "U": [float(u) for u in U], "R": [float(r) for r in R],
                       "E": [[float(f"{v:.9g}") for v in row] for row in values]}, indent=1)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text + "\n")
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise
    table.cache_clear()
