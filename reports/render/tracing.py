"""Ray queries of the renderer: the nearest hit, and whether a segment is blocked."""

from __future__ import annotations

import numpy as np

__all__ = ["intersect", "occluded"]


def intersect(prims, o, d, tmin):
    """Nearest hit of rays ``(o, d)`` (m, 3): t (inf on a miss), primitive index and part."""
    n = len(o)
    best = np.full(n, np.inf)
    pid = np.full(n, -1, np.int16)
    part = np.zeros(n, np.int8)
    for k, prim in enumerate(prims):
        t, pt = prim.intersect(o, d, tmin)
        closer = t < best
        best = np.where(closer, t, best)
        pid[closer] = k
        part[closer] = pt[closer]
    return best, pid, part


def occluded(prims, o, d, tmax, tmin):
    """True where a primitive lies between ``o`` and ``o + tmax d`` (tmax may be inf)."""
    hit = np.zeros(len(o), bool)
    for prim in prims:
        rest = np.nonzero(~hit)[0]
        if rest.size == 0:
            break
        t, _ = prim.intersect(o[rest], d[rest], tmin)
        hit[rest] = t < np.asarray(tmax)[rest] if np.ndim(tmax) else t < tmax
    return hit
