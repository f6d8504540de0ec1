"""Frames and angles: the one home of directions, polar angles, rotations, Rusinkiewicz
half/difference angles and in-plane angles.

Frame: n = +z; the warp (thread 1) along +x, the weft along +y; theta is the polar angle from
n, phi the azimuth from +x toward +y. Directions are (..., 3) arrays, components last; every
function broadcasts over leading dimensions. All angles in radians.
"""

from __future__ import annotations

import numpy as np

__all__ = ["from_angles", "to_angles", "as_directions", "normalize", "flat_pairs", "rotate_z", "rotate_y",
           "half_diff_to_directions", "directions_to_half_diff", "plane_to_directions",
           "directions_to_plane"]



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
        Polar angle in [0, pi] and azimuth in (-pi, pi], radians; NaN for a zero or
        non-finite direction.

    Notes
    -----
    theta = atan2(sqrt(x^2 + y^2), z), phi = atan2(y, x): accurate to the last digits at
    every angle, where arccos(z / |w|) loses half of them near the poles (a direction at
    1e-8 rad from the normal would come back at 0).

    Examples
    --------
    >>> float(to_angles([1e-8, 0.0, 1.0])[0])
    1e-08
    >>> theta, phi = to_angles([0.0, 1.0, 1.0])
    >>> float(np.degrees(theta)), float(np.degrees(phi))
    (45.0, 90.0)
    """
    w = as_directions("w", w)
    with np.errstate(over="ignore", under="ignore"):
        r = np.linalg.norm(w, axis=-1)
    if not np.all((r > 2.0 ** -500) & (r < 2.0 ** 500)):   # huge, tiny, zero or not finite
        w, bad = normalize(w)          # scaled first: huge or tiny vectors keep their angles
        r = np.where(bad, np.nan, 1.0)
    with np.errstate(invalid="ignore"):
        theta = np.arctan2(np.hypot(w[..., 0], w[..., 1]), w[..., 2])
    bad = np.isnan(r)
    return (np.where(bad, np.nan, theta),
            np.where(bad, np.nan, np.arctan2(w[..., 1], w[..., 0])))


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
    w : array_like, shape (..., 3)

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
    w = as_directions("w", w)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        # Scale by the largest component first so that huge finite vectors do not overflow.
        a = np.abs(w)       # the largest |component| (np.max over an axis of 3 is slow)
        big = np.maximum(np.maximum(a[..., 0], a[..., 1]), a[..., 2])
        bad = ~np.isfinite(big) | (big == 0.0)
        if bad.any():
            w = np.where(bad[..., None], np.array([0.0, 0.0, 1.0]), w)
            big = np.where(bad, 1.0, big)
        w = w / big[..., None]
        norm = np.sqrt(np.einsum("...i,...i->...", w, w))
    return w / norm[..., None], bad


def rotate_z(w, angle) -> np.ndarray:
    """Rotate (..., 3) vectors by ``angle`` (radians, broadcast) about +z, counter-clockwise.

    Examples
    --------
    >>> rotate_z([1.0, 0.0, 0.0], np.pi / 2).round(12)
    array([0., 1., 0.])
    """
    w = np.asarray(w, float)
    c, s = np.cos(angle), np.sin(angle)
    x, y = w[..., 0], w[..., 1]
    return np.stack(np.broadcast_arrays(c * x - s * y, s * x + c * y, w[..., 2]), axis=-1)


def rotate_y(w, angle) -> np.ndarray:
    """Rotate (..., 3) vectors by ``angle`` (radians) about +y (right hand: z toward x)."""
    c, s = np.cos(angle), np.sin(angle)
    x, z = w[..., 0], w[..., 2]
    return np.stack(np.broadcast_arrays(c * x + s * z, w[..., 1], -s * x + c * z), axis=-1)


def half_diff_to_directions(theta_h, phi_h, theta_d, phi_d) -> tuple[np.ndarray, np.ndarray]:
    """Rusinkiewicz (1998) half/difference angles to a pair of directions.

    Parameters
    ----------
    theta_h, phi_h : array_like
        Polar angle and azimuth of the half vector h = (wi + wo) / |wi + wo|, radians.
    theta_d, phi_d : array_like
        Polar angle and azimuth of the difference vector d, radians: wi expressed in the frame
        where h is the pole.

    Returns
    -------
    wi, wo : ndarray, shape (..., 3)
        wi = R_z(phi_h) R_y(theta_h) d and wo = R_z(phi_h) R_y(theta_h) d', where d' is d
        turned by 180 degrees about the pole (d'_x = -d_x, d'_y = -d_y), so that wi + wo is
        parallel to h.

    Notes
    -----
    This is the inverse of :func:`directions_to_half_diff`, which follows Rusinkiewicz:
    d = R_y(-theta_h) R_z(-phi_h) wi (rotate by -phi_h about n, then by -theta_h about the
    binormal), as in MERL's reference code ``std_coords_to_half_diff_coords`` (there d comes
    from its first, "in", direction).

    Examples
    --------
    >>> wi, wo = half_diff_to_directions(0.0, 0.0, np.pi / 4, 0.0)
    >>> wi.round(6), wo.round(6)
    (array([0.707107, 0.      , 0.707107]), array([-0.707107,  0.      ,  0.707107]))
    """
    theta_h, phi_h, theta_d, phi_d = np.broadcast_arrays(
        *(np.asarray(a, float) for a in (theta_h, phi_h, theta_d, phi_d)))
    d = from_angles(theta_d, phi_d)
    dp = d * np.array([-1.0, -1.0, 1.0])
    wi = rotate_z(rotate_y(d, theta_h), phi_h)
    wo = rotate_z(rotate_y(dp, theta_h), phi_h)
    return wi, wo


def directions_to_half_diff(wi, wo) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rusinkiewicz (1998) half/difference angles of direction pairs.

    Parameters
    ----------
    wi, wo : array_like, shape (..., 3)
        Directions (normalized here).

    Returns
    -------
    theta_h, phi_h, theta_d, phi_d : ndarray
        Radians; theta in [0, pi], phi in (-pi, pi]. Where theta_h = 0, phi_h = 0 and phi_d
        carries the azimuth; where theta_d = 0, phi_d is 0.

    Notes
    -----
    h = (wi + wo) / |wi + wo|; d = R_y(-theta_h) R_z(-phi_h) wi.

    Examples
    --------
    >>> wi, wo = half_diff_to_directions(0.3, 1.0, 0.5, -2.0)
    >>> np.round(directions_to_half_diff(wi, wo), 12).tolist()
    [0.3, 1.0, 0.5, -2.0]
    """
    wi = np.asarray(wi, float)
    wo = np.asarray(wo, float)
    wi = wi / np.linalg.norm(wi, axis=-1, keepdims=True)
    wo = wo / np.linalg.norm(wo, axis=-1, keepdims=True)
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    theta_h, phi_h = to_angles(h)
    phi_h = np.where(np.hypot(h[..., 0], h[..., 1]) < 1e-12, 0.0, phi_h)
    d = rotate_y(rotate_z(wi, -phi_h), -theta_h)
    theta_d, phi_d = to_angles(d)
    phi_d = np.where(np.hypot(d[..., 0], d[..., 1]) < 1e-12, 0.0, phi_d)
    return theta_h, phi_h, theta_d, phi_d


