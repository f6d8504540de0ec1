r"""Several models fitted to each measured dataset, and compared: ``fit-measured --models``.

Each (dataset, model) is fitted into its own folder of the output: ``NAME`` for the
microcylinder (as before models), ``NAME-MODEL`` for a baseline model (:func:`fit_folder`, a
safe file name). A baseline starts from its parameters' typical values with its default free
set for the table (:meth:`analysis.families.ModelFamily.default_free`: on CUReT's grey,
relative tables the colour channels are tied and the base colour fixed, the scale free).

``measured.json``'s entry of a dataset then holds ``models``: per model (:func:`models_entry`)
its folder's ``results`` path, ``converged``, ``adequate`` and ``adequate_reason``,
``warnings`` (results.json's: ``kind``, ``parameters``, ``message``), ``elpd`` and ``se``
(PSIS-LOO) with ``pareto_k_max``, ``n_high_k`` and the ``k_threshold`` they are counted
above, ``rms_residual``, ``rms_normalized``, ``values_used``, ``steps``, ``error`` (a fit
that failed) and, from :func:`analysis.fit.compare.compare_fits` over the models with a
PSIS-LOO, ``rank`` (1 the best), ``d_elpd`` (the best's elpd minus this one's), ``d_se`` (the
standard error of that difference from the paired pointwise values), ``d_se_block`` and
``d_lag1`` (its block se and the lag-1 autocorrelation of the pointwise differences:
:func:`analysis.fit.compare.paired_structure`); ``compare_error`` says why no ranking was
made (fits of different values of the table).

Examples
--------
>>> parse_models("all")[:2]
('microcylinder', 'lambert')
>>> fit_folder("curet_07_velvet", "lambert"), fit_folder("curet_07_velvet", "microcylinder")
('curet_07_velvet-lambert', 'curet_07_velvet')
"""

from __future__ import annotations

from pathlib import Path

from analysis.families import MICROCYLINDER, family, model_names
from analysis.fit.compare import compare_fits
from analysis.fit.loo import HIGH_K
from analysis.fit.results import read_results
from gonio.safenames import check_component

__all__ = ["parse_models", "fit_folder", "models_entry", "verdict_warnings", "MODEL_FIELDS"]

#: The numbers of each model's entry (finite numbers or null).
MODEL_FIELDS = ("elpd", "se", "d_elpd", "d_se", "d_se_block", "d_lag1", "rms_residual",
                "rms_normalized", "pareto_k_max", "k_threshold", "wall_s")


def parse_models(text) -> tuple[str, ...]:
    """``--models``: ``"all"`` (every model), ``"lambert,charlie"`` or a sequence; None: the
    microcylinder alone. A ValueError names an unknown model and lists them."""
    if text is None:
        return (MICROCYLINDER,)
    if isinstance(text, str) and text.strip().lower() == "all":
        return model_names()
    items = text.split(",") if isinstance(text, str) else list(text)
    out = tuple(dict.fromkeys(str(s).strip() for s in items if str(s).strip()))
    if not out:
        raise ValueError(f"--models: none given ({text!r}); models: all or "
                         f"{', '.join(model_names())}")
    for m in out:
        if m not in model_names():
            raise ValueError(f"--models: unknown model {m!r}; models: all or "
                             f"{', '.join(model_names())}")
    return out


def fit_folder(dataset: str, model: str) -> str:
    """The folder (a file name) of ``model``'s fit of ``dataset``: the dataset's name for the
    microcylinder, ``DATASET-MODEL`` otherwise; refused unless a safe component."""
    family(model)
    name = dataset if model == MICROCYLINDER else f"{dataset}-{model}"
    return check_component(name, source="fit-measured", entry="dataset and model")


def verdict_warnings(res: dict) -> list[dict]:
    """The ``warnings`` of a results document as measured.json keeps them: per warning its
    ``kind``, ``parameters`` and ``message`` as strings (anything else dropped).

    Examples
    --------
    >>> verdict_warnings({"warnings": [{"kind": "at_bound", "parameters": ["eta1"],
    ...                                 "message": "eta1 at its bound", "x": 1}, "junk"]})
    [{'kind': 'at_bound', 'parameters': ['eta1'], 'message': 'eta1 at its bound'}]
    """
    return [{"kind": str(w.get("kind", "")),
             "parameters": [str(x) for x in w.get("parameters") or []],
             "message": str(w.get("message", ""))}
            for w in res.get("warnings") or [] if isinstance(w, dict)]


def _one(out: Path, folder: str, row: dict | None) -> dict:
    """The entry of one model's fit: from its results.json, or its batch row's error."""
    entry = {"results": f"{folder}/results.json", "converged": False, "adequate": None,
             "steps": (row or {}).get("steps", 0), "wall_s": (row or {}).get("wall_s")}
    path = out / folder / "results.json"
    if row is not None and row.get("status") == "error":
        return dict(entry, error=str(row.get("error", "")))
    if not path.is_file():
        return dict(entry, error="no results.json")
    res = read_results(path)
    q = res.get("quality") or {}
    loo = res.get("loo") or {}
    return dict(entry, converged=bool(res["converged"]), adequate=res.get("adequate"),
                adequate_reason=str(res.get("adequate_reason", "not checked")),
                warnings=verdict_warnings(res),
                elpd=loo.get("elpd"), se=loo.get("se"), pareto_k_max=loo.get("pareto_k_max"),
                n_high_k=loo.get("n_high_k"), k_threshold=loo.get("k_threshold", HIGH_K),
                rms_residual=q.get("rms_residual"),
                rms_normalized=q.get("rms_normalized"),
                values_used=(res.get("fit") or {}).get("points", {}).get("used"),
                steps=(res.get("fit") or {}).get("steps", entry["steps"]),
                identifiability=[str(x) for x in res.get("identifiability") or []])


def models_entry(out, dataset: str, models, rows: dict, previous: dict | None = None) -> dict:
    """The ``models`` of a dataset's entry: ``previous`` (an earlier run's) updated with the
    ``models`` fitted now (their batch ``rows`` by folder name), then ranked by PSIS-LOO
    over every model with one.

    Returns
    -------
    dict
        model -> entry (see the module notes), and under the key ``compare_error`` (when
        the ranking failed) why.
    """
    out = Path(out)
    doc = {m: dict(e) for m, e in (previous or {}).items() if m in model_names()}
    for m in models:
        folder = fit_folder(dataset, m)
        doc[m] = _one(out, folder, rows.get(folder))
    ranked = [m for m, e in doc.items() if e.get("elpd") is not None
              and (out / fit_folder(dataset, m) / "loo.npz").is_file()]
    for e in doc.values():
        for k in ("rank", "d_elpd", "d_se", "d_se_block", "d_lag1"):
            e.pop(k, None)
    error = None
    if len(ranked) >= 2:
        try:
            rows_c = compare_fits([out / fit_folder(dataset, m) for m in ranked],
                                  names=ranked)
        except ValueError as exc:
            error = str(exc)
        else:
            for k, r in enumerate(rows_c, start=1):
                doc[r["fit"]].update(rank=k, d_elpd=r["d_elpd"], d_se=r["d_se"],
                                     d_se_block=r["d_se_block"], d_lag1=r["d_lag1"])
    elif len(ranked) == 1:
        doc[ranked[0]].update(rank=1, d_elpd=0.0, d_se=0.0)
    return {"models": doc, **({"compare_error": error} if error else {})}
