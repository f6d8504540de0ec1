"""gonio: a virtual gonioreflectometer, and BRDF tables in the formats of the field."""

from gonio.table import Table

__all__ = ["Table"]
