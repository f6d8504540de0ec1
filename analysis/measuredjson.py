"""``measured.json`` read through its schema: the summary ``microcyl fit-measured`` writes
beside its per-dataset folders, and ``microcyl report --measured`` reads.

The file may come from someone else (a shared fit folder), so every field a reader uses is
checked here for type and finiteness, every dataset name is a safe file name
(:func:`gonio.safenames.check_component`: it names the dataset's folder, and is refused when
absolute, climbing or hidden), and every ``results`` path resolves inside the folder (links
included). A bad entry is one ``ValueError`` line naming the file and the field.

The document: ``{"datasets": {NAME: ENTRY}}``, each ENTRY (every field optional, as older
versions wrote fewer): ``title``, ``preset``, ``source``, ``reason``, ``error`` (strings),
``pairs``, ``values_used``, ``steps`` (integers >= 0, ``values_used`` and ``pairs`` may be
null), ``converged`` (true/false), ``wall_s`` (a finite number >= 0 or null), ``free`` and
``ties`` (lists of strings), ``quality`` (an object whose ``rms_residual``,
``rms_normalized`` and ``albedo_delta_e2000`` are finite numbers >= 0 or null),
``albedo_delta_e2000`` (the same), ``results`` (the relative path of the dataset's
``results.json``, default ``NAME/results.json``), the fit's verdict: ``adequate`` (true,
false or null), ``adequate_reason`` (a string) and ``warnings`` (a list of objects whose
``kind`` and ``message`` are strings and ``parameters`` a list of strings), and where
several models were fitted (``fit-measured --models``, :mod:`analysis.measuredmodels`)
``models``: an object keyed by model names (safe file names), each with ``results`` (a
relative path, checked like the dataset's), ``converged`` (true/false), ``adequate``,
``adequate_reason`` and ``warnings`` (as the dataset's), ``rank``, ``steps``,
``values_used``, ``n_high_k`` (integers >= 0 or null), ``elpd``, ``d_elpd``, ``d_lag1``
(finite numbers or null; elpd may be negative, d_lag1 is in [-1, 1]), ``se``, ``d_se``,
``d_se_block``, ``pareto_k_max``, ``k_threshold``, ``rms_residual``, ``rms_normalized``,
``wall_s`` (finite numbers >= 0 or null), ``error`` (a string) and ``identifiability`` (a
list of strings); and ``compare_error`` (a string). Files written before the verdict was
kept lack ``adequate``, ``warnings`` and the Pareto k fields: readers take them as unknown. A dataset fitted by baseline models only
has no ``results`` of its own (:func:`has_microcylinder`).
"""

from __future__ import annotations

import math
import os
from pathlib import Path, PurePosixPath

from gonio.safenames import check_component, check_inside
from gonio.statefields import FileFields, load_json

__all__ = ["load_measured_json", "check_measured_doc", "results_path", "has_microcylinder"]

_STRINGS = ("title", "preset", "source", "reason", "error", "adequate_reason")
_COUNTS = ("pairs", "values_used", "steps")
_LISTS = ("free", "ties")
_QUALITY = ("rms_residual", "rms_normalized", "albedo_delta_e2000")


def _bad(path, field: str, allowed: str, value) -> ValueError:
    """The one-line error of :class:`gonio.statefields.FileFields` (names escaped)."""
    return FileFields(path).error(field, allowed, value)


def _number(path, field: str, value) -> None:
    """A finite number >= 0, or null."""
    if value is None:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
            math.isfinite(value) and value >= 0):
        raise _bad(path, field, "a finite number >= 0 or null", value)


def _entry(path, name: str, e) -> None:
    where = f"datasets.{name}"
    if not isinstance(e, dict):
        raise _bad(path, where, "an object", e)
    for k in _STRINGS:
        if k in e and not isinstance(e[k], str):
            raise _bad(path, f"{where}.{k}", "a string", e[k])
    for k in _COUNTS:
        v = e.get(k)
        if v is not None and (isinstance(v, bool) or not isinstance(v, int) or v < 0):
            raise _bad(path, f"{where}.{k}", "an integer >= 0", v)
    for k in _LISTS:
        if k in e and not (isinstance(e[k], list) and all(isinstance(x, str) for x in e[k])):
            raise _bad(path, f"{where}.{k}", "a list of strings", e[k])
    if "converged" in e and not isinstance(e["converged"], bool):
        raise _bad(path, f"{where}.converged", "true or false", e["converged"])
    _verdict(path, where, e)
    _number(path, f"{where}.wall_s", e.get("wall_s"))
    _number(path, f"{where}.albedo_delta_e2000", e.get("albedo_delta_e2000"))
    q = e.get("quality", {})
    if not isinstance(q, dict):
        raise _bad(path, f"{where}.quality", "an object", q)
    for k in _QUALITY:
        _number(path, f"{where}.quality.{k}", q.get(k))
    if "results" in e and not isinstance(e["results"], str):
        raise _bad(path, f"{where}.results", "a relative path (a string)", e["results"])
    if "compare_error" in e and not isinstance(e["compare_error"], str):
        raise _bad(path, f"{where}.compare_error", "a string", e["compare_error"])
    models = e.get("models", {})
    if not isinstance(models, dict):
        raise _bad(path, f"{where}.models", "an object", models)
    for m, me in models.items():
        check_component(m, source=path, entry=f"{where}.models")
        _model(path, f"{where}.models.{m}", me)


