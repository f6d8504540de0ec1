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
from pathlib import Path

import h5py
import numpy as np

from gonio import atomic_write
from gonio.jsonplain import plain

__all__ = ["FitFolder", "table_digest", "CONFIG_FILE", "CHECKPOINT_FILE"]

CONFIG_FILE = "fit_config.json"
CHECKPOINT_FILE = "checkpoint.h5"


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
            stored = json.loads(self.config_path.read_text())
            stored_cfg = stored["config"]
        except (ValueError, KeyError, TypeError) as exc:
            raise ValueError(f"{self.config_path}: corrupt fit configuration ({exc}); delete "
                             f"the folder to start again") from None
        config = plain(config)
        if config != stored_cfg:
            diff = sorted(k for k in set(config) | set(stored_cfg)
                          if config.get(k) != stored_cfg.get(k))
            raise ValueError(f"{self.path} holds a fit with another configuration (differs in: "
                             f"{', '.join(diff)}); use another output folder or delete it")
        cov = stored.get("cov")
        return {"best": np.asarray(stored["best"], dtype=np.float64),
                "best_logp": float(stored["best_logp"]),
                "cov": None if cov is None else np.asarray(cov, dtype=np.float64)}

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
        try:
            with h5py.File(self.checkpoint_path, "r") as f:
                progress = json.loads(f.attrs["progress"])
                ens = []
                for k in range(int(f.attrs["ensembles"])):
                    g = f[f"ensemble_{k}"]
                    ens.append({name: _read_node(g[name]) for name in g})
                    ens[-1].update({f"attr:{a}": v for a, v in g.attrs.items()})
        except (OSError, KeyError, ValueError, TypeError) as exc:
            raise ValueError(f"{self.checkpoint_path}: corrupt or unreadable checkpoint "
                             f"({exc}); delete it (or the whole output folder) to start "
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
