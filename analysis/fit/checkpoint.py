"""The output folder of a fit: its configuration and its checkpoint, both written whole.

``fit_config.json`` holds the configuration (with a digest of the table) and the point
estimate; ``checkpoint.h5`` the chains, random states, proposals and progress of every
ensemble. Both are written through :func:`gonio.atomic_write` (a temporary file renamed into
place), only by the thread that runs the fit and only while no ensemble is stepping, so a
kill at any moment leaves the previous checkpoint whole, and no file is ever open in two
threads. A fit run again with the same folder and configuration resumes from the checkpoint;
another configuration, or an unreadable file, is a ``ValueError`` naming the file.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path

import h5py
import numpy as np

from analysis.lazy import lazy_module
from gonio import atomic_write
from gonio.jsonplain import plain
from gonio.memory import memory_limit
from gonio.safeh5 import H5Data, H5Group, read_h5
from gonio.statefields import FileFields, load_json, loads_json

__all__ = ["FitFolder", "table_digest", "read_config", "checkpoint_layout", "check_checkpoint",
           "CONFIG_FILE", "CHECKPOINT_FILE"]

#: The proposal's module, on use (it loads emcee: :mod:`analysis.lazy`).
proposal = lazy_module("analysis.fit.proposal")

CONFIG_FILE = "fit_config.json"
CHECKPOINT_FILE = "checkpoint.h5"
#: Most ensembles a checkpoint may hold (``--ensembles`` is at most 64).
MAX_ENSEMBLES = 1024
#: Most walkers a checkpoint's configuration may name, and most importance draws
#: (``draw_lw``) a proposal may keep (the fit keeps analysis.fit.moves.DRAWS = 256).
MAX_WALKERS = 1 << 16
MAX_DRAWS = 1 << 16


def table_digest(table) -> str:
    """16 hex digits of SHA-256 over a table's directions, values and sigma."""
    h = hashlib.sha256()
    for a in (table.wi, table.wo, table.values, table.sigma):
        h.update(b"none" if a is None else np.ascontiguousarray(a, dtype=np.float64).tobytes())
    return h.hexdigest()[:16]


