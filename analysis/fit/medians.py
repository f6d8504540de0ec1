"""The fabric of a fit's posterior medians: what ``microcyl export`` writes for a renderer.

A fit of a baseline model (``microcyl fit --model lambert``) gives that model at its medians
(a registered model of :data:`brdf.MODELS`, :attr:`MedianFabric.fabric`) in the same way;
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
import os
from pathlib import Path

import numpy as np

from analysis.families import family
from analysis.fit.checkpoint import CONFIG_FILE, read_config
from analysis.fit.results import read_results
from brdf.models import DEFAULT_MODEL
from gonio.statefields import MAX_MAGNITUDE, FileFields
from gonio.terminal import shown

__all__ = ["MedianFabric", "median_fabric", "fabric_at", "FitModel"]


@dataclasses.dataclass(frozen=True)
class FitModel:
    """A fit's model at its medians, as a BRDF: ``scale`` times the median fabric's f_r.

    Attributes
    ----------
    fabric : brdf.Model (brdf.Fabric, a baseline)
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
    fabric : brdf.Model (brdf.Fabric, a baseline)
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
        The model fitted (its name in :data:`brdf.MODELS`).
    """

    fabric: object
    preset: str | None
    values: dict
    free: tuple
    converged: bool | None
    model_name: str = DEFAULT_MODEL

    @property
    def is_fabric(self) -> bool:
        """Whether the model has presets (a microcylinder fabric, named after one)."""
        return self.preset is not None

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
    if not os.path.lexists(path):           # a link or a FIFO: read_config names it
        raise ValueError(f"{path}: cannot read the fit's configuration (no such file); is "
                         f"{folder} a `microcyl fit` output folder?")
    cfg = read_config(path)["config"]      # every field used here checked, errors named
    spec = cfg["spec"]
    extra = cfg.get("extra", {})   # `microcyl fit` and fit-batch: fabric; fit-measured: preset
    preset = extra.get("fabric")
    return {"preset": extra.get("preset") if preset is None else preset,
            "model": cfg.get("model", DEFAULT_MODEL),
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
    presets = fam.cls.PRESETS
    if presets and cfg["preset"] not in presets:
        raise ValueError(f"{folder / CONFIG_FILE}: cannot tell which preset was fitted "
                         f"({cfg['preset']!r}); name it")
    missing = [n for n in fam.model_names if n not in cfg["params"]]
    if missing:
        raise ValueError(f"{folder / CONFIG_FILE}: config.spec.params: no value of "
                         f"{', '.join(missing)} (parameters of model {fam.name})")
    values = _values(folder, cfg, results)
    preset = cfg["preset"] if presets else None
    try:
        start = fam.start(preset, cfg["options"])
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{folder / CONFIG_FILE}: config.extra.options: {exc}") from None
    try:
        model = start.with_values({n: values[n] for n in fam.model_names})
    except ValueError as exc:
        raise ValueError(f"{folder}: the fit's values make no valid {fam.name} model "
                         f"({exc})") from None
    return MedianFabric(model, preset, values, cfg["free"], results.get("converged"),
                        fam.name)


def fabric_at(med: "MedianFabric", fit_dir, values: dict):
    """The fit's model at other parameter values (a posterior draw): ``values`` (natural
    units) replace those of ``med`` (:func:`median_fabric` of ``fit_dir``); the model
    (a :class:`brdf.Fabric`, or the baseline of a baseline fit) through the protocol's
    ``with_values``.

    Raises
    ------
    ValueError
        Values that make no valid model.
    """
    merged = {**med.values, **{k: float(v) for k, v in values.items()}}
    fam = family(med.model_name)
    try:
        return med.fabric.with_values({n: merged[n] for n in fam.model_names if n in merged})
    except ValueError as exc:
        raise ValueError(f"{Path(fit_dir)}: the values make no valid {fam.name} model "
                         f"({exc})") from None


def _values(folder: Path, cfg: dict, results: dict) -> dict:
    """Every parameter's value: medians of the free ones, fixed ones at their defaults,
    tied ones from their sources."""
    medians = results.get("parameters", {})
    values = {name: float(p["default"]) for name, p in cfg["params"].items()}
    missing = [n for n in cfg["free"] if n not in medians]
    if missing:
        raise ValueError(f"{folder / 'results.json'}: no median for free parameter(s) "
                         f"{shown(', '.join(missing))}")
    values.update({n: float(medians[n]["median"]) for n in cfg["free"]})
    _check_magnitudes(folder, values, cfg["free"])
    for target, (source, kind) in cfg["ties"].items():
        values[target] = values[source] if kind == "equal" else 1.0 - values[source]
    return values
