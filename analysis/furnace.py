"""The white furnace: albedo maxima over a direction grid, with A = 1 on both threads.

Each configuration starts from a preset's tangent curves, areas and other parameters, sets the
albedo of both threads to 1 and varies one parameter (eta, k_d or gamma_s); the two directional
albedos of :data:`MODES` are computed on a small grid of fixed directions and their maxima kept.
A value counts as *exceeding 1* when value - error > 1 and as *possibly* exceeding when only
value + error > 1.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from analysis.albedo import run_tasks
from analysis.variants import VARIANTS, fabric_of, label_of
from brdf.presets import PRESETS

__all__ = ["MODES", "FURNACE_SCAN", "SCAN_THETA", "SCAN_PHI", "white_furnace",
           "directions_grid", "max_info"]

#: The two albedos: name -> ``swap`` argument of :func:`analysis.albedo`.
MODES = {"furnace": False, "reflectance": True}

#: White-furnace scan, one parameter at a time from each preset with A = 1 on both threads
#: (gamma in degrees; gamma_v follows as 2 gamma_s, the ratio of most presets).
FURNACE_SCAN = {
    "eta": (1.1, 1.46, 2.0, 2.5),
    "kd": (0.0, 0.5, 1.0),
    "gamma_s": (1.0, 2.5, 10.0, 40.0),
}

#: Directions of the scan: polar angles and azimuths, degrees.
SCAN_THETA = (0.0, 60.0, 85.0, 89.0)
SCAN_PHI = (0.0, 90.0)


def directions_grid(theta_deg, phi_deg) -> np.ndarray:
    """Unit directions (T, P, 3) at polar angles theta_deg and azimuths phi_deg (degrees).

    Examples
    --------
    >>> directions_grid([0, 90], [0]).round(12).tolist()
    [[[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]]]
    """
    th = np.radians(np.atleast_1d(np.asarray(theta_deg, dtype=np.float64)))
    ph = np.radians(np.atleast_1d(np.asarray(phi_deg, dtype=np.float64)))
    T, P = np.meshgrid(th, ph, indexing="ij")
    s = np.sin(T)
    return np.stack([s * np.cos(P), s * np.sin(P), np.cos(T)], axis=-1)


def max_info(theta, phi, value, error) -> dict[str, Any]:
    """The largest albedo of a (T, P, 3) grid, where it is, and whether the grid exceeds 1.

    Parameters
    ----------
    theta, phi : ndarray, shapes (T,), (P,)
        The grid's polar angles and azimuths, degrees.
    value, error : ndarray, shape (T, P, 3)
        Albedo (dimensionless) and its error bound.

    Returns
    -------
    dict
        ``value``, ``error``, ``theta_deg``, ``phi_deg`` and ``channel`` (0, 1, 2 = R, G, B)
        of the maximum; ``exceeds_one`` (value - error > 1 somewhere),
        ``possibly_exceeds_one`` (value + error > 1 somewhere) and ``max_lower_bound``.

    Examples
    --------
    >>> v = np.full((1, 2, 3), 0.5); v[0, 1, 2] = 1.2
    >>> m = max_info(np.array([0.0]), np.array([0.0, 90.0]), v, np.full_like(v, 0.01))
    >>> m["phi_deg"], m["channel"], m["exceeds_one"]
    (90.0, 2, True)
    """
    idx = np.unravel_index(int(np.argmax(value)), value.shape)
    lower = value - error
    return {
        "value": float(value[idx]), "error": float(error[idx]),
        "theta_deg": float(theta[idx[0]]), "phi_deg": float(phi[idx[1]]), "channel": int(idx[2]),
        "exceeds_one": bool(np.any(lower > 1.0)),
        "possibly_exceeds_one": bool(np.any(value + error > 1.0)),
        "max_lower_bound": float(lower.max()),
    }


def _white(threads):
    """The threads with albedo A = 1 in every channel."""
    return tuple(t.replace(albedo=(1.0, 1.0, 1.0)) for t in threads)


def _configurations(name: str, scan: dict, variant: str):
    """(configuration, fabric) of the white preset ``name`` and of each scanned value."""
    base = fabric_of(name, variant)
    white = _white(base.threads)
    entries = [("none", None)] + [(k, v) for k, vals in scan.items() for v in vals]
    for param, val in entries:
        if param == "none":
            threads = white
        elif param == "gamma_s":
            threads = tuple(t.replace(gamma_s=val, gamma_v=2 * val) for t in white)
        else:
            threads = tuple(t.replace(**{param: val}) for t in white)
        yield ({"curves": label_of(name), "parameter": param, "value": val,
                "variant": variant},
               base.replace(threads=threads))


def white_furnace(presets=None, *, scan=None, variant: str = "default", theta_deg=SCAN_THETA,
                  phi_deg=SCAN_PHI, modes=("furnace", "reflectance"), tol: float = 2e-3,
                  min_level: int = -1, workers=None, progress=None) -> list[dict[str, Any]]:
    """White-furnace scan: A = 1 on both threads, one parameter varied at a time.

    Parameters
    ----------
    presets : sequence of str or brdf.Fabric, optional
        Presets whose tangent curves, areas and other parameters are the starting points
        (default: all six).
    scan : dict, optional
        Parameter name (``eta``, ``kd``, ``gamma_s``) -> values, applied to both threads;
        ``gamma_s`` also sets gamma_v = 2 gamma_s. Default :data:`FURNACE_SCAN`. The white
        preset itself is always included (parameter ``"none"``).
    variant : str, default "default"
        A key of :data:`analysis.variants.VARIANTS`.
    theta_deg, phi_deg : sequence of float
        Directions examined, degrees.
    modes : sequence of str
        Keys of :data:`MODES`.
    tol : float, default 2e-3
        Albedo tolerance (deciding "above 1" does not need 1e-3).
    min_level : int, default -1
        Coarsest level of :func:`analysis.albedo` (-1: start with the cheap pair of levels).
    workers : int, optional
        Processes.
    progress : callable, optional
        Called with the number of directions done.

    Returns
    -------
    list of dict
        One per configuration: ``curves``, ``parameter``, ``value``, ``variant``, and for each
        mode ``{mode: max-info}`` (see :func:`max_info`).
    """
    presets = tuple(PRESETS if presets is None else presets)
    scan = FURNACE_SCAN if scan is None else scan
    for k in scan:
        if k not in ("eta", "kd", "gamma_s"):
            raise ValueError(f"scan parameter must be 'eta', 'kd' or 'gamma_s'; got {k!r}")
    if variant not in VARIANTS:
        raise ValueError(f"variant must be one of {', '.join(VARIANTS)}; got {variant!r}")
    dirs = directions_grid(theta_deg, phi_deg).reshape(-1, 3)
    th, ph = np.asarray(theta_deg, float), np.asarray(phi_deg, float)
    configs, tasks = [], []
    for name in presets:
        for cfg, fab in _configurations(name, scan, variant):
            configs.append(cfg)
            for mode in modes:
                tasks.append((fab, dirs, {"swap": MODES[mode], "tol": tol,
                                          "min_level": min_level}))
    res = run_tasks(tasks, workers, progress=progress)
    out, k = [], 0
    for cfg in configs:
        for mode in modes:
            v, e, _ = res[k]
            k += 1
            cfg[mode] = max_info(th, ph, v.reshape(th.size, ph.size, 3),
                                  e.reshape(th.size, ph.size, 3))
        out.append(cfg)
    return out

