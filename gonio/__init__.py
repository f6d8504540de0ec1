"""gonio: a virtual gonioreflectometer, and BRDF tables in the formats of the field."""

from gonio.errors import FormatError
from gonio.rgl import load_rgl
from gonio.table import Table

__all__ = ["Table", "FormatError", "load_rgl"]
