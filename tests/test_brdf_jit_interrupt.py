"""Ctrl-C while Dr.Jit imports: nanobind leaves its extension half registered, and a second
import aborts the process ("Critical nanobind error"), so brdf.jit never imports it again and
runs NumPy; the interrupt stays an interrupt."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("drjit")
REPO = Path(__file__).resolve().parents[1]

CHILD = r"""
import os, signal, sys, threading, time
from brdf import jit
delay = float(sys.argv[1])
first = "imported"
try:                                 # (an interrupt before the import lands here too)
    threading.Thread(target=lambda: (time.sleep(delay), os.kill(os.getpid(), signal.SIGINT)),
                     daemon=True).start()
    jit.compiled()
    time.sleep(delay + 1.0)          # an interrupt that came after the import lands here
except KeyboardInterrupt:
    first = "interrupt"
print(first, jit.available(), jit.backend())
"""


@pytest.mark.parametrize("delay", [0.0, 0.01, 0.02, 0.05, 0.1])
def test_an_import_of_drjit_cut_by_ctrl_c_is_an_interrupt_and_then_numpy(delay):
    r = subprocess.run([sys.executable, "-c", CHILD, str(delay)], cwd=REPO, text=True,
                       env=dict(os.environ, PYTHONPATH=str(REPO)), capture_output=True,
                       timeout=120)
    assert r.returncode == 0 and "nanobind" not in r.stderr, r.stderr[-2000:]
    first, *rest = r.stdout.split(maxsplit=1)
    assert first == "interrupt", r.stdout
    if "(False" in rest[0]:               # the interrupt cut the import: numpy from then on
        assert "interrupted" in rest[0] and rest[0].rstrip().endswith("numpy"), rest
