"""The workflow of ``microcyl measure``: a BRDF measured on a geometry spec, written to a file.

The size is checked before the geometry is built (memory against :mod:`gonio.memory`'s limit;
the time estimated), the pairs against the instrument's reach (:func:`gonio.measure` refuses
them before any work), and the table written atomically under the output's lock.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable

import gonio
from analysis.budget import (MEASURE_BYTES_PER_PAIR, check_memory, format_bytes,
                             format_seconds, spec_pairs)
from analysis.folderlock import output_lock
from gonio.geomspec import from_spec

__all__ = ["measure_estimate", "measure_to_file", "SECONDS_PER_EVALUATION"]

#: Seconds per BRDF evaluation with 32 tangent samples (about 10 us measured on 2 cores).
SECONDS_PER_EVALUATION = 1.2e-5


def measure_estimate(spec: str, instrument: gonio.Instrument, brdf) -> tuple[int, int, float] | None:
    """(pairs, bytes, seconds) of measuring ``brdf`` on the geometry ``spec``, counted without
    building it; None when the spec's size is not known before it is read (``pairs:FILE``).

    Raises
    ------
    ValueError
        More memory than there is (the estimate in the message).

    Examples
    --------
    >>> import brdf
    >>> n, nbytes, seconds = measure_estimate("plane:0:10:30", gonio.Instrument(),
    ...                                       brdf.fabric("velvet"))
    >>> n, nbytes > 0, seconds < 1
    (17, True, True)
    """
    n = spec_pairs(spec)
    if n is None:
        return None
    nbytes = n * MEASURE_BYTES_PER_PAIR
    check_memory(f"--geometry {spec} ({n:.3g} pairs)", nbytes, "use a coarser step")
    points = instrument.n_source * instrument.n_detector      # no quadrature built
    options = getattr(brdf, "options", None)
    samples = 32 if options is None else options["tangent_samples"]
    if options is not None and options.get("tangent_sampling") == "control_points":
        samples = max(len(t.offsets) for t in brdf.threads)    # each control point a sample
    return int(n), int(nbytes), n * points * SECONDS_PER_EVALUATION * samples / 32


def measure_to_file(brdf, label: str, spec: str, out, instrument: gonio.Instrument, *,
                    rotation_deg: float = 0.0, seed: int | None = None, progress=True,
                    notify: Callable[[str], None] | None = None):
    """Measure ``brdf`` on the geometry ``spec`` and write the table to ``out``.

    Parameters
    ----------
    brdf : object with ``eval(wi, wo)``
        f_r in 1/sr (a fabric, a baseline model, a measured table's evaluator).
    label : str
        The source's name, recorded in the table's metadata when the BRDF gives none.
    spec : str
        A geometry spec (:data:`gonio.geometry.SPEC_HELP`).
    out : path
        The table file (format from its suffix).
    instrument : gonio.Instrument
    rotation_deg : float
        The sample's azimuth on the stage, degrees.
    seed : int, optional
        Seeds the noise.
    progress : bool or callable
        As :func:`gonio.measure`.
    notify : callable, optional
        ``notify(line)`` gets the size and time estimate of a measurement over 5 s.

    Returns
    -------
    (gonio.Table, gonio.Geometry, pathlib.Path)
    """
    if not math.isfinite(rotation_deg):
        raise ValueError(f"--rotation must be a finite angle in degrees; got {rotation_deg}")
    if seed is not None and seed < 0:
        raise ValueError(f"--seed must be a non-negative integer; got {seed}")
    est = measure_estimate(spec, instrument, brdf)
    if est is not None and est[2] > 5 and notify is not None:
        points = instrument.n_source * instrument.n_detector
        notify(f"measure: --geometry {spec} ({est[0]:.3g} pairs) x {points} cone points: "
               f"about {format_bytes(est[1])} of memory and {format_seconds(est[2])}")
    geometry = from_spec(spec, rotation=math.radians(rotation_deg))
    table = gonio.measure(brdf, geometry, instrument, seed=seed, progress=progress)
    if "name" not in table.meta["source"]:
        table.meta["source"]["name"] = label
    out = Path(out)
    with output_lock(out, "measure", inside=False):   # removes a killed run's temporaries
        gonio.write(table, out)
    return table, geometry, out
