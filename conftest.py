"""Root pytest configuration: applies to the tests and to every package's doctests."""

import importlib.util
import os

import numpy as np
import pytest

#: These import Mitsuba or Dr.Jit at their top (optional dependencies at run time, imported
#: only by reports.mitsuba.register() and brdf.jit.compiled()): their doctests are collected
#: only where it is installed.
collect_ignore = ([] if importlib.util.find_spec("mitsuba") else ["reports/mitsuba/bsdf.py",
                                                                  "reports/mitsuba/scene.py"])
collect_ignore += [] if importlib.util.find_spec("drjit") else [
    f"brdf/jit/{m}.py" for m in ("consts", "kernel", "llvm", "sampler")]


#: One Dr.Jit thread a process, in the tests and every microcyl they start
#: (:data:`brdf.jit.THREADS_ENV`): `make test` runs a pytest worker a core and one more, each
#: starting fits, renders and Dask workers, and a pool of one thread a core in every one of
#: them oversubscribes the cores. Set before anything imports Dr.Jit.
os.environ.setdefault("MICROCYL_JIT_THREADS", "1")


@pytest.fixture(autouse=True)
def _numpy_print_defaults():
    """Importing colour-science switches NumPy to legacy 1.13 printing for the process; keep
    every test and doctest on NumPy's own defaults whatever was imported before it."""
    np.set_printoptions(legacy=False)
    yield
