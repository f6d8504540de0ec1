"""The workflows of the physical-plausibility verbs (``microcyl energy``, ``reciprocity`` and
``sanity``): each report computed (:mod:`analysis.energy`, :mod:`analysis.reciprocity`,
:mod:`analysis.sanity`), made a JSON document with its findings and written, when asked, to a
JSON file checked before any work (atomically; NaN and infinities as null).

The findings in words come from the caller (``statements``, :mod:`reports.prose` for the
command line), as analysis does not write prose.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Callable, Iterable

import numpy as np

import analysis.sanity
import gonio
from analysis.energy import energy_report
from analysis.reciprocity import reciprocity_report
from gonio.atomic import atomic_write
from gonio.jsonplain import plain

__all__ = ["FELTS", "theta_sweep", "check_json_target", "write_json", "document",
           "energy_document", "measured_felts", "reciprocity_document", "sanity_results"]

#: The RGL acrylic felts that ``microcyl reciprocity`` shows as a measured contrast (files of
#: the data folder's ``rgl/``).
FELTS = ("acrylic_felt_white_rgb.bsdf", "acrylic_felt_pink_rgb.bsdf",
         "acrylic_felt_purple_rgb.bsdf")


def theta_sweep(step_deg: float) -> list[float]:
    """The polar angles of ``microcyl energy``'s albedo sweep, degrees: 0 to 89 by
    ``step_deg``, with 85 and 89 always added (the grazing angles where albedos grow).

    Examples
    --------
    >>> theta_sweep(45)
    [0.0, 45.0, 85.0, 89.0]
    >>> theta_sweep(30)
    [0.0, 30.0, 60.0, 85.0, 89.0]
    """
    grid = np.arange(0.0, 89.0 + 1e-9, step_deg).round(9).tolist()
    return sorted(set(grid) | {85.0, 89.0})


def check_json_target(path, option: str = "--json") -> Path | None:
    """``path`` as a Path when its folder exists and is writable (None for None); an OSError
    naming ``option`` and the folder otherwise, before any work.

    Examples
    --------
    >>> check_json_target("/no/such/folder/r.json")
    Traceback (most recent call last):
    ...
    OSError: --json: folder '/no/such/folder' does not exist
    """
    if path is None:
        return None
    p = Path(path)
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise OSError(f"{option}: folder {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK):
        raise OSError(f"{option}: folder {str(parent)!r} is not writable")
    return p


def write_json(path, data) -> None:
    """Write ``data`` as indented strict JSON (NaN and inf as null,
    :func:`gonio.jsonplain.plain`) through a temporary file renamed into place."""
    with atomic_write(path, "w") as fh:
        json.dump(plain(data, nonfinite="null"), fh, indent=2, allow_nan=False)
        fh.write("\n")


def document(rep, statements: Iterable[str]) -> dict:
    """The JSON document of an energy or reciprocity report: its ``to_dict()`` with the
    findings as ``statements`` before ``seconds``."""
    doc = rep.to_dict()
    seconds = doc.pop("seconds")
    doc["statements"] = list(statements)
    doc["seconds"] = seconds
    return doc


def energy_document(presets, variants, *, theta_step: float, phi_deg, tol: float,
                    hemispherical: bool, furnace: bool, workers=None, progress: bool = False,
                    statements: Callable, json_path=None) -> dict:
    """``microcyl energy``: :func:`analysis.energy.energy_report` over :func:`theta_sweep`
    of ``theta_step`` (degrees) and the azimuths ``phi_deg`` (degrees), its :func:`document`
    with ``statements(report)``, written to ``json_path`` when given (its folder checked
    first: :func:`check_json_target`).

    Returns
    -------
    dict
        The document.
    """
    target = check_json_target(json_path)
    rep = energy_report(presets, variants, theta_deg=theta_sweep(theta_step), phi_deg=phi_deg,
                        tol=tol, hemispherical=hemispherical, furnace=furnace,
                        workers=workers, progress=progress)
    doc = document(rep, statements(rep))
    if target is not None:
        write_json(target, doc)
    return doc


def measured_felts(data_dir) -> tuple[list[Path], list[str]]:
    """The :data:`FELTS` found in ``data_dir/rgl/``, and a note for each one missing.

    Examples
    --------
    >>> felts, notes = measured_felts("/no/such/data")
    >>> felts, len(notes), notes[0]
    ([], 3, 'measured felt /no/such/data/rgl/acrylic_felt_white_rgb.bsdf not found: skipped')
    """
    felts, notes = [], []
    for name in FELTS:
        path = Path(data_dir) / "rgl" / name
        if path.is_file():
            felts.append(path)
        else:
            notes.append(f"measured felt {path} not found: skipped")
    return felts, notes


def reciprocity_document(presets, variants, *, tables=(), n: int, seed: int,
                         grid_step: float, channel: str, data_dir=None, statements: Callable,
                         json_path=None) -> dict:
    """``microcyl reciprocity``: :func:`analysis.reciprocity.reciprocity_report` of the
    fabrics ``presets`` and the measured ``tables`` (``(label, brdf)`` pairs), with the
    :func:`measured_felts` of ``data_dir`` when given, on ``n`` random pairs and a gonio full
    grid of ``grid_step`` degrees (none for 0); its :func:`document` with
    ``statements(report)`` and ``notes`` (the felts missing), written to ``json_path`` when
    given (its folder checked first: :func:`check_json_target`).

    Returns
    -------
    dict
        The document.
    """
    target = check_json_target(json_path)
    geometry = gonio.full_grid(grid_step) if grid_step > 0 else None
    felts, notes = measured_felts(data_dir) if data_dir is not None else ([], [])
    rep = reciprocity_report(presets, variants, n=n, seed=seed, geometry=geometry,
                             felts=list(tables) + felts, channel=channel)
    doc = document(rep, statements(rep))
    doc["notes"] = notes
    if target is not None:
        write_json(target, doc)
    return doc


def sanity_results(fabrics: dict, json_path=None) -> dict:
    """``microcyl sanity``: :func:`analysis.sanity.sanity_scan` of each of ``fabrics``
    (label -> preset name or BRDF), written as ``{label: result.to_dict()}`` to ``json_path``
    when given (its folder checked first: :func:`check_json_target`).

    Returns
    -------
    dict
        Label -> :class:`analysis.sanity.SanityResult`.
    """
    target = check_json_target(json_path)
    results = {label: analysis.sanity.sanity_scan(f) for label, f in fabrics.items()}
    if target is not None:
        write_json(target, {label: r.to_dict() for label, r in results.items()})
    return results
