"""Ctrl-C while Dr.Jit imports: inside the extension's initialisation it crashed the process
(nanobind's std::terminate, a segfault, or a NameError and then an abort at the next import);
brdf.jit holds it back until the import has ended, then it is an ordinary interrupt."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from _signals import default_sigint

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
def test_ctrl_c_during_the_import_of_drjit_is_an_interrupt_after_it(delay):
    r = subprocess.run([sys.executable, "-c", CHILD, str(delay)], cwd=REPO, text=True,
                       preexec_fn=default_sigint,
                       env=dict(os.environ, PYTHONPATH=str(REPO)), capture_output=True,
                       timeout=120)
    assert r.returncode == 0 and "nanobind" not in r.stderr, r.stderr[-2000:]
    assert r.stdout.split() == ["interrupt", "(True,", "'')", "drjit"], r.stdout
