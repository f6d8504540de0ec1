"""What a FABRIC argument names: the one resolver of every verb's BRDF source.

A source is one of

- a preset of :data:`brdf.PRESETS` (``velvet``);
- a fit's output folder, or its ``results.json`` (the fabric of its posterior medians,
  :func:`analysis.fit.medians.median_fabric`: what ``microcyl export`` writes, without the
  fit's overall ``scale``, which only calibrates relative tables);
- a fabric file of ``microcyl export``: the plugin dictionary (``.json``) or its ``<bsdf>``
  element (``.xml``), :func:`analysis.fabricfile.read_fabric_file`;
- an export for a renderer read back as microcyl's model of what the renderer evaluates
  (:data:`analysis.export.TARGETS`): a ``.mtlx`` (OpenPBR ``open_pbr_surface`` or MaterialX
  ``sheen_bsdf`` mode zeltner over a diffuse base: :class:`brdf.baselines.Zeltner`) or a
  ``.gltf`` / ``.glb`` (KHR_materials_sheen: :class:`brdf.baselines.Charlie`);
- where the caller takes any BRDF (``tables=True``), a measured table that evaluates between
  its samples: an RGL ``.bsdf`` (:func:`gonio.load_rgl`) or a MERL ``.binary``
  (:func:`gonio.load_merl`).

:func:`resolve` returns a :class:`Source`: its kind, a label for tables and legends, the
BRDF (a :class:`brdf.Fabric` for every kind but ``table``) and the path it came from.
:data:`Source.model` names the model a fit is of: ``microcylinder``, or a baseline model
(``lambert``, ...; :data:`brdf.MODELS`) whose :attr:`Source.brdf` is that model at the
fit's posterior medians (a :class:`brdf.Model`: ``eval``, ``sample``,
``pdf``, not a fabric: fabric-only options refuse it).
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import brdf
import gonio
from analysis.export import read_suffixes
from analysis.fabricfile import SUFFIXES as FABRIC_SUFFIXES
from analysis.fabricfile import read_fabric_file
from analysis.fit.medians import median_fabric

__all__ = ["Source", "resolve", "resolve_all", "accepted", "KINDS", "TABLE_SUFFIXES"]

#: The kinds of source, in the order :func:`accepted` names them.
KINDS = ("preset", "fit", "json", "xml", "mtlx", "gltf", "glb", "table")
#: Suffixes of the measured tables a BRDF-taking verb evaluates directly.
TABLE_SUFFIXES = (".bsdf", ".binary")


@dataclasses.dataclass(frozen=True)
class Source:
    """A resolved FABRIC argument.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    label : str
        What tables, legends and pages call it: the preset's name, else the file's or
        folder's name without suffix (``fit`` for ``runs/fit/``).
    brdf : object
        The BRDF: a :class:`brdf.Fabric`, a baseline model (a fit of one), or for a table
        its evaluator (``eval(wi, wo)``, f_r in 1/sr, shape (..., 3)).
    path : pathlib.Path or None
        The file or folder it was read from (None for a preset).
    preset : str or None
        The preset the fabric derives from (a fit's start, a file's ``fabric`` key).
    model : str
        The model of the BRDF: ``microcylinder``, a baseline's name for a fit of one, or
        ``measured`` for a table.
    median : analysis.fit.medians.MedianFabric or None
        For a fit folder, its posterior medians as read once when it was resolved (values,
        free set, ``scale``), which :attr:`brdf` is built from; None for any other kind.
    """

    kind: str
    label: str
    brdf: object
    path: Path | None = None
    preset: str | None = None
    model: str = brdf.DEFAULT_MODEL
    median: object = dataclasses.field(default=None, compare=False, repr=False)

    @property
    def is_fabric(self) -> bool:
        """Whether :attr:`brdf` is a :class:`brdf.Fabric` (variant options apply)."""
        return isinstance(self.brdf, brdf.Fabric)

    @property
    def fabric(self) -> brdf.Fabric:
        """The :class:`brdf.Fabric`; a ValueError for a measured table."""
        if not self.is_fabric:
            raise ValueError(f"{self.label}: {self.what}, not a fabric (the microcylinder "
                             f"fabric's options and parameters do not apply)")
        return self.brdf

    @property
    def what(self) -> str:
        """What the source is when not a fabric, in words (for refusals)."""
        if self.kind == "table":
            return "a measured table"
        if self.kind == "fit":
            return f"a fit of model {self.model}"
        return f"a .{self.kind} export read back as model {self.model}"

    def with_options(self, **options) -> "Source":
        """The same source with the fabric's variant options changed (``masking``,
        ``rotation`` in radians, ...); unchanged when ``options`` is empty. A table
        refuses options (a ValueError naming them)."""
        if not options:
            return self
        if not self.is_fabric:
            raise ValueError(f"{self.label}: {self.what} takes no model option "
                             f"({', '.join(sorted(options))})")
        return dataclasses.replace(self, brdf=self.brdf.replace(**options))


def accepted(tables: bool = False) -> str:
    """What a FABRIC argument may be, in words (the one error's tail).

    Examples
    --------
    >>> accepted().startswith("a preset (linen_plain, ")
    True
    """
    kinds = [f"a preset ({', '.join(brdf.PRESETS)})", "a `microcyl fit` output folder",
             f"a {' or '.join(FABRIC_SUFFIXES)} fabric file or a "
             f"{' or '.join(read_suffixes())} export of `microcyl export`"]
    if tables:
        kinds.append(f"a measured table ({' or '.join(TABLE_SUFFIXES)})")
    return ", ".join(kinds[:-1]) + " or " + kinds[-1]


def _label(path: Path) -> str:
    name = path.name if path.name not in ("", ".", "..") else path.resolve().name
    return Path(name).stem or name or "fabric"


def _fit(text: str, path: Path, what: str, preset: str | None) -> Source:
    folder = path if path.is_dir() else path.parent
    try:
        med = median_fabric(folder, preset=preset)
    except ValueError as exc:
        raise ValueError(f"{what} {text!r}: not a fit folder: {exc}") from None
    return Source("fit", _label(folder), med.fabric, folder, med.preset, med.model_name, med)


def resolve(text, *, what: str = "FABRIC", tables: bool = False,
            preset: str | None = None, options: dict | None = None) -> Source:
    """The source that a FABRIC argument names.

    Parameters
    ----------
    text : str or os.PathLike
        A preset's name, a fit folder (or its ``results.json``), a ``.json`` or ``.xml``
        fabric file, or (with ``tables``) a measured ``.bsdf`` or ``.binary`` table.
    what : str
        The argument's name in error messages (``FABRIC``, ``--fabric``, ``--fit``).
    tables : bool
        Whether the caller takes any BRDF (a measured table too).
    preset : str, optional
        For a fit whose ``fit_config.json`` does not name its preset.
    options : dict, optional
        Variant options of the fabric (``masking``, ``rotation`` in radians, ...) replacing
        its own (:meth:`Source.with_options`); a table refuses them.

    Returns
    -------
    Source

    Raises
    ------
    ValueError
        One line naming the argument and the value: for a name that is no preset and no
        file or folder, what is accepted (:func:`accepted`); else what is wrong with the file.

    Examples
    --------
    >>> s = resolve("velvet")
    >>> s.kind, s.label, s.brdf.name
    ('preset', 'velvet', 'velvet')
    >>> resolve("denim")
    Traceback (most recent call last):
    ...
    ValueError: FABRIC 'denim': not a preset (linen_plain, silk_crepe_de_chine, polyester_satin_charmeuse, polyester_satin_charmeuse_back, silk_shot, velvet), a `microcyl fit` output folder or a .json or .xml fabric file or a .mtlx or .gltf or .glb export of `microcyl export`
    """
    text = str(text)
    if text in brdf.PRESETS:
        return Source("preset", text, brdf.fabric(text, **(options or {})), None, text)
    if not text.strip():
        raise ValueError(f"{what} is empty; expected {accepted(tables)}")
    return _resolve_path(text, what, tables, preset).with_options(**(options or {}))


def _resolve_path(text: str, what: str, tables: bool, preset: str | None) -> Source:
    """:func:`resolve` of a name that is no preset: a folder or a file."""
    path = Path(text)
    suffix = path.suffix.lower()
    # a file here may be a link or a FIFO: its reader (safeopen) refuses it by name, at once
    is_file = os.path.lexists(path) and not path.is_dir()
    if path.is_dir() or (path.name == "results.json" and is_file):
        return _fit(text, path, what, preset)
    if is_file and suffix in FABRIC_SUFFIXES:
        try:
            fab = read_fabric_file(path)
        except ValueError as exc:
            raise ValueError(f"{what} {text!r}: {str(exc).removeprefix(f'{path}: ')}") \
                from None
        return Source(suffix[1:], _label(path), fab, path, fab.name)
    readers = read_suffixes()
    if is_file and suffix in readers:
        try:
            model = readers[suffix].read(path)
        except ValueError as exc:
            raise ValueError(f"{what} {text!r}: {str(exc).removeprefix(f'{path}: ')}") \
                from None
        return Source(suffix[1:], _label(path), model, path, None, model.name)
    if tables and is_file and suffix in TABLE_SUFFIXES:
        load = gonio.load_rgl if suffix == ".bsdf" else gonio.load_merl
        try:
            table = load(path)
        except (ValueError, OSError) as exc:
            raise ValueError(f"{what} {text!r}: not a readable {suffix} table: {exc}") \
                from None
        return Source("table", _label(path), table, path, None, "measured")
    if not path.exists():
        raise ValueError(f"{what} {text!r}: not {accepted(tables)}")
    raise ValueError(f"{what} {text!r}: not a fabric source; expected {accepted(tables)}")


def resolve_all(texts, *, what: str = "FABRIC", tables: bool = False,
                options: dict | None = None) -> list[Source]:
    """:func:`resolve` each of ``texts``, with the variant ``options`` applied to each
    fabric (a table refuses them); two sources of one label are refused by name.

    Raises
    ------
    ValueError
        What :func:`resolve` raises, or a label given twice.
    """
    out = [resolve(t, what=what, tables=tables, options=options) for t in texts]
    labels = [s.label for s in out]
    twice = sorted({n for n in labels if labels.count(n) > 1})
    if twice:
        raise ValueError(f"{what}: {', '.join(map(repr, twice))} given twice (each source "
                         f"is named by its preset, file or folder name)")
    return out
