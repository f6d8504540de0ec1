r"""A tabulated importance sampler of :math:`f_r \cos\theta_i`, built once per render.

The sky's light on cloth (:mod:`reports.render.envlight`) is the integral
:math:`\int f_r(\omega_i, \omega_o) \cos\theta_i L(\omega_i) V\, d\omega_i` over a broad,
smooth sky. A fabric's own sampler (:meth:`brdf.Fabric.sample`) draws its lobes in each
thread's frame; for a fabric whose reflection gathers at grazing incidence (velvet:
:math:`f_r` near 20 / sr at :math:`\cos\theta_i = 0.003`) its density there was some 30
times too low, with two thirds of the draws below the surface, until its lobes were
truncated to the upper hemisphere (issue 36: it now exceeds :math:`f_r\cos\theta_i / \rho`
there; the table was not compared with it again): a few samples carried most of the light and
showed as white speckles. :class:`BRDFTable` tabulates the integrand itself instead:

- the viewer directions in :data:`WO_BINS` equal bins of (:math:`\cos\theta_o`,
  :math:`\phi_o`), the light directions in :data:`WI_BINS` bins of
  (:math:`\cos\theta_i`, :math:`\phi_i`), all of equal solid angle
  :math:`\Delta\omega = 2\pi / (n_c n_\phi)`;
- a row per viewer bin: :math:`T_b = \overline{f_r} \cos\theta_i` (the mean of the RGB
  channels) at each light bin's centre, plus :data:`FLOOR` times the row's mean, so that every
  bin can be drawn (a lobe narrower than a bin is then found by the other strategy of the
  sky's MIS, the cosine one);
- :meth:`BRDFTable.sample` picks the viewer's row (the bin that holds ``wo``), a bin with
  probability :math:`T_b / \sum T`, and a direction uniform in the bin's solid angle:
  density :math:`p(\omega_i) = T_b / (\Delta\omega \sum T)`, which :meth:`BRDFTable.pdf`
  gives exactly (zero below the surface).

The row of a viewer is that of its bin, so :meth:`pdf` is the exact density of what
:meth:`sample` draws, and the estimate stays unbiased whatever the table's resolution; the
resolution only sets how close the density comes to the integrand (the variance).
"""

from __future__ import annotations

import numpy as np

__all__ = ["BRDFTable", "WO_BINS", "WI_BINS", "FLOOR"]

#: Viewer bins (cos theta_o, phi_o).
WO_BINS = (8, 16)
#: Light bins (cos theta_i, phi_i).
WI_BINS = (16, 32)
#: Share of a row's mean added to each of its bins (every direction of the hemisphere drawable).
FLOOR = 0.05


def _bin_of(w, shape) -> np.ndarray:
    """Flat bin index of unit directions ``w`` (m, 3) in a (cos theta, phi) grid ``shape``;
    directions below the surface land in the lowest cos theta bin."""
    nc, nphi = shape
    c = np.clip((np.clip(w[:, 2], 0.0, 1.0) * nc).astype(np.int64), 0, nc - 1)
    phi = np.arctan2(w[:, 1], w[:, 0]) % (2.0 * np.pi)
    k = np.clip((phi * (nphi / (2.0 * np.pi))).astype(np.int64), 0, nphi - 1)
    return c * nphi + k


def _centres(shape) -> np.ndarray:
    """Unit directions (nc * nphi, 3) at the centres of a (cos theta, phi) grid's bins."""
    nc, nphi = shape
    cos = (np.arange(nc) + 0.5) / nc
    phi = (np.arange(nphi) + 0.5) * (2.0 * np.pi / nphi)
    c, p = np.meshgrid(cos, phi, indexing="ij")
    s = np.sqrt(1.0 - c * c)
    return np.stack([s * np.cos(p), s * np.sin(p), c], axis=-1).reshape(-1, 3)