class FitFolder:
    """A fit's output folder (created when missing).

    Parameters
    ----------
    path : path
    """

    def __init__(self, path):
        self.path = Path(path)
        self.path.mkdir(parents=True, exist_ok=True)
        self.config_path = self.path / CONFIG_FILE
        self.checkpoint_path = self.path / CHECKPOINT_FILE

    def read_start(self, config: dict) -> dict | None:
        """The stored point estimate (``best``, ``best_logp``, ``cov``) when the folder holds a
        fit of ``config``; None for a new folder.

        Raises
        ------
        ValueError
            A corrupt configuration, another configuration, or a checkpoint without one.
        """
        if not self.config_path.exists():
            if self.checkpoint_path.exists() or any(self.path.glob("chains_*.h5")):
                raise ValueError(f"{self.path}: checkpoint without {CONFIG_FILE}; delete the "
                                 f"folder to start again")
            return None
        try:
            stored = read_config(self.config_path)
        except ValueError as exc:
            raise self._corrupt(exc) from None
        stored_cfg = stored["config"]
        config = plain(config)
        stored_cfg.setdefault("model", "microcylinder")     # written before models: the one
        config.setdefault("model", "microcylinder")
        if config["model"] != stored_cfg["model"]:
            raise ValueError(f"{self.path} holds a fit of model {stored_cfg['model']}, not "
                             f"{config['model']}; use another output folder (or --model "
                             f"{stored_cfg['model']} to resume it)")
        if config != stored_cfg:
            diff = sorted(k for k in set(config) | set(stored_cfg)
                          if config.get(k) != stored_cfg.get(k))
            raise ValueError(f"{self.path} holds a fit with another configuration (differs in: "
                             f"{', '.join(diff)}); use another output folder or delete it")
        f, d = FileFields(self.config_path), len(stored_cfg["spec"]["free"])
        try:
            return {"best": f.array(stored, "best", shape=(d,)),
                    "best_logp": f.number(stored, "best_logp", finite=False, hi=math.inf),
                    "cov": f.array(stored, "cov", shape=(d, d), default=None, none=True)}
        except ValueError as exc:
            raise self._corrupt(exc) from None

    def _corrupt(self, exc: ValueError) -> ValueError:
        """A bad fit_config.json: the reader's line (file and field) and what to do."""
        what = str(exc).removeprefix(f"{self.config_path}: ")
        return ValueError(f"{self.config_path}: corrupt fit configuration: {what}; delete the "
                          f"folder to start again")

    def write_start(self, config: dict, best, best_logp: float, cov):
        """Store the configuration and the point estimate."""
        doc = {"config": config, "best": best, "best_logp": best_logp, "cov": cov}
        with atomic_write(self.config_path, "w") as fh:
            fh.write(json.dumps(plain(doc), indent=1) + "\n")

    def read_checkpoint(self, config: dict | None = None) -> dict | None:
        """The checkpoint: ``{"progress": dict, "ensembles": [dict of arrays, ...]}``, or None.

        The file is read as data by :func:`gonio.safeh5.read_h5`, the one reader of
        ``checkpoint.h5`` (the resume, ``plan FITDIR``): opened once (no link, no FIFO, no
        larger than :func:`gonio.memory.memory_limit`), its structure checked against what
        the fit of ``config`` writes (:func:`checkpoint_layout`: its ensembles, walkers and
        free parameters; no link but hard links to nodes of its own, no external, virtual or
        chunked storage) and the values it declares against the memory limit, before any
        value is read; then the values are checked (:func:`check_checkpoint`).

        Parameters
        ----------
        config : dict, optional
            The fit's configuration (``fit_config.json``'s ``config``, checked equal by
            :meth:`read_start`); None: read from ``fit_config.json``.

        Raises
        ------
        ValueError
            One line naming the file: not a regular file, a structure or value that is not
            what the fit writes, more than memory allows, or not readable.
        """
        path = self.checkpoint_path
        if not os.path.lexists(path):          # a link is refused by the reader, not skipped
            return None
        if config is None:
            try:
                config = read_config(self.config_path)["config"]
            except ValueError as exc:
                raise self._corrupt(exc) from None
        layout, bounds = checkpoint_layout(*_shape_of(self.config_path, config))
        try:
            doc = read_h5(path, layout, what="a fit's checkpoint", max_bytes=memory_limit()[0],
                          bounds=bounds, change="chains this long need more memory than this "
                          "machine allows")
            progress = doc["attr:progress"]
            n = FileFields(path).integer(doc, "attr:ensembles", lo=len(layout.entries),
                                         hi=len(layout.entries))
            ens = [doc[f"ensemble_{k}"] for k in range(n)]
            if not isinstance(progress, str):
                raise ValueError(f"progress must be JSON text; got {type(progress).__name__}")
            progress = loads_json(progress, path, "checkpoint's progress")
            check_checkpoint(path, progress, ens)
        except (OSError, KeyError, ValueError, TypeError, RecursionError) as exc:
            text = (str(exc) if str(exc).startswith(f"{path}: ") else
                    f"{path}: corrupt or unreadable checkpoint ({exc})")
            raise ValueError(f"{text}; delete it (or the whole output folder) to start "
                             f"again") from None
        return {"progress": progress, "ensembles": ens}

    def write_checkpoint(self, progress: dict, ensembles: list[dict]):
        """Write the checkpoint whole: ``progress`` (JSON-able) and, per ensemble, a dict of
        arrays (a nested dict becomes an HDF5 group; keys ``attr:NAME`` become attributes)."""
        with atomic_write(self.checkpoint_path, "wb") as fh:
            with h5py.File(fh, "w") as f:
                f.attrs["progress"] = json.dumps(plain(progress))
                f.attrs["ensembles"] = len(ensembles)
                for k, doc in enumerate(ensembles):
                    _write_node(f.create_group(f"ensemble_{k}"), doc)


def _shape_of(path, config: dict) -> tuple[int, int, int]:
    """(ensembles, walkers, free parameters) of a fit configuration, checked."""
    f = FileFields(path)
    cfg = f.mapping({"config": config}, "config")
    free = f.mapping(cfg, "spec", "config").get("free")
    if not isinstance(free, list) or not free:
        raise f.error("config.spec.free", "a list of parameter names", free)
    return (f.integer(cfg, "ensembles", "config", lo=1, hi=MAX_ENSEMBLES),
            f.integer(cfg, "walkers", "config", lo=2, hi=MAX_WALKERS), len(free))


