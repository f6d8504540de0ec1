"""What a batch fits: one :class:`BatchJob` per table, from the inputs a user names.

Inputs are table files, globs or folders (the files directly inside a folder whose names
:func:`gonio.read` knows), and CUReT's ``abrdf.dat`` with a sample selection (each sample a
table). Every input is checked here, before any fit starts: a missing file, an unknown suffix
or a CUReT file without samples is refused by name. A file ``STEM.toml`` beside a table (STEM
the table's stem; for CUReT ``FOLDER_SS``, the folder's name and the sample) replaces the
batch's ``--spec``/``--free``/``--tie`` for it, and its ``fabric`` key the batch's preset.

Each table's folder in the batch's output is named by :func:`table_names` from the set of
tables alone, never from their order, so the same inputs in another order name the same
folders: the stem (``FOLDER_SS`` for CUReT), made a safe file name
(:func:`gonio.safenames.safe_component`: a table ``...exr``, whose stem is ``..``, gets
``_-<digest>``, and so does a stem that names one of the batch's own files,
:data:`analysis.batch.summary.BATCH_FILES`: ``summary.json.csv`` gets
``summary.json-<digest>``); where stems collide (case ignored), the path relative to the tables' common
folder (``a/x.csv`` and ``b/x.csv`` give ``a_x`` and ``b_x``), then with its suffix
(``x_csv``, ``x_exr``), then with a digest of that path. A table named twice is fitted once.
"""

from __future__ import annotations

import dataclasses
import glob
import hashlib
import json
import os
from pathlib import Path
from typing import Callable

import gonio
from gonio.io import READ_SUFFIXES
from analysis.families import MICROCYLINDER, family
from analysis.fit.workflow import fit_spec
from gonio.curet import N_SAMPLES
from analysis.batch.summary import BATCH_FILES
from gonio.safenames import digest, safe_component
from gonio.statefields import load_toml

__all__ = ["BatchJob", "jobs_from_inputs", "read_job_table", "parse_samples", "table_names"]


