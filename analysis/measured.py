r"""Fits of the model to the measured fabrics of ``../shared/data``: which tables, which preset
each starts from, which parameters are free.

Nine datasets: the three RGL acrylic felts (absolute f_r in 1/sr, RGB) and six CUReT fabric
samples (relative reflectance, grey: a free ``scale``). Neither kind has per-value sigma, so a
``log_noise`` parameter is added by :func:`analysis.fit.fit`.

Choices, all physically motivated and stated in the report:

- **Start preset.** The closest fabric of the paper: ``linen_plain`` (a matte staple-fibre
  weave) for felt, linen and cotton; ``velvet`` for velvet and corduroy (both cut piles);
  ``polyester_satin_charmeuse`` for polyester. The preset fixes the tangent curves and the
  values of the parameters that are not free.
- **Free parameters.** One set of optical parameters shared by both threads (the two threads
  of a felt or of a grey measurement cannot be told apart): ``eta1``, ``kd1``, ``gamma_s1``,
  ``gamma_v1``, ``area1`` (``area2 = 1 - area1``), and for the RGB felts the albedo
  ``albedo1_r/g/b``; thread 2 is tied to thread 1. CUReT is grey and relative, so its albedo
  cannot be separated from the free scale and stays at the preset's.
- **Tables.** RGL: the tensor file evaluated (:func:`gonio.load_rgl`) at its own incidence
  nodes below 90 degrees and outgoing directions every ``rgl_step`` degrees (default 15:
  the felts' f_r is smooth at that scale, and the time of a fit grows in proportion to the
  pairs). The felt files are isotropic, stored for one incidence azimuth and mirrored about
  the plane of incidence, so only outgoing azimuths in [0, 180] degrees are kept, and each
  direction pair once (at theta_o = 0 every azimuth names the same pair): 462 pairs of the
  1008. The mirrored half and the repeats are the same measurements and would count each
  several times, making the intervals too narrow. CUReT: the 205 configurations as measured.

Examples
--------
>>> sorted(MEASURED)[:3]
['curet_01_felt', 'curet_02_polyester', 'curet_07_velvet']
>>> MEASURED["rgl_white_felt"].preset
'linen_plain'
"""

from __future__ import annotations

import dataclasses
import functools
import json
import os
from pathlib import Path

import numpy as np

from analysis.fit.results import read_results
from analysis.fit.swap import with_symmetries
from analysis.folderlock import output_lock
from analysis.families import MICROCYLINDER
from analysis.lazy import lazy_module
from analysis.measuredjson import load_measured_json
from analysis.measuredmodels import fit_folder, models_entry, parse_models, verdict_warnings
from analysis.params import ParamSpec, defaults_from_fabric
from brdf.presets import fabric as preset_fabric
from gonio import atomic_write, meta_text, plain
from gonio.curet import N_SAMPLES, read_curet
from gonio.io import read
from gonio.rgl import load_rgl

__all__ = ["MeasuredDataset", "MEASURED", "load_measured", "measured_spec", "default_data_dir",
           "fit_measured", "SUMMARY_FILE", "curet_sample"]

#: The batch (the fit, Dask), on use: a reader of a dataset's name does not load them.
batch = lazy_module("analysis.batch")

#: The summary written beside the per-dataset folders by :func:`fit_measured`.
SUMMARY_FILE = "measured.json"

_SHARED_FREE = ("eta1", "kd1", "gamma_s1", "gamma_v1", "area1")
_SHARED_TIES = ("eta2=eta1", "kd2=kd1", "gamma_s2=gamma_s1", "gamma_v2=gamma_v1",
                "area2=1-area1")
_ALBEDO_TIES = ("albedo2_r=albedo1_r", "albedo2_g=albedo1_g", "albedo2_b=albedo1_b")


@dataclasses.dataclass(frozen=True)
class MeasuredDataset:
    """One measured table and how it is fitted.

    Attributes
    ----------
    name : str
        Key, also the name of its output folder.
    title : str
        Human-readable description (material and source).
    kind : {"rgl", "curet"}
        Reader.
    path : str
        Path relative to the data folder (``../shared/data``).
    sample : int or None
        CUReT sample number.
    preset : str
        Preset giving the tangent curves, fixed values and start.
    free, ties : tuple of str
        Free parameters and ties (:class:`analysis.params.ParamSpec` syntax).
    """

    name: str
    title: str
    kind: str
    path: str
    sample: int | None
    preset: str
    free: tuple[str, ...]
    ties: tuple[str, ...]


