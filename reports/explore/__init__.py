"""The BRDF Explorer of cloth (``microcyl explore``): every view of a model linked to one
state, in the browser (a local Bokeh server) and in Jupyter (``explore(brdf.fabric("velvet"))``).

models (the sliders and variants of each model: one adapter), fast (prepared pairs shaded
again for each slider move), data (fabrics, fit folders' posterior draws, tables' points),
engine (the state and the numbers of every view), figures (the Bokeh views), page (the
page's test ids and keyboard), app (the document), server (the local server), notebook
(the app in a Jupyter output cell).
"""

from reports.explore.app import Controller, app
from reports.explore.engine import Explorer, Frame, State
from reports.explore.notebook import explore
from reports.explore.server import serve

__all__ = ["app", "serve", "explore", "Controller", "Explorer", "State", "Frame"]
