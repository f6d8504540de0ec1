"""Energy conservation of the microcylinder model: albedo curves and a white furnace.

Two directional albedos are measured (see :mod:`analysis.albedo`):

* ``furnace``: rho(wo) = integral of f_r(wi, wo) cos(theta_i) dwi, the radiance seen from wo
  in a uniform white environment (what a renderer's white-furnace test shows);
* ``reflectance``: rho'(wi) = integral of f_r(wi, wo) cos(theta_o) dwo, the fraction of the
  power arriving from wi that is reflected. Energy conservation proper is rho'(wi) <= 1.

For a reciprocal BRDF they coincide; the microcylinder model is not reciprocal, so both are
reported. A value counts as *exceeding 1* when value - error > 1 and as *possibly* exceeding
when only value + error > 1. The white-furnace scan is :mod:`analysis.furnace`; the findings
in words are written by :func:`reports.prose.energy_statements`.
"""

from __future__ import annotations

import dataclasses
import itertools
import time
from typing import Any

import numpy as np

from analysis.albedo import albedo_hemispherical, run_tasks
from analysis.furnace import (FURNACE_SCAN, MODES, SCAN_PHI, SCAN_THETA, directions_grid,
                              max_info, white_furnace)
from analysis.variants import VARIANTS, Named, applies, check_names, fabric_of, label_of
from gonio.progress import progress_bar

__all__ = [
    "VARIANTS",
    "MODES",
    "FURNACE_SCAN",
    "EnergyReport",
    "energy_report",
    "white_furnace",
    "directions_grid",
]

DEFAULT_THETA = tuple(range(0, 90, 5)) + (89,)
#: Directions counted per preset for the progress of the hemispherical albedo.
_HEMI_TICKS = 60
_DEFINITIONS = {
    "furnace": "rho(wo) = integral f_r(wi, wo) cos(theta_i) dwi; theta, phi of wo",
    "reflectance": "rho'(wi) = integral f_r(wi, wo) cos(theta_o) dwo; theta, phi of wi",
    "exceeds_one": "value - error > 1 somewhere on the grid",
}


@dataclasses.dataclass(frozen=True, eq=False)
class EnergyReport:
    """Everything :func:`energy_report` measured, as plain data.

    Attributes
    ----------
    settings : dict
        Directions, tolerance, modes, variants and scan grid used.
    curves : list of dict
        One per (preset, variant, mode): ``theta_deg``, ``phi_deg``, ``value`` and ``error``
        (T, P, 3), ``max`` (value, error, theta_deg, phi_deg, channel), ``exceeds_one``,
        ``possibly_exceeds_one`` and ``first_theta_above_one`` (degrees, or None).
    hemispherical : list of dict
        Hemispherical-hemispherical albedo per preset (default variant): value, error (3,).
    furnace : list of dict
        White-furnace configurations: ``curves`` (the preset whose tangent curves and areas
        are used), ``parameter``, ``value``, ``variant``, and per mode the max with location.
    seconds : float
        Wall time.
    """

    settings: dict
    curves: list
    hemispherical: list
    furnace: list
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return dataclasses.asdict(self)


def _check_modes(modes):
    """ValueError for a mode that is not a key of :data:`MODES`."""
    for m in modes:
        if m not in MODES:
            raise ValueError(f"unknown mode {m!r}; modes: {', '.join(MODES)}")


def _curve(p, v, m, th, ph, val, err) -> dict[str, Any]:
    """One entry of :attr:`EnergyReport.curves` from its (T, P, 3) albedo and error."""
    info = max_info(th, ph, val, err)
    return {
        "preset": p, "variant": v, "options": dict(VARIANTS[v]), "mode": m,
        "theta_deg": th.tolist(), "phi_deg": ph.tolist(), "value": val.tolist(),
        "error": err.tolist(), "max": info,
        "exceeds_one": info["exceeds_one"],
        "possibly_exceeds_one": info["possibly_exceeds_one"],
        "first_theta_above_one": (float(th[np.any(val - err > 1, axis=(1, 2))][0])
                                  if info["exceeds_one"] else None),
    }


def _curves(presets, variants, modes, th, ph, tol, min_level, workers, tick) -> list[dict]:
    """The albedo curves of every (preset, variant, mode) over the (th, ph) grid."""
    dirs = directions_grid(th, ph).reshape(-1, 3)
    keys, tasks = [], []
    for p, v, m in itertools.product(presets, variants, modes):
        if not applies(p, v):
            continue
        keys.append((p, v, m))
        tasks.append((fabric_of(p, v), dirs,
                      {"swap": MODES[m], "tol": tol, "min_level": min_level}))
    res = run_tasks(tasks, workers, progress=tick)
    return [_curve(label_of(p), v, m, th, ph, val.reshape(th.size, ph.size, 3),
                   err.reshape(th.size, ph.size, 3))
            for (p, v, m), (val, err, _) in zip(keys, res)]


