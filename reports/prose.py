"""The findings of the physical checks in words: what ``microcyl energy`` and ``microcyl
reciprocity`` print under "Findings" and write as ``statements`` in their JSON.

analysis returns the measurements (:class:`analysis.energy.EnergyReport`,
:class:`analysis.reciprocity.ReciprocityReport`); this module turns them into sentences.
The albedo sentences of the report live in :mod:`reports.albedowords` (re-exported here).
"""

from __future__ import annotations

import numpy as np

from reports.albedowords import (ALBEDO_KINDS, albedo_exceeds, albedo_range,  # noqa: F401
                                 albedo_sentence, energy_verdict, overview_sentence)

__all__ = ["energy_statements", "reciprocity_statements", "ALBEDO_KINDS", "albedo_exceeds",
           "albedo_sentence", "albedo_range", "energy_verdict", "overview_sentence",
           "energy_summary"]


def _fmt(v, e) -> str:
    """An albedo and its error bound: ``0.9876 +- 1.2e-03``."""
    return f"{v:.4f} +- {e:.1e}"


def _energy_maximum(curves, mode) -> list[str]:
    """How many curves of ``mode`` exceed 1, and the largest albedo (one line, or none)."""
    mine = [c for c in curves if c["mode"] == mode]
    if not mine:
        return []
    over = [c for c in mine if c["max"]["exceeds_one"]]
    maybe = [c for c in mine if not c["max"]["exceeds_one"] and c["max"]["possibly_exceeds_one"]]
    top = max(mine, key=lambda c: c["max"]["value"])
    m = top["max"]
    return [f"{mode}: with the presets' own colours, {len(over)} of "
            f"{len(mine)} (preset, variant) curves exceed 1"
            + (f" ({', '.join(sorted({c['preset'] + '/' + c['variant'] for c in over}))})"
               if over else "")
            + (f"; {len(maybe)} more are within their error bar of 1" if maybe else "")
            + f". Largest: {top['preset']}/{top['variant']} {_fmt(m['value'], m['error'])} at "
            f"theta = {m['theta_deg']:g} deg, phi = {m['phi_deg']:g} deg "
            f"({'RGB'[m['channel']]})."]


def _energy_by_variant(curves, mode) -> list[str]:
    """Presets above 1 per variant, for ``mode`` (one indented line, or none)."""
    per_variant = {}
    for c in curves:
        if c["mode"] == mode:
            per_variant.setdefault(c["variant"], []).append(c)
    parts = [f"{v}: {sum(c['max']['exceeds_one'] for c in cs)}/{len(cs)} presets above 1"
             for v, cs in per_variant.items()]
    return [f"  {mode} by variant: " + "; ".join(parts) + "."] if parts else []


def _energy_grazing(curves) -> list[str]:
    """Where the reflectance of the default variant exceeds 1, and why it grows at grazing."""
    refl = [c for c in curves if c["mode"] == "reflectance" and c["variant"] == "default"]
    if not refl:
        return []
    lines = []
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
    return lines


def _furnace_parameter(mode, param, fs) -> str:
    """The white-furnace line of one scanned parameter: its violations per value, or none."""
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
        return f"  {mode}, {param}: " + "; ".join(parts) + "."
    return f"  {mode}, {param}: no violation over {', '.join(str(f['value']) for f in fs)}."


def _furnace(furnace, mode) -> list[str]:
    """The white-furnace lines of ``mode``: the count, each parameter, the largest albedo."""
    rows = [f for f in furnace if mode in f]
    bad = [f for f in rows if f[mode]["exceeds_one"]]
    lines = [f"white furnace ({mode}, A = 1): {len(bad)} of {len(rows)} configurations "
             "exceed 1."]
    by_param = {}
    for f in rows:
        by_param.setdefault(f["parameter"], []).append(f)
    lines += [_furnace_parameter(mode, param, fs) for param, fs in by_param.items()]
    if bad:
        w = max(bad, key=lambda f: f[mode]["value"])
        lines.append(
            f"  largest {mode} albedo in the scan: {w[mode]['value']:.3f} "
            f"(+{w[mode]['value'] - 1:.3f} above 1) for the curves of {w['curves']}, "
            f"{w['parameter']} = {w['value']}, at theta = {w[mode]['theta_deg']:g} deg, "
            f"phi = {w[mode]['phi_deg']:g} deg.")
    return lines


def energy_statements(report) -> list[str]:
    """Plain-language findings of an energy report.

    Parameters
    ----------
    report : analysis.energy.EnergyReport
        The albedo curves, white-furnace rows and settings (``modes``) of
        :func:`analysis.energy.energy_report`.

    Returns
    -------
    list of str
        One finding a line; lines starting with two spaces detail the line before.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> row = {"curves": "velvet", "parameter": "none", "value": None, "variant": "default",
    ...        "furnace": {"value": 0.9, "error": 1e-3, "theta_deg": 0.0, "phi_deg": 0.0,
    ...                    "channel": 0, "exceeds_one": False}}
    >>> rep = SimpleNamespace(settings={"modes": ["furnace"]}, curves=[], furnace=[row])
    >>> energy_statements(rep)
    ['white furnace (furnace, A = 1): 0 of 1 configurations exceed 1.', '  furnace, none: no violation over None.']
    """
    modes = report.settings["modes"]
    curves, furnace = report.curves, report.furnace
    lines = [s for mode in modes for s in _energy_maximum(curves, mode)]
    lines += [s for mode in modes for s in _energy_by_variant(curves, mode)]
    lines += _energy_grazing(curves)
    if furnace:
        lines += [s for mode in modes for s in _furnace(furnace, mode)]
    return lines


