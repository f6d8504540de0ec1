"""The explorer's local web server (Bokeh's): bound to 127.0.0.1 by default, on a free port
unless told one, BokehJS served by itself (nothing from another host), the address printed.

Examples
--------
>>> url_of("127.0.0.1", 5006)
'http://127.0.0.1:5006/'
>>> 0 < free_port("127.0.0.1") < 65536
True
"""

from __future__ import annotations

import socket
import webbrowser

from bokeh.server.server import Server

from reports.explore.app import app

__all__ = ["serve", "free_port", "url_of"]


def free_port(address: str) -> int:
    """A port free on ``address`` now (the system's choice)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((address, 0))
        return int(s.getsockname()[1])


def url_of(address: str, port: int) -> str:
    """The page's address."""
    return f"http://{address}:{port}/"


def serve(texts, *, address: str = "127.0.0.1", port: int = 0, open_browser: bool = True,
          announce=print) -> None:
    """Serve the explorer of ``texts`` (FABRIC / TABLE / FITDIR arguments) until
    interrupted; ``announce(url)`` is called once the server listens.

    Raises
    ------
    ValueError
        An argument that names nothing the explorer reads (from the resolver).
    """
    build = app(*texts)
    port = int(port) or free_port(address)
    origins = [f"{address}:{port}"] + ([f"localhost:{port}"] if address == "127.0.0.1"
                                       else [])
    server = Server({"/": build}, address=address, port=port,
                    allow_websocket_origin=origins, num_procs=1)
    server.start()
    url = url_of(address, port)
    announce(url)
    if open_browser:
        server.io_loop.add_callback(lambda: webbrowser.open(url))
    try:
        server.io_loop.start()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
