"""CPU seconds per test of the suite: a pytest plugin, and a summary of what it recorded.

On the shared 2-core machine the wall time of a test says more about the other processes than
about the test; its CPU seconds (its own process's and its waited-for subprocesses': a CLI run,
a Dask worker) do not. Record, in one process or on xdist workers (each appends its lines):

    PYTHONPATH=bench MICROCYL_SUITE_CPU=/tmp/cpu.jsonl .venv/bin/python -m pytest \\
        -p suite_cpu -p no:xdist -q tests/test_cli_plan.py

then summarize (the sum, the share of subprocesses, the slowest tests and files):

    .venv/bin/python bench/suite_cpu.py /tmp/cpu.jsonl [TOP]

The suite forks its CLI runs from a server (``tests/_forkcli.py``): their CPU comes from the
server (``_forkcli.CPU_OF_RUNS``) and counts as the test's subprocesses'.

Each line of the file is ``{"id", "self", "child", "wall"}`` in seconds; ``__collection__``
is a process's CPU up to the end of collection (imports of the test modules and doctests).
"""

from __future__ import annotations

import collections
import json
import os
import resource
import sys
import time

import pytest

_OUT = os.environ.get("MICROCYL_SUITE_CPU", "suite_cpu.jsonl")


def _cpu() -> tuple[float, float]:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    forked = getattr(sys.modules.get("_forkcli"), "CPU_OF_RUNS", 0.0)
    return own.ru_utime + own.ru_stime, kids.ru_utime + kids.ru_stime + forked


def _unforked() -> collections.Counter:
    """The worker's CLI runs so far that were not forked, by the variable that kept them."""
    return collections.Counter(getattr(sys.modules.get("_forkcli"), "UNFORKED", {}))


def _record(**row) -> None:
    with open(_OUT, "a", encoding="utf-8") as fh:
        fh.write(json.dumps(row) + "\n")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """Setup, call and teardown of one test (its fixtures built there included)."""
    s0, c0 = _cpu()
    n0 = _unforked()
    w0 = time.perf_counter()
    yield
    s1, c1 = _cpu()
    _record(id=item.nodeid, self=s1 - s0, child=c1 - c0, wall=time.perf_counter() - w0,
            unforked=dict(_unforked() - n0))


def pytest_collection_finish(session):
    own, kids = _cpu()
    _record(id="__collection__", self=own, child=kids, wall=0.0)


def summarize(path: str, top: int = 15) -> None:
    """Print the CPU sum of the file's tests, their slowest ``top`` and the slowest files."""
    rows = [json.loads(line) for line in open(path, encoding="utf-8") if line.strip()]
    cpu = {r["id"]: 0.0 for r in rows}
    for r in rows:
        cpu[r["id"]] += r["self"] + r["child"]
    files = collections.Counter()
    for name, sec in cpu.items():
        files[name.split("::")[0]] += sec
    child = sum(r["child"] for r in rows)
    total = sum(cpu.values())
    print(f"{len(cpu)} tests, {total:.0f} s CPU ({child:.0f} s in subprocesses)")
    for name, sec in sorted(cpu.items(), key=lambda kv: -kv[1])[:top]:
        print(f"{sec:8.1f}  {name}")
    unforked = sum((collections.Counter(r.get("unforked", {})) for r in rows),
                   collections.Counter())
    print(f"CLI runs not forked, by the variable that differed: {dict(unforked) or 'none'}")
    print("files:")
    for name, sec in files.most_common(top):
        print(f"{sec:8.1f}  {name}")


if __name__ == "__main__":
    summarize(sys.argv[1], *(int(a) for a in sys.argv[2:3]))
