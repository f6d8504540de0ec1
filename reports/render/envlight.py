r"""Light from the sky: an environment light and its estimator, for the built-in renderer.

:class:`EnvironmentLight` gives radiance from every direction (a blend from the horizon to the
zenith, world +y up). Its direct light at a surface point is estimated with one shadow ray per
strategy:

- diffuse surfaces: a cosine-weighted direction, ``L_o = albedo L(wi) V``;
- cloth: multiple importance sampling (balance heuristic) of two directions, one drawn from
  the render's table of the fabric's :math:`f_r \cos\theta_i`
  (:class:`reports.render.brdftable.BRDFTable`, density ``p_t``) and one cosine-weighted
  (``p_c = cos / pi``):

  .. math::
      L_o = \frac{f_r(w_t) \cos\theta_t L(w_t) V_t}{p_t(w_t) + p_c(w_t)}
          + \frac{f_r(w_c) \cos\theta_c L(w_c) V_c}{p_t(w_c) + p_c(w_c)},

  an unbiased estimate of :math:`\int f_r L \cos\theta V\, d\omega` whose variance stays low
  both where the fabric's reflection gathers (the table follows it, velvet's grazing rim
  included) and for the diffuse part and lobes narrower than a table bin (the cosine
  directions). The table needs ``eval`` alone; without one (``table=None``) the cosine
  directions are used alone.

The fabric's own sampler (:meth:`brdf.Fabric.sample`) is not used here: for velvet it put
(before issue 36 truncated its lobes to the upper hemisphere; not compared since) two thirds
of its draws below the surface and some 30 times too few at grazing incidence,
where velvet's f_r cos gathers, so that a few sky samples carried most of the light and
showed as white speckles on the cylinder's shaded side; the table's estimate has 8 to 60
times less variance there and on every preset, and costs two ``eval`` calls instead of an
``eval``, a ``pdf`` and a ``sample`` (tests/test_reports_envlight.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reports.render.tracing import occluded

__all__ = ["EnvironmentLight", "environment_radiance"]


@dataclass(frozen=True)
class EnvironmentLight:
    """Sky radiance (W / (m^2 sr), RGB): ``horizon`` at and below the horizon, blending
    linearly in the height ``w_y`` of the direction to ``zenith`` straight up."""

    zenith: tuple = (0.05, 0.06, 0.08)
    horizon: tuple = (0.06, 0.06, 0.06)

    def radiance(self, w) -> np.ndarray:
        """Radiance (m, 3) arriving from the unit directions ``w`` (m, 3), world frame."""
        t = np.clip(np.asarray(w)[:, 1], 0.0, 1.0)[:, None]
        return (1.0 - t) * np.asarray(self.horizon, float) + t * np.asarray(self.zenith, float)


def _cosine_local(u) -> np.ndarray:
    """Cosine-weighted directions about +z from uniform ``u`` (m, 2)."""
    r = np.sqrt(u[:, 0])
    phi = 2.0 * np.pi * u[:, 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - u[:, 0])], axis=-1)


def _visible_sky(env, prims, p, n, wi, off, eps):
    """Sky radiance along ``wi`` where the ray from ``p`` (lifted along ``n``) escapes."""
    free = ~occluded(prims, p + off * n, wi, np.inf, eps)
    return env.radiance(wi) * free[:, None]


def _eval(fabric, wi, wo, batch):
    out = np.empty((len(wi), 3))
    for s in range(0, len(wi), batch):
        out[s:s + batch] = fabric.eval(wi[s:s + batch], wo[s:s + batch])
    return out


def environment_radiance(env, prims, fabric, p, n, frame, wo_l, cloth, albedo, rng, *,
                         off, eps, batch=131072, u=None, table=None) -> np.ndarray:
    """Radiance (m, 3) reflected toward the viewer from the sky at points ``p``.

    Parameters
    ----------
    env : EnvironmentLight
    prims : sequence of primitives (for the shadow rays)
    fabric : BRDF
        The cloth's BRDF (local frame).
    p, n : ndarray (m, 3)
        Points and their normals (toward the viewer).
    frame : ndarray (m, 3, 3)
        Rows: warp, n x warp, n (world -> local).
    wo_l : ndarray (m, 3)
        Direction to the viewer, local frame.
    cloth : ndarray (m,) bool
        Cloth points (the others are Lambertian with ``albedo`` (m,)).
    rng : numpy.random.Generator
    off, eps : float
        Lift of shadow-ray origins and the smallest hit distance, scene units.
    u : ndarray (m, 4), optional
        Uniform numbers in [0, 1) of the two draws (the cosine direction: ``u[:, :2]``; the
        table's: ``u[:, 2:]``), e.g. stratified over a pixel's samples; default from ``rng``.
    table : BRDFTable, optional
        ``fabric``'s table (:class:`reports.render.brdftable.BRDFTable`): MIS of its
        directions and cosine ones on cloth; None: cosine directions alone.
    """
    out = np.zeros((len(p), 3))
    to_world = np.swapaxes(frame, 1, 2)
    if u is None:
        u = rng.random((len(p), 4))
    w_c = _cosine_local(u[:, :2])
    wc_world = np.einsum("mij,mj->mi", to_world, w_c)
    sky_c = _visible_sky(env, prims, p, n, wc_world, off, eps)
    d = ~cloth
    out[d] = albedo[d, None] * sky_c[d]                    # (albedo / pi) L cos / (cos / pi)
    c = np.nonzero(cloth)[0]
    if c.size == 0:
        return out
    f_c = _eval(fabric, w_c[c], wo_l[c], batch)
    cos_c = w_c[c, 2]
    if table is None:                                  # cosine directions alone
        out[c] = f_c * np.pi * sky_c[c]
        return out
    pt_c = table.pdf(wo_l[c], w_c[c])
    out[c] = f_c * (cos_c / (pt_c + cos_c / np.pi))[:, None] * sky_c[c]
    w_t, pt_t = table.sample(wo_l[c], np.ascontiguousarray(u[c, 2:]))
    up = w_t[:, 2] > 0
    k = c[up]
    w_t, pt_t = w_t[up], pt_t[up]
    f_t = _eval(fabric, w_t, wo_l[k], batch)
    wt_world = np.einsum("mij,mj->mi", to_world[k], w_t)
    sky_t = _visible_sky(env, prims, p[k], n[k], wt_world, off, eps)
    out[k] += f_t * (w_t[:, 2] / (pt_t + w_t[:, 2] / np.pi))[:, None] * sky_t
    return out
