"""Costly libraries and a package's re-exported names, imported on first use, so that a
``microcyl`` verb pays only for what it runs: emcee loads scipy.stats (together about 0.5 s
on the 2-core machine), which a verb that only reads a fabric, a table or a fit folder never
needs.

- :func:`lazy_module`: a stand-in for a module, imported at its first attribute
  (``stats.norm``); each costly library used this way is named once, here.
- :func:`lazy_getattr`: a package's ``__getattr__`` (PEP 562) importing each re-exported name
  from its module on first use (``analysis``, ``analysis.fit``).

Examples
--------
>>> math = lazy_module("math")
>>> math.sqrt(9.0)
3.0
>>> getattr_ = lazy_getattr("demo", {"sqrt": "math"}, {})
>>> getattr_("sqrt")(16.0)
4.0
>>> getattr_("cbrt")
Traceback (most recent call last):
...
AttributeError: module 'demo' has no attribute 'cbrt'
"""

from __future__ import annotations

import importlib
from typing import Callable, Mapping

__all__ = ["lazy_module", "lazy_getattr", "stats", "qmc", "autocorr"]


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


def lazy_getattr(package: str, names: Mapping[str, str], namespace: dict) -> Callable:
    """The module ``__getattr__`` of ``package`` that imports each of ``names`` (name ->
    module) on first use and keeps it in ``namespace`` (the package's globals)."""

    def __getattr__(name: str):
        if name not in names:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(names[name]), name)
        namespace[name] = value
        return value

    return __getattr__


#: scipy.stats (0.4 s): distributions and tests of the likelihood, the adequacy checks,
#: PSIS-LOO's PIT and the albedo's Student-t interval.
stats = lazy_module("scipy.stats")
#: scipy.stats.qmc: scrambled Sobol points (albedo quadrature, planning candidates).
qmc = lazy_module("scipy.stats.qmc")
#: emcee.autocorr: emcee's window of the integrated autocorrelation time (emcee loads
#: scipy.stats for its KDE move).
autocorr = lazy_module("emcee.autocorr")
