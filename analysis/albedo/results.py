"""What an albedo computation returns: one direction, a sweep, the hemispherical average."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

__all__ = ["AlbedoResult", "AlbedoCurve", "HemisphericalAlbedo"]


@dataclasses.dataclass(frozen=True, eq=False)
class AlbedoResult:
    """Directional albedo at one or more fixed directions.

    Attributes
    ----------
    value : ndarray, shape (..., 3)
        Albedo per RGB channel (dimensionless).
    error : ndarray, shape (..., 3)
        Estimated absolute error bound of ``value`` (see the module notes).
    direction : ndarray, shape (..., 3)
        The fixed direction: wo when ``swap`` is False, wi when True.
    swap : bool
        False: integral over wi of f_r cos(theta_i); True: integral over wo of f_r cos(theta_o).
    method : str
        ``"threads"``, ``"sphere"`` or ``"rqmc"`` (with the rule it scrambled).
    evals : int
        Number of (wi, wo) pairs at which the BRDF was evaluated.
    level : ndarray of int, shape (...)
        Finest level used per direction (gauss methods; -1 for rqmc).
    """

    value: np.ndarray
    error: np.ndarray
    direction: np.ndarray
    swap: bool
    method: str
    evals: int
    level: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return {
            "value": self.value.tolist(), "error": self.error.tolist(),
            "direction": self.direction.tolist(), "swap": self.swap,
            "method": self.method, "evals": int(self.evals), "level": self.level.tolist(),
        }


@dataclasses.dataclass(frozen=True, eq=False)
class AlbedoCurve:
    """Albedo over a (theta, phi) sweep of the fixed direction.

    Attributes
    ----------
    theta_deg, phi_deg : ndarray, shapes (T,), (P,)
        Polar angle from the normal and azimuth from the warp (+x), degrees.
    value, error : ndarray, shape (T, P, 3)
        Albedo and its error bound per RGB channel.
    swap : bool
        As in :class:`AlbedoResult`.
    method : str
        Quadrature used.
    evals : int
        BRDF evaluations in total.
    seconds : float
        Wall time of the computation.
    """

    theta_deg: np.ndarray
    phi_deg: np.ndarray
    value: np.ndarray
    error: np.ndarray
    swap: bool
    method: str
    evals: int
    seconds: float

    def max(self) -> dict[str, Any]:
        """The largest albedo over the sweep and channels, where it occurs, and its error.

        Returns
        -------
        dict
            ``value``, ``error``, ``theta_deg``, ``phi_deg``, ``channel`` (0, 1, 2 = R, G, B).
        """
        idx = np.unravel_index(int(np.argmax(self.value)), self.value.shape)
        return {
            "value": float(self.value[idx]), "error": float(self.error[idx]),
            "theta_deg": float(self.theta_deg[idx[0]]), "phi_deg": float(self.phi_deg[idx[1]]),
            "channel": int(idx[2]),
        }

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return {
            "theta_deg": self.theta_deg.tolist(), "phi_deg": self.phi_deg.tolist(),
            "value": self.value.tolist(), "error": self.error.tolist(), "swap": self.swap,
            "method": self.method, "evals": int(self.evals), "seconds": float(self.seconds),
            "max": self.max(),
        }


@dataclasses.dataclass(frozen=True, eq=False)
class HemisphericalAlbedo:
    """Hemispherical-hemispherical albedo (1/pi) integral of rho(w) cos(theta) dw.

    Attributes
    ----------
    value, error : ndarray, shape (3,)
        Per RGB channel; ``error`` adds the inner albedo errors (weighted) and the outer
        quadrature's two-resolution difference.
    evals : int
        BRDF evaluations in total.
    """

    value: np.ndarray
    error: np.ndarray
    evals: int

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return {"value": self.value.tolist(), "error": self.error.tolist(),
                "evals": int(self.evals)}

