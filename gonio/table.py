"""The BRDF table: measured or simulated f_r values at (wi, wo) pairs."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np

from brdf.frames import normalize, to_angles

__all__ = ["Table"]


def _as_n3(name: str, value, n: int | None) -> np.ndarray:
    try:
        arr = np.array(value, dtype=np.float64)   # a copy: the caller's arrays are never changed
    except (TypeError, ValueError):
        raise ValueError(f"Table {name} must be a numeric array of shape (n, 3); got "
                         f"{value!r}"[:200]) from None
    if arr.ndim == 1 and name in ("values", "sigma"):
        arr = np.repeat(arr[:, None], 3, axis=1)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"Table {name} must have shape (n, 3); got {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(f"Table {name} has {arr.shape[0]} rows; wi has {n}")
    return arr


@dataclasses.dataclass(frozen=True, eq=False)
class Table:
    """A BRDF table: RGB f_r (1/sr, no cosine) at n direction pairs.

    Parameters
    ----------
    wi, wo : array_like, shape (n, 3)
        Unit directions toward the light and toward the viewer, in the sample's local frame
        (n = +z, warp = +x). Re-normalized on construction.
    values : array_like, shape (n, 3) or (n,)
        f_r in 1/sr per RGB channel (a 1-D array is grey and repeated to 3 channels). NaN or
        negative values are kept: they mark missing or invalid measurements (see ``valid``).
    sigma : array_like, shape (n, 3) or (n,), optional
        Standard deviation of each value in 1/sr, or None when unknown.
    meta : dict, optional
        What was measured and how: source, geometry, instrument, seed, units, version.

    Examples
    --------
    >>> t = Table([[0, 0, 1.0]], [[0, 0, 1.0]], [[0.1, 0.2, 0.3]])
    >>> len(t), t.values.shape, t.sigma
    (1, (1, 3), None)
    """

    wi: np.ndarray
    wo: np.ndarray
    values: np.ndarray
    sigma: np.ndarray | None = None
    meta: dict[str, Any] = dataclasses.field(default_factory=dict)

    def __post_init__(self):
        wi = _as_n3("wi", self.wi, None)
        n = wi.shape[0]
        wo = _as_n3("wo", self.wo, n)
        for name, w in (("wi", wi), ("wo", wo)):
            with np.errstate(over="ignore", under="ignore"):
                norm = np.linalg.norm(w, axis=1, keepdims=True)
            if not np.all((norm > 2.0 ** -500) & (norm < 2.0 ** 500)):  # scale first
                unit, bad = normalize(w)
                if bad.any():
                    raise ValueError(f"Table {name} holds zero or non-finite directions (row "
                                     f"{int(np.argmax(bad))})")
                w[...] = unit
            else:
                w /= norm
        values = _as_n3("values", self.values, n)
        sigma = None if self.sigma is None else _as_n3("sigma", self.sigma, n)
        object.__setattr__(self, "wi", wi)
        object.__setattr__(self, "wo", wo)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "sigma", sigma)
        if not isinstance(self.meta, Mapping):
            raise ValueError(f"Table meta must be a dict; got {type(self.meta).__name__}")
        object.__setattr__(self, "meta", dict(self.meta))

    def __len__(self) -> int:
        return self.wi.shape[0]

    @property
    def valid(self) -> np.ndarray:
        """(n, 3) bool: True where the value is finite and non-negative."""
        return np.isfinite(self.values) & (self.values >= 0)

    @property
    def angles(self) -> np.ndarray:
        """(n, 4) array of theta_i, phi_i, theta_o, phi_o in radians.

        theta is the polar angle from n = +z; phi the azimuth from +x toward +y, in (-pi, pi].
        """
        ti, pi_ = to_angles(self.wi)
        to, po = to_angles(self.wo)
        return np.stack([ti, pi_, to, po], axis=1)

    def replace(self, **changes) -> "Table":
        """Return a copy with the given fields replaced."""
        return dataclasses.replace(self, **changes)
