r"""Fits of one table ranked by their PSIS-LOO (``microcyl compare``): ``arviz.compare`` on
the pointwise elpd each fit stored in ``loo.npz`` (:mod:`analysis.fit.loo`).

Two fits compare only when they saw the same data: the same table (the digest of its
directions, values and sigma that ``fit_config.json`` records) and the same values of it (the
masks of their likelihoods: ``--likelihood relative`` drops zero values). The elpd of every fit
is the density of the table's values f_r (the likelihood's space carried back by its
Jacobian), so fits under different ``--likelihood`` compare as well as fits of different
presets, variants or free sets.

For fits A (the best) and B, ``d_elpd`` = elpd_A - elpd_B >= 0 and
``d_se`` = sqrt(n var_i(elpd_A,i - elpd_B,i)): the standard error of the difference from the
paired pointwise values, far smaller than either se when the fits err on the same values.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from analysis.families import model_names
from analysis.fit.checkpoint import CONFIG_FILE
from analysis.fit.loo import HIGH_K, LOO_FILE, import_arviz, load_loo
from analysis.fit.results import read_results
from gonio.statefields import load_json

__all__ = ["compare_fits", "read_fit", "difference_in_se", "FIT_KEYS"]

#: The keys of each fit in :func:`compare_fits`'s answer (``microcyl compare --json``).
FIT_KEYS = ("fit", "model", "elpd", "se", "d_elpd", "d_se")


def read_fit(folder) -> dict:
    """What :func:`compare_fits` needs of one fit's folder.

    Returns
    -------
    dict
        ``folder`` (Path), ``model`` (the model fitted, ``results.json``'s; a name no
        model has is shown as its ``ascii()``), ``loo`` (:class:`~analysis.fit.loo.Loo`),
        ``table`` (digest), ``converged`` (bool or None).

    Raises
    ------
    ValueError
        Not a folder, no ``results.json``, no ``loo.npz``, a file that is a link, not a
        regular file, too large or out of its schema (``fit_config.json`` through
        :func:`gonio.statefields.load_json`, ``loo.npz`` through
        :func:`gonio.safenpz.load_npz`), or files that disagree on the table (each message
        names the file).
    """
    folder = Path(folder)
    if folder.is_symlink() or not folder.is_dir():
        raise ValueError(f"{folder}: not a fit's folder (not a directory, or a link)")
    rpath = folder / "results.json"
    if not os.path.lexists(rpath):          # a link or a FIFO: read_results names it
        raise ValueError(f"{rpath}: not found; is {folder} the output folder of "
                         f"`microcyl fit`?")
    results = read_results(rpath)
    loo = load_loo(folder)
    table = loo.table
    cpath = folder / CONFIG_FILE
    if os.path.lexists(cpath):
        doc = load_json(cpath, "fit configuration")     # a link, FIFO, deep or huge: one line
        try:
            recorded = doc["config"]["table"]
        except (KeyError, TypeError):
            raise ValueError(f"{cpath}: config.table is missing; a fit configuration records "
                             f"its table's digest there") from None
        if str(recorded) != table:
            raise ValueError(f"{folder / LOO_FILE} was computed for another table ({table}) "
                             f"than {cpath} records ({recorded}); run the same `microcyl "
                             f"fit` again to recompute it")
    if not table:
        raise ValueError(f"{folder / LOO_FILE}: records no table digest; run the same "
                         f"`microcyl fit` again to recompute it")
    converged = results.get("converged")
    model = results["model"]
    return {"folder": folder, "model": model if model in model_names() else ascii(model),
            "loo": loo, "table": table,
            "converged": None if converged is None else bool(converged)}


def _check_same_data(fits: list[dict], names: list[str]) -> None:
    """One table, the same values of it, or a ValueError naming the first fit that differs."""
    first, name0 = fits[0], names[0]
    for fit, name in zip(fits[1:], names[1:]):
        if fit["table"] != first["table"]:
            raise ValueError(f"{name} is a fit of another table (digest {fit['table']}) than "
                             f"{name0} (digest {first['table']}); compare ranks fits of one "
                             f"table")
        a, b = first["loo"], fit["loo"]
        if not (np.array_equal(a.point, b.point) and np.array_equal(a.channel, b.channel)):
            raise ValueError(f"{name} and {name0} fit different values of the table "
                             f"({b.point.size} and {a.point.size} values: other masks, e.g. "
                             f"--likelihood relative drops zero values); compare needs the "
                             f"same values")


def _elpd_data(az, loo):
    """An ``arviz.ELPDData`` of a stored :class:`~analysis.fit.loo.Loo` (as ``arviz.loo``
    returns with ``pointwise=True``)."""
    import xarray as xr        # arviz's own dependency, loaded with it
    return az.ELPDData(
        data=[loo.elpd, loo.se, loo.p_loo, loo.draws, loo.elpd_i.size,
              bool(loo.n_high_k > 0), xr.DataArray(loo.elpd_i, dims=["value"]),
              loo.pareto_k, "log", HIGH_K],
        index=["elpd_loo", "se", "p_loo", "n_samples", "n_data_points", "warning", "loo_i",
               "pareto_k", "scale", "good_k"])


def compare_fits(folders, names=None) -> list[dict]:
    """Rank fits of one table by PSIS-LOO elpd (``arviz.compare``), best first.

    Parameters
    ----------
    folders : sequence of path
        Two or more output folders of ``microcyl fit`` (or of a fit-batch's tables).
    names : sequence of str, optional
        How each fit is named in the answer (default the folder as given).

    Returns
    -------
    list of dict
        Best first: ``fit``, ``model`` (the model fitted), ``elpd``, ``se``, ``d_elpd`` (the best's elpd minus this one's,
        >= 0), ``d_se`` (its standard error), and ``p_loo``, ``weight`` (arviz's stacking
        weight), ``n_high_k``, ``pareto_k_max``, ``converged``, ``values``, ``table``.

    Raises
    ------
    ValueError
        Fewer than two folders, one given twice, a folder that is not a fit with its PSIS-LOO,
        fits of different tables or of different values of one: before any comparison.
    """
    folders = [Path(f) for f in folders]
    names = [str(f) for f in folders] if names is None else [str(n) for n in names]
    if len(folders) < 2:
        raise ValueError(f"compare needs two or more fit folders; got {len(folders)}")
    seen = {}
    for f, n in zip(folders, names):
        key = f.resolve()
        if key in seen or n in seen.values():
            raise ValueError(f"{n}: given twice (as {seen.get(key, n)})")
        seen[key] = n
    fits = [read_fit(f) for f in folders]
    _check_same_data(fits, names)
    az = import_arviz()
    table = az.compare({n: _elpd_data(az, fit["loo"]) for n, fit in zip(names, fits)},
                       ic="loo", method="stacking", scale="log")
    by_name = dict(zip(names, fits))
    out = []
    for name, row in table.iterrows():
        fit = by_name[name]
        loo = fit["loo"]
        d_se = float(row["dse"])
        out.append({"fit": name, "model": fit["model"], "elpd": float(row["elpd_loo"]),
                    "se": float(row["se"]),
                    "d_elpd": float(row["elpd_diff"]), "d_se": d_se,
                    "p_loo": float(row["p_loo"]), "weight": float(row["weight"]),
                    "n_high_k": loo.n_high_k, "pareto_k_max": float(np.max(loo.pareto_k)),
                    "converged": fit["converged"], "values": int(loo.elpd_i.size),
                    "table": fit["table"]})
    return out


def difference_in_se(row: dict) -> float:
    """``d_elpd / d_se`` of a row of :func:`compare_fits` (inf when d_se is 0 and d_elpd is
    not; 0 for the best).

    Examples
    --------
    >>> difference_in_se({"d_elpd": 6.0, "d_se": 1.5})
    4.0
    >>> [difference_in_se({"d_elpd": d, "d_se": 0.0}) for d in (0.0, 2.0)]
    [0.0, inf]
    """
    if row["d_se"] > 0:
        return row["d_elpd"] / row["d_se"]
    return 0.0 if row["d_elpd"] == 0 else math.inf
