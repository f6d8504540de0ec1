"""The fabric of a fit's posterior medians: what ``microcyl export`` writes for a renderer.

A fit of a baseline model (``microcyl fit --model lambert``) gives that model at its medians
(a :class:`brdf.baselines.BaselineModel`, :attr:`MedianFabric.fabric`) in the same way;
:attr:`MedianFabric.model_name` says which model it is.

A fit folder holds ``results.json`` (each free parameter's median) and ``fit_config.json``
(the preset, the options, the spec: fixed values and ties). :func:`median_fabric` puts them
together: free parameters at their medians, tied ones from their sources, fixed ones at the
values the fit held them at, tangent offsets scaled by ``tangent_scale`` as the fit's model
scales them (clipped to +-90 degrees). :attr:`MedianFabric.model` is what the fit's model
predicts there: that fabric's f_r times the fit's overall ``scale`` (1 unless the table was
relative), as :class:`analysis.fit.LogPosterior` predicts it.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

import brdf
from analysis.families import family
from analysis.fit.checkpoint import CONFIG_FILE, read_config
from analysis.fit.results import read_results
from brdf import schema
from gonio.statefields import MAX_MAGNITUDE, FileFields

__all__ = ["MedianFabric", "median_fabric", "fabric_at", "FitModel"]


@dataclasses.dataclass(frozen=True)
class FitModel:
    """A fit's model at its medians, as a BRDF: ``scale`` times the median fabric's f_r.

    Attributes
    ----------
    fabric : brdf.Fabric or brdf.baselines.BaselineModel
        The median fabric (tangent offsets already scaled by ``tangent_scale``), or the
        median baseline model.
    scale : float
        The fit's overall factor on f_r (its ``scale`` parameter; 1 for absolute data).
    """

    fabric: object
    scale: float = 1.0

    def eval(self, wi, wo) -> np.ndarray:
        """``scale`` x f_r (1/sr, or the fitted table's relative units), shape (..., 3)."""
        f = self.fabric.eval(wi, wo)
        return f if self.scale == 1.0 else f * self.scale


@dataclasses.dataclass(frozen=True)
class MedianFabric:
    """A fit's median fabric.

    Attributes
    ----------
    fabric : brdf.Fabric or brdf.baselines.BaselineModel
        Named after the preset the fit started from, with the fit's options (a fit of a
        baseline model: that model at the medians).
    preset : str or None
        None for a baseline model.
    values : dict
        Every parameter's value (natural units: degrees for gammas): medians of the free
        ones, the rest fixed or tied.
    free : tuple of str
        The fit's free parameters.
    converged : bool or None
        The fit's verdict (``results.json``).
    model_name : str
        The model fitted (``microcylinder`` or a baseline's name).
    """

    fabric: object
    preset: str | None
    values: dict
    free: tuple
    converged: bool | None
    model_name: str = "microcylinder"

    @property
    def is_fabric(self) -> bool:
        """Whether this is a microcylinder fabric (not a baseline model)."""
        return self.model_name == "microcylinder"

    @property
    def scale(self) -> float:
        """The fit's overall factor on f_r (``scale``: fitted for relative data, else 1)."""
        return float(self.values.get("scale", 1.0))

    @property
    def model(self) -> FitModel:
        """What the fit's model predicts at the medians (:class:`FitModel`): the fabric's
        f_r times :attr:`scale`, to compare with the table that was fitted."""
        return FitModel(self.fabric, self.scale)


def _config(folder: Path) -> dict:
    path = folder / CONFIG_FILE
    if not path.is_file():
        raise ValueError(f"{path}: cannot read the fit's configuration (no such file); is "
                         f"{folder} a `microcyl fit` output folder?")
    cfg = read_config(path)["config"]      # every field used here checked, errors named
    spec = cfg["spec"]
    extra = cfg.get("extra", {})   # `microcyl fit` and fit-batch: fabric; fit-measured: preset
    preset = extra.get("fabric")
    return {"preset": extra.get("preset") if preset is None else preset,
            "model": cfg.get("model", "microcylinder"),
            "options": dict(extra.get("options") or {}),
            "params": spec["params"], "ties": spec.get("ties", {}),
            "free": tuple(spec["free"])}


def _check_magnitudes(folder: Path, values: dict, free) -> None:
    """Every value at most :data:`gonio.statefields.MAX_MAGNITUDE` in magnitude (an albedo of
    1e308 is finite but renders inf), naming the file and the field it came from."""
    for n, v in values.items():
        if abs(v) > MAX_MAGNITUDE:
            f, field = ((FileFields(folder / "results.json"), f"parameters.{n}.median")
                        if n in free else (FileFields(folder / CONFIG_FILE),
                                           f"config.spec.params.{n}.default"))
            raise f.error(field, f"a number of magnitude at most {MAX_MAGNITUDE:g}", v)


def median_fabric(fit_dir, preset: str | None = None) -> MedianFabric:
    """The fabric at the posterior medians of the fit in ``fit_dir``.

    Parameters
    ----------
    fit_dir : path
        A ``microcyl fit`` output folder (``results.json`` and ``fit_config.json``).
    preset : str, optional
        The preset that was fitted, when ``fit_config.json`` does not name it.

    Returns
    -------
    MedianFabric

    Raises
    ------
    ValueError
        A missing or corrupt file (named), a preset or parameter the files do not explain, or
        medians that make no valid fabric.
    """
    folder = Path(fit_dir)
    results = read_results(folder / "results.json")
    cfg = _config(folder)
    if preset is not None:
        cfg["preset"] = preset
    try:
        fam = family(cfg["model"])
    except ValueError as exc:
        raise ValueError(f"{folder / CONFIG_FILE}: config.model: {exc}") from None
    if results["model"] != fam.name:
        raise ValueError(f"{folder}: results.json is a fit of model {ascii(results['model'])}"
                         f", {CONFIG_FILE} of {fam.name}")
    if not fam.is_microcylinder:
        return _median_baseline(folder, fam, cfg, results)
    if cfg["preset"] not in brdf.PRESETS:
        raise ValueError(f"{folder / CONFIG_FILE}: cannot tell which preset was fitted "
                         f"({cfg['preset']!r}); name it")
    values = _values(folder, cfg, results)
    fab = _fabric_at(folder, cfg, values)
    return MedianFabric(fab, cfg["preset"], values, cfg["free"], results.get("converged"))


def fabric_at(med: "MedianFabric", fit_dir, values: dict):
    """The fit's model at other parameter values (a posterior draw): ``values`` (natural
    units) replace those of ``med`` (:func:`median_fabric` of ``fit_dir``); a
    :class:`brdf.Fabric`, or the baseline model of a baseline fit.

    Raises
    ------
    ValueError
        Values that make no valid fabric or model.
    """
    folder = Path(fit_dir)
    merged = {**med.values, **{k: float(v) for k, v in values.items()}}
    if not med.is_fabric:
        fam = family(med.model_name)
        try:
            return fam.build(merged)
        except ValueError as exc:
            raise ValueError(f"{folder}: the values make no valid {fam.name} model "
                             f"({exc})") from None
    cfg = {"preset": med.preset, "options": med.fabric.options}
    return _fabric_at(folder, cfg, merged)


def _fabric_at(folder: Path, cfg: dict, values: dict) -> brdf.Fabric:
    """The fabric of the fitted preset with every parameter at ``values``."""
    threads = []
    for j, t in enumerate(brdf.preset_threads(cfg["preset"]), start=1):
        change = {q: values[f"{q}{j}"] for q in schema.SCALAR_PARAMS if f"{q}{j}" in values}
        rgb = [f"albedo{j}_{c}" for c in schema.RGB_CHANNELS]
        if all(k in values for k in rgb):
            change["albedo"] = tuple(values[k] for k in rgb)
        scale = values.get(f"tangent_scale{j}", 1.0)
        if scale != 1.0:
            change["offsets"] = tuple(np.clip(np.asarray(t.offsets) * scale, -90, 90).tolist())
        try:
            threads.append(t.replace(**change))
        except ValueError as exc:
            raise ValueError(f"{folder}: the fit's values make no valid fabric (thread {j}: "
                             f"{exc})") from None
    try:
        return brdf.Fabric(threads, name=cfg["preset"], **cfg["options"])
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{folder / CONFIG_FILE}: config.extra.options: {exc}") from None


def _values(folder: Path, cfg: dict, results: dict) -> dict:
    """Every parameter's value: medians of the free ones, fixed ones at their defaults,
    tied ones from their sources."""
    medians = results.get("parameters", {})
    values = {name: float(p["default"]) for name, p in cfg["params"].items()}
    missing = [n for n in cfg["free"] if n not in medians]
    if missing:
        raise ValueError(f"{folder / 'results.json'}: no median for free parameter(s) "
                         f"{', '.join(missing)}")
    values.update({n: float(medians[n]["median"]) for n in cfg["free"]})
    _check_magnitudes(folder, values, cfg["free"])
    for target, (source, kind) in cfg["ties"].items():
        values[target] = values[source] if kind == "equal" else 1.0 - values[source]
    return values


def _median_baseline(folder: Path, fam, cfg: dict, results: dict) -> MedianFabric:
    """A baseline model's fit at its medians."""
    missing = [n for n in fam.model_names if n not in cfg["params"]]
    if missing:
        raise ValueError(f"{folder / CONFIG_FILE}: config.spec.params: no value of "
                         f"{', '.join(missing)} (parameters of model {fam.name})")
    values = _values(folder, cfg, results)
    try:
        model = fam.build(values)
    except ValueError as exc:
        raise ValueError(f"{folder}: the fit's values make no valid {fam.name} model "
                         f"({exc})") from None
    return MedianFabric(model, None, values, cfg["free"], results.get("converged"), fam.name)
