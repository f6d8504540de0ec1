"""What an export target is: a renderer's file format and the model it evaluates.

A :class:`Target` names the format (``--to``), its file suffixes, the microcyl model that
stands for what the renderer evaluates (``zeltner``, ``charlie``; None for the Mitsuba plugin,
which is the microcylinder fabric itself), a writer and, where the format can be read back as
data, a reader. The registry is :data:`analysis.export.TARGETS`: a new target is its module
(defining ``TARGET``) plus one line there.

Examples
--------
>>> t = Target("demo", (".demo",), "zeltner", print, None, "a demonstration")
>>> t.name, t.model, t.read is None
('demo', 'zeltner', True)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

__all__ = ["Target"]


@dataclasses.dataclass(frozen=True)
class Target:
    """An export target.

    Attributes
    ----------
    name : str
        The ``--to`` name.
    suffixes : tuple of str
        File suffixes it writes (the first the default).
    model : str or None
        The microcyl model the renderer evaluates (projection target), or None when the
        source itself is written (the Mitsuba plugin).
    write : callable
        ``write(path, projection_or_fabric, info)``: writes the file atomically.
    read : callable or None
        ``read(path)`` -> the exported model (a :mod:`brdf.baselines` model), or None where
        the file is code (Blender's script) or the reader lives elsewhere.
    describe : str
        The target's parameters and conventions, in one sentence.
    settle : callable or None
        ``settle(path) -> (path, note or None)``: where the export of ``path`` is written
        when this machine cannot write that file (Blender's ``.blend`` without ``bpy``: its
        script), checked before any work; None: always ``path``.
    """

    name: str
    suffixes: tuple
    model: str | None
    write: Callable
    read: Callable | None
    describe: str
    settle: Callable | None = None

    def settled(self, path):
        """``(path, note)``: :attr:`settle`'s answer, or ``path`` and None.

        Examples
        --------
        >>> Target("demo", (".demo",), None, print, None, "a demonstration").settled("a.demo")
        ('a.demo', None)
        """
        return (path, None) if self.settle is None else self.settle(path)
