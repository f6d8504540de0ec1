"""The built-in renderer: a path tracer of small scenes for previews and the report.

:mod:`~reports.render.engine` renders (tiles on worker processes); :mod:`~reports.render.scenes`
the named scenes, built of :mod:`~reports.render.cameras`, :mod:`~reports.render.lights`,
:mod:`~reports.render.envlight` and :mod:`~reports.render.primitives`; :mod:`~reports.render.tracing`
and :mod:`~reports.render.vec3` the ray helpers; :mod:`~reports.render.imageio` EXR and PNG output.
Nothing is re-exported here: importing a module of the package stays cheap.
"""

__all__ = []
