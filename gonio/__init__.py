"""gonio: a virtual gonioreflectometer, and BRDF tables in the formats of the field.

Naming: ``read_*`` returns a :class:`Table`, ``load_*`` an evaluable BRDF (``eval(wi, wo)``).
``load_curet`` and ``merl_table`` are deprecated aliases of ``read_curet`` and ``read_merl``.
"""

from gonio.alta import read_alta, write_alta
from gonio.atomic import atomic_write
from gonio.progress import progress_bar
from gonio.jsonplain import json_line, meta_text, plain
from gonio.csvtable import read_csv
from gonio.csvwrite import write_csv
from gonio.curet import load_curet, read_curet
from gonio.errors import FormatError, TableWarning
from gonio.exr import read_exr, write_exr
from gonio.geometry import Geometry
from gonio.layouts import full_grid, pairs, pairs_from_angles, plane, rusinkiewicz
from gonio.layouts import merl as merl_grid
from gonio.geomspec import from_spec
from gonio.instrument import Instrument
from gonio.io import read, write
from gonio.measure import measure
from gonio.pairsfile import read_pairs_header, write_pairs_csv
from gonio.travel import order_for_travel
from gonio.merl import MerlBRDF, load_merl, merl_table, read_merl, write_merl
from gonio.rgl import RGLBRDF, load_rgl
from gonio.table import Table
from gonio.terminal import shown

__all__ = [
    "Table", "FormatError", "TableWarning", "read", "write", "load_rgl", "load_merl", "read_curet",
    "read_merl", "load_curet",
    "read_exr", "write_exr", "read_csv", "write_csv", "read_alta", "write_alta",
    "merl_table", "write_merl", "MerlBRDF", "RGLBRDF", "atomic_write", "plain", "json_line", "meta_text", "progress_bar",
    "Geometry", "Instrument", "measure", "full_grid", "plane", "rusinkiewicz", "merl_grid",
    "pairs", "pairs_from_angles", "from_spec", "write_pairs_csv", "read_pairs_header",
    "order_for_travel", "shown",
]
