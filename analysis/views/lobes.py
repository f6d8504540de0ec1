"""Lobes in planes of incidence as data: each curve evaluated once, and every figure, CSV and
number of a lobe view read from the same arrays.

A *plane of incidence* is the vertical plane at azimuth ``phi`` (0 = along the warp, 90 =
along the weft, 45 = the diagonal). The light sits on the negative side, wi at signed angle
-theta_i (azimuth phi + 180 degrees); the viewer sweeps the signed angle theta_o from -90 to
90 degrees, positive toward azimuth phi, so the mirror direction is at +theta_i.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.views.common import (check_angle, check_resolution, eval_brdf,
                                   finite_max, reduce_quantity)
from brdf.frames import from_angles

__all__ = ["plane_directions", "LobeView", "compute_lobes", "MaskingLobesView",
           "compute_masking_lobes"]


def plane_directions(theta_i_deg, theta_o_deg, phi_deg=0.0):
    """Directions in the plane of incidence at azimuth ``phi_deg``.

    Parameters
    ----------
    theta_i_deg : float
        Polar angle of the light in degrees, [0, 90); wi lies at azimuth phi + 180.
    theta_o_deg : array_like
        Signed viewing angles in degrees, [-90, 90]; positive toward azimuth phi.
    phi_deg : float
        Azimuth of the plane in degrees (from the warp, +x, toward the weft, +y).

    Returns
    -------
    wi : numpy.ndarray, shape (3,)
    wo : numpy.ndarray, shape (n, 3)

    Examples
    --------
    >>> wi, wo = plane_directions(30.0, [30.0], 0.0)
    >>> np.round(wi, 6).tolist(), np.round(wo, 6).tolist()
    ([-0.5, 0.0, 0.866025], [[0.5, 0.0, 0.866025]])
    """
    phi = np.radians(float(phi_deg))
    wi = from_angles(np.radians(float(theta_i_deg)), phi + np.pi)
    s = np.radians(np.atleast_1d(np.asarray(theta_o_deg, dtype=np.float64)))
    wo = np.stack([np.sin(s) * np.cos(phi), np.sin(s) * np.sin(phi), np.cos(s)], axis=-1)
    return wi, wo


def _index(values, value, name) -> int:
    """Position of ``value`` (degrees) in ``values``; a ValueError when it is not there."""
    hit = np.flatnonzero(np.isclose(np.asarray(values, dtype=np.float64), float(value),
                                    rtol=0.0, atol=1e-9))
    if hit.size == 0:
        raise ValueError(f"{name} must be one of the view's "
                         f"({', '.join(f'{v:g}' for v in values)}); got {float(value):g}")
    return int(hit[0])


@dataclass(frozen=True, eq=False)
class LobeView:
    """f_r of one BRDF in planes of incidence: a curve per plane and incidence.

    Attributes
    ----------
    theta_o_deg : numpy.ndarray, shape (n,)
        Signed viewing angles, degrees, -90 to 90 (:func:`plane_directions`).
    theta_i_deg : tuple of float
        Incidences, degrees.
    planes_deg : tuple of float
        Azimuths of the planes, degrees.
    rgb : numpy.ndarray, shape (len(planes_deg), len(theta_i_deg), n, 3)
        f_r in 1/sr, evaluated once; every quantity and figure of the view derives from it.
    cosine : bool
        Whether the curves are f_r cos(theta_o) (the visible lobe) rather than f_r.
    """

    theta_o_deg: np.ndarray
    theta_i_deg: tuple
    planes_deg: tuple
    rgb: np.ndarray
    cosine: bool = False

    #: Unit of every curve.
    unit = "1/sr"

    @property
    def label(self) -> str:
        """What the curves are: "f_r" or "f_r cos θo"."""
        return "f_r cos θo" if self.cosine else "f_r"

    def curve(self, phi_deg, theta_i_deg, quantity="luminance") -> np.ndarray:
        """The curve of one plane and incidence (1/sr): (n,) or (n, 3) for "rgb"."""
        p = _index(self.planes_deg, phi_deg, "phi_deg")
        t = _index(self.theta_i_deg, theta_i_deg, "theta_i_deg")
        f = reduce_quantity(self.rgb[p, t], quantity)
        if self.cosine:
            c = np.cos(np.radians(self.theta_o_deg))
            f = f * (c[:, None] if f.ndim == 2 else c)
        return f

    def curves(self, phi_deg, quantity="luminance") -> list:
        """The curves of one plane, one per incidence in :attr:`theta_i_deg` order."""
        return [self.curve(phi_deg, ti, quantity) for ti in self.theta_i_deg]

    def peak(self, quantity="luminance") -> float:
        """The largest finite value of every curve of the view (1/sr; 0 when none): the
        shared radial limit and log floor of all panels of a figure."""
        return max(finite_max(self.curve(phi, ti, quantity))
                   for phi in self.planes_deg for ti in self.theta_i_deg)

    def select(self, theta_i_deg=None, planes_deg=None) -> "LobeView":
        """The view of some of its incidences and planes (the same arrays, nothing
        evaluated again)."""
        ts = self.theta_i_deg if theta_i_deg is None else tuple(
            float(v) for v in np.atleast_1d(theta_i_deg))
        ps = self.planes_deg if planes_deg is None else tuple(
            float(v) for v in np.atleast_1d(planes_deg))
        ti = [_index(self.theta_i_deg, v, "theta_i_deg") for v in ts]
        pi = [_index(self.planes_deg, v, "phi_deg") for v in ps]
        return LobeView(self.theta_o_deg, ts, ps, self.rgb[np.ix_(pi, ti)], self.cosine)

    def columns(self) -> tuple[list, np.ndarray]:
        """The view as a table: header ``theta_o_deg`` then ``f_<c>_phi<deg>_ti<deg>`` for
        c in r, g, b and Y (luminance) per plane and incidence; rows = theta_o samples."""
        cols, header = [self.theta_o_deg], ["theta_o_deg"]
        for phi in self.planes_deg:
            for ti in self.theta_i_deg:
                f = self.curve(phi, ti, "rgb")
                for k, c in enumerate("rgb"):
                    cols.append(f[:, k])
                    header.append(f"f_{c}_phi{phi:g}_ti{ti:g}")
                cols.append(self.curve(phi, ti, "luminance"))
                header.append(f"f_Y_phi{phi:g}_ti{ti:g}")
        return header, np.stack(cols, axis=1)


def compute_lobes(brdf, theta_i_deg=(0.0, 30.0, 60.0), planes_deg=(0.0,), *, resolution=181,
                  cosine=False) -> LobeView:
    """Evaluate ``brdf`` once on every curve of a lobe view.

    Parameters
    ----------
    brdf : object
        Anything with ``.eval(wi, wo) -> (..., 3)`` f_r in 1/sr.
    theta_i_deg : float or sequence of float
        Incidences in degrees, each in [0, 90).
    planes_deg : float or sequence of float
        Azimuths of the planes of incidence in degrees, each in [-360, 360].
    resolution : int
        Samples of theta_o over [-90, 90] degrees (at least 3).
    cosine : bool
        The curves are f_r cos(theta_o) instead of f_r.

    Returns
    -------
    LobeView

    Examples
    --------
    >>> class Lambert:
    ...     def eval(self, wi, wo):
    ...         return np.full(wi.shape, 0.1)
    >>> v = compute_lobes(Lambert(), (0.0, 30.0), (0.0, 90.0), resolution=5)
    >>> v.rgb.shape, v.peak("g")
    ((2, 2, 5, 3), 0.1)
    """
    thetas = tuple(float(v) for v in np.atleast_1d(
        check_angle("theta_i_deg", theta_i_deg, 0.0, 89.999)))
    planes = tuple(float(v) for v in np.atleast_1d(
        check_angle("planes_deg", planes_deg, -360.0, 360.0)))
    n = check_resolution(resolution, 3)
    theta_o = np.linspace(-90.0, 90.0, n)
    wi = np.empty((len(planes), len(thetas), 1, 3))
    wo = np.empty((len(planes), 1, n, 3))
    for p, phi in enumerate(planes):
        for t, ti in enumerate(thetas):
            wi[p, t, 0], wo[p, 0] = plane_directions(ti, theta_o, phi)
    return LobeView(theta_o, thetas, planes, eval_brdf(brdf, wi, wo), bool(cosine))


@dataclass(frozen=True, eq=False)
class MaskingLobesView:
    """The same lobes with shadowing and masking on and off (each a :class:`LobeView`)."""

    on: LobeView
    off: LobeView

    def curves(self, phi_deg, theta_i_deg) -> dict:
        """Luminance f_r (1/sr) of one panel: {"masking on": ..., "masking off": ...}."""
        return {"masking on": self.on.curve(phi_deg, theta_i_deg),
                "masking off": self.off.curve(phi_deg, theta_i_deg)}


def compute_masking_lobes(brdf, theta_i_deg=(60.0,), planes_deg=(0.0,), *,
                          resolution=181) -> MaskingLobesView:
    """Lobes of ``brdf.replace(masking=True)`` and ``brdf.replace(masking=False)``.

    Raises
    ------
    ValueError
        If the BRDF has no ``replace`` (accepting ``masking``), before any evaluation.
    """
    replace = getattr(brdf, "replace", None)
    if replace is None:
        raise ValueError(f"brdf must have .replace(masking=...) for masking views; "
                         f"got {type(brdf).__name__}")
    on, off = replace(masking=True), replace(masking=False)
    return MaskingLobesView(compute_lobes(on, theta_i_deg, planes_deg, resolution=resolution),
                            compute_lobes(off, theta_i_deg, planes_deg, resolution=resolution))
