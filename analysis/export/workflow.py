"""What ``microcyl export`` does: project, measure the fidelity, write the file and its
fidelity beside it.

:func:`export_fabric` takes a resolved FABRIC (:func:`analysis.sources.resolve`), a target of
:data:`analysis.export.TARGETS` and an output path. For a target with a model it projects the
source onto it (:func:`analysis.export.projection.project`; for a fit folder the medians and
``draws`` posterior draws, :func:`~analysis.export.projection.project_draws`), measures the
fidelity of the projected model to the source (:func:`analysis.export.fidelity.fidelity`) and
writes ``FILE.fidelity.json`` and then ``FILE``, each atomically: an export is never written
without its fidelity. The Mitsuba target writes the fabric itself (its fidelity is exact by
construction and measured all the same).
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np

from analysis.export import TARGETS, target_named
from analysis.export.fidelity import fidelity, summary_lines
from analysis.export.grid import DEFAULT_GRID, HemisphereGrid
from analysis.export.projection import Projection, project_draws
from analysis.export.scale import Scaled, check_albedo_scale, relative_fit, scale_report
from analysis.fit.medians import fabric_at
from analysis.planning.draws import fit_folder_spec, posterior_draws
from gonio.atomic import atomic_write
from gonio.safeopen import read_bytes
from gonio.jsonplain import plain

__all__ = ["ExportResult", "export_fabric", "fidelity_path", "DEFAULT_DRAWS"]

#: Posterior draws projected for a fit folder.
DEFAULT_DRAWS = 40


@dataclasses.dataclass(frozen=True)
class ExportResult:
    """What an export wrote and measured.

    Attributes
    ----------
    path, fidelity_path : pathlib.Path
        The export and its ``.fidelity.json``.
    target : str
    projection : Projection or None
        None for the Mitsuba target (the fabric itself).
    fidelity : dict
        :func:`analysis.export.fidelity.fidelity`'s document.
    notes : tuple of str
    """

    path: Path
    fidelity_path: Path
    target: str
    projection: Projection | None
    fidelity: dict
    notes: tuple = ()

    def lines(self) -> list[str]:
        """What the terminal shows."""
        out = [f"{self.target}: the fabric itself -> {self.path}"]
        if self.projection is not None:
            v = self.projection.values
            rgb = ", ".join
            out[0] = f"{self.target} ({self.projection.model} projection) -> {self.path}"
            out.append(f"  base "
                       f"({rgb(f'{c:.3f}' for c in v['base'])}), sheen "
                       f"({rgb(f'{c:.3f}' for c in v['sheen'])}), roughness "
                       f"{v['roughness']:.3f}")
            iv = self.projection.intervals
            if iv:
                out.append(f"  95% over {self.projection.draws} posterior draws: roughness "
                           f"[{iv['roughness'][0]:.3f}, {iv['roughness'][1]:.3f}]")
        out += [f"  {line}" for line in summary_lines(self.fidelity)]
        out += [f"  note: {n}" for n in self.notes]
        return out


def fidelity_path(path) -> Path:
    """``FILE.fidelity.json`` beside ``FILE``."""
    path = Path(path)
    return path.with_name(path.name + ".fidelity.json")


def _draw_sources(src, draws: int, seed: int) -> tuple[list, list[str]]:
    """The fabrics (or baseline models) at ``draws`` posterior draws of a fit folder."""
    if src.kind != "fit" or draws == 0:
        return [], []
    med = src.median
    try:
        spec = fit_folder_spec(src.path)[0]
        thetas = posterior_draws(src.path, spec, draws, np.random.default_rng(seed))
    except ValueError as exc:
        return [], [f"posterior draws not projected ({exc}); the medians only"]
    values = spec.values(thetas)
    out, refused = [], []
    for k in range(len(thetas)):
        try:
            out.append(fabric_at(med, src.path, {n: float(values[n][k]) for n in spec.params}))
        except ValueError as exc:
            refused.append(str(exc))
    notes = []
    if refused:
        notes.append(f"{len(refused)} of {len(thetas)} posterior draws make no valid fabric "
                     f"and were left out (first: {refused[0][:120]})")
    return out, notes


def _earlier_fidelity(fpath: Path) -> bytes | None:
    """The bytes of an earlier export's fidelity file at ``fpath`` (a regular file under
    1 MiB), to put back should this export fail; None otherwise."""
    try:
        return read_bytes(fpath, max_bytes=1 << 20) if fpath.is_file() else None
    except (OSError, ValueError):
        return None


def export_fabric(src, target: str, path, *, grid: HemisphereGrid = DEFAULT_GRID,
                  draws: int = DEFAULT_DRAWS, seed: int = 0,
                  objective: str = "cos_cos", albedo_scale: float | None = None
                  ) -> ExportResult:
    """Export the resolved FABRIC ``src`` to ``target`` at ``path`` (module notes).

    Parameters
    ----------
    src : analysis.sources.Source
    target : str
        A name of :data:`analysis.export.TARGETS`.
    path : path
        The file to write; its suffix must be one of the target's.
    grid : HemisphereGrid
        Where the projection is fitted and the fidelity measured.
    draws : int
        Posterior draws of a fit folder to project (0: the medians only), 0 to 1000.
    seed : int
        Picks the draws.
    objective : str
        What the projection fits (:data:`analysis.export.projection.OBJECTIVES`).
    albedo_scale : float, optional
        A factor on the source's f_r before the projection (``--albedo-scale``), for a fit
        of a relative table whose absolute level the user knows
        (:mod:`analysis.export.scale`); not for the Mitsuba target.

    Returns
    -------
    ExportResult

    Raises
    ------
    ValueError
        A suffix the target does not write, a source the target cannot take (a baseline
        model or a table for Mitsuba, a measured table for any), draws out of range.
    """
    tgt = target_named(target)
    path = Path(path)
    k = _check_request(tgt, path, src, draws, albedo_scale)
    path, settled_note = tgt.settled(path)
    rel = relative_fit(src)
    source = src.brdf if k is None else Scaled(src.brdf, k)
    if tgt.model is None:
        if not src.is_fabric:
            raise ValueError(f"--to {tgt.name}: the Mitsuba plugin is the microcylinder "
                             f"fabric; {src.label} is {src.what} (export it --to "
                             f"{', '.join(n for n, t in TARGETS.items() if t.model)})")
        proj, target_brdf, notes = None, src.brdf, []
    else:
        sources, notes = _draw_sources(src, draws, seed)
        if k is not None:
            sources = [Scaled(b, k) for b in sources]
        proj = project_draws(source, sources, tgt.model, grid, objective)
        target_brdf = proj.brdf()
    fid = fidelity(source, target_brdf, grid)
    scale_doc, scale_note = scale_report(src, rel, k, fid)
    notes += [n for n in (scale_note, settled_note) if n]
    doc = {"file": path.name, "target": tgt.name, "target_conventions": tgt.describe,
           "source": {"label": src.label, "kind": src.kind, "model": src.model,
                      "path": None if src.path is None else str(src.path)},
           "projection": None if proj is None else proj.as_dict(),
           "scale": scale_doc, "fidelity": fid, "notes": notes}
    fpath = fidelity_path(path)
    _write_both(fpath, doc, lambda: (tgt.write(path, src.brdf, src.preset) if proj is None
                                     else tgt.write(path, proj, src.label)))
    return ExportResult(path, fpath, tgt.name, proj, fid, tuple(notes))


def _check_request(tgt, path: Path, src, draws, albedo_scale) -> float | None:
    """The request's checks, before any work (one ValueError line each); the factor of
    ``--albedo-scale`` (None without one)."""
    if path.suffix.lower() not in tgt.suffixes:
        raise ValueError(f"-o {str(path)!r}: the {tgt.name} target writes "
                         f"{' or '.join(tgt.suffixes)}")
    if not isinstance(draws, int) or isinstance(draws, bool) or not 0 <= draws <= 1000:
        raise ValueError(f"--draws {draws!r}: must be an integer in [0, 1000]")
    if src.kind == "table":
        raise ValueError(f"{src.label}: a measured table is exported by fitting it first "
                         f"(`microcyl fit`), then exporting the fit folder")
    k = check_albedo_scale(albedo_scale)
    if k is not None and tgt.model is None:
        raise ValueError(f"--albedo-scale {albedo_scale!r}: the {tgt.name} target writes the "
                         f"fabric itself, whose f_r no parameter scales as a whole; export "
                         f"--to {', '.join(n for n, t in TARGETS.items() if t.model)}")
    return k


def _write_both(fpath: Path, doc: dict, write_export) -> None:
    """The fidelity file, then the export (``write_export()``); when the export fails
    (Blender's .blend), the fidelity file as it was before (removed, or an earlier export's
    put back) and the error raised."""
    earlier = _earlier_fidelity(fpath)
    with atomic_write(fpath, "w") as fh:
        fh.write(json.dumps(plain(doc), indent=1, allow_nan=False) + "\n")
    try:
        write_export()
    except BaseException:
        if earlier is None:
            fpath.unlink(missing_ok=True)
        else:
            with atomic_write(fpath, "wb") as fh:
                fh.write(earlier)
        raise