def _reciprocity_preset(p, rows) -> list[str]:
    """The line of preset ``p``: its default variant's statistics against the others'."""
    mine = {r["variant"]: r["random"] for r in rows if r["name"] == p}
    if "default" not in mine or mine["default"]["median"] is None:
        return []
    d = mine["default"]
    parts = [f"{p}: median {d['median']:.3f}, p95 {d['p95']:.3f}, max {d['max']:.3f} "
             "(default)"]
    for v, s in mine.items():
        if v != "default" and s["median"] is not None:
            parts.append(f"{v} median {s['median']:.3f} "
                         f"({'lower' if s['median'] < d['median'] else 'not lower'})")
    c = next(r["random_cos_i"] for r in rows if r["name"] == p and r["variant"] == "default")
    if c["median"] is not None:
        parts.append(f"without the 1/(n.wi) factor (f cos theta_i) median "
                     f"{c['median']:.3f}, p95 {c['p95']:.3f}")
    return ["; ".join(parts) + "."]


def reciprocity_statements(report) -> list[str]:
    """Plain-language findings of a reciprocity report.

    Parameters
    ----------
    report : analysis.reciprocity.ReciprocityReport
        The rows and settings (``presets``) of :func:`analysis.reciprocity.reciprocity_report`.

    Returns
    -------
    list of str
        One line per preset (its variants and the cos_i diagnostic beside the default), then
        one per measured BRDF.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> stats = {"median": 0.25, "p95": 0.5, "max": 0.75}
    >>> rows = [{"source": "model", "name": "velvet", "variant": "default", "random": stats,
    ...          "random_cos_i": {"median": None}}]
    >>> reciprocity_statements(SimpleNamespace(settings={"presets": ["velvet"]}, rows=rows))
    ['velvet: median 0.250, p95 0.500, max 0.750 (default).']
    """
    rows = report.rows
    lines = [s for p in report.settings["presets"] for s in _reciprocity_preset(p, rows)]
    for r in rows:
        if r["source"] == "measured" and r["random"]["median"] is not None:
            s = r["random"]
            lines.append(f"measured {r['name']}: median {s['median']:.3f}, p95 {s['p95']:.3f},"
                         f" max {s['max']:.3f} (interpolated table; a contrast, not a model)")
    return lines


def _range_ascii(c) -> str:
    v = np.asarray(c["value"], dtype=np.float64)
    return f"{np.min(v):.3f} - {np.max(v):.3f}"


def energy_summary(report) -> list[str]:
    """The few lines ``microcyl energy`` prints first: per preset (its default variant, or
    the first variant computed) the largest reflectance and where, the furnace albedo's
    range, and a verdict; then one line on the other variants and one on the white furnace.

    Parameters
    ----------
    report : dict
        :meth:`analysis.energy.EnergyReport.to_dict` (or the report itself).

    Returns
    -------
    list of str
        Plain ASCII lines.
    """
    d = report.to_dict() if hasattr(report, "to_dict") else report
    curves = d["curves"]
    variants = list(dict.fromkeys(c["variant"] for c in curves))
    main = "default" if "default" in variants else (variants[0] if variants else None)
    lines = []
    for p in dict.fromkeys(c["preset"] for c in curves):
        mine = {c["mode"]: c for c in curves if c["preset"] == p and c["variant"] == main}
        parts, bad = [], []
        for mode, label, angle in (("reflectance", "reflectance rho'(wi)", "theta_i"),
                                   ("furnace", "furnace albedo rho(wo)", "theta_o")):
            c = mine.get(mode)
            if c is None:
                continue
            m = c["max"]
            parts.append(f"{label} {_range_ascii(c)}, largest {m['value']:.3f} +- "
                         f"{m['error']:.0e} at {angle} = {m['theta_deg']:g}, phi = "
                         f"{m['phi_deg']:g} ({'RGB'[m['channel']]})")
            if c["exceeds_one"]:
                f = albedo_exceeds(c["theta_deg"], c["value"], c["error"])
                start = (f"from {angle} = {f['first']:g} deg" if f["onward"] else
                         f"at {len(f['thetas'])} angles from {angle} = {f['first']:g} deg")
                bad.append(f"{mode} exceeds 1 {start}, up to {m['value']:.3f}")
            elif c["possibly_exceeds_one"]:
                bad.append(f"{mode} within its error bound of 1")
        verdict = ("ENERGY CREATED: " + "; ".join(bad)) if any("exceeds" in b for b in bad) \
            else ("; ".join(bad) if bad else "ok: both albedos at or below 1")
        lines.append(f"{p} ({main}): {verdict}")
        lines += [f"    {s}" for s in parts]
    others = [c for c in curves if c["variant"] != main]
    if others:
        over = sorted({f"{c['preset']}/{c['variant']}/{c['mode']}" for c in others
                       if c["exceeds_one"]})
        lines.append(f"other variants: {len(over)} of {len(others)} curves exceed 1"
                     + (f" ({', '.join(over)})" if over else "") + ".")
    for mode in d["settings"].get("modes", ()):
        rows = [f for f in d.get("furnace") or () if mode in f]
        if rows:
            n = sum(f[mode]["exceeds_one"] for f in rows)
            lines.append(f"white furnace ({mode}, A = 1): {n} of {len(rows)} configurations "
                         "exceed 1.")
    return lines
