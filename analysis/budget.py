"""The size of work before it starts: the memory there is, estimates, and the refusal.

A verb or workflow that can be asked for more than the machine holds (a geometry of 16e9
pairs, a million walkers, an RGL table sampled every 0.01 degrees) estimates its memory from
the sizes it is given and calls :func:`check_memory` first, so that it is refused in one line
that states the estimate and the limit, instead of ending in a MemoryError or the kernel's
out-of-memory killer. The limit is 80% of the memory the kernel reports available
(``MemAvailable`` of /proc/meminfo, else ``os.sysconf``), or ``$MICROCYL_MEMORY_LIMIT``
(bytes, or with a suffix K, M, G, T) when set.
"""

from __future__ import annotations

import math
import os
import re

from gonio import geomspec

__all__ = ["available_memory", "memory_limit", "check_memory", "format_bytes",
           "format_seconds", "spec_pairs", "MEASURE_BYTES_PER_PAIR", "RGL_BYTES_PER_PAIR",
           "FIT_BYTES_PER_VALUE"]

#: Peak memory of ``measure`` per direction pair (geometry, values, chunked evaluation),
#: bytes: about 270 measured on full:5 (1.5 M pairs), rounded up.
MEASURE_BYTES_PER_PAIR = 400
#: Peak memory of reading an RGL .bsdf per sampled pair, bytes (about 430 measured).
RGL_BYTES_PER_PAIR = 600
#: Memory of one batched model evaluation in a fit per walker and table value, bytes.
FIT_BYTES_PER_VALUE = 100
#: Share of the available memory a job may plan to use.
SHARE = 0.8
_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def available_memory() -> int:
    """Bytes of memory available to a new job (MemAvailable, else free pages)."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 8 << 30


def memory_limit() -> tuple[int, str]:
    """(bytes, how it was set): ``$MICROCYL_MEMORY_LIMIT`` or 80% of the available memory."""
    env = os.environ.get("MICROCYL_MEMORY_LIMIT", "").strip().upper().removesuffix("B")
    m = re.fullmatch(r"(\d+(?:\.\d*)?)\s*([KMGT]?)I?", env)
    if m:
        return int(float(m.group(1)) * _UNITS[m.group(2)]), "MICROCYL_MEMORY_LIMIT"
    return int(SHARE * available_memory()), f"{SHARE:.0%} of the available memory"


def format_bytes(n: float) -> str:
    """``1.5 GB`` style (powers of 1024).

    Examples
    --------
    >>> format_bytes(3 << 30), format_bytes(512)
    ('3.0 GB', '512 B')
    """
    if not math.isfinite(n):
        return "more than any machine has"
    n = float(n)
    for unit in ("B", "KB", "MB", "GB", "TB", "PB"):
        if n < 1024 or unit == "PB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} PB"  # pragma: no cover


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


def check_memory(what: str, nbytes: float, change: str) -> None:
    """Refuse work whose estimated memory exceeds :func:`memory_limit`.

    Parameters
    ----------
    what : str
        The work and its size, e.g. ``"--geometry full:0.5 (1.66e10 pairs)"``.
    nbytes : float
        Its estimated peak memory in bytes.
    change : str
        What to change, e.g. ``"use a coarser step"``.

    Raises
    ------
    ValueError
        ``"{what} would take about X of memory; the limit is Y (how); {change}"``.
    """
    limit, how = memory_limit()
    nbytes = float(nbytes) if nbytes < 1e300 else math.inf
    if not nbytes <= limit:
        raise ValueError(f"{what} would take about {format_bytes(nbytes)} of memory; the "
                         f"limit is {format_bytes(limit)} ({how}); {change}")


def spec_pairs(spec: str) -> int | float | None:
    """Number of direction pairs a geometry spec (``full:10``, ``rus:5``, ``merl:2``) makes,
    counted without building it (:func:`gonio.geomspec.spec_pairs`, the same parser as
    :func:`gonio.from_spec`); a float (inf past the float range) from 10^18 on; None when the
    spec is malformed (then :func:`gonio.from_spec` gives the error) or small by construction
    (``plane``, ``pairs``).

    Examples
    --------
    >>> spec_pairs("full:45:90"), spec_pairs("full:0.5"), spec_pairs("plane:warp:5")
    (25, 16610312161, None)
    """
    try:
        n = geomspec.spec_pairs(spec)
    except ValueError:
        return None
    if n is None or n < 10**18:
        return n
    return float(n) if n < 10**300 else math.inf
