"""The workflow of ``microcyl fit``: fit a fabric to a table, write its results (and plots)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable

import gonio.io
import gonio.tablesize
from analysis.budget import check_fit_rows
from analysis.fit.checkpoint import table_digest
from analysis.fit.driver import FitOptions, fit
from analysis.fit.loo import psis_loo
from analysis.fit.posterior import FabricModel
from analysis.fit.quality import fit_quality
from analysis.fit.results import FitResult, write_results
from analysis.folderlock import output_lock
from analysis.params import DEFAULT_FREE, DEFAULT_TIES, ParamSpec, defaults_from_fabric

__all__ = ["fit_fabric", "fit_spec", "check_fit_size"]


def fit_spec(fabric, free=None, ties=None, toml=None) -> ParamSpec:
    """The parameter spec of a fit as ``microcyl fit`` builds it from its options.

    Parameters
    ----------
    fabric : brdf.Fabric
        Gives the defaults (fixed values and the start).
    free : str or sequence of str, optional
        Free parameters (comma-separated or a sequence); a name ending in ``.toml`` is a spec
        file. Default :data:`analysis.params.DEFAULT_FREE`.
    ties : sequence of str, optional
        ``"a=b"`` / ``"a=1-b"`` ties (each item may hold several, comma-separated; ``"none"``
        is dropped). Default :data:`analysis.params.DEFAULT_TIES` when neither ``free`` nor
        ``toml`` is given, none otherwise.
    toml : path, optional
        A TOML spec (:meth:`ParamSpec.from_toml`); ``free`` and ``ties`` are added to it.

    Returns
    -------
    ParamSpec

    Examples
    --------
    >>> import brdf
    >>> fit_spec(brdf.fabric("silk_crepe_de_chine"), "kd1,gamma_s1").free
    ('kd1', 'gamma_s1')
    """
    defaults = defaults_from_fabric(fabric)
    if ties is not None:
        ties = [t for item in ties for t in str(item).split(",")
                if t.strip() and t.strip().lower() != "none"]
    if isinstance(free, str) and free.lower().endswith(".toml"):
        toml, free = free, None
    if ties is None and free is None and toml is None:
        ties = list(DEFAULT_TIES)
    if toml is not None:
        return ParamSpec.from_toml(toml, defaults=defaults, free=free, ties=ties)
    return ParamSpec(free if free is not None else DEFAULT_FREE, defaults=defaults,
                     ties=ties or ())


def check_fit_size(path, spec: ParamSpec, walkers: int | None = None, **read_options) -> None:
    """Before the table ``path`` is parsed: its size estimated from the file and refused when
    its reading would exceed the memory limit (:func:`gonio.tablesize.check_table`), then the
    fit's batched evaluations at that size (:func:`analysis.budget.check_fit_rows`, walkers
    and threads as :meth:`FitOptions.resolve` makes them for ``spec``). Nothing is refused
    when the size cannot be told (the reader then says what is wrong).
    """
    path = Path(path)
    kind = gonio.io.table_kind(path, quiet=True)
    if kind is None or not path.is_file():
        return
    est = gonio.tablesize.check_table(path, kind, **read_options)
    if est is not None:
        opts = FitOptions(walkers=walkers).resolve(spec.ndim)
        check_fit_rows(path.name, est.rows, opts.walkers, opts.threads)


def fit_fabric(table, fabric, spec, out_dir, *, plots: Callable | None = None,
               **fit_kw) -> FitResult:
    """Fit ``fabric``'s free parameters to ``table`` and write the results into ``out_dir``.

    The fit (:func:`analysis.fit.fit`) checkpoints into ``out_dir`` and resumes there; the
    folder is locked meanwhile (:func:`analysis.folderlock.output_lock`, the lock a batch or a
    report there takes too: a second run into it is refused, ``another fit is running in DIR
    (pid N)``; a folder holding a report is refused), and temporaries a killed fit left in it
    are removed. Then the
    quality figures are computed (:func:`analysis.fit.quality.fit_quality`: residuals, albedo
    colours and their CIEDE2000 difference), the PSIS-LOO (:func:`analysis.fit.loo.psis_loo`:
    ``loo`` in the results, its pointwise values in ``loo.npz``, the LOO-PIT test in
    ``quality["loo_pit"]``, a ``pareto_k`` warning when values have a high Pareto k), the
    plots drawn when ``plots`` is given, and ``results.json`` / ``results.csv`` written, once,
    atomically.

    Parameters
    ----------
    table : gonio.Table
    fabric : brdf.Fabric
        The fabric whose parameters ``spec`` fixes and whose geometry is evaluated.
    spec : analysis.params.ParamSpec
    out_dir : path
        Output folder.
    plots : callable, optional
        ``plots(result, table, model_factory, out_dir) -> {name: path}`` (for example
        ``reports.plots.fit_diagnostics.write_fit_plots``); ``model_factory(wi, wo)`` is a
        :class:`~analysis.fit.posterior.FabricModel` of the fabric at other pairs.
    **fit_kw
        Passed to :func:`analysis.fit.fit`.

    Returns
    -------
    FitResult
        With ``quality``, ``loo``, ``warnings`` and ``plots`` filled in.
    """
    out = Path(out_dir)
    with output_lock(out, "fit"):
        result = fit(table, spec, FabricModel(fabric, table.wi, table.wo), out_dir=out,
                     **fit_kw)
        result.quality = fit_quality(result, table)
        t0 = time.perf_counter()
        result.loo = psis_loo(result, table_digest(table))
        result.timing["loo_s"] = time.perf_counter() - t0
        result.quality["loo_pit"] = result.loo.pit_test()
        result.warnings = [*result.warnings, *result.loo.warnings()]
        result.loo.save(out)
        if plots is not None:
            files = plots(result, table, lambda wi, wo: FabricModel(fabric, wi, wo), out)
            result.plots = {k: Path(v).name for k, v in files.items()}
        write_results(result, out)
    return result
