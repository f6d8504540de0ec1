"""Root pytest configuration: applies to the tests and to every package's doctests."""

import importlib.util

import numpy as np
import pytest

#: These import Mitsuba or Dr.Jit at their top (optional dependencies at run time, imported
#: only by reports.mitsuba.register() and brdf.jit.compiled()): their doctests are collected
#: only where it is installed.
collect_ignore = ([] if importlib.util.find_spec("mitsuba") else ["reports/mitsuba/bsdf.py",
                                                                  "reports/mitsuba/scene.py"])
collect_ignore += [] if importlib.util.find_spec("drjit") else [
    f"brdf/jit/{m}.py" for m in ("consts", "kernel", "llvm", "sampler")]


@pytest.fixture(autouse=True)
def _numpy_print_defaults():
    """Importing colour-science switches NumPy to legacy 1.13 printing for the process; keep
    every test and doctest on NumPy's own defaults whatever was imported before it."""
    np.set_printoptions(legacy=False)
    yield
