"""Energy conservation of the microcylinder model: albedo curves and a white furnace.

Two directional albedos are measured (see :mod:`analysis.albedo`):

* ``furnace``: rho(wo) = integral of f_r(wi, wo) cos(theta_i) dwi, the radiance seen from wo
  in a uniform white environment (what a renderer's white-furnace test shows);
* ``reflectance``: rho'(wi) = integral of f_r(wi, wo) cos(theta_o) dwo, the fraction of the
  power arriving from wi that is reflected. Energy conservation proper is rho'(wi) <= 1.

For a reciprocal BRDF they coincide; the microcylinder model is not reciprocal, so both are
reported. A value counts as *exceeding 1* when value - error > 1 and as *possibly* exceeding
when only value + error > 1.
"""

from __future__ import annotations

import dataclasses
import itertools
import time
from typing import Any

import numpy as np

from analysis.albedo import albedo_hemispherical, run_tasks
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

#: Model variants examined, by name: options passed to ``brdf.fabric``.
VARIANTS = {
    "default": {},
    "masking_off": {"masking": False},
    "reweighting_off": {"reweighting": False},
    "transmission_longitudinal": {"transmission": "longitudinal"},
    "gap_outgoing": {"gap": "outgoing"},
}

#: The two albedos: name -> ``swap`` argument of :func:`analysis.albedo`.
MODES = {"furnace": False, "reflectance": True}

#: White-furnace scan, one parameter at a time from each preset with A = 1 on both threads
#: (gamma in degrees; gamma_v follows as 2 gamma_s, the ratio of most presets).
FURNACE_SCAN = {
    "eta": (1.1, 1.46, 2.0, 2.5),
    "kd": (0.0, 0.5, 1.0),
    "gamma_s": (1.0, 2.5, 10.0, 40.0),
}

DEFAULT_THETA = tuple(range(0, 90, 5)) + (89,)
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
    statements : list of str
        Plain-language findings.
    seconds : float
        Wall time.
    """

    settings: dict
    curves: list
    hemispherical: list
    furnace: list
    statements: list
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serializable data."""
        return dataclasses.asdict(self)


def _max_info(theta, phi, value, error) -> dict[str, Any]:
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
    return tuple(t.replace(albedo=(1.0, 1.0, 1.0)) for t in threads)


def white_furnace(presets=None, *, scan=None, variant: str = "default", theta_deg=SCAN_THETA,
                  phi_deg=SCAN_PHI, modes=("furnace", "reflectance"), tol: float = 2e-3,
                  min_level: int = -1, workers=None, progress=None) -> list[dict[str, Any]]:
    """White-furnace scan: A = 1 on both threads, one parameter varied at a time.

    Parameters
    ----------
    presets : sequence of str, optional
        Presets whose tangent curves, areas and other parameters are the starting points
        (default: all six).
    scan : dict, optional
        Parameter name (``eta``, ``kd``, ``gamma_s``) -> values, applied to both threads;
        ``gamma_s`` also sets gamma_v = 2 gamma_s. Default :data:`FURNACE_SCAN`. The white
        preset itself is always included (parameter ``"none"``).
    variant : str, default "default"
        A key of :data:`VARIANTS`.
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
        mode ``{mode: max-info}`` (see :class:`EnergyReport`).
    """
    import brdf

    presets = tuple(brdf.PRESETS if presets is None else presets)
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
        base = brdf.fabric(name, **VARIANTS[variant])
        white = _white(base.threads)
        entries = [("none", None)] + [(k, v) for k, vals in scan.items() for v in vals]
        for param, val in entries:
            if param == "none":
                threads = white
            elif param == "gamma_s":
                threads = tuple(t.replace(gamma_s=val, gamma_v=2 * val) for t in white)
            else:
                threads = tuple(t.replace(**{param: val}) for t in white)
            fab = base.replace(threads=threads)
            configs.append({"curves": name, "parameter": param, "value": val,
                            "variant": variant})
            for mode in modes:
                tasks.append((fab, dirs, {"swap": MODES[mode], "tol": tol,
                                          "min_level": min_level}))
    res = run_tasks(tasks, workers, progress=progress)
    out, k = [], 0
    for cfg in configs:
        for mode in modes:
            v, e, _ = res[k]
            k += 1
            cfg[mode] = _max_info(th, ph, v.reshape(th.size, ph.size, 3),
                                  e.reshape(th.size, ph.size, 3))
        out.append(cfg)
    return out


def _fmt(v, e):
    return f"{v:.4f} +- {e:.1e}"


