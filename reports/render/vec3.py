"""Small 3-vector helpers of the renderer's scenes: unit vectors, dot products, camera bases."""

from __future__ import annotations

import numpy as np

__all__ = ["INF", "unit", "dot", "basis"]

#: The distance to a light at infinity.
INF = np.inf


def unit(v):
    """``v`` (..., 3) scaled to unit length."""
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def dot(a, b):
    """Dot products of (..., 3) vectors over the last axis."""
    return np.einsum("...i,...i->...", a, b)


def basis(position, target, up):
    """Forward, right and up unit vectors of a view from ``position`` toward ``target``."""
    f = unit(np.asarray(target, float) - np.asarray(position, float))
    r = np.cross(f, np.asarray(up, float))
    if np.linalg.norm(r) < 1e-9:
        r = np.cross(f, np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.9 else np.array([1.0, 0, 0]))
    r = unit(r)
    return f, r, np.cross(r, f)
