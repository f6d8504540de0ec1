"""The memory a job may plan to use, and the refusal of work that would take more.

The limit is the least of four sources, each read when asked (so it follows the process's
surroundings, not the machine's):

- ``MemAvailable`` of /proc/meminfo (else ``os.sysconf``): 80% of it;
- the address space left under ``RLIMIT_AS`` (``ulimit -v``): 80% of the soft limit less the
  process's current virtual size (``VmSize`` of /proc/self/status);
- the memory left in the process's cgroup: 80% of ``memory.max`` (cgroup v2) or
  ``memory.limit_in_bytes`` (v1) less the cgroup's working set (usage less inactive file
  cache), for the process's cgroup (/proc/self/cgroup) and each of its ancestors;
- ``$MICROCYL_MEMORY_LIMIT`` (bytes, or with a suffix K, M, G, T), taken as it is.

Each source is read by a public function returning bytes (or None when the source sets no
limit or cannot be read), so that tests can replace it. The message of a refusal names the
source that set the limit. This module lives in gonio, below analysis, so that the table
readers and the geometry layouts (and :mod:`analysis.budget`, which re-exports it) share
one limit.
"""

from __future__ import annotations

import math
import os
import re
import resource
from pathlib import Path

__all__ = ["memory_limit", "check_memory", "format_bytes", "available_memory",
           "meminfo_available", "address_space_left", "cgroup_memory_left", "environment_limit",
           "MemoryLimitError", "SHARE", "ENV", "CGROUP_ROOT", "PROC_CGROUP"]

#: Share of the memory a source leaves that a job may plan to use (not of the environment's).
SHARE = 0.8
#: The environment variable that caps the limit.
ENV = "MICROCYL_MEMORY_LIMIT"
_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}
#: A cgroup limit at or above this is "no limit" (v1 writes 2^63 rounded to a page).
_NO_LIMIT = 1 << 60
#: Where the cgroup file systems are mounted, and the file naming the process's cgroups.
CGROUP_ROOT = Path("/sys/fs/cgroup")
PROC_CGROUP = Path("/proc/self/cgroup")


def meminfo_available() -> int | None:
    """Bytes the kernel reports available (``MemAvailable``, else free pages), or None."""
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
        return None


def available_memory() -> int:
    """Bytes of memory available to a new job (:func:`meminfo_available`; 8 GiB if unknown)."""
    n = meminfo_available()
    return 8 << 30 if n is None else n


def _vm_size() -> int:
    """The process's virtual size in bytes (``VmSize``), 0 when unknown."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


def address_space_left() -> tuple[int, int] | None:
    """(bytes of address space left, the soft ``RLIMIT_AS``), or None without a limit."""
    try:
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    except (OSError, ValueError):
        return None
    if soft == resource.RLIM_INFINITY or soft < 0:
        return None
    return max(0, soft - _vm_size()), soft


def _read_int(path: Path) -> int | None:
    try:
        text = path.read_text().strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None      # "max" (v2) is no limit


def _inactive_file(folder: Path) -> int:
    """Reclaimable page cache of a cgroup (``inactive_file`` of memory.stat), 0 if unknown."""
    try:
        for line in (folder / "memory.stat").read_text().splitlines():
            key, _, value = line.partition(" ")
            if key in ("inactive_file", "total_inactive_file") and value.strip().isdigit():
                return int(value)
    except OSError:
        pass
    return 0


def _cgroup_folders() -> list[tuple[Path, str, str]]:
    """(folder, limit file, usage file) of the process's memory cgroup and its ancestors,
    v2 and v1 (only the folders that exist)."""
    try:
        lines = PROC_CGROUP.read_text().splitlines()
    except OSError:
        return []
    found = []
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        _, controllers, rel = parts
        if controllers == "":
            roots = [CGROUP_ROOT, CGROUP_ROOT / "unified"]
            files = ("memory.max", "memory.current")
        elif "memory" in controllers.split(","):
            roots = [CGROUP_ROOT / "memory"]
            files = ("memory.limit_in_bytes", "memory.usage_in_bytes")
        else:
            continue
        for root in roots:
            folder = root / rel.strip("/")
            while True:
                if (folder / files[0]).is_file():
                    found.append((folder, *files))
                if folder == root or root not in folder.parents:
                    break
                folder = folder.parent
    return found


def cgroup_memory_left() -> tuple[int, int] | None:
    """(bytes left in the tightest memory cgroup of this process, its limit), or None when
    no cgroup sets a limit. Left = the limit less the working set (usage less inactive file
    cache)."""
    best = None
    for folder, limit_file, usage_file in _cgroup_folders():
        limit = _read_int(folder / limit_file)
        if limit is None or limit >= _NO_LIMIT:
            continue
        usage = _read_int(folder / usage_file) or 0
        left = max(0, limit - max(0, usage - _inactive_file(folder)))
        if best is None or left < best[0]:
            best = (left, limit)
    return best


def environment_limit() -> int | None:
    """``$MICROCYL_MEMORY_LIMIT`` in bytes, None when unset or empty.

    Raises
    ------
    ValueError
        A value that is not a size (``16G``, ``500M``, ``1.5T``, ``1000000``).
    """
    raw = os.environ.get(ENV, "")
    env = raw.strip().upper().removesuffix("B")
    if not env:
        return None
    m = re.fullmatch(r"(\d+(?:\.\d*)?)\s*([KMGT]?)I?", env)
    if not m:
        raise ValueError(f"{ENV}={raw!r} is not a size; use bytes or a number with K, M, G "
                         f"or T (e.g. 16G)")
    return int(float(m.group(1)) * _UNITS[m.group(2)])


def memory_limit() -> tuple[int, str]:
    """(bytes, which source set it): the least of the sources of this module's docstring.

    Examples
    --------
    >>> limit, how = memory_limit()
    >>> limit > 0 and isinstance(how, str)
    True
    """
    share = f"{SHARE:.0%} of"
    candidates = []
    env = environment_limit()
    if env is not None:
        candidates.append((env, ENV))
    avail = meminfo_available()
    if avail is not None:
        candidates.append((int(SHARE * avail), f"{share} MemAvailable, the memory available"))
    rl = address_space_left()
    if rl is not None:
        candidates.append((int(SHARE * rl[0]), f"{share} the address space left under "
                                                f"ulimit -v, RLIMIT_AS {format_bytes(rl[1])}"))
    cg = cgroup_memory_left()
    if cg is not None:
        candidates.append((int(SHARE * cg[0]), f"{share} the memory left in the cgroup, "
                                                f"memory.max {format_bytes(cg[1])}"))
    if not candidates:
        return int(SHARE * available_memory()), f"{share} an assumed 8 GB"
    return min(candidates, key=lambda c: c[0])


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


class MemoryLimitError(ValueError):
    """Work refused by :func:`check_memory`: its estimate exceeds the memory limit (a
    ValueError, so that the command line prints it as one line)."""


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
    MemoryLimitError
        A ValueError, ``"{what} would take about X of memory; the limit is Y (how);
        {change}"``.
    """
    limit, how = memory_limit()
    nbytes = float(nbytes) if nbytes < 1e300 else math.inf
    if not nbytes <= limit:
        raise MemoryLimitError(f"{what} would take about {format_bytes(nbytes)} of memory; the "
                         f"limit is {format_bytes(limit)} ({how}); {change}")