def checkpoint_layout(ensembles: int, walkers: int, ndim: int) -> tuple[H5Group, dict]:
    """What :meth:`FitFolder.write_checkpoint` writes for a fit of ``ensembles`` ensembles of
    ``walkers`` walkers in ``ndim`` free parameters, as :func:`gonio.safeh5.read_h5`'s layout,
    and the bounds of its free lengths (mixture components, importance draws; the steps are
    bounded by the memory limit).

    Examples
    --------
    >>> layout, bounds = checkpoint_layout(2, 6, 2)
    >>> sorted(layout.entries), layout.entries["ensemble_0"].entries["chain"].shape
    (['ensemble_0', 'ensemble_1'], ('steps@0', 6, 2))
    >>> layout.nodes(), bounds["components"]
    (27, 8)
    """
    def one(k):
        steps, comps = f"steps@{k}", f"components@{k}"
        rng = H5Group({"keys": H5Data((624,), "int")},
                      attrs={"pos": "int", "has_gauss": "int", "cached": "number"})
        proposal = H5Group({"means": H5Data((comps, ndim)), "chols": H5Data((comps, ndim, ndim)),
                            "weights": H5Data((comps,)), "warps": H5Data((ndim,), "int"),
                            "df": H5Data(()), "draw_lw": H5Data((f"draws@{k}",))},
                           attrs={"share": "number", "last_kept": "int"},
                           optional=frozenset({"draw_lw"}))
        return H5Group({"chain": H5Data((steps, walkers, ndim)),
                        "log_prob": H5Data((steps, walkers)), "accepted": H5Data((walkers,)),
                        "rng": rng, "proposal": proposal})
    root = H5Group({f"ensemble_{k}": one(k) for k in range(ensembles)},
                   attrs={"progress": "text", "ensembles": "int"})
    return root, {"components": max(proposal.MIXTURE_COMPONENTS), "draws": MAX_DRAWS}


def read_config(path) -> dict:
    """A ``fit_config.json``, every field the readers use checked: ``config.spec`` (``free``
    a list of names, ``params`` each with finite ``lo``, ``hi``, ``default`` and string
    ``prior``/``unit``, ``ties`` target -> [source, "equal" or "complement"] among the
    params, ``periods`` and ``folds`` a parameter's name -> a number >= 0),
    ``config.model`` (a string; absent: ``microcylinder``), ``config.extra``
    (``fabric``/``preset`` a string, ``options`` an object).

    Raises
    ------
    ValueError
        ``PATH: FIELD must be ...; got ...`` (or PATH: not JSON).
    """
    f = FileFields(path)
    doc = load_json(path, "fit configuration")
    if not isinstance(doc, dict):
        raise ValueError(f"{path}: not a fit configuration (not a JSON object)")
    cfg = f.mapping(doc, "config")
    f.string(cfg, "model", "config", default="microcylinder")   # absent before models
    spec = f.mapping(cfg, "spec", "config")
    params = f.mapping(spec, "params", "config.spec")
    for name in params:
        where = f"config.spec.params.{name}"
        f.mapping(params, name, "config.spec.params")
        for k in ("lo", "hi", "default"):
            f.number(params[name], k, where)
        for k in ("prior", "unit"):
            f.string(params[name], k, where, default="")
    free = spec.get("free")
    if not isinstance(free, list) or not all(isinstance(n, str) for n in free):
        raise f.error("config.spec.free", "a list of parameter names", free)
    ties = f.mapping(spec, "ties", "config.spec", default={})
    for target, tie in ties.items():
        if not (isinstance(tie, list) and len(tie) == 2 and tie[0] in params
                and tie[1] in ("equal", "complement") and target in params):
            raise f.error(f"config.spec.ties.{target}", "[SOURCE, \"equal\" or "
                          "\"complement\"] with SOURCE and the target among the parameters",
                          tie)
    for key in ("periods", "folds"):            # name -> a positive angle or a fold's value
        for name, v in f.mapping(spec, key, "config.spec", default={}).items():
            if name not in params:
                raise f.error(f"config.spec.{key}.{name}", "a parameter's name", name)
            f.number(spec[key], name, f"config.spec.{key}", lo=0.0)
    extra = f.mapping(cfg, "extra", "config", default={})
    for k in ("fabric", "preset"):
        f.string(extra, k, "config.extra", default=None, none=True)
    f.mapping(extra, "options", "config.extra", default=None)
    return doc


