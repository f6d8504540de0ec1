"""The BRDF Explorer's slices as data: f_r against one angle (theta_o, theta_h or theta_d)
with the others fixed, and luminance over the theta_h x theta_d square.

Half/difference angles follow Rusinkiewicz (1998) (:func:`brdf.frames.half_diff_to_directions`);
for an anisotropic BRDF such as cloth phi_h matters too, so every slice takes it. Pairs with
either direction below the horizon evaluate to 0 (the BRDF's own convention).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.colour import luminance
from analysis.views.common import check_angle, check_resolution, eval_brdf, reduce_quantity
from brdf.frames import from_angles, half_diff_to_directions

__all__ = ["SliceView", "compute_slice_theta_o", "compute_slice_theta_h",
           "compute_slice_theta_d", "SliceImageView", "compute_slice_image"]


@dataclass(frozen=True, eq=False)
class SliceView:
    """f_r against one angle, the others fixed.

    Attributes
    ----------
    axis : str
        The swept angle: "theta_o", "theta_h" or "theta_d".
    x_deg : numpy.ndarray, shape (n,)
        Its values, degrees, from 0 to the slice's theta_max.
    rgb : numpy.ndarray, shape (n, 3)
        f_r in 1/sr, evaluated once.
    fixed : tuple of (str, float)
        The fixed angles (symbol, degrees), e.g. (("θi", 30.0), ("φi", 180.0), ("φo", 0.0)).
    """

    axis: str
    x_deg: np.ndarray
    rgb: np.ndarray
    fixed: tuple

    unit = "1/sr"

    def values(self, quantity="rgb") -> np.ndarray:
        """f_r (1/sr) reduced to ``quantity``: (n,) or (n, 3) for "rgb"."""
        return reduce_quantity(self.rgb, quantity)

    @property
    def caption(self) -> str:
        """The fixed angles in words, e.g. "θi = 30°, φi = 180°, φo = 0°"."""
        return ", ".join(f"{name} = {value:g}°" for name, value in self.fixed)


def _sweep(resolution, theta_max_deg) -> np.ndarray:
    v = float(theta_max_deg)
    if not 0.0 < v <= 90.0:
        raise ValueError(f"theta_max_deg must be in (0, 90] degrees; got {theta_max_deg!r}")
    return np.linspace(0.0, v, check_resolution(resolution, 2))


def compute_slice_theta_o(brdf, theta_i_deg=30.0, phi_i_deg=180.0, phi_o_deg=0.0, *,
                          resolution=181, theta_max_deg=89.5) -> SliceView:
    """f_r against theta_o in [0, theta_max_deg] at fixed wi and viewing azimuth (degrees)."""
    check_angle("theta_i_deg", theta_i_deg, 0.0, 90.0)
    x = _sweep(resolution, theta_max_deg)
    wi = from_angles(np.radians(theta_i_deg), np.radians(phi_i_deg))
    wo = from_angles(np.radians(x), np.radians(phi_o_deg))
    return SliceView("theta_o", x, eval_brdf(brdf, wi, wo),
                     (("θi", theta_i_deg), ("φi", phi_i_deg), ("φo", phi_o_deg)))


def compute_slice_theta_h(brdf, theta_d_deg=10.0, phi_d_deg=90.0, phi_h_deg=0.0, *,
                          resolution=181, theta_max_deg=89.5) -> SliceView:
    """f_r against theta_h in [0, theta_max_deg] at fixed theta_d, phi_d, phi_h (degrees)."""
    check_angle("theta_d_deg", theta_d_deg, 0.0, 90.0)
    x = _sweep(resolution, theta_max_deg)
    wi, wo = half_diff_to_directions(np.radians(x), np.radians(phi_h_deg),
                                     np.radians(theta_d_deg), np.radians(phi_d_deg))
    return SliceView("theta_h", x, eval_brdf(brdf, wi, wo),
                     (("θd", theta_d_deg), ("φd", phi_d_deg), ("φh", phi_h_deg)))


def compute_slice_theta_d(brdf, theta_h_deg=0.0, phi_d_deg=90.0, phi_h_deg=0.0, *,
                          resolution=181, theta_max_deg=89.5) -> SliceView:
    """f_r against theta_d in [0, theta_max_deg] at fixed theta_h, phi_d, phi_h (degrees)."""
    check_angle("theta_h_deg", theta_h_deg, 0.0, 90.0)
    x = _sweep(resolution, theta_max_deg)
    wi, wo = half_diff_to_directions(np.radians(theta_h_deg), np.radians(phi_h_deg),
                                     np.radians(x), np.radians(phi_d_deg))
    return SliceView("theta_d", x, eval_brdf(brdf, wi, wo),
                     (("θh", theta_h_deg), ("φd", phi_d_deg), ("φh", phi_h_deg)))


@dataclass(frozen=True, eq=False)
class SliceImageView:
    """Luminance f_r (1/sr) on the theta_h x theta_d grid at fixed phi_d, phi_h (degrees).

    Attributes
    ----------
    theta_deg : numpy.ndarray, shape (n,)
        Cell centres, (k + 1/2) 90 / n degrees (the same for both axes).
    image : numpy.ndarray, shape (n, n)
        Rows theta_d, columns theta_h.
    phi_d_deg, phi_h_deg : float
    """

    theta_deg: np.ndarray
    image: np.ndarray
    phi_d_deg: float
    phi_h_deg: float

    unit = "1/sr"


def compute_slice_image(brdf, phi_d_deg=90.0, phi_h_deg=0.0, resolution=90) -> SliceImageView:
    """Evaluate ``brdf`` once on the cells of the theta_h x theta_d image.

    Examples
    --------
    >>> class Grey:
    ...     def eval(self, wi, wo):
    ...         return np.full(wi.shape, 0.2)
    >>> v = compute_slice_image(Grey(), resolution=3)
    >>> v.theta_deg.tolist(), v.image.shape
    ([15.0, 45.0, 75.0], (3, 3))
    """
    n = check_resolution(resolution, 1)
    theta = (np.arange(n) + 0.5) * 90.0 / n
    TD, TH = np.meshgrid(np.radians(theta), np.radians(theta), indexing="ij")
    wi, wo = half_diff_to_directions(TH, np.radians(phi_h_deg), TD, np.radians(phi_d_deg))
    return SliceImageView(theta, luminance(eval_brdf(brdf, wi, wo)), float(phi_d_deg),
                          float(phi_h_deg))
