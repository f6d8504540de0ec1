"""The ``microcyl export`` verb: a fabric (a fit's posterior medians) as a Mitsuba plugin
dictionary.

``microcyl export FABRIC -o fabric.json`` (or ``-o fabric.xml``)

FABRIC is any fabric source (:func:`analysis.sources.resolve`); for a fit folder, its
``results.json`` and ``fit_config.json`` (:func:`analysis.fit.medians.median_fabric`). Writes
the ``microcylinder`` BSDF's dictionary (:func:`analysis.fabricfile.plugin_dict`: every
thread parameter and option spelled out) as JSON, or as a Mitsuba XML ``<bsdf>`` element
where FILE ends in ``.xml`` (:func:`analysis.fabricfile.plugin_xml`), atomically
(:func:`analysis.fabricfile.write_fabric_file`); the suffix
and folder are checked before anything is read. ``microcyl render SCENE FILE`` and every
other FABRIC argument read either back. After ``reports.mitsuba.register()``,
``mi.load_dict(json.load(open("fabric.json")))`` loads the first, and a scene file holding the
second refers to it by ``<ref id="fabric"/>``. Needs no Mitsuba.
"""

from __future__ import annotations

import logging

from analysis.fabricfile import SUFFIXES, write_fabric_file
from analysis.fit.medians import median_fabric
from gonio.terminal import shown
from reports.cli import options as cliutil

__all__ = ["register", "run"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``export`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "export", help="write a fit's median parameters as a Mitsuba 3 BSDF dictionary",
        description="Write a fabric as the JSON dictionary (or XML element) of the Mitsuba 3 "
                    "BSDF 'microcylinder' (reports.mitsuba.plugin): for a `microcyl fit` output "
                    "folder its posterior medians (free parameters; fixed and tied ones as "
                    "the fit held them).")
    cliutil.add_fabric_argument(p)
    cliutil.add_fabric_options(p)
    p.add_argument("-o", "--output", required=True, metavar="FILE",
                   help="file to write: fabric.json (the dictionary for mi.load_dict) or "
                        "fabric.xml (a <bsdf> element for Mitsuba scene files)")
    p.set_defaults(func=run)


def run(args) -> int:
    """Check the output, resolve the fabric, write its plugin dictionary, print a summary."""
    out = cliutil.check_output_suffix(args.output, SUFFIXES)
    src = cliutil.source_from_args(cliutil.fabric_argument(args), args)
    if not src.is_fabric:
        raise ValueError(f"export writes the microcylinder plugin's fabric; {src.label} is "
                         f"{src.what} (exporting baseline models is not supported yet)")
    write_fabric_file(out, src.brdf, src.preset)
    log.info("wrote %s", out)
    if src.kind == "fit":
        med = median_fabric(src.path)
        verdict = ("converged" if med.converged
                   else "NOT converged (medians of an unfinished fit)")
        print(shown(f"{med.preset}: medians of {', '.join(med.free)} ({verdict}) -> {out}"))
    else:
        print(shown(f"{src.label} ({src.kind}) -> {out}"))
    return 0
