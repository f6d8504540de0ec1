"""Reciprocity error maps as data: the relative error |f(wi, wo) - f(wo, wi)| / max over a
(theta_i, theta_o) grid at fixed azimuths."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.colour import luminance
from analysis.reciprocity import relative_asymmetry
from analysis.views.common import eval_brdf
from brdf.frames import from_angles

__all__ = ["ReciprocityView", "compute_reciprocity"]


@dataclass(frozen=True, eq=False)
class ReciprocityView:
    """The relative reciprocity error on a grid of incidence and viewing angles.

    Attributes
    ----------
    theta_deg : numpy.ndarray, shape (n,)
        Cell centres, (k + 1/2) 90 / n degrees (the same for theta_i and theta_o).
    error : numpy.ndarray, shape (n, n)
        Unitless, rows theta_i, columns theta_o: :func:`analysis.reciprocity.relative_asymmetry`
        of f(wi, wo) and f(wo, wi), 0 where both are 0, NaN where one is not finite.
    phi_i_deg, phi_o_deg : float
        The fixed azimuths of wi and wo, degrees.
    quantity : str
        "luminance" (Rec. 709 luminances compared) or "rgb" (the largest channel error).
    """

    theta_deg: np.ndarray
    error: np.ndarray
    phi_i_deg: float
    phi_o_deg: float
    quantity: str = "luminance"

    def finite_stats(self) -> tuple[float, float] | None:
        """(median, max) of the finite errors, None when none is finite."""
        finite = self.error[np.isfinite(self.error)]
        return (float(np.median(finite)), float(np.max(finite))) if finite.size else None


def compute_reciprocity(brdf, phi_i_deg=180.0, phi_o_deg=0.0, resolution=45,
                        quantity="luminance") -> ReciprocityView:
    """Evaluate ``brdf`` once each way on the cells of the map.

    Parameters
    ----------
    brdf : object with ``.eval``
    phi_i_deg, phi_o_deg : float
        Fixed azimuths of wi and wo in degrees (default: the plane of incidence along the
        warp, light and viewer on opposite sides).
    resolution : int
        Cells per axis; cell centres at theta = (k + 1/2) 90 / resolution degrees.
    quantity : {"luminance", "rgb"}

    Returns
    -------
    ReciprocityView

    Examples
    --------
    f_r = cos theta_i is reciprocal on the diagonal only; off it the error is
    |cos a - cos b| / max(cos a, cos b):

    >>> class CosineOfLight:
    ...     def eval(self, wi, wo):
    ...         f = np.asarray(wi)[..., 2:3] + 0 * np.asarray(wo)[..., :1]
    ...         return np.repeat(f, 3, axis=-1)
    >>> v = compute_reciprocity(CosineOfLight(), resolution=2)
    >>> v.theta_deg.tolist(), np.round(v.error, 4).tolist()
    ([22.5, 67.5], [[0.0, 0.5858], [0.5858, 0.0]])
    """
    if quantity not in ("luminance", "rgb"):
        raise ValueError(f"quantity must be 'luminance' or 'rgb'; got {quantity!r}")
    n = int(resolution)
    if n < 1:
        raise ValueError(f"resolution must be at least 1; got {resolution}")
    theta = (np.arange(n) + 0.5) * 90.0 / n
    TI, TO = np.meshgrid(np.radians(theta), np.radians(theta), indexing="ij")
    wi = from_angles(TI, np.radians(phi_i_deg))
    wo = from_angles(TO, np.radians(phi_o_deg))
    a = eval_brdf(brdf, wi, wo)
    b = eval_brdf(brdf, wo, wi)
    if quantity == "luminance":
        a, b = luminance(a), luminance(b)
    err = relative_asymmetry(a, b)
    err[(a == 0) & (b == 0)] = 0.0          # both zero: drawn as reciprocal
    if quantity == "rgb":
        err = err.max(axis=-1)
    return ReciprocityView(theta, err, phi_i_deg, phi_o_deg, quantity)
