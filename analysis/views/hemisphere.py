"""f_r(wo) over the viewing hemisphere for a fixed light, as data: the equal-area disc of the
hemisphere plot and the surface of the 3-D lobe.

Lambert's azimuthal equal-area projection puts a viewing direction at polar angle theta and
azimuth phi at radius rho = sqrt(2) sin(theta / 2) (1 at the horizon) and angle phi in the
unit disc: equal solid angles cover equal areas. +x is the warp, +y the weft.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.colour import luminance
from analysis.views.common import check_angle, eval_brdf
from brdf.frames import from_angles

__all__ = ["equal_area_xy", "equal_area_grid", "HemisphereView", "compute_hemisphere",
           "Lobe3DView", "compute_lobe_3d"]


def equal_area_xy(w):
    """Disc coordinates (x, y) of unit directions (..., 3) in the equal-area projection.

    Examples
    --------
    >>> [round(float(v), 6) for v in equal_area_xy(np.array([1.0, 0.0, 0.0]))]
    [1.0, 0.0]
    """
    w = np.asarray(w, dtype=np.float64)
    theta = np.arccos(np.clip(w[..., 2], -1.0, 1.0))
    phi = np.arctan2(w[..., 1], w[..., 0])
    rho = np.sqrt(2.0) * np.sin(theta / 2.0)
    return rho * np.cos(phi), rho * np.sin(phi)


def equal_area_grid(resolution=101):
    """Pixel centres of a square image over [-1, 1]^2 and their directions.

    Parameters
    ----------
    resolution : int
        Pixels per side.

    Returns
    -------
    x, y : numpy.ndarray, shape (resolution, resolution)
        Pixel centres (row index = y, increasing upward when drawn with origin="lower").
    inside : numpy.ndarray of bool
        Pixels inside the unit disc (the hemisphere).
    wo : numpy.ndarray, shape (resolution, resolution, 3)
        Directions of the pixels (those outside the disc are clamped to the horizon).

    Notes
    -----
    Inverse projection: rho = sqrt(x^2 + y^2), theta = 2 asin(rho / sqrt 2), phi = atan2(y, x).
    """
    n = int(resolution)
    if n < 2:
        raise ValueError(f"resolution must be at least 2; got {resolution}")
    c = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    y, x = np.meshgrid(c, c, indexing="ij")
    rho = np.hypot(x, y)
    inside = rho <= 1.0
    theta = 2.0 * np.arcsin(np.clip(rho, 0.0, 1.0) / np.sqrt(2.0))
    return x, y, inside, from_angles(theta, np.arctan2(y, x))


@dataclass(frozen=True, eq=False)
class HemisphereView:
    """RGB f_r(wo) (1/sr) over the equal-area disc for one light.

    Attributes
    ----------
    theta_i_deg, phi_i_deg : float
        The light's direction, degrees.
    rgb : numpy.ndarray, shape (n, n, 3)
        f_r, evaluated once; NaN outside the disc.
    wo : numpy.ndarray, shape (n, n, 3)
        The pixels' directions (:func:`equal_area_grid`).
    """

    theta_i_deg: float
    phi_i_deg: float
    rgb: np.ndarray
    wo: np.ndarray

    unit = "1/sr"

    @property
    def wi(self) -> np.ndarray:
        """The light's direction, shape (3,)."""
        return from_angles(np.radians(self.theta_i_deg), np.radians(self.phi_i_deg))

    def values(self, cosine=False) -> np.ndarray:
        """RGB f_r, or f_r cos(theta_o) when ``cosine`` (1/sr; NaN outside the disc)."""
        return self.rgb * self.wo[..., 2:3] if cosine else self.rgb

    def peak(self, cosine=False) -> float:
        """The largest luminance of the disc (1/sr; 0 when none is finite)."""
        lum = luminance(self.values(cosine))
        return float(np.nanmax(lum)) if np.any(np.isfinite(lum)) else 0.0


def compute_hemisphere(brdf, theta_i_deg=45.0, phi_i_deg=0.0, resolution=101) -> HemisphereView:
    """Evaluate ``brdf`` once on the pixels of the disc for the light at (theta_i, phi_i)."""
    check_angle("theta_i_deg", theta_i_deg, 0.0, 90.0)
    _, _, inside, wo = equal_area_grid(resolution)
    wi = from_angles(np.radians(theta_i_deg), np.radians(phi_i_deg))
    values = np.full(wo.shape, np.nan)
    values[inside] = eval_brdf(brdf, wi, wo[inside])    # the disc's pixels only
    return HemisphereView(theta_i_deg, phi_i_deg, values, wo)


@dataclass(frozen=True, eq=False)
class Lobe3DView:
    """The 3-D lobe: r(wo) over a (theta_o, phi_o) grid of the upper hemisphere.

    Attributes
    ----------
    theta_i_deg, phi_i_deg : float
        The light's direction, degrees.
    theta_o : numpy.ndarray, shape (nt, np)
        Polar angles of the grid, radians.
    wo : numpy.ndarray, shape (nt, np, 3)
    r : numpy.ndarray, shape (nt, np)
        Luminance f_r, times cos(theta_o) when ``cosine`` (1/sr).
    cosine : bool
    """

    theta_i_deg: float
    phi_i_deg: float
    theta_o: np.ndarray
    wo: np.ndarray
    r: np.ndarray
    cosine: bool

    unit = "1/sr"

    @property
    def wi(self) -> np.ndarray:
        return from_angles(np.radians(self.theta_i_deg), np.radians(self.phi_i_deg))

    @property
    def xyz(self) -> tuple:
        """The surface's points r wo: X, Y, Z, each (nt, np), in 1/sr."""
        return tuple(self.r * self.wo[..., k] for k in range(3))


def compute_lobe_3d(brdf, theta_i_deg=45.0, phi_i_deg=0.0, *, cosine=True,
                    resolution=(30, 60)) -> Lobe3DView:
    """Evaluate ``brdf`` once on a grid of ``resolution`` = (theta_o samples over [0, 90],
    phi_o samples over [0, 360]) degrees for the light at (theta_i, phi_i)."""
    check_angle("theta_i_deg", theta_i_deg, 0.0, 89.999)
    nt, npf = (int(v) for v in resolution)
    if nt < 2 or npf < 3:
        raise ValueError(f"resolution must be at least (2, 3); got {resolution}")
    t = np.radians(np.linspace(0.0, 90.0, nt))
    p = np.radians(np.linspace(0.0, 360.0, npf))
    T, P = np.meshgrid(t, p, indexing="ij")
    wo = from_angles(T, P)
    wi = from_angles(np.radians(theta_i_deg), np.radians(phi_i_deg))
    r = luminance(eval_brdf(brdf, wi, wo))
    if cosine:
        r = r * np.cos(T)
    return Lobe3DView(theta_i_deg, phi_i_deg, T, wo, r, bool(cosine))
