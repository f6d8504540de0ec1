"""Directions as (..., 3) unit vectors, and their polar angles.

Frame: n = +z; the warp (thread 1) along +x; theta is the polar angle from n, phi the
azimuth from +x toward +y. All angles in radians.
"""

from __future__ import annotations

import numpy as np

__all__ = ["from_angles", "to_angles", "as_directions", "normalize"]


def from_angles(theta, phi) -> np.ndarray:
    """Unit vectors from polar angle and azimuth.

    Parameters
    ----------
    theta : array_like
        Polar angle from the normal n = +z, radians.
    phi : array_like
        Azimuth from +x (the warp) toward +y, radians. Broadcasts with ``theta``.

    Returns
    -------
    ndarray, shape (..., 3)
        ``(sin theta cos phi, sin theta sin phi, cos theta)``.

    Examples
    --------
    >>> from_angles(np.pi / 2, 0.0).round(12)
    array([1., 0., 0.])
    """
    theta = np.asarray(theta, dtype=np.float64)
    phi = np.asarray(phi, dtype=np.float64)
    st = np.sin(theta)
    return np.stack(np.broadcast_arrays(st * np.cos(phi), st * np.sin(phi), np.cos(theta)), axis=-1)


def to_angles(w) -> tuple[np.ndarray, np.ndarray]:
    """Polar angle and azimuth of (not necessarily unit) directions.

    Parameters
    ----------
    w : array_like, shape (..., 3)
        Directions.

    Returns
    -------
    theta, phi : ndarray, shape (...)
        Polar angle in [0, pi] and azimuth in (-pi, pi], radians.

    Examples
    --------
    >>> theta, phi = to_angles([0.0, 1.0, 1.0])
    >>> float(np.degrees(theta)), float(np.degrees(phi))
    (45.0, 90.0)
    """
    w = as_directions("w", w)
    r = np.linalg.norm(w, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        theta = np.arccos(np.clip(w[..., 2] / r, -1.0, 1.0))
    return theta, np.arctan2(w[..., 1], w[..., 0])


def as_directions(name: str, w) -> np.ndarray:
    """Check that ``w`` is a float array with a last axis of length 3.

    Raises
    ------
    ValueError
        If ``w`` is not numeric or its last axis is not 3; the message names ``name``.
    """
    try:
        arr = np.asarray(w, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be a numeric array of shape (..., 3); got {w!r}") from exc
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3) with components on the last axis; "
                         f"got shape {arr.shape}")
    return arr


def normalize(w) -> tuple[np.ndarray, np.ndarray]:
    """Normalize directions; flag zero and non-finite vectors.

    Parameters
    ----------
    w : ndarray, shape (..., 3)

    Returns
    -------
    unit : ndarray, shape (..., 3)
        ``w / |w|``; entries flagged bad are set to (0, 0, 1) so later arithmetic stays finite.
    bad : ndarray of bool, shape (...)
        True where ``w`` is zero or has a non-finite component.

    Examples
    --------
    >>> u, bad = normalize(np.array([[0.0, 0.0, 2.0], [0.0, 0.0, 0.0]]))
    >>> u[0], bad
    (array([0., 0., 1.]), array([False,  True]))
    """
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        # Scale by the largest component first so that huge finite vectors do not overflow.
        big = np.max(np.abs(w), axis=-1)
        bad = ~np.isfinite(big) | (big == 0.0)
        if bad.any():
            w = np.where(bad[..., None], np.array([0.0, 0.0, 1.0]), w)
            big = np.where(bad, 1.0, big)
        w = w / big[..., None]
        norm = np.sqrt(np.einsum("...i,...i->...", w, w))
    return w / norm[..., None], bad
