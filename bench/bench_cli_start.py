"""The CPU time of short ``microcyl`` verbs as a user runs them (a new process each), this
source tree against another one (``--other TREE``, e.g. a ``git worktree`` of an older
commit), interleaved so that the machine's load falls on both alike.

Each verb runs ``--rounds`` times a tree, alternating; the figure is the median of the
child's user + system CPU seconds (``resource.getrusage``), so that waiting on a loaded
machine does not count. The machine and its load are printed with the figures.

Run: DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so \
     .venv/bin/python bench/bench_cli_start.py [--other TREE] [--rounds N]
"""

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
VERBS = (["--help"], ["sanity", "velvet"], ["reciprocity", "velvet"],
         ["eval", "velvet", "--wi", "30,0", "--wo", "30,180"],
         ["plot", "lobes", "velvet", "-o", "{tmp}/lobes.png"],
         ["export", "velvet", "-o", "{tmp}/velvet.json"])


def cpu_of(tree: Path, argv: list[str], tmp: str) -> float:
    """CPU seconds (user + system) of ``python -m reports ARGV`` run from ``tree``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    env = dict(os.environ, PYTHONPATH=str(tree))
    subprocess.run([sys.executable, "-m", "reports", *(a.format(tmp=tmp) for a in argv)],
                   env=env, cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--other", type=Path, help="another source tree to compare against")
    ap.add_argument("--rounds", type=int, default=7)
    args = ap.parse_args(argv)
    trees = {"this": HERE, **({"other": args.other.resolve()} if args.other else {})}
    print(f"{platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; "
          f"median CPU s of {args.rounds} runs, interleaved")
    with tempfile.TemporaryDirectory() as tmp:
        for verb in VERBS:
            times = {k: [] for k in trees}
            for _ in range(args.rounds):
                for k, tree in trees.items():
                    times[k].append(cpu_of(tree, verb, tmp))
            med = {k: statistics.median(v) for k, v in times.items()}
            line = "  ".join(f"{k} {v:.2f}" for k, v in med.items())
            ratio = f"  other/this {med['other'] / med['this']:.2f}x" if "other" in med else ""
            print(f"microcyl {' '.join(verb):<44} {line}{ratio}")
    print(f"load at the end {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
