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
from analysis.fit.outputs import (PLOT_FILES, STATE_FILES, check_fit_folder, claim_fit_folder,
                                  release_fit_folder)
from analysis.families import family_of
from analysis.fit.posterior import forward_model
from analysis.fit.quality import fit_quality, start_colour_difference
from analysis.fit.results import FitResult, write_results
from analysis.fit.swap import with_symmetries
from analysis.fit.trust import COLOUR_DE_MAX, colour_warnings, fixed_colour_channels
from analysis.folderlock import output_lock
from analysis.likelihood import is_grey, is_relative
from analysis.params import ParamSpec

__all__ = ["fit_fabric", "fit_spec", "check_fit_size"]


def fit_spec(fabric, free=None, ties=None, toml=None, table=None) -> ParamSpec:
    """The parameter spec of a fit as ``microcyl fit`` builds it from its options.

    Parameters
    ----------
    fabric : brdf.Model (brdf.Fabric, a baseline)
        The model fitted (its family, :func:`analysis.families.family_of`); gives the
        defaults (fixed values and the start).
    free : str or sequence of str, optional
        Free parameters (comma-separated or a sequence); a name ending in ``.toml`` is a spec
        file. Default the family's default free set
        (:meth:`analysis.families.ModelFamily.default_free`: the microcylinder's
        :data:`analysis.params.DEFAULT_FREE`; every parameter of a baseline, with the
        identifiability choices for a grey or relative ``table``); on an RGB ``table``
        whose mean colour the start contradicts, every colour channel besides (a note in
        the spec says so).
    ties : sequence of str, optional
        ``"a=b"`` / ``"a=1-b"`` ties (each item may hold several, comma-separated; ``"none"``
        is dropped). Default the family's default ties when neither ``free`` nor ``toml`` is
        given, none otherwise.
    toml : path, optional
        A TOML spec (:meth:`ParamSpec.from_toml`); ``free`` and ``ties`` are added to it.
    table : gonio.Table, optional
        The table to be fitted: whether it is grey or relative decides a baseline's default
        free set (without it: neither).

    Returns
    -------
    ParamSpec

    Examples
    --------
    >>> import brdf
    >>> fit_spec(brdf.fabric("silk_crepe_de_chine"), "kd1,gamma_s1").free
    ('kd1', 'gamma_s1')
    >>> from brdf.baselines import Lambert
    >>> fit_spec(Lambert()).free
    ('base_r', 'base_g', 'base_b')
    """
    return with_symmetries(_fit_spec(fabric, free, ties, toml, table), fabric)


def _fit_spec(fabric, free, ties, toml, table) -> ParamSpec:
    """:func:`fit_spec` before the model's periods are added."""
    fam = family_of(fabric)
    defaults = fam.defaults(fabric)
    if ties is not None:
        ties = [t for item in ties for t in str(item).split(",")
                if t.strip() and t.strip().lower() != "none"]
    if isinstance(free, str) and free.lower().endswith(".toml"):
        toml, free = free, None
    notes = ()
    if free is None and toml is None:
        grey = table is not None and is_grey(table.values)
        relative = table is not None and is_relative(getattr(table, "meta", {}))
        free, default_ties, notes = fam.default_free(grey=grey, relative=relative)
        if ties is None:
            ties = list(default_ties)
        if table is not None and not grey and fam.cls.DEFAULT_FREE is not None:
            return _with_table_colour(fabric, table, free, ties, notes, defaults)
    if toml is not None:
        return ParamSpec.from_toml(toml, defaults=defaults, free=free, ties=ties, family=fam)
    return ParamSpec(free, defaults=defaults, ties=ties or (), family=fam, notes=notes)