def check_checkpoint(path, progress, ensembles: list[dict]) -> None:
    """Check a checkpoint's ``progress`` and every ensemble's arrays (shapes consistent with
    its chain (steps, walkers, ndim), all finite; the random state's 624 keys, position,
    cached normal; the proposal's mixture); ``ValueError`` naming the file and the field."""
    f = FileFields(path)
    f.mapping({"progress": progress}, "progress")
    f.integer(progress, "checked_step", "progress", lo=0, none=True)
    f.integer(progress, "next_refit", "progress", lo=0)
    for k in ("tau_before", "tau_last"):
        f.array(progress, k, "progress", shape=(None,), finite=False, none=True)
    f.mapping(progress, "proposal", "progress")
    shape = None
    for k, g in enumerate(ensembles):
        where = f"ensemble_{k}"
        chain = f.array(g, "chain", where, shape=(None, None, None) if shape is None else
                        (None,) + shape)
        n, w, d = chain.shape
        if n < 1 or w < 2 or d < 1:
            raise f.error(f"{where}.chain", "steps x walkers x parameters, at least 1 x 2 x 1",
                          got=f"shape {chain.shape}")
        shape = (w, d)
        lp = f.array(g, "log_prob", where, shape=(n, w), finite=False)
        if np.any(np.isnan(lp) | (lp == np.inf)):
            raise f.error(f"{where}.log_prob", "numbers below +inf", got="NaN or +inf")
        f.array(g, "accepted", where, shape=(w,))
        _check_rng(f, f.mapping(g, "rng", where), f"{where}.rng")
        _check_proposal(f, f.mapping(g, "proposal", where), f"{where}.proposal", d)


def _check_rng(f: FileFields, r: dict, where: str) -> None:
    """The MT19937 state of numpy's RandomState: 624 keys, position, cached normal."""
    f.array(r, "keys", where, shape=(624,), integer=True)
    f.integer(r, "attr:pos", where, lo=0, hi=624)
    f.integer(r, "attr:has_gauss", where, lo=0, hi=1)
    f.number(r, "attr:cached", where)


def _check_proposal(f: FileFields, p: dict, where: str, d: int) -> None:
    """The independence proposal: K components of means (K, d), Cholesky factors (K, d, d)
    with a positive diagonal, weights (K,) > 0, warps (d,), df > 0."""
    means = f.array(p, "means", where, shape=(None, d))
    k = means.shape[0]
    chols = f.array(p, "chols", where, shape=(k, d, d))
    if k < 1 or not np.all(np.diagonal(chols, axis1=1, axis2=2) > 0):
        raise f.error(f"{where}.chols", "Cholesky factors with a positive diagonal",
                      got=f"{k} component(s)" if k < 1 else "a diagonal entry <= 0")
    weights = f.array(p, "weights", where, shape=(k,))
    if not np.all(weights > 0):
        raise f.error(f"{where}.weights", "positive numbers", weights.tolist())
    f.array(p, "warps", where, shape=(d,), integer=True)
    if f.number(p, "df", where, lo=0) == 0:
        raise f.error(f"{where}.df", "a finite number > 0", p["df"])
    f.number(p, "attr:share", where, lo=0, hi=1)
    f.integer(p, "attr:last_kept", where, lo=0)
    f.array(p, "draw_lw", where, shape=(None,), finite=False, default=None)


def _write_node(group, doc: dict):
    for key, value in doc.items():
        if key.startswith("attr:"):
            group.attrs[key[5:]] = value
        elif isinstance(value, dict):
            _write_node(group.create_group(key), value)
        elif value is not None:
            group[key] = np.asarray(value)