@dataclasses.dataclass(frozen=True)
class BatchJob:
    """One table of a batch and how to fit it (plain data: it travels to a Dask worker).

    Attributes
    ----------
    name : str
        Unique in the batch; the fit's folder is ``DIR/<name>``.
    path : str
        The table file (read on the worker).
    sample : int or None
        CUReT sample number.
    preset : str
        Preset giving the fixed values and the start.
    free, ties : tuple of str or None
        As ``microcyl fit --free`` / ``--tie`` (None: the defaults).
    spec : str or None
        A TOML spec file (:meth:`analysis.params.ParamSpec.from_toml`).
    fit : dict
        Options of :func:`analysis.fit.fit` (likelihood, seed, max_steps, ...).
    fabric_options : dict
        Options of the preset's Fabric (MODEL.md's variants).
    read_options : dict
        Options of the table's reader (e.g. ``step`` for RGL files).
    loader : callable, optional
        ``loader() -> gonio.Table`` instead of reading ``path`` (a picklable function, e.g.
        a :func:`functools.partial` of :func:`analysis.measured.load_measured`).
    plots : callable, optional
        Passed to :func:`analysis.fit.fit_fabric` (e.g. ``reports.plots.fit_diagnostics.write_fit_plots``).
    config_extra : dict, optional
        Recorded in (and matched against) the fit's stored configuration; default the
        preset, its options and the sample, as ``microcyl fit`` records them.
    model : str
        The model fitted (:func:`analysis.families.model_names`; default microcylinder). A
        baseline model starts from its typical values (``preset`` unused) and, with
        ``free`` None, takes its default free set for the table
        (:meth:`analysis.families.ModelFamily.default_free`).
    """

    name: str
    path: str
    sample: int | None = None
    preset: str = "linen_plain"
    free: tuple[str, ...] | None = None
    ties: tuple[str, ...] | None = None
    spec: str | None = None
    fit: dict = dataclasses.field(default_factory=dict)
    fabric_options: dict = dataclasses.field(default_factory=dict)
    read_options: dict = dataclasses.field(default_factory=dict)
    loader: Callable | None = None
    plots: Callable | None = None
    config_extra: dict | None = None
    model: str = MICROCYLINDER

    def fabric(self):
        """The start model: the preset's fabric with its options (a baseline model at its
        typical values)."""
        fam = family(self.model)
        return fam.start(self.preset if fam.presets else None, self.fabric_options)

    def param_spec(self, fab=None, table=None):
        """The :class:`~analysis.params.ParamSpec` of this fit (checks every name); ``table``
        decides a baseline's default free set."""
        return fit_spec(fab if fab is not None else self.fabric(), self.free, self.ties,
                        self.spec, table=table)

    def key(self) -> str:
        """A digest of everything that decides the fit: the job's fields and the size and
        modification time of its files. A converged row with the same key is not redone."""
        doc = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
               if f.name not in ("plots",)}
        if doc["model"] == MICROCYLINDER:
            del doc["model"]                # the keys of batches run before models stand
        doc["loader"] = repr(self.loader)
        for what, p in (("table", self.path), ("spec_file", self.spec)):
            if p is not None and Path(p).exists():
                st = Path(p).stat()
                doc[what] = [st.st_size, st.st_mtime_ns]
        text = json.dumps(gonio.plain(doc, nonfinite="repr"), sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def read_job_table(job: BatchJob):
    """The job's table: ``job.loader()``, else :func:`gonio.read` of its path."""
    if job.loader is not None:
        return job.loader()
    opts = dict(job.read_options)
    if job.sample is not None:
        opts["sample"] = job.sample
    return gonio.read(job.path, **opts)


def parse_samples(text) -> tuple[int, ...] | None:
    """``"all"`` -> 1..61, ``"1,2,7"`` -> (1, 2, 7), None -> None (CUReT sample numbers).

    Examples
    --------
    >>> parse_samples("2,7"), len(parse_samples("all"))
    ((2, 7), 61)
    """
    if text is None:
        return None
    if isinstance(text, str) and text.strip().lower() == "all":
        return tuple(range(1, N_SAMPLES + 1))
    items = text.split(",") if isinstance(text, str) else list(text)
    try:
        out = tuple(int(str(s).strip()) for s in items if str(s).strip())
    except ValueError:
        raise ValueError(f"--sample must be 'all' or comma-separated integers in 1..{N_SAMPLES}"
                         f"; got {text!r}") from None
    bad = [s for s in out if not 1 <= s <= N_SAMPLES]
    if bad or not out:
        raise ValueError(f"--sample must be 'all' or integers in 1..{N_SAMPLES}; got {text!r}")
    return out


def _is_table(path: Path) -> bool:
    name = path.name.lower()
    return name == "abrdf.dat" or (path.suffix.lower() in READ_SUFFIXES)


def _expand(item: str) -> list[Path]:
    """Files named by one input: a glob, a folder (its table files) or a file."""
    if any(ch in item for ch in "*?["):
        found = sorted(Path(p) for p in glob.glob(item))
        files = [p for p in found if p.is_file() and _is_table(p)]
        if not files:
            raise ValueError(f"input {item!r} matches no table file (known: "
                             f"{', '.join(READ_SUFFIXES)})")
        return files
    path = Path(item)
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if p.is_file() and _is_table(p))
        if not files:
            raise ValueError(f"input folder {item!r} holds no table file (known: "
                             f"{', '.join(READ_SUFFIXES)})")
        return files
    if not path.exists():
        raise ValueError(f"input {item!r}: no such file or folder")
    if not _is_table(path):
        raise ValueError(f"input {item!r}: not a table file gonio reads (known: "
                         f"{', '.join(READ_SUFFIXES)})")
    return [path]


def _candidates(path: Path, sample: int | None, root: Path) -> list[str]:
    """The names a table may get, most readable first (see the module's docstring); the last
    is unique to the table's path and sample."""
    rel = path.relative_to(root)
    if sample is None:
        base, label = path.stem, "_".join(rel.with_suffix("").parts)
        full = "_".join(rel.parent.parts + (rel.name.replace(".", "_"),))
    else:
        base = f"{path.parent.name}_{sample:02d}"
        label = "_".join(rel.parent.parts + (f"{sample:02d}",)) if rel.parent.parts else base
        full = "_".join(rel.parts).replace(".", "_") + f"_{sample:02d}"
    key = f"{rel.as_posix()}#{sample}"
    return [safe_component(base, BATCH_FILES), safe_component(label, BATCH_FILES),
            safe_component(full, BATCH_FILES), f"{safe_component(label)[:80]}-{digest(key)}"]