def _statements(curves, furnace, modes) -> list[str]:
    lines = []
    for mode in modes:
        over = [c for c in curves if c["mode"] == mode and c["max"]["exceeds_one"]]
        maybe = [c for c in curves if c["mode"] == mode and not c["max"]["exceeds_one"]
                 and c["max"]["possibly_exceeds_one"]]
        top = max((c for c in curves if c["mode"] == mode), key=lambda c: c["max"]["value"],
                  default=None)
        if top is None:
            continue
        m = top["max"]
        lines.append(
            f"{mode}: with the presets' own colours, {len(over)} of "
            f"{sum(c['mode'] == mode for c in curves)} (preset, variant) curves exceed 1"
            + (f" ({', '.join(sorted({c['preset'] + '/' + c['variant'] for c in over}))})"
               if over else "")
            + (f"; {len(maybe)} more are within their error bar of 1" if maybe else "")
            + f". Largest: {top['preset']}/{top['variant']} {_fmt(m['value'], m['error'])} at "
            f"theta = {m['theta_deg']:g} deg, phi = {m['phi_deg']:g} deg "
            f"({'RGB'[m['channel']]}).")
    for mode in modes:
        per_variant = {}
        for c in curves:
            if c["mode"] == mode:
                per_variant.setdefault(c["variant"], []).append(c)
        parts = [f"{v}: {sum(c['max']['exceeds_one'] for c in cs)}/{len(cs)} presets above 1"
                 for v, cs in per_variant.items()]
        if parts:
            lines.append(f"  {mode} by variant: " + "; ".join(parts) + ".")
    refl = [c for c in curves if c["mode"] == "reflectance" and c["variant"] == "default"]
    if refl:
        grazing = sum(c["max"]["theta_deg"] >= 80 for c in refl)
        firsts = [f"{c['preset']} {c['first_theta_above_one']:g}" for c in refl
                  if c["first_theta_above_one"] is not None]
        if firsts:
            lines.append("  reflectance of the default variant first exceeds 1 at theta_i "
                         "(degrees, smallest on the grid): " + ", ".join(firsts) + ".")
        lines.append(
            f"  reflectance maxima of the default variant sit at grazing incidence in {grazing} "
            f"of {len(refl)} presets: f_r = (a1 S1 + a2 S2) / (Q n.wi) keeps the 1/(n.wi) "
            "while S_j carries only the longitudinal cosine, so rho'(wi) grows like "
            "1/cos(theta_i) toward the horizon.")
    if furnace:
        for mode in modes:
            rows = [f for f in furnace if mode in f]
            bad = [f for f in rows if f[mode]["exceeds_one"]]
            lines.append(f"white furnace ({mode}, A = 1): {len(bad)} of {len(rows)} "
                         "configurations exceed 1.")
            by_param = {}
            for f in rows:
                by_param.setdefault(f["parameter"], []).append(f)
            for param, fs in by_param.items():
                parts = []
                for val in sorted({f["value"] for f in fs}, key=lambda x: (x is None, x)):
                    group = [f for f in fs if f["value"] == val]
                    nb = [f for f in group if f[mode]["exceeds_one"]]
                    if nb:
                        worst = max(nb, key=lambda f: f[mode]["value"])
                        w = worst[mode]
                        parts.append(
                            f"{'white preset' if param == 'none' else f'{param} = {val:g}'}: "
                            f"{len(nb)}/{len(group)} presets' curves "
                            f"(max {w['value']:.3f} for {worst['curves']} at theta = "
                            f"{w['theta_deg']:g}, phi = {w['phi_deg']:g})")
                if parts:
                    lines.append(f"  {mode}, {param}: " + "; ".join(parts) + ".")
                else:
                    lines.append(f"  {mode}, {param}: no violation over "
                                 f"{', '.join(str(f['value']) for f in fs[:len(fs)])}.")
            if bad:
                w = max(bad, key=lambda f: f[mode]["value"])
                lines.append(
                    f"  largest {mode} albedo in the scan: {w[mode]['value']:.3f} "
                    f"(+{w[mode]['value'] - 1:.3f} above 1) for the curves of {w['curves']}, "
                    f"{w['parameter']} = {w['value']}, at theta = {w[mode]['theta_deg']:g} deg, "
                    f"phi = {w[mode]['phi_deg']:g} deg.")
    return lines