def _with_table_colour(fabric, table, free, ties, notes, defaults) -> ParamSpec:
    """The default spec on an RGB table of a model with a default free set of its own (the
    microcylinder's; a baseline's frees its colours already), with every colour channel freed
    when the start's
    hue and chroma contradict the table's mean colour (CIEDE2000 above
    :data:`analysis.fit.trust.COLOUR_DE_MAX`, :func:`analysis.fit.quality.start_colour_difference`):
    a fixed colour the data contradict pulls every other parameter to make up for it."""
    fam = family_of(fabric)
    spec = ParamSpec(free, defaults=defaults, ties=ties or (), family=fam, notes=notes)
    fixed = fixed_colour_channels(spec)
    if not fixed:
        return spec
    de = start_colour_difference(table, spec, forward_model(fabric, table.wi, table.wo))
    if not de > COLOUR_DE_MAX:
        return spec
    groups = [g for g, names in fam.aliases.items() if any(n in fixed for n in names)]
    note = (f"RGB table whose mean colour the start contradicts (CIEDE2000 {de:.1f} in hue "
            f"and chroma, above {COLOUR_DE_MAX:g}): {', '.join(groups)} freed")
    return ParamSpec(list(free) + list(fixed), defaults=defaults, ties=ties or (), family=fam,
                     notes=(*notes, note))


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
               table_file=None, **fit_kw) -> FitResult:
    """Fit ``fabric``'s free parameters to ``table`` and write the results into ``out_dir``.

    The fit (:func:`analysis.fit.fit`) checkpoints into ``out_dir`` and resumes there; the
    folder is locked meanwhile (:func:`analysis.folderlock.output_lock`, the lock a batch or a
    report there takes too: a second run into it is refused, ``another fit is running in DIR
    (pid N)``; a folder holding a report is refused), and temporaries a killed fit left in it
    are removed. A folder holding files no fit wrote there, or the table file itself, is
    refused (:func:`analysis.fit.outputs.check_fit_folder`); the files the fit will write are
    listed in the folder's marker first (:func:`~analysis.fit.outputs.claim_fit_folder`), so
    the next fit there, a resume, takes them for its own. Then the
    quality figures are computed (:func:`analysis.fit.quality.fit_quality`: residuals, albedo
    colours and their CIEDE2000 difference; a ``colour_fixed`` warning when it is large with a
    colour held fixed, :func:`analysis.fit.trust.colour_warnings`), the PSIS-LOO
    (:func:`analysis.fit.loo.psis_loo`:
    ``loo`` in the results, its pointwise values in ``loo.npz``, the LOO-PIT test in
    ``quality["loo_pit"]``, a ``pareto_k`` warning when values have a high Pareto k), the
    plots drawn when ``plots`` is given, and ``results.json`` / ``results.csv`` written, once,
    atomically.

    Parameters
    ----------
    table : gonio.Table
    fabric : brdf.Model (brdf.Fabric, a baseline)
        The model whose parameters ``spec`` fixes and whose geometry is evaluated (of the
        spec's family).
    spec : analysis.params.ParamSpec
    out_dir : path
        Output folder.
    plots : callable, optional
        ``plots(result, table, model_factory, out_dir) -> {name: path}`` (for example
        ``reports.plots.fit_diagnostics.write_fit_plots``); ``model_factory(wi, wo)`` is a
        forward model (:func:`~analysis.fit.posterior.forward_model`) of the model at
        other pairs.
    table_file : path, optional
        The file ``table`` was read from: refused when it lies in ``out_dir``.
    **fit_kw
        Passed to :func:`analysis.fit.fit`.

    Returns
    -------
    FitResult
        With ``quality``, ``loo``, ``warnings`` and ``plots`` filled in.
    """
    out = Path(out_dir)
    if family_of(fabric) is not spec.family:
        raise ValueError(f"the spec is of model {spec.model}, the start of model "
                         f"{family_of(fabric).name}")
    with output_lock(out, "fit"):
        check_fit_folder(out, table_file)
        claim_fit_folder(out, STATE_FILES + (PLOT_FILES if plots is not None else ()))
        try:
            result = fit(table, spec, forward_model(fabric, table.wi, table.wo), out_dir=out,
                         **fit_kw)
        except BaseException:
            release_fit_folder(out)     # refused before its first file: the folder as it was
            raise
        result.quality = fit_quality(result, table)
        result.warnings = [*result.warnings, *colour_warnings(result)]
        t0 = time.perf_counter()
        result.loo = psis_loo(result, table_digest(table))
        result.timing["loo_s"] = time.perf_counter() - t0
        result.quality["loo_pit"] = result.loo.pit_test()
        result.warnings = [*result.warnings, *result.loo.warnings()]
        result.loo.save(out)
        if plots is not None:
            files = plots(result, table, lambda wi, wo: forward_model(fabric, wi, wo), out)
            claim_fit_folder(out, [Path(v).name for v in files.values()])
            result.plots = {k: Path(v).name for k, v in files.items()}
        write_results(result, out)
    return result
