"""The explorer in a Jupyter notebook: :func:`explore` shows the app in the output cell,
served by a Bokeh server that runs in the kernel (on its event loop, bound to 127.0.0.1),
with BokehJS written into the notebook from the package: nothing is loaded from the web.

::

    import brdf
    from reports.explore import explore
    explore(brdf.fabric("velvet"))            # a model object, or what the verb takes:
    explore("velvet", "fit/", "velvet.exr")   # presets, fit folders, tables

The app's websocket accepts the pages of the Jupyter servers running on this machine
(:func:`jupyter_origins`: their ports, read from Jupyter's runtime files, on ``localhost``
and ``127.0.0.1``) and no other; a notebook behind a proxy or on another machine passes
``notebook_url`` (Bokeh's :func:`bokeh.io.show` argument).

Examples
--------
>>> jupyter_origins(runtime_dir="/nonexistent")      # none running: Jupyter's default
['localhost:8888', '127.0.0.1:8888']
>>> explore("denim")
Traceback (most recent call last):
...
ValueError: FABRIC 'denim': not a preset (linen_plain, silk_crepe_de_chine, polyester_satin_charmeuse, polyester_satin_charmeuse_back, silk_shot, velvet), a `microcyl fit` output folder or a .json or .xml fabric file or a .mtlx or .gltf or .glb export of `microcyl export`
"""

from __future__ import annotations

import json
from pathlib import Path
from uuid import uuid4

from bokeh.embed import server_document
from bokeh.io import output_notebook, show
from bokeh.io.notebook import EXEC_MIME_TYPE, HTML_MIME_TYPE, publish_display_data
from bokeh.io.state import curstate
from bokeh.resources import INLINE
from bokeh.server.server import Server
from tornado.ioloop import IOLoop

try:                       # optional (not a dependency of microcyl): there in any Jupyter kernel
    from jupyter_core.paths import jupyter_runtime_dir
except ImportError:
    jupyter_runtime_dir = None

from reports.explore.app import app

__all__ = ["explore", "jupyter_origins"]

#: Views a row in a notebook's output cell (narrower than a browser's page).
VIEWS_PER_ROW = 3
#: The port of a Jupyter server when none is found running.
DEFAULT_PORT = 8888


def _runtime_ports(folder: Path) -> list:
    ports = []
    for f in sorted(folder.glob("*server-*.json")):     # jpserver-PID.json, nbserver-PID.json
        try:
            port = json.loads(f.read_text(encoding="utf-8")).get("port")
        except (OSError, ValueError, AttributeError):
            continue
        if isinstance(port, int) and 0 < port < 65536 and port not in ports:
            ports.append(port)
    return ports


def jupyter_origins(runtime_dir=None) -> list:
    """The origins (``host:port``) of the Jupyter servers running on this machine, from
    their runtime files in ``runtime_dir`` (Jupyter's by default), each on ``localhost``
    and ``127.0.0.1``; Jupyter's default port when none is found."""
    if runtime_dir is None:
        if jupyter_runtime_dir is None:
            raise RuntimeError("explore in a notebook needs jupyter_core (every Jupyter kernel "
                               "has it: pip install ipykernel)")
        runtime_dir = jupyter_runtime_dir()
    ports = _runtime_ports(Path(runtime_dir)) or [DEFAULT_PORT]
    return [f"{host}:{p}" for p in ports for host in ("localhost", "127.0.0.1")]


def explore(*sources, notebook_url=None, port: int = 0) -> None:
    """Show the explorer of ``sources`` (model objects such as ``brdf.fabric("velvet")``,
    or FABRIC / TABLE / FITDIR arguments as ``microcyl explore`` takes them; default the
    ``linen_plain`` preset) in the current Jupyter output cell; its server runs until the
    kernel ends (``port`` 0: a free one).

    Raises
    ------
    ValueError
        A source the explorer cannot read (before anything is shown).
    """
    build = app(*sources, per_row=VIEWS_PER_ROW)   # reads every source: errors before output
    output_notebook(resources=INLINE, hide_banner=True)
    if notebook_url is not None:
        show(build, notebook_url=notebook_url)
        return
    server = Server({"/": build}, io_loop=IOLoop.current(), address="127.0.0.1",
                    port=int(port), allow_websocket_origin=jupyter_origins())
    server.start()
    server_id = uuid4().hex
    curstate().uuid_to_server[server_id] = server      # Bokeh's handle on notebook servers
    script = server_document(f"http://127.0.0.1:{server.port}/", resources=None)
    publish_display_data({HTML_MIME_TYPE: script, EXEC_MIME_TYPE: ""},
                         metadata={EXEC_MIME_TYPE: {"server_id": server_id}})