def table_names(tables) -> list[str]:
    """The folder names of a batch's tables, one each, from the set of tables alone.

    Parameters
    ----------
    tables : sequence of (path, sample)
        Distinct table files (resolved, absolute) with their CUReT sample or None.

    Returns
    -------
    list of str
        Safe file names, distinct even where case is ignored, in the order of ``tables``; the
        same tables in another order get the same names.

    Examples
    --------
    >>> from pathlib import Path
    >>> table_names([(Path("/d/b/x.csv"), None), (Path("/d/a/x.csv"), None),
    ...              (Path("/d/a/y.csv"), None), (Path("/d/a/...csv"), None)])
    ['b_x', 'a_x', 'y', '_-5ec1f7e7']
    """
    tables = [(Path(p), s) for p, s in tables]
    if not tables:
        return []
    root = Path(os.path.commonpath([str(p.parent) for p, _ in tables]))
    cands = [_candidates(p, s, root) for p, s in tables]
    level = [0] * len(tables)
    while True:
        names = [c[k] for c, k in zip(cands, level)]
        groups: dict[str, list[int]] = {}
        for i, n in enumerate(names):
            groups.setdefault(n.casefold(), []).append(i)
        clash = [i for g in groups.values() if len(g) > 1 for i in g]
        if not clash:
            return names
        if all(level[i] == len(cands[i]) - 1 for i in clash):
            raise ValueError(f"tables {', '.join(str(tables[i][0]) for i in clash)} cannot "
                             f"be given distinct folder names")
        for i in clash:
            level[i] = min(level[i] + 1, len(cands[i]) - 1)


def _override(job: BatchJob, folder: Path, stem: str) -> BatchJob:
    """The job with ``STEM.toml`` beside its table, when there is one, as its spec."""
    toml = folder / f"{stem}.toml"
    if not toml.is_file():
        return job
    doc = load_toml(toml, "fit spec")
    preset = doc.get("fabric", job.preset)
    return dataclasses.replace(job, spec=str(toml), free=None, ties=(), preset=preset)


def jobs_from_inputs(inputs, *, preset: str | None, free=None, ties=None, spec=None,
                     samples=None, fit=None, fabric_options=None, read_options=None,
                     plots=None, model: str = MICROCYLINDER) -> list[BatchJob]:
    """The jobs of a batch, every input and every spec checked before any fit starts.

    Parameters
    ----------
    inputs : sequence of str
        Table files, globs or folders.
    preset : str or None
        Preset of every table (a ``NAME.toml`` beside a table may name another); None for
        a baseline ``model`` (which takes none).
    free, ties, spec
        As ``microcyl fit``'s ``--free``, ``--tie``, ``--spec``.
    samples : str or sequence of int, optional
        CUReT samples (:func:`parse_samples`): needed when an input is ``abrdf.dat``.
    fit, fabric_options, read_options : dict, optional
        Fit options, Fabric options, reader options (see :class:`BatchJob`).
    plots : callable, optional
    model : str
        The model fitted to every table (:func:`analysis.families.model_names`).

    Returns
    -------
    list of BatchJob
        In input order (files of a folder or glob sorted; a table named twice once), named
        by :func:`table_names`.

    Raises
    ------
    ValueError
        A missing input, a file gonio cannot read, CUReT without samples, an unknown preset,
        or a spec with unknown parameters (naming the table).
    """
    family(model).check_preset(preset)            # an unknown model or preset: one line
    sample_list = parse_samples(samples)
    base = dict(model=model, preset=preset or BatchJob.preset, free=None if free is None else tuple(free),
                ties=None if ties is None else tuple(ties), spec=spec, fit=dict(fit or {}),
                fabric_options=dict(fabric_options or {}),
                read_options=dict(read_options or {}), plots=plots)
    found: dict[tuple[Path, int | None], Path] = {}      # (resolved, sample) -> as given
    for item in inputs:
        for path in _expand(str(item)):
            if path.name.lower() == "abrdf.dat":
                if sample_list is None:
                    raise ValueError(f"input {str(path)!r} is CUReT's abrdf.dat: name the "
                                     f"samples with --sample all or --sample 1,2,7")
                samples_of = sample_list
            else:
                samples_of = (None,)
            for s in samples_of:
                found.setdefault((path.resolve(), s), path)
    names = table_names(list(found))
    jobs = []
    for ((real, s), path), name in zip(found.items(), names):
        stem = path.stem if s is None else f"{real.parent.name}_{s:02d}"
        jobs.append(_override(BatchJob(name, str(path), s, **base), path.parent, stem))
    if not jobs:
        raise ValueError("no tables to fit: name at least one input")
    for job in jobs:
        _check(job)
    return jobs


def _check(job: BatchJob) -> None:
    """The preset, its options and the spec of a job, or a ValueError naming the table."""
    try:
        family(job.model).check_preset(job.preset)
        job.param_spec()
    except ValueError as exc:
        raise ValueError(f"table {job.name} ({job.path}): {exc}") from None
