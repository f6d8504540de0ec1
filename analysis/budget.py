"""The size of work before it starts: the memory there is, estimates, and the refusal.

A verb or workflow that can be asked for more than the machine holds (a geometry of 16e9
pairs, a million walkers, an RGL table sampled every 0.01 degrees) estimates its memory from
the sizes it is given and calls :func:`check_memory` first, so that it is refused in one line
that states the estimate and the limit, instead of ending in a MemoryError or the kernel's
out-of-memory killer. The limit (:func:`gonio.memory.memory_limit`, re-exported here) is the
least of 80% of the memory the kernel reports available (``MemAvailable``), 80% of the address
space left under ``ulimit -v`` (``RLIMIT_AS``), 80% of the memory left in the process's cgroup
(``memory.max``), and ``$MICROCYL_MEMORY_LIMIT`` (bytes, or with a suffix K, M, G, T); the
refusal names the one that set it. It lives in gonio so that the table readers and the
geometry layouts check the same limit.
"""

from __future__ import annotations

import math

from gonio import geomspec
from gonio.memory import available_memory, check_memory, format_bytes, memory_limit
from gonio.tablesize import RGL_BYTES_PER_PAIR

__all__ = ["available_memory", "memory_limit", "check_memory", "format_bytes",
           "format_seconds", "spec_pairs", "check_fit_rows", "MEASURE_BYTES_PER_PAIR",
           "RGL_BYTES_PER_PAIR",
           "FIT_BYTES_PER_VALUE"]

#: Peak memory of ``measure`` per direction pair (geometry, values, chunked evaluation),
#: bytes: about 270 measured on full:5 (1.5 M pairs), rounded up.
MEASURE_BYTES_PER_PAIR = 400
#: Memory of one batched model evaluation in a fit per walker and table value, bytes.
FIT_BYTES_PER_VALUE = 100


def format_seconds(s: float) -> str:
    """``45 s``, ``12 min``, ``18.2 h``, ``3.1 days``.

    Examples
    --------
    >>> format_seconds(40), format_seconds(720), format_seconds(65520)
    ('40 s', '12 min', '18.2 h')
    """
    if not math.isfinite(s):
        return "forever"
    if s < 120:
        return f"{s:.0f} s"
    if s < 7200:
        return f"{s / 60:.0f} min"
    if s < 3 * 86400:
        return f"{s / 3600:.1f} h"
    return f"{s / 86400:.1f} days"


def spec_pairs(spec: str) -> int | float | None:
    """Number of direction pairs a geometry spec (``full:10``, ``rus:5``, ``merl:2``,
    ``plane:warp:5``) makes,
    counted without building it (:func:`gonio.geomspec.spec_pairs`, the same parser as
    :func:`gonio.from_spec`); a float (inf past the float range) from 10^18 on; None when the
    spec is malformed (then :func:`gonio.from_spec` gives the error) or reads a file
    (``pairs``, sized when it is read).

    Examples
    --------
    >>> spec_pairs("full:45:90"), spec_pairs("full:0.5"), spec_pairs("pairs:p.csv")
    (25, 16610312161, None)
    """
    try:
        n = geomspec.spec_pairs(spec)
    except ValueError:
        return None
    if n is None or n < 10**18:
        return n
    return float(n) if n < 10**300 else math.inf


def check_fit_rows(name: str, rows: int, walkers: int, threads: int) -> None:
    """Refuse, before a table is read, a fit whose batched evaluations (``walkers`` x its
    values x :data:`FIT_BYTES_PER_VALUE` x ``threads``, the fit's own check once the table
    is read) cannot fit in memory even at one value a row (a grey table; three for RGB).

    Parameters
    ----------
    name : str
        The table's file name, for the message.
    rows : int
        Its rows, estimated from the file (:func:`gonio.tablesize.estimate_table`).
    walkers, threads : int
        The fit's walkers per ensemble and threads (:meth:`analysis.fit.FitOptions.resolve`).

    Raises
    ------
    ValueError
        ``fitting t.csv (about 5,000,002 rows) with 18 walkers would take about ...``.
    """
    check_memory(f"fitting {name} (about {rows:,} rows) with {walkers} walkers (--walkers)",
                 walkers * rows * FIT_BYTES_PER_VALUE * threads,
                 "fit a part of the table, or lower --walkers")
