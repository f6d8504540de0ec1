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

That se treats the values as independent. A model that misses a feature of the cloth misses
it over neighbouring directions together, so the pointwise differences run in streaks along
the table and the se is too small. :func:`paired_structure` measures this from the data:
the lag-1 autocorrelation of the differences along the table's order (its rows, then
channels) and a block (batch-means) standard error over runs of about sqrt(n) consecutive
values, which allows for correlation within a run; both are reported beside ``d_se``
(``d_lag1``, ``d_se_block``), and the words of a close call say so
(:func:`reports.fitwords.gap_sentence`).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from analysis.families import model_names
from analysis.fit.checkpoint import CONFIG_FILE
from analysis.fit.loo import LOO_FILE, import_arviz, load_loo
from analysis.fit.results import read_results
from gonio.terminal import shown
from gonio.statefields import load_json

__all__ = ["compare_fits", "read_fit", "difference_in_se", "paired_structure", "FIT_KEYS"]

#: The keys of each fit in :func:`compare_fits`'s answer (``microcyl compare --json``).
FIT_KEYS = ("fit", "model", "elpd", "se", "d_elpd", "d_se", "d_se_block", "d_lag1",
            "adequate", "n_high_k", "k_threshold")


def read_fit(folder) -> dict:
    """What :func:`compare_fits` needs of one fit's folder.

    Returns
    -------
    dict
        ``folder`` (Path), ``model`` (the model fitted, ``results.json``'s; a name no
        model has is shown as its ``ascii()``), ``loo`` (:class:`~analysis.fit.loo.Loo`),
        ``table`` (digest), ``converged`` (bool or None), ``adequate`` (bool or None),
        ``warnings`` (the kinds of results.json's warnings).

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
            raise ValueError(f"{folder / LOO_FILE} was computed for another table "
                             f"({shown(table)}) than {cpath} records ({shown(recorded)}); run "
                             f"the same `microcyl "
                             f"fit` again to recompute it")
    if not table:
        raise ValueError(f"{folder / LOO_FILE}: records no table digest; run the same "
                         f"`microcyl fit` again to recompute it")
    converged = results.get("converged")
    model = results["model"]
    adequate = results.get("adequate")
    kinds = [str(w.get("kind")) for w in results.get("warnings") or [] if isinstance(w, dict)]
    return {"folder": folder, "model": model if model in model_names() else ascii(model),
            "loo": loo, "table": table,
            "converged": None if converged is None else bool(converged),
            "adequate": adequate if isinstance(adequate, bool) else None,
            "warnings": kinds}


def _check_same_data(fits: list[dict], names: list[str]) -> None:
    """One table, the same values of it, or a ValueError naming the first fit that differs."""
    first, name0 = fits[0], names[0]
    for fit, name in zip(fits[1:], names[1:]):
        if fit["table"] != first["table"]:
            raise ValueError(f"{name} is a fit of another table (digest {shown(fit['table'])}) "
                             f"than {name0} (digest {shown(first['table'])}); compare ranks "
                             f"fits of one "
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
              loo.pareto_k, "log", loo.k_threshold],
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
        >= 0), ``d_se`` (its standard error), ``d_se_block`` and ``d_lag1`` (the block se
        of the difference and the lag-1 autocorrelation of its pointwise values,
        :func:`paired_structure`; 0 and None for the best), and ``p_loo``, ``weight``
        (arviz's stacking weight), ``n_high_k``, ``pareto_k_max``, ``k_threshold`` (the
        Pareto k above which a value counts in ``n_high_k``), ``converged``, ``adequate``,
        ``warnings`` (kinds), ``values``, ``table``.

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
    best = by_name[table.index[0]]["loo"]
    out = []
    for name, row in table.iterrows():
        fit = by_name[name]
        loo = fit["loo"]
        d_se = float(row["dse"])
        block, lag1 = (0.0, None) if loo is best else paired_structure(best, loo)
        out.append({"fit": name, "model": fit["model"], "elpd": float(row["elpd_loo"]),
                    "se": float(row["se"]),
                    "d_elpd": float(row["elpd_diff"]), "d_se": d_se, "d_se_block": block,
                    "d_lag1": lag1,
                    "p_loo": float(row["p_loo"]), "weight": float(row["weight"]),
                    "n_high_k": loo.n_high_k, "pareto_k_max": float(np.max(loo.pareto_k)),
                    "k_threshold": loo.k_threshold,
                    "converged": fit["converged"], "adequate": fit["adequate"],
                    "warnings": fit["warnings"], "values": int(loo.elpd_i.size),
                    "table": fit["table"]})
    return out


def paired_structure(best, other) -> tuple[float, float | None]:
    """The block standard error of ``best.elpd - other.elpd`` and the lag-1 autocorrelation
    of its pointwise differences, along the table's order (rows, then channels).

    Parameters
    ----------
    best, other : Loo
        Fits of the same values (:class:`analysis.fit.loo.Loo`).

    Returns
    -------
    se_block : float
        sqrt(n b var_j(mean of block j)) over m = n // b blocks of b = ceil(sqrt(n))
        consecutive differences (the batch-means estimate of the se of their sum; near the
        naive sqrt(n var_i) when the differences are independent, larger when they run in
        streaks).
    lag1 : float or None
        The lag-1 autocorrelation of the differences; None with fewer than 3 values or none
        varying.

    Examples
    --------
    >>> from analysis.fit.loo import Loo
    >>> def fit(e):
    ...     n = len(e)
    ...     return Loo(np.asarray(e, float), np.zeros(n), np.zeros(n), np.arange(n),
    ...                np.zeros(n, int), 1.0, 400, 1.0)
    >>> se, r = paired_structure(fit([1.0] * 4 + [0.0] * 4), fit([0.0] * 8))
    >>> round(r, 3)      # one streak: positively correlated neighbours
    0.625
    """
    order = np.lexsort((best.channel, best.point))
    d = (best.elpd_i - other.elpd_i)[order]
    n = d.size
    b = max(1, math.ceil(math.sqrt(n)))
    m = n // b
    se = float(math.sqrt(n * b * np.var(d[:m * b].reshape(m, b).mean(axis=1)))) if m >= 2 \
        else float(math.sqrt(n * np.var(d)))
    c = d - d.mean()
    den = float(np.dot(c, c))
    lag1 = float(np.dot(c[:-1], c[1:]) / den) if n >= 3 and den > 0 else None
    return se, lag1


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
