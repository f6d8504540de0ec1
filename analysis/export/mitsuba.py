"""The Mitsuba 3 target: the microcylinder plugin's dictionary (.json) or element (.xml).

The fabric itself is written (:func:`analysis.fabricfile.write_fabric_file`), not a
projection: the Mitsuba plugin evaluates microcyl's model. Only a microcylinder fabric has
this target; a baseline fit is refused by :func:`analysis.export.workflow.export_fabric`.

Examples
--------
>>> MITSUBA.name, MITSUBA.suffixes, MITSUBA.model
('mitsuba', ('.json', '.xml'), None)
"""

from __future__ import annotations

from analysis.export.target import Target
from analysis.fabricfile import SUFFIXES, read_fabric_file, write_fabric_file

__all__ = ["MITSUBA"]


def _write(path, fabric, preset):
    write_fabric_file(path, fabric, preset)


MITSUBA = Target("mitsuba", SUFFIXES, None, _write, read_fabric_file,
                 "Mitsuba 3 BSDF 'microcylinder' (reports.mitsuba.plugin): every thread "
                 "parameter and option of the fabric itself")
