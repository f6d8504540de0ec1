"""What ``microcyl explore`` is given: fabrics (presets, exported files), fit folders (their
medians, and their posterior draws for bands) and measured tables (their points, drawn
where they lie), and the overlays computed from them for one incidence and plane.

Examples
--------
>>> loaded = load_inputs(["velvet"])
>>> [(s.label, s.kind) for s in loaded.sources], loaded.tables
([('velvet', 'preset')], [])
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

import brdf
import gonio
from analysis.planning.draws import fit_folder_spec, posterior_draws
from analysis.sources import Source, resolve
from analysis.views.common import reduce_quantity
from analysis.views.lobes import plane_directions
from analysis.views.table import plane_points, reduce_sigma

__all__ = ["Inputs", "Band", "Points", "load_inputs", "object_source", "posterior_values", "lobe_band",
           "lobe_points", "BAND_DRAWS"]

#: Posterior draws a band is computed from.
BAND_DRAWS = 48


@dataclasses.dataclass
class Inputs:
    """The models (``sources``: :class:`analysis.sources.Source`) and the measured tables
    (``tables``: (label, :class:`gonio.Table`)) of the command line, and each fit's posterior
    draws (``draws``: label -> {name: (K,) natural values})."""

    sources: list
    tables: list
    draws: dict


def _is_table(path: Path) -> bool:
    return path.is_file() and gonio.io.table_kind(path, quiet=True) is not None \
        and path.suffix.lower() not in (".json", ".xml")


def posterior_values(folder, n: int = BAND_DRAWS, seed: int = 0) -> dict:
    """``n`` posterior draws of a fit folder as natural values of every parameter
    ({name: (n,)}); a ValueError when the folder holds no readable posterior."""
    spec = fit_folder_spec(folder)[0]
    theta = posterior_draws(folder, spec, n, np.random.default_rng(seed))
    return {k: np.asarray(v, float) for k, v in spec.values(theta).items()}


def object_source(obj) -> Source:
    """A model object as a source (kind ``fabric``), labelled by its name or its model's.

    >>> object_source(brdf.fabric("velvet")).label
    'velvet'
    """
    model = brdf.model_name(obj)
    return Source("fabric", getattr(obj, "name", None) or model, obj, model=model)


def load_inputs(texts) -> Inputs:
    """Resolve each argument: a model object (a :class:`brdf.Fabric` or a baseline model of
    :data:`brdf.MODELS`, :func:`object_source`), a measured table (by its suffix and
    content) or a FABRIC (:func:`analysis.sources.resolve`: preset, fit folder, exported
    .json/.xml). A fit
    folder's posterior is read when it has one (a missing checkpoint leaves no band)."""
    sources, tables, draws = [], [], {}
    for text in texts:
        if isinstance(text, tuple(brdf.MODELS.values())):
            src = object_source(text)
            taken = {s.label for s in sources}
            label = next(f"{src.label} ({k})" if k > 1 else src.label for k in range(1, 99)
                         if (f"{src.label} ({k})" if k > 1 else src.label) not in taken)
            sources.append(dataclasses.replace(src, label=label))
            continue
        path = Path(text)
        if _is_table(path):
            tables.append((path.name, gonio.io.read(path)))
            continue
        src: Source = resolve(text)
        sources.append(src)
        if src.kind == "fit" and src.path is not None:
            folder = src.path if src.path.is_dir() else src.path.parent
            try:
                draws[src.label] = posterior_values(folder)
            except ValueError:
                pass
    return Inputs(sources, tables, draws)


@dataclasses.dataclass(frozen=True)
class Band:
    """The 95% band of f_r along a lobe: ``lo``, ``median``, ``hi`` (1/sr) at
    ``theta_o_deg`` (signed, degrees)."""

    theta_o_deg: np.ndarray
    lo: np.ndarray
    median: np.ndarray
    hi: np.ndarray


def lobe_band(fast, theta_o_deg, theta_i_deg, phi_deg, quantity) -> Band:
    """The band of a batch model (:class:`reports.explore.fast.FastBRDF` built on draws)
    in the plane ``phi_deg`` at incidence ``theta_i_deg``."""
    wi, wo = plane_directions(theta_i_deg, theta_o_deg, phi_deg)
    f = reduce_quantity(np.asarray(fast.eval(np.broadcast_to(wi, wo.shape), wo)), quantity)
    lo, med, hi = np.nanpercentile(f, [2.5, 50.0, 97.5], axis=0)
    return Band(np.asarray(theta_o_deg, float), lo, med, hi)


@dataclasses.dataclass(frozen=True)
class Points:
    """A table's points in a plane near an incidence: signed ``theta_o_deg``, ``value`` and
    ``sigma`` (1/sr; sigma 0 where the table has none)."""

    theta_o_deg: np.ndarray
    value: np.ndarray
    sigma: np.ndarray


def lobe_points(table, theta_i_deg, phi_deg, quantity, tol_deg: float = 2.5) -> Points:
    """The rows of ``table`` within ``tol_deg`` of the plane and of the incidence."""
    idx, ti, so = plane_points(table, phi_deg, tol_deg)
    near = np.abs(ti - float(theta_i_deg)) <= tol_deg
    idx, so = idx[near], so[near]
    vals = np.where(table.valid[idx], table.values[idx], np.nan)
    value = reduce_quantity(vals, quantity) if quantity != "rgb" else vals.mean(-1)
    sigma = (np.zeros_like(value) if table.sigma is None
             else reduce_sigma(table.sigma[idx], quantity))
    keep = np.isfinite(value)
    return Points(so[keep], value[keep], np.asarray(sigma)[keep])