def _rgl(colour: str) -> MeasuredDataset:
    return MeasuredDataset(
        f"rgl_{colour}_felt", f"RGL acrylic felt, {colour} (Dupuy and Jakob 2018)", "rgl",
        f"rgl/acrylic_felt_{colour}_rgb.bsdf", None, "linen_plain",
        _SHARED_FREE + ("albedo1_r", "albedo1_g", "albedo1_b"), _SHARED_TIES + _ALBEDO_TIES)


def _curet(sample: int, what: str, preset: str) -> MeasuredDataset:
    return MeasuredDataset(
        f"curet_{sample:02d}_{what}", f"CUReT sample {sample}, {what} (Dana et al. 1999)",
        "curet", "curet/abrdf.dat", sample, preset, _SHARED_FREE + ("rotation",), _SHARED_TIES)


#: The measured datasets by name.
MEASURED: dict[str, MeasuredDataset] = {d.name: d for d in (
    _rgl("white"), _rgl("pink"), _rgl("purple"),
    _curet(1, "felt", "linen_plain"), _curet(2, "polyester", "polyester_satin_charmeuse"),
    _curet(7, "velvet", "velvet"), _curet(42, "corduroy", "velvet"),
    _curet(44, "linen", "linen_plain"), _curet(46, "cotton", "linen_plain"),
)}


def curet_sample(text) -> int:
    """A CUReT sample number from what a user gives for one: the number (``7``, ``"07"``) or
    the name of a CUReT dataset of :data:`MEASURED` (``"curet_07_velvet"``, the name
    ``fit-measured`` prints).

    Examples
    --------
    >>> curet_sample("curet_07_velvet"), curet_sample("7"), curet_sample(42)
    (7, 7, 42)
    """
    key = str(text).strip()
    d = MEASURED.get(key.lower())
    if d is not None and d.sample is not None:
        return d.sample
    try:
        n = int(key)
    except ValueError:
        n = None
    if n is None or not 1 <= n <= N_SAMPLES or isinstance(text, bool):
        names = ", ".join(k for k, v in MEASURED.items() if v.sample is not None)
        raise ValueError(f"CUReT sample {key!r}: must be a number in 1..{N_SAMPLES} or one "
                         f"of {names}")
    return n


