"""The ``microcyl export`` verb: a fit's posterior medians as a Mitsuba plugin dictionary.

``microcyl export FIT_DIR -o fabric.json`` (or ``-o fabric.xml``)

Reads ``FIT_DIR/results.json`` and ``FIT_DIR/fit_config.json``
(:func:`analysis.fit.medians.median_fabric`) and writes the ``microcylinder`` BSDF's
dictionary (:func:`reports.mitsuba.plugin_dict`: every thread parameter and option spelled
out) as JSON, or as a Mitsuba XML ``<bsdf>`` element where FILE ends in ``.xml``
(:func:`reports.mitsuba.plugin_xml`), atomically. After ``reports.mitsuba.register()``,
``mi.load_dict(json.load(open("fabric.json")))`` loads the first, and a scene file holding the
second refers to it by ``<ref id="fabric"/>``. Needs no Mitsuba.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

from analysis.fit.medians import median_fabric
from gonio import atomic_write
from gonio.jsonplain import plain
from reports.mitsuba import plugin_dict, plugin_xml

__all__ = ["register", "run"]

log = logging.getLogger("microcyl")


def register(sub):
    """Add ``export`` to the ``microcyl`` sub-parsers."""
    p = sub.add_parser(
        "export", help="write a fit's median parameters as a Mitsuba 3 BSDF dictionary",
        description="Write the posterior medians of a `microcyl fit` output folder (free "
                    "parameters; fixed and tied ones as the fit held them) as the JSON "
                    "dictionary of the Mitsuba 3 BSDF 'microcylinder' (reports.mitsuba).")
    p.add_argument("fit_dir", metavar="FIT_DIR", help="a `microcyl fit` output folder")
    p.add_argument("-o", "--output", required=True, metavar="FILE",
                   help="file to write: fabric.json (the dictionary for mi.load_dict) or "
                        "fabric.xml (a <bsdf> element for Mitsuba scene files)")
    p.set_defaults(func=run)


def run(args) -> int:
    """Build the median fabric, write its plugin dictionary, print a summary."""
    folder = Path(args.fit_dir)
    if not folder.is_dir():
        raise ValueError(f"{folder}: no such fit folder")
    med = median_fabric(folder)
    out = Path(args.output)
    if not out.parent.is_dir():
        raise ValueError(f"{out.parent}: output folder does not exist")
    if out.suffix.lower() == ".xml":
        text = plugin_xml(med.fabric, med.preset)
    else:
        text = json.dumps(plain(plugin_dict(med.fabric, med.preset)), indent=2) + "\n"
    with atomic_write(out, "w") as fh:
        fh.write(text)
    log.info("wrote %s", out)
    verdict = "converged" if med.converged else "NOT converged (medians of an unfinished fit)"
    print(f"{med.preset}: medians of {', '.join(med.free)} ({verdict}) -> {out}")
    return 0
