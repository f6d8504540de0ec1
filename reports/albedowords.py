"""The directional albedos in words: whether each exceeds 1, its range, the energy verdict
and the report's overview sentence (re-exported by :mod:`reports.prose`).

analysis computes the albedos (:mod:`analysis.albedo`); the report's energy section, its
overview and its cards quote these sentences.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ALBEDO_KINDS", "albedo_exceeds", "albedo_range", "albedo_sentence",
           "energy_verdict", "overview_sentence"]

#: The two directional albedos: name, symbol and the angle they are a function of.
ALBEDO_KINDS = {
    "furnace": ("furnace albedo", "ρ(wo) = ∫ f_r cos θi dwi", "θo"),
    "reflectance": ("directional reflectance", "ρ'(wi) = ∫ f_r cos θo dwo", "θi"),
}


def albedo_exceeds(theta_deg, value, error) -> dict:
    """Where a directional albedo exceeds 1 by more than its error bound, and how much.

    Parameters
    ----------
    theta_deg : array_like, shape (T,)
        Polar angles of the fixed direction, degrees.
    value, error : array_like, shape (T, ...)
        The albedo (any trailing axes: azimuths, channels) and its error bound.

    Returns
    -------
    dict
        ``exceeds`` (bool), ``thetas`` (the angles where some value - error > 1),
        ``first`` (the smallest of them or None), ``onward`` (every angle from ``first`` on
        exceeds), ``max``, ``max_error`` and ``max_theta`` (the largest value, any angle),
        ``min`` (the smallest value) and ``within_error`` (value + error > 1 somewhere, but
        value - error > 1 nowhere).

    Examples
    --------
    >>> d = albedo_exceeds([0, 45, 80, 85], [[0.5], [0.9], [1.2], [1.5]], [[0.01]] * 4)
    >>> d["first"], d["onward"], d["max"], d["max_theta"]
    (80.0, True, 1.5, 85.0)
    """
    th = np.asarray(theta_deg, dtype=np.float64).ravel()
    v = np.asarray(value, dtype=np.float64).reshape(th.size, -1)
    e = np.asarray(error, dtype=np.float64).reshape(th.size, -1)
    over = np.any(v - e > 1.0, axis=1)
    k = np.unravel_index(int(np.argmax(v)), v.shape)
    first = int(np.argmax(over)) if over.any() else None
    return {"exceeds": bool(over.any()), "thetas": th[over].tolist(),
            "first": None if first is None else float(th[first]),
            "onward": bool(first is not None and over[first:].all()),
            "max": float(v[k]), "max_error": float(e[k]), "max_theta": float(th[k[0]]),
            "min": float(np.min(v)),
            "within_error": bool(not over.any() and np.any(v + e > 1.0))}


def albedo_range(value) -> str:
    """``min–max`` of an albedo (every direction and channel) to three decimals.

    Examples
    --------
    >>> albedo_range([[0.1234, 0.5], [0.9, 4.567]])
    '0.123–4.567'
    """
    v = np.asarray(value, dtype=np.float64)
    return f"{np.min(v):.3f}–{np.max(v):.3f}"


def albedo_sentence(kind: str, theta_deg, value, error) -> str:
    """One sentence on whether a directional albedo exceeds 1: where from and how much.

    Parameters
    ----------
    kind : {"furnace", "reflectance"}
        Which albedo (:data:`ALBEDO_KINDS`).
    theta_deg, value, error
        As in :func:`albedo_exceeds`.

    Examples
    --------
    >>> albedo_sentence("reflectance", [0, 60, 85], [[0.5], [1.1], [4.6]], [[1e-3]] * 3)
    "The directional reflectance ρ'(wi) exceeds 1 from θi = 60°, up to 4.600 at θi = 85°."
    >>> albedo_sentence("furnace", [0, 60], [[0.5], [0.8]], [[1e-3]] * 2)
    'The furnace albedo ρ(wo) stays at or below 1 within its error bound at every θo on the grid (0–60°): at most 0.800 ± 1.0e-03, at θo = 60°.'
    """
    name, symbol, angle = ALBEDO_KINDS[kind]
    d = albedo_exceeds(theta_deg, value, error)
    symbol = symbol.split(" = ")[0]
    th = np.asarray(theta_deg, dtype=np.float64)
    top = f"{d['max']:.3f} at {angle} = {d['max_theta']:g}°"
    if d["exceeds"]:
        where = (f"from {angle} = {d['first']:g}°" if d["onward"] else
                 f"at {len(d['thetas'])} of the {th.size} angles {angle} on the grid, the "
                 f"first {d['first']:g}°")
        return f"The {name} {symbol} exceeds 1 {where}, up to {top}."
    if d["within_error"]:
        return (f"The {name} {symbol} comes within its error bound of 1 (at most "
                f"{d['max']:.3f} ± {d['max_error']:.1e}, at {angle} = {d['max_theta']:g}°) "
                "but does not exceed it beyond the error.")
    return (f"The {name} {symbol} stays at or below 1 within its error bound at every {angle} "
            f"on the grid ({th.min():g}–{th.max():g}°): at most {d['max']:.3f} ± "
            f"{d['max_error']:.1e}, at {angle} = {d['max_theta']:g}°.")


def energy_verdict(furnace: dict, reflectance: dict | None) -> str:
    """A short verdict from :func:`albedo_exceeds` of the two albedos (reflectance optional).

    Examples
    --------
    >>> ok = {"exceeds": False, "within_error": False}
    >>> energy_verdict(ok, {"exceeds": True, "first": 60.0, "max": 4.6, "max_theta": 85.0})
    'reflectance exceeds 1 (up to 4.60 at θi = 85°)'
    >>> energy_verdict(ok, ok)
    'both albedos at or below 1'
    """
    parts = []
    for kind, d in (("furnace", furnace), ("reflectance", reflectance)):
        if d is None:
            continue
        if d["exceeds"]:
            parts.append(f"{'furnace albedo' if kind == 'furnace' else kind} exceeds 1 (up to "
                         f"{d['max']:.2f} at {ALBEDO_KINDS[kind][2]} = {d['max_theta']:g}°)")
        elif d["within_error"]:
            parts.append(f"{'furnace albedo' if kind == 'furnace' else kind} within its "
                         "error of 1")
    if parts:
        return "; ".join(parts)
    return "both albedos at or below 1" if reflectance is not None else "albedo at or below 1"


def overview_sentence(findings: dict) -> str:
    """What the albedos of several fabrics show, in one or two sentences.

    Parameters
    ----------
    findings : dict
        Fabric name -> {mode -> :func:`albedo_exceeds` of that albedo}; a fabric without
        energy results maps to an empty dict.

    Examples
    --------
    >>> over = {"exceeds": True, "max": 4.61, "max_theta": 87.0, "first": 60.0}
    >>> ok = {"exceeds": False, "max": 0.8, "max_theta": 0.0, "first": None}
    >>> overview_sentence({"a": {"furnace": ok, "reflectance": over},
    ...                    "b": {"furnace": ok, "reflectance": ok}})
    "The directional reflectance ρ'(wi) exceeds 1 for 1 of 2 fabrics (a up to 4.61 at θi = 87°); the furnace albedo ρ(wo) stays at or below 1 for all 2."
    """
    have = {n: f for n, f in findings.items() if f}
    if not have:
        return "No fabric's albedo was computed (the energy section was not requested)."
    parts = []
    for mode in ("reflectance", "furnace"):
        mine = {n: f[mode] for n, f in have.items() if mode in f}
        if not mine:
            continue
        name, symbol, angle = ALBEDO_KINDS[mode]
        symbol = symbol.split(" = ")[0]
        over = {n: d for n, d in mine.items() if d["exceeds"]}
        if over:
            where = ", ".join(f"{n} up to {d['max']:.3g} at {angle} = {d['max_theta']:g}°"
                              for n, d in over.items())
            parts.append(f"the {name} {symbol} exceeds 1 for {len(over)} of {len(mine)} "
                         f"fabrics ({where})")
        else:
            parts.append(f"the {name} {symbol} stays at or below 1 for all {len(mine)}")
    text = "; ".join(parts) + "."
    return text[0].upper() + text[1:]
