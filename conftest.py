"""Root pytest configuration: applies to the tests and to every package's doctests."""

import importlib.util

import numpy as np
import pytest

#: These import Mitsuba at their top (an optional dependency at run time, imported only by
#: reports.mitsuba.register()): their doctests are collected only where it is installed.
collect_ignore = [] if importlib.util.find_spec("mitsuba") else [
    "reports/mitsuba/kernel.py", "reports/mitsuba/bsdf.py"]


@pytest.fixture(autouse=True)
def _numpy_print_defaults():
    """Importing colour-science switches NumPy to legacy 1.13 printing for the process; keep
    every test and doctest on NumPy's own defaults whatever was imported before it."""
    np.set_printoptions(legacy=False)
    yield
