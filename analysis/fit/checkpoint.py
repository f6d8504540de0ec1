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
from pathlib import Path

import h5py
import numpy as np

from gonio import atomic_write
from gonio.jsonplain import plain
from gonio.statefields import FileFields, load_json, loads_json

__all__ = ["FitFolder", "table_digest", "read_config", "CONFIG_FILE", "CHECKPOINT_FILE"]

CONFIG_FILE = "fit_config.json"
CHECKPOINT_FILE = "checkpoint.h5"
#: Most ensembles a checkpoint may hold (``--ensembles`` is at most 64).
MAX_ENSEMBLES = 1024


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

    def read_checkpoint(self) -> dict | None:
        """The checkpoint: ``{"progress": dict, "ensembles": [dict of arrays, ...]}``, or None.

        Raises
        ------
        ValueError
            When the file cannot be read.
        """
        if not self.checkpoint_path.exists():
            return None
        path = self.checkpoint_path
        try:
            with h5py.File(path, "r") as f:
                progress = f.attrs["progress"]
                n = FileFields(path).integer(f.attrs, "ensembles", lo=1, hi=MAX_ENSEMBLES)
                ens = []
                for k in range(n):
                    g = f[f"ensemble_{k}"]
                    ens.append({name: _read_node(g[name]) for name in g})
                    ens[-1].update({f"attr:{a}": v for a, v in g.attrs.items()})
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


def read_config(path) -> dict:
    """A ``fit_config.json``, every field the readers use checked: ``config.spec`` (``free``
    a list of names, ``params`` each with finite ``lo``, ``hi``, ``default`` and string
    ``prior``/``unit``, ``ties`` target -> [source, "equal" or "complement"] among the
    params), ``config.model`` (a string; absent: ``microcylinder``), ``config.extra``
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
                          f"\"complement\"] with SOURCE and the target among the parameters",
                          tie)
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


def _read_node(node):
    if isinstance(node, h5py.Group):
        out = {name: _read_node(node[name]) for name in node}
        out.update({f"attr:{a}": v for a, v in node.attrs.items()})
        return out
    return node[()]
