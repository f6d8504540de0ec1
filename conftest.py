"""Root pytest configuration: applies to the tests and to every package's doctests."""

import numpy as np
import pytest


@pytest.fixture(autouse=True)
def _numpy_print_defaults():
    """Importing colour-science switches NumPy to legacy 1.13 printing for the process; keep
    every test and doctest on NumPy's own defaults whatever was imported before it."""
    np.set_printoptions(legacy=False)
    yield
