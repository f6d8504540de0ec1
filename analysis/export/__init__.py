"""A fabric exported to the renderers people use, with the fidelity of each export.

``microcyl export FABRIC --to TARGET -o FILE``: the target's model projected from the source
(:mod:`~analysis.export.projection`, over :mod:`~analysis.export.grid`'s stated grid), written
in the target's format, and its fidelity (:mod:`~analysis.export.fidelity`) written beside it
as ``FILE.fidelity.json`` (:func:`~analysis.export.workflow.export_fabric`). :data:`TARGETS`
is the registry: a new target is its module (a :class:`~analysis.export.target.Target`) plus
one line here.

Examples
--------
>>> list(TARGETS)
['mitsuba', 'openpbr', 'materialx', 'gltf', 'blender']
>>> target_for("out.glb").name, target_for("out.mtlx").name
('gltf', 'openpbr')
"""

from __future__ import annotations

from analysis.export.blender import BLENDER
from analysis.export.fidelity import fidelity, summary_lines
from analysis.export.gltf import GLTF
from analysis.export.grid import DEFAULT_GRID, HemisphereGrid
from analysis.export.mitsuba import MITSUBA
from analysis.export.mtlx import MATERIALX, OPENPBR
from analysis.export.projection import Projection, project, project_draws
from analysis.export.target import Target

__all__ = ["TARGETS", "Target", "target_named", "target_for", "read_suffixes", "fidelity",
           "summary_lines", "HemisphereGrid", "DEFAULT_GRID", "Projection", "project",
           "project_draws"]

#: The export targets by ``--to`` name (the first with a suffix is that suffix's default).
TARGETS: dict[str, Target] = {t.name: t for t in (MITSUBA, OPENPBR, MATERIALX, GLTF, BLENDER)}


def target_named(name: str) -> Target:
    """The target ``name``; one ValueError line listing the targets otherwise."""
    try:
        return TARGETS[name]
    except (KeyError, TypeError):
        raise ValueError(f"--to {name!r}: not a target; targets: {', '.join(TARGETS)}") \
            from None


def target_for(path) -> Target:
    """The default target of a file name's suffix (the first target that writes it)."""
    suffix = "." + str(path).rsplit(".", 1)[-1].lower() if "." in str(path) else ""
    for t in TARGETS.values():
        if suffix in t.suffixes:
            return t
    raise ValueError(f"-o {str(path)!r}: must end in "
                     f"{', '.join(dict.fromkeys(s for t in TARGETS.values() for s in t.suffixes))} (no target "
                     f"writes {suffix or 'a file without suffix'})")


def read_suffixes() -> dict:
    """Suffix -> target of the exports that read back as a FABRIC (besides Mitsuba's)."""
    return {s: t for t in TARGETS.values() if t.read is not None and t.model is not None
            for s in t.suffixes}