def plane_to_directions(theta_i, theta_o, azimuth=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Signed in-plane angles to directions, for a plane of incidence at ``azimuth``.

    Parameters
    ----------
    theta_i, theta_o : array_like
        Signed polar angles, radians, in (-pi/2, pi/2). theta_i > 0 puts wi at azimuth
        ``azimuth``; theta_o > 0 puts wo on the opposite side (azimuth + pi, the specular
        side), so theta_o = theta_i is the mirror direction and theta_o = -theta_i is
        back-scatter (wo = wi).
    azimuth : float or array_like
        Azimuth of the plane, radians (0: along the warp, pi/2: along the weft).

    Returns
    -------
    wi, wo : ndarray, shape (..., 3)

    Examples
    --------
    >>> wi, wo = plane_to_directions(np.pi / 4, np.pi / 4)
    >>> wi.round(6), wo.round(6)
    (array([0.707107, 0.      , 0.707107]), array([-0.707107,  0.      ,  0.707107]))
    """
    wi = from_angles(theta_i, azimuth)
    wo = from_angles(theta_o, np.asarray(azimuth, float) + np.pi)
    return wi, wo


def directions_to_plane(wi, wo, azimuth=0.0, *, atol=1e-9) -> tuple[np.ndarray, np.ndarray]:
    """Signed in-plane angles (radians) of direction pairs lying in a plane of incidence.

    The inverse of :func:`plane_to_directions`.

    Raises
    ------
    ValueError
        If a direction lies off the plane by more than ``atol`` (sine of the angle).

    Examples
    --------
    >>> wi, wo = plane_to_directions(0.2, -0.7, np.pi / 2)
    >>> np.round(directions_to_plane(wi, wo, np.pi / 2), 12).tolist()
    [0.2, -0.7]
    """
    p = np.stack(np.broadcast_arrays(np.cos(azimuth), np.sin(azimuth), 0.0 * np.asarray(azimuth)),
                 axis=-1)
    q = rotate_z(p, np.pi / 2)
    out = []
    for name, w, sign in (("wi", wi, 1.0), ("wo", wo, -1.0)):
        w = np.asarray(w, float)
        w = w / np.linalg.norm(w, axis=-1, keepdims=True)
        off = np.abs(np.sum(w * q, axis=-1))
        if np.any(off > atol):
            raise ValueError(f"{name} lies off the plane at azimuth {np.degrees(azimuth)} deg "
                             f"(largest |sin| off the plane: {float(np.max(off)):.3g})")
        out.append(np.arctan2(sign * np.sum(w * p, axis=-1), w[..., 2]))
    return out[0], out[1]


def flat_pairs(wi, wo, names=("wi", "wo")):
    """Validate, broadcast, flatten and normalize direction pairs.

    Returns wi, wo (n, 3) unit (bad entries replaced), the leading shape, and the masks of
    bad (zero or non-finite) pairs and of pairs at or below the horizon. ``names`` are the
    parameters' names in error messages.
    """
    wi = as_directions(names[0], wi)
    wo = as_directions(names[1], wo)
    try:
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
    except ValueError:
        raise ValueError(f"{names[0]} and {names[1]} must broadcast; got shapes {wi.shape} "
                         f"and {wo.shape}") from None
    wi = np.broadcast_to(wi, shape + (3,)).reshape(-1, 3)
    wo = np.broadcast_to(wo, shape + (3,)).reshape(-1, 3)
    wi, bad_i = normalize(wi)
    wo, bad_o = normalize(wo)
    bad = bad_i | bad_o
    below = ~bad & ((wi[:, 2] <= 0.0) | (wo[:, 2] <= 0.0))
    return wi, wo, shape, bad, below