def _hemispherical(presets, tol, min_level, workers, tick) -> list[dict]:
    """The hemispherical-hemispherical albedo of each preset (default variant)."""
    hemi = []
    for p in presets:
        h = albedo_hemispherical(fabric_of(p), n_theta=6, n_phi=8, tol=tol,
                                 min_level=min_level, workers=workers)
        hemi.append({"preset": label_of(p), "variant": "default", **h.to_dict()})
        if tick:
            tick(_HEMI_TICKS)
    return hemi


def _total(presets, variants, modes, n_dirs, hemispherical, furnace, scan, scan_dirs) -> int:
    """Directions computed in all, for the progress bar."""
    fabrics = [p for p in presets if not isinstance(p, Named)]
    n_scan = (len(fabrics) * (1 + sum(len(v) for v in scan.values())) * len(modes)
              * scan_dirs) if furnace else 0
    n_curves = sum(applies(p, v) for p in presets for v in variants)
    return (n_curves * len(modes) * n_dirs + n_scan
            + (len(presets) * _HEMI_TICKS if hemispherical else 0))


def _settings(th, ph, modes, variants, presets, tol, furnace, scan, scan_theta_deg,
              scan_phi_deg) -> dict[str, Any]:
    """The settings of :class:`EnergyReport`."""
    return {
        "theta_deg": th.tolist(), "phi_deg": ph.tolist(), "modes": list(modes),
        "variants": {v: VARIANTS[v] for v in variants},
        "presets": [label_of(p) for p in presets], "tol": tol,
        "furnace_scan": {k: list(v) for k, v in scan.items()} if furnace else None,
        "scan_theta_deg": list(scan_theta_deg), "scan_phi_deg": list(scan_phi_deg),
        "definitions": dict(_DEFINITIONS),
    }


def energy_report(presets=None, variants=None, *, theta_deg=DEFAULT_THETA, phi_deg=(0.0, 90.0),
                  modes=("furnace", "reflectance"), tol: float = 1e-3, min_level: int = -1,
                  hemispherical: bool = True, furnace: bool = True, scan=None,
                  scan_theta_deg=SCAN_THETA, scan_phi_deg=SCAN_PHI, workers=None,
                  progress: bool = False) -> EnergyReport:
    """Albedo curves per preset and variant, and the white-furnace scan.

    Parameters
    ----------
    presets : sequence of str or brdf.Fabric, optional
        Preset names (default: all of ``brdf.PRESETS``), or fabrics named by their ``name``
        (a fit's, a file's: :func:`analysis.variants.label_of`).
    variants : sequence of str, optional
        Keys of :data:`VARIANTS` (default: all).
    theta_deg, phi_deg : sequence of float
        The sweep of the fixed direction, degrees.
    modes : sequence of {"furnace", "reflectance"}
        Which albedos to compute.
    tol : float, default 1e-3
        Absolute albedo tolerance (relative 1e-3 for albedos above 1).
    min_level : int, default -1
        Coarsest quadrature level (see :func:`analysis.albedo`).
    hemispherical : bool, default True
        Also compute the hemispherical-hemispherical albedo of each preset (default variant).
    furnace : bool, default True
        Run the white-furnace scan (:func:`white_furnace`, default variant).
    scan : dict, optional
        Scan grid for the white furnace (default :data:`FURNACE_SCAN`).
    scan_theta_deg, scan_phi_deg : sequence of float
        Directions of the white-furnace scan, degrees.
    workers : int, optional
        Processes (default: up to 2).
    progress : bool, default False
        Show a tqdm progress bar on stderr.

    Returns
    -------
    EnergyReport
        Its findings in words: :func:`reports.prose.energy_statements`.

    Raises
    ------
    ValueError
        Unknown preset, variant or mode.
    """
    t0 = time.perf_counter()
    presets, variants = check_names(presets, variants)
    _check_modes(modes)
    th = np.atleast_1d(np.asarray(theta_deg, float))
    ph = np.atleast_1d(np.asarray(phi_deg, float))
    scan = FURNACE_SCAN if scan is None else scan
    total = _total(presets, variants, modes, th.size * ph.size, hemispherical, furnace, scan,
                   len(scan_theta_deg) * len(scan_phi_deg))
    bar = progress_bar(total, desc="energy", unit="albedo", enabled=progress)
    tick = bar.update if progress else None
    try:
        curves = _curves(presets, variants, modes, th, ph, tol, min_level, workers, tick)
        hemi = _hemispherical(presets, tol, min_level, workers, tick) if hemispherical else []
        fabrics = [p for p in presets if not isinstance(p, Named)]
        scan_rows = (white_furnace(fabrics, scan=scan, theta_deg=scan_theta_deg,
                                   phi_deg=scan_phi_deg, modes=modes, workers=workers,
                                   min_level=min_level, progress=tick)
                     if furnace and fabrics else [])
    finally:
        if bar is not None:
            bar.close()
    settings = _settings(th, ph, modes, variants, presets, tol, furnace, scan, scan_theta_deg,
                         scan_phi_deg)
    return EnergyReport(settings=settings, curves=curves, hemispherical=hemi, furnace=scan_rows,
                        seconds=time.perf_counter() - t0)
