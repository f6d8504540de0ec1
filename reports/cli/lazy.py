"""The costly modules the command line loads on use, each imported in one place.

matplotlib, corner and colour-science cost ``microcyl --help`` and the verbs that do not draw
about two seconds; the verbs that draw, render or write the report reach them through these
accessors (imported on first call, cached by Python's module table after).
"""

from __future__ import annotations

import importlib
from types import SimpleNamespace


class _PlotModules:
    """``reports.plots.NAME`` for the NAMEs in :data:`PLOT_MODULES`, each imported when its
    attribute is first read: ``fit_diagnostics`` loads corner, which loads arviz (about 2 s
    of CPU), and only the verbs that fit draw its plots."""

    def __getattr__(self, name: str):
        if name not in PLOT_MODULES:
            raise AttributeError(f"reports.plots has no module {name!r} for the verbs")
        # lazy: matplotlib, corner (and arviz) and colour-science, which `microcyl --help`,
        # `plot` and `plan` skip where they do not draw them; through importlib, one module
        # at a time
        return importlib.import_module(f"reports.plots.{name}")


#: The plot modules the verbs call.
PLOT_MODULES = ("common", "fit", "fit_diagnostics", "imagefit", "plan", "views")
_PLOTS = _PlotModules()


def plots() -> _PlotModules:
    """The plot modules the verbs call (:data:`PLOT_MODULES`), each imported on first use.

    Examples
    --------
    >>> plots().plan.__name__
    'reports.plots.plan'
    """
    return _PLOTS


def report():
    """:func:`reports.report.build_report` (the report's plots load matplotlib).

    Examples
    --------
    >>> report().__module__, plots().views.__name__, renderer().engine.__name__
    ('reports.report.build', 'reports.plots.views', 'reports.render.engine')
    """
    # lazy: matplotlib and colour-science (~2 s), which the other verbs skip
    from reports.report import build_report
    return build_report


def renderer() -> SimpleNamespace:
    """The built-in renderer's ``engine``, ``exposure``, ``files``, ``imageio`` and
    ``scenefile`` modules."""
    # lazy: imageio pulls in colour-science (~2 s), which `microcyl --help` does not need
    from reports.render import engine, exposure, files, imageio, scenefile
    return SimpleNamespace(engine=engine, exposure=exposure, files=files, imageio=imageio,
                           scenefile=scenefile)


def explorer():
    """The :mod:`reports.explore` package (``microcyl explore``: the Bokeh server)."""
    # lazy: bokeh (~1.5 s with the explorer's views), which every other verb skips; through
    # importlib as reports.cli loads its verb modules
    return importlib.import_module("reports.explore")
