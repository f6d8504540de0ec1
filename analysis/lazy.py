"""Costly libraries and a package's re-exported names, imported on first use, so that a
``microcyl`` verb pays only for what it runs: emcee loads scipy.stats (together about 0.5 s
on the 2-core machine), which a verb that only reads a fabric, a table or a fit folder never
needs.

- :func:`lazy_module` (:mod:`brdf.lazy`'s): a stand-in for a module, imported at its first
  attribute (``stats.norm``); each costly library used this way is named once, here (brdf's
  own in :mod:`brdf.lazy`).
- :func:`lazy_getattr`: a package's ``__getattr__`` (PEP 562) importing each re-exported name
  from its module on first use (``analysis``, ``analysis.fit``, ``analysis.batch``,
  ``analysis.planning``).

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

from brdf.lazy import lazy_module, special

__all__ = ["lazy_module", "lazy_getattr", "stats", "qmc", "autocorr", "optimize", "fft",
           "special"]


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
#: scipy.optimize (0.11 s): the export's projection (least squares); every verb that reads a
#: fabric source imports :mod:`analysis.export`'s registry.
optimize = lazy_module("scipy.optimize")
#: scipy.fft (0.12 s, its array-API layer): the autocorrelation times of a fit's checks
#: (:func:`analysis.diagnostics.autocorr_time`); ``analysis`` imports the diagnostics.
fft = lazy_module("scipy.fft")
# ``special`` is brdf.lazy's scipy.special, imported above: also the internal coordinates'
# logistic function (analysis.param), which a verb that does not fit never evaluates.
