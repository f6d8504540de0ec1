r"""The stated hemisphere grid of an export: where a projection is fitted and its fidelity
measured.

Directions sit at the midpoints of ``n_theta`` equal polar bins over [0, 90) degrees and
``n_phi`` equal azimuth bins over [0, 360) degrees; every incident direction is paired with
every outgoing one, each pair weighted by the product of the two cells' solid angles

    dw = (cos(theta - dtheta/2) - cos(theta + dtheta/2)) dphi        (sr)

so that sum(w g) approximates the double integral of g over both hemispheres (sr^2). The full
azimuth range is kept (no symmetry assumed): an anisotropic source is seen as it is.

Examples
--------
>>> g = HemisphereGrid(6, 8)
>>> g.wi.shape, round(float(g.weights.sum() / (2 * np.pi) ** 2), 12)    # (2 pi)^2 sr^2
((2304, 3), 1.0)
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

__all__ = ["HemisphereGrid", "albedo_rule", "DEFAULT_GRID"]


@dataclasses.dataclass(frozen=True)
class HemisphereGrid:
    """Pairs of directions over the upper hemisphere (module notes).

    Attributes
    ----------
    n_theta : int
        Polar bins over [0, 90) degrees (midpoints at (k + 1/2) 90 / n_theta degrees).
    n_phi : int
        Azimuth bins over [0, 360) degrees (midpoints at (k + 1/2) 360 / n_phi degrees).
    """

    n_theta: int = 9
    n_phi: int = 12

    def __post_init__(self):
        for name, v, lo in (("n_theta", self.n_theta, 2), ("n_phi", self.n_phi, 4)):
            if not isinstance(v, int) or isinstance(v, bool) or not lo <= v <= 64:
                raise ValueError(f"grid {name} must be an integer in [{lo}, 64]; got {v!r}")

    @functools.cached_property
    def _cells(self):
        dt, dp = 0.5 * np.pi / self.n_theta, 2.0 * np.pi / self.n_phi
        t = (np.arange(self.n_theta) + 0.5) * dt
        p = (np.arange(self.n_phi) + 0.5) * dp
        T, P = np.meshgrid(t, p, indexing="ij")
        d = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1)
        dw = (np.cos(T - dt / 2) - np.cos(T + dt / 2)) * dp
        return d.reshape(-1, 3), dw.ravel()

    @property
    def directions(self) -> np.ndarray:
        """The cell midpoints (m, 3), m = n_theta n_phi."""
        return self._cells[0]

    @property
    def wi(self) -> np.ndarray:
        """Incident directions of every pair (m^2, 3)."""
        d = self._cells[0]
        return np.repeat(d, len(d), axis=0)

    @property
    def wo(self) -> np.ndarray:
        """Outgoing directions of every pair (m^2, 3)."""
        d = self._cells[0]
        return np.tile(d, (len(d), 1))

    @property
    def weights(self) -> np.ndarray:
        """Solid-angle weights of every pair (m^2,), sr^2."""
        dw = self._cells[1]
        return np.outer(dw, dw).ravel()

    def describe(self) -> str:
        """The grid in words (for the fidelity file and the terminal)."""
        return (f"{self.n_theta} x {self.n_phi} directions per hemisphere (theta at the "
                f"midpoints of {90 / self.n_theta:g} deg bins over [0, 90), phi of "
                f"{360 / self.n_phi:g} deg bins over [0, 360)), every incident with every "
                f"outgoing direction, weighted by solid angle")

    def as_dict(self) -> dict:
        """The grid as plain data."""
        return {"n_theta": self.n_theta, "n_phi": self.n_phi, "pairs": len(self.weights),
                "description": self.describe()}


#: The grid of ``microcyl export``: 108 directions a hemisphere, 11664 pairs.
DEFAULT_GRID = HemisphereGrid(9, 12)


def albedo_rule(theta_i_deg: float, n_mu: int = 24, n_phi: int = 48):
    """Outgoing directions and weights for a directional albedo at incidence ``theta_i_deg``
    (degrees, azimuth 0): Gauss-Legendre in cos(theta_o) over [0, 1] times ``n_phi``
    equal azimuths over [0, 2 pi); sum(w g(wo)) ~ integral of g cos(theta_o) dwo.

    Returns ``(wi (n, 3), wo (n, 3), w (n,))``.

    Examples
    --------
    >>> wi, wo, w = albedo_rule(30.0)
    >>> round(float(w.sum() / np.pi), 12)          # integral of cos over the hemisphere
    1.0
    """
    x, wx = np.polynomial.legendre.leggauss(n_mu)
    mu, wmu = 0.5 * (x + 1.0), 0.5 * wx
    ph = (np.arange(n_phi) + 0.5) * 2.0 * np.pi / n_phi
    M, P = np.meshgrid(mu, ph, indexing="ij")
    s = np.sqrt(1.0 - M * M)
    wo = np.stack([s * np.cos(P), s * np.sin(P), M], -1).reshape(-1, 3)
    w = (np.outer(wmu, np.full(n_phi, 2.0 * np.pi / n_phi)) * M).ravel()
    t = np.radians(theta_i_deg)
    wi = np.broadcast_to([np.sin(t), 0.0, np.cos(t)], wo.shape)
    return np.ascontiguousarray(wi), wo, w