def default_data_dir() -> Path:
    """The measured-data folder: ``$MICROCYL_DATA``, else ``shared/data`` beside this source
    tree (``../shared/data`` from the repository). The command line also looks beside the
    current folder (:func:`reports.cli.options.data_dir`)."""
    env = os.environ.get("MICROCYL_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[2] / "shared" / "data"


def _dataset(name) -> MeasuredDataset:
    if isinstance(name, MeasuredDataset):
        return name
    if name not in MEASURED:
        raise ValueError(f"unknown measured dataset {name!r}; valid: {', '.join(MEASURED)}")
    return MEASURED[name]


def load_measured(name, data_dir=None, rgl_step: float = 15.0):
    """The table of a measured dataset.

    Parameters
    ----------
    name : str or MeasuredDataset
        A key of :data:`MEASURED`.
    data_dir : path, optional
        The data folder (default :func:`default_data_dir`).
    rgl_step : float
        Outgoing-direction step for sampling an RGL file, degrees (> 0).

    Returns
    -------
    gonio.Table

    Raises
    ------
    ValueError
        Unknown name or bad step.
    FileNotFoundError
        The data file is missing.
    """
    d = _dataset(name)
    if not (rgl_step > 0):
        raise ValueError(f"rgl_step must be > 0 degrees; got {rgl_step}")
    root = Path(data_dir) if data_dir is not None else default_data_dir()
    path = root / d.path
    if not path.exists():
        raise FileNotFoundError(2, f"measured data for {d.name} not found (give the data "
                                   f"folder, or set MICROCYL_DATA)", str(path))
    if d.kind == "rgl":
        table = read(path, step=float(rgl_step))
        if load_rgl(path).isotropic:
            # one incidence azimuth (0) and a mirror-symmetric file: keep phi_o in [0, pi]
            keep = np.flatnonzero(table.wo[:, 1] >= -1e-9)
            # and each direction pair once (at theta_o = 0 every azimuth is the same pair)
            key = np.round(np.concatenate([table.wi[keep], table.wo[keep]], axis=1), 9) + 0.0
            keep = np.sort(keep[np.unique(key, axis=0, return_index=True)[1]])
            meta = dict(table.meta, mirror_half="outgoing azimuths in [0, 180] degrees only "
                        "(the file is isotropic: the other half mirrors them), each pair once")
            table = table.replace(wi=table.wi[keep], wo=table.wo[keep],
                                  values=table.values[keep],
                                  sigma=None if table.sigma is None else table.sigma[keep],
                                  meta=meta)
        return table
    return read_curet(path.parent, d.sample)


def measured_spec(name, fab=None):
    """The :class:`~analysis.params.ParamSpec` and start fabric of a measured dataset.

    Returns
    -------
    spec : ParamSpec
    fabric : brdf.Fabric
        The start preset (defaults for every fixed parameter).

    Examples
    --------
    >>> spec, fab = measured_spec("curet_07_velvet")
    >>> spec.free, fab.name
    (('eta1', 'kd1', 'gamma_s1', 'gamma_v1', 'area1', 'rotation'), 'velvet')
    """
    d = _dataset(name)
    fab = fab if fab is not None else preset_fabric(d.preset)
    spec = ParamSpec(d.free, defaults=defaults_from_fabric(fab), ties=d.ties)
    return with_symmetries(spec, fab), fab


def fit_measured(names=None, out_dir="fits", *, data_dir=None, seed: int = 0,
                 max_steps: int = 20000, time_limit: float | None = None,
                 rgl_step: float = 15.0, plots=None, progress: bool = True,
                 echo=None, workers: int | None = None, scheduler: str | None = None,
                 models=None) -> dict:
    """Fit measured datasets as a batch (:func:`analysis.batch.run_batch`); write
    ``out_dir/NAME/``, the batch summaries and ``out_dir/measured.json``.

    Parameters
    ----------
    names : sequence of str, optional
        Keys of :data:`analysis.measured.MEASURED` (default all).
    models : str or sequence of str, optional
        The models fitted to each dataset (:func:`analysis.measuredmodels.parse_models`:
        ``"all"`` or names; default the microcylinder alone). A baseline model's fit goes
        into ``out_dir/NAME-MODEL/``; with models other than the microcylinder alone, each
        dataset's entry gets ``models``, the models ranked by PSIS-LOO
        (:func:`analysis.measuredmodels.models_entry`).
    out_dir : path
        Output folder; existing fits there are resumed, converged ones not redone.
    data_dir : path, optional
        The measured-data folder (default :func:`analysis.measured.default_data_dir`).
    seed, max_steps, time_limit
        Passed to :func:`analysis.fit.fit` (time limit per dataset, seconds).
    rgl_step : float
        Outgoing step for sampling the RGL files, degrees.
    plots : callable, optional
        Draws each fit's plots (see :func:`analysis.fit.fit_fabric`).
    progress : bool
        A progress bar over the datasets.
    echo : callable, optional
        Called with one line per finished dataset.
    workers, scheduler
        The Dask cluster (see :func:`analysis.batch.run_batch`).

    Returns
    -------
    dict
        The ``measured.json`` document: ``{"datasets": {name: {...}}}``; each entry's
        ``wall_s`` is the time of the run that wrote it (a resumed fit counts only its last
        run).

    Raises
    ------
    ValueError
        An unknown dataset name (before any fit).
        A ``measured.json`` in ``out_dir`` that is out of its schema (before any fit).
    FileNotFoundError
        A missing data file (before any fit).
    analysis.folderlock.FolderBusy
        Another run holds ``out_dir``'s lock; this run holds it from the first fit to the
        last write of ``measured.json``.
    """
    names = list(names) if names else list(MEASURED)
    bad = [n for n in names if n not in MEASURED]
    if bad:
        raise ValueError(f"unknown measured dataset {bad[0]!r}; valid: {', '.join(MEASURED)}")
    compare = models is not None and tuple(parse_models(models)) != (MICROCYLINDER,)
    models = parse_models(models)
    root = (Path(data_dir) if data_dir is not None else default_data_dir()).resolve()
    tables = {n: load_measured(n, root, rgl_step=rgl_step) for n in names}
    out = Path(out_dir)
    spath = out / SUMMARY_FILE
    _read_summary(spath)                # a damaged summary is refused before any fit
    fit = {"seed": seed, "max_steps": max_steps, "time_limit": time_limit}
    jobs = [_job(n, root, rgl_step, plots, fit, m) for n in names for m in models]
    with output_lock(out, "fit-measured"):       # the batch's lock, measured.json included
        summary = batch.run_batch(jobs, out, workers=workers, scheduler=scheduler,
                            progress=progress, echo=echo, locked=True)
        # read just before writing: another fit-measured run may have added its datasets
        doc = _read_summary(spath)
        for n in names:
            doc["datasets"][n] = _dataset_entry(n, tables[n], summary.rows, out, models,
                                                compare, doc["datasets"].get(n, {}))
        with atomic_write(spath, "w") as fh:
            # strict JSON: a non-finite number is written null (the schema refuses NaN)
            fh.write(json.dumps(plain(doc, nonfinite="null"), indent=2) + "\n")
    return doc


def _job(n: str, root: Path, rgl_step: float, plots, fit: dict,
         model: str = MICROCYLINDER):
    """The batch job of dataset ``n`` and ``model``: read on the worker by
    :func:`load_measured`; a baseline model with its default free set for the table
    (an :class:`analysis.batch.BatchJob`)."""
    d = MEASURED[n]
    loader = functools.partial(load_measured, n, str(root), rgl_step)
    job = batch.BatchJob
    if model != MICROCYLINDER:
        return job(fit_folder(n, model), str(root / d.path), d.sample, d.preset, fit=fit,
                   loader=loader, plots=plots, model=model,
                   config_extra={"dataset": n, "rgl_step": rgl_step})
    return job(n, str(root / d.path), d.sample, d.preset, d.free, d.ties, fit=fit,
               loader=loader, plots=plots,
               config_extra={"dataset": n, "preset": d.preset, "rgl_step": rgl_step})


def _dataset_entry(n: str, table, rows: dict, out: Path, models, compare: bool,
                   old: dict) -> dict:
    """Dataset ``n``'s new entry: the microcylinder's fields (from this run, else ``old``'s),
    and its ``models`` ranked where several models are or were fitted."""
    if MICROCYLINDER in models:
        entry = _entry(n, table, rows[n], out)
    else:               # the microcylinder's fields stay as an earlier run wrote them
        entry = {**_base_entry(n, table), **old}
    if compare or "models" in old:
        entry.pop("compare_error", None)
        entry.update(models_entry(out, n, models, rows, old.get("models")))
    return entry


def _base_entry(n: str, table) -> dict:
    """What ``measured.json`` says of dataset ``n`` whatever was fitted."""
    d = MEASURED[n]
    return {"title": d.title, "preset": d.preset,
            "source": meta_text(table.meta.get("source", "")), "pairs": len(table)}


def _entry(n: str, table, row: dict, out: Path) -> dict:
    """The ``measured.json`` entry of dataset ``n`` from its batch row and results."""
    d = MEASURED[n]
    entry = {**_base_entry(n, table),
             "free": list(d.free), "ties": list(d.ties), "converged": False,
             "reason": row.get("error") or row.get("reason", ""),
             "steps": row.get("steps", 0), "wall_s": row.get("wall_s"),
             "results": f"{n}/results.json"}
    if row["status"] == "error":
        return dict(entry, error=row["error"], values_used=0, quality={},
                    albedo_delta_e2000=None, loo=None, adequate=None,
                    adequate_reason="the fit failed", warnings=[])
    res = read_results(out / n / "results.json")
    quality = res.get("quality", {})
    return dict(entry, converged=bool(res["converged"]), reason=res["reason"],
                values_used=res.get("fit", {}).get("points", {}).get("used"),
                free=list(res["parameters"]), quality=quality,
                albedo_delta_e2000=quality.get("albedo_delta_e2000"), loo=res.get("loo"),
                adequate=res.get("adequate"),
                adequate_reason=str(res.get("adequate_reason", "not checked")),
                warnings=verdict_warnings(res))


def _read_summary(path: Path) -> dict:
    """The summary document at ``path`` ({"datasets": {}} when missing), read through its
    schema (:func:`analysis.measuredjson.check_measured_doc`: a damaged or hostile one is
    refused with one line naming the file and the field, never silently replaced)."""
    if not path.exists():
        return {"datasets": {}}
    return load_measured_json(path.parent)
