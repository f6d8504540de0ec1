"""gonio: a virtual gonioreflectometer, and BRDF tables in the formats of the field."""

from gonio.geometry import (Geometry, full_grid, merl, pairs, pairs_from_angles, plane,
                            rusinkiewicz)
from gonio.instrument import Instrument
from gonio.measure import measure
from gonio.table import Table

__all__ = [
    "Table",
    "Geometry",
    "Instrument",
    "measure",
    "full_grid",
    "plane",
    "rusinkiewicz",
    "merl",
    "pairs",
    "pairs_from_angles",
]