def energy_report(presets=None, variants=None, *, theta_deg=DEFAULT_THETA, phi_deg=(0.0, 90.0),
                  modes=("furnace", "reflectance"), tol: float = 1e-3, min_level: int = -1,
                  hemispherical: bool = True, furnace: bool = True, scan=None,
                  scan_theta_deg=SCAN_THETA, scan_phi_deg=SCAN_PHI, workers=None,
                  progress: bool = False) -> EnergyReport:
    """Albedo curves per preset and variant, the white-furnace scan, and plain findings.

    Parameters
    ----------
    presets : sequence of str, optional
        Preset names (default: all of ``brdf.PRESETS``).
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

    Raises
    ------
    ValueError
        Unknown preset, variant or mode.
    """
    import brdf

    t0 = time.perf_counter()
    presets = tuple(brdf.PRESETS if presets is None else presets)
    variants = tuple(VARIANTS if variants is None else variants)
    for p in presets:
        if p not in brdf.PRESETS:
            raise ValueError(f"unknown fabric {p!r}; presets: {', '.join(brdf.PRESETS)}")
    for v in variants:
        if v not in VARIANTS:
            raise ValueError(f"unknown variant {v!r}; variants: {', '.join(VARIANTS)}")
    for m in modes:
        if m not in MODES:
            raise ValueError(f"unknown mode {m!r}; modes: {', '.join(MODES)}")
    th = np.atleast_1d(np.asarray(theta_deg, float))
    ph = np.atleast_1d(np.asarray(phi_deg, float))
    dirs = directions_grid(th, ph).reshape(-1, 3)
    scan = FURNACE_SCAN if scan is None else scan
    n_scan = (len(presets) * (1 + sum(len(v) for v in scan.values())) * len(modes)
              * len(scan_theta_deg) * len(scan_phi_deg)) if furnace else 0
    total = len(presets) * len(variants) * len(modes) * dirs.shape[0] + n_scan \
        + (len(presets) * 60 if hemispherical else 0)
    bar = progress_bar(total, desc="energy", unit="albedo", enabled=progress)
    tick = bar.update if progress else None
    try:
        keys, tasks = [], []
        for p, v, m in itertools.product(presets, variants, modes):
            fab = brdf.fabric(p, **VARIANTS[v])
            keys.append((p, v, m))
            tasks.append((fab, dirs, {"swap": MODES[m], "tol": tol, "min_level": min_level}))
        res = run_tasks(tasks, workers, progress=tick)
        curves = []
        for (p, v, m), (val, err, _) in zip(keys, res):
            val = val.reshape(th.size, ph.size, 3)
            err = err.reshape(th.size, ph.size, 3)
            info = _max_info(th, ph, val, err)
            curves.append({
                "preset": p, "variant": v, "options": dict(VARIANTS[v]), "mode": m,
                "theta_deg": th.tolist(), "phi_deg": ph.tolist(), "value": val.tolist(),
                "error": err.tolist(), "max": info,
                "exceeds_one": info["exceeds_one"],
                "possibly_exceeds_one": info["possibly_exceeds_one"],
                "first_theta_above_one": (float(th[np.any(val - err > 1, axis=(1, 2))][0])
                                          if info["exceeds_one"] else None),
            })
        hemi = []
        if hemispherical:
            for p in presets:
                h = albedo_hemispherical(brdf.fabric(p), n_theta=6, n_phi=8, tol=tol,
                                         min_level=min_level, workers=workers)
                hemi.append({"preset": p, "variant": "default", **h.to_dict()})
                if tick:
                    tick(60)
        scan_rows = []
        if furnace:
            scan_rows = white_furnace(presets, scan=scan, theta_deg=scan_theta_deg,
                                      phi_deg=scan_phi_deg, modes=modes, workers=workers,
                                      min_level=min_level, progress=tick)
    finally:
        if bar is not None:
            bar.close()
    settings = {
        "theta_deg": th.tolist(), "phi_deg": ph.tolist(), "modes": list(modes),
        "variants": {v: VARIANTS[v] for v in variants}, "presets": list(presets), "tol": tol,
        "furnace_scan": {k: list(v) for k, v in scan.items()} if furnace else None,
        "scan_theta_deg": list(scan_theta_deg), "scan_phi_deg": list(scan_phi_deg),
        "definitions": {
            "furnace": "rho(wo) = integral f_r(wi, wo) cos(theta_i) dwi; theta, phi of wo",
            "reflectance": "rho'(wi) = integral f_r(wi, wo) cos(theta_o) dwo; theta, phi of wi",
            "exceeds_one": "value - error > 1 somewhere on the grid",
        },
    }
    return EnergyReport(settings=settings, curves=curves, hemispherical=hemi, furnace=scan_rows,
                        statements=_statements(curves, scan_rows, modes),
                        seconds=time.perf_counter() - t0)
