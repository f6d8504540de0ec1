"""Measurement layouts: the constructors of :class:`gonio.geometry.Geometry` objects.

Full hemispherical grids, planes of incidence, the Rusinkiewicz half/difference grid, the MERL
layout and arbitrary pairs. Each takes the angles that define it in **degrees** and the sample
``rotation`` in **radians**, and drops pairs at or below the horizon (see :mod:`gonio.geometry`
for the conventions).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from brdf.frames import from_angles, half_diff_to_directions, plane_to_directions, to_angles
from gonio.geometry import HORIZON_EPS, Geometry
from gonio.gridsize import (check_pairs, full_steps, merl_stride, node_count, node_range,
                            rus_steps, side_count, step_degrees)
from gonio.numtext import parse_number

__all__ = ["full_grid", "plane", "rusinkiewicz", "merl", "pairs", "pairs_from_angles",
           "PLANE_AZIMUTHS", "PLANE_THETA_I"]

#: Named planes of incidence and their azimuths, degrees.
PLANE_AZIMUTHS = {"warp": 0.0, "weft": 90.0, "45": 45.0}
#: The incidence angles of a plane by default, degrees.
PLANE_THETA_I = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0)


def _build(kind, params, wi, wo, coords, rotation) -> Geometry:
    """Drop pairs at or below the horizon, record the count, and make the Geometry."""
    wi = np.asarray(wi, float).reshape(-1, 3)
    wo = np.asarray(wo, float).reshape(-1, 3)
    n_layout = wi.shape[0]
    keep = (wi[:, 2] > HORIZON_EPS) & (wo[:, 2] > HORIZON_EPS)
    idx = np.flatnonzero(keep)
    coords = {k: np.asarray(v, float).reshape(-1)[idx] for k, v in coords.items()}
    return Geometry(wi[idx], wo[idx], coords, kind=kind, params=params, rotation=rotation,
                    index=idx, info={"n_layout": n_layout,
                                     "dropped_below_horizon": int(n_layout - idx.size)})


def _hemisphere(theta_step, phi_step, theta_max=90.0):
    """Directions of a (theta, phi) grid, one direction at theta = 0; degrees in, radians out."""
    thetas = node_range(theta_step, theta_max)
    phis = node_range(phi_step, 360.0)
    t = [0.0] + [th for th in thetas[1:] for _ in phis]
    p = [0.0] + [ph for _ in thetas[1:] for ph in phis]
    return np.radians(t), np.radians(p)


def full_grid(theta_step: float = 10.0, phi_step: float | None = None, *,
              theta_o_step: float | None = None, phi_o_step: float | None = None,
              rotation: float = 0.0) -> Geometry:
    """A full hemispherical grid of light and view directions.

    Parameters
    ----------
    theta_step : float
        Step of theta_i in degrees (and of theta_o unless ``theta_o_step`` is given). The polar
        angles are 0, step, 2 step, ... strictly below 90 (the horizon is excluded).
    phi_step : float, optional
        Step of phi_i in degrees over [0, 360) (and of phi_o unless ``phi_o_step``); defaults
        to ``theta_step``.
    theta_o_step, phi_o_step : float, optional
        Steps of the view directions in degrees.
    rotation : float
        Sample rotation, radians.

    Returns
    -------
    Geometry
        kind "full", coordinates theta_i, phi_i, theta_o, phi_o (radians). At theta = 0 every
        azimuth gives the same direction, so the grid keeps one (phi = 0) there: each side has
        1 + (n_theta - 1) n_phi directions and the geometry is their product (light-major).

    Examples
    --------
    >>> g = full_grid(45, 90)
    >>> len(g)  # (1 + 1 * 4) ** 2
    25
    >>> float(np.degrees(g.coords["theta_i"]).max())
    45.0
    """
    ti_s, pi_s, to_s, po_s = full_steps(theta_step, phi_step, theta_o_step, phi_o_step)
    check_pairs("full_grid", (side_count(ti_s, pi_s), side_count(to_s, po_s)))
    ti, pi_ = _hemisphere(ti_s, pi_s)
    to, po = _hemisphere(to_s, po_s)
    TI = np.repeat(ti, to.size)
    PI = np.repeat(pi_, to.size)
    TO = np.tile(to, ti.size)
    PO = np.tile(po, ti.size)
    wi = from_angles(TI, PI)
    wo = from_angles(TO, PO)
    params = {"theta_i_step": ti_s, "phi_i_step": pi_s, "theta_o_step": to_s, "phi_o_step": po_s}
    return _build("full", params, wi, wo,
                  {"theta_i": TI, "phi_i": PI, "theta_o": TO, "phi_o": PO}, rotation)


def plane(azimuth="warp", theta_o_step: float = 5.0,
          theta_i=PLANE_THETA_I, *, rotation: float = 0.0) -> Geometry:
    """Measurements in a plane of incidence (phi_o = phi_i + 180 degrees).

    Parameters
    ----------
    azimuth : {"warp", "weft", "45"} or float
        The plane: along the warp (0 degrees), the weft (90), at 45, or any azimuth in degrees.
    theta_o_step : float
        Step of the signed view angle in degrees; theta_o sweeps k * step strictly inside
        (-90, 90) (the horizon excluded). theta_o > 0 is the specular side.
    theta_i : sequence of float
        Signed incidence angles in degrees, each in (-90, 90); theta_i > 0 puts the light at
        the plane's azimuth.
    rotation : float
        Sample rotation, radians.

    Returns
    -------
    Geometry
        kind "plane"; coordinates theta_i, theta_o (signed, radians); see
        :func:`brdf.frames.plane_to_directions`. Pairs are ordered incidence-major.

    Examples
    --------
    >>> g = plane("weft", 30, theta_i=[0, 30])
    >>> np.degrees(g.coords["theta_o"]).round(6).tolist()
    [-60.0, -30.0, 0.0, 30.0, 60.0, -60.0, -30.0, 0.0, 30.0, 60.0]
    >>> g.wi[-1].round(6)  # the light at theta_i = 30 in the weft (y) plane
    array([0.      , 0.5     , 0.866025])
    """
    if isinstance(azimuth, str):
        key = azimuth.strip().lower()
        if key in PLANE_AZIMUTHS:
            az = PLANE_AZIMUTHS[key]
        else:
            try:
                az = parse_number(key)
            except ValueError:
                raise ValueError(f"plane azimuth must be warp, weft, 45 or degrees; "
                                 f"got {azimuth!r}") from None
    else:
        az = float(azimuth)
    if not math.isfinite(az):
        raise ValueError(f"plane azimuth must be finite degrees; got {azimuth!r}")
    step = step_degrees("theta_o_step", theta_o_step)
    ti = np.atleast_1d(np.asarray(theta_i, float))
    if ti.ndim != 1 or ti.size == 0 or not np.all(np.isfinite(ti)) or np.any(np.abs(ti) >= 90):
        raise ValueError(f"theta_i must be a non-empty list of degrees in (-90, 90); "
                         f"got {theta_i!r}")
    k = node_count(step, 90.0) - 1
    check_pairs("plane", (ti.size, 2 * k + 1))
    to = step * np.arange(-k, k + 1)
    TI = np.radians(np.repeat(ti, to.size))
    TO = np.radians(np.tile(to, ti.size))
    wi, wo = plane_to_directions(TI, TO, math.radians(az))
    params = {"azimuth": az, "theta_o_step": step, "theta_i": ti.tolist()}
    return _build("plane", params, wi, wo, {"theta_i": TI, "theta_o": TO}, rotation)


def rusinkiewicz(theta_h_step: float = 5.0, phi_h_step: float | None = None,
                 theta_d_step: float | None = None, phi_d_step: float | None = None, *,
                 rotation: float = 0.0) -> Geometry:
    """The anisotropic Rusinkiewicz half/difference grid.

    Parameters
    ----------
    theta_h_step, phi_h_step, theta_d_step, phi_d_step : float
        Steps in degrees (each defaults to ``theta_h_step``). theta_h and theta_d take the
        nodes 0, step, ... strictly below 90; phi_h and phi_d the nodes 0, step, ... below
        360 (the full circle, since neither isotropy nor reciprocity is assumed).
    rotation : float
        Sample rotation, radians.

    Returns
    -------
    Geometry
        kind "rusinkiewicz"; coordinates theta_h, phi_h, theta_d, phi_d (radians), ordered
        with phi_d fastest, then theta_d, phi_h, theta_h; pairs below the horizon dropped.
        All grid nodes are kept, including the degenerate ones (theta_d = 0 repeats one
        direction pair for every phi_d), so the layout stays a regular 4-D grid.

    Examples
    --------
    >>> g = rusinkiewicz(30, 90, 30, 90)
    >>> g.info["n_layout"], len(g) + g.info["dropped_below_horizon"]
    (144, 144)
    """
    th_s, ph_s, td_s, pd_s = rus_steps(theta_h_step, phi_h_step, theta_d_step, phi_d_step)
    check_pairs("rusinkiewicz", [node_count(s, stop) for s, stop in
                                 ((th_s, 90.0), (ph_s, 360.0), (td_s, 90.0), (pd_s, 360.0))])
    axes = [np.radians(node_range(th_s, 90.0)), np.radians(node_range(ph_s, 360.0)),
            np.radians(node_range(td_s, 90.0)), np.radians(node_range(pd_s, 360.0))]
    TH, PH, TD, PD = (a.reshape(-1) for a in np.meshgrid(*axes, indexing="ij"))
    wi, wo = half_diff_to_directions(TH, PH, TD, PD)
    params = {"theta_h_step": th_s, "phi_h_step": ph_s, "theta_d_step": td_s, "phi_d_step": pd_s}
    return _build("rusinkiewicz", params, wi, wo,
                  {"theta_h": TH, "phi_h": PH, "theta_d": TD, "phi_d": PD}, rotation)


def merl(stride: int = 1, *, rotation: float = 0.0) -> Geometry:
    """The MERL isotropic layout: 90 theta_h x 90 theta_d x 180 phi_d, phi_h = 0.

    Parameters
    ----------
    stride : int
        Keep every ``stride``-th index in each of the three dimensions (1: the full
        1,458,000-entry layout).
    rotation : float
        Sample rotation, radians. An isotropic table of an anisotropic sample is what one
        rotation gives; average several rotations for the rotation-averaged table.

    Returns
    -------
    Geometry
        kind "merl"; coordinates theta_h, phi_h (= 0), theta_d, phi_d in radians;
        ``index`` = the flat MERL index phi_d + 180 (theta_d + 90 theta_h) of each pair.

    Notes
    -----
    MERL's reference code (``BRDFRead.cpp``) indexes by truncation:
    theta_h index = floor(sqrt(theta_h / 90 deg) * 90), theta_d index = floor(theta_d / 1 deg),
    phi_d index = floor(phi_d / 1 deg) for phi_d in [0, 180) (phi_d + 180 folds onto phi_d).
    Entry (i, j, k) is placed at the centre of its bin, as :mod:`gonio.merl` reads and writes
    MERL files: theta_h = ((i + 1/2) / 90)^2 * 90 deg (the centre in the square-root mapped
    coordinate), theta_d = j + 1/2 deg and phi_d = k + 1/2 deg, so that a truncating lookup of
    the placed directions finds (i, j, k) again. (The lower node (i / 90)^2 * 90 deg sits on
    the bin's edge, where round-off sends the lookup to the bin below about a third of the
    time.)
    Pairs with a direction below the horizon are dropped (``index`` keeps the others' places).

    Examples
    --------
    >>> g = merl(30)
    >>> g.info["n_layout"], sorted(set(g.index.tolist()))[:3]
    (54, [0, 30, 60])
    >>> np.degrees(g.coords["theta_h"][g.index == 30 * 180 * 90]).round(6).tolist()   # 30.5^2/90
    [10.336111]
    """
    stride = merl_stride(stride)
    check_pairs("merl", [node_count(stride, stop) for stop in (90.0, 90.0, 180.0)])
    i = np.arange(0, 90, stride)
    j = np.arange(0, 90, stride)
    k = np.arange(0, 180, stride)
    I, J, K = (a.reshape(-1) for a in np.meshgrid(i, j, k, indexing="ij"))
    TH = np.radians(((I + 0.5) / 90.0) ** 2 * 90.0)
    TD = np.radians(J + 0.5)
    PD = np.radians(K + 0.5)
    PH = np.zeros_like(TH)
    wi, wo = half_diff_to_directions(TH, PH, TD, PD)
    g = _build("merl", {"stride": int(stride)}, wi, wo,
               {"theta_h": TH, "phi_h": PH, "theta_d": TD, "phi_d": PD}, rotation)
    flat = (K + 180 * (J + 90 * I))[g.index]
    return dataclasses.replace(g, index=flat)


def pairs(wi, wo, *, rotation: float = 0.0, params: dict | None = None) -> Geometry:
    """An arbitrary list of direction pairs (lab frame).

    Parameters
    ----------
    wi, wo : array_like, shape (n, 3)
        Directions toward the light and the detector (normalized here).
    rotation : float
        Sample rotation, radians.

    Returns
    -------
    Geometry
        kind "pairs", coordinates theta_i, phi_i, theta_o, phi_o (radians) of the directions;
        pairs below the horizon dropped.

    Examples
    --------
    >>> g = pairs([[0, 0, 1], [1, 0, 0]], [[0, 0, 1], [0, 0, 1]])
    >>> len(g), g.info["dropped_below_horizon"]
    (1, 1)
    """
    wi = np.asarray(wi, float)
    wo = np.asarray(wo, float)
    if wi.ndim != 2 or wi.shape[1] != 3 or wo.shape != wi.shape:
        raise ValueError(f"wi and wo must both have shape (n, 3); got {wi.shape} and {wo.shape}")
    ni = np.linalg.norm(wi, axis=1, keepdims=True)
    no = np.linalg.norm(wo, axis=1, keepdims=True)
    if not (np.all(np.isfinite(ni) & (ni > 0)) and np.all(np.isfinite(no) & (no > 0))):
        raise ValueError("wi and wo must hold finite, non-zero directions")
    wi, wo = wi / ni, wo / no
    ti, pi_ = to_angles(wi)
    to, po = to_angles(wo)
    return _build("pairs", dict(params or {}), wi, wo,
                  {"theta_i": ti, "phi_i": pi_, "theta_o": to, "phi_o": po}, rotation)


def pairs_from_angles(theta_i, phi_i, theta_o, phi_o, *, degrees: bool = True,
                      rotation: float = 0.0, params: dict | None = None) -> Geometry:
    """An arbitrary list of pairs from their angles (such as CUReT's 205 configurations).

    Parameters
    ----------
    theta_i, phi_i, theta_o, phi_o : array_like, shape (n,)
        Polar angles and azimuths of light and view; degrees, or radians with
        ``degrees=False``.
    rotation : float
        Sample rotation, radians.

    Returns
    -------
    Geometry
        kind "pairs"; the coordinates are the given angles (in radians), pairs below the
        horizon dropped.

    Examples
    --------
    >>> g = pairs_from_angles([30, 95], [0, 0], [30, 30], [180, 180])
    >>> len(g), g.wo[0].round(6)
    (1, array([-0.5     ,  0.      ,  0.866025]))
    """
    arrs = [np.atleast_1d(np.asarray(a, float)) for a in (theta_i, phi_i, theta_o, phi_o)]
    try:
        arrs = np.broadcast_arrays(*arrs)
    except ValueError:
        raise ValueError("theta_i, phi_i, theta_o, phi_o must have the same length; got "
                         + ", ".join(str(a.shape) for a in arrs)) from None
    arrs = [a.reshape(-1) for a in arrs]
    if not all(np.all(np.isfinite(a)) for a in arrs):
        raise ValueError("pair angles must be finite")
    if degrees:
        arrs = [np.radians(a) for a in arrs]
    ti, pi_, to, po = arrs
    wi = from_angles(ti, pi_)
    wo = from_angles(to, po)
    return _build("pairs", dict(params or {}), wi, wo,
                  {"theta_i": ti, "phi_i": pi_, "theta_o": to, "phi_o": po}, rotation)
