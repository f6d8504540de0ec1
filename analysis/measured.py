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
import json
import os
import time
from pathlib import Path

import numpy as np

import analysis.fit
from analysis.params import ParamSpec, defaults_from_fabric
from brdf.presets import fabric as preset_fabric
from gonio import atomic_write
from gonio.curet import read_curet
from gonio.io import read
from gonio.rgl import load_rgl

__all__ = ["MeasuredDataset", "MEASURED", "load_measured", "measured_spec", "default_data_dir",
           "fit_measured", "SUMMARY_FILE"]

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
        "curet", "curet/abrdf.dat", sample, preset, _SHARED_FREE, _SHARED_TIES)


#: The measured datasets by name.
MEASURED: dict[str, MeasuredDataset] = {d.name: d for d in (
    _rgl("white"), _rgl("pink"), _rgl("purple"),
    _curet(1, "felt", "linen_plain"), _curet(2, "polyester", "polyester_satin_charmeuse"),
    _curet(7, "velvet", "velvet"), _curet(42, "corduroy", "velvet"),
    _curet(44, "linen", "linen_plain"), _curet(46, "cotton", "linen_plain"),
)}


def default_data_dir() -> Path:
    """The measured-data folder: ``$MICROCYL_DATA``, else ``../shared/data`` from the current
    folder, else the same beside this source tree's parent."""
    env = os.environ.get("MICROCYL_DATA")
    if env:
        return Path(env)
    here = Path.cwd() / ".." / "shared" / "data"
    if here.is_dir():
        return here.resolve()
    return (Path(__file__).resolve().parents[2] / "shared" / "data")


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
        raise FileNotFoundError(2, f"measured data for {d.name} not found (set --data or "
                                   f"MICROCYL_DATA)", str(path))
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
    (('eta1', 'kd1', 'gamma_s1', 'gamma_v1', 'area1'), 'velvet')
    """
    d = _dataset(name)
    fab = fab if fab is not None else preset_fabric(d.preset)
    return ParamSpec(d.free, defaults=defaults_from_fabric(fab), ties=d.ties), fab


def fit_measured(names=None, out_dir="fits", *, data_dir=None, seed: int = 0,
                 max_steps: int = 20000, time_limit: float | None = None,
                 rgl_step: float = 15.0, plots=None, progress: bool = True,
                 echo=None) -> dict:
    """Fit measured datasets; write ``out_dir/NAME/`` and ``out_dir/measured.json``.

    Parameters
    ----------
    names : sequence of str, optional
        Keys of :data:`analysis.measured.MEASURED` (default all).
    out_dir : path
        Output folder; existing fits there are resumed.
    data_dir : path, optional
        The measured-data folder (default :func:`analysis.measured.default_data_dir`).
    seed, max_steps, time_limit
        Passed to :func:`analysis.fit.fit` (time limit per dataset, seconds).
    rgl_step : float
        Outgoing step for sampling the RGL files, degrees.
    plots : callable, optional
        Draws each fit's plots (see :func:`analysis.fit.fit_fabric`).
    progress : bool
        A progress bar per fit.
    echo : callable, optional
        Called with one line per finished dataset.

    Returns
    -------
    dict
        The ``measured.json`` document: ``{"datasets": {name: {...}}}``; each entry's
        ``wall_s`` is the time of the run that wrote it (a resumed fit counts only its last
        run, a finished one only the re-summary).

    Raises
    ------
    ValueError
        An unknown dataset name (before any fit).
    FileNotFoundError
        A missing data file (before any fit).
    """
    names = list(names) if names else list(MEASURED)
    bad = [n for n in names if n not in MEASURED]
    if bad:
        raise ValueError(f"unknown measured dataset {bad[0]!r}; valid: {', '.join(MEASURED)}")
    tables = {n: load_measured(n, data_dir, rgl_step=rgl_step) for n in names}
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    spath = out / SUMMARY_FILE
    for n in names:
        entry, result = _fit_one(n, tables[n], out, plots=plots, seed=seed,
                                 max_steps=max_steps, time_limit=time_limit,
                                 progress=progress, rgl_step=rgl_step)
        # read just before writing: another fit-measured run may have added its datasets
        doc = _read_summary(spath)
        doc["datasets"][n] = entry
        with atomic_write(spath, "w") as fh:
            fh.write(json.dumps(doc, indent=2) + "\n")
        if echo is not None:
            echo(_echo_line(n, entry, result))
    return doc


def _fit_one(n: str, table, out: Path, *, plots, seed, max_steps, time_limit, progress,
             rgl_step) -> tuple[dict, object]:
    """Fit dataset ``n`` into ``out/n``: its summary entry and the :class:`FitResult`."""
    d = MEASURED[n]
    spec, fab = measured_spec(n)
    t0 = time.perf_counter()
    result = analysis.fit.fit_fabric(  # looked up at call time: tests substitute it
        table, fab, spec, out / n, plots=plots, seed=seed, max_steps=max_steps,
        time_limit=time_limit, progress=progress,
        config_extra={"dataset": n, "preset": d.preset, "rgl_step": rgl_step})
    entry = {
        "title": d.title, "preset": d.preset, "source": str(table.meta.get("source", "")),
        "pairs": len(table), "values_used": result.counts["used"],
        "free": list(result.names), "ties": list(d.ties),
        "converged": bool(result.converged), "reason": result.reason,
        "steps": result.steps, "wall_s": round(time.perf_counter() - t0, 2),
        "quality": result.quality,
        "albedo_delta_e2000": result.quality.get("albedo_delta_e2000"),
        "results": f"{n}/results.json",
    }
    return entry, result


def _echo_line(n: str, entry: dict, result) -> str:
    """The line :func:`fit_measured` prints for a finished dataset."""
    return (f"{n}: {'converged' if result.converged else 'NOT converged'} after "
            f"{result.steps} steps (this run {entry['wall_s']:.0f} s); residual rms "
            f"{entry['quality']['rms_residual']:.3f}"
            + (f", albedo CIEDE2000 {entry['albedo_delta_e2000']:.1f}"
               if entry["albedo_delta_e2000"] is not None else "")
            + (f"; resumed from step {result.timing['resumed_from']}"
               if result.timing.get("resumed_from") else ""))


def _read_summary(path: Path) -> dict:
    """The summary document at ``path`` ({"datasets": {}} when missing or unreadable)."""
    try:
        doc = json.loads(path.read_text()) if path.exists() else {}
    except ValueError:
        doc = {}
    if not isinstance(doc, dict):
        doc = {}
    doc.setdefault("datasets", {})
    return doc
