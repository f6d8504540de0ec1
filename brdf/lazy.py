"""Modules imported on first use: :func:`lazy_module`, the stand-in that every layer uses to
defer a costly library (:mod:`analysis.lazy` names the analysis layer's). brdf's own:
:data:`special`.

Examples
--------
>>> math = lazy_module("math")
>>> math
<lazy module 'math'>
>>> math.sqrt(9.0)
3.0
"""

from __future__ import annotations

import importlib

__all__ = ["lazy_module", "special"]


class _LazyModule:
    """The module ``name``, imported at the first attribute read through this object."""

    def __init__(self, name: str):
        self._name = name
        self._module = None

    def __getattr__(self, attr: str):
        if self._module is None:
            self._module = importlib.import_module(self._name)
        return getattr(self._module, attr)

    def __repr__(self) -> str:
        return f"<lazy module {self._name!r}>"


def lazy_module(name: str) -> _LazyModule:
    """A stand-in for module ``name`` that imports it at its first attribute read."""
    return _LazyModule(name)


#: scipy.special (0.12 s, its array-API layer): the truncated normal of the sampler's
#: horizon-aware lobes (:mod:`brdf.horizon`), which a verb that only evaluates never needs.
special = lazy_module("scipy.special")
