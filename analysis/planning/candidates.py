"""The pairs a plan may choose from, and the uniform designs it is compared with.

The candidates are a geometry (by default :data:`DEFAULT_CANDIDATES`, a full hemispherical
grid of 10 degrees in theta and 20 in phi on both sides: 21,025 pairs) less the pairs the
instrument cannot reach (:meth:`gonio.Instrument.reachable`: its largest theta, its smallest
angle between source and detector, in-plane only). A uniform design draws both directions
uniformly in solid angle (a scrambled Sobol sequence in cos theta and phi, seeded), keeps
the pairs the instrument reaches within the candidates' largest theta, and takes the first N:
the habit a plan is measured against.
"""

from __future__ import annotations

import math

import numpy as np

from analysis.lazy import qmc
from brdf.frames import from_angles
from gonio.geometry import Geometry
from gonio.geomspec import from_spec, spec_pairs

__all__ = ["DEFAULT_CANDIDATES", "MAX_CANDIDATES", "Candidates", "candidates",
           "uniform_pairs", "reachable"]

#: The default candidate geometry (a geometry spec, degrees).
DEFAULT_CANDIDATES = "full:10:20"
#: Most pairs a candidate geometry may hold (each costs K x r x d numbers of information).
MAX_CANDIDATES = 200_000


def reachable(instrument, wi, wo) -> np.ndarray:
    """Which pairs (..., 3) ``instrument`` reaches (:meth:`gonio.Instrument.reachable`) above
    the horizon; every pair above it when ``instrument`` is None."""
    wi, wo = np.asarray(wi, dtype=np.float64), np.asarray(wo, dtype=np.float64)
    above = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    if instrument is None or wi.shape[0] == 0:
        return above
    return above & np.asarray(instrument.reachable(wi, wo), bool)


class Candidates:
    """The candidate pairs: ``wi``, ``wo`` (M, 3) unit directions, ``spec`` (the geometry
    spec they came from) and ``dropped`` (the geometry's pairs the instrument cannot
    reach)."""

    def __init__(self, wi, wo, spec: str, dropped: int = 0):
        self.wi = np.asarray(wi, dtype=np.float64)
        self.wo = np.asarray(wo, dtype=np.float64)
        self.spec, self.dropped = spec, int(dropped)

    def __len__(self) -> int:
        return self.wi.shape[0]

    @property
    def max_theta(self) -> float:
        """The largest polar angle of either direction, radians."""
        return float(np.arccos(np.clip(min(self.wi[:, 2].min(), self.wo[:, 2].min()),
                                       -1, 1)))


def candidates(geometry=None, instrument=None) -> Candidates:
    """The candidate pairs of ``geometry`` (a :class:`gonio.Geometry` or a spec string,
    default :data:`DEFAULT_CANDIDATES`) that ``instrument`` reaches.

    Raises
    ------
    ValueError
        A bad spec, more than :data:`MAX_CANDIDATES` pairs, or no reachable pair (naming
        the spec).

    Examples
    --------
    >>> len(candidates("full:45:90"))   # (1 + 1 * 4) ** 2
    25
    """
    geometry = DEFAULT_CANDIDATES if geometry is None else geometry
    n = None if isinstance(geometry, Geometry) else spec_pairs(geometry)
    if n is not None and n > MAX_CANDIDATES:
        raise ValueError(f"candidates {geometry!r}: {n:.3g} pairs, at most "
                         f"{MAX_CANDIDATES:,}: use a coarser step")
    geo = geometry if isinstance(geometry, Geometry) else from_spec(geometry)
    spec = geo.spec if isinstance(geometry, Geometry) else str(geometry)
    ok = reachable(instrument, geo.wi, geo.wo)
    if not np.any(ok):
        raise ValueError(f"candidates {spec!r}: the instrument reaches none of its "
                         f"{len(geo)} pairs; widen the instrument's limits or give other "
                         f"candidates")
    return Candidates(geo.wi[ok], geo.wo[ok], spec, int((~ok).sum()))


def uniform_pairs(n: int, instrument=None, *, max_theta: float = math.radians(80.0),
                  seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``n`` pairs uniform in solid angle on both sides, within ``max_theta`` (radians) and
    reachable by ``instrument`` (module notes). Same seed, same pairs.

    Returns
    -------
    wi, wo : ndarray (n, 3)

    Raises
    ------
    ValueError
        When the instrument reaches too small a part of the hemisphere to draw them.

    Examples
    --------
    >>> wi, wo = uniform_pairs(5, seed=1)
    >>> wi.shape, bool(np.all(wi[:, 2] >= np.cos(np.radians(80)) - 1e-12))
    ((5, 3), True)
    """
    sobol = qmc.Sobol(d=4, scramble=True, seed=seed)
    cos_max = math.cos(max_theta)
    wi_all, wo_all, have = [], [], 0
    size = 2 ** max(6, math.ceil(math.log2(4 * n)))
    for _ in range(8):
        u = sobol.random(size if sobol.num_generated == 0 else sobol.num_generated)
        cos_i = 1.0 - u[:, 0] * (1.0 - cos_max)
        cos_o = 1.0 - u[:, 2] * (1.0 - cos_max)
        wi = from_angles(np.arccos(cos_i), 2 * np.pi * u[:, 1])
        wo = from_angles(np.arccos(cos_o), 2 * np.pi * u[:, 3])
        ok = reachable(instrument, wi, wo)
        wi_all.append(wi[ok])
        wo_all.append(wo[ok])
        have += int(ok.sum())
        if have >= n:
            break
    if have < n:
        raise ValueError(f"the instrument reaches too little of the hemisphere to draw {n} "
                         f"uniform pairs (found {have})")
    return np.concatenate(wi_all)[:n], np.concatenate(wo_all)[:n]