class BRDFTable:
    """The tabulated sampler of ``fabric``'s :math:`f_r \\cos\\theta_i` (module notes).

    Parameters
    ----------
    fabric : BRDF
        Anything with ``eval(wi, wo)`` (local frame, RGB f_r in 1/sr).
    wo_bins, wi_bins : (int, int)
        The grids of viewer and light directions, (cos theta bins, phi bins).
    batch : int
        Pairs per ``fabric.eval`` call.

    Examples
    --------
    >>> import brdf
    >>> t = BRDFTable(brdf.fabric("velvet"), wo_bins=(2, 4), wi_bins=(4, 8))
    >>> wo = np.array([[0.3, 0.1, 0.95]])
    >>> wi, p = t.sample(np.repeat(wo, 3, 0), np.random.default_rng(0).random((3, 2)))
    >>> bool(np.allclose(p, t.pdf(np.repeat(wo, 3, 0), wi)))
    True
    """

    def __init__(self, fabric, wo_bins=WO_BINS, wi_bins=WI_BINS, batch=131072):
        self.wo_bins, self.wi_bins = tuple(wo_bins), tuple(wi_bins)
        wo, wi = _centres(self.wo_bins), _centres(self.wi_bins)
        nwo, nwi = len(wo), len(wi)
        pairs_wo = np.repeat(wo, nwi, axis=0)
        pairs_wi = np.tile(wi, (nwo, 1))
        f = np.empty(nwo * nwi)
        for s in range(0, f.size, batch):
            rgb = np.asarray(fabric.eval(pairs_wi[s:s + batch], pairs_wo[s:s + batch]))
            f[s:s + batch] = np.nan_to_num(rgb, nan=0.0, posinf=0.0, neginf=0.0).mean(-1)
        t = np.maximum(f, 0.0).reshape(nwo, nwi) * wi[:, 2]
        t += FLOOR * t.mean(axis=1, keepdims=True) + 1e-300   # every bin drawable
        prob = t / t.sum(axis=1, keepdims=True)
        #: Density of each (viewer bin, light bin), 1/sr.
        self.density = prob * (nwi / (2.0 * np.pi))
        cdf = np.cumsum(prob, axis=1)
        cdf[:, -1] = 1.0
        self._cdf = cdf
        # rows offset by their index: one increasing array for all rows' inverse CDFs
        self._flat = (cdf + np.arange(nwo)[:, None]).ravel()

    def pdf(self, wo, wi) -> np.ndarray:
        """Density (m,) in 1/sr of :meth:`sample`'s directions ``wi`` (m, 3) for the viewers
        ``wo`` (m, 3), local frame; 0 at or below the surface."""
        d = self.density[_bin_of(wo, self.wo_bins), _bin_of(wi, self.wi_bins)]
        return np.where(wi[:, 2] > 0, d, 0.0)

    def sample(self, wo, u) -> tuple[np.ndarray, np.ndarray]:
        """Directions ``wi`` (m, 3) toward the light for the viewers ``wo`` (m, 3) from
        uniform numbers ``u`` (m, 2) in [0, 1), and their density (m,) in 1/sr.

        ``u[:, 0]`` picks the bin and, rescaled within it, ``cos theta``; ``u[:, 1]`` the
        azimuth within the bin.
        """
        row = _bin_of(wo, self.wo_bins)
        nwi = self._cdf.shape[1]
        j = np.searchsorted(self._flat, row + u[:, 0], side="right") - row * nwi
        j = np.clip(j, 0, nwi - 1)
        hi = self._cdf[row, j]
        lo = np.where(j > 0, self._cdf[row, np.maximum(j - 1, 0)], 0.0)
        v = np.clip((u[:, 0] - lo) / np.maximum(hi - lo, 1e-300), 0.0, 1.0 - 1e-12)
        nc, nphi = self.wi_bins
        cos = (j // nphi + v) / nc
        phi = (j % nphi + u[:, 1]) * (2.0 * np.pi / nphi)
        s = np.sqrt(np.maximum(1.0 - cos * cos, 0.0))
        wi = np.stack([s * np.cos(phi), s * np.sin(phi), cos], axis=-1)
        return wi, self.density[row, j]
