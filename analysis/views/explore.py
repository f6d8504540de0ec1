"""The numbers of the BRDF Explorer's views that no other view has: a lit sphere and the
directional albedo against the incidence.

The sphere is seen from straight above (orthographic, the viewer along +z); each pixel's
surface frame has the normal n of the sphere, the warp t along +x projected onto the
tangent plane and b = n x t. The directional albedo is the equal-area quadrature of
f_r cos theta_o over the hemisphere (the pixels of :func:`equal_area_grid`: each covers the
same solid angle, 2 pi / N).

Examples
--------
>>> class Lambert:
...     def eval(self, wi, wo):
...         return np.full(np.broadcast_shapes(wi.shape, wo.shape), 0.1)
>>> a = compute_albedo_curve(Lambert(), (0.0, 60.0), resolution=40)
>>> np.round(a.albedo[:, 1], 2).tolist()                   # 0.1 pi
[0.31, 0.31]
>>> s = compute_sphere(Lambert(), 0.0, 0.0, resolution=9)
>>> s.radiance.shape, float(s.radiance[4, 4, 0]).__round__(3)   # f_r cos 0 at the pole
((9, 9, 3), 0.1)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.views.common import check_angle, check_resolution, eval_brdf
from analysis.views.hemisphere import equal_area_grid
from brdf.frames import from_angles

__all__ = ["SphereView", "compute_sphere", "AlbedoCurveView", "compute_albedo_curve",
           "sphere_frames"]


@dataclass(frozen=True, eq=False)
class SphereView:
    """A sphere under a point light of unit irradiance at normal incidence.

    Attributes
    ----------
    light_theta_deg, light_phi_deg : float
        The light's direction, degrees (polar from +z, azimuth from +x).
    inside : numpy.ndarray of bool, shape (n, n)
        Pixels on the sphere (row index = y, upward).
    radiance : numpy.ndarray, shape (n, n, 3)
        f_r cos theta_i (1/sr) toward the viewer; 0 off the sphere and in shadow.
    """

    light_theta_deg: float
    light_phi_deg: float
    inside: np.ndarray
    radiance: np.ndarray


def sphere_frames(resolution: int):
    """Pixels of the sphere image and their frames: (inside, n, t, b), each (n, n[, 3])."""
    n = check_resolution(resolution, 3)
    c = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    y, x = np.meshgrid(c, c, indexing="ij")
    inside = x * x + y * y < 1.0
    z = np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, 1.0))
    nrm = np.stack([x, y, z], axis=-1)
    t = np.stack([z, np.zeros_like(z), -x], axis=-1)
    t /= np.maximum(np.linalg.norm(t, axis=-1, keepdims=True), 1e-12)
    b = np.cross(nrm, t)
    return inside, nrm, t, b


def compute_sphere(brdf, light_theta_deg=45.0, light_phi_deg=180.0, *,
                   resolution=64) -> SphereView:
    """Evaluate ``brdf`` once on the sphere's pixels lit from (theta, phi) degrees."""
    th = float(check_angle("light_theta_deg", light_theta_deg, 0.0, 90.0))
    ph = float(check_angle("light_phi_deg", light_phi_deg, -360.0, 360.0))
    inside, nrm, t, b = sphere_frames(resolution)
    light = from_angles(np.radians(th), np.radians(ph))
    view = np.array([0.0, 0.0, 1.0])
    local = lambda w: np.stack([(w * t).sum(-1), (w * b).sum(-1),   # noqa: E731
                                (w * nrm).sum(-1)], axis=-1)
    wi, wo = local(np.broadcast_to(light, nrm.shape)), local(np.broadcast_to(view, nrm.shape))
    lit = inside & (wi[..., 2] > 1e-6) & (wo[..., 2] > 1e-6)
    out = np.zeros(inside.shape + (3,))
    if lit.any():
        f = eval_brdf(brdf, wi[lit], wo[lit])
        out[lit] = np.nan_to_num(f, nan=0.0, posinf=0.0) * wi[lit][:, 2:3]
    return SphereView(th, ph, inside, out)


@dataclass(frozen=True, eq=False)
class AlbedoCurveView:
    """Directional albedo (reflectance) against the incidence.

    Attributes
    ----------
    theta_i_deg : numpy.ndarray, shape (m,)
    phi_i_deg : float
        The light's azimuth, degrees.
    albedo : numpy.ndarray, shape (m, 3)
        Integral of f_r cos theta_o over the hemisphere (dimensionless), per channel.
    """

    theta_i_deg: np.ndarray
    phi_i_deg: float
    albedo: np.ndarray


def compute_albedo_curve(brdf, theta_i_deg=tuple(range(0, 90, 10)), phi_i_deg=180.0, *,
                         resolution=32) -> AlbedoCurveView:
    """The directional albedo of ``brdf`` at each incidence (degrees), on an equal-area grid
    of ``resolution`` pixels a side (one evaluation of every pair)."""
    ti = np.atleast_1d(check_angle("theta_i_deg", theta_i_deg, 0.0, 89.999)).astype(float)
    ph = float(check_angle("phi_i_deg", phi_i_deg, -360.0, 360.0))
    _, _, inside, wo = equal_area_grid(check_resolution(resolution, 3))
    wo = wo[inside]
    wi = from_angles(np.radians(ti), np.radians(ph))[:, None, :]
    f = eval_brdf(brdf, wi, wo[None])
    f = np.nan_to_num(f, nan=0.0, posinf=0.0)
    albedo = (f * wo[None, :, 2:3]).sum(axis=1) * (2.0 * np.pi / wo.shape[0])
    return AlbedoCurveView(ti, ph, albedo)
