"""The BRDF Explorer of cloth (``microcyl explore``): every view of a model linked to one
state, in the browser (a local Bokeh server) and in Jupyter (``show(app(...))``).

models (the sliders and variants of each model: one adapter), fast (prepared pairs shaded
again for each slider move), data (fabrics, fit folders' posterior draws, tables' points),
engine (the state and the numbers of every view), figures (the Bokeh views), page (the
page's test ids and keyboard), app (the document), server (the local server).
"""

from reports.explore.app import Controller, app
from reports.explore.engine import Explorer, Frame, State
from reports.explore.server import serve

__all__ = ["app", "serve", "Controller", "Explorer", "State", "Frame"]
