"""ALTA input parametrizations: direction pairs to and from ALTA's ``#PARAM_IN`` coordinates.

Conventions follow ALTA's ``sources/core/params.cpp`` (``params::to_cartesian`` and
``params::from_cartesian``) and ``sources/core/params.h`` (``half_to_cartesian``, the
``CARTESIAN`` enum comment). ALTA names the light vector L and the view vector V; here
L = wi (toward the light) and V = wo (toward the viewer). All angles are in radians; the
frame is n = +z, tangent +x, binormal +y; azimuths are ``atan2(y, x)`` in (-pi, pi].

========================  ===  ===================================================
name                      dim  coordinates
========================  ===  ===================================================
COS_TH                    1    cos theta_h; back-scatter only, wi = wo = h, phi_h = 0
RUSIN_TH_TD_PD            3    theta_h, theta_d, phi_d (phi_h = 0: isotropic)
SPHERICAL_TL_PL_TV_PV     4    theta_L, phi_L, theta_V, phi_V
RUSIN_TH_PH_TD_PD         4    theta_h, phi_h, theta_d, phi_d
CARTESIAN                 6    V.x, V.y, V.z, L.x, L.y, L.z (view vector first)
========================  ===  ===================================================

Rusinkiewicz angles: h = (L + V) / |L + V|; the difference vector d is the **view** vector V
rotated by -phi_h about n and then by -theta_h about the binormal (``from_cartesian``,
case ``RUSIN_TH_PH_TD_PD``), and L is V mirrored about h (``half_to_cartesian``). This is
:func:`brdf.frames.directions_to_half_diff` with its first argument V = wo, so the ALTA
angles are ``directions_to_half_diff(wo, wi)`` (microcyl's own phi_d, which takes d from wi,
differs by pi).
"""

from __future__ import annotations

import numpy as np

from brdf.frames import directions_to_half_diff, from_angles, half_diff_to_directions, to_angles

__all__ = ["DIMENSION", "WRITABLE", "to_params", "from_params", "phi_h"]

DIMENSION = {"COS_TH": 1, "RUSIN_TH_TD_PD": 3, "SPHERICAL_TL_PL_TV_PV": 4,
             "RUSIN_TH_PH_TD_PD": 4, "CARTESIAN": 6}
WRITABLE = ("COS_TH", "SPHERICAL_TL_PL_TV_PV", "RUSIN_TH_PH_TD_PD", "RUSIN_TH_TD_PD",
            "CARTESIAN")


def phi_h(wi, wo) -> np.ndarray:
    """Azimuth of the half vector of each pair, radians (0 where h is along n).

    Parameters
    ----------
    wi, wo : ndarray, shape (n, 3)
        Unit directions.

    Returns
    -------
    ndarray, shape (n,)
    """
    return directions_to_half_diff(wo, wi)[1]


def to_params(name: str, wi, wo) -> np.ndarray:
    """ALTA coordinates of direction pairs.

    Parameters
    ----------
    name : str
        One of :data:`WRITABLE`.
    wi, wo : ndarray, shape (n, 3)
        Unit directions toward the light (ALTA's L) and the viewer (ALTA's V).

    Returns
    -------
    ndarray, shape (n, DIMENSION[name])
        Angles in radians (COS_TH: a cosine; CARTESIAN: unit-vector components). For
        RUSIN_TH_TD_PD, phi_h is dropped: the caller checks that it may be (rotating each
        pair about n by -phi_h).

    Raises
    ------
    ValueError
        An unknown name.
    """
    wi = np.asarray(wi, float)
    wo = np.asarray(wo, float)
    if name == "COS_TH":
        return wi[:, 2:3].copy()
    if name == "SPHERICAL_TL_PL_TV_PV":
        tl, pl = to_angles(wi)
        tv, pv = to_angles(wo)
        return np.stack([tl, pl, tv, pv], axis=1)
    if name == "CARTESIAN":
        return np.concatenate([wo, wi], axis=1)
    if name in ("RUSIN_TH_PH_TD_PD", "RUSIN_TH_TD_PD"):
        th, ph, td, pd = directions_to_half_diff(wo, wi)
        cols = [th, ph, td, pd] if name == "RUSIN_TH_PH_TD_PD" else [th, td, pd]
        return np.stack(cols, axis=1)
    raise ValueError(f"ALTA parametrization {name!r} is not supported; known: "
                     + ", ".join(WRITABLE))


def from_params(name: str, x) -> tuple[np.ndarray, np.ndarray]:
    """Direction pairs from ALTA coordinates (the inverse of :func:`to_params`).

    Parameters
    ----------
    name : str
        One of :data:`WRITABLE`.
    x : ndarray, shape (n, DIMENSION[name])
        Radians (COS_TH: cos theta_h in [0, 1]).

    Returns
    -------
    wi, wo : ndarray, shape (n, 3)
        L and V. COS_TH gives wi = wo = (sin theta_h, 0, cos theta_h); RUSIN_TH_TD_PD puts
        the half vector at phi_h = 0.

    Raises
    ------
    ValueError
        An unknown name.
    """
    x = np.asarray(x, float)
    if name == "COS_TH":
        c = x[:, 0]
        w = np.stack([np.sqrt(1.0 - c ** 2), np.zeros_like(c), c], axis=1)
        return w, w.copy()
    if name == "SPHERICAL_TL_PL_TV_PV":
        return from_angles(x[:, 0], x[:, 1]), from_angles(x[:, 2], x[:, 3])
    if name == "CARTESIAN":
        wo, wi = x[:, 0:3], x[:, 3:6]
        return wi / np.linalg.norm(wi, axis=1, keepdims=True), \
            wo / np.linalg.norm(wo, axis=1, keepdims=True)
    if name == "RUSIN_TH_PH_TD_PD":
        v, l_ = half_diff_to_directions(x[:, 0], x[:, 1], x[:, 2], x[:, 3])
        return l_, v
    if name == "RUSIN_TH_TD_PD":
        v, l_ = half_diff_to_directions(x[:, 0], 0.0, x[:, 1], x[:, 2])
        return l_, v
    raise ValueError(f"ALTA parametrization {name!r} is not supported; known: "
                     + ", ".join(WRITABLE))