def _verdict(path, where: str, e: dict) -> None:
    """A fit's ``adequate``, ``adequate_reason`` and ``warnings`` (each optional)."""
    if e.get("adequate") is not None and not isinstance(e["adequate"], bool):
        raise _bad(path, f"{where}.adequate", "true, false or null", e["adequate"])
    if "adequate_reason" in e and not isinstance(e["adequate_reason"], str):
        raise _bad(path, f"{where}.adequate_reason", "a string", e["adequate_reason"])
    ws = e.get("warnings", [])
    if not isinstance(ws, list):
        raise _bad(path, f"{where}.warnings", "a list", ws)
    for i, w in enumerate(ws):
        ok = (isinstance(w, dict) and all(isinstance(w.get(k, ""), str)
                                          for k in ("kind", "message"))
              and isinstance(w.get("parameters", []), list)
              and all(isinstance(x, str) for x in w.get("parameters", [])))
        if not ok:
            raise _bad(path, f"{where}.warnings[{i}]", "an object of strings (kind, message) "
                       "and a list of strings (parameters)", w)


def _model(path, where: str, e) -> None:
    """One model's entry of a dataset's ``models``."""
    if not isinstance(e, dict):
        raise _bad(path, where, "an object", e)
    for k in ("results", "error"):
        if k in e and not isinstance(e[k], str):
            raise _bad(path, f"{where}.{k}", "a string", e[k])
    if "converged" in e and not isinstance(e["converged"], bool):
        raise _bad(path, f"{where}.converged", "true or false", e["converged"])
    _verdict(path, where, e)
    for k in ("rank", "steps", "values_used", "n_high_k"):
        v = e.get(k)
        if v is not None and (isinstance(v, bool) or not isinstance(v, int) or v < 0):
            raise _bad(path, f"{where}.{k}", "an integer >= 0 or null", v)
    for k in ("se", "d_se", "d_se_block", "pareto_k_max", "k_threshold", "rms_residual",
              "rms_normalized", "wall_s"):
        _number(path, f"{where}.{k}", e.get(k))
    for k in ("elpd", "d_elpd", "d_lag1"):
        v = e.get(k)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))
                              or not math.isfinite(v)):
            raise _bad(path, f"{where}.{k}", "a finite number or null", v)
    ids = e.get("identifiability", [])
    if not (isinstance(ids, list) and all(isinstance(x, str) for x in ids)):
        raise _bad(path, f"{where}.identifiability", "a list of strings", ids)


def has_microcylinder(entry: dict) -> bool:
    """Whether a dataset's entry holds a microcylinder fit of its own (``results``): not
    when only baseline models were fitted to it."""
    return "results" in entry or "microcylinder" in entry.get("models", {}) or \
        "models" not in entry


def check_measured_doc(doc, path) -> dict:
    """``doc`` (a parsed ``measured.json``, read from ``path``) when every field is as the
    module's schema says; else a ValueError naming the file and the field.

    Examples
    --------
    >>> check_measured_doc({"datasets": {"felt": {"steps": 3}}}, "m.json")["datasets"]
    {'felt': {'steps': 3}}
    >>> check_measured_doc({"datasets": {"felt": {"steps": "3"}}}, "m.json")
    Traceback (most recent call last):
    ...
    ValueError: m.json: datasets.felt.steps must be an integer >= 0; got '3'
    """
    if not isinstance(doc, dict) or not isinstance(doc.get("datasets"), dict):
        raise ValueError(f"{path}: not a fit-measured summary (no \"datasets\" object)")
    seen: dict[str, str] = {}
    for name, e in doc["datasets"].items():
        check_component(name, source=path, entry="datasets")
        if name.casefold() in seen:             # one folder on a case-insensitive disk
            raise ValueError(f"{path}: datasets: {name!r} and {seen[name.casefold()]!r} "
                             f"differ only in case; refused")
        seen[name.casefold()] = name
        _entry(path, name, e)
    return doc


def results_path(folder, name: str, entry: dict, source) -> Path:
    """The ``results.json`` of dataset ``name``: ``folder/entry["results"]`` (default
    ``NAME/results.json``), every part a safe name and the whole inside ``folder`` once
    links are resolved; else a ValueError naming ``source`` and the field."""
    rel = entry.get("results", f"{name}/results.json")
    field = f"datasets.{name}.results"
    parts = PurePosixPath(rel).parts if isinstance(rel, str) else ()
    if not parts:
        raise _bad(source, field, "a relative path inside the folder", rel)
    for p in parts:
        check_component(p, source=source, entry=field)
    return check_inside(Path(folder).joinpath(*parts), folder, source=source, entry=field)


def load_measured_json(folder) -> dict:
    """``folder/measured.json``, parsed and checked (:func:`check_measured_doc`).

    Raises
    ------
    ValueError
        Missing (saying how to make it), unreadable, not JSON, or a field out of the schema;
        one line naming the file.
    """
    path = Path(folder) / "measured.json"
    if not os.path.lexists(path):
        raise ValueError(f"{path}: not found; run `microcyl fit-measured -o {folder}` first")
    doc = load_json(path, "fit-measured summary")   # a link, FIFO, huge or deep file: one line
    return check_measured_doc(doc, path)
