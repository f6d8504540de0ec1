"""The ``microcyl explore`` verb: the BRDF Explorer of cloth in the browser.

``microcyl explore [FABRIC|TABLE|FITDIR ...] [--port N] [--address A] [--no-browser]``

Starts a local web server (:func:`reports.explore.serve`) bound to 127.0.0.1 unless told
otherwise, on a free port unless ``--port`` names one, prints its address and opens it in
the browser (not with ``--no-browser``); Ctrl-C stops it. Every page it serves loads its
scripts from it alone.
"""

from __future__ import annotations

import sys

from reports.cli import lazy

__all__ = ["register", "run"]


def register(sub):
    """Add ``explore`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "explore", help="explore a BRDF in the browser: every view linked to sliders",
        description="Start the BRDF Explorer of cloth, a local web app: the lobe, the "
                    "hemisphere, the theta_h x theta_d slice, a lit sphere, the albedo and "
                    "the masking and tangent curves of a model, a slider for each of its "
                    "parameters; tables' points and fits' posterior bands over the lobe.")
    p.add_argument("sources", nargs="*", metavar="FABRIC|TABLE|FITDIR",
                   help="presets, exported fabrics (.json, .xml), fit folders (their medians "
                        "and posterior band) and measured tables (their points); default "
                        "linen_plain")
    p.add_argument("--port", type=int, default=0,
                   help="port to listen on (default 0: a free one)")
    p.add_argument("--address", default="127.0.0.1",
                   help="address to bind (default 127.0.0.1: this machine only)")
    p.add_argument("--no-browser", action="store_true",
                   help="print the address without opening a browser")
    p.set_defaults(func=run)


def run(args) -> int:
    """Serve the explorer until interrupted."""
    if not 0 <= args.port <= 65535:
        raise ValueError(f"--port must be in 0..65535; got {args.port}")
    lazy.explorer().serve(
        args.sources, address=args.address, port=args.port,
        open_browser=not args.no_browser,
        announce=lambda url: print(f"microcyl explore: serving {url} (Ctrl-C stops)",
                                   file=sys.stdout, flush=True))
    return 0
